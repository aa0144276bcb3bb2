//! Dynamixel Protocol 1.0 packets: the checksum, instruction and status
//! packets, their encoding and the instruction parser. Decoding a byte
//! stream into packets is [`super::decoder`].

use heapless::Vec;
/// The two header bytes that start every packet.
pub const HEADER: [u8; 2] = [0xFF, 0xFF];
/// The broadcast ID: every servo executes the instruction, none answers.
pub const BROADCAST_ID: u8 = 0xFE;
/// The highest ID a servo can have (RX-28: 0–253).
pub const MAX_ID: u8 = 0xFD;
/// Bytes of a packet besides its parameters: two header bytes, ID, LENGTH,
/// INSTRUCTION/ERROR and CHECKSUM.
pub const OVERHEAD: usize = 6;
/// The most parameters a Protocol 1.0 packet can carry (LENGTH is one byte).
pub const MAX_PARAMS: usize = 253;
/// Default decoder buffer: a whole packet of up to 58 parameter bytes, enough
/// for a READ of the RX-28's entire control table (50 bytes) and a
/// SYNC_WRITE of four bytes to eleven servos.
pub const DEFAULT_PACKET_LEN: usize = 64;

/// Instruction codes of Protocol 1.0 (e-Manual, "Instruction Packet").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum InstructionCode {
    /// Asks for a status packet; no effect otherwise.
    Ping = 0x01,
    /// Reads `len` bytes from the control table starting at `addr`.
    Read = 0x02,
    /// Writes bytes to the control table starting at `addr`.
    Write = 0x03,
    /// Like WRITE, but held until an ACTION instruction.
    RegWrite = 0x04,
    /// Executes the registered REG_WRITE.
    Action = 0x05,
    /// Resets the control table to factory defaults.
    Reset = 0x06,
    /// Writes the same addresses of several servos (broadcast, no answer).
    SyncWrite = 0x83,
    /// Reads each servo its own address and length (broadcast; the servos
    /// answer in turn). The Protocol 1.0 page defines it; the MX series
    /// answers it.
    BulkRead = 0x92,
}

impl InstructionCode {
    /// The code for a byte, if it is one this codec knows.
    pub fn from_u8(b: u8) -> Option<Self> {
        Some(match b {
            0x01 => Self::Ping,
            0x02 => Self::Read,
            0x03 => Self::Write,
            0x04 => Self::RegWrite,
            0x05 => Self::Action,
            0x06 => Self::Reset,
            0x83 => Self::SyncWrite,
            0x92 => Self::BulkRead,
            _ => return None,
        })
    }
}

/// The error byte of a status packet: one bit per condition
/// (e-Manual, "Status Packet"). Unknown bits (bit 7) are kept.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ErrorFlags(pub u8);

impl ErrorFlags {
    /// No error.
    pub const NONE: ErrorFlags = ErrorFlags(0);
    /// Bit 0: the input voltage is outside the limits of the control table.
    pub const INPUT_VOLTAGE: ErrorFlags = ErrorFlags(0x01);
    /// Bit 1: Goal Position is outside the CW/CCW angle limits.
    pub const ANGLE_LIMIT: ErrorFlags = ErrorFlags(0x02);
    /// Bit 2: the internal temperature exceeds the temperature limit.
    pub const OVERHEATING: ErrorFlags = ErrorFlags(0x04);
    /// Bit 3: an instruction parameter is out of range.
    pub const RANGE: ErrorFlags = ErrorFlags(0x08);
    /// Bit 4: the checksum of the received instruction packet was wrong.
    pub const CHECKSUM: ErrorFlags = ErrorFlags(0x10);
    /// Bit 5: the load cannot be controlled with the set maximum torque.
    pub const OVERLOAD: ErrorFlags = ErrorFlags(0x20);
    /// Bit 6: an undefined instruction, or ACTION without REG_WRITE.
    pub const INSTRUCTION: ErrorFlags = ErrorFlags(0x40);
    /// All bits the e-Manual defines.
    pub const ALL: ErrorFlags = ErrorFlags(0x7F);
    /// The hardware conditions after which a servo should not keep driving:
    /// input voltage, overheating and overload.
    pub const HARDWARE: ErrorFlags = ErrorFlags(0x01 | 0x04 | 0x20);

