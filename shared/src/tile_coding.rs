//! Tile coding in fixed point.
//!
//! A state `x` (one `f32` per dimension) is converted once, at the boundary,
//! to integers: dimension `i` with range `[min_i, max_i]` and tile width `w_i`
//! becomes `q_i = ⌊(clamp(x_i) − min_i) · T / w_i⌋`, the position in units of
//! `w_i / T` (a "sub-tile"), where `T` is the number of tilings. Everything
//! after that is integer arithmetic.
//!
//! **Offsets.** Tiling `j` shifts dimension `i` by `b_ij = j·(2i + 1)`
//! sub-tiles (modulo `T`), the odd displacement vector (1, 3, 5, …)
//! recommended by Sutton & Barto and used by the paper's reference
//! implementation (GRL, `docs/reference/grl.md` §5.1). The tile
//! that contains `q_i` in tiling `j` starts at
//! `c_ij = q_i − ((q_i − b_ij) mod T)` (non-negative modulo).
//! A wrapping dimension (an angle) has a whole number `n` of tiles per
//! period; its `c_ij` is taken modulo `n·T`.
//!
//! **Layouts.** [`Layout::Hashed`]: the integer vector
//! `(c_0j, …, c_(d−1)j, j, action)` is hashed with 32-bit MurmurHash2
//! (multiplier `0x5bd1e995`, seed 449, as in GRL) and masked to the table
//! size, which must be a power of two. The state part of the hash is
//! computed once per step and tiling ([`StateCode`]); each candidate action
//! then costs one mixing round and the finaliser per tiling. Collisions are
//! allowed. [`Layout::Exact`]: every (tiling, tile, action) has its own
//! weight; for small problems whose tile count fits the table.
//!
//! By default actions are not generalised over: the joint action index is
//! one more integer word of the hash. With
//! [`TileCoder::with_action_tiles`] (hashed layout) the actions' values are
//! tile-coded too and the word is the action's tile combination
//! ([`crate::action_tiles`]), as the paper's LEO learner does.

use crate::action_space::ActionSpace;
use crate::action_tiles::ActionTiles;
pub(crate) use crate::tiling::tile_start;
use crate::error::ConfigError;
use crate::fixed::floor_i32;
use heapless::Vec;

pub use crate::limits::MAX_STATE_DIMS;

/// MurmurHash2's multiplier.
const MURMUR_M: u32 = 0x5bd1_e995;
/// MurmurHash2's shift.
const MURMUR_R: u32 = 24;
/// Hash seed of the paper's reference implementation (GRL §5.1).
const MURMUR_SEED: u32 = 449;

/// One state dimension: its range and tile width.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StateDim {
    /// Lower end of the range; smaller values are clamped to it (or wrapped).
    pub min: f32,
    /// Upper end of the range; larger values are clamped to it (or wrapped).
    pub max: f32,
    /// Width of one tile, in the dimension's units.
    pub tile_width: f32,
    /// Whether the dimension wraps (an angle): then `max − min` is one period
    /// and holds a whole number of tiles.
    pub wrap: bool,
}

impl StateDim {
    /// A clamped dimension over `[min, max]` with tiles of `tile_width`.
    pub fn new(min: f32, max: f32, tile_width: f32) -> Result<StateDim, ConfigError> {
        let d = StateDim { min, max, tile_width, wrap: false };
        d.validate()?;
        Ok(d)
    }

    /// A wrapping dimension: `[min, max)` is one period, split into
    /// `tiles_per_period` tiles.
    pub fn wrapping(min: f32, max: f32, tiles_per_period: u32) -> Result<StateDim, ConfigError> {
        if tiles_per_period == 0 || tiles_per_period > 1 << 16 {
            return Err(ConfigError::new(
                "tiles_per_period",
                tiles_per_period as f32,
                "1 <= tiles_per_period <= 65536",
            ));
        }
        let d = StateDim { min, max, tile_width: (max - min) / tiles_per_period as f32, wrap: true };
        d.validate()?;
        Ok(d)
    }

    /// Checks the range, tile width and (for a wrapping dimension) the whole
    /// number of tiles per period; the error names the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if !self.min.is_finite() {
            return Err(ConfigError::new("state.min", self.min, "a finite number below state.max"));
        }
        if !self.max.is_finite() || self.max <= self.min {
            return Err(ConfigError::new("state.max", self.max, "a finite number above state.min"));
        }
        if !self.tile_width.is_finite() || self.tile_width <= 0.0 {
            return Err(ConfigError::new("state.tile_width", self.tile_width, "tile_width > 0"));
        }
        // Bound the integer range so that q_i and the tile counts fit i32
        // comfortably for any number of tilings up to 256.
        let tiles = (self.max - self.min) / self.tile_width;
        if tiles > (1 << 20) as f32 {
            return Err(ConfigError::new(
                "state.tile_width",
                self.tile_width,
                "at most 2^20 tiles over state.max - state.min",
            ));
        }
        Ok(())
    }
}

