//! Where an agent keeps its weights: a table of [`Q16`] values however a
//! board stores it ([`WeightStore`]).
//!
//! The agent reads and writes weights only through this trait, so a
//! board's memory can shape its table without touching the learner:
//!
//! - any `AsRef<[Q16]> + AsMut<[Q16]>` (an array, a boxed slice, a
//!   `&'static mut` table in a chosen RAM section) stores full Q15.16
//!   weights, 4 bytes each ([`WeightFormat::Q16`]);
//! - [`Split`] puts the first part of one table in one memory and the rest
//!   in another (the F405's 64 KB of CCM and part of its SRAM, which are not
//!   contiguous);
//! - [`Half`] stores 16-bit weights, 2 bytes each ([`WeightFormat::Half`]),
//!   with stochastic rounding: an update smaller than the 16-bit step is
//!   applied with the probability of its fraction, so small updates are not
//!   lost but kept in expectation. The dither comes from the agent's own
//!   generator, so a replay with the same seed stays bit for bit.
//!
//! Every access is total: an index out of range reads 0 and writes
//! nothing (the tile coder never produces one; this keeps the chip free of
//! panics).

use crate::claims::{Claim, InitialWeights, Occupancy, WhenFull};
use crate::fixed::Q16;

/// How weights are stored: part of a board's learner profile and of the
/// configuration hash, since it changes what the learner can represent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WeightFormat {
    /// Q15.16 in an `i32`: ±32768 in steps of 2⁻¹⁶.
    Q16,
    /// An `i16` holding `Q16 >> shift`: ±2^(15 + shift − 16) in steps of
    /// 2^(shift − 16), rounded stochastically.
    Half {
        /// Right shift from Q15.16, 1 ..= 16.
        shift: u8,
    },
}

impl WeightFormat {
    /// Bytes per stored weight.
    pub const fn bytes(self) -> usize {
        match self {
            WeightFormat::Q16 => 4,
            WeightFormat::Half { .. } => 2,
        }
    }

    /// A stable number for the configuration hash.
    pub const fn code(self) -> u32 {
        match self {
            WeightFormat::Q16 => 1,
            WeightFormat::Half { shift } => 0x100 | shift as u32,
        }
    }

    /// The smallest step between two stored weights, in Q16 units.
    pub const fn step(self) -> i32 {
        match self {
            WeightFormat::Q16 => 1,
            WeightFormat::Half { shift } => 1 << shift,
        }
    }
}

/// A table of weights.
pub trait WeightStore {
    /// Whether [`add`](Self::add) rounds stochastically: the agent then
    /// draws one dither per weight write, otherwise none (so full-width
    /// tables draw exactly what they always drew). A method, not a
    /// constant, so that one host type can hold either kind of table.
    #[inline]
    fn dithered(&self) -> bool {
        false
    }


    /// Number of weights.
    fn len(&self) -> usize;

    /// Whether the table is empty.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Weight `i` (0 outside the table).
    fn get(&self, i: usize) -> Q16;

    /// Sets weight `i` to the nearest storable value (saturating).
    fn set(&mut self, i: usize, w: Q16);

    /// Adds `inc` to weight `i`, saturating at the format's range; `dither`
    /// is a uniform `u32` for stochastic rounding (ignored unless
    /// [`dithered`](Self::dithered)). Returns whether the weight
    /// saturated.
    fn add(&mut self, i: usize, inc: Q16, dither: u32) -> bool;

    /// The storage format.
    fn format(&self) -> WeightFormat;

    /// The stored bytes of weight `i`, little endian, into
    /// `out[..format().bytes()]`.
    fn stored_le(&self, i: usize, out: &mut [u8]);

    /// Sets weight `i` from bytes written by [`stored_le`](Self::stored_le).
    fn load_le(&mut self, i: usize, bytes: &[u8]);

    /// The stored bits of weight `i` (the `i32` of a full-width weight, the
    /// `i16` of a 16-bit one, sign-extended), 0 outside the table.
    fn raw(&self, i: usize) -> u32;

    /// Whether features claim their slots ([`crate::claim_table`]): then
    /// the agent reads through [`read`](Self::read), claims through
    /// [`claim`](Self::claim) before it writes, and the features it hands
    /// in are full 32-bit keys, not slots. A plain table (`false`) reads
    /// and writes the feature's index directly. (A method, not a constant,
    /// so that one host type can hold either kind of table.)
    #[inline]
    fn claims(&self) -> bool {
        false
    }