    /// The raw byte.
    pub const fn bits(self) -> u8 {
        self.0
    }
    /// Whether no bit is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
    /// Whether every bit of `other` is set in `self`.
    pub const fn contains(self, other: ErrorFlags) -> bool {
        self.0 & other.0 == other.0
    }
    /// Whether any bit of `other` is set in `self`.
    pub const fn intersects(self, other: ErrorFlags) -> bool {
        self.0 & other.0 != 0
    }
    /// Bits set in either.
    pub const fn union(self, other: ErrorFlags) -> ErrorFlags {
        ErrorFlags(self.0 | other.0)
    }
    /// Bits set in both.
    pub const fn intersection(self, other: ErrorFlags) -> ErrorFlags {
        ErrorFlags(self.0 & other.0)
    }
    /// The names of the set bits, lowest first (bit 7 is `"unknown"`).
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        const NAMES: [&str; 8] =
            ["input voltage", "angle limit", "overheating", "range", "checksum", "overload", "instruction", "unknown"];
        (0..8).filter(move |b| self.0 & (1 << b) != 0).map(|b| NAMES[b])
    }
}

impl core::ops::BitOr for ErrorFlags {
    type Output = ErrorFlags;
    fn bitor(self, rhs: ErrorFlags) -> ErrorFlags {
        self.union(rhs)
    }
}

impl core::ops::BitAnd for ErrorFlags {
    type Output = ErrorFlags;
    fn bitand(self, rhs: ErrorFlags) -> ErrorFlags {
        self.intersection(rhs)
    }
}

/// Why a packet could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The output buffer is too small.
    BufferTooSmall {
        /// Bytes the packet needs.
        needed: usize,
        /// Bytes available.
        available: usize,
    },
    /// More than [`MAX_PARAMS`] parameter bytes.
    TooManyParams {
        /// Parameter bytes given.
        params: usize,
    },
    /// The ID is 0xFF (never an ID), or a status packet from the broadcast ID.
    InvalidId {
        /// The offending ID.
        id: u8,
    },
    /// WRITE or REG_WRITE without data: Protocol 1.0 writes at least one
    /// byte, and [`Instruction::parse`] refuses the packet
    /// ([`InstructionError::BadParams`]), so it is not encoded either.
    NoData {
        /// The instruction code.
        code: u8,
    },
    /// SYNC_WRITE data whose length does not match the declared data length,
    /// or whose data length is zero.
    SyncDataLength {
        /// Index of the offending servo entry.
        entry: usize,
        /// Declared data length per servo.
        expected: u8,
        /// Bytes given for this entry.
        got: usize,
    },
    /// An instruction the protocol does not have (Feetech's: BULK READ).
    Unsupported {
        /// The instruction code.
        code: u8,
    },
}

/// The checksum of Protocol 1.0 over `ID, LENGTH, INSTRUCTION/ERROR, params`.
pub fn checksum(bytes: &[u8]) -> u8 {
    !bytes.iter().fold(0u8, |s, &b| s.wrapping_add(b))
}

/// Writes one packet into `out`, returning the written prefix (Feetech's
/// packets are framed so too: [`crate::feetech`]).
pub(crate) fn write_packet<'b>(id: u8, code: u8, parts: &[&[u8]], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    if id == 0xFF {
        return Err(EncodeError::InvalidId { id });
    }
    let params: usize = parts.iter().map(|p| p.len()).sum();
    if params > MAX_PARAMS {
        return Err(EncodeError::TooManyParams { params });
    }
    let total = params + OVERHEAD;
    if out.len() < total {
        return Err(EncodeError::BufferTooSmall { needed: total, available: out.len() });
    }
    out[0] = 0xFF;
    out[1] = 0xFF;
    out[2] = id;
    out[3] = (params + 2) as u8;
    out[4] = code;
    let mut i = 5;
    for part in parts {
        out[i..i + part.len()].copy_from_slice(part);
        i += part.len();
    }
    out[i] = checksum(&out[2..i]);
    Ok(&out[..total])
}

