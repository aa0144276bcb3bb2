//! Feetech's instruction table: Dynamixel Protocol 1.0's, with SYNC READ
//! and without BULK READ (docs/reference/feetech.md § "Instructions").
//!
//! | code | instruction | parameters | reply | parsed and encoded by |
//! |---|---|---|---|---|
//! | 0x01 | PING | – | status, no parameters | Protocol 1.0 |
//! | 0x02 | READ | address, length | the data | Protocol 1.0 |
//! | 0x03 | WRITE | address, data | status (Response Status Level 1) | Protocol 1.0 |
//! | 0x04 | REG WRITE | address, data; held until ACTION | status (level 1) | Protocol 1.0 |
//! | 0x05 | ACTION | – | status (level 1) | Protocol 1.0 |
//! | 0x06 | RECOVERY (factory reset; Protocol 1.0's RESET) | – | status (level 1) | Protocol 1.0 |
//! | 0x82 | SYNC READ | address, length, IDs | one status packet per ID, in order | here |
//! | 0x83 | SYNC WRITE | address, length, per servo: ID, data | none | Protocol 1.0 |
//!
//! The shared rows are Protocol 1.0's [`dynamixel::Instruction`], wrapped:
//! their bytes, their checks and their encoders are written once. Feetech
//! has no BULK READ (0x92): it parses as an unknown code, and encoding one
//! is [`EncodeError::Unsupported`].

use crate::dynamixel::packet::write_packet;
use crate::dynamixel::{self, EncodeError, BROADCAST_ID};

pub use crate::dynamixel::InstructionError;

/// Feetech's instruction table: each code and its name.
pub const INSTRUCTIONS: [(u8, &str); 8] = [
    (0x01, "PING"),
    (0x02, "READ"),
    (0x03, "WRITE"),
    (0x04, "REG WRITE"),
    (0x05, "ACTION"),
    (0x06, "RECOVERY"),
    (SYNC_READ, "SYNC READ"),
    (0x83, "SYNC WRITE"),
];

/// SYNC READ's code, the one row Protocol 1.0 lacks.
pub const SYNC_READ: u8 = 0x82;

/// The name of a code in Feetech's table, if it has it.
pub fn name(code: u8) -> Option<&'static str> {
    INSTRUCTIONS.iter().find(|(c, _)| *c == code).map(|(_, n)| *n)
}

/// A Feetech instruction, borrowing its parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Instruction<'a> {
    /// A row Feetech shares with Protocol 1.0 (every one but BULK READ;
    /// Protocol 1.0's RESET is Feetech's RECOVERY).
    Shared(dynamixel::Instruction<'a>),
    /// SYNC READ of `len` bytes at `addr` from each of `ids`.
    SyncRead {
        /// Start address.
        addr: u8,
        /// Bytes per servo.
        len: u8,
        /// The servos, in the order they answer.
        ids: &'a [u8],
    },
}

impl<'a> Instruction<'a> {
    /// The instruction's code.
    pub fn code(&self) -> u8 {
        match self {
            Instruction::Shared(i) => i.code() as u8,
            Instruction::SyncRead { .. } => SYNC_READ,
        }
    }

    /// Parses a decoded instruction packet's code and parameters. SYNC
    /// READ needs at least one ID and a length of at least one byte.
    pub fn parse(code: u8, params: &'a [u8]) -> Result<Self, InstructionError> {
        let bad = InstructionError::BadParams { code, len: params.len() as u8 };
        match name(code) {
            None => Err(InstructionError::UnknownCode { code }),
            Some(_) if code == SYNC_READ => match params {
                [addr, len, ids @ ..] if *len > 0 && !ids.is_empty() => {
                    Ok(Instruction::SyncRead { addr: *addr, len: *len, ids })
                }
                _ => Err(bad),
            },
            Some(_) => dynamixel::Instruction::parse(code, params).map(Instruction::Shared),
        }
    }

