//! PCG32 whose state can be saved and restored.
//!
//! [`Pcg32`] is the generator `pcg32` (PCG-XSH-RR 64/32 on a 64-bit LCG
//! with a chosen stream), written to give **bit-identical** output to
//! `rand_pcg::Pcg32` (rand_pcg 0.9, `Lcg64Xsh32`): the same
//! [`SeedableRng::from_seed`] and `seed_from_u64` (rand_core's default,
//! not overridden), the same `next_u32`, and `next_u64`/`fill_bytes` built
//! from `next_u32` in the same little-endian order. The host keeps using
//! `rand_pcg::Pcg32`; `shared/tests/learner_state.rs` checks the two against
//! each other draw for draw.
//!
//! What rand_pcg does not offer on the chip is reading the state back. Its
//! fields are private; its `serde` feature would expose them, but it
//! depends on serde with serde's default features (rand_pcg 0.9's manifest
//! does not set `default-features = false`), which turns on serde's `std`
//! and so cannot build for `thumbv7em-none-eabihf`. Hence this copy of its
//! twenty lines of arithmetic. [`Pcg32::state`] gives the two words
//! ([`RngState`]) and [`Pcg32::from_state`] continues exactly where they
//! were taken, so a checkpoint can carry the generator
//! (`crate::checkpoint`).

use crate::error::ConfigError;
use rand_core::{RngCore, SeedableRng};

/// The LCG multiplier of PCG with 64-bit state.
const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// The two words of a [`Pcg32`]: the LCG state and its (odd) increment,
/// which selects the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RngState {
    /// The LCG state before the next draw.
    pub state: u64,
    /// The LCG increment; always odd.
    pub increment: u64,
}

impl RngState {
    /// Checks that the increment is odd (an even one is no PCG stream).
    pub fn check(&self) -> Result<(), ConfigError> {
        if self.increment & 1 == 1 {
            Ok(())
        } else {
            Err(ConfigError::new("rng.increment", (self.increment & 0xFF) as f32, "an odd increment"))
        }
    }
}

/// PCG-XSH-RR 64/32, output-compatible with `rand_pcg::Pcg32` (see the
/// module documentation), with its state readable.
#[derive(Clone, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    increment: u64,
}

// Like rand_pcg's: the state is not printed.
impl core::fmt::Debug for Pcg32 {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Pcg32 {}")
    }
}

impl Pcg32 {
    /// As `rand_pcg::Pcg32::new(state, stream)`: the stream's highest bit
    /// is discarded, and the state is moved away from the given value.
    pub fn new(state: u64, stream: u64) -> Self {
        Self::from_state_incr(state, (stream << 1) | 1)
    }

    fn from_state_incr(state: u64, increment: u64) -> Self {
        let mut pcg = Pcg32 { state: state.wrapping_add(increment), increment };
        pcg.step();
        pcg
    }

    /// The generator's two words: [`from_state`](Self::from_state) with them
    /// continues with the very next draw.
    pub fn state(&self) -> RngState {
        RngState { state: self.state, increment: self.increment }
    }

    /// The generator exactly where [`state`](Self::state) left it; an even
    /// increment is refused (`rng.increment`).
    pub fn from_state(s: RngState) -> Result<Self, ConfigError> {
        s.check()?;
        Ok(Pcg32 { state: s.state, increment: s.increment })
    }

    #[inline]
    fn step(&mut self) {
        self.state = self.state.wrapping_mul(MULTIPLIER).wrapping_add(self.increment);
    }
}

impl SeedableRng for Pcg32 {
    type Seed = [u8; 16];

    /// As rand_pcg: the first eight bytes are the state, the next eight the
    /// increment with its lowest bit forced to 1 (little endian).
    fn from_seed(seed: Self::Seed) -> Self {
        let mut lo = [0u8; 8];
        let mut hi = [0u8; 8];
        lo.copy_from_slice(&seed[..8]);
        hi.copy_from_slice(&seed[8..]);
        Self::from_state_incr(u64::from_le_bytes(lo), u64::from_le_bytes(hi) | 1)
    }
}

impl RngCore for Pcg32 {
    #[inline]
    fn next_u32(&mut self) -> u32 {
        let state = self.state;
        self.step();
        // XSH RR: xorshift high bits, then a random rotation.
        let rot = (state >> 59) as u32;
        let xsh = (((state >> 18) ^ state) >> 27) as u32;
        xsh.rotate_right(rot)
    }

    #[inline]
    fn next_u64(&mut self) -> u64 {
        // rand_core's `next_u64_via_u32`: low word first.
        let lo = u64::from(self.next_u32());
        let hi = u64::from(self.next_u32());
        (hi << 32) | lo
    }

    fn fill_bytes(&mut self, dest: &mut [u8]) {
        // rand_core's `fill_bytes_via_next`: whole u64s, then one u64 for
        // 5–7 bytes left or one u32 for 1–4.
        let mut chunks = dest.chunks_exact_mut(8);
        for chunk in &mut chunks {
            chunk.copy_from_slice(&self.next_u64().to_le_bytes());
        }
        let rest = chunks.into_remainder();
        let n = rest.len();
        if n > 4 {
            rest.copy_from_slice(&self.next_u64().to_le_bytes()[..n]);
        } else if n > 0 {
            rest.copy_from_slice(&self.next_u32().to_le_bytes()[..n]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pcg32_reference_stream() {
        // The PCG reference (pcg32-demo, seed 42, stream 54) as rand_pcg's
        // own test of `Lcg64Xsh32::new(42, 54)`.
        let mut rng = Pcg32::new(42, 54);
        let expected = [0xa15c02b7u32, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e];
        for e in expected {
            assert_eq!(rng.next_u32(), e);
        }
    }

    #[test]
    fn state_round_trip_continues_the_sequence() {
        let mut a = Pcg32::seed_from_u64(7);
        for _ in 0..10 {
            a.next_u32();
        }
        let mut b = Pcg32::from_state(a.state()).unwrap();
        for _ in 0..100 {
            assert_eq!(a.next_u32(), b.next_u32());
        }
        assert_eq!(
            Pcg32::from_state(RngState { state: 1, increment: 2 }).unwrap_err().param,
            "rng.increment"
        );
    }
}