    /// Bytes of a claim tag stored after each weight (0: no tags).
    fn tag_bytes(&self) -> usize {
        0
    }

    /// Bytes per stored entry: the weight's, then its tag's
    /// ([`stored_le`](Self::stored_le) writes both).
    fn entry_bytes(&self) -> usize {
        self.format().bytes() + self.tag_bytes()
    }

    /// The weight of `feature`: the weight at that index in a plain table,
    /// the feature's slot's (or its initial weight) in a claim table.
    #[inline]
    fn read(&self, feature: u32) -> Q16 {
        self.get(feature as usize)
    }

    /// [`read`](Self::read) of every feature in `buf`, each replaced by
    /// its weight's bits (`Q16.0 as u32`). One call per batch, so that a
    /// table behind a dispatch dispatches once, and the loop keeps the
    /// table's fields in registers. The reads are independent, so a
    /// processor that executes ahead overlaps their cache misses.
    #[inline]
    fn read_each(&self, buf: &mut [u32]) {
        for x in buf {
            *x = self.read(*x).0 as u32;
        }
    }

    /// The slot a learning update of `feature` writes: the index itself in
    /// a plain table (never fresh), the claimed slot in a claim table.
    #[inline]
    fn claim(&mut self, feature: u32) -> Claim {
        Claim::Slot { slot: feature, fresh: false }
    }

    /// [`read`](Self::read) of every feature in `features`, then
    /// [`claim`](Self::claim) of each in order (a learning update needs
    /// the pair's `Q` and the slots it writes): the claims go to `claims`,
    /// the sum of the weights read is returned. A claim table does both
    /// with one probe per feature where it can
    /// ([`ClaimTable::read_then_claim`](crate::claim_table::ClaimTable::read_then_claim)).
    fn read_then_claim(&mut self, features: &[u32], claims: &mut [Claim]) -> i64 {
        let sum = features.iter().map(|&f| self.read(f).0 as i64).sum();
        for (claim, &f) in claims.iter_mut().zip(features) {
            *claim = self.claim(f);
        }
        sum
    }

    /// [`add`](Self::add) of `inc` to the weight of each slot in `slots`,
    /// in order; a slot outside the table is skipped (a refused claim's
    /// `u32::MAX`). A [`dithered`](Self::dithered) table takes one draw
    /// from `dither` per weight it writes, others none. Returns the
    /// saturations and the change of the [`checksum`](Self::checksum).
    /// One call per trace entry, so that a table behind a dispatch (the
    /// host's one type for every table) dispatches once per entry rather
    /// than three times per weight.
    fn add_each<D: FnMut() -> u32>(&mut self, slots: &[u32], inc: Q16, mut dither: D) -> Added
    where
        Self: Sized,
    {
        let dithered = self.dithered();
        let mut out = Added::default();
        for &slot in slots {
            let i = slot as usize;
            if i >= self.len() {
                continue;
            }
            let d = if dithered { dither() } else { 0 };
            let old = self.raw(i);
            out.saturations += self.add(i, inc, d) as u32;
            let change = self.raw(i).wrapping_sub(old);
            out.checksum_change = out.checksum_change.wrapping_add(change.wrapping_mul(entry_factor(i)));
        }
        out
    }

    /// Frees every slot of a claim table and sets its unclaimed features'
    /// initial weights (nothing in a plain table).
    fn reset_claims(&mut self, _init: InitialWeights) {}

    /// After a claim table's slots were loaded: its initial weights and the
    /// refusals saved with it (nothing in a plain table).
    fn restore_claims(&mut self, _init: InitialWeights, _refused: u32) {}

    /// What a claim table does when a claim finds it full
    /// ([`WhenFull::Refuse`] for a plain table, which never claims).
    fn when_full(&self) -> WhenFull {
        WhenFull::Refuse
    }

    /// A claim table's occupancy; `None` for a plain table.
    fn occupancy(&self) -> Option<Occupancy> {
        None
    }

    /// A claim table's seed of its initial weights (0 for a plain table).
    fn table_seed(&self) -> u64 {
        0
    }