    /// Encodes the instruction for servo `id` (SYNC READ and SYNC WRITE:
    /// the broadcast ID) into `out`.
    pub fn encode<'b>(&self, id: u8, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        match *self {
            Instruction::Shared(i @ dynamixel::Instruction::BulkRead { .. }) => {
                Err(EncodeError::Unsupported { code: i.code() as u8 })
            }
            Instruction::Shared(i) => i.encode(id, out),
            Instruction::SyncRead { addr, len, ids } => {
                if len == 0 || ids.is_empty() {
                    return Err(EncodeError::SyncDataLength { entry: 0, expected: len, got: ids.len() });
                }
                write_packet(id, SYNC_READ, &[&[addr, len], ids], out)
            }
        }
    }

    /// Parameter bytes of the status packet that answers it from one
    /// servo: the length read for READ and SYNC READ, none otherwise.
    pub fn reply_params(&self) -> u8 {
        match *self {
            Instruction::Shared(dynamixel::Instruction::Read { len, .. }) | Instruction::SyncRead { len, .. } => len,
            _ => 0,
        }
    }
}

/// Encodes a SYNC READ (to the broadcast ID) of `len` bytes at `addr` from
/// each of `ids`, which answer in turn.
pub fn sync_read<'b>(addr: u8, len: u8, ids: &[u8], out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
    Instruction::SyncRead { addr, len, ids }.encode(BROADCAST_ID, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sync_read_bytes_and_parse() {
        let mut buf = [0u8; 16];
        // Present Position (56, 2 bytes) of IDs 1 and 2:
        // FF FF FE 06 82 38 02 01 02 and the checksum.
        let p = sync_read(56, 2, &[1, 2], &mut buf).unwrap();
        let sum = dynamixel::checksum(&[0xFE, 0x06, 0x82, 0x38, 0x02, 0x01, 0x02]);
        assert_eq!(p, &[0xFF, 0xFF, 0xFE, 0x06, 0x82, 0x38, 0x02, 0x01, 0x02, sum]);
        assert_eq!(Instruction::parse(0x82, &p[5..9]), Ok(Instruction::SyncRead { addr: 56, len: 2, ids: &[1, 2] }));
        assert_eq!(Instruction::parse(0x82, &[56, 2]), Err(InstructionError::BadParams { code: 0x82, len: 2 }));
        assert_eq!(Instruction::parse(0x82, &[56, 0, 1]), Err(InstructionError::BadParams { code: 0x82, len: 3 }));
        assert!(sync_read(56, 2, &[], &mut buf).is_err());
    }

    #[test]
    fn the_shared_rows_are_protocol_1s_and_bulk_read_is_not_one() {
        let ping = Instruction::parse(0x01, &[]).unwrap();
        assert_eq!(ping, Instruction::Shared(dynamixel::Instruction::Ping));
        let mut a = [0u8; 16];
        let mut b = [0u8; 16];
        assert_eq!(ping.encode(1, &mut a).unwrap(), dynamixel::ping(1, &mut b).unwrap());
        assert_eq!(Instruction::parse(0x92, &[0, 2, 1, 36]), Err(InstructionError::UnknownCode { code: 0x92 }));
        let bulk = Instruction::Shared(dynamixel::Instruction::BulkRead { entries: &[2, 1, 36] });
        assert_eq!(bulk.encode(0xFE, &mut a), Err(EncodeError::Unsupported { code: 0x92 }));
        assert_eq!(name(Instruction::parse(0x06, &[]).unwrap().code()), Some("RECOVERY"));
        assert_eq!(Instruction::parse(0x0A, &[]), Err(InstructionError::UnknownCode { code: 0x0A }));
        assert_eq!(Instruction::parse(0x02, &[56, 8]).unwrap().reply_params(), 8);
        assert_eq!(INSTRUCTIONS.iter().filter(|(c, _)| name(*c).is_some()).count(), 8);
    }
}