/// How (tiling, tile, action) coordinates become weight indices (or keys).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Layout {
    /// Hash into a table whose size is a power of two (collisions allowed).
    Hashed,
    /// One weight per (tiling, tile, action); the table must hold them all.
    Exact,
    /// Hashed as [`Hashed`](Self::Hashed), but the feature is the whole
    /// 32-bit hash, a key that a [`crate::claim_table::ClaimTable`] of a
    /// power-of-two size places so that features of one home never share
    /// a slot (as far as the table keeps a key's bits:
    /// [`crate::claim_table::key_bits`]).
    Claimed,
}

impl Layout {
    /// A stable number of the layout, for the configuration hash.
    pub const fn code(self) -> u32 {
        match self {
            Layout::Hashed => 1,
            Layout::Exact => 2,
            Layout::Claimed => 3,
        }
    }

    /// The name for reports and errors.
    pub const fn name(self) -> &'static str {
        match self {
            Layout::Hashed => "hashed",
            Layout::Exact => "exact",
            Layout::Claimed => "claim",
        }
    }

    /// Whether features are hashed (hashed or claimed).
    pub const fn is_hashed(self) -> bool {
        matches!(self, Layout::Hashed | Layout::Claimed)
    }
}

/// A dimension prepared for integer coding.
#[derive(Debug, Clone, Copy)]
struct PreparedDim {
    min: f32,
    max: f32,
    /// `T / w`: sub-tiles per unit.
    scale: f32,
    /// Largest `q` of a clamped dimension.
    q_max: i32,
    /// Sub-tiles per period of a wrapping dimension, 0 if it does not wrap.
    period: i32,
    /// Tiles along this dimension in the exact layout.
    tiles: u32,
    /// Stride of this dimension in the exact layout's flat tile index.
    stride: u32,
}

/// The integer code of one state: per tiling, the state part of the hash
/// ([`Layout::Hashed`]) or the first index of the state's tile
/// ([`Layout::Exact`]). Computing it is the only per-step work that touches
/// floats; feature indices for any action follow from it with integer work.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateCode<const TILINGS: usize> {
    per_tiling: [u32; TILINGS],
}

/// The tile coder: `TILINGS` offset tilings over up to [`MAX_STATE_DIMS`]
/// dimensions, mapping (state, action) to `TILINGS` weight indices.
#[derive(Debug, Clone)]
pub struct TileCoder<const TILINGS: usize> {
    dims: Vec<PreparedDim, MAX_STATE_DIMS>,
    layout: Layout,
    actions: u32,
    table_size: u32,
    /// What a hash is masked with: the table's index bits (hashed), all 32
    /// bits (claimed: the key).
    mask: u32,
    /// Tiles per tiling in the exact layout (0 when hashed).
    tiles_per_tiling: u32,
    /// The action tiling, when actions are generalised over.
    action_tiles: Option<ActionTiles<TILINGS>>,
}