    /// The table's checksum, `Σ raw(i) · entry_factor(i)` (wrapping,
    /// [`entry_factor`]): equal on every machine for equal tables, and cheap
    /// to keep up to date one write at a time ([`crate::agent::Agent`]
    /// does), so that a board with millions of weights need not read them
    /// all at every episode's end.
    fn checksum(&self) -> u32 {
        (0..self.len()).fold(0u32, |sum, i| sum.wrapping_add(self.raw(i).wrapping_mul(entry_factor(i))))
    }
}

/// What [`WeightStore::add_each`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Added {
    /// Writes that hit the format's range and saturated.
    pub saturations: u32,
    /// What the writes added to the table's checksum (wrapping).
    pub checksum_change: u32,
}

/// The multiplier of weight `i` in the table checksum: `(2i + 1)·φ`, with
/// φ = 0x9E37_79B9 (the golden ratio's 32-bit fraction), odd for every `i`.
/// The checksum is `Σ raw_i · entry_factor(i)` (wrapping), linear in each
/// weight, so a write changes it by `(new − old) · entry_factor(i)`: one
/// multiplication, which the chip can afford on every weight write. An odd
/// factor is invertible modulo 2³², so any single change of a weight
/// changes the checksum; it is a check that two learners stayed the same
/// (a replay), not a cryptographic hash.
#[inline]
pub fn entry_factor(i: usize) -> u32 {
    (2 * i as u32).wrapping_add(1).wrapping_mul(0x9E37_79B9)
}

impl<T: AsRef<[Q16]> + AsMut<[Q16]> + ?Sized> WeightStore for T {
    fn len(&self) -> usize {
        self.as_ref().len()
    }

    #[inline]
    fn raw(&self, i: usize) -> u32 {
        self.get(i).0 as u32
    }

    #[inline]
    fn get(&self, i: usize) -> Q16 {
        self.as_ref().get(i).copied().unwrap_or(Q16::ZERO)
    }

    #[inline]
    fn set(&mut self, i: usize, w: Q16) {
        if let Some(slot) = self.as_mut().get_mut(i) {
            *slot = w;
        }
    }

    #[inline]
    fn add(&mut self, i: usize, inc: Q16, _dither: u32) -> bool {
        match self.as_mut().get_mut(i) {
            Some(w) => {
                *w = w.saturating_add(inc);
                *w == Q16::MAX || *w == Q16::MIN
            }
            None => false,
        }
    }

    fn format(&self) -> WeightFormat {
        WeightFormat::Q16
    }

    fn stored_le(&self, i: usize, out: &mut [u8]) {
        if let Some(dst) = out.get_mut(..4) {
            dst.copy_from_slice(&self.get(i).0.to_le_bytes());
        }
    }

    fn load_le(&mut self, i: usize, bytes: &[u8]) {
        if let Some(&[a, b, c, d]) = bytes.get(..4) {
            self.set(i, Q16(i32::from_le_bytes([a, b, c, d])));
        }
    }
}

/// One table in two stores: indices below `first.len()` in `first`, the
/// rest in `second` (two memories that are not contiguous). Both must have
/// the same format.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Split<A, B> {
    /// The first part.
    pub first: A,
    /// The rest.
    pub second: B,
}

impl<A: WeightStore, B: WeightStore> WeightStore for Split<A, B> {
    #[inline]
    fn dithered(&self) -> bool {
        self.first.dithered() || self.second.dithered()
    }

    fn len(&self) -> usize {
        self.first.len() + self.second.len()
    }

    #[inline]
    fn raw(&self, i: usize) -> u32 {
        let n = self.first.len();
        if i < n {
            self.first.raw(i)
        } else {
            self.second.raw(i - n)
        }
    }

    #[inline]
    fn get(&self, i: usize) -> Q16 {
        let n = self.first.len();
        if i < n {
            self.first.get(i)
        } else {
            self.second.get(i - n)
        }
    }

    #[inline]
    fn set(&mut self, i: usize, w: Q16) {
        let n = self.first.len();
        if i < n {
            self.first.set(i, w)
        } else {
            self.second.set(i - n, w)
        }
    }

    #[inline]
    fn add(&mut self, i: usize, inc: Q16, dither: u32) -> bool {
        let n = self.first.len();
        if i < n {
            self.first.add(i, inc, dither)
        } else {
            self.second.add(i - n, inc, dither)
        }
    }

    fn format(&self) -> WeightFormat {
        self.first.format()
    }

    fn stored_le(&self, i: usize, out: &mut [u8]) {
        let n = self.first.len();
        if i < n {
            self.first.stored_le(i, out)
        } else {
            self.second.stored_le(i - n, out)
        }
    }

