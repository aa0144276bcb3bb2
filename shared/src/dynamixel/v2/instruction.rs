//! The instructions of Protocol 2.0 (e-Manual, "DYNAMIXEL Protocol 2.0", §
//! "Instruction" and § "Instruction Details"), borrowed from a packet's
//! parameters: what a servo (or the bus emulator) parses, and what a master
//! encodes. The master's convenience encoders, which build the parameters
//! from typed entries, are [`super::encoders`].
//!
//! | code | instruction | parameters (little endian) | reply |
//! |---|---|---|---|
//! | 0x01 | Ping | – | model number (2), firmware (1); every servo answers a broadcast PING |
//! | 0x02 | Read | address (2), length (2) | the data |
//! | 0x03 | Write | address (2), data | – |
//! | 0x04 | Reg Write | address (2), data; executed on ACTION | – |
//! | 0x05 | Action | – | – |
//! | 0x06 | Factory Reset | 0xFF all, 0x01 all but ID, 0x02 all but ID and baud rate | – |
//! | 0x08 | Reboot | – | – |
//! | 0x10 | Clear | 0x01 44 58 4C 22: multi-turn position back into one turn | – |
//! | 0x82 | Sync Read | address (2), length (2), IDs | one status packet per ID, in order |
//! | 0x83 | Sync Write | address (2), length (2), per servo: ID, data | none |
//! | 0x8A | Fast Sync Read | as Sync Read | one combined packet ([`super::fast`]) |
//! | 0x92 | Bulk Read | per servo: ID, address (2), length (2) | one status packet per ID |
//! | 0x93 | Bulk Write | per servo: ID, address (2), length (2), data | none |
//! | 0x9A | Fast Bulk Read | as Bulk Read | one combined packet |
//!
//! "–" replies are a status packet without parameters, subject to Status
//! Return Level; nothing answers an instruction to the broadcast ID but
//! PING and the sync/bulk reads. The multi-servo instructions go to the
//! broadcast ID (e-Manual: "Packet ID field: 0xFE").
//!
//! pada refuses, in parsing and encoding alike, what the e-Manual gives no
//! meaning to: reads and writes of zero bytes, a multi-servo instruction
//! without servos or naming a servo twice ("the same ID cannot be used
//! multiple times", § "Bulk Read"), an ID above 252 in it, factory-reset
//! options and CLEAR parameters other than the e-Manual's. What parses
//! encodes back to the same bytes, and what encodes parses.

use super::packet::{write_frame, EncodeError, InstructionPacket, BROADCAST_ID, MAX_ID, STATUS};
use super::status::ErrorNumber;

/// Instruction codes (e-Manual § "Instruction"). Control Table Backup
/// (0x20) is not implemented: it parses as an unknown code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum InstructionCode {
    /// Is a servo there, and which model.
    Ping = 0x01,
    /// Read from the control table.
    Read = 0x02,
    /// Write to the control table.
    Write = 0x03,
    /// Write, held until ACTION.
    RegWrite = 0x04,
    /// Execute the held REG WRITE.
    Action = 0x05,
    /// Reset the control table to factory defaults.
    FactoryReset = 0x06,
    /// Reboot the servo (the only way out of a hardware-error shutdown).
    Reboot = 0x08,
    /// Reset certain information (the multi-turn count).
    Clear = 0x10,
    /// Read the same item of several servos, one reply each.
    SyncRead = 0x82,
    /// Write the same item of several servos.
    SyncWrite = 0x83,
    /// Sync Read with one combined reply.
    FastSyncRead = 0x8A,
    /// Read a different item of each servo, one reply each.
    BulkRead = 0x92,
    /// Write a different item of each servo.
    BulkWrite = 0x93,
    /// Bulk Read with one combined reply.
    FastBulkRead = 0x9A,
}

impl InstructionCode {
    /// The code for a byte, if it is one this codec knows.
    pub const fn from_u8(b: u8) -> Option<Self> {
        Some(match b {
            0x01 => Self::Ping,
            0x02 => Self::Read,
            0x03 => Self::Write,
            0x04 => Self::RegWrite,
            0x05 => Self::Action,
            0x06 => Self::FactoryReset,
            0x08 => Self::Reboot,
            0x10 => Self::Clear,
            0x82 => Self::SyncRead,
            0x83 => Self::SyncWrite,
            0x8A => Self::FastSyncRead,
            0x92 => Self::BulkRead,
            0x93 => Self::BulkWrite,
            0x9A => Self::FastBulkRead,
            _ => return None,
        })
    }

