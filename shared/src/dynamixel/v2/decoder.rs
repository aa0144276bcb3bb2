//! The incremental decoder of Protocol 2.0 packets, for both directions:
//! status packets on the firmware ([`StatusDecoder`]), instruction packets
//! in a servo or the bus emulator ([`InstructionDecoder`]).
//!
//! It follows the 1.0 decoder ([`crate::dynamixel::decoder`]): the bytes
//! of the packet being received sit in a fixed buffer of `N` bytes that
//! always starts at a candidate header, and every byte fed ends up in
//! exactly one of three places: an accepted packet,
//! [`DecoderStats::skipped_bytes`], or the buffer ([`Decoder::buffered`]).
//! A packet longer than `N` is a counted [`DecodeError::BadLength`], never
//! a panic.
//!
//! Reception follows the e-Manual's "Processing Order of Reception"
//! (§ "Packet Process"): find `FF FF FD 00` (a stuffed `FF FF FD FD` is
//! not a header), read LENGTH bytes, check the CRC over the bytes as
//! received, then remove the stuffing. A refusal found before the CRC
//! (a bad ID or LENGTH, a packet of the wrong kind, a CRC mismatch) drops
//! only the first header byte and scans the rest again, so a packet that a
//! damaged one swallowed is still found; a refusal after the CRC matched
//! (stuffing that is not the e-Manual's, or the wrong parameter count for
//! the expected reply) drops the whole packet, which is certainly one.
//!
//! A status decoder told which reply to expect ([`Decoder::expect`])
//! refuses a header from any other ID, or whose LENGTH cannot be the
//! reply's, as soon as those bytes arrive.

use super::crc::crc16;
use super::packet::{is_stuffed, InstructionPacket, StatusPacket, BROADCAST_ID, DEFAULT_PACKET_LEN, HEADER, MAX_ID, PREFIX_LEN, STATUS, STATUS_OVERHEAD};
use super::status::StatusError;
use super::stuffing::{destuff, max_stuffed_len};
use crate::framing::{bump, Step};
use heapless::Vec;

/// Why bytes received did not form an acceptable packet. The decoder has
/// already resynchronised when it reports one of these.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DecodeError {
    /// The CRC does not match the packet's bytes.
    BadCrc {
        /// ID byte of the corrupted packet (itself possibly corrupted).
        id: u8,
        /// CRC computed over the received bytes.
        expected: u16,
        /// CRC received.
        got: u16,
    },
    /// LENGTH below the smallest packet, a packet longer than the
    /// decoder's buffer, or not the expected reply's length.
    BadLength {
        /// ID byte of the packet.
        id: u8,
        /// The LENGTH field.
        length: u16,
    },
    /// ID 253 or 255, which are never IDs.
    InvalidId {
        /// The ID byte.
        id: u8,
    },
    /// A header from another ID than the one asked.
    UnexpectedId {
        /// The ID that was asked.
        expected: u8,
        /// The ID in the header.
        got: u8,
    },
    /// A packet that is not a status packet (INSTRUCTION ≠ 0x55) where one
    /// was expected: an instruction echoed, or noise.
    NotStatus {
        /// ID byte of the packet.
        id: u8,
        /// Its INSTRUCTION byte.
        instruction: u8,
    },
    /// The CRC matched but the payload holds a bare `FF FF FD` (see
    /// [`super::stuffing`]).
    BadStuffing {
        /// ID of the packet.
        id: u8,
    },
}

/// Decoder counters, for health telemetry. Every byte fed is in an accepted
/// packet, in `skipped_bytes`, or still buffered; every refusal is counted
/// in exactly one of the other fields.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Packets decoded.
    pub packets: u32,
    /// Bytes discarded: outside any header, the first header byte of every
    /// packet refused before its CRC, every byte of one refused after.
    pub skipped_bytes: u32,
    /// Packets with a wrong CRC ([`DecodeError::BadCrc`]).
    pub bad_crcs: u32,
    /// [`DecodeError::BadLength`].
    pub bad_lengths: u32,
    /// [`DecodeError::InvalidId`] and [`DecodeError::UnexpectedId`].
    pub unexpected_ids: u32,
    /// [`DecodeError::NotStatus`].
    pub not_status: u32,
    /// [`DecodeError::BadStuffing`].
    pub bad_stuffing: u32,
}

