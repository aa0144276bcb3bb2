//! Dynamixel Protocol 1.0 codec and the RX-28 control table.
//!
//! Pure codec: packets are encoded into caller buffers and decoded from bytes
//! fed one at a time or in chunks; the firmware does the IO (RS-485 half
//! duplex, driver-enable pin, timeouts and retries).
//!
//! Both directions are here, because the host's software-in-the-loop run
//! emulates RX-28 servos (issue 6): the firmware encodes instruction packets
//! and decodes status packets ([`StatusDecoder`]); the bus emulator decodes
//! instruction packets ([`InstructionDecoder`]) and encodes status packets
//! ([`StatusPacket::encode`]).
//!
//! # Packet format (Robotis e-Manual, "DYNAMIXEL Protocol 1.0")
//!
//! ```text
//! instruction: 0xFF 0xFF ID LENGTH INSTRUCTION PARAM_1 … PARAM_N CHECKSUM
//! status:      0xFF 0xFF ID LENGTH ERROR       PARAM_1 … PARAM_N CHECKSUM
//! LENGTH   = N + 2
//! CHECKSUM = !(ID + LENGTH + INSTRUCTION/ERROR + PARAM_1 + … + PARAM_N) (low byte)
//! ```
//!
//! ID 0xFE is the broadcast ID (no servo answers); 0xFF is never an ID, which
//! is what lets a receiver resynchronise on `0xFF 0xFF`. Two-byte values are
//! little endian (low byte at the lower address).
//!
//! # Decoding never panics
//!
//! The decoders keep the bytes of the packet being received in a fixed
//! buffer of `N` bytes. On a bad checksum or an impossible length they report
//! a typed [`DecodeError`], drop only the first header byte and scan the rest
//! again, so a packet that a corrupted one swallowed is still found. Every
//! input sequence is handled without a panic (property-tested).

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
}

/// Why bytes received did not form a packet. The decoder has already
/// resynchronised when it reports one of these.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// The checksum byte does not match the packet's contents.
    BadChecksum {
        /// ID byte of the corrupted packet (itself possibly corrupted).
        id: u8,
        /// Checksum computed over the received bytes.
        expected: u8,
        /// Checksum byte received.
        got: u8,
    },
    /// LENGTH below 2, or a packet longer than the decoder's buffer.
    BadLength {
        /// ID byte of the packet.
        id: u8,
        /// The LENGTH byte received.
        length: u8,
    },
    /// A valid status packet, but not from the servo that was asked.
    UnexpectedId {
        /// The ID that was asked.
        expected: u8,
        /// The ID that answered.
        got: u8,
    },
}

/// The checksum of Protocol 1.0 over `ID, LENGTH, INSTRUCTION/ERROR, params`.
pub fn checksum(bytes: &[u8]) -> u8 {
    !bytes.iter().fold(0u8, |s, &b| s.wrapping_add(b))
}

/// Writes one packet into `out`, returning the written prefix.
fn write_packet<'b>(id: u8, code: u8, parts: &[&[u8]], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
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
        }
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
    if params > MAX_PARAMS {
        return Err(EncodeError::TooManyParams { params });
    }
    let total = params + OVERHEAD;
    if out.len() < total {
        return Err(EncodeError::BufferTooSmall { needed: total, available: out.len() });
    }
    out[0] = 0xFF;
    out[1] = 0xFF;
    out[2] = BROADCAST_ID;
    out[3] = (params + 2) as u8;
    out[4] = InstructionCode::SyncWrite as u8;
    out[5] = addr;
    out[6] = data_len;
    let mut i = 7;
    for (id, data) in entries {
        out[i] = *id;
        out[i + 1..i + 1 + data.len()].copy_from_slice(data);
        i += 1 + data.len();
    }
    out[i] = checksum(&out[2..i]);
    Ok(&out[..total])
}

