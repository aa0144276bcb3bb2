//! Control tables of the Protocol 2.0 servos pada supports, as data: what
//! is at which address, how long, who may write it, which values are
//! valid, in which unit. The e-Manual pages and the choices where they
//! disagree with each other are in docs/reference/dynamixel.md §§ 5–7,
//! whose tables a test compares with these ones (`shared/tests/
//! dynamixel_tables.rs`), so the two cannot drift.
//!
//! | model | model number | protocol | module |
//! |---|---|---|---|
//! | XM430-W350 | 1020 | 2.0 | [`x_series::XM430_W350`] |
//! | XL430-W250 | 1060 | 2.0 | [`x_series::XL430_W250`] |
//! | XL330-M288 | 1200 | 2.0 | [`x_series::XL330_M288`] |
//! | MX-28 (2.0 firmware) | 30 | 2.0 | [`mx28::MX28_V2`] |
//! | RX-28 | 28 | 1.0 | [`rx28::RX28`] (not in [`TABLES`], the Protocol 2.0 ones) |
//!
//! A table is about the bus only; a robot's servo-model entry (stall
//! torque, speed, gear ratio) refers to one as `&'static ControlTable`,
//! found by the model number a PING returns ([`by_model_number`]).
//!
//! The checks a servo makes before it writes ([`ControlTable::check_write`],
//! [`ControlTable::check_read`]) are here, so that the bus emulator answers
//! with the e-Manual's Error Numbers: Access Error for read-only, undefined
//! or torque-locked EEPROM addresses, Data Length Error for a write that
//! covers only part of an item, Data Range Error for a value outside the
//! item's range, Data Limit Error for one beyond the limit another item
//! sets (Goal PWM beyond PWM Limit).

use super::v2::ErrorNumber;
use super::Protocol;
use core::fmt;

pub mod mx28;
pub mod rx28;
pub mod x_series;

/// Who may access an item.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    /// Read only.
    R,
    /// Read and write.
    RW,
}

/// Where an item lives: EEPROM items keep their value over power cycles
/// and can be written only while Torque Enable is 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Memory {
    /// Non-volatile; locked while torque is on.
    Eeprom,
    /// Volatile.
    Ram,
}

/// The values a write may carry (e-Manual: the "Range" column; a value
/// outside is a Data Range Error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Valid {
    /// Any value of the item's size (read-only items, raw bytes).
    Any,
    /// `min ..= max`.
    Range(i64, i64),
    /// A bit field: only these bits may be set.
    Mask(u32),
    /// One of these values (Operating Mode).
    OneOf(&'static [i64]),
}

impl Valid {
    /// Whether `v` is valid.
    pub fn contains(&self, v: i64) -> bool {
        match *self {
            Valid::Any => true,
            Valid::Range(min, max) => (min..=max).contains(&v),
            Valid::Mask(m) => v >= 0 && v & !(m as i64) == 0,
            Valid::OneOf(list) => list.contains(&v),
        }
    }
}

/// A limit another item sets on this one's value (a value beyond it is a
/// Data Limit Error).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Limit {
    /// `|value| ≤` the item at this address (Goal PWM ≤ PWM Limit).
    Magnitude(u16),
    /// Between the items at `min` and `max`, while Operating Mode equals
    /// `mode` (Goal Position within the position limits in Position
    /// Control Mode only).
    Between {
        /// Address of the lower limit.
        min: u16,
        /// Address of the upper limit.
        max: u16,
        /// The Operating Mode in which the limit applies.
        mode: u8,
    },
}

/// An item's unit: the physical value of one count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// The quantity one count stands for (in `symbol`).
    pub per_count: f32,
    /// The unit's symbol; empty for dimensionless items.
    pub symbol: &'static str,
}

impl Unit {
    /// No unit (IDs, modes, flags).
    pub const NONE: Unit = Unit { per_count: 1.0, symbol: "" };
    /// A unit of `per_count` `symbol`s.
    pub const fn new(per_count: f32, symbol: &'static str) -> Unit {
        Unit { per_count, symbol }
    }
}

impl fmt::Display for Unit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.symbol.is_empty() {
            f.write_str("-")
        } else {
            write!(f, "{} {}", self.per_count, self.symbol)
        }
    }
}

