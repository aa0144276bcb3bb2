//! Generalisation over actions: the action's voltages tile-coded like state
//! dimensions, so that neighbouring levels share weights.
//!
//! The paper's LEO learner (GRL, `docs/reference/grl.md` §3.9:
//! `generalizeActions` true, action tile width 6.67 V over the 7 levels of
//! [−10.7, 10.7] V) codes the 3 actions as three more tile-coded dimensions.
//! A level two steps away (7.13 V) then shares tiles with its neighbour in
//! some tilings, and what one voltage teaches is partly learned for the
//! voltages beside it; with 343 joint actions this is what makes learning
//! fast enough to see in an hour of simulated time.
//!
//! The action dimensions continue the state's odd displacement vector: action
//! dimension `d` is coordinate `i = state_dims + d` and tiling `j` shifts it
//! by `j·(2i + 1)` sub-tiles (`tile_coding` module doc). In each tiling, level
//! `l` of dimension `d` falls into tile `k_jdl` (counted from the tile of the
//! lowest level), and a joint action falls into the *combination*
//! `Σ_d k_jdl_d · stride_d`. The hashed feature index absorbs the combination
//! instead of the joint action index, so actions in the same combination
//! share the weight.
//!
//! Because one tiling holds only a few combinations (at most
//! [`MAX_ACTION_COMBOS`]; 125 for LEO's 343 actions), the agent's greedy
//! choice loads each combination's weight once per tiling and sums from that
//! small table, instead of hashing every (tiling, action) pair.

use crate::action_space::{ActionSpace, Levels, MAX_ACTION_DIMS, MAX_LEVELS};
use crate::error::ConfigError;
use crate::fixed::floor_i32;
use crate::tiling::tile_start;

/// Most action-tile combinations in one tiling (the product over action
/// dimensions of the tiles their levels fall into). Bounds the table the
/// agent's greedy choice keeps on the stack: `TILINGS × 128 × 4` bytes
/// (8 KiB with 16 tilings).
pub const MAX_ACTION_COMBOS: usize = 128;
const _: () = assert!(MAX_ACTION_COMBOS.is_power_of_two() && MAX_LEVELS.is_power_of_two());

/// The precomputed action tiling of one action space.
#[derive(Debug, Clone, PartialEq)]
pub struct ActionTiles<const TILINGS: usize> {
    dims: usize,
    /// Levels per action dimension (to decode joint indices).
    levels: [u8; MAX_ACTION_DIMS],
    /// `tile[j][d][l] = k_jdl`: the tile of level `l` of dimension `d` in
    /// tiling `j`, counted from the tile of the dimension's lowest level
    /// (non-decreasing in `l`: levels ascend).
    tile: [[[u8; MAX_LEVELS]; MAX_ACTION_DIMS]; TILINGS],
    /// `stride_d`: what one tile of dimension `d` adds to the combination
    /// index (1 for the first dimension; 0 for a dimension the space does
    /// not have).
    stride: [u32; MAX_ACTION_DIMS],
    combos: u32,
}