impl<const TILINGS: usize> TileCoder<TILINGS> {
    /// Builds a coder for `dims`, `actions` joint actions and a weight table
    /// of `table_size` entries.
    ///
    /// Errors: no dimension or more than [`MAX_STATE_DIMS`]; a bad
    /// dimension; `TILINGS` outside 1..=256; `actions` = 0; a hashed table
    /// size that is not a power of two; an exact layout that does not fit.
    pub fn new(
        dims: &[StateDim],
        actions: u32,
        layout: Layout,
        table_size: usize,
    ) -> Result<Self, ConfigError> {
        if TILINGS == 0 || TILINGS > 256 {
            return Err(ConfigError::new("tilings", TILINGS as f32, "1 <= tilings <= 256"));
        }
        if dims.is_empty() || dims.len() > MAX_STATE_DIMS {
            return Err(ConfigError::new(
                "state dimensions",
                dims.len() as f32,
                "1 ..= 16 state dimensions (observation plus policy extension)",
            ));
        }
        if actions == 0 {
            return Err(ConfigError::new("actions", 0.0, "at least one joint action"));
        }
        if table_size == 0 || table_size > u32::MAX as usize {
            return Err(ConfigError::new("table_size", table_size as f32, "1 <= table_size < 2^32"));
        }
        let t = TILINGS as f32;
        let mut prepared: Vec<PreparedDim, MAX_STATE_DIMS> = Vec::new();
        for (i, d) in dims.iter().enumerate() {
            d.validate().map_err(|e| e.at(i))?;
            let scale = t / d.tile_width;
            let span = floor_i32((d.max - d.min) * scale);
            let (q_max, period, tiles) = if d.wrap {
                // A whole number of tiles per period, so the period in
                // sub-tiles is tiles·T exactly (see StateDim::wrapping).
                let n = ((d.max - d.min) / d.tile_width + 0.5) as i32;
                (n * TILINGS as i32 - 1, n * TILINGS as i32, n as u32)
            } else {
                (span, 0, (span / TILINGS as i32) as u32 + 2)
            };
            // Cannot fail: dims.len() <= MAX_STATE_DIMS was checked above.
            let _ = prepared.push(PreparedDim { min: d.min, max: d.max, scale, q_max, period, tiles, stride: 0 });
        }
        let mut tiles_per_tiling = 0u32;
        match layout {
            Layout::Hashed | Layout::Claimed => {
                if !table_size.is_power_of_two() {
                    return Err(ConfigError::new(
                        "table_size",
                        table_size as f32,
                        "a power of two (hashed layout)",
                    ));
                }
            }
            Layout::Exact => {
                let mut stride: u64 = 1;
                for p in prepared.iter_mut() {
                    p.stride = stride as u32;
                    stride = stride.saturating_mul(p.tiles as u64);
                    if stride > u32::MAX as u64 {
                        break;
                    }
                }
                let needed = stride.saturating_mul(TILINGS as u64).saturating_mul(actions as u64);
                if needed > table_size as u64 {
                    return Err(ConfigError::new(
                        "table_size",
                        table_size as f32,
                        "at least tilings x tiles x actions entries for the exact layout",
                    ));
                }
                tiles_per_tiling = stride as u32;
            }
        }
        let mask = match layout {
            Layout::Claimed => u32::MAX,
            _ => (table_size - 1) as u32,
        };
        Ok(TileCoder {
            dims: prepared,
            layout,
            actions,
            table_size: table_size as u32,
            mask,
            tiles_per_tiling,
            action_tiles: None,
        })
    }

    /// The same coder, generalising over actions: the values of `space`
    /// (whose joint actions are this coder's actions) are tile-coded with
    /// one tile width per action dimension ([`crate::action_tiles`]).
    ///
    /// Errors: the exact layout (action tiles are hashed only); a space with
    /// another number of joint actions; the errors of [`ActionTiles::new`].
    pub fn with_action_tiles(mut self, space: &ActionSpace, widths: &[f32]) -> Result<Self, ConfigError> {
        if !self.layout.is_hashed() {
            return Err(ConfigError::new("layout", 0.0, "a hashed or claim layout when actions are tile-coded"));
        }
        if space.joint_count() != self.actions {
            return Err(ConfigError::new(
                "actions",
                space.joint_count() as f32,
                "the coder's number of joint actions",
            ));
        }
        self.action_tiles = Some(ActionTiles::new(space, widths, self.dims.len())?);
        Ok(self)
    }

    /// The action tiling, if actions are generalised over.
    pub fn action_tiles(&self) -> Option<&ActionTiles<TILINGS>> {
        self.action_tiles.as_ref()
    }

    /// The weight index of action-tile combination `combo` in `tiling`
    /// (only meaningful with [`with_action_tiles`](Self::with_action_tiles)).
    #[inline]
    pub fn combo_feature(&self, code: &StateCode<TILINGS>, tiling: usize, combo: u32) -> u32 {
        murmur_finish(murmur_mix(code.per_tiling[tiling], combo)) & self.mask
    }

    /// The state's share of `tiling`'s hashed features, for
    /// [`feature_of_parts`](Self::feature_of_parts): the same for every
    /// action or combination in that tiling.
    #[inline]
    pub fn state_part(&self, code: &StateCode<TILINGS>, tiling: usize) -> u32 {
        code.per_tiling[tiling].wrapping_mul(MURMUR_M)
    }

    /// The last hashed word's share of a feature (a joint action or an
    /// action-tile combination), for [`feature_of_parts`](Self::feature_of_parts):
    /// the same in every state and tiling, so a caller that hashes many
    /// features of few words computes it once per word.
    #[inline]
    pub const fn word_part(word: u32) -> u32 {
        murmur_word(word)
    }

