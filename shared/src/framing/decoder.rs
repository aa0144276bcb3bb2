//! The incremental decoder every protocol shares: a fixed buffer of `N`
//! bytes that always starts at a candidate header, the protocol's
//! [`Framed::examine`] deciding on what it holds, and the counters.

use super::{bump, header_start, Counters, Framed, Step};
use core::marker::PhantomData;

/// Incremental decoder of packets `P` of up to `N` bytes (header to check,
/// as received). Feed it bytes with [`push`](Self::push) or
/// [`feed`](Self::feed).
///
/// `N` must hold the protocol's smallest packet ([`Framed::MIN_PACKET`]:
/// 6 bytes for Protocol 1.0 and Feetech, 11 for a Protocol 2.0 status
/// packet); a smaller decoder does not compile.
#[derive(Debug, Clone)]
pub struct Decoder<P: Framed<N>, const N: usize> {
    buf: [u8; N],
    len: usize,
    stats: P::Stats,
    expected: Option<P::Reply>,
    _packet: PhantomData<fn() -> P>,
}

impl<P: Framed<N>, const N: usize> Default for Decoder<P, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<P: Framed<N>, const N: usize> Decoder<P, N> {
    /// A decoder that accepts any ID and length; `N` below the protocol's
    /// smallest packet is a compile-time error naming the valid range.
    pub const fn new() -> Self {
        const {
            assert!(
                N >= P::MIN_PACKET,
                "Decoder capacity N is too small: valid is N >= the protocol's smallest packet (Protocol 1.0 and Feetech: 6 bytes; Protocol 2.0 status: 11)"
            )
        };
        Decoder { buf: [0; N], len: 0, stats: P::NO_STATS, expected: None, _packet: PhantomData }
    }

    /// Accept only `reply` (`None`: any packet). A status decoder is told
    /// before every request that has one reply. For a sync or bulk read,
    /// whose replies follow one another, drive it with
    /// [`push`](Self::push) and set the next servo's reply after each
    /// accepted packet, before [`poll`](Self::poll) looks at the bytes
    /// already buffered (or expect `None` and check the IDs afterwards).
    pub fn expect(&mut self, reply: Option<P::Reply>) {
        self.expected = reply;
    }

    /// Drops any partial packet (e.g. after a timeout, before the next
    /// request); the dropped bytes count as skipped.
    pub fn reset(&mut self) {
        self.skip(self.len);
    }

    /// Counters since creation.
    pub fn stats(&self) -> P::Stats {
        self.stats
    }

    /// Bytes held for a packet not yet complete.
    pub fn buffered(&self) -> usize {
        self.len
    }

    fn skip(&mut self, n: usize) {
        let n = n.min(self.len);
        let s = self.stats.skipped_bytes();
        *s = s.saturating_add(n as u32);
        self.buf.copy_within(n..self.len, 0);
        self.len -= n;
    }

    /// Takes one byte; returns a packet or an error if this byte completed
    /// one. After `Some`, call [`poll`](Self::poll) until `None`: the bytes
    /// kept after an error may already hold the next packet.
    pub fn push(&mut self, byte: u8) -> Option<Result<P, P::Error>> {
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
    pub fn poll(&mut self) -> Option<Result<P, P::Error>> {
        loop {
            let start = header_start(&self.buf[..self.len], P::HEADER);
            self.skip(start);
            if self.len < P::HEADER.len() {
                return None;
            }
            match P::examine(&self.buf[..self.len], self.expected) {
                Step::More => return None,
                Step::Resync => self.skip(1),
                Step::Refuse { drop, error } => {
                    P::count(&mut self.stats, &error);
                    self.skip(drop.max(1));
                    return Some(Err(error));
                }
                Step::Accept { len, packet } => {
                    let len = len.clamp(1, self.len);
                    self.buf.copy_within(len..self.len, 0);
                    self.len -= len;
                    bump(self.stats.packets());
                    return Some(Ok(packet));
                }
            }
        }
    }

    /// Feeds a chunk and iterates over every packet and error in it.
    pub fn feed<'s, 'b>(&'s mut self, bytes: &'b [u8]) -> Feed<'s, 'b, P, N> {
        Feed { decoder: self, rest: bytes }
    }
}

/// Iterator over the packets and errors of a chunk fed to a decoder. Bytes
/// of an incomplete packet at the end stay in the decoder for the next chunk.
pub struct Feed<'s, 'b, P: Framed<N>, const N: usize> {
    decoder: &'s mut Decoder<P, N>,
    rest: &'b [u8],
}

impl<P: Framed<N>, const N: usize> Iterator for Feed<'_, '_, P, N> {
    type Item = Result<P, P::Error>;
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