impl<const TILINGS: usize> ActionTiles<TILINGS> {
    /// The action tiling of `space` with one tile width per action dimension
    /// (in the dimension's units, e.g. volts), whose first dimension is
    /// coordinate `first_coordinate` of the coder (the number of state
    /// dimensions).
    ///
    /// Errors: a width count other than the space's dimension count; a width
    /// that is not finite and positive; more than [`MAX_ACTION_COMBOS`]
    /// combinations per tiling (wider tiles or fewer levels fix it).
    pub fn new(space: &ActionSpace, widths: &[f32], first_coordinate: usize) -> Result<Self, ConfigError> {
        if widths.len() != space.dims() {
            return Err(ConfigError::new(
                "action tile widths",
                widths.len() as f32,
                "one tile width per action dimension",
            ));
        }
        for (d, &w) in widths.iter().enumerate() {
            if !(w.is_finite() && w > 0.0) {
                return Err(ConfigError::new("action tile width", w, "finite and > 0").at(d));
            }
        }
        // Tile of value `v` of dimension `d` in tiling `j`, counted from the
        // tile of the dimension's lowest level (levels ascend, so ≥ 0).
        let tile_of = |d: usize, j: usize, v: f32| -> u32 {
            let (dim, t) = (space.dim(d), TILINGS as i32);
            let scale = TILINGS as f32 / widths[d];
            let start = |v: f32| tile_start(floor_i32((v - dim.min()) * scale), j as i32, (first_coordinate + d) as i32, t, 0);
            ((start(v) - start(dim.min())) / t) as u32
        };
        let mut levels = [1u8; MAX_ACTION_DIMS];
        let mut stride = [0u32; MAX_ACTION_DIMS];
        let mut combos = 1u32;
        for d in 0..space.dims() {
            let dim = space.dim(d);
            levels[d] = dim.len() as u8;
            stride[d] = combos;
            let tiles = (0..TILINGS).flat_map(|j| dim.values().iter().map(move |&v| (j, v))).map(|(j, v)| tile_of(d, j, v) + 1).max();
            combos = combos.saturating_mul(tiles.unwrap_or(1));
        }
        if combos > MAX_ACTION_COMBOS as u32 {
            return Err(ConfigError::new(
                "action tile combinations",
                combos as f32,
                "at most 128 per tiling (use wider action tiles or fewer levels)",
            ));
        }
        let mut tile = [[[0u8; MAX_LEVELS]; MAX_ACTION_DIMS]; TILINGS];
        for (j, tile_j) in tile.iter_mut().enumerate() {
            for d in 0..space.dims() {
                for (l, &v) in space.dim(d).values().iter().enumerate() {
                    // tile < combos ≤ MAX_ACTION_COMBOS: fits a u8.
                    tile_j[d][l] = tile_of(d, j, v) as u8;
                }
            }
        }
        Ok(ActionTiles { dims: space.dims(), levels, tile, stride, combos })
    }

    /// Writes the tiling into a configuration hash: dimensions, levels,
    /// combinations and every tiling's offsets.
    pub fn write_config(&self, h: &mut crate::checkpoint::ConfigHasher) {
        h.write_u32(self.dims as u32).write_u32(self.combos).write(&self.levels[..self.dims]);
        // Each level's part of the combination index, as bytes: what this
        // hash has always been given (it was the stored table).
        for j in 0..TILINGS {
            for d in 0..self.dims {
                let mut row = [0u8; MAX_LEVELS];
                for (l, b) in row.iter_mut().enumerate().take(self.levels[d] as usize) {
                    *b = self.part(j, d, l as u8) as u8;
                }
                h.write(&row[..self.levels[d] as usize]);
            }
        }
    }

    /// Combinations per tiling (every combination index is below this).
    pub fn combos(&self) -> u32 {
        self.combos
    }

    /// What level `level` of action dimension `d` adds to the combination
    /// index in tiling `j` (0 for a dimension the space does not have):
    /// its [`tile`](Self::tile) times the dimension's
    /// [`stride`](Self::stride).
    #[inline(always)]
    pub fn part(&self, j: usize, d: usize, level: u8) -> u32 {
        self.tile(j, d, level) * self.stride(d)
    }

    /// The tile that level `level` of action dimension `d` falls into in
    /// tiling `j`, counted from the tile of the dimension's lowest level
    /// (0 for a dimension the space does not have). Non-decreasing in
    /// `level`.
    #[inline(always)]
    pub fn tile(&self, j: usize, d: usize, level: u8) -> u32 {
        // MAX_LEVELS is a power of two and every level is below it: the
        // mask changes nothing but lets the compiler drop the bounds check.
        self.tile[j][d & (MAX_ACTION_DIMS - 1)][level as usize & (MAX_LEVELS - 1)] as u32
    }