    /// The hashed feature of a state's and a word's shares:
    /// `feature_of_parts(state_part(code, j), word_part(c))` is
    /// [`combo_feature`](Self::combo_feature)`(code, j, c)`, and with the
    /// joint action as the word, [`action_feature`](Self::action_feature)
    /// of a hashed layout. (MurmurHash2 mixes the word independently of
    /// the state before the two meet, so the split changes no bit.)
    #[inline]
    pub fn feature_of_parts(&self, state_part: u32, word_part: u32) -> u32 {
        murmur_finish(state_part ^ word_part) & self.mask
    }

    /// Writes what gives this coder's features their meaning into a
    /// configuration hash: tilings, layout, table size, joint actions, each
    /// dimension as prepared (range, sub-tiles per unit, wrap period,
    /// tiles) and the action tiling if any.
    pub fn write_config(&self, h: &mut crate::checkpoint::ConfigHasher) {
        h.write_u32(TILINGS as u32)
            .write_u32(self.layout.code())
            .write_u32(self.table_size)
            .write_u32(self.actions)
            .write_u32(self.dims.len() as u32);
        for d in &self.dims {
            h.write_f32(d.min).write_f32(d.max).write_f32(d.scale).write_u32(d.period as u32).write_u32(d.tiles);
        }
        match &self.action_tiles {
            Some(at) => {
                h.write_str("action tiles");
                at.write_config(h);
            }
            None => {
                h.write_str("no action tiles");
            }
        }
    }

    /// Number of state dimensions.
    pub fn dims(&self) -> usize {
        self.dims.len()
    }

    /// Number of joint actions.
    pub fn actions(&self) -> u32 {
        self.actions
    }

    /// The layout.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Weights needed by the exact layout (tilings × tiles × actions), or
    /// `None` for the hashed layout.
    pub fn exact_size(&self) -> Option<usize> {
        match self.layout {
            Layout::Exact => Some(self.tiles_per_tiling as usize * TILINGS * self.actions as usize),
            Layout::Hashed | Layout::Claimed => None,
        }
    }

    /// The integer sub-tile position `q_i` of each dimension: the one place
    /// where floats become integers. The caller has checked finiteness.
    pub fn quantise(&self, x: &[f32], q: &mut [i32; MAX_STATE_DIMS]) {
        for (i, (d, &xi)) in self.dims.iter().zip(x).enumerate() {
            q[i] = if d.period > 0 {
                floor_i32((xi - d.min) * d.scale).rem_euclid(d.period)
            } else {
                let clamped = if xi < d.min { d.min } else if xi > d.max { d.max } else { xi };
                let v = floor_i32((clamped - d.min) * d.scale);
                if v > d.q_max { d.q_max } else { v }
            };
        }
    }

    /// Encodes a state. `x` must have [`dims`](Self::dims) finite entries
    /// (the agent checks both before calling).
    pub fn encode(&self, x: &[f32]) -> StateCode<TILINGS> {
        let mut q = [0i32; MAX_STATE_DIMS];
        self.quantise(x, &mut q);
        self.encode_quantised(&q)
    }

    /// Encodes an already quantised state (integer only).
    pub fn encode_quantised(&self, q: &[i32; MAX_STATE_DIMS]) -> StateCode<TILINGS> {
        let t = TILINGS as i32;
        let mut per_tiling = [0u32; TILINGS];
        for (j, slot) in per_tiling.iter_mut().enumerate() {
            match self.layout {
                Layout::Hashed | Layout::Claimed => {
                    // Words hashed per (state, action): d coordinates, the
                    // tiling and the action.
                    let words = self.dims.len() as u32 + 2;
                    let mut h = MURMUR_SEED ^ words.wrapping_mul(4);
                    for (i, d) in self.dims.iter().enumerate() {
                        let c = tile_start(q[i], j as i32, i as i32, t, d.period);
                        h = murmur_mix(h, c as u32);
                    }
                    *slot = murmur_mix(h, j as u32);
                }
                Layout::Exact => {
                    let mut flat = 0u32;
                    for (i, d) in self.dims.iter().enumerate() {
                        let b = (j as i32 * (2 * i as i32 + 1)).rem_euclid(t);
                        let c = tile_start(q[i], j as i32, i as i32, t, d.period);
                        // c ≡ b (mod T) and c > −T, so this is ≥ 0 (see module doc).
                        let k = if d.period > 0 { (c - b) / t } else { (c - b) / t + 1 };
                        flat += k as u32 * d.stride;
                    }
                    *slot = (j as u32 * self.tiles_per_tiling + flat) * self.actions;
                }
            }
        }
        StateCode { per_tiling }
    }

