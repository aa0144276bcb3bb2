//! The claim table: a collision-free home for hashed tile-coding features,
//! the memory of the paper's framework with `safe: 1`
//! (`docs/reference/grl.md` §5.1, step 4).
//!
//! A hashed table ([`crate::tile_coding::Layout::Hashed`]) lets features
//! share a slot. That is harmless while few do; once a trial has written a
//! good part of the table, the greedy choice over LEO's 343 actions reads
//! other features' learned weights for actions it never tried. The claim
//! table keeps, beside each slot's weight, a *tag* of the feature that owns
//! it, and places features by open addressing with linear probing:
//!
//! - a feature's key is its full 32-bit hash
//!   ([`Layout::Claimed`](crate::tile_coding::Layout::Claimed)); its home
//!   slot is `key mod slots` (the low bits), and its tag comes from the
//!   key's bits as far as the table can tell them apart ([Tags](#tags),
//!   [`stored_tag`]);
//! - a **learning update claims** the feature's slot ([`ClaimTable::claim`]):
//!   the first slot from home on that holds its tag, or else the first empty
//!   one, which then gets the tag and the feature's initial weight;
//! - **reads never claim** ([`ClaimTable::read`]): action selection reads
//!   every candidate's features, and most of those are never written;
//! - a feature that holds no slot reads its **initial weight**, a function
//!   of the trial's seed and its key alone (the bits of it the table
//!   keeps: [`ClaimTable::initial_weight`]), never another feature's
//!   learned weight;
//! - the probe is bounded ([`MAX_PROBE`] slots). A claim that finds neither
//!   its tag nor an empty slot there finds the table full, and the table
//!   does what its [`WhenFull`] says: it **refuses** (the update for that
//!   feature is dropped and counted, and lands in no other feature's
//!   slot), or it **replaces** the least-learned feature among the probe's
//!   slots ([`WhenFull::Replace`], module `evict`), which then reads its
//!   initial weight again.
//!
//! # Where pada differs from the framework
//!
//! The framework (`docs/reference/grl.md` §5.1 and §5.2) keeps a side
//! table of 32-bit hashes and probes without a bound, and its linear
//! representation draws every weight uniformly at start.
//! A feature it has not claimed reads the weight of the empty slot where
//! its probe stopped, so two unclaimed features that stop at the same slot
//! read the same initial weight, and what an unclaimed feature reads changes
//! when another feature claims that slot. pada draws the initial weight
//! from the feature's key instead, so it is the same value however full the
//! table is, and a claim starts from the value the feature read before. The
//! probe bound and the refusal keep a full table from looping or writing
//! into a stranger's slot.
//!
//! # Tags
//!
//! A feature's key is a 32-bit hash, but a slot holds only what its place
//! and its tag can say: in a table of 2^k slots with b-bit tags, 2^k homes
//! and 2^b − 1 tags (0 marks a free slot) tell apart fewer than 2^(k + b)
//! keys, so no table of 2^16 slots or fewer with 16-bit tags can tell
//! every 32-bit key apart. To a table a key is therefore its **low
//! `key_bits` = min(32, k + b − 1) bits** ([`key_bits`], the most whole
//! bits that 2^k homes and 2^b − 1 tags can hold): the home is the low k
//! of them, and the tag and
//! the initial weight are functions of all of them. For 32-bit tags that
//! is the whole key at every size; for 16-bit tags, from 2^17 slots up
//! (the F429's 2^21); a 2^14-slot table (the F405's) keeps 29 bits, and
//! two keys that agree in those are one feature to it.
//!
//! **The promise: two features with the same home never share a slot**
//! unless their keys agree in their low `key_bits` bits (then they are one
//! feature, with one initial weight). Features with different homes whose
//! probe runs meet share one when their tags are equal: with 16-bit tags
//! with probability about 2⁻¹⁶ per occupied slot they both pass; with
//! 32-bit tags only the two keys that both get tag 1 (below), so that two
//! features share a slot only if their 32-bit hashes are equal, as in the
//! framework, but for that one pair.
//!
//! Why it holds. The stored tag of `key` is [`tag_of`]`(key << s, b)` with
//! s = 32 − `key_bits` ([`stored_tag`]): the key's kept bits moved to the
//! top, multiplied by an odd constant, and the product's top b bits taken,
//! 0 becoming 1. Let `x` and `y` be two keys of one home, shifted by s.
//! Their low s + k ≥ 33 − b bits are equal (s zeros, then the home), so
//! their products with the odd constant are equal modulo 2^(33 − b), and
//! they are equal modulo 2³² only if `x = y` (an odd multiplier is a
//! bijection). Two products that differ but agree in bits 0 … 32 − b
//! differ in bits 33 − b … 31, all of them in the tag, so the tags differ;
//! and the lowest tag bit (bit 32 − b) is equal, so the two tags have the
//! same parity, and a tag 0 made 1 can meet no other tag of that home (its
//! parity is even). `x = y` means the keys agree in their low `key_bits`
//! bits. For 32-bit tags s = 0 and the stored tag is a bijection of the
//! whole key but for the empty mark: the key whose product is 0 shares
//! tag 1 with the key whose product is 1, and the two have different
//! homes (the second is odd), so they share a slot only if their probe
//! runs meet.
//!
//! Why a remix and not the key's bits as they are: in a table of 2²¹
//! slots the home takes bits 0–20, so a 16-bit tag from bits 16–31 would
//! repeat five of the home's bits, and features whose homes lie close
//! together (exactly those that meet on a probe run) would be told apart by
//! 11 bits only. The multiplication spreads every kept bit over the tag.
//!
//! Capacities are in the types: the slots are the stores' lengths (a power
//! of two, fixed at compile time on the chip), the probe bound a constant.