    /// What one tile of action dimension `d` adds to the combination index
    /// (1 for the first dimension, the product of the earlier dimensions'
    /// tile counts for the others; 0 for a dimension the space does not
    /// have).
    #[inline(always)]
    pub fn stride(&self, d: usize) -> u32 {
        self.stride[d & (MAX_ACTION_DIMS - 1)]
    }

    /// The combination that `levels` falls into in tiling `j`.
    #[inline]
    pub fn combo(&self, j: usize, levels: &Levels) -> u32 {
        (0..MAX_ACTION_DIMS).map(|d| self.part(j, d, levels[d])).sum()
    }

    /// The combination of joint action `action` (first dimension fastest)
    /// in tiling `j`.
    #[inline]
    pub fn combo_of_action(&self, j: usize, mut action: u32) -> u32 {
        let mut levels = [0u8; MAX_ACTION_DIMS];
        for d in 0..self.dims {
            let n = self.levels[d] as u32;
            levels[d] = (action % n) as u8;
            action /= n;
        }
        self.combo(j, &levels)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::action_space::ActionDim;

    fn leo_space() -> ActionSpace {
        let v = ActionDim::uniform(-10.7, 10.7, 7).unwrap();
        ActionSpace::new(&[v.clone(), v.clone(), v]).unwrap()
    }

    #[test]
    fn leo_actions_fall_into_at_most_125_combinations() {
        let at = ActionTiles::<16>::new(&leo_space(), &[6.67; 3], 10).unwrap();
        assert!(at.combos() <= 125, "{}", at.combos());
        assert!(at.combos() >= 27, "{}", at.combos());
    }

    #[test]
    fn neighbouring_levels_share_some_tilings_and_far_ones_none() {
        let space = leo_space();
        let at = ActionTiles::<16>::new(&space, &[6.67; 3], 10).unwrap();
        let shared = |a: Levels, b: Levels| (0..16).filter(|&j| at.combo(j, &a) == at.combo(j, &b)).count();
        // 3.57 V apart: same tile in about (1 − 3.57/6.67) of the tilings.
        let near = shared([3, 3, 3, 0], [4, 3, 3, 0]);
        assert!((5..=10).contains(&near), "{near}");
        // 7.13 V apart is more than a tile width: never shared.
        assert_eq!(shared([2, 3, 3, 0], [4, 3, 3, 0]), 0);
        // Each dimension is coded: a change in the last one also separates.
        assert!(shared([3, 3, 0, 0], [3, 3, 6, 0]) == 0);
        assert_eq!(shared([1, 5, 2, 0], [1, 5, 2, 0]), 16);
    }

    #[test]
    fn combo_of_action_agrees_with_combo_of_levels() {
        let space = leo_space();
        let at = ActionTiles::<16>::new(&space, &[6.67; 3], 10).unwrap();
        for a in 0..space.joint_count() {
            let levels = space.decode(a);
            for j in 0..16 {
                assert_eq!(at.combo_of_action(j, a), at.combo(j, &levels));
                assert!(at.combo(j, &levels) < at.combos());
            }
        }
    }

    #[test]
    fn bad_widths_and_too_many_combinations_are_refused() {
        let space = leo_space();
        let e = ActionTiles::<16>::new(&space, &[6.67; 2], 10).unwrap_err();
        assert_eq!(e.param, "action tile widths");
        let e = ActionTiles::<16>::new(&space, &[6.67, 0.0, 6.67], 10).unwrap_err();
        assert_eq!((e.param, e.index), ("action tile width", Some(1)));
        let e = ActionTiles::<16>::new(&space, &[6.67, f32::NAN, 6.67], 10).unwrap_err();
        assert_eq!(e.index, Some(1));
        // Tiles narrower than the level spacing: 7 tiles per dimension, 343.
        let e = ActionTiles::<16>::new(&space, &[1.0; 3], 10).unwrap_err();
        assert_eq!(e.param, "action tile combinations");
    }
}