    /// Whether the instruction addresses several servos (and so must go to
    /// the broadcast ID).
    pub const fn is_multi(self) -> bool {
        (self as u8) & 0x80 != 0
    }
}

/// What FACTORY RESET keeps (its one parameter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum ResetMode {
    /// 0xFF: reset everything (ignored when sent to the broadcast ID, from
    /// firmware 42 on).
    All = 0xFF,
    /// 0x01: everything but the ID.
    ExceptId = 0x01,
    /// 0x02: everything but the ID and the baud rate.
    ExceptIdAndBaudRate = 0x02,
}

impl ResetMode {
    /// The mode for a parameter byte.
    pub const fn from_u8(b: u8) -> Option<Self> {
        Some(match b {
            0xFF => Self::All,
            0x01 => Self::ExceptId,
            0x02 => Self::ExceptIdAndBaudRate,
            _ => return None,
        })
    }
}

/// CLEAR's parameters that reset the multi-turn count (option 0x01 and
/// the fixed key `44 58 4C 22`, "DXL\"").
pub const CLEAR_MULTI_TURN: [u8; 5] = [0x01, 0x44, 0x58, 0x4C, 0x22];
/// Bytes of one Bulk Read entry: ID, address (2), length (2).
pub const BULK_READ_ENTRY: usize = 5;

/// One servo's part of a Bulk Read or Fast Bulk Read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BulkReadEntry {
    /// The servo.
    pub id: u8,
    /// Start address.
    pub addr: u16,
    /// Bytes to read.
    pub len: u16,
}

impl BulkReadEntry {
    /// The entry's five bytes.
    pub const fn to_bytes(self) -> [u8; BULK_READ_ENTRY] {
        let [a0, a1] = self.addr.to_le_bytes();
        let [l0, l1] = self.len.to_le_bytes();
        [self.id, a0, a1, l0, l1]
    }
}

/// One servo's part of a Bulk Write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BulkWriteEntry<'a> {
    /// The servo.
    pub id: u8,
    /// Start address.
    pub addr: u16,
    /// Bytes to write there.
    pub data: &'a [u8],
}

/// An instruction, borrowing its parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Instruction<'a> {
    /// PING.
    Ping,
    /// READ of `len` bytes at `addr`.
    Read {
        /// Start address.
        addr: u16,
        /// Bytes to read.
        len: u16,
    },
    /// WRITE of `data` at `addr`.
    Write {
        /// Start address.
        addr: u16,
        /// Bytes to write.
        data: &'a [u8],
    },
    /// REG WRITE of `data` at `addr` (executed on ACTION).
    RegWrite {
        /// Start address.
        addr: u16,
        /// Bytes to write.
        data: &'a [u8],
    },
    /// ACTION.
    Action,
    /// FACTORY RESET.
    FactoryReset(ResetMode),
    /// REBOOT.
    Reboot,
    /// CLEAR of the multi-turn count ([`CLEAR_MULTI_TURN`]).
    ClearMultiTurn,
    /// SYNC READ of `len` bytes at `addr` from each of `ids`.
    SyncRead {
        /// Start address.
        addr: u16,
        /// Bytes per servo.
        len: u16,
        /// The servos, in the order they answer.
        ids: &'a [u8],
    },
    /// SYNC WRITE of `len` bytes at `addr`; `entries` holds, per servo, its
    /// ID and its `len` bytes ([`Instruction::sync_write_entries`]).
    SyncWrite {
        /// Start address.
        addr: u16,
        /// Bytes per servo.
        len: u16,
        /// `ID, data…` per servo, concatenated.
        entries: &'a [u8],
    },
    /// FAST SYNC READ: as SYNC READ, one combined reply.
    FastSyncRead {
        /// Start address.
        addr: u16,
        /// Bytes per servo.
        len: u16,
        /// The servos, in the order of their blocks.
        ids: &'a [u8],
    },
    /// BULK READ: five bytes per servo ([`Instruction::bulk_read_entries`]).
    BulkRead {
        /// `ID, address (2), length (2)` per servo, concatenated.
        entries: &'a [u8],
    },
    /// BULK WRITE ([`Instruction::bulk_write_entries`]).
    BulkWrite {
        /// `ID, address (2), length (2), data…` per servo, concatenated.
        entries: &'a [u8],
    },
    /// FAST BULK READ: as BULK READ, one combined reply.
    FastBulkRead {
        /// `ID, address (2), length (2)` per servo, concatenated.
        entries: &'a [u8],
    },
}