/// Encodes a SYNC_WRITE of one little-endian 16-bit value per servo at
/// `addr` (the usual case: Moving Speed of every joint in one packet).
pub fn sync_write_u16<'b>(addr: u8, entries: &[(u8, u16)], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    let params = 2 + 3 * entries.len();
    if params > MAX_PARAMS {
        return Err(EncodeError::TooManyParams { params });
    }
    let total = params + OVERHEAD;
    if out.len() < total {
        return Err(EncodeError::BufferTooSmall { needed: total, available: out.len() });
    }
    out[0] = 0xFF;
    out[1] = 0xFF;
    out[2] = BROADCAST_ID;
    out[3] = (params + 2) as u8;
    out[4] = InstructionCode::SyncWrite as u8;
    out[5] = addr;
    out[6] = 2;
    let mut i = 7;
    for &(id, value) in entries {
        out[i] = id;
        out[i + 1..i + 3].copy_from_slice(&value.to_le_bytes());
        i += 3;
    }
    out[i] = checksum(&out[2..i]);
    Ok(&out[..total])
}

/// A status packet (the servo's answer), owning up to `N` parameter bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StatusPacket<const N: usize = DEFAULT_PACKET_LEN> {
    /// The answering servo.
    pub id: u8,
    /// The error bits.
    pub error: ErrorFlags,
    /// The data read (empty for answers to PING and WRITE).
    pub params: Vec<u8, N>,
}

impl<const N: usize> StatusPacket<N> {
    /// A status packet with `params` (which must fit `N`).
    pub fn new(id: u8, error: ErrorFlags, params: &[u8]) -> Result<Self, EncodeError> {
        let params = Vec::from_slice(params).map_err(|_| EncodeError::TooManyParams { params: params.len() })?;
        Ok(StatusPacket { id, error, params })
    }

    /// Parameter byte `i`.
    pub fn u8_at(&self, i: usize) -> Option<u8> {
        self.params.get(i).copied()
    }

    /// Little-endian 16-bit value at parameter bytes `i, i+1`.
    pub fn u16_at(&self, i: usize) -> Option<u16> {
        Some(u16::from_le_bytes([*self.params.get(i)?, *self.params.get(i + 1)?]))
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
}

/// Decoder counters, for health telemetry.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Packets decoded.
    pub packets: u32,
    /// Bytes dropped while looking for a header.
    pub skipped_bytes: u32,
    /// Packets with a wrong checksum.
    pub bad_checksums: u32,
    /// Packets with an impossible LENGTH.
    pub bad_lengths: u32,
    /// Valid status packets from an unexpected ID.
    pub unexpected_ids: u32,
}

/// A raw packet found in the byte stream.
struct Raw<const N: usize> {
    id: u8,
    byte4: u8,
    params: Vec<u8, N>,
}

/// The byte-level framing shared by both decoders: a buffer holding the
/// packet being received, which always starts at a candidate header.
#[derive(Debug, Clone)]
struct Framer<const N: usize> {
    buf: [u8; N],
    len: usize,
    stats: DecoderStats,
}

impl<const N: usize> Framer<N> {
    const fn new() -> Self {
        Framer { buf: [0; N], len: 0, stats: DecoderStats {
            packets: 0,
            skipped_bytes: 0,
            bad_checksums: 0,
            bad_lengths: 0,
            unexpected_ids: 0,
        } }
    }

    fn reset(&mut self) {
        self.stats.skipped_bytes = self.stats.skipped_bytes.saturating_add(self.len as u32);
        self.len = 0;
    }

    fn drop_front(&mut self, n: usize) {
        let n = n.min(self.len);
        self.buf.copy_within(n..self.len, 0);
        self.len -= n;
    }

    fn skip(&mut self, n: usize) {
        self.stats.skipped_bytes = self.stats.skipped_bytes.saturating_add(n.min(self.len) as u32);
        self.drop_front(n);
    }

