//! The one framing skeleton of the servo protocols: Dynamixel Protocol 1.0
//! ([`crate::dynamixel`]), Dynamixel Protocol 2.0
//! ([`crate::dynamixel::v2`]) and Feetech's SCS/STS protocol
//! ([`crate::feetech`]).
//!
//! What the three share is written here once:
//!
//! - the byte-stream resynchronisation: the decoder's fixed buffer always
//!   starts at a candidate header (or at the partial header the last bytes
//!   may be the start of); a refused candidate drops the bytes its
//!   protocol says (its first header byte, or all of a packet whose check
//!   matched) and the rest is scanned again, so a packet that a damaged one
//!   swallowed is still found;
//! - the counting of discarded bytes: every byte fed ends up in exactly one
//!   of three places, an accepted packet, the protocol's `skipped_bytes`
//!   counter, or the buffer ([`Decoder::buffered`]);
//! - the decoder's interface: [`Decoder::push`], [`Decoder::poll`],
//!   [`Decoder::feed`], [`Decoder::expect`], [`Decoder::reset`].
//!
//! What differs is each protocol's [`Framed`] implementation: its header,
//! its smallest packet, how it reads LENGTH and the ID, its check
//! (Protocol 1.0 and Feetech: the one-byte checksum; Protocol 2.0: the
//! CRC-16 and byte stuffing), the reply it can be told to expect, its
//! errors and counters. A protocol's `examine` is a pure function of the
//! buffered bytes, so it can be tested and fuzzed alone.

mod decoder;

pub use decoder::{Decoder, Feed};

/// What a protocol's framing makes of the bytes at the front of the
/// decoder's buffer, which start with its whole header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Step<P, E> {
    /// Not enough bytes yet to decide.
    More,
    /// Not a header after all (a header byte repeated, e.g. Protocol
    /// 1.0's `FF FF FF`): drop the first byte without an error.
    Resync,
    /// A refused candidate: count `error`, drop `drop` bytes (counted as
    /// skipped), report the error.
    Refuse {
        /// Bytes to drop from the front.
        drop: usize,
        /// The refusal.
        error: E,
    },
    /// A packet of `len` bytes from the front.
    Accept {
        /// Its length on the wire.
        len: usize,
        /// The packet.
        packet: P,
    },
}

/// The counters every protocol's decoder keeps besides its refusals.
pub trait Counters {
    /// Packets accepted.
    fn packets(&mut self) -> &mut u32;
    /// Bytes discarded.
    fn skipped_bytes(&mut self) -> &mut u32;
}

/// A packet type a protocol's framing decodes (each protocol has one for
/// each direction, status and instruction).
pub trait Framed<const N: usize>: Sized {
    /// The bytes that start every packet.
    const HEADER: &'static [u8];
    /// The smallest packet's length: a decoder of fewer bytes could never
    /// complete one.
    const MIN_PACKET: usize;
    /// The reply a decoder can be told to expect (see [`Decoder::expect`]).
    type Reply: Copy + core::fmt::Debug;
    /// Why a candidate was refused.
    type Error: Copy + core::fmt::Debug;
    /// The decoder's counters.
    type Stats: Counters + Copy + core::fmt::Debug;
    /// The counters at creation.
    const NO_STATS: Self::Stats;
    /// Counts a refusal in its counter.
    fn count(stats: &mut Self::Stats, error: &Self::Error);
    /// Examines `buf`, which starts with [`Self::HEADER`] and holds at most
    /// `N` bytes, for a packet or a refusal, given the reply expected.
    fn examine(buf: &[u8], expected: Option<Self::Reply>) -> Step<Self, Self::Error>;
}

/// Implements [`Framed`] for each packet type named, all with one
/// protocol's framing: its header, smallest packet, reply, error and
/// counters (whose `packets` and `skipped_bytes` fields make
/// [`Counters`]), and its `count` and `examine` functions.
#[macro_export]
#[doc(hidden)]
macro_rules! framed {
    (header: $header:expr, min: $min:expr, reply: $reply:ty, error: $error:ty, stats: $stats:ty = $none:expr,
     count: $count:path, examine: $examine:path, packets: [$($packet:ident),*]) => {
        impl $crate::framing::Counters for $stats {
            fn packets(&mut self) -> &mut u32 {
                &mut self.packets
            }
            fn skipped_bytes(&mut self) -> &mut u32 {
                &mut self.skipped_bytes
            }
        }
        $(
            impl<const N: usize> $crate::framing::Framed<N> for $packet<N> {
                const HEADER: &'static [u8] = &$header;
                const MIN_PACKET: usize = $min;
                type Reply = $reply;
                type Error = $error;
                type Stats = $stats;
                const NO_STATS: $stats = $none;
                fn count(stats: &mut $stats, error: &$error) {
                    $count(stats, error)
                }
                fn examine(buf: &[u8], expected: Option<$reply>) -> $crate::framing::Step<Self, $error> {
                    $examine(buf, expected)
                }
            }
        )*
    };
}

/// Adds one to a counter, saturating.
pub fn bump(counter: &mut u32) {
    *counter = counter.saturating_add(1);
}

/// The first index from which `buf` can be the start of a packet: where
/// `header` begins, or where the bytes left are a beginning of it. It is
/// `buf.len()` if there is none.
pub fn header_start(buf: &[u8], header: &[u8]) -> usize {
    (0..buf.len())
        .find(|&i| {
            let rest = &buf[i..];
            let n = rest.len().min(header.len());
            rest[..n] == header[..n]
        })
        .unwrap_or(buf.len())
}

#[cfg(test)]
mod tests {
    use super::header_start;

    #[test]
    fn the_header_is_found_whole_or_begun() {
        assert_eq!(header_start(&[1, 2, 0xFF, 0xFF, 3], &[0xFF, 0xFF]), 2);
        assert_eq!(header_start(&[1, 0xFF], &[0xFF, 0xFF]), 1);
        assert_eq!(header_start(&[0xFF, 1, 0xFF, 0xFF, 0xFD, 0], &[0xFF, 0xFF, 0xFD, 0]), 2);
        assert_eq!(header_start(&[0xFF, 0xFF, 0xFF, 0xFD, 0], &[0xFF, 0xFF, 0xFD, 0]), 1);
        assert_eq!(header_start(&[1, 2, 3], &[0xFF, 0xFF]), 3);
        assert_eq!(header_start(&[], &[0xFF, 0xFF]), 0);
    }
}