/// The reply a status decoder waits for: from `id`, with `params`
/// parameter bytes after ERROR (unstuffed).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reply {
    /// The servo asked, or [`BROADCAST_ID`] for a fast read's combined
    /// reply.
    pub id: u8,
    /// Parameter bytes of its status packet
    /// ([`super::instruction::Instruction::reply_params`]; for a fast
    /// reply [`super::fast::fast_sync_reply_params`]).
    pub params: u16,
}

impl Reply {
    /// A status packet from servo `id` with `params` parameter bytes.
    pub const fn status(id: u8, params: u16) -> Self {
        Reply { id, params }
    }

    /// The LENGTH values this reply can have when the smallest LENGTH of
    /// its kind is `base` (4 for status packets): `params + base`
    /// unstuffed, and up to a third more of the stuffed bytes (INSTRUCTION
    /// excluded, as it is never `FF`); a fast reply is never stuffed.
    fn length_range(&self, base: u16, status: bool) -> (usize, usize) {
        let min = self.params as usize + base as usize;
        if status && self.id == BROADCAST_ID {
            (min, min)
        } else {
            let stuffed = min - 3; // ERROR (for status) and parameters
            (min, min - stuffed + max_stuffed_len(stuffed))
        }
    }
}

/// A packet type the decoder can build.
pub trait FromFrame<const N: usize>: Sized {
    /// Only status packets (INSTRUCTION 0x55) are accepted.
    const STATUS_ONLY: bool;
    /// The smallest LENGTH: INSTRUCTION (and ERROR) and the CRC.
    const MIN_LENGTH: u16;
    /// The packet from its ID, INSTRUCTION byte and unstuffed bytes after
    /// INSTRUCTION (`None` if they do not fit).
    fn from_frame(id: u8, instruction: u8, body: &[u8]) -> Option<Self>;
}

impl<const N: usize> FromFrame<N> for StatusPacket<N> {
    const STATUS_ONLY: bool = true;
    const MIN_LENGTH: u16 = 4;
    fn from_frame(id: u8, _instruction: u8, body: &[u8]) -> Option<Self> {
        let (&error, params) = body.split_first()?;
        Some(StatusPacket { id, error: StatusError(error), params: Vec::from_slice(params).ok()? })
    }
}

impl<const N: usize> FromFrame<N> for InstructionPacket<N> {
    const STATUS_ONLY: bool = false;
    const MIN_LENGTH: u16 = 3;
    fn from_frame(id: u8, instruction: u8, body: &[u8]) -> Option<Self> {
        Some(InstructionPacket { id, instruction, params: Vec::from_slice(body).ok()? })
    }
}

pub use crate::framing::{Decoder, Feed};

/// The firmware's decoder of status packets: the skeleton every protocol
/// shares ([`crate::framing::Decoder`]) with Protocol 2.0's framing
/// ([`examine`]). Feed it bytes with [`push`](Decoder::push) or
/// [`feed`](Decoder::feed).
///
/// `N` must hold the smallest status packet, 11 bytes; a smaller decoder
/// could never complete one. Such a decoder does not compile:
///
/// ```compile_fail
/// let d = pada_core::dynamixel::v2::StatusDecoder::<10>::new();
/// ```
///
/// ```
/// let d = pada_core::dynamixel::v2::StatusDecoder::<11>::new();
/// assert_eq!(d.buffered(), 0);
/// ```
pub type StatusDecoder<const N: usize = DEFAULT_PACKET_LEN> = Decoder<StatusPacket<N>, N>;
/// A servo's (or the bus emulator's) decoder of instruction packets.
pub type InstructionDecoder<const N: usize = DEFAULT_PACKET_LEN> = Decoder<InstructionPacket<N>, N>;