/// An instruction, borrowing its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Instruction<'a> {
    /// PING.
    Ping,
    /// READ_DATA of `len` bytes from `addr`.
    Read {
        /// Start address in the control table.
        addr: u8,
        /// Number of bytes.
        len: u8,
    },
    /// WRITE_DATA of `data` to `addr`.
    Write {
        /// Start address in the control table.
        addr: u8,
        /// Bytes to write.
        data: &'a [u8],
    },
    /// REG_WRITE of `data` to `addr` (executed on ACTION).
    RegWrite {
        /// Start address in the control table.
        addr: u8,
        /// Bytes to write.
        data: &'a [u8],
    },
    /// ACTION.
    Action,
    /// RESET to factory defaults.
    Reset,
    /// SYNC_WRITE: `data_len` bytes at `addr` for several servos. `entries`
    /// holds, per servo, its ID followed by its `data_len` bytes; see
    /// [`Instruction::sync_entries`].
    SyncWrite {
        /// Start address in every servo's control table.
        addr: u8,
        /// Bytes per servo.
        data_len: u8,
        /// `ID, data…` per servo, concatenated.
        entries: &'a [u8],
    },
    /// BULK_READ: per servo, `length, ID, address` (after the leading
    /// 0x00 parameter); see [`Instruction::bulk_read_entries`].
    BulkRead {
        /// `len, id, addr` per servo, concatenated.
        entries: &'a [u8],
    },
}

impl<'a> Instruction<'a> {
    /// The instruction code.
    pub fn code(&self) -> InstructionCode {
        match self {
            Instruction::Ping => InstructionCode::Ping,
            Instruction::Read { .. } => InstructionCode::Read,
            Instruction::Write { .. } => InstructionCode::Write,
            Instruction::RegWrite { .. } => InstructionCode::RegWrite,
            Instruction::Action => InstructionCode::Action,
            Instruction::Reset => InstructionCode::Reset,
            Instruction::SyncWrite { .. } => InstructionCode::SyncWrite,
            Instruction::BulkRead { .. } => InstructionCode::BulkRead,
        }
    }

