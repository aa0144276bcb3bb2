//! The one incremental packet decoder, for both directions: status packets
//! on the firmware ([`StatusDecoder`]), instruction packets in the bus
//! emulator ([`InstructionDecoder`]).
//!
//! The decoder keeps the bytes of the packet being received in a fixed
//! buffer of `N` bytes, which always starts at a candidate header
//! `0xFF 0xFF`. On a bad checksum, an impossible length or a header that is
//! not the reply expected it reports a typed [`DecodeError`], drops only the
//! first header byte and scans the rest again, so a packet that a damaged
//! one swallowed is still found. Every byte fed ends up in exactly one of
//! three places: an accepted packet, [`DecoderStats::skipped_bytes`], or
//! the buffer ([`Decoder::buffered`]).
//!
//! Protocol 1.0's checksum is one byte, so one in 256 random headers passes
//! it. A status decoder told which reply to expect ([`Decoder::expect`]:
//! the servo asked and the parameter count its request implies) refuses a
//! header from any other ID or with any other LENGTH as soon as its fourth
//! byte arrives, before waiting for the bytes that LENGTH announces: a
//! spurious header cannot hold back or swallow the real reply behind it,
//! and garbage must match ID, LENGTH and checksum to pass.

use super::packet::{checksum, ErrorFlags, InstructionPacket, StatusPacket, BROADCAST_ID, DEFAULT_PACKET_LEN, HEADER, OVERHEAD};
use crate::framing::{bump, Step};
use heapless::Vec;

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
    /// LENGTH below 2, a packet longer than the decoder's buffer, or not
    /// the LENGTH of the expected reply.
    BadLength {
        /// ID byte of the packet.
        id: u8,
        /// The LENGTH byte received.
        length: u8,
    },
    /// A header from another servo than the one asked.
    UnexpectedId {
        /// The ID that was asked.
        expected: u8,
        /// The ID in the header.
        got: u8,
    },
    /// A status packet from the broadcast ID, which no servo answers from
    /// (and which [`StatusPacket::encode`] refuses).
    BroadcastStatus,
}

/// Decoder counters, for health telemetry. Every byte fed is in an accepted
/// packet, in `skipped_bytes`, or still buffered.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DecoderStats {
    /// Packets decoded.
    pub packets: u32,
    /// Bytes discarded: outside any header, and the first header byte of
    /// every packet refused.
    pub skipped_bytes: u32,
    /// Packets with a wrong checksum.
    pub bad_checksums: u32,
    /// Headers with an impossible LENGTH, or not the expected reply's.
    pub bad_lengths: u32,
    /// Headers from an unexpected ID (for status packets, the broadcast ID
    /// too).
    pub unexpected_ids: u32,
}

/// The reply a status decoder waits for: from servo `id`, with `params`
/// parameter bytes (the READ's length; 0 for PING and WRITE).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reply {
    /// The servo asked.
    pub id: u8,
    /// Parameter bytes its status packet carries.
    pub params: u8,
}

/// A packet the decoder can build from the fields it found.
pub trait FromRaw<const N: usize>: Sized {
    /// Whether the broadcast ID may send this kind of packet (instructions:
    /// yes; status packets: no servo answers from it).
    const FROM_BROADCAST: bool;
    /// The packet with `id`, byte 4 (INSTRUCTION or ERROR) and `params`.
    fn from_raw(id: u8, byte4: u8, params: Vec<u8, N>) -> Self;
}

impl<const N: usize> FromRaw<N> for StatusPacket<N> {
    const FROM_BROADCAST: bool = false;
    fn from_raw(id: u8, byte4: u8, params: Vec<u8, N>) -> Self {
        StatusPacket { id, error: ErrorFlags(byte4), params }
    }
}

impl<const N: usize> FromRaw<N> for InstructionPacket<N> {
    const FROM_BROADCAST: bool = true;
    fn from_raw(id: u8, byte4: u8, params: Vec<u8, N>) -> Self {
        InstructionPacket { id, code: byte4, params }
    }
}

pub use crate::framing::{Decoder, Feed};