    fn load_le(&mut self, i: usize, bytes: &[u8]) {
        let n = self.first.len();
        if i < n {
            self.first.load_le(i, bytes)
        } else {
            self.second.load_le(i - n, bytes)
        }
    }
}

/// 16-bit weights: each `i16` holds a Q15.16 weight shifted right by
/// `SHIFT` bits, so the table covers ±2^(SHIFT − 1) in steps of
/// 2^(SHIFT − 16) (`SHIFT` = 12: ±2048 in steps of 1/16).
///
/// Writes round stochastically: `w + inc` lands on one of its two
/// neighbouring storable values, the upper one with probability equal to
/// the fraction of the step it covers, decided by the dither. The expected
/// stored value is then exactly `w + inc` (updates far below the step are
/// not lost, only applied now and then), and the rounding error of many
/// updates averages out instead of piling up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Half<T, const SHIFT: u32> {
    /// The stored weights.
    pub data: T,
}

impl<T, const SHIFT: u32> Half<T, SHIFT> {
    const _VALID: () = assert!(SHIFT >= 1 && SHIFT <= 16, "Half: 1 <= SHIFT <= 16");

    /// A table over `data`.
    pub const fn new(data: T) -> Self {
        #[allow(clippy::let_unit_value)]
        let _ = Self::_VALID;
        Half { data }
    }
}

/// The `i16` nearest to `raw / 2^shift` (ties away from zero), saturating.
fn to_half(raw: i32, shift: u32) -> i16 {
    let half = 1i64 << (shift - 1);
    let x = raw as i64;
    let q = if x >= 0 { (x + half) >> shift } else { -((-x + half) >> shift) };
    q.clamp(i16::MIN as i64, i16::MAX as i64) as i16
}

impl<T: AsRef<[i16]> + AsMut<[i16]>, const SHIFT: u32> WeightStore for Half<T, SHIFT> {
    #[inline]
    fn dithered(&self) -> bool {
        true
    }

    fn len(&self) -> usize {
        self.data.as_ref().len()
    }

    #[inline]
    fn raw(&self, i: usize) -> u32 {
        self.data.as_ref().get(i).copied().unwrap_or(0) as i32 as u32
    }

    #[inline]
    fn get(&self, i: usize) -> Q16 {
        Q16((self.data.as_ref().get(i).copied().unwrap_or(0) as i32) << SHIFT)
    }

    fn set(&mut self, i: usize, w: Q16) {
        if let Some(slot) = self.data.as_mut().get_mut(i) {
            *slot = to_half(w.0, SHIFT);
        }
    }

    #[inline]
    fn add(&mut self, i: usize, inc: Q16, dither: u32) -> bool {
        let Some(slot) = self.data.as_mut().get_mut(i) else {
            return false;
        };
        // In units of the step: the whole part, and the fraction left over
        // (0 ≤ frac < 2^SHIFT), which rounds up when the dither's top SHIFT
        // bits fall below it.
        let sum = ((*slot as i64) << SHIFT) + inc.0 as i64;
        let whole = sum >> SHIFT;
        let frac = (sum - (whole << SHIFT)) as u64;
        let up = ((dither as u64) >> (32 - SHIFT)) < frac;
        let next = whole + up as i64;
        let clamped = next.clamp(i16::MIN as i64, i16::MAX as i64);
        *slot = clamped as i16;
        clamped != next || clamped == i16::MAX as i64 || clamped == i16::MIN as i64
    }

    fn format(&self) -> WeightFormat {
        WeightFormat::Half { shift: SHIFT as u8 }
    }

    fn stored_le(&self, i: usize, out: &mut [u8]) {
        if let Some(dst) = out.get_mut(..2) {
            dst.copy_from_slice(&self.data.as_ref().get(i).copied().unwrap_or(0).to_le_bytes());
        }
    }