    /// Appends a byte; if the buffer is somehow full, the oldest is dropped.
    fn push(&mut self, byte: u8) {
        if self.len >= N {
            self.skip(1);
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        }
    }

    /// Looks for one complete packet or error in the buffered bytes.
    fn poll(&mut self) -> Option<Result<Raw<N>, DecodeError>> {
        loop {
            // Find `0xFF 0xFF` at the front.
            let start = (0..self.len).find(|&i| self.buf[i] == 0xFF).unwrap_or(self.len);
            self.skip(start);
            if self.len < 2 {
                return None;
            }
            if self.buf[1] != 0xFF {
                self.skip(1);
                continue;
            }
            if self.len < 3 {
                return None;
            }
            if self.buf[2] == 0xFF {
                // 0xFF 0xFF 0xFF: the header starts one byte later.
                self.skip(1);
                continue;
            }
            if self.len < 4 {
                return None;
            }
            let (id, length) = (self.buf[2], self.buf[3]);
            let total = length as usize + 4;
            if length < 2 || total > N {
                self.stats.bad_lengths = self.stats.bad_lengths.saturating_add(1);
                self.skip(1);
                return Some(Err(DecodeError::BadLength { id, length }));
            }
            if self.len < total {
                return None;
            }
            let expected = checksum(&self.buf[2..total - 1]);
            let got = self.buf[total - 1];
            if expected != got {
                self.stats.bad_checksums = self.stats.bad_checksums.saturating_add(1);
                self.skip(1);
                return Some(Err(DecodeError::BadChecksum { id, expected, got }));
            }
            let params = Vec::from_slice(&self.buf[5..total - 1]).unwrap_or_default();
            let raw = Raw { id, byte4: self.buf[4], params };
            self.drop_front(total);
            return Some(Ok(raw));
        }
    }
}

/// Incremental decoder of status packets (firmware side).
///
/// Feed it bytes with [`push`](Self::push) or [`feed`](Self::feed); set the
/// servo being asked with [`expect`](Self::expect) so that answers from
/// another ID are reported as [`DecodeError::UnexpectedId`]. `N` is the
/// longest packet accepted, header and checksum included.
#[derive(Debug, Clone)]
pub struct StatusDecoder<const N: usize = DEFAULT_PACKET_LEN> {
    framer: Framer<N>,
    expected: Option<u8>,
}

impl<const N: usize> Default for StatusDecoder<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> StatusDecoder<N> {
    /// A decoder that accepts any ID.
    pub const fn new() -> Self {
        StatusDecoder { framer: Framer::new(), expected: None }
    }

    /// Only accept answers from `id` (`None`: any).
    pub fn expect(&mut self, id: Option<u8>) {
        self.expected = id;
    }

    /// Drops any partial packet (e.g. after a timeout, before the next
    /// request); the dropped bytes count as skipped.
    pub fn reset(&mut self) {
        self.framer.reset();
    }

    /// Counters since creation.
    pub fn stats(&self) -> DecoderStats {
        self.framer.stats
    }

    /// Takes one byte; returns a packet or an error if this byte completed
    /// one. After `Some`, call [`poll`](Self::poll) until `None`: the bytes
    /// kept after an error may already hold the next packet.
    pub fn push(&mut self, byte: u8) -> Option<Result<StatusPacket<N>, DecodeError>> {
        self.framer.push(byte);
        self.poll()
    }

    /// Looks for a packet or error in the bytes already buffered.
    pub fn poll(&mut self) -> Option<Result<StatusPacket<N>, DecodeError>> {
        let raw = match self.framer.poll()? {
            Ok(raw) => raw,
            Err(e) => return Some(Err(e)),
        };
        if let Some(expected) = self.expected {
            if raw.id != expected {
                self.framer.stats.unexpected_ids = self.framer.stats.unexpected_ids.saturating_add(1);
                return Some(Err(DecodeError::UnexpectedId { expected, got: raw.id }));
            }
        }
        self.framer.stats.packets = self.framer.stats.packets.saturating_add(1);
        Some(Ok(StatusPacket { id: raw.id, error: ErrorFlags(raw.byte4), params: raw.params }))
    }

