//! Discrete multi-dimensional actions.
//!
//! Each action dimension (a motor) has its own ascending set of levels
//! (3 torques for the pendulum, 7 voltages for each of LEO's 3 learned
//! joints). The agent works on joint action indices: the index of the level
//! combination `(l_0, …, l_(k−1))` is `Σ l_i · Π_(m<i) n_m`, the first
//! dimension varying fastest (as GRL's uniform discretiser,
//! `docs/reference/grl.md` §3.4).

use crate::error::ConfigError;
use heapless::Vec;

pub use crate::limits::{MAX_ACTION_DIMS, MAX_LEVELS};

/// Levels of one action dimension, one per entry of a joint action.
pub type Levels = [u8; MAX_ACTION_DIMS];
/// The applied output of every action dimension (torque, voltage …).
pub type Output = [f32; MAX_ACTION_DIMS];

/// One action dimension: its levels in ascending order.
#[derive(Debug, Clone, PartialEq)]
pub struct ActionDim {
    levels: Vec<f32, MAX_LEVELS>,
}

impl ActionDim {
    /// `n` levels evenly spaced over `[min, max]` (both ends included).
    pub fn uniform(min: f32, max: f32, n: usize) -> Result<ActionDim, ConfigError> {
        if !(2..=MAX_LEVELS).contains(&n) {
            return Err(ConfigError::new("action levels", n as f32, "2 ..= 16 levels per action dimension"));
        }
        if !min.is_finite() || !max.is_finite() || max <= min {
            return Err(ConfigError::new("action max", max, "finite, with action min < action max"));
        }
        let mut levels = Vec::new();
        for i in 0..n {
            // Computed from both ends so that min and max are exact.
            let t = i as f32 / (n - 1) as f32;
            let _ = levels.push(min * (1.0 - t) + max * t);
        }
        Ok(ActionDim { levels })
    }

    /// Explicit levels, which must be finite and strictly ascending.
    pub fn from_levels(values: &[f32]) -> Result<ActionDim, ConfigError> {
        if values.is_empty() || values.len() > MAX_LEVELS {
            return Err(ConfigError::new("action levels", values.len() as f32, "1 ..= 16 levels per action dimension"));
        }
        let mut levels = Vec::new();
        for (i, &v) in values.iter().enumerate() {
            if !v.is_finite() || (i > 0 && v <= values[i - 1]) {
                return Err(ConfigError::new("action level", v, "finite and strictly ascending").at(i));
            }
            let _ = levels.push(v);
        }
        Ok(ActionDim { levels })
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Always false: a dimension has at least one level.
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }

    /// The value of `level`.
    pub fn value(&self, level: u8) -> f32 {
        self.levels[level as usize]
    }

    /// The levels' values.
    pub fn values(&self) -> &[f32] {
        &self.levels
    }

    /// `max − min`: the size of the action range that Δ is relative to.
    pub fn range(&self) -> f32 {
        self.levels[self.levels.len() - 1] - self.levels[0]
    }

    /// Smallest value.
    pub fn min(&self) -> f32 {
        self.levels[0]
    }

    /// Largest value.
    pub fn max(&self) -> f32 {
        self.levels[self.levels.len() - 1]
    }

    /// The level whose value is nearest to `x` (the lower one on a tie).
    pub fn nearest(&self, x: f32) -> u8 {
        let mut best = 0;
        for (i, &v) in self.levels.iter().enumerate() {
            if (v - x).abs() < (self.levels[best] - x).abs() {
                best = i;
            }
        }
        best as u8
    }
}

/// The action space: up to [`MAX_ACTION_DIMS`] dimensions.
#[derive(Debug, Clone, PartialEq)]
pub struct ActionSpace {
    dims: Vec<ActionDim, MAX_ACTION_DIMS>,
    joint: u32,
}

