//! LEO's stance: which leg carries the robot, footsteps and their length
//! (docs/reference/grl.md §3.3, BW `updateDerivedStateVars`).

use super::Leg;

/// What one stance update found (§3.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceUpdate {
    /// Footstep length L after the update.
    pub length: f32,
    /// L_prev for the reward (sign kept continuous across stance switches).
    pub previous_length: f32,
    /// Whether the stance leg changed (a footstep).
    pub footstep: bool,
}

/// The stance/swing state machine of §3.3 (BW `updateDerivedStateVars`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceTracker {
    stance: Option<Leg>,
    length: f32,
    last_was_footstep: bool,
    footsteps: i32,
    walked: f32,
}

impl Default for StanceTracker {
    fn default() -> Self {
        Self::new()
    }
}

impl StanceTracker {
    /// Unknown stance, no footsteps (episode start).
    pub const fn new() -> Self {
        StanceTracker { stance: None, length: 0.0, last_was_footstep: false, footsteps: 0, walked: 0.0 }
    }

    /// The current stance leg, `None` before the first update.
    pub fn stance(&self) -> Option<Leg> {
        self.stance
    }

    /// The stance leg; the start pose stands on the left leg (§1.8), so
    /// that is the answer before any foot ever touched.
    pub fn stance_or_left(&self) -> Leg {
        self.stance.unwrap_or(Leg::Left)
    }

    /// Footstep count: +1 per forward step, −1 per backward step.
    pub fn footsteps(&self) -> i32 {
        self.footsteps
    }

    /// Walked distance: the sum of footstep lengths \[m\].
    pub fn walked(&self) -> f32 {
        self.walked
    }

    /// One update after a control step. `contact_left/right`: toe or heel
    /// of that foot touches; `ankle_left/right`: [`ankle_x`] of each leg.
    ///
    /// - stance: only left touches → left; only right → right; neither →
    ///   unchanged; both → the front foot (larger ankle x);
    /// - L = x_a(swing) − x_a(stance) with the stance from *before* this
    ///   update (unknown before the first update: L = x_L − x_R);
    /// - a footstep is a stance change with a known previous stance:
    ///   count ±1 by the sign of L, walked distance += L;
    /// - L_prev = old L, negated if the previous update was a footstep.
    pub fn update(
        &mut self,
        contact_left: bool,
        contact_right: bool,
        ankle_left: f32,
        ankle_right: f32,
    ) -> StanceUpdate {
        let previous_length = if self.last_was_footstep { -self.length } else { self.length };
        let before = self.stance;
        let after = match (contact_left, contact_right) {
            (true, false) => Some(Leg::Left),
            (false, true) => Some(Leg::Right),
            (false, false) => before,
            (true, true) => Some(if ankle_left >= ankle_right { Leg::Left } else { Leg::Right }),
        };
        let x = |leg: Leg| match leg {
            Leg::Left => ankle_left,
            Leg::Right => ankle_right,
        };
        self.length = match before {
            Some(st) => x(st.other()) - x(st),
            None => ankle_left - ankle_right,
        };
        let footstep = before.is_some() && after != before;
        if footstep {
            self.footsteps += if self.length > 0.0 { 1 } else { -1 };
            self.walked += self.length;
        }
        self.last_was_footstep = footstep;
        self.stance = after;
        StanceUpdate { length: self.length, previous_length, footstep }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stance_logic_follows_section_3_3() {
        let mut s = StanceTracker::new();
        // First update, left on the floor, right foot ahead by 0.02 m:
        // previous stance unknown → L = x_L − x_R.
        let u = s.update(true, false, 0.01, 0.03);
        assert_eq!(s.stance(), Some(Leg::Left));
        assert!((u.length - (-0.02)).abs() < 1e-6 && !u.footstep);
        // Still left stance: L = x_R − x_L.
        let u = s.update(true, false, 0.0, 0.05);
        assert!((u.length - 0.05).abs() < 1e-6 && (u.previous_length + 0.02).abs() < 1e-6);
        // Right touches down ahead: both feet down, right is in front → footstep.
        let u = s.update(true, true, -0.04, 0.06);
        assert!(u.footstep && s.stance() == Some(Leg::Right));
        assert!((u.length - 0.10).abs() < 1e-6);
        assert_eq!(s.footsteps(), 1);
        assert!((s.walked() - 0.10).abs() < 1e-6);
        // Next update: L is measured for the right stance, L_prev is −L.
        let u = s.update(false, true, -0.05, 0.05);
        assert!((u.previous_length + 0.10).abs() < 1e-6);
        assert!((u.length + 0.10).abs() < 1e-6);
        // Neither foot: keep stance.
        s.update(false, false, 0.0, 0.0);
        assert_eq!(s.stance(), Some(Leg::Right));
        // Backward step: left lands behind → footstep −1.
        let u = s.update(true, false, -0.1, 0.0);
        assert!(u.footstep && u.length < 0.0);
        assert_eq!(s.footsteps(), 0);
    }
}