    /// Feeds a chunk and iterates over every packet and error in it.
    pub fn feed<'s, 'b>(&'s mut self, bytes: &'b [u8]) -> Feed<'s, 'b, StatusDecoder<N>> {
        Feed { decoder: self, rest: bytes }
    }
}

/// Incremental decoder of instruction packets (bus-emulator side); the same
/// framing and resynchronisation as [`StatusDecoder`].
#[derive(Debug, Clone)]
pub struct InstructionDecoder<const N: usize = DEFAULT_PACKET_LEN> {
    framer: Framer<N>,
}

impl<const N: usize> Default for InstructionDecoder<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> InstructionDecoder<N> {
    /// A new decoder.
    pub const fn new() -> Self {
        InstructionDecoder { framer: Framer::new() }
    }

    /// Drops any partial packet.
    pub fn reset(&mut self) {
        self.framer.reset();
    }

    /// Counters since creation.
    pub fn stats(&self) -> DecoderStats {
        self.framer.stats
    }

    /// Takes one byte; see [`StatusDecoder::push`].
    pub fn push(&mut self, byte: u8) -> Option<Result<InstructionPacket<N>, DecodeError>> {
        self.framer.push(byte);
        self.poll()
    }

    /// Looks for a packet or error in the bytes already buffered.
    pub fn poll(&mut self) -> Option<Result<InstructionPacket<N>, DecodeError>> {
        let r = self.framer.poll()?;
        Some(r.map(|raw| {
            self.framer.stats.packets = self.framer.stats.packets.saturating_add(1);
            InstructionPacket { id: raw.id, code: raw.byte4, params: raw.params }
        }))
    }

    /// Feeds a chunk and iterates over every packet and error in it.
    pub fn feed<'s, 'b>(&'s mut self, bytes: &'b [u8]) -> Feed<'s, 'b, InstructionDecoder<N>> {
        Feed { decoder: self, rest: bytes }
    }
}

/// The two decoders, for [`Feed`].
pub trait PacketDecoder {
    /// What a decoded packet is.
    type Packet;
    /// Takes one byte.
    fn push_byte(&mut self, byte: u8) -> Option<Result<Self::Packet, DecodeError>>;
    /// Looks at buffered bytes.
    fn poll_buffered(&mut self) -> Option<Result<Self::Packet, DecodeError>>;
}

impl<const N: usize> PacketDecoder for StatusDecoder<N> {
    type Packet = StatusPacket<N>;
    fn push_byte(&mut self, byte: u8) -> Option<Result<Self::Packet, DecodeError>> {
        self.push(byte)
    }
    fn poll_buffered(&mut self) -> Option<Result<Self::Packet, DecodeError>> {
        self.poll()
    }
}

impl<const N: usize> PacketDecoder for InstructionDecoder<N> {
    type Packet = InstructionPacket<N>;
    fn push_byte(&mut self, byte: u8) -> Option<Result<Self::Packet, DecodeError>> {
        self.push(byte)
    }
    fn poll_buffered(&mut self) -> Option<Result<Self::Packet, DecodeError>> {
        self.poll()
    }
}

/// Iterator over the packets and errors of a chunk fed to a decoder. Bytes
/// of an incomplete packet at the end stay in the decoder for the next chunk.
pub struct Feed<'s, 'b, D> {
    decoder: &'s mut D,
    rest: &'b [u8],
}

impl<D: PacketDecoder> Iterator for Feed<'_, '_, D> {
    type Item = Result<D::Packet, DecodeError>;
    fn next(&mut self) -> Option<Self::Item> {
        if let Some(r) = self.decoder.poll_buffered() {
            return Some(r);
        }
        while let Some((&b, rest)) = self.rest.split_first() {
            self.rest = rest;
            if let Some(r) = self.decoder.push_byte(b) {
                return Some(r);
            }
        }
        None
    }
}