/// One item of a control table (or `count` items of the same size in a
/// row, like the Indirect Addresses).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Item {
    /// The e-Manual's name (for a row of items, the first and last, "Indirect
    /// Address 1–28").
    pub name: &'static str,
    /// First address.
    pub address: u16,
    /// Bytes per item: 1, 2 or 4.
    pub size: u8,
    /// Items in the row (1 for a single item).
    pub count: u8,
    /// Read only or read/write.
    pub access: Access,
    /// EEPROM or RAM.
    pub memory: Memory,
    /// Two's complement (Present Velocity) or not.
    pub signed: bool,
    /// The values a write may carry.
    pub valid: Valid,
    /// The limit another item sets, if any.
    pub limit: Option<Limit>,
    /// The unit of one count.
    pub unit: Unit,
}

impl Item {
    /// An item of `size` bytes at `address`, any value, no unit; refine it
    /// with the builder methods below.
    pub const fn new(name: &'static str, address: u16, size: u8, access: Access, memory: Memory) -> Item {
        Item { name, address, size, count: 1, access, memory, signed: false, valid: Valid::Any, limit: None, unit: Unit::NONE }
    }
    /// A read-only RAM item.
    pub const fn ro(name: &'static str, address: u16, size: u8) -> Item {
        Item::new(name, address, size, Access::R, Memory::Ram)
    }
    /// A read-write RAM item.
    pub const fn ram(name: &'static str, address: u16, size: u8) -> Item {
        Item::new(name, address, size, Access::RW, Memory::Ram)
    }
    /// A read-write EEPROM item.
    pub const fn eeprom(name: &'static str, address: u16, size: u8) -> Item {
        Item::new(name, address, size, Access::RW, Memory::Eeprom)
    }
    /// The same item, read-only.
    pub const fn read_only(mut self) -> Item {
        self.access = Access::R;
        self
    }
    /// The same item, two's complement.
    pub const fn signed(mut self) -> Item {
        self.signed = true;
        self
    }
    /// Valid values `min ..= max`.
    pub const fn range(mut self, min: i64, max: i64) -> Item {
        self.valid = Valid::Range(min, max);
        self
    }
    /// Valid values: these bits.
    pub const fn mask(mut self, bits: u32) -> Item {
        self.valid = Valid::Mask(bits);
        self
    }
    /// Valid values: one of these.
    pub const fn one_of(mut self, values: &'static [i64]) -> Item {
        self.valid = Valid::OneOf(values);
        self
    }
    /// Limited by other items.
    pub const fn limit(mut self, limit: Limit) -> Item {
        self.limit = Some(limit);
        self
    }
    /// One count is `per_count` `symbol`.
    pub const fn unit(mut self, per_count: f32, symbol: &'static str) -> Item {
        self.unit = Unit::new(per_count, symbol);
        self
    }
    /// `count` items of this size in a row.
    pub const fn times(mut self, count: u8) -> Item {
        self.count = count;
        self
    }

    /// Bytes the item (or row) covers.
    pub const fn span(&self) -> u16 {
        self.size as u16 * self.count as u16
    }

    /// One past the last address.
    pub const fn end(&self) -> u16 {
        self.address + self.span()
    }

    /// The value of one item's bytes (little endian, sign-extended if the
    /// item is signed); `None` if `bytes` is not `size` long.
    pub fn decode(&self, bytes: &[u8]) -> Option<i64> {
        if bytes.len() != self.size as usize {
            return None;
        }
        let mut raw = [0u8; 8];
        raw.get_mut(..bytes.len())?.copy_from_slice(bytes);
        let v = u64::from_le_bytes(raw);
        let bits = 8 * self.size as u32;
        Some(if self.signed && bits < 64 && v >> (bits - 1) & 1 == 1 { (v | (u64::MAX << bits)) as i64 } else { v as i64 })
    }
}