impl ActionSpace {
    /// An action space over `dims` (1 ..= [`MAX_ACTION_DIMS`] dimensions).
    pub fn new(dims: &[ActionDim]) -> Result<ActionSpace, ConfigError> {
        if dims.is_empty() || dims.len() > MAX_ACTION_DIMS {
            return Err(ConfigError::new("action dimensions", dims.len() as f32, "1 ..= 4 action dimensions"));
        }
        let mut v = Vec::new();
        let mut joint = 1u32;
        for (i, d) in dims.iter().enumerate() {
            if d.is_empty() {
                return Err(ConfigError::new("action levels", 0.0, "at least one level").at(i));
            }
            joint *= d.len() as u32;
            let _ = v.push(d.clone());
        }
        Ok(ActionSpace { dims: v, joint })
    }

    /// The same `dim` repeated `count` times (LEO: 3 × 7 voltages).
    pub fn repeated(dim: ActionDim, count: usize) -> Result<ActionSpace, ConfigError> {
        if count == 0 || count > MAX_ACTION_DIMS {
            return Err(ConfigError::new("action dimensions", count as f32, "1 ..= 4 action dimensions"));
        }
        let mut dims: Vec<ActionDim, MAX_ACTION_DIMS> = Vec::new();
        for _ in 0..count {
            let _ = dims.push(dim.clone());
        }
        ActionSpace::new(&dims)
    }

    /// Number of dimensions.
    pub fn dims(&self) -> usize {
        self.dims.len()
    }

    /// Dimension `i`.
    pub fn dim(&self, i: usize) -> &ActionDim {
        &self.dims[i]
    }

    /// Number of joint actions (product of the level counts).
    pub fn joint_count(&self) -> u32 {
        self.joint
    }

    /// Joint index of a level combination (first dimension fastest).
    pub fn encode(&self, levels: &Levels) -> u32 {
        let mut idx = 0u32;
        let mut stride = 1u32;
        for (i, d) in self.dims.iter().enumerate() {
            idx += levels[i] as u32 * stride;
            stride *= d.len() as u32;
        }
        idx
    }

    /// Level combination of a joint index.
    pub fn decode(&self, mut idx: u32) -> Levels {
        let mut levels = [0u8; MAX_ACTION_DIMS];
        for (i, d) in self.dims.iter().enumerate() {
            let n = d.len() as u32;
            levels[i] = (idx % n) as u8;
            idx /= n;
        }
        levels
    }

    /// The values of a level combination; unused dimensions are 0.
    pub fn values(&self, levels: &Levels) -> Output {
        let mut out = [0.0; MAX_ACTION_DIMS];
        for (i, d) in self.dims.iter().enumerate() {
            out[i] = d.value(levels[i]);
        }
        out
    }

    /// Per dimension, the level nearest to zero (a motor at rest).
    pub fn rest_levels(&self) -> Levels {
        let mut levels = [0u8; MAX_ACTION_DIMS];
        for (i, d) in self.dims.iter().enumerate() {
            levels[i] = d.nearest(0.0);
        }
        levels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leo_space_has_343_joint_actions_and_round_trips() {
        let s = ActionSpace::repeated(ActionDim::uniform(-10.7, 10.7, 7).unwrap(), 3).unwrap();
        assert_eq!(s.joint_count(), 343);
        for idx in 0..343 {
            assert_eq!(s.encode(&s.decode(idx)), idx);
        }
        // First dimension varies fastest.
        assert_eq!(s.decode(1), [1, 0, 0, 0]);
        assert_eq!(s.decode(7), [0, 1, 0, 0]);
        assert_eq!(s.dim(0).value(0), -10.7);
        assert_eq!(s.dim(0).value(6), 10.7);
        assert_eq!(s.dim(0).value(3), 0.0);
        assert_eq!(s.rest_levels(), [3, 3, 3, 0]);
    }

    #[test]
    fn bad_levels_are_refused() {
        assert_eq!(ActionDim::uniform(1.0, 1.0, 3).unwrap_err().param, "action max");
        assert_eq!(ActionDim::uniform(-1.0, 1.0, 1).unwrap_err().param, "action levels");
        assert_eq!(ActionDim::from_levels(&[]).unwrap_err().param, "action levels");
        let e = ActionDim::from_levels(&[0.0, 1.0, 1.0]).unwrap_err();
        assert_eq!((e.param, e.index), ("action level", Some(2)));
        assert_eq!(ActionSpace::new(&[]).unwrap_err().param, "action dimensions");
    }
}