use crate::fixed::Q16;
use crate::weights::{entry_factor, Added, WeightStore};

pub use crate::claims::{Claim, InitialWeights, Occupancy, WhenFull};

/// The longest probe: slots looked at from a feature's home on. At a load
/// of ½ a linear probe that misses looks at 2.5 slots on average, at 0.9
/// about 50 (Knuth's ½(1 + 1/(1 − α)²)), so claims begin to be refused as
/// a table passes about nine tenths full. (The framework warns from 8.)
pub const MAX_PROBE: u32 = 64;

/// The tag of an empty slot.
pub const EMPTY: u32 = 0;

/// Odd multiplier that spreads a key's bits over its tag (the 32-bit
/// golden-ratio fraction).
const TAG_MIX: u32 = 0x9E37_79B1;

/// The `bits`-bit remix of `key` (1 ..= 32 bits): its product with an odd
/// constant, the top `bits` bits, 0 made 1 so that it is never [`EMPTY`].
/// A table stores [`stored_tag`], this of the key's kept bits.
#[inline]
pub const fn tag_of(key: u32, bits: u32) -> u32 {
    let t = key.wrapping_mul(TAG_MIX) >> (32 - bits);
    if t == EMPTY {
        1
    } else {
        t
    }
}

/// The bits of a key that a table of 2^`log2_slots` slots with
/// `tag_bits`-bit tags tells apart: its low min(32, `log2_slots` +
/// `tag_bits` − 1). Keys that agree in these are one feature to it
/// ([module documentation](self#tags)). 32 for 32-bit tags at any size
/// and for 16-bit tags from 2^17 slots up; 29 for 16-bit tags in 2^14.
#[inline]
pub const fn key_bits(tag_bits: u32, log2_slots: u32) -> u32 {
    let bits = log2_slots + tag_bits;
    if bits > 32 {
        32
    } else {
        // A tag of b bits has 2^b − 1 values besides the empty mark: it
        // tells apart b − 1 bits beyond the home's.
        bits - 1
    }
}

/// The tag a table of 2^`log2_slots` slots with `tag_bits`-bit tags stores
/// for `key`: [`tag_of`] its [`key_bits`] kept bits moved to the top. Two
/// keys of one home get the same stored tag only if they agree in those
/// bits (proved in the [module documentation](self#tags)); never
/// [`EMPTY`].
#[inline]
pub const fn stored_tag(key: u32, tag_bits: u32, log2_slots: u32) -> u32 {
    tag_of(key << (32 - key_bits(tag_bits, log2_slots)), tag_bits)
}

/// Where a table keeps its tags: one per slot, [`EMPTY`] for a free one.
pub trait TagStore {
    /// Bits per tag (16 or 32).
    const BITS: u32;

    /// Number of tags (= slots).
    fn len(&self) -> usize;

    /// Whether there are none.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Tag `i` ([`EMPTY`] outside the table).
    fn get(&self, i: usize) -> u32;