/// Why a servo refuses a read or a write (each maps to an Error Number).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableError {
    /// An address no item covers, or past the table's end (Access Error).
    Undefined {
        /// The first such address.
        address: u16,
    },
    /// A write to a read-only item (Access Error).
    ReadOnly {
        /// The item's address.
        address: u16,
    },
    /// A write to EEPROM while Torque Enable is 1 (Access Error).
    EepromLocked {
        /// The item's address.
        address: u16,
    },
    /// A write that covers only part of an item, or no byte at all (Data
    /// Length Error).
    Partial {
        /// The item's address.
        address: u16,
    },
    /// A value outside the item's range (Data Range Error).
    OutOfRange {
        /// The item's address.
        address: u16,
        /// The value.
        value: i64,
    },
    /// A value beyond the limit another item sets (Data Limit Error).
    OverLimit {
        /// The item's address.
        address: u16,
        /// The value.
        value: i64,
    },
}

impl TableError {
    /// The Error Number a servo answers with (e-Manual, Protocol 2.0 §
    /// "Error").
    pub const fn error_number(self) -> ErrorNumber {
        match self {
            Self::Undefined { .. } | Self::ReadOnly { .. } | Self::EepromLocked { .. } => ErrorNumber::Access,
            Self::Partial { .. } => ErrorNumber::DataLength,
            Self::OutOfRange { .. } => ErrorNumber::DataRange,
            Self::OverLimit { .. } => ErrorNumber::DataLimit,
        }
    }
}

/// A model's control table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlTable {
    /// The model's name.
    pub model: &'static str,
    /// The Model Number at address 0 (and in a PING reply).
    pub model_number: u16,
    /// The protocol of this table.
    pub protocol: Protocol,
    /// The items pada uses, by address.
    pub items: &'static [Item],
    /// Baud Rate value → bits per second.
    pub baud_rates: &'static [u32],
    /// One past the table's last address.
    pub end: u16,
    /// Torque Enable's address (EEPROM is locked while it is 1).
    pub torque_enable: u16,
    /// Operating Mode's address (for mode-dependent limits).
    pub operating_mode: u16,
}

/// Every table pada knows.
pub static TABLES: [&ControlTable; 4] = [&x_series::XM430_W350, &x_series::XL430_W250, &x_series::XL330_M288, &mx28::MX28_V2];

/// The table of the model that answers PING with `model_number`.
pub fn by_model_number(model_number: u16) -> Option<&'static ControlTable> {
    TABLES.iter().copied().find(|t| t.model_number == model_number)
}

impl ControlTable {
    /// The item (or row) covering `address`.
    pub fn item_at(&self, address: u16) -> Option<&'static Item> {
        self.items.iter().find(|i| (i.address..i.end()).contains(&address))
    }

    /// The item named `name` (exactly as the e-Manual writes it).
    pub fn item_named(&self, name: &str) -> Option<&'static Item> {
        self.items.iter().find(|i| i.name == name)
    }

    /// The bit rate of a Baud Rate value.
    pub fn baud_rate_bps(&self, value: u8) -> Option<u32> {
        self.baud_rates.get(value as usize).copied()
    }

    /// The current value of the single item at `address` in a servo's
    /// table image `memory` (indexed by address).
    pub fn value(&self, memory: &[u8], address: u16) -> Option<i64> {
        let item = self.item_at(address)?;
        let offset = (address - item.address) as usize;
        if offset % item.size as usize != 0 {
            return None;
        }
        item.decode(memory.get(address as usize..address as usize + item.size as usize)?)
    }

    /// Whether a READ of `len` bytes at `address` is allowed: it must lie
    /// within the table (addresses between items read as the servo keeps
    /// them; the ROBOTIS tools read whole tables in one READ).
    pub fn check_read(&self, address: u16, len: u16) -> Result<(), TableError> {
        let end = address as u32 + len as u32;
        if len == 0 {
            return Err(TableError::Partial { address });
        }
        if end > self.end as u32 {
            return Err(TableError::Undefined { address: address.max(self.end) });
        }
        Ok(())
    }

    /// Whether a servo whose table image is `memory` (indexed by address:
    /// Torque Enable, Operating Mode and the limit items are read from it)
    /// accepts a WRITE of `data` at `address`. Every byte must belong to a
    /// whole, writable item, and each value must be valid and within its
    /// limit; the first refusal is returned.
    pub fn check_write(&self, address: u16, data: &[u8], memory: &[u8]) -> Result<(), TableError> {
        let end = address as usize + data.len();
        if data.is_empty() {
            return Err(TableError::Partial { address });
        }
        let torque_on = self.value(memory, self.torque_enable).is_some_and(|v| v != 0);
        let mut pos = address as usize;
        while pos < end {
            let at = pos as u16;
            let item = self.item_at(at).ok_or(TableError::Undefined { address: at })?;
            let element = item.address as usize + (pos - item.address as usize) / item.size as usize * item.size as usize;
            let element_end = element + item.size as usize;
            if element != pos || element_end > end {
                return Err(TableError::Partial { address: element as u16 });
            }
            if item.access == Access::R {
                return Err(TableError::ReadOnly { address: at });
            }
            if item.memory == Memory::Eeprom && torque_on {
                return Err(TableError::EepromLocked { address: at });
            }
            let bytes = data.get(pos - address as usize..element_end - address as usize).unwrap_or_default();
            let value = item.decode(bytes).ok_or(TableError::Partial { address: at })?;
            if !item.valid.contains(value) {
                return Err(TableError::OutOfRange { address: at, value });
            }
            if !self.within_limit(item, value, memory) {
                return Err(TableError::OverLimit { address: at, value });
            }
            pos = element_end;
        }
        Ok(())
    }

    /// Whether `value` is within `item`'s limit; a limit item missing from
    /// `memory` does not limit.
    fn within_limit(&self, item: &Item, value: i64, memory: &[u8]) -> bool {
        match item.limit {
            None => true,
            Some(Limit::Magnitude(at)) => self.value(memory, at).is_none_or(|lim| value.abs() <= lim),
            Some(Limit::Between { min, max, mode }) => {
                if self.value(memory, self.operating_mode) != Some(mode as i64) {
                    return true;
                }
                self.value(memory, min).is_none_or(|lo| value >= lo) && self.value(memory, max).is_none_or(|hi| value <= hi)
            }
        }
    }

    /// The table as the Markdown that docs/reference/dynamixel.md holds
    /// (a test compares them).
    pub fn markdown(&self) -> Markdown<'_> {
        Markdown(self)
    }
}