/// The RX-28 control table: addresses and value encodings.
///
/// Source: Robotis e-Manual, "RX-28", section "Control Table" (EEPROM area
/// 0–23, RAM area 24–49). Two-byte items are little endian, at the address
/// given and the next.
pub mod table {
    /// Model Number (2 bytes, R); the RX-28 reads 28.
    pub const MODEL_NUMBER: u8 = 0;
    /// Firmware Version (1, R).
    pub const FIRMWARE_VERSION: u8 = 2;
    /// ID (1, RW, EEPROM): 0–253.
    pub const ID: u8 = 3;
    /// Baud Rate (1, RW, EEPROM): bps = 2 000 000 / (value + 1); see [`baud_rate_bps`].
    pub const BAUD_RATE: u8 = 4;
    /// Return Delay Time (1, RW, EEPROM): 2 µs per unit.
    pub const RETURN_DELAY_TIME: u8 = 5;
    /// CW Angle Limit (2, RW, EEPROM): 0–1023. Both limits 0 = wheel mode.
    pub const CW_ANGLE_LIMIT: u8 = 6;
    /// CCW Angle Limit (2, RW, EEPROM): 0–1023. Both limits 0 = wheel mode.
    pub const CCW_ANGLE_LIMIT: u8 = 8;
    /// Highest Limit Temperature (1, RW, EEPROM), °C.
    pub const HIGHEST_LIMIT_TEMPERATURE: u8 = 11;
    /// Lowest Limit Voltage (1, RW, EEPROM), 0.1 V.
    pub const LOWEST_LIMIT_VOLTAGE: u8 = 12;
    /// Highest Limit Voltage (1, RW, EEPROM), 0.1 V.
    pub const HIGHEST_LIMIT_VOLTAGE: u8 = 13;
    /// Max Torque (2, RW, EEPROM): 0–1023 of the maximum.
    pub const MAX_TORQUE: u8 = 14;
    /// Status Return Level (1, RW, EEPROM): 0 PING only, 1 READ too, 2 all.
    pub const STATUS_RETURN_LEVEL: u8 = 16;
    /// Alarm LED (1, RW, EEPROM): error bits that light the LED.
    pub const ALARM_LED: u8 = 17;
    /// Alarm Shutdown (1, RW, EEPROM): error bits that switch torque off.
    pub const ALARM_SHUTDOWN: u8 = 18;
    /// Torque Enable (1, RW, RAM): 0 off, 1 on.
    pub const TORQUE_ENABLE: u8 = 24;
    /// LED (1, RW, RAM).
    pub const LED: u8 = 25;
    /// CW Compliance Margin (1, RW, RAM).
    pub const CW_COMPLIANCE_MARGIN: u8 = 26;
    /// CCW Compliance Margin (1, RW, RAM).
    pub const CCW_COMPLIANCE_MARGIN: u8 = 27;
    /// CW Compliance Slope (1, RW, RAM).
    pub const CW_COMPLIANCE_SLOPE: u8 = 28;
    /// CCW Compliance Slope (1, RW, RAM).
    pub const CCW_COMPLIANCE_SLOPE: u8 = 29;
    /// Goal Position (2, RW, RAM): 0–1023 over 0–300°.
    pub const GOAL_POSITION: u8 = 30;
    /// Moving Speed (2, RW, RAM). Wheel mode: 0–1023 CCW, 1024–2047 CW, as
    /// a ratio of the output (bit 10 = direction); see [`moving_speed_from_ratio`].
    pub const MOVING_SPEED: u8 = 32;
    /// Torque Limit (2, RW, RAM): 0–1023.
    pub const TORQUE_LIMIT: u8 = 34;
    /// Present Position (2, R, RAM): 0–1023 over 0–300°.
    pub const PRESENT_POSITION: u8 = 36;
    /// Present Speed (2, R, RAM): 0–1023 CCW, 1024–2047 CW (bit 10 = direction).
    pub const PRESENT_SPEED: u8 = 38;
    /// Present Load (2, R, RAM): 0–1023 CCW, 1024–2047 CW (bit 10 = direction).
    pub const PRESENT_LOAD: u8 = 40;
    /// Present Voltage (1, R, RAM): 0.1 V units.
    pub const PRESENT_VOLTAGE: u8 = 42;
    /// Present Temperature (1, R, RAM): °C.
    pub const PRESENT_TEMPERATURE: u8 = 43;
    /// Registered (1, R, RAM): a REG_WRITE is pending.
    pub const REGISTERED: u8 = 44;
    /// Moving (1, R, RAM).
    pub const MOVING: u8 = 46;
    /// Lock (1, RW, RAM): locks the EEPROM area.
    pub const LOCK: u8 = 47;
    /// Punch (2, RW, RAM).
    pub const PUNCH: u8 = 48;
    /// Size of the control table in bytes (addresses 0–49).
    pub const TABLE_LEN: usize = 50;