/// Why a packet's instruction is not one a servo executes (the bus
/// emulator answers with [`InstructionError::error_number`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InstructionError {
    /// A code this codec does not know.
    UnknownCode {
        /// The INSTRUCTION byte.
        code: u8,
    },
    /// Parameters that do not fit the instruction.
    BadParams {
        /// The INSTRUCTION byte.
        code: u8,
        /// Parameter bytes received.
        len: usize,
    },
    /// A multi-servo instruction not sent to the broadcast ID.
    NotBroadcast {
        /// The INSTRUCTION byte.
        code: u8,
    },
    /// A status packet (another servo's reply on a shared bus): not an
    /// instruction, and never answered.
    Status,
}

impl InstructionError {
    /// The Error Number a servo answers this with, or `None` for a status
    /// packet (no answer). An unknown code is an Instruction Error (e-Manual
    /// § "Error": "Undefined Instruction"), parameters that do not fit are
    /// a Data Length Error.
    pub const fn error_number(self) -> Option<ErrorNumber> {
        match self {
            Self::UnknownCode { .. } | Self::NotBroadcast { .. } => Some(ErrorNumber::Instruction),
            Self::BadParams { .. } => Some(ErrorNumber::DataLength),
            Self::Status => None,
        }
    }
}

/// A set of IDs (256 bits), to refuse an ID named twice without a heap.
struct IdSet([u32; 8]);

impl IdSet {
    /// Adds `id`; false if it is not a servo's ID or already in the set.
    fn insert(&mut self, id: u8) -> bool {
        let (word, bit) = ((id >> 5) as usize, 1u32 << (id & 31));
        match self.0.get_mut(word) {
            Some(w) if id <= MAX_ID && *w & bit == 0 => {
                *w |= bit;
                true
            }
            _ => false,
        }
    }
}

/// Whether every ID is a servo's and none is named twice, and there is
/// at least one.
pub(crate) fn distinct_servo_ids(ids: impl Iterator<Item = u8>) -> bool {
    let mut set = IdSet([0; 8]);
    let mut any = false;
    for id in ids {
        if !set.insert(id) {
            return false;
        }
        any = true;
    }
    any
}

fn le16(b: &[u8], at: usize) -> u16 {
    match b.get(at..at + 2) {
        Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
        _ => 0,
    }
}

impl<'a> Instruction<'a> {
    /// The instruction code.
    pub const fn code(&self) -> InstructionCode {
        match self {
            Self::Ping => InstructionCode::Ping,
            Self::Read { .. } => InstructionCode::Read,
            Self::Write { .. } => InstructionCode::Write,
            Self::RegWrite { .. } => InstructionCode::RegWrite,
            Self::Action => InstructionCode::Action,
            Self::FactoryReset(_) => InstructionCode::FactoryReset,
            Self::Reboot => InstructionCode::Reboot,
            Self::ClearMultiTurn => InstructionCode::Clear,
            Self::SyncRead { .. } => InstructionCode::SyncRead,
            Self::SyncWrite { .. } => InstructionCode::SyncWrite,
            Self::FastSyncRead { .. } => InstructionCode::FastSyncRead,
            Self::BulkRead { .. } => InstructionCode::BulkRead,
            Self::BulkWrite { .. } => InstructionCode::BulkWrite,
            Self::FastBulkRead { .. } => InstructionCode::FastBulkRead,
        }
    }

