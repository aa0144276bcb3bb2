//! What a packet decoder returned, counted, and the invariants every packet
//! decoder's target checks with the counts (Protocol 1.0, Feetech and 2.0
//! alike): each accepted packet encodes again to bytes that were fed, and
//! every byte fed is in an accepted packet, skipped or buffered, every
//! refusal counted once, in its own counter.

use super::{ensure, Outcome};
use core::fmt::Display;

/// [`Tally::accept`]: the accepted packet's bytes, or returns the failure
/// from the enclosing check (as [`ensure!`] does).
macro_rules! accept {
    ($tally:expr, $encoded:expr, $fed:expr, $which:expr) => {
        match $tally.accept($encoded, $fed, $which) {
            Ok(bytes) => bytes,
            Err(failed) => return failed,
        }
    };
}
pub(crate) use accept;

/// The counts of one run of a decoder whose refusals fall in `K` kinds.
pub struct Tally<const K: usize> {
    /// Packets accepted.
    oks: u32,
    /// Refusals, by kind.
    errs: [u32; K],
    /// Bytes of the accepted packets.
    accepted: usize,
}

impl<const K: usize> Tally<K> {
    pub fn new() -> Self {
        Tally { oks: 0, errs: [0; K], accepted: 0 }
    }

    /// Counts an accepted packet from its encoding again, `encoded`, which
    /// must stand in `fed`; `which` names the packet in a failure.
    pub fn accept<'b, E>(&mut self, encoded: Result<&'b [u8], E>, fed: &[u8], which: impl Display) -> Result<&'b [u8], Outcome> {
        self.oks += 1;
        let Ok(bytes) = encoded else {
            return Err(Outcome::Failed(format!("accepted packet {which} does not encode")));
        };
        if !fed.windows(bytes.len()).any(|w| w == bytes) {
            return Err(Outcome::Failed(format!("accepted packet {which} was never fed")));
        }
        self.accepted += bytes.len();
        Ok(bytes)
    }

    /// Counts a refusal of kind `kind`.
    pub fn refuse(&mut self, kind: usize) {
        self.errs[kind] += 1;
    }

    /// Checks the decoder's own counters against the counts: `packets`
    /// accepted, `refusals` by kind, `skipped` bytes, `buffered` bytes of
    /// `fed`.
    pub fn check(&self, packets: u32, refusals: [u32; K], skipped: u32, fed: usize, buffered: usize) -> Outcome {
        let (oks, errs, accepted) = (self.oks, self.errs, self.accepted);
        ensure!(packets == oks, "packets {packets} counted, {oks} returned");
        ensure!(refusals == errs, "refusals counted {refusals:?}, returned {errs:?}");
        let kept = skipped as usize + accepted + buffered;
        ensure!(
            kept == fed,
            "{fed} bytes fed, {kept} accounted for (skipped {skipped}, in packets {accepted}, buffered {buffered})"
        );
        Outcome::Ok
    }
}