    /// Sets tag `i` (nothing outside the table).
    fn set(&mut self, i: usize, tag: u32);
}

/// 16-bit tags in any `[u16]` (an array, a boxed slice, a `&'static mut`
/// table in a chosen memory).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tags16<T>(pub T);

/// 32-bit tags in any `[u32]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tags32<T>(pub T);

impl<T: AsRef<[u16]> + AsMut<[u16]>> TagStore for Tags16<T> {
    const BITS: u32 = 16;

    fn len(&self) -> usize {
        self.0.as_ref().len()
    }

    #[inline]
    fn get(&self, i: usize) -> u32 {
        self.0.as_ref().get(i).copied().unwrap_or(0) as u32
    }

    #[inline]
    fn set(&mut self, i: usize, tag: u32) {
        if let Some(t) = self.0.as_mut().get_mut(i) {
            *t = tag as u16;
        }
    }
}

impl<T: AsRef<[u32]> + AsMut<[u32]>> TagStore for Tags32<T> {
    const BITS: u32 = 32;

    fn len(&self) -> usize {
        self.0.as_ref().len()
    }

    #[inline]
    fn get(&self, i: usize) -> u32 {
        self.0.as_ref().get(i).copied().unwrap_or(0)
    }

    #[inline]
    fn set(&mut self, i: usize, tag: u32) {
        if let Some(t) = self.0.as_mut().get_mut(i) {
            *t = tag;
        }
    }
}

/// What a probe from a key's home found.
enum Probe {
    Found(u32),
    Free(u32),
    Exhausted,
}

/// A claim table over a weight store `W` and a tag store `T` of the same
/// length, a power of two. See the [module documentation](self).
#[derive(Debug, Clone)]
pub struct ClaimTable<W, T> {
    weights: W,
    tags: T,
    mask: u32,
    /// 32 − [`key_bits`]: how far a key is shifted up to drop the bits the
    /// table cannot tell apart (0 from 2^17 slots up with 16-bit tags, and
    /// always with 32-bit tags).
    shift: u32,
    init: InitialWeights,
    claimed: u32,
    refused: u32,
    replaced: u32,
    longest_probe: u32,
    when_full: WhenFull,
}

/// Why a claim table could not be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClaimTableError {
    /// The weight and tag stores differ in length.
    LengthMismatch {
        /// Weights.
        weights: usize,
        /// Tags.
        tags: usize,
    },
    /// The length is not a power of two in 2 ..= 2³¹.
    NotPowerOfTwo(usize),
}

impl core::fmt::Display for ClaimTableError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ClaimTableError::LengthMismatch { weights, tags } => {
                write!(f, "claim table: {weights} weights but {tags} tags (they must be equal)")
            }
            ClaimTableError::NotPowerOfTwo(n) => {
                write!(f, "claim table: {n} slots, expected a power of two from 2 to 2^31")
            }
        }
    }
}

impl<W: WeightStore, T: TagStore> ClaimTable<W, T> {
    /// A table over `weights` and `tags`; every tag is cleared (all slots
    /// free) and unclaimed features read 0 until
    /// [`reset`](Self::reset) sets their initial weights.
    pub fn new(weights: W, tags: T) -> Result<Self, ClaimTableError> {
        let n = weights.len();
        if tags.len() != n {
            return Err(ClaimTableError::LengthMismatch { weights: n, tags: tags.len() });
        }
        if n < 2 || !n.is_power_of_two() || n > 1 << 31 {
            return Err(ClaimTableError::NotPowerOfTwo(n));
        }
        let mut t = ClaimTable {
            weights,
            tags,
            mask: (n - 1) as u32,
            shift: 32 - key_bits(T::BITS, n.trailing_zeros()),
            init: InitialWeights { seed: 0, lo: 0, span: 1 },
            claimed: 0,
            refused: 0,
            replaced: 0,
            longest_probe: 0,
            when_full: WhenFull::Refuse,
        };
        t.reset(t.init);
        Ok(t)
    }

    /// The same table, doing `when_full` with a claim that finds it full
    /// (a new table refuses).
    pub fn on_full(mut self, when_full: WhenFull) -> Self {
        self.when_full = when_full;
        self
    }

