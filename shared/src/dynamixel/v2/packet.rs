//! Protocol 2.0 packets (e-Manual, "DYNAMIXEL Protocol 2.0", §§
//! "Instruction Packet", "Status Packet", "Packet Process"): the frame
//! writer, the two packet types and their encoding. Decoding a byte stream
//! into packets is [`super::decoder`].
//!
//! ```text
//! instruction: FF FF FD 00  ID  LEN_L LEN_H  INSTRUCTION        PARAM_1 … PARAM_N  CRC_L CRC_H
//! status:      FF FF FD 00  ID  LEN_L LEN_H  0x55        ERROR  PARAM_1 … PARAM_N  CRC_L CRC_H
//! LENGTH = stuffed bytes from INSTRUCTION to the last parameter + 2 (the CRC)
//! CRC    = CRC-16 of every byte from the first FF to the last parameter
//! ```

use super::crc::crc16;
use super::status::StatusError;
use super::stuffing::{stuff_into, stuffed_len};
use heapless::Vec;

/// The four header bytes that start every packet (three header bytes and
/// the reserved `0x00`, which is never `0xFD`).
pub const HEADER: [u8; 4] = [0xFF, 0xFF, 0xFD, 0x00];
/// The broadcast ID: every servo executes the instruction; none answers
/// READ or WRITE, every one answers PING in turn, and the one combined
/// reply to Fast Sync Read and Fast Bulk Read carries this ID.
pub const BROADCAST_ID: u8 = 0xFE;
/// The highest ID of a servo (0–252; 253 and 255 are never IDs, so that
/// they are not mistaken for header bytes).
pub const MAX_ID: u8 = 0xFC;
/// The INSTRUCTION byte of every status packet.
pub const STATUS: u8 = 0x55;
/// Bytes before the INSTRUCTION byte: header, ID, LENGTH.
pub const PREFIX_LEN: usize = 7;
/// Bytes of an instruction packet besides its parameters: prefix,
/// INSTRUCTION and CRC (the smallest packet, a PING, is 10 bytes).
pub const INSTRUCTION_OVERHEAD: usize = 10;
/// Bytes of a status packet besides its parameters: prefix, `0x55`,
/// ERROR and CRC.
pub const STATUS_OVERHEAD: usize = 11;
/// Default decoder buffer and parameter capacity: the Fast Sync Read reply
/// of the present block (Present PWM(124) to Present Temperature(146), 23
/// bytes) from eight servos, [`crate::limits::MAX_SERVOS`], is
/// 7 + 1 + 8 × (23 + 4) = 224 bytes.
pub const DEFAULT_PACKET_LEN: usize = 256;

/// Whether a packet with this ID and INSTRUCTION byte is byte-stuffed:
/// every one but the Fast Sync/Bulk Read reply (a status packet from the
/// broadcast ID), which the e-Manual sends unstuffed.
pub const fn is_stuffed(id: u8, instruction: u8) -> bool {
    !(id == BROADCAST_ID && instruction == STATUS)
}

/// Whether `id` may appear in a packet's ID field (0–252 or the broadcast
/// ID).
pub const fn is_packet_id(id: u8) -> bool {
    id <= MAX_ID || id == BROADCAST_ID
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
    /// More bytes than the 16-bit LENGTH, or a parameter's 16-bit length
    /// field, can describe, or than a packet type's capacity holds.
    TooLong {
        /// The byte count that does not fit.
        bytes: usize,
    },
    /// An ID that cannot be sent here (253 or 255 anywhere; the broadcast
    /// ID inside a multi-servo instruction or as a servo's status).
    InvalidId {
        /// The offending ID.
        id: u8,
    },
    /// Parameters the instruction's layout does not allow (what
    /// [`super::instruction::Instruction::parse`] would refuse as
    /// [`super::instruction::InstructionError::BadParams`]).
    BadParams {
        /// The instruction code.
        code: u8,
    },
    /// A multi-servo instruction (sync/bulk read and write, fast reads) to
    /// another ID than the broadcast ID.
    NotBroadcast {
        /// The instruction code.
        code: u8,
    },
}

/// Writes one packet: header, `id`, LENGTH, the INSTRUCTION byte and `body`
/// (stuffed unless [`is_stuffed`] says not), the CRC. Returns the written
/// prefix of `out`. `body` is iterated twice (to size, then to write), so
/// nothing is buffered.
pub fn write_frame<I>(id: u8, instruction: u8, body: I, out: &mut [u8]) -> Result<&[u8], EncodeError>
where
    I: Iterator<Item = u8> + Clone,
{
    if !is_packet_id(id) {
        return Err(EncodeError::InvalidId { id });
    }
    let payload = core::iter::once(instruction).chain(body);
    let stuff = is_stuffed(id, instruction);
    let len = if stuff { stuffed_len(payload.clone()) } else { payload.clone().count() };
    let length = len + 2;
    if length > u16::MAX as usize {
        return Err(EncodeError::TooLong { bytes: length });
    }
    let total = PREFIX_LEN + length;
    let available = out.len();
    let Some(out) = out.get_mut(..total) else {
        return Err(EncodeError::BufferTooSmall { needed: total, available });
    };
    let (head, rest) = out.split_at_mut(PREFIX_LEN);
    let [l0, l1] = (length as u16).to_le_bytes();
    head.copy_from_slice(&[HEADER[0], HEADER[1], HEADER[2], HEADER[3], id, l0, l1]);
    let (mid, _) = rest.split_at_mut(len);
    let written = if stuff {
        stuff_into(payload, mid)
    } else {
        mid.iter_mut().zip(payload).for_each(|(o, b)| *o = b);
        Some(len)
    };
    debug_assert_eq!(written, Some(len));
    let crc = crc16(&out[..total - 2]);
    out[total - 2..].copy_from_slice(&crc.to_le_bytes());
    Ok(out)
}

