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

use super::packet::{checksum, ErrorFlags, InstructionPacket, StatusPacket, BROADCAST_ID, DEFAULT_PACKET_LEN, OVERHEAD};
use core::marker::PhantomData;
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

/// Incremental decoder of packets `P` of up to `N` bytes (header to
/// checksum). Feed it bytes with [`push`](Self::push) or
/// [`feed`](Self::feed).
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
#[derive(Debug, Clone)]
pub struct Decoder<P, const N: usize> {
    buf: [u8; N],
    len: usize,
    stats: DecoderStats,
    expected: Option<Reply>,
    _packet: PhantomData<fn() -> P>,
}

/// The firmware's decoder of status packets.
pub type StatusDecoder<const N: usize = DEFAULT_PACKET_LEN> = Decoder<StatusPacket<N>, N>;
/// The bus emulator's decoder of instruction packets.
pub type InstructionDecoder<const N: usize = DEFAULT_PACKET_LEN> = Decoder<InstructionPacket<N>, N>;

impl<P: FromRaw<N>, const N: usize> Default for Decoder<P, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<P: FromRaw<N>, const N: usize> Decoder<P, N> {
    /// A decoder that accepts any ID and length; `N` below [`OVERHEAD`]
    /// is a compile-time error naming the valid range.
    pub const fn new() -> Self {
        const {
            assert!(
                N >= OVERHEAD,
                "Decoder capacity N is too small: valid is N >= 6 (OVERHEAD: header, ID, length, instruction or error, checksum)"
            )
        };
        Decoder {
            buf: [0; N],
            len: 0,
            stats: DecoderStats { packets: 0, skipped_bytes: 0, bad_checksums: 0, bad_lengths: 0, unexpected_ids: 0 },
            expected: None,
            _packet: PhantomData,
        }
    }

    /// Accept only `reply` (`None`: any packet). A status decoder is told
    /// before every request.
    pub fn expect(&mut self, reply: Option<Reply>) {
        self.expected = reply;
    }

    /// Drops any partial packet (e.g. after a timeout, before the next
    /// request); the dropped bytes count as skipped.
    pub fn reset(&mut self) {
        self.skip(self.len);
    }

    /// Counters since creation.
    pub fn stats(&self) -> DecoderStats {
        self.stats
    }

    /// Bytes held for a packet not yet complete.
    pub fn buffered(&self) -> usize {
        self.len
    }

    fn skip(&mut self, n: usize) {
        let n = n.min(self.len);
        self.stats.skipped_bytes = self.stats.skipped_bytes.saturating_add(n as u32);
        self.buf.copy_within(n..self.len, 0);
        self.len -= n;
    }

    /// Takes one byte; returns a packet or an error if this byte completed
    /// one. After `Some`, call [`poll`](Self::poll) until `None`: the bytes
    /// kept after an error may already hold the next packet.
    pub fn push(&mut self, byte: u8) -> Option<Result<P, DecodeError>> {
        if self.len >= N {
            // Cannot happen (a candidate longer than N is refused as soon
            // as its LENGTH is seen), but never overrun.
            self.skip(1);
        }
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = byte;
            self.len += 1;
        }
        self.poll()
    }

    /// Looks for one complete packet or error in the buffered bytes.
    pub fn poll(&mut self) -> Option<Result<P, DecodeError>> {
        loop {
            // Find `0xFF 0xFF` at the front.
            let start = self.buf[..self.len].iter().position(|&b| b == 0xFF).unwrap_or(self.len);
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
            if self.buf[2] == BROADCAST_ID && !P::FROM_BROADCAST {
                self.stats.unexpected_ids = self.stats.unexpected_ids.saturating_add(1);
                self.skip(1);
                return Some(Err(DecodeError::BroadcastStatus));
            }
            if self.len < 4 {
                return None;
            }
            let (id, length) = (self.buf[2], self.buf[3]);
            let total = length as usize + 4;
            if let Some(reply) = self.expected {
                if id != reply.id {
                    self.stats.unexpected_ids = self.stats.unexpected_ids.saturating_add(1);
                    self.skip(1);
                    return Some(Err(DecodeError::UnexpectedId { expected: reply.id, got: id }));
                }
                if length as u16 != reply.params as u16 + 2 {
                    self.stats.bad_lengths = self.stats.bad_lengths.saturating_add(1);
                    self.skip(1);
                    return Some(Err(DecodeError::BadLength { id, length }));
                }
            }
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
            let packet = P::from_raw(id, self.buf[4], params);
            self.buf.copy_within(total..self.len, 0);
            self.len -= total;
            self.stats.packets = self.stats.packets.saturating_add(1);
            return Some(Ok(packet));
        }
    }

    /// Feeds a chunk and iterates over every packet and error in it.
    pub fn feed<'s, 'b>(&'s mut self, bytes: &'b [u8]) -> Feed<'s, 'b, P, N> {
        Feed { decoder: self, rest: bytes }
    }
}

/// Iterator over the packets and errors of a chunk fed to a decoder. Bytes
/// of an incomplete packet at the end stay in the decoder for the next chunk.
pub struct Feed<'s, 'b, P, const N: usize> {
    decoder: &'s mut Decoder<P, N>,
    rest: &'b [u8],
}

impl<P: FromRaw<N>, const N: usize> Iterator for Feed<'_, '_, P, N> {
    type Item = Result<P, DecodeError>;
    fn next(&mut self) -> Option<Self::Item> {
        if let Some(r) = self.decoder.poll() {
            return Some(r);
        }
        while let Some((&b, rest)) = self.rest.split_first() {
            self.rest = rest;
            if let Some(r) = self.decoder.push(b) {
                return Some(r);
            }
        }
        None
    }
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