    /// The `(id, addr, len)` of each servo a BULK_READ asks, in its order
    /// (empty for other instructions). An ID named twice: only the first
    /// counts (e-Manual, "Bulk Read").
    pub fn bulk_read_entries(&self) -> impl Iterator<Item = (u8, u8, u8)> + 'a {
        let entries: &'a [u8] = match *self {
            Instruction::BulkRead { entries } => entries,
            _ => &[],
        };
        entries
            .chunks_exact(3)
            .enumerate()
            .filter(move |(i, c)| !entries.chunks_exact(3).take(*i).any(|e| e[1] == c[1]))
            .map(|(_, c)| (c[1], c[2], c[0]))
    }

    /// The `(id, data)` pairs of a SYNC_WRITE (empty for other instructions;
    /// a trailing partial entry is not yielded).
    pub fn sync_entries(&self) -> impl Iterator<Item = (u8, &'a [u8])> {
        let (chunk, entries): (usize, &'a [u8]) = match *self {
            Instruction::SyncWrite { data_len, entries, .. } => (data_len as usize + 1, entries),
            _ => (1, &[]),
        };
        entries.chunks_exact(chunk).map(|c| (c[0], &c[1..]))
    }

    /// Encodes the instruction for servo `id` into `out` and returns the
    /// packet (a prefix of `out`).
    pub fn encode<'b>(&self, id: u8, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        let code = self.code() as u8;
        match *self {
            Instruction::Ping | Instruction::Action | Instruction::Reset => write_packet(id, code, &[], out),
            Instruction::Read { addr, len } => write_packet(id, code, &[&[addr, len]], out),
            Instruction::Write { addr, data } | Instruction::RegWrite { addr, data } => {
                if data.is_empty() {
                    return Err(EncodeError::NoData { code });
                }
                write_packet(id, code, &[&[addr], data], out)
            }
            Instruction::SyncWrite { addr, data_len, entries } => {
                let chunk = data_len as usize + 1;
                if data_len == 0 || entries.len() % chunk != 0 {
                    return Err(EncodeError::SyncDataLength {
                        entry: entries.len() / chunk,
                        expected: data_len,
                        got: entries.len() % chunk,
                    });
                }
                write_packet(id, code, &[&[addr, data_len], entries], out)
            }
            Instruction::BulkRead { entries } => {
                if entries.is_empty() || entries.len() % 3 != 0 {
                    return Err(EncodeError::SyncDataLength { entry: entries.len() / 3, expected: 3, got: entries.len() % 3 });
                }
                write_packet(id, code, &[&[0x00], entries], out)
            }
        }
    }

    /// Encodes into a fresh `heapless::Vec` of capacity `N`.
    pub fn encode_vec<const N: usize>(&self, id: u8) -> Result<Vec<u8, N>, EncodeError> {
        let mut buf = [0u8; N];
        let n = self.encode(id, &mut buf)?.len();
        Ok(Vec::from_slice(&buf[..n]).unwrap_or_default())
    }

    /// Parses a decoded instruction packet's code and parameters.
    pub fn parse(code: u8, params: &'a [u8]) -> Result<Self, InstructionError> {
        let code = InstructionCode::from_u8(code).ok_or(InstructionError::UnknownCode { code })?;
        let bad = InstructionError::BadParams { code: code as u8, len: params.len() as u8 };
        Ok(match code {
            InstructionCode::Ping if params.is_empty() => Instruction::Ping,
            InstructionCode::Action if params.is_empty() => Instruction::Action,
            InstructionCode::Reset if params.is_empty() => Instruction::Reset,
            InstructionCode::Read if params.len() == 2 => Instruction::Read { addr: params[0], len: params[1] },
            InstructionCode::Write if params.len() >= 2 => Instruction::Write { addr: params[0], data: &params[1..] },
            InstructionCode::RegWrite if params.len() >= 2 => {
                Instruction::RegWrite { addr: params[0], data: &params[1..] }
            }
            InstructionCode::SyncWrite if params.len() >= 2 => {
                let (addr, data_len, entries) = (params[0], params[1], &params[2..]);
                if data_len == 0 || entries.len() % (data_len as usize + 1) != 0 {
                    return Err(bad);
                }
                Instruction::SyncWrite { addr, data_len, entries }
            }
            InstructionCode::BulkRead if params.len() >= 4 && params[0] == 0x00 && (params.len() - 1) % 3 == 0 => {
                Instruction::BulkRead { entries: &params[1..] }
            }
            _ => return Err(bad),
        })
    }
}

/// Why a well-formed instruction packet is not a valid instruction (the bus
/// emulator answers these with the INSTRUCTION or RANGE error bit).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InstructionError {
    /// An instruction code this codec does not know.
    UnknownCode {
        /// The code byte.
        code: u8,
    },
    /// Parameters that do not fit the instruction.
    BadParams {
        /// The code byte.
        code: u8,
        /// Number of parameter bytes.
        len: u8,
    },
}

/// Encodes a PING for servo `id`.
pub fn ping(id: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Ping.encode(id, out)
}

/// Encodes a READ_DATA of `len` bytes at `addr` of servo `id`.
pub fn read_data(id: u8, addr: u8, len: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Read { addr, len }.encode(id, out)
}

/// Encodes a WRITE_DATA of `data` at `addr` of servo `id`.
pub fn write_data<'b>(id: u8, addr: u8, data: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::Write { addr, data }.encode(id, out)
}