/// A status packet (a servo's answer), owning up to `N` parameter bytes
/// (unstuffed): the two protocols' [`crate::dynamixel::status_packet::StatusPacket`]
/// with Protocol 2.0's ERROR byte.
///
/// A status packet from [`BROADCAST_ID`] is the one combined reply to Fast
/// Sync Read or Fast Bulk Read: `error` is the first servo's ERROR and
/// `params` the rest of the blocks (read them with
/// [`StatusPacket::fast_blocks`]); it is encoded without stuffing.
pub type StatusPacket<const N: usize = DEFAULT_PACKET_LEN> = crate::dynamixel::status_packet::StatusPacket<StatusError, N>;

impl<const N: usize> StatusPacket<N> {
    /// A status packet with `params`, which must fit `N`.
    pub fn new(id: u8, error: StatusError, params: &[u8]) -> Result<Self, EncodeError> {
        let params = Vec::from_slice(params).map_err(|_| EncodeError::TooLong { bytes: params.len() })?;
        Ok(StatusPacket { id, error, params })
    }

    /// Whether this is the combined reply of a fast read.
    pub fn is_fast(&self) -> bool {
        self.id == BROADCAST_ID
    }

    /// Encodes the packet (the servo's side) into `out`. IDs 253 and 255
    /// are refused; the broadcast ID encodes a fast reply, unstuffed.
    pub fn encode<'b>(&self, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        if !is_packet_id(self.id) {
            return Err(EncodeError::InvalidId { id: self.id });
        }
        let body = core::iter::once(self.error.0).chain(self.params.iter().copied());
        write_frame(self.id, STATUS, body, out)
    }
}

/// An instruction packet as a servo (or the bus emulator) decodes it,
/// owning up to `N` parameter bytes (unstuffed). Any INSTRUCTION byte is
/// kept, [`STATUS`] too: a servo on a shared bus hears the other servos'
/// replies, and [`InstructionPacket::instruction`] tells it to ignore them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InstructionPacket<const N: usize = DEFAULT_PACKET_LEN> {
    /// The addressed servo (or [`BROADCAST_ID`]).
    pub id: u8,
    /// The INSTRUCTION byte.
    pub instruction: u8,
    /// The parameters.
    pub params: Vec<u8, N>,
}

impl<const N: usize> InstructionPacket<N> {
    /// Encodes the packet as it was received (ID, INSTRUCTION and
    /// parameters as they are, a valid instruction or not) into `out`.
    pub fn encode<'b>(&self, out: &'b mut [u8]) -> Result<&'b [u8], EncodeError> {
        write_frame(self.id, self.instruction, self.params.iter().copied(), out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ping_is_the_manuals_ten_bytes() {
        // e-Manual § "Ping", Example 1: FF FF FD 00 01 03 00 01 19 4E.
        let mut buf = [0u8; 16];
        let p = write_frame(1, 0x01, core::iter::empty(), &mut buf).unwrap();
        assert_eq!(p, &[0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E]);
        assert_eq!(p.len(), INSTRUCTION_OVERHEAD);
        assert_eq!(
            write_frame(1, 0x01, core::iter::empty(), &mut buf[..9]),
            Err(EncodeError::BufferTooSmall { needed: 10, available: 9 })
        );
        assert_eq!(write_frame(0xFD, 0x01, core::iter::empty(), &mut buf), Err(EncodeError::InvalidId { id: 0xFD }));
    }

    #[test]
    fn stuffing_counts_in_length_and_crc_except_for_fast_replies() {
        let mut buf = [0u8; 32];
        let body = [0x00, 0x00, 0xFF, 0xFF, 0xFD];
        let p = write_frame(1, 0x03, body.iter().copied(), &mut buf).unwrap().to_vec_in_test();
        // INSTRUCTION + 5 body bytes + 1 stuffing byte + CRC.
        assert_eq!(u16::from_le_bytes([p[5], p[6]]), 9);
        assert_eq!(&p[8..14], &[0x00, 0x00, 0xFF, 0xFF, 0xFD, 0xFD]);
        assert_eq!(crc16(&p[..p.len() - 2]).to_le_bytes(), [p[p.len() - 2], p[p.len() - 1]]);
        let fast = write_frame(BROADCAST_ID, STATUS, body.iter().copied(), &mut buf).unwrap();
        assert_eq!(u16::from_le_bytes([fast[5], fast[6]]), 8);
        let st = StatusPacket::<8>::new(BROADCAST_ID, StatusError(0), &[0xFF, 0xFF, 0xFD]).unwrap();
        assert!(st.is_fast());
        assert_eq!(st.encode(&mut buf).unwrap().len(), STATUS_OVERHEAD + 3);
        assert_eq!(st.u16_at(1), Some(0xFDFF));
        assert_eq!(st.u16_at(2), None);
        assert_eq!(st.u32_at(0), None);
    }

    /// A fixed-capacity copy for comparisons (the crate is `no_std`).
    trait ToVecInTest {
        fn to_vec_in_test(&self) -> Vec<u8, 64>;
    }
    impl ToVecInTest for [u8] {
        fn to_vec_in_test(&self) -> Vec<u8, 64> {
            Vec::from_slice(self).unwrap()
        }
    }
}