/// [`ControlTable::markdown`]'s output.
pub struct Markdown<'a>(&'a ControlTable);

impl fmt::Display for Markdown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let t = self.0;
        writeln!(f, "Model Number {}. Baud Rate values (bps):", t.model_number)?;
        for (i, bps) in t.baud_rates.iter().enumerate() {
            write!(f, "{}{i} = {bps}", if i == 0 { "" } else { ", " })?;
        }
        writeln!(f, ".")?;
        writeln!(f)?;
        writeln!(f, "| address | size | item | access | memory | valid values | limited by | unit |")?;
        writeln!(f, "|---|---|---|---|---|---|---|---|")?;
        for i in t.items {
            let size = if i.count > 1 { (i.count, "×") } else { (0, "") };
            write!(f, "| {} | ", i.address)?;
            if size.0 > 0 {
                write!(f, "{} {} {}", size.0, size.1, i.size)?;
            } else {
                write!(f, "{}", i.size)?;
            }
            let access = if i.access == Access::R { "R" } else { "RW" };
            let memory = if i.memory == Memory::Eeprom { "EEPROM" } else { "RAM" };
            let signed = if i.signed { ", signed" } else { "" };
            write!(f, " | {} | {access}{signed} | {memory} | ", i.name)?;
            match i.valid {
                Valid::Any => f.write_str("-")?,
                Valid::Range(a, b) => write!(f, "{a} ~ {b}")?,
                Valid::Mask(m) => write!(f, "bits 0x{m:02X}")?,
                Valid::OneOf(list) => {
                    for (k, v) in list.iter().enumerate() {
                        write!(f, "{}{v}", if k == 0 { "" } else { ", " })?;
                    }
                }
            }
            f.write_str(" | ")?;
            let name = |at: u16| t.item_at(at).map_or("?", |i| i.name);
            match i.limit {
                None => f.write_str("-")?,
                Some(Limit::Magnitude(at)) => write!(f, "±{}({at})", name(at))?,
                Some(Limit::Between { min, max, mode }) => {
                    write!(f, "{}({min}) ~ {}({max}) in Operating Mode {mode}", name(min), name(max))?
                }
            }
            writeln!(f, " | {} |", i.unit)?;
        }
        Ok(())
    }
}