    /// Present Position through Present Temperature: the block one READ
    /// returns per control period (position, speed, load, voltage, temperature).
    pub const PRESENT_BLOCK: u8 = PRESENT_POSITION;
    /// Length of [`PRESENT_BLOCK`].
    pub const PRESENT_BLOCK_LEN: u8 = 8;

    /// The RX-28's model number.
    pub const RX28_MODEL: u16 = 28;
    /// Baud Rate value for 1 Mbps.
    pub const BAUD_1MBPS: u8 = 1;
    /// Position units over the 0–300° range: 0–1023.
    pub const POSITION_MAX: u16 = 1023;
    /// The angle Present Position 1023 stands for: 300°, in radians.
    pub const POSITION_RANGE_RAD: f32 = 300.0 * core::f32::consts::PI / 180.0;
    /// Magnitude units of the 11-bit speed and load encodings: 0–1023.
    pub const MAGNITUDE_MAX: u16 = 1023;
    /// Direction bit of Moving Speed (wheel mode), Present Speed and Present
    /// Load: set = clockwise.
    pub const DIRECTION_BIT: u16 = 1 << 10;
    /// Present Speed unit in joint mode: about 0.111 rpm.
    pub const SPEED_UNIT_RPM: f32 = 0.111;

    /// The bit rate of a Baud Rate value: 2 000 000 / (value + 1) bps.
    pub const fn baud_rate_bps(value: u8) -> u32 {
        2_000_000 / (value as u32 + 1)
    }

    /// Wheel-mode Moving Speed for a signed output ratio in −1..1: positive is
    /// counter-clockwise (0–1023), negative clockwise (1024 + magnitude).
    /// Values outside −1..1 saturate; NaN gives 0 (stop).
    pub fn moving_speed_from_ratio(ratio: f32) -> u16 {
        encode_signed(ratio)
    }

    /// The signed ratio a Moving Speed value commands (the inverse of
    /// [`moving_speed_from_ratio`], for the bus emulator).
    pub fn ratio_from_moving_speed(value: u16) -> f32 {
        decode_signed(value)
    }

    /// Present Speed as a signed ratio of the maximum, −1..1 (CCW positive).
    pub fn present_speed_ratio(value: u16) -> f32 {
        decode_signed(value)
    }

    /// Present Speed in rpm (joint-mode unit), CCW positive.
    pub fn present_speed_rpm(value: u16) -> f32 {
        decode_magnitude(value) * SPEED_UNIT_RPM
    }

    /// Present Load as a signed ratio of the maximum torque, −1..1 (CCW
    /// positive).
    pub fn present_load_ratio(value: u16) -> f32 {
        decode_signed(value)
    }