    /// Frees every slot and sets the initial weights of unclaimed features.
    pub fn reset(&mut self, init: InitialWeights) {
        for i in 0..self.tags.len() {
            self.tags.set(i, EMPTY);
            self.weights.set(i, Q16::ZERO);
        }
        self.init = init;
        self.claimed = 0;
        self.refused = 0;
        self.replaced = 0;
        self.longest_probe = 0;
    }

    /// The initial weights of unclaimed features.
    pub fn initial_weights(&self) -> InitialWeights {
        self.init
    }

    /// Counts the claimed slots again (after the tags were loaded from a
    /// checkpoint), sets the refusals to `refused`, and the longest probe
    /// to 0 (a checkpoint does not keep it, and a tag does not say how far
    /// its feature sits from home).
    pub fn recount(&mut self, refused: u32) {
        self.claimed = (0..self.tags.len()).filter(|&i| self.tags.get(i) != EMPTY).count() as u32;
        self.refused = refused;
        self.replaced = 0;
        self.longest_probe = 0;
    }

    /// Occupancy: slots claimed, slots, refusals, the longest probe a
    /// claim needed ([`Occupancy::longest_probe`]: reads are not counted).
    pub fn occupancy(&self) -> Occupancy {
        Occupancy {
            claimed: self.claimed,
            slots: self.mask + 1,
            refused: self.refused,
            replaced: self.replaced,
            longest_probe: self.longest_probe,
        }
    }

    /// The tag stored in slot `i` ([`EMPTY`] if free).
    pub fn tag(&self, i: usize) -> u32 {
        self.tags.get(i)
    }

    /// The weight store.
    pub fn weight_store(&self) -> &W {
        &self.weights
    }

    /// The bits of a key this table tells apart ([`key_bits`]): keys that
    /// agree in their low `key_bits()` bits are one feature to it.
    pub fn key_bits(&self) -> u32 {
        32 - self.shift
    }

    /// The tag this table stores for `key` ([`stored_tag`]).
    #[inline]
    pub fn tag_for(&self, key: u32) -> u32 {
        tag_of(key << self.shift, T::BITS)
    }

    /// The weight `key` reads while it holds no slot: the initial weight
    /// ([`InitialWeights::of`]) of its kept bits, so that keys which are
    /// one feature to the table start from one weight.
    #[inline]
    pub fn initial_weight(&self, key: u32) -> Q16 {
        self.init.of((key << self.shift) >> self.shift)
    }

    #[inline]
    fn probe(&self, key: u32) -> (Probe, u32) {
        let tag = self.tag_for(key);
        let mut i = key & self.mask;
        for n in 0..MAX_PROBE {
            let t = self.tags.get(i as usize);
            if t == tag {
                return (Probe::Found(i), n);
            }
            if t == EMPTY {
                return (Probe::Free(i), n);
            }
            i = (i + 1) & self.mask;
        }
        (Probe::Exhausted, MAX_PROBE)
    }

    /// The weight of the feature `key`: its slot's, or its initial weight
    /// if it holds none. Claims nothing and changes nothing, the occupancy
    /// included (the hot path: see [`Occupancy::longest_probe`]).
    #[inline(always)]
    pub fn read(&self, key: u32) -> Q16 {
        // Most features a choice reads hold no slot, and in a table far
        // from full most of their homes are free: the first look of the
        // probe settles those, without the tag, inlined into the caller's
        // loop; the probe is a call.
        if self.tags.get((key & self.mask) as usize) == EMPTY {
            return self.initial_weight(key);
        }
        self.read_probing(key)
    }

    /// [`read`](Self::read) past a home that is not free.
    #[inline(never)]
    fn read_probing(&self, key: u32) -> Q16 {
        match self.probe(key).0 {
            Probe::Found(i) => self.weights.get(i as usize),
            Probe::Free(_) | Probe::Exhausted => self.initial_weight(key),
        }
    }