/// Encodes a REG_WRITE of `data` at `addr` of servo `id`.
pub fn reg_write<'b>(id: u8, addr: u8, data: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::RegWrite { addr, data }.encode(id, out)
}

/// Encodes an ACTION (usually to [`BROADCAST_ID`]).
pub fn action(id: u8, out: &mut [u8]) -> Result<&[u8], EncodeError> {
    Instruction::Action.encode(id, out)
}

/// Encodes a SYNC_WRITE (to [`BROADCAST_ID`]) of `data_len` bytes at `addr`
/// for each `(id, data)` entry; every `data` must be `data_len` long.
pub fn sync_write<'b>(
    addr: u8,
    data_len: u8,
    entries: &[(u8, &[u8])],
    out: &'b mut [u8],
) -> Result<&'b [u8], EncodeError> {
    if data_len == 0 {
        return Err(EncodeError::SyncDataLength { entry: 0, expected: 0, got: 0 });
    }
    let mut params = 2usize;
    for (i, (_, data)) in entries.iter().enumerate() {
        if data.len() != data_len as usize {
            return Err(EncodeError::SyncDataLength { entry: i, expected: data_len, got: data.len() });
        }
        params += 1 + data.len();
    }
    let total = sync_write_header(addr, data_len, params, out)?;
    let mut i = 7;
    for (id, data) in entries {
        out[i] = *id;
        out[i + 1..i + 1 + data.len()].copy_from_slice(data);
        i += 1 + data.len();
    }
    out[i] = checksum(&out[2..i]);
    Ok(&out[..total])
}

/// Checks that a SYNC_WRITE of `params` parameter bytes fits a packet and
/// `out`, and writes its first 7 bytes (header, broadcast ID, length,
/// instruction, `addr`, `data_len`); returns the packet's whole length.
fn sync_write_header(addr: u8, data_len: u8, params: usize, out: &mut [u8]) -> Result<usize, EncodeError> {
    if params > MAX_PARAMS {
        return Err(EncodeError::TooManyParams { params });
    }
    let total = params + OVERHEAD;
    if out.len() < total {
        return Err(EncodeError::BufferTooSmall { needed: total, available: out.len() });
    }
    out[..7].copy_from_slice(&[0xFF, 0xFF, BROADCAST_ID, (params + 2) as u8, InstructionCode::SyncWrite as u8, addr, data_len]);
    Ok(total)
}

/// Encodes a SYNC_WRITE of one little-endian 16-bit value per servo at
/// `addr` (the usual case: Moving Speed of every joint in one packet).
pub fn sync_write_u16<'b>(addr: u8, entries: &[(u8, u16)], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    let total = sync_write_header(addr, 2, 2 + 3 * entries.len(), out)?;
    let mut i = 7;
    for &(id, value) in entries {
        out[i] = id;
        out[i + 1..i + 3].copy_from_slice(&value.to_le_bytes());
        i += 3;
    }
    out[i] = checksum(&out[2..i]);
    Ok(&out[..total])
}

/// A status packet (the servo's answer), owning up to `N` parameter bytes:
/// the two protocols' [`super::status_packet::StatusPacket`] with Protocol
/// 1.0's error byte.
pub type StatusPacket<const N: usize = DEFAULT_PACKET_LEN> = super::status_packet::StatusPacket<ErrorFlags, N>;

impl<const N: usize> StatusPacket<N> {
    /// A status packet with `params` (which must fit `N`).
    pub fn new(id: u8, error: ErrorFlags, params: &[u8]) -> Result<Self, EncodeError> {
        let params = Vec::from_slice(params).map_err(|_| EncodeError::TooManyParams { params: params.len() })?;
        Ok(StatusPacket { id, error, params })
    }