    /// The 11-bit direction/magnitude encoding of a signed ratio (Present
    /// Speed and Present Load too, for the bus emulator).
    pub fn encode_signed(ratio: f32) -> u16 {
        if ratio.is_nan() {
            return 0;
        }
        let r = ratio.clamp(-1.0, 1.0);
        let m = libm::roundf(libm::fabsf(r) * MAGNITUDE_MAX as f32) as u16;
        let m = m.min(MAGNITUDE_MAX);
        if r < 0.0 && m > 0 {
            DIRECTION_BIT | m
        } else {
            m
        }
    }

    fn decode_magnitude(value: u16) -> f32 {
        let m = (value & 0x3FF) as f32;
        if value & DIRECTION_BIT != 0 {
            -m
        } else {
            m
        }
    }

    fn decode_signed(value: u16) -> f32 {
        decode_magnitude(value) / MAGNITUDE_MAX as f32
    }

    /// Present/Goal Position in radians, 0 at position 0 and 300° at 1023
    /// (values above 1023 saturate).
    pub fn position_rad(value: u16) -> f32 {
        value.min(POSITION_MAX) as f32 * (POSITION_RANGE_RAD / POSITION_MAX as f32)
    }

    /// Position in radians relative to the centre (512 = 150°), the
    /// natural zero of a joint.
    pub fn position_rad_centered(value: u16) -> f32 {
        position_rad(value) - position_rad(512)
    }

    /// The position value for an angle in radians from position 0, rounded
    /// and saturated to 0–1023 (NaN gives 0); for the bus emulator.
    pub fn position_from_rad(rad: f32) -> u16 {
        if rad.is_nan() {
            return 0;
        }
        let v = libm::roundf(rad * (POSITION_MAX as f32 / POSITION_RANGE_RAD));
        v.clamp(0.0, POSITION_MAX as f32) as u16
    }

    /// Present Voltage in volts (0.1 V units).
    pub fn voltage_v(value: u8) -> f32 {
        value as f32 * 0.1
    }

    /// Present Temperature in °C.
    pub fn temperature_c(value: u8) -> f32 {
        value as f32
    }