    /// [`read`](Self::read) of every key in `keys`, then
    /// [`claim`](Self::claim) of each in order, with one probe per key
    /// where the claims leave its probe's outcome as it was: a claim only
    /// fills a free slot, so a key found stays found, a key refused stays
    /// refused, and a key whose probe stopped at a free slot takes that
    /// slot if it is still free (the earlier keys' claims did not fill
    /// it) and probes again if not. So the weights, the claims and the
    /// counts are those of the reads and claims one by one, but for one
    /// thing: a table that replaces ([`WhenFull::Replace`]) spares every
    /// slot the batch's features hold or take, so that no feature of an
    /// update loses its slot to another feature of the same update.
    /// Writes each claim to `claims` and returns the sum of the weights
    /// read.
    pub fn read_then_claim(&mut self, keys: &[u32], claims: &mut [Claim]) -> i64 {
        let mut sum = 0i64;
        // The probes, their outcomes kept in `claims` for now: a free slot
        // as a fresh claim of it.
        for (claim, &key) in claims.iter_mut().zip(keys) {
            let (found, _) = self.probe(key);
            let (c, w) = match found {
                Probe::Found(i) => (Claim::Slot { slot: i, fresh: false }, self.weights.get(i as usize)),
                Probe::Free(i) => (Claim::Slot { slot: i, fresh: true }, self.initial_weight(key)),
                Probe::Exhausted => (Claim::Refused, self.initial_weight(key)),
            };
            *claim = c;
            sum += w.0 as i64;
        }
        for i in 0..claims.len().min(keys.len()) {
            let key = keys[i];
            let probed = match claims[i] {
                Claim::Slot { slot, fresh: true } if self.tags.get(slot as usize) == EMPTY => {
                    self.tags.set(slot as usize, self.tag_for(key));
                    self.weights.set(slot as usize, self.initial_weight(key));
                    self.claimed += 1;
                    slot.wrapping_sub(key) & self.mask
                }
                Claim::Slot { fresh: true, .. } => {
                    // An earlier key of this batch took the free slot.
                    claims[i] = self.claim_sparing(key, claims);
                    continue;
                }
                Claim::Slot { slot, fresh: false } => slot.wrapping_sub(key) & self.mask,
                Claim::Refused | Claim::Replaced { .. } => {
                    // A full probe stays full: claims fill free slots, and
                    // a replacement leaves its slot held.
                    claims[i] = self.when_full_sparing(key, claims);
                    MAX_PROBE
                }
            };
            if probed > self.longest_probe {
                self.longest_probe = probed;
            }
        }
        sum
    }

    /// The slot of the feature `key`, claimed now if it held none (its
    /// weight then starts at the initial weight it read before); refused
    /// and counted if the probe finds neither its tag nor a free slot. Its
    /// probe counts towards [`Occupancy::longest_probe`].
    pub fn claim(&mut self, key: u32) -> Claim {
        self.claim_sparing(key, &[])
    }

    /// [`claim`](Self::claim), sparing the slots of `batch` if the table
    /// is full ([`when_full_sparing`](Self::when_full_sparing)).
    fn claim_sparing(&mut self, key: u32, batch: &[Claim]) -> Claim {
        let (found, probed) = self.probe(key);
        if probed > self.longest_probe {
            self.longest_probe = probed;
        }
        match found {
            Probe::Found(i) => Claim::Slot { slot: i, fresh: false },
            Probe::Free(i) => {
                self.tags.set(i as usize, self.tag_for(key));
                self.weights.set(i as usize, self.initial_weight(key));
                self.claimed += 1;
                Claim::Slot { slot: i, fresh: true }
            }
            Probe::Exhausted => self.when_full_sparing(key, batch),
        }
    }

    /// A claim of `key` whose probe found the table full: refused and
    /// counted, or another feature's slot taken ([`WhenFull`]), never one
    /// of the slots in `batch` (the claims of the update's other
    /// features: each keeps its slot for the update).
    fn when_full_sparing(&mut self, key: u32, batch: &[Claim]) -> Claim {
        match self.when_full {
            WhenFull::Refuse => {
                self.refused = self.refused.saturating_add(1);
                Claim::Refused
            }
            WhenFull::Replace => match evict::victim(&self.weights, key & self.mask, self.mask, self.init.centre(), batch) {
                Some(slot) => {
                    let old_raw = WeightStore::raw(self, slot as usize);
                    self.tags.set(slot as usize, self.tag_for(key));
                    self.weights.set(slot as usize, self.initial_weight(key));
                    self.replaced = self.replaced.saturating_add(1);
                    Claim::Replaced { slot, old_raw }
                }
                // Every slot of the probe is the batch's own (at most
                // TILINGS of MAX_PROBE: never with the boards' 16).
                None => {
                    self.refused = self.refused.saturating_add(1);
                    Claim::Refused
                }
            },
        }
    }
}