/// The firmware's decoder of status packets: the skeleton every protocol
/// shares ([`crate::framing::Decoder`]) with Protocol 1.0's framing
/// ([`examine`]). Feed it bytes with [`push`](Decoder::push) or
/// [`feed`](Decoder::feed).
///
/// `N` must hold the smallest packet, [`OVERHEAD`] = 6 bytes (header,
/// ID, length, instruction or error, checksum): a smaller decoder could
/// never complete a packet, and one of 0 bytes would drop every byte
/// without counting it. Such a decoder does not compile:
///
/// ```compile_fail
/// let d = pada_core::dynamixel::StatusDecoder::<0>::new();
/// ```
///
/// ```
/// let d = pada_core::dynamixel::StatusDecoder::<6>::new();
/// assert_eq!(d.buffered(), 0);
/// ```
pub type StatusDecoder<const N: usize = DEFAULT_PACKET_LEN> = Decoder<StatusPacket<N>, N>;
/// The bus emulator's decoder of instruction packets.
pub type InstructionDecoder<const N: usize = DEFAULT_PACKET_LEN> = Decoder<InstructionPacket<N>, N>;

/// The counters of a new decoder.
const NO_STATS: DecoderStats =
    DecoderStats { packets: 0, skipped_bytes: 0, bad_checksums: 0, bad_lengths: 0, unexpected_ids: 0 };

/// Counts a refusal of Protocol 1.0's framing in its counter.
fn count(stats: &mut DecoderStats, error: &DecodeError) {
    bump(match error {
        DecodeError::BadChecksum { .. } => &mut stats.bad_checksums,
        DecodeError::BadLength { .. } => &mut stats.bad_lengths,
        DecodeError::UnexpectedId { .. } | DecodeError::BroadcastStatus => &mut stats.unexpected_ids,
    })
}

/// Protocol 1.0's framing (Feetech's too): what the bytes at the front of
/// `buf`, which start with `FF FF`, make. A refusal before the checksum
/// matched drops only the first header byte.
pub fn examine<P: FromRaw<N>, const N: usize>(buf: &[u8], expected: Option<Reply>) -> Step<P, DecodeError> {
    let refuse = |error| Step::Refuse { drop: 1, error };
    let Some(&id) = buf.get(2) else { return Step::More };
    if id == 0xFF {
        // 0xFF 0xFF 0xFF: the header starts one byte later.
        return Step::Resync;
    }
    if id == BROADCAST_ID && !P::FROM_BROADCAST {
        return refuse(DecodeError::BroadcastStatus);
    }
    let Some(&length) = buf.get(3) else { return Step::More };
    let total = length as usize + 4;
    if let Some(reply) = expected {
        if id != reply.id {
            return refuse(DecodeError::UnexpectedId { expected: reply.id, got: id });
        }
        if length as u16 != reply.params as u16 + 2 {
            return refuse(DecodeError::BadLength { id, length });
        }
    }
    if length < 2 || total > N {
        return refuse(DecodeError::BadLength { id, length });
    }
    let Some(packet) = buf.get(..total) else { return Step::More };
    let expected = checksum(&packet[2..total - 1]);
    let got = packet[total - 1];
    if expected != got {
        return refuse(DecodeError::BadChecksum { id, expected, got });
    }
    let params = Vec::from_slice(&packet[5..total - 1]).unwrap_or_default();
    Step::Accept { len: total, packet: P::from_raw(id, packet[4], params) }
}

crate::framed! {
    header: HEADER, min: OVERHEAD, reply: Reply, error: DecodeError, stats: DecoderStats = NO_STATS,
    count: count, examine: examine, packets: [StatusPacket, InstructionPacket]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamixel::ErrorFlags;

    #[test]
    fn status_round_trip_and_wrong_id() {
        let mut buf = [0u8; 32];
        let st = StatusPacket::<64>::new(3, ErrorFlags::OVERHEATING, &[0x10, 0x02]).unwrap();
        let bytes = st.encode(&mut buf).unwrap();
        let mut dec = StatusDecoder::<64>::new();
        dec.expect(Some(Reply { id: 3, params: 2 }));
        let got: heapless::Vec<_, 4> = dec.feed(bytes).collect();
        assert_eq!(got.len(), 1);
        let p = got[0].clone().unwrap();
        assert_eq!(p, st);
        assert_eq!(p.u16_at(0), Some(0x0210));
        dec.expect(Some(Reply { id: 4, params: 2 }));
        let got: heapless::Vec<_, 4> = dec.feed(bytes).collect();
        assert_eq!(got[0], Err(DecodeError::UnexpectedId { expected: 4, got: 3 }));
        assert_eq!(dec.stats().unexpected_ids, 1);
    }
}