    /// The decoded [`PRESENT_BLOCK`] of one servo.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    pub struct PresentState {
        /// Present Position (raw 0–1023).
        pub position: u16,
        /// Present Speed (raw, bit 10 = CW).
        pub speed: u16,
        /// Present Load (raw, bit 10 = CW).
        pub load: u16,
        /// Present Voltage (0.1 V).
        pub voltage: u8,
        /// Present Temperature (°C).
        pub temperature: u8,
    }

    impl PresentState {
        /// Parses the 8 bytes of a READ of [`PRESENT_BLOCK`]; `None` if
        /// `bytes` is shorter.
        pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
            let b: &[u8; 8] = bytes.get(..8)?.try_into().ok()?;
            Some(PresentState {
                position: u16::from_le_bytes([b[0], b[1]]),
                speed: u16::from_le_bytes([b[2], b[3]]),
                load: u16::from_le_bytes([b[4], b[5]]),
                voltage: b[6],
                temperature: b[7],
            })
        }

        /// The 8 bytes of the block (bus-emulator side).
        pub fn to_bytes(&self) -> [u8; 8] {
            let [p0, p1] = self.position.to_le_bytes();
            let [s0, s1] = self.speed.to_le_bytes();
            let [l0, l1] = self.load.to_le_bytes();
            [p0, p1, s0, s1, l0, l1, self.voltage, self.temperature]
        }

        /// Position in radians from position 0.
        pub fn position_rad(&self) -> f32 {
            position_rad(self.position)
        }
        /// Speed as a signed ratio.
        pub fn speed_ratio(&self) -> f32 {
            present_speed_ratio(self.speed)
        }
        /// Load as a signed ratio.
        pub fn load_ratio(&self) -> f32 {
            present_load_ratio(self.load)
        }
        /// Supply voltage in volts.
        pub fn voltage_v(&self) -> f32 {
            voltage_v(self.voltage)
        }
        /// Temperature in °C.
        pub fn temperature_c(&self) -> f32 {
            temperature_c(self.temperature)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::table::*;
    use super::*;

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
    fn status_round_trip_and_wrong_id() {
        let mut buf = [0u8; 32];
        let st = StatusPacket::<64>::new(3, ErrorFlags::OVERHEATING, &[0x10, 0x02]).unwrap();
        let bytes = st.encode(&mut buf).unwrap();
        let mut dec = StatusDecoder::<64>::new();
        dec.expect(Some(3));
        let got: heapless::Vec<_, 4> = dec.feed(bytes).collect();
        assert_eq!(got.len(), 1);
        let p = got[0].clone().unwrap();
        assert_eq!(p, st);
        assert_eq!(p.u16_at(0), Some(0x0210));
        dec.expect(Some(4));
        let got: heapless::Vec<_, 4> = dec.feed(bytes).collect();
        assert_eq!(got[0], Err(DecodeError::UnexpectedId { expected: 4, got: 3 }));
        assert_eq!(dec.stats().unexpected_ids, 1);
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

    #[test]
    fn moving_speed_encoding() {
        assert_eq!(moving_speed_from_ratio(0.0), 0);
        assert_eq!(moving_speed_from_ratio(1.0), 1023);
        assert_eq!(moving_speed_from_ratio(-1.0), 2047);
        assert_eq!(moving_speed_from_ratio(2.0), 1023);
        assert_eq!(moving_speed_from_ratio(-7.0), 2047);
        assert_eq!(moving_speed_from_ratio(f32::NAN), 0);
        assert_eq!(moving_speed_from_ratio(0.5), 512);
        assert_eq!(moving_speed_from_ratio(-0.5), 1024 + 512);
        assert_eq!(moving_speed_from_ratio(-0.0001), 0, "no negative zero");
        for v in 0..2048u16 {
            if v == 1024 {
                continue; // "CW, magnitude 0" encodes as plain 0
            }
            assert_eq!(moving_speed_from_ratio(ratio_from_moving_speed(v)), v);
        }
    }

    #[test]
    fn feedback_decoding() {
        assert_eq!(present_load_ratio(1023), 1.0);
        assert_eq!(present_load_ratio(2047), -1.0);
        assert_eq!(present_speed_ratio(1024), -0.0);
        assert!((present_speed_rpm(100) - 11.1).abs() < 1e-4);
        assert!((present_speed_rpm(1124) + 11.1).abs() < 1e-4);
        assert_eq!(position_rad(0), 0.0);
        assert!((position_rad(1023) - 300f32.to_radians()).abs() < 1e-6);
        assert!((position_rad(1) - 0.005_118_268).abs() < 1e-7);
        assert!(position_rad_centered(512).abs() < 1e-7);
        assert_eq!(position_rad(5000), position_rad(1023));
        for v in 0..=1023u16 {
            assert_eq!(position_from_rad(position_rad(v)), v);
        }
        assert!((voltage_v(148) - 14.8).abs() < 1e-5);
        assert_eq!(temperature_c(45), 45.0);
        assert_eq!(baud_rate_bps(BAUD_1MBPS), 1_000_000);
        assert_eq!(baud_rate_bps(34), 57_142);
    }

    #[test]
    fn present_block_round_trip() {
        let s = PresentState { position: 700, speed: 1024 + 30, load: 200, voltage: 148, temperature: 41 };
        assert_eq!(PresentState::from_bytes(&s.to_bytes()), Some(s));
        assert_eq!(PresentState::from_bytes(&[0; 7]), None);
        assert_eq!(PRESENT_BLOCK_LEN as usize, s.to_bytes().len());
        assert_eq!(PRESENT_TEMPERATURE - PRESENT_POSITION + 1, PRESENT_BLOCK_LEN);
    }
}