    /// The weight index of `action` in `tiling` for an encoded state.
    #[inline]
    pub fn feature(&self, code: &StateCode<TILINGS>, tiling: usize, action: u32) -> u32 {
        match &self.action_tiles {
            Some(at) => self.combo_feature(code, tiling, at.combo_of_action(tiling, action)),
            None => self.action_feature(code, tiling, action),
        }
    }

    /// [`feature`](Self::feature) of a coder without action tiles: the
    /// joint action index is the hashed word (or the exact offset).
    #[inline(always)]
    pub fn action_feature(&self, code: &StateCode<TILINGS>, tiling: usize, action: u32) -> u32 {
        match self.layout {
            Layout::Hashed | Layout::Claimed => {
                murmur_finish(murmur_mix(code.per_tiling[tiling], action)) & self.mask
            }
            Layout::Exact => code.per_tiling[tiling] + action,
        }
    }

    /// The `TILINGS` weight indices of (state, action).
    pub fn features(&self, code: &StateCode<TILINGS>, action: u32) -> [u32; TILINGS] {
        let mut f = [0u32; TILINGS];
        for (j, slot) in f.iter_mut().enumerate() {
            *slot = self.feature(code, j, action);
        }
        f
    }
}

/// One MurmurHash2 round: absorbs the 32-bit word `k` into `h`.
#[inline]
fn murmur_mix(h: u32, k: u32) -> u32 {
    h.wrapping_mul(MURMUR_M) ^ murmur_word(k)
}

/// MurmurHash2's mixing of one word before it meets the running hash.
#[inline]
const fn murmur_word(k: u32) -> u32 {
    let mut k = k.wrapping_mul(MURMUR_M);
    k ^= k >> MURMUR_R;
    k.wrapping_mul(MURMUR_M)
}