/// The counters of a new decoder.
const NO_STATS: DecoderStats = DecoderStats {
    packets: 0,
    skipped_bytes: 0,
    bad_crcs: 0,
    bad_lengths: 0,
    unexpected_ids: 0,
    not_status: 0,
    bad_stuffing: 0,
};

/// Counts a refusal of Protocol 2.0's framing in its counter.
fn count(stats: &mut DecoderStats, error: &DecodeError) {
    bump(match error {
        DecodeError::BadCrc { .. } => &mut stats.bad_crcs,
        DecodeError::BadLength { .. } => &mut stats.bad_lengths,
        DecodeError::InvalidId { .. } | DecodeError::UnexpectedId { .. } => &mut stats.unexpected_ids,
        DecodeError::NotStatus { .. } => &mut stats.not_status,
        DecodeError::BadStuffing { .. } => &mut stats.bad_stuffing,
    })
}

/// Protocol 2.0's framing: what the bytes at the front of `buf`, which
/// start with `FF FF FD 00`, make (the e-Manual's order of reception: ID,
/// LENGTH, INSTRUCTION, CRC, then the stuffing).
pub fn examine<P: FromFrame<N>, const N: usize>(buf: &[u8], expected: Option<Reply>) -> Step<P, DecodeError> {
    // Refused before the CRC matched: only the first header byte goes.
    let early = |error| Step::Refuse { drop: 1, error };
    let Some(&id) = buf.get(4) else { return Step::More };
    if id > MAX_ID && id != BROADCAST_ID {
        return early(DecodeError::InvalidId { id });
    }
    if let Some(r) = expected {
        if id != r.id {
            return early(DecodeError::UnexpectedId { expected: r.id, got: id });
        }
    }
    let Some(&[l0, l1]) = buf.get(5..7) else { return Step::More };
    let length = u16::from_le_bytes([l0, l1]);
    let total = PREFIX_LEN + length as usize;
    let in_window = expected.is_none_or(|r| {
        let (min, max) = r.length_range(P::MIN_LENGTH, P::STATUS_ONLY);
        (min..=max).contains(&(length as usize))
    });
    if length < P::MIN_LENGTH || total > N || !in_window {
        return early(DecodeError::BadLength { id, length });
    }
    let Some(&instruction) = buf.get(PREFIX_LEN) else { return Step::More };
    if P::STATUS_ONLY && instruction != STATUS {
        return early(DecodeError::NotStatus { id, instruction });
    }
    if instruction == STATUS && length < 4 {
        // A status packet without its ERROR byte.
        return early(DecodeError::BadLength { id, length });
    }
    let Some(packet) = buf.get(..total) else { return Step::More };
    let (body, crc) = packet.split_at(total - 2);
    let expected_crc = crc16(body);
    let got = u16::from_le_bytes([crc.first().copied().unwrap_or(0), crc.get(1).copied().unwrap_or(0)]);
    if expected_crc != got {
        return early(DecodeError::BadCrc { id, expected: expected_crc, got });
    }
    // From here on it is a packet: refusals drop all of it.
    let payload = body.get(PREFIX_LEN..).unwrap_or_default();
    let mut plain: Vec<u8, N> = Vec::new();
    let ok = if is_stuffed(id, instruction) {
        destuff(payload, &mut plain).is_ok()
    } else {
        plain.extend_from_slice(payload).is_ok()
    };
    // INSTRUCTION (and ERROR) precede the parameters.
    let params_ok = expected.is_none_or(|r| plain.len() == r.params as usize + P::MIN_LENGTH as usize - 2);
    let packet = if ok { plain.get(1..).and_then(|b| P::from_frame(id, instruction, b)) } else { None };
    match packet {
        None => Step::Refuse { drop: total, error: DecodeError::BadStuffing { id } },
        Some(_) if !params_ok => Step::Refuse { drop: total, error: DecodeError::BadLength { id, length } },
        Some(packet) => Step::Accept { len: total, packet },
    }
}

crate::framed! {
    header: HEADER, min: STATUS_OVERHEAD, reply: Reply, error: DecodeError, stats: DecoderStats = NO_STATS,
    count: count, examine: examine, packets: [StatusPacket, InstructionPacket]
}