    fn load_le(&mut self, i: usize, bytes: &[u8]) {
        if let (Some(&[a, b]), Some(slot)) = (bytes.get(..2), self.data.as_mut().get_mut(i)) {
            *slot = i16::from_le_bytes([a, b]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_width_tables_behave_as_slices() {
        let mut t = [Q16::ZERO; 4];
        t.set(1, Q16(7));
        assert!(!t.add(1, Q16(3), 0));
        assert_eq!(t.get(1), Q16(10));
        assert_eq!(t.get(99), Q16::ZERO, "out of range reads 0");
        t.set(99, Q16(1));
        assert!(!t.add(99, Q16(1), 0), "out of range writes nothing");
        assert!(t.add(2, Q16::MAX, 0), "saturation is reported");
        let mut b = [0u8; 4];
        t.stored_le(1, &mut b);
        assert_eq!(b, 10i32.to_le_bytes());
    }

    #[test]
    fn split_tables_address_both_parts() {
        let mut s = Split { first: [Q16::ZERO; 3], second: [Q16::ZERO; 2] };
        assert_eq!(s.len(), 5);
        for i in 0..5 {
            s.set(i, Q16(i as i32 + 1));
        }
        assert_eq!(s.first, [Q16(1), Q16(2), Q16(3)]);
        assert_eq!(s.second, [Q16(4), Q16(5)]);
        let whole = [Q16(1), Q16(2), Q16(3), Q16(4), Q16(5)];
        assert_eq!(s.checksum(), whole.checksum());
        assert_eq!(s.get(5), Q16::ZERO);
    }

    #[test]
    fn half_rounds_to_nearest_on_set_and_keeps_small_updates_in_expectation() {
        let mut h = Half::<_, 12>::new([0i16; 2]);
        h.set(0, Q16::from_f32(1.0 + 1.0 / 64.0));
        assert_eq!(h.get(0), Q16::from_f32(1.0), "nearest step of 1/16");
        h.set(1, Q16::from_f32(1.0e6));
        assert_eq!(h.data[1], i16::MAX, "saturates");
        // 1000 updates of 1/160 (a tenth of the step) with uniform dither:
        // about 100 of them move the weight up one step, so the weight
        // grows by about 1000/160 = 6.25.
        let mut h = Half::<_, 12>::new([0i16; 1]);
        let inc = Q16::from_f32(1.0 / 160.0);
        let mut x: u32 = 12345;
        for _ in 0..1000 {
            x = x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            h.add(0, inc, x);
        }
        let got = h.get(0).to_f32();
        assert!((got - 6.25).abs() < 1.0, "{got}");
        // Dither 0 rounds every positive fraction up, u32::MAX rounds down.
        let mut h = Half::<_, 12>::new([0i16; 1]);
        h.add(0, Q16(1), 0);
        assert_eq!(h.data[0], 1);
        let mut h = Half::<_, 12>::new([0i16; 1]);
        h.add(0, Q16(1), u32::MAX);
        assert_eq!(h.data[0], 0);
        // Negative increments round the same way (floor plus a coin).
        let mut h = Half::<_, 12>::new([0i16; 1]);
        h.add(0, Q16(-1), u32::MAX);
        assert_eq!(h.data[0], -1);
        // Exact multiples of the step are exact.
        let mut h = Half::<_, 12>::new([5i16; 1]);
        h.add(0, Q16(3 << 12), 0);
        assert_eq!(h.data[0], 8);
        assert!(h.add(0, Q16::MAX, 0), "saturation is reported");
        assert_eq!(h.data[0], i16::MAX);
    }

    #[test]
    fn half_stores_two_bytes() {
        let h = Half::<_, 12>::new([-2i16; 3]);
        assert_eq!(h.format().bytes(), 2);
        let mut b = [0u8; 2];
        h.stored_le(1, &mut b);
        assert_eq!(b, (-2i16).to_le_bytes());
        let mut g = Half::<_, 12>::new([0i16; 3]);
        g.load_le(1, &b);
        assert_eq!(g.data, [0, -2, 0]);
    }

    #[test]
    fn the_checksum_sees_any_single_change_and_is_the_running_sum() {
        let mut t = [Q16::ZERO; 64];
        for (i, w) in t.iter_mut().enumerate() {
            *w = Q16((i as i32 - 30) * 977);
        }
        let base = t.checksum();
        for i in [0usize, 1, 31, 63] {
            for delta in [1i32, -1, 2, 1 << 16, i32::MIN] {
                let mut u = t;
                u[i] = Q16(u[i].0.wrapping_add(delta));
                assert_ne!(u.checksum(), base, "weight {i} changed by {delta}");
                // The running update of one write gives the whole sum.
                let change = (u[i].0 as u32).wrapping_sub(t[i].0 as u32);
                assert_eq!(base.wrapping_add(change.wrapping_mul(entry_factor(i))), u.checksum());
            }
        }
    }
}