    /// Encodes the packet (bus-emulator side) into `out`.
    pub fn encode<'b>(&self, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        if self.id == BROADCAST_ID {
            return Err(EncodeError::InvalidId { id: self.id });
        }
        write_packet(self.id, self.error.0, &[&self.params], out)
    }
}

/// An instruction packet as decoded by the bus emulator, owning up to `N`
/// parameter bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstructionPacket<const N: usize = DEFAULT_PACKET_LEN> {
    /// The addressed servo (or [`BROADCAST_ID`]).
    pub id: u8,
    /// The instruction code byte.
    pub code: u8,
    /// The parameters.
    pub params: Vec<u8, N>,
}

impl<const N: usize> InstructionPacket<N> {
    /// The instruction, borrowing this packet's parameters.
    pub fn instruction(&self) -> Result<Instruction<'_>, InstructionError> {
        Instruction::parse(self.code, &self.params)
    }

    /// Encodes the packet as it was received (ID, code and parameters as
    /// they are, valid instruction or not) into `out`.
    pub fn encode<'b>(&self, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        write_packet(self.id, self.code, &[&self.params], out)
    }
}


#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamixel::table::*;
    use crate::dynamixel::{ping, read_data, sync_write, sync_write_u16, write_data};

    #[test]
    fn ping_matches_the_manual_example() {
        // e-Manual example: PING to ID 1 is FF FF 01 02 01 FB.
        let mut buf = [0u8; 8];
        assert_eq!(ping(1, &mut buf).unwrap(), &[0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB]);
    }

    #[test]
    fn read_and_write_encode() {
        let mut buf = [0u8; 16];
        // READ of Present Temperature (1 byte) of ID 1: FF FF 01 04 02 2B 01 CC.
        assert_eq!(read_data(1, PRESENT_TEMPERATURE, 1, &mut buf).unwrap(), &[0xFF, 0xFF, 1, 4, 2, 0x2B, 1, 0xCC]);
        let p = write_data(1, TORQUE_ENABLE, &[1], &mut buf).unwrap();
        assert_eq!(p, &[0xFF, 0xFF, 1, 4, 3, 24, 1, checksum(&[1, 4, 3, 24, 1])]);
    }

    #[test]
    fn buffer_too_small_is_an_error() {
        let mut buf = [0u8; 5];
        assert_eq!(ping(1, &mut buf), Err(EncodeError::BufferTooSmall { needed: 6, available: 5 }));
        assert_eq!(ping(0xFF, &mut [0u8; 8]), Err(EncodeError::InvalidId { id: 0xFF }));
        let big = [0u8; 300];
        assert!(matches!(write_data(1, 0, &big, &mut [0u8; 400]), Err(EncodeError::TooManyParams { .. })));
    }

    #[test]
    fn sync_write_u16_matches_generic() {
        let mut a = [0u8; 32];
        let mut b = [0u8; 32];
        let x = sync_write_u16(MOVING_SPEED, &[(1, 0x0123), (2, 0x0456)], &mut a).unwrap();
        let y = sync_write(MOVING_SPEED, 2, &[(1, &[0x23, 0x01]), (2, &[0x56, 0x04])], &mut b).unwrap();
        assert_eq!(x, y);
        assert_eq!(x[2], BROADCAST_ID);
        assert_eq!(x[4], 0x83);
        assert!(matches!(
            sync_write(MOVING_SPEED, 2, &[(1, &[1])], &mut b),
            Err(EncodeError::SyncDataLength { entry: 0, expected: 2, got: 1 })
        ));
    }

    #[test]
    fn error_flags_names() {
        let f = ErrorFlags::OVERLOAD | ErrorFlags::INPUT_VOLTAGE;
        let names: heapless::Vec<&str, 8> = f.names().collect();
        assert_eq!(&names[..], &["input voltage", "overload"]);
        assert!(f.intersects(ErrorFlags::HARDWARE));
        assert!(!ErrorFlags::RANGE.intersects(ErrorFlags::HARDWARE));
        assert!(ErrorFlags::ALL.contains(f));
    }
}