    /// The IDs of a (fast) sync read, or of the entries of the other
    /// multi-servo instructions, in order (empty for the rest).
    pub fn ids(&self) -> impl Iterator<Item = u8> + 'a {
        let ids: &'a [u8] = match *self {
            Self::SyncRead { ids, .. } | Self::FastSyncRead { ids, .. } => ids,
            _ => &[],
        };
        ids.iter()
            .copied()
            .chain(self.sync_write_entries().map(|(id, _)| id))
            .chain(self.bulk_read_entries().map(|e| e.id))
            .chain(self.bulk_write_entries().map(|e| e.id))
    }

    /// The `(id, data)` pairs of a SYNC WRITE (empty for other
    /// instructions; a trailing partial entry is not yielded).
    pub fn sync_write_entries(&self) -> impl Iterator<Item = (u8, &'a [u8])> + 'a {
        let (chunk, entries): (usize, &'a [u8]) = match *self {
            Self::SyncWrite { len, entries, .. } => (len as usize + 1, entries),
            _ => (1, &[]),
        };
        entries.chunks_exact(chunk).filter_map(|c| c.split_first().map(|(&id, d)| (id, d)))
    }

    /// The entries of a (fast) BULK READ (empty for other instructions).
    pub fn bulk_read_entries(&self) -> impl Iterator<Item = BulkReadEntry> + 'a {
        let entries: &'a [u8] = match *self {
            Self::BulkRead { entries } | Self::FastBulkRead { entries } => entries,
            _ => &[],
        };
        entries.chunks_exact(BULK_READ_ENTRY).map(|c| BulkReadEntry {
            id: c.first().copied().unwrap_or(0),
            addr: le16(c, 1),
            len: le16(c, 3),
        })
    }

    /// The entries of a BULK WRITE (empty for other instructions; stops at
    /// a malformed entry).
    pub fn bulk_write_entries(&self) -> BulkWrites<'a> {
        match *self {
            Self::BulkWrite { entries } => BulkWrites { rest: entries },
            _ => BulkWrites { rest: &[] },
        }
    }

    /// Parses a decoded packet's INSTRUCTION byte and parameters.
    pub fn parse(code: u8, params: &'a [u8]) -> Result<Self, InstructionError> {
        if code == STATUS {
            return Err(InstructionError::Status);
        }
        let c = InstructionCode::from_u8(code).ok_or(InstructionError::UnknownCode { code })?;
        let bad = InstructionError::BadParams { code, len: params.len() };
        let (addr, len, rest) = (le16(params, 0), le16(params, 2), params.get(4..).unwrap_or_default());
        let data = params.get(2..).unwrap_or_default();
        let ins = match c {
            InstructionCode::Ping if params.is_empty() => Self::Ping,
            InstructionCode::Action if params.is_empty() => Self::Action,
            InstructionCode::Reboot if params.is_empty() => Self::Reboot,
            InstructionCode::Read if params.len() == 4 => Self::Read { addr, len },
            InstructionCode::Write if params.len() >= 2 => Self::Write { addr, data },
            InstructionCode::RegWrite if params.len() >= 2 => Self::RegWrite { addr, data },
            InstructionCode::FactoryReset => match *params {
                [mode] => Self::FactoryReset(ResetMode::from_u8(mode).ok_or(bad)?),
                _ => return Err(bad),
            },
            InstructionCode::Clear if params == CLEAR_MULTI_TURN => Self::ClearMultiTurn,
            InstructionCode::SyncRead if params.len() >= 4 => Self::SyncRead { addr, len, ids: rest },
            InstructionCode::FastSyncRead if params.len() >= 4 => Self::FastSyncRead { addr, len, ids: rest },
            InstructionCode::SyncWrite if params.len() >= 4 => Self::SyncWrite { addr, len, entries: rest },
            InstructionCode::BulkRead => Self::BulkRead { entries: params },
            InstructionCode::FastBulkRead => Self::FastBulkRead { entries: params },
            InstructionCode::BulkWrite => Self::BulkWrite { entries: params },
            _ => return Err(bad),
        };
        if ins.is_valid() {
            Ok(ins)
        } else {
            Err(bad)
        }
    }

    /// Whether the parameters follow the instruction's layout and pada's
    /// rules (the module docs); [`Self::parse`] and [`Self::encode`] both
    /// refuse what is not.
    pub fn is_valid(&self) -> bool {
        match *self {
            Self::Ping | Self::Action | Self::Reboot | Self::ClearMultiTurn | Self::FactoryReset(_) => true,
            Self::Read { len, .. } => len > 0,
            Self::Write { data, .. } | Self::RegWrite { data, .. } => !data.is_empty(),
            Self::SyncRead { len, ids, .. } | Self::FastSyncRead { len, ids, .. } => {
                len > 0 && distinct_servo_ids(ids.iter().copied())
            }
            Self::SyncWrite { len, entries, .. } => {
                len > 0 && entries.len() % (len as usize + 1) == 0 && distinct_servo_ids(self.ids())
            }
            Self::BulkRead { entries } | Self::FastBulkRead { entries } => {
                entries.len() % BULK_READ_ENTRY == 0
                    && self.bulk_read_entries().all(|e| e.len > 0)
                    && distinct_servo_ids(self.ids())
            }
            Self::BulkWrite { entries } => {
                let consumed: usize = self.bulk_write_entries().map(|e| BULK_READ_ENTRY + e.data.len()).sum();
                consumed == entries.len()
                    && self.bulk_write_entries().all(|e| !e.data.is_empty())
                    && distinct_servo_ids(self.ids())
            }
        }
    }

    /// The parameter bytes: up to four leading bytes, then a borrowed tail.
    fn parts(&self) -> ([u8; 5], usize, &'a [u8]) {
        let two = |a: u16, b: u16| {
            let ([a0, a1], [b0, b1]) = (a.to_le_bytes(), b.to_le_bytes());
            [a0, a1, b0, b1, 0]
        };
        match *self {
            Self::Ping | Self::Action | Self::Reboot => ([0; 5], 0, &[]),
            Self::ClearMultiTurn => (CLEAR_MULTI_TURN, 5, &[]),
            Self::FactoryReset(m) => ([m as u8, 0, 0, 0, 0], 1, &[]),
            Self::Read { addr, len } => (two(addr, len), 4, &[]),
            Self::Write { addr, data } | Self::RegWrite { addr, data } => (two(addr, 0), 2, data),
            Self::SyncRead { addr, len, ids } | Self::FastSyncRead { addr, len, ids } => (two(addr, len), 4, ids),
            Self::SyncWrite { addr, len, entries } => (two(addr, len), 4, entries),
            Self::BulkRead { entries } | Self::FastBulkRead { entries } | Self::BulkWrite { entries } => {
                ([0; 5], 0, entries)
            }
        }
    }

    /// Encodes the instruction for `id` into `out` (a multi-servo
    /// instruction only for [`BROADCAST_ID`]) and returns the packet.
    pub fn encode<'b>(&self, id: u8, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        let code = self.code();
        if code.is_multi() && id != BROADCAST_ID {
            return Err(EncodeError::NotBroadcast { code: code as u8 });
        }
        if !self.is_valid() {
            return Err(EncodeError::BadParams { code: code as u8 });
        }
        let (head, n, tail) = self.parts();
        let body = head.iter().take(n).chain(tail).copied();
        write_frame(id, code as u8, body, out)
    }

    /// Parameter bytes of the status packet that answers this instruction
    /// from one servo: 3 for PING, the length read for (sync, bulk) reads,
    /// 0 otherwise. `None` for a fast read (one combined reply, see
    /// [`super::fast`]) and for a bulk read whose entries differ in length.
    pub fn reply_params(&self) -> Option<u16> {
        match *self {
            Self::Ping => Some(super::status::PingReply::PARAMS as u16),
            Self::Read { len, .. } | Self::SyncRead { len, .. } => Some(len),
            Self::FastSyncRead { .. } | Self::FastBulkRead { .. } => None,
            Self::BulkRead { .. } => {
                let mut lens = self.bulk_read_entries().map(|e| e.len);
                let first = lens.next()?;
                lens.all(|l| l == first).then_some(first)
            }
            _ => Some(0),
        }
    }
}

