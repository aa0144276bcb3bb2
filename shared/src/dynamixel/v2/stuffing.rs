//! Byte stuffing (e-Manual, "DYNAMIXEL Protocol 2.0", § "Packet Process").
//!
//! Sending: from the INSTRUCTION byte to the last parameter (never the
//! CRC), every `FF FF FD` gets one more `FD` (`FF FF FD FD`), so that a
//! header `FF FF FD 00` never appears inside a packet; LENGTH and the CRC
//! are those of the stuffed bytes. Receiving: once the CRC matches, each
//! `FF FF FD FD` loses its extra `FD`.
//!
//! A stuffed payload therefore never holds a bare `FF FF FD` followed by
//! anything but `FD`. [`destuff`] refuses one ([`StuffingError::Bare`]): a
//! sender that does not stuff is broken, and accepting its packet would
//! break the rule that an accepted packet re-encodes to the bytes received
//! (the re-encoding would gain an `FD`). The ROBOTIS SDK's
//! `removeStuffing` leaves such bytes as they are; pada is stricter.
//!
//! The Fast Sync Read and Fast Bulk Read replies are not stuffed (e-Manual,
//! § "Fast Sync Read": "does not perform Byte Stuffing"); the packet layer
//! decides which packets are ([`super::packet::is_stuffed`]).

use heapless::Vec;

/// The byte sequence that gets a stuffing byte after it.
pub const PATTERN: [u8; 3] = [0xFF, 0xFF, 0xFD];
/// The stuffing byte.
pub const STUFF: u8 = 0xFD;

/// The most bytes `n` payload bytes can take once stuffed: one extra byte
/// per three (`FF FF FD` patterns cannot overlap, as `FD` is not `FF`).
pub const fn max_stuffed_len(n: usize) -> usize {
    n + n / 3
}

/// Why a received payload is not a correctly stuffed one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StuffingError {
    /// `FF FF FD` at this offset of the stuffed payload is not followed by
    /// the stuffing `FD`.
    Bare {
        /// Offset of the pattern's first byte.
        at: usize,
    },
    /// The unstuffed bytes do not fit the output's capacity.
    Overflow,
}

/// Streams bytes through the stuffing rule: tracks the `FF` run so that an
/// `FD` after two `FF` is doubled.
#[derive(Debug, Clone, Copy, Default)]
struct Run {
    ffs: u8,
}

impl Run {
    /// Whether `b` completes the pattern (and so must be followed by the
    /// stuffing byte); updates the run.
    fn completes(&mut self, b: u8) -> bool {
        let hit = b == STUFF && self.ffs >= 2;
        self.ffs = if b == 0xFF { (self.ffs + 1).min(2) } else { 0 };
        hit
    }
}

/// The length of `payload` once stuffed.
pub fn stuffed_len(payload: impl Iterator<Item = u8>) -> usize {
    let mut run = Run::default();
    payload.map(|b| if run.completes(b) { 2 } else { 1 }).sum()
}

/// Writes `payload` stuffed into `out`, returning the bytes written, or
/// `None` if `out` is too short.
pub fn stuff_into(payload: impl Iterator<Item = u8>, out: &mut [u8]) -> Option<usize> {
    let mut run = Run::default();
    let mut n = 0;
    for b in payload {
        *out.get_mut(n)? = b;
        n += 1;
        if run.completes(b) {
            *out.get_mut(n)? = STUFF;
            n += 1;
        }
    }
    Some(n)
}

/// Removes the stuffing from a received payload, appending the bytes to
/// `out`.
pub fn destuff<const N: usize>(stuffed: &[u8], out: &mut Vec<u8, N>) -> Result<(), StuffingError> {
    let mut run = Run::default();
    let mut i = 0;
    while let Some(&b) = stuffed.get(i) {
        out.push(b).map_err(|_| StuffingError::Overflow)?;
        if run.completes(b) {
            if stuffed.get(i + 1) != Some(&STUFF) {
                return Err(StuffingError::Bare { at: i - 2 });
            }
            i += 1; // the stuffing byte
        }
        i += 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stuff(p: &[u8]) -> std::vec::Vec<u8> {
        let mut out = [0u8; 64];
        let n = stuff_into(p.iter().copied(), &mut out).unwrap();
        assert_eq!(n, stuffed_len(p.iter().copied()));
        out[..n].to_vec()
    }

    extern crate std;

    #[test]
    fn the_pattern_gets_one_fd() {
        // e-Manual, "Packet Process": "FF FF FD" becomes "FF FF FD FD".
        assert_eq!(stuff(&[0xFF, 0xFF, 0xFD]), [0xFF, 0xFF, 0xFD, 0xFD]);
        // An already stuffed-looking sequence gets one more (e-Manual: "If
        // FF FF FD already exists, add a 0xFD").
        assert_eq!(stuff(&[0xFF, 0xFF, 0xFD, 0xFD]), [0xFF, 0xFF, 0xFD, 0xFD, 0xFD]);
        // A run of three FF before FD: the pattern is its last two.
        assert_eq!(stuff(&[0xFF, 0xFF, 0xFF, 0xFD, 0x00]), [0xFF, 0xFF, 0xFF, 0xFD, 0xFD, 0x00]);
        // Two patterns back to back, and no pattern.
        assert_eq!(stuff(&[0xFF, 0xFF, 0xFD, 0xFF, 0xFF, 0xFD]), [0xFF, 0xFF, 0xFD, 0xFD, 0xFF, 0xFF, 0xFD, 0xFD]);
        assert_eq!(stuff(&[0xFF, 0xFD, 0xFF, 0x00, 0xFD]), [0xFF, 0xFD, 0xFF, 0x00, 0xFD]);
        assert_eq!(max_stuffed_len(6), 8);
        assert_eq!(stuff_into([0xFF, 0xFF, 0xFD].into_iter(), &mut [0u8; 3]), None);
    }

    #[test]
    fn destuffing_inverts_and_refuses_bare_patterns() {
        let mut v: Vec<u8, 16> = Vec::new();
        destuff(&[0x01, 0xFF, 0xFF, 0xFD, 0xFD, 0x00], &mut v).unwrap();
        assert_eq!(&v[..], &[0x01, 0xFF, 0xFF, 0xFD, 0x00]);
        v.clear();
        assert_eq!(destuff(&[0x01, 0xFF, 0xFF, 0xFD, 0x00], &mut v), Err(StuffingError::Bare { at: 1 }));
        v.clear();
        assert_eq!(destuff(&[0xFF, 0xFF, 0xFD], &mut v), Err(StuffingError::Bare { at: 0 }));
        let mut small: Vec<u8, 2> = Vec::new();
        assert_eq!(destuff(&[1, 2, 3], &mut small), Err(StuffingError::Overflow));
    }
}