/// MurmurHash2's finaliser.
#[inline]
fn murmur_finish(mut h: u32) -> u32 {
    h ^= h >> 13;
    h = h.wrapping_mul(MURMUR_M);
    h ^ (h >> 15)
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeSet;

    fn pendulum_dims() -> [StateDim; 2] {
        [
            StateDim::wrapping(-core::f32::consts::PI, core::f32::consts::PI, 20).unwrap(),
            StateDim::new(-12.0 * core::f32::consts::PI, 12.0 * core::f32::consts::PI, 3.0).unwrap(),
        ]
    }

    #[test]
    fn known_hash_indices_are_stable() {
        // Pinned values: a change of the hash or the offsets changes every
        // learned table, so it must be deliberate. The same numbers are what
        // the Cortex-M4 build computes (integer-only arithmetic).
        let c = TileCoder::<16>::new(&pendulum_dims(), 3, Layout::Hashed, 1 << 16).unwrap();
        let f = c.features(&c.encode(&[0.3, -1.0]), 2);
        let again = c.features(&c.encode(&[0.3, -1.0]), 2);
        assert_eq!(f, again);
        assert_eq!(&f[..4], &PINNED[..], "hash or offsets changed: {:?}", &f[..4]);
    }
    const PINNED: [u32; 4] = [22940, 45525, 43316, 29011];

    #[test]
    fn exact_layout_is_injective_over_a_grid() {
        let dims = [StateDim::new(0.0, 1.0, 0.25).unwrap(), StateDim::new(-1.0, 1.0, 0.5).unwrap()];
        let c = TileCoder::<4>::new(&dims, 3, Layout::Exact, 4096).unwrap();
        let size = c.exact_size().unwrap();
        // Two states in different tiles of tiling 0 must get different indices,
        // and every index must be in range.
        let mut seen = std::collections::BTreeMap::new();
        for xi in 0..=40 {
            for yi in 0..=40 {
                let x = [xi as f32 / 40.0, -1.0 + yi as f32 / 20.0];
                let code = c.encode(&x);
                for a in 0..3 {
                    let f = c.features(&code, a);
                    for &i in &f {
                        assert!((i as usize) < size);
                    }
                    let mut q = [0i32; MAX_STATE_DIMS];
                    c.quantise(&x, &mut q);
                    let tile0 = (tile_start(q[0], 0, 0, 4, 0), tile_start(q[1], 0, 1, 4, 0), a);
                    if let Some(prev) = seen.insert(f[0], tile0) {
                        assert_eq!(prev, tile0, "two tiles share index {}", f[0]);
                    }
                }
            }
        }
    }

    #[test]
    fn wrapping_dimension_joins_its_ends() {
        let c = TileCoder::<8>::new(&pendulum_dims(), 3, Layout::Hashed, 1 << 16).unwrap();
        let just_below = c.features(&c.encode(&[core::f32::consts::PI - 1e-4, 0.0]), 1);
        let just_above = c.features(&c.encode(&[-core::f32::consts::PI + 1e-4, 0.0]), 1);
        let shared = just_below.iter().filter(|i| just_above.contains(i)).count();
        assert!(shared >= 7, "only {shared} of 8 tiles shared across the wrap");
    }

    #[test]
    fn construction_errors_name_the_parameter() {
        let d = [StateDim { min: 1.0, max: 1.0, tile_width: 0.1, wrap: false }];
        let e = TileCoder::<4>::new(&d, 3, Layout::Hashed, 1024).unwrap_err();
        assert_eq!(e.param, "state.max");
        assert_eq!(e.index, Some(0));
        let d = [StateDim::new(0.0, 1.0, 0.1).unwrap()];
        let e = TileCoder::<4>::new(&d, 3, Layout::Hashed, 1000).unwrap_err();
        assert_eq!(e.param, "table_size");
        assert!(std::format!("{e}").contains("power of two"));
        let e = TileCoder::<4>::new(&d, 3, Layout::Exact, 10).unwrap_err();
        assert_eq!(e.param, "table_size");
        assert_eq!(TileCoder::<4>::new(&d, 0, Layout::Hashed, 1024).unwrap_err().param, "actions");
        assert_eq!(TileCoder::<4>::new(&[], 3, Layout::Hashed, 1024).unwrap_err().param, "state dimensions");
        assert_eq!(StateDim::new(0.0, 1.0, -1.0).unwrap_err().param, "state.tile_width");
        assert_eq!(StateDim::new(f32::NAN, 1.0, 1.0).unwrap_err().param, "state.min");
    }

    fn shared_tiles(c: &TileCoder<16>, a: &[f32], b: &[f32]) -> usize {
        let fa = c.features(&c.encode(a), 0);
        let fb = c.features(&c.encode(b), 0);
        let sa: BTreeSet<_> = fa.iter().collect();
        fb.iter().filter(|i| sa.contains(i)).count()
    }

    proptest! {
        #[test]
        fn indices_in_range_and_deterministic(
            x in prop::collection::vec(-100.0f32..100.0, 3),
            a in 0u32..7,
            log_size in 4u32..20,
        ) {
            let dims = [
                StateDim::new(-10.0, 10.0, 1.5).unwrap(),
                StateDim::wrapping(0.0, 6.0, 12).unwrap(),
                StateDim::new(-1.0, 3.0, 0.3).unwrap(),
            ];
            let size = 1usize << log_size;
            let c = TileCoder::<16>::new(&dims, 7, Layout::Hashed, size).unwrap();
            let f1 = c.features(&c.encode(&x), a);
            let f2 = c.features(&c.encode(&x), a);
            prop_assert_eq!(f1, f2);
            for &i in &f1 { prop_assert!((i as usize) < size); }

            let ce = TileCoder::<16>::new(&dims, 7, Layout::Exact, 1 << 20).unwrap();
            let size_e = ce.exact_size().unwrap();
            for &i in &ce.features(&ce.encode(&x), a) { prop_assert!((i as usize) < size_e); }
        }

        /// Along one dimension, the number of tilings in which two states
        /// share a tile falls linearly with their distance: it is
        /// T·(1 − d/w) up to rounding of the sub-tile grid (±1), and 0 from
        /// one tile width on.
        #[test]
        fn sharing_is_proportional_to_distance(x in 1.0f32..9.0, d in 0.0f32..1.2) {
            let w = 0.5f32;
            let dims = [StateDim::new(0.0, 10.0, w).unwrap(), StateDim::new(0.0, 1.0, 1.0).unwrap()];
            let c = TileCoder::<16>::new(&dims, 1, Layout::Exact, 1 << 16).unwrap();
            let n = shared_tiles(&c, &[x, 0.5], &[x + d, 0.5]) as f32;
            let expected = (16.0 * (1.0 - d / w)).max(0.0);
            prop_assert!((n - expected).abs() <= 1.0 + 1e-3, "d = {}, shared {}, expected {}", d, n, expected);
        }
    }
}