/// The entries of a BULK WRITE, in order; ends at the first entry that
/// does not fit what is left.
#[derive(Debug, Clone)]
pub struct BulkWrites<'a> {
    rest: &'a [u8],
}

impl<'a> Iterator for BulkWrites<'a> {
    type Item = BulkWriteEntry<'a>;

    fn next(&mut self) -> Option<Self::Item> {
        let (&id, _) = self.rest.split_first()?;
        let (addr, len) = (le16(self.rest, 1), le16(self.rest, 3) as usize);
        let data = self.rest.get(BULK_READ_ENTRY..BULK_READ_ENTRY + len);
        match data {
            Some(data) => {
                self.rest = self.rest.get(BULK_READ_ENTRY + len..).unwrap_or_default();
                Some(BulkWriteEntry { id, addr, data })
            }
            _ => {
                self.rest = &[];
                None
            }
        }
    }
}

impl<const N: usize> InstructionPacket<N> {
    /// The instruction, borrowing this packet's parameters; a status
    /// packet, an unknown code, bad parameters and a multi-servo
    /// instruction not sent to the broadcast ID are errors.
    pub fn instruction(&self) -> Result<Instruction<'_>, InstructionError> {
        let ins = Instruction::parse(self.instruction, &self.params)?;
        if ins.code().is_multi() && self.id != BROADCAST_ID {
            return Err(InstructionError::NotBroadcast { code: self.instruction });
        }
        Ok(ins)
    }
}