/// Multiplier of a slot's tag in [`ClaimTable`]'s raw value, so that the
/// table checksum sees a tag change as well as a weight change.
const TAG_CHECK: u32 = 0x85EB_CA6B;

impl<W: WeightStore, T: TagStore> WeightStore for ClaimTable<W, T> {
    #[inline]
    fn dithered(&self) -> bool {
        self.weights.dithered()
    }

    #[inline]
    fn claims(&self) -> bool {
        true
    }

    fn len(&self) -> usize {
        self.weights.len()
    }

    #[inline]
    fn get(&self, i: usize) -> Q16 {
        self.weights.get(i)
    }

    #[inline]
    fn set(&mut self, i: usize, w: Q16) {
        self.weights.set(i, w)
    }

    #[inline]
    fn add(&mut self, i: usize, inc: Q16, dither: u32) -> bool {
        self.weights.add(i, inc, dither)
    }

    fn format(&self) -> crate::weights::WeightFormat {
        self.weights.format()
    }

    fn tag_bytes(&self) -> usize {
        T::BITS as usize / 8
    }

    /// The weight's bytes, then the tag's.
    fn stored_le(&self, i: usize, out: &mut [u8]) {
        let wb = self.weights.format().bytes();
        self.weights.stored_le(i, out);
        let tag = self.tags.get(i).to_le_bytes();
        let tb = T::BITS as usize / 8;
        if let Some(dst) = out.get_mut(wb..wb + tb) {
            dst.copy_from_slice(&tag[..tb]);
        }
    }

    fn load_le(&mut self, i: usize, bytes: &[u8]) {
        let wb = self.weights.format().bytes();
        self.weights.load_le(i, bytes);
        let tb = T::BITS as usize / 8;
        if let Some(src) = bytes.get(wb..wb + tb) {
            let mut tag = [0u8; 4];
            tag[..tb].copy_from_slice(src);
            self.tags.set(i, u32::from_le_bytes(tag));
        }
    }

    /// 0 for a free slot, else the weight's raw bits plus a multiple of
    /// its tag.
    #[inline]
    fn raw(&self, i: usize) -> u32 {
        let tag = self.tags.get(i);
        if tag == EMPTY {
            0
        } else {
            self.weights.raw(i).wrapping_add(tag.wrapping_mul(TAG_CHECK))
        }
    }

    #[inline]
    fn read(&self, feature: u32) -> Q16 {
        ClaimTable::read(self, feature)
    }

    #[inline]
    fn claim(&mut self, feature: u32) -> Claim {
        ClaimTable::claim(self, feature)
    }

    #[inline]
    fn read_then_claim(&mut self, features: &[u32], claims: &mut [Claim]) -> i64 {
        ClaimTable::read_then_claim(self, features, claims)
    }

    /// The weight store's writes, with the checksum's change taken from
    /// the weight alone: a write leaves the slot's tag as it is, so a
    /// claimed slot's [`raw`](WeightStore::raw) changes with its weight's,
    /// and a free slot's stays 0.
    fn add_each<D: FnMut() -> u32>(&mut self, slots: &[u32], inc: Q16, mut dither: D) -> Added {
        let dithered = self.weights.dithered();
        let n = self.weights.len();
        let mut out = Added::default();
        for &slot in slots {
            let i = slot as usize;
            if i >= n {
                continue;
            }
            let d = if dithered { dither() } else { 0 };
            let old = self.weights.raw(i);
            out.saturations += self.weights.add(i, inc, d) as u32;
            if self.tags.get(i) != EMPTY {
                let change = self.weights.raw(i).wrapping_sub(old);
                out.checksum_change = out.checksum_change.wrapping_add(change.wrapping_mul(entry_factor(i)));
            }
        }
        out
    }

    fn reset_claims(&mut self, init: InitialWeights) {
        self.reset(init)
    }

    fn occupancy(&self) -> Option<Occupancy> {
        Some(ClaimTable::occupancy(self))
    }

    fn when_full(&self) -> WhenFull {
        self.when_full
    }

    fn table_seed(&self) -> u64 {
        self.init.seed
    }

    fn restore_claims(&mut self, init: InitialWeights, refused: u32) {
        self.init = init;
        self.recount(refused);
    }
}

mod evict;

#[cfg(test)]
mod tests;
