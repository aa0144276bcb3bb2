//! The wear governor: learning within a stated gearbox life. Given a budget
//! — the smallest predicted MTBF the user accepts — it moves PADA's Δ
//! (Eq. 9) or the low-pass filter's α (Eq. 8) while the robot learns, from
//! the damage the fatigue counter counts (Eqs. 3–7), so that the predicted
//! MTBF over the last [`WINDOW_STEPS`] learning actions stays at or above
//! the budget while the learner is restricted as little as possible.
//!
//! # What it measures
//!
//! Every learning action, the damage each governed gearbox took in it (the
//! increase of the fatigue counter's damage, in its exact Q16.48 units),
//! summed over a sliding window of the last [`WINDOW_STEPS`] = 1200
//! learning actions (the paper's MTBF window, end of Section IV) in
//! [`WINDOW_BUCKETS`] buckets of [`BUCKET_STEPS`]: the window covers the
//! last 1101–1200 actions once it is full, every action before that. The
//! robot's MTBF is its weakest gearbox's, so the governor follows the
//! gearbox with the most damage in the window.
//!
//! # How it moves Δ or α
//!
//! The budget `B` allows the window `covered·T/B` of damage (`covered`
//! learning actions of period `T`); the **headroom** is that allowance less
//! the weakest gearbox's window damage. The governor knows, from the
//! model, the damage `d` of one re-engagement at the largest torque a
//! learning action can command (Eqs. 3–7): the most one action can add to
//! a gearbox. A full window's allowance pays for `N = W·T/(B·d)` such
//! re-engagements. The governor keeps a **reserve**
//! `r = d·(1 + z·√N)`, `z = 1.2816`: one worst re-engagement (what the next
//! action can add before the governor can react) plus the spread of the
//! window's count of re-engagements — a count of independent events varies
//! about its mean by its square root, and `z` is the normal quantile that
//! is exceeded in 10 % of windows, the target of holding the budget
//! in at least 90 % of trials. After every learning action:
//!
//! - headroom below `d` — the next worst re-engagement would break the
//!   budget: restrict **one rung at every action** while it lasts, without
//!   waiting for the last move to show (no rung makes the next action's
//!   damage 0 — a re-engagement at the floor costs the same `d` — so what
//!   a rung changes is the rate, and jumping to the floor would restrict
//!   far more than one dip needs);
//! - headroom below `r`, and the rung in force **spending** — the headroom
//!   fell since the last move, so this rung costs more than the budget
//!   earns: restrict **one rung**, at most once per `m = ⌈d·B/T⌉` actions
//!   (the time the budget takes to earn one worst re-engagement: long
//!   enough for the last move to show in the damage);
//! - headroom of `r + d` or more — room for the relaxed rung's first worst
//!   re-engagement with the reserve intact — the headroom at or above `r`
//!   for `m` actions since the last move, and the rung in force **not
//!   spending** (it earns at least what it costs): relax **one rung**;
//! - otherwise keep the rung.
//!
//! Tightening only a rung that spends, and relaxing only one that does
//! not, is a comparison of the rung's damage *rate* with the budget's, not
//! only of the window's level: acting on the level alone (the headroom, an
//! integral) overshoots by the window's lag and swings over the whole
//! ladder (measured on the pendulum at a 2600 s budget: the low-pass α
//! between 0.1 and 1, 22 % of the time at 0.1). With the rate test the
//! governor settles between the two rungs whose rates bracket the budget's.
//!
//! The allowance grows from 0 with the first action, so a run **starts at
//! the floor and relaxes** as the budget pays for it: the paper's MTBF over
//! the first 1200 actions is held from the start, not only on average.
//! Moving one rung at a time keeps the learner's actions from lurching
//! (the low-pass filter from α = 1 to 0.1 in a step).
//!
//! # Bounds
//!
//! PADA's Δ moves over `k/(L − 1)` for `k = 1 … L − 1` (`L` levels per
//! dimension): **never below one level, never above the full range**
//! (Δ = 1, which is SARSA(λ)'s choice). The low-pass α moves over
//! [`LOWPASS_LADDER`], the paper's α sweep from 0.1 to 1 (no filtering).
//! A budget the floor cannot hold is not held: the governor then stays at
//! the floor and counts the actions whose window was over budget
//! ([`GovernorStatus::over_budget_steps`]).
//!
//! # Determinism
//!
//! Every decision is integer arithmetic on the counter's Q16.48 damage;
//! the allowance per action and `d` are computed once, in `f64` with
//! `libm` (software, identical on host and chip). No clock, no float sum
//! whose order could differ: a replay moves Δ at the same actions, bit for
//! bit. The state ([`GovernorState`]) goes into the checkpoint.

use crate::action_space::ActionSpace;
use crate::error::ConfigError;
use crate::fatigue::{damage_of_raw, FatigueModel, GearboxParams, PAPER_WINDOW_STEPS};
use crate::policy::PolicyKind;

/// Learning actions per bucket of the sliding window.
pub const BUCKET_STEPS: u32 = 100;
/// Buckets of the sliding window.
pub const WINDOW_BUCKETS: usize = 12;
/// Learning actions in the sliding window: the paper's 1200.
pub const WINDOW_STEPS: u32 = BUCKET_STEPS * WINDOW_BUCKETS as u32;
const _: () = assert!(WINDOW_STEPS == PAPER_WINDOW_STEPS);
/// Gearboxes a governor follows (LEO's two hips and two knees).
pub const GOVERNED_JOINTS: usize = 4;
/// The low-pass filter's α rungs, most restrictive first: the α values the
/// paper sweeps on the pendulum (Section VII) and α = 1, no filtering.
pub const LOWPASS_LADDER: [f32; 7] = [0.1, 0.25, 0.5, 0.7, 0.834, 0.9, 1.0];
/// The standard normal quantile exceeded with probability 0.1: the
/// reserve covers the window's count of re-engagements up to it, so a
/// governor running at its allowance breaks the budget in about one window
/// in ten (the target: held in at least 90 % of trials).
pub const HOLD_QUANTILE: f64 = 1.2816;
/// Largest budget \[s\]: about 300 years, well above any gearbox's
/// predicted life in the paper (10⁸ s on the physical pendulum); keeps the
/// allowance per action at least one damage unit on a 1 ms control period.
pub const MAX_BUDGET_S: f32 = 1.0e10;

/// What a governor moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Restricts {
    /// PADA's Δ (Eq. 9).
    Delta,
    /// The low-pass filter's α (Eq. 8).
    Alpha,
}

impl Restricts {
    /// A stable number for the checkpoint.
    pub const fn code(self) -> u8 {
        match self {
            Restricts::Delta => 0,
            Restricts::Alpha => 1,
        }
    }

    /// The restriction of a [`code`](Self::code).
    pub const fn from_code(code: u8) -> Option<Restricts> {
        match code {
            0 => Some(Restricts::Delta),
            1 => Some(Restricts::Alpha),
            _ => None,
        }
    }
}

/// How a governor is set up: the budget and what the robot's actions can
/// cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GovernorConfig {
    /// The budget: the smallest predicted MTBF accepted \[s\],
    /// `0 < budget_s ≤` [`MAX_BUDGET_S`].
    pub budget_s: f32,
    /// The control period \[s per learning action\].
    pub period_s: f64,
    /// The gearbox whose fatigue is counted (the fatigue counter's).
    pub gearbox: GearboxParams,
    /// The largest gear torque one learning action can command \[N·m\]:
    /// its re-engagement is the most damage one action can add.
    pub worst_torque_nm: f32,
    /// Gearboxes followed, `1 ..=` [`GOVERNED_JOINTS`].
    pub joints: u8,
}

/// A governor's state as plain data, for a checkpoint
/// ([`Governor::state`], [`Governor::restore`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GovernorState {
    /// The budget \[s\], as `f32` bits (so the state compares exactly).
    pub budget_bits: u32,
    /// What it moves.
    pub restricts: Restricts,
    /// The rung in force, 0 the floor.
    pub rung: u8,
    /// The bucket being filled.
    pub cursor: u8,
    /// Full buckets before it, up to `WINDOW_BUCKETS − 1`.
    pub filled: u8,
    /// Actions in the bucket being filled, below [`BUCKET_STEPS`].
    pub in_bucket: u8,
    /// Actions since the last move or since the headroom was last below
    /// the reserve.
    pub calm_steps: u32,
    /// Actions since the last move.
    pub since_move: u32,
    /// Moves so far.
    pub moves: u32,
    /// Learning actions observed.
    pub steps: u64,
    /// Actions after which the window was over budget.
    pub over_budget_steps: u64,
    /// The headroom right after the last move (or at the start), Q16.48,
    /// clamped to `i64`: a later headroom below it means the rung in force
    /// spends more than the budget earns.
    pub headroom_at_move: i64,
    /// Damage per gearbox and bucket, Q16.48.
    pub buckets: [[u64; WINDOW_BUCKETS]; GOVERNED_JOINTS],
}

impl GovernorState {
    /// The budget \[s\].
    pub fn budget_s(&self) -> f32 {
        f32::from_bits(self.budget_bits)
    }
}

/// What a governor reports in telemetry (`wire::PolicyReport`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GovernorStatus {
    /// The budget \[s\].
    pub budget_s: f32,
    /// What it moves.
    pub restricts: Restricts,
    /// The Δ or α in force.
    pub parameter: f32,
    /// The rung in force, 0 the floor.
    pub rung: u8,
    /// Rungs on the ladder.
    pub rungs: u8,
    /// Learning actions the window covers now.
    pub window_steps: u32,
    /// The weakest gearbox's damage rate over the window \[J per s\].
    pub damage_rate: f32,
    /// The predicted MTBF over the window \[s\] (the weakest gearbox's;
    /// infinite without damage).
    pub window_mtbf_s: f32,
    /// Moves so far.
    pub moves: u32,
    /// Learning actions after which the window was over budget.
    pub over_budget_steps: u32,
}

/// The wear governor (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Governor {
    restricts: Restricts,
    /// PADA's Δ step count `L − 1`, or the ladder's length.
    rungs: u8,
    budget_s: f32,
    period_s: f64,
    joints: u8,
    /// Allowed damage per learning action, Q16.48.
    per_step: u64,
    /// One worst re-engagement `d`, Q16.48.
    worst: u64,
    /// The reserve `d·(1 + z·√N)`, Q16.48.
    reserve: u64,
    /// Calm actions before a relaxation.
    relax_after: u32,
    state: GovernorState,
}

impl Governor {
    /// A governor of the built policy `kind` (PADA or the low-pass filter)
    /// on `motor`, starting at its floor. Errors name the parameter and its
    /// range: a policy other than `pada` or `lowpass`, a budget outside
    /// `0 < budget ≤ 1e10 s`, a non-positive period or worst torque, a
    /// gearbox the fatigue model refuses, 0 or more than four gearboxes,
    /// a motor without two levels to move between.
    pub fn new(kind: &PolicyKind, motor: &ActionSpace, config: &GovernorConfig) -> Result<Governor, ConfigError> {
        let restricts = match kind {
            PolicyKind::Pada { .. } => Restricts::Delta,
            PolicyKind::LowPass { .. } => Restricts::Alpha,
            _ => {
                return Err(ConfigError::new(
                    "mtbf budget policy",
                    crate::policy::kind_code(kind) as f32,
                    "pada or lowpass (the governor moves PADA's delta or the filter's alpha)",
                ))
            }
        };
        let b = config.budget_s;
        if !(b.is_finite() && b > 0.0 && b <= MAX_BUDGET_S) {
            return Err(ConfigError::new("mtbf budget", b, "0 < mtbf budget <= 1e10 s"));
        }
        if !(config.period_s.is_finite() && config.period_s > 0.0) {
            return Err(ConfigError::new("control period", config.period_s as f32, "0 < period < inf (s)"));
        }
        let t = config.worst_torque_nm;
        if !(t.is_finite() && t > 0.0) {
            return Err(ConfigError::new("worst torque", t, "0 < worst torque < inf (N m)"));
        }
        if config.joints == 0 || config.joints as usize > GOVERNED_JOINTS {
            return Err(ConfigError::new("governed gearboxes", config.joints as f32, "1 ..= 4"));
        }
        let model = FatigueModel::new(&config.gearbox)
            .map_err(|_| ConfigError::new("gearbox", 0.0, "parameters the fatigue model accepts (Table I)"))?;
        let rungs = match restricts {
            Restricts::Delta => (0..motor.dims()).map(|i| motor.dim(i).len()).max().unwrap_or(0).saturating_sub(1),
            Restricts::Alpha => LOWPASS_LADDER.len(),
        };
        if rungs < 1 {
            return Err(ConfigError::new("action levels", 1.0, "at least 2 levels for the governor to move between"));
        }
        let per_step = crate::fatigue::raw_of_damage(config.period_s / b as f64).max(1);
        let worst = model.damage_raw(t as f64).max(1);
        // N worst re-engagements fit a full window's allowance.
        let n = WINDOW_STEPS as f64 * per_step as f64 / worst as f64;
        let reserve = crate::fatigue::raw_of_damage(
            crate::fatigue::damage_of_raw(worst) * (1.0 + HOLD_QUANTILE * libm::sqrt(n)),
        );
        let relax_after = worst.div_ceil(per_step).min(u32::MAX as u64) as u32;
        Ok(Governor {
            restricts,
            rungs: rungs as u8,
            budget_s: b,
            period_s: config.period_s,
            joints: config.joints,
            per_step,
            worst,
            reserve,
            relax_after,
            state: GovernorState {
                budget_bits: b.to_bits(),
                restricts,
                rung: 0,
                cursor: 0,
                filled: 0,
                in_bucket: 0,
                calm_steps: 0,
                since_move: 0,
                moves: 0,
                steps: 0,
                over_budget_steps: 0,
                headroom_at_move: 0,
                buckets: [[0; WINDOW_BUCKETS]; GOVERNED_JOINTS],
            },
        })
    }

    /// The budget \[s\].
    pub fn budget_s(&self) -> f32 {
        self.budget_s
    }

    /// What it moves.
    pub fn restricts(&self) -> Restricts {
        self.restricts
    }

    /// Rungs on its ladder.
    pub fn rungs(&self) -> u8 {
        self.rungs
    }

    /// The rung in force, 0 the floor.
    pub fn rung(&self) -> u8 {
        self.state.rung
    }

    /// The Δ or α of `rung` (clamped to the ladder).
    pub fn parameter_of(&self, rung: u8) -> f32 {
        let r = rung.min(self.rungs - 1);
        match self.restricts {
            Restricts::Delta => (r as f32 + 1.0) / self.rungs as f32,
            Restricts::Alpha => LOWPASS_LADDER[r as usize],
        }
    }

    /// The Δ or α in force: set the policy to it when the governor starts
    /// (and after a restore).
    pub fn parameter(&self) -> f32 {
        self.parameter_of(self.state.rung)
    }

    /// Actions of calm needed before a relaxation.
    pub fn relax_after(&self) -> u32 {
        self.relax_after
    }

    /// The damage of one worst re-engagement `d`, Q16.48.
    pub fn worst_raw(&self) -> u64 {
        self.worst
    }

    /// The reserve `d·(1 + z·√N)` below which it restricts, Q16.48.
    pub fn reserve_raw(&self) -> u64 {
        self.reserve
    }

    /// Learning actions the window covers now.
    pub fn window_steps(&self) -> u32 {
        self.state.filled as u32 * BUCKET_STEPS + self.state.in_bucket as u32
    }

    /// The weakest governed gearbox's damage in the window, Q16.48.
    pub fn window_damage_raw(&self) -> u64 {
        self.state.buckets[..self.joints as usize]
            .iter()
            .map(|b| b.iter().fold(0u64, |s, &x| s.saturating_add(x)))
            .max()
            .unwrap_or(0)
    }

    /// The allowance less the weakest gearbox's window damage, Q16.48
    /// (negative when over budget).
    pub fn headroom_raw(&self) -> i128 {
        self.window_steps() as i128 * self.per_step as i128 - self.window_damage_raw() as i128
    }

    /// One learning action: `increments[j]` is the damage gearbox `j` took
    /// in it (the increase of its fatigue counter's Q16.48 damage; entries
    /// past the governed gearboxes are ignored, missing ones count 0).
    /// Returns the new Δ or α when the governor moved, for the policy to
    /// take before the next decision.
    pub fn observe(&mut self, increments: &[u64]) -> Option<f32> {
        let s = &mut self.state;
        s.steps = s.steps.saturating_add(1);
        let cursor = s.cursor as usize;
        for (j, &inc) in increments.iter().take(self.joints as usize).enumerate() {
            s.buckets[j][cursor] = s.buckets[j][cursor].saturating_add(inc);
        }
        s.in_bucket += 1;
        let headroom = self.headroom_raw();
        let s = &mut self.state;
        if headroom < 0 {
            s.over_budget_steps = s.over_budget_steps.saturating_add(1);
        }
        if s.in_bucket as u32 == BUCKET_STEPS {
            // The oldest bucket leaves the window when a new one starts.
            s.cursor = ((cursor + 1) % WINDOW_BUCKETS) as u8;
            for b in s.buckets.iter_mut() {
                b[s.cursor as usize] = 0;
            }
            s.in_bucket = 0;
            s.filled = (s.filled + 1).min(WINDOW_BUCKETS as u8 - 1);
        }
        s.since_move = s.since_move.saturating_add(1);
        let (reserve, worst) = (self.reserve as i128, self.worst as i128);
        // Whether the rung in force spends the window's allowance faster
        // than the budget earns it: the headroom fell since the last move.
        let spending = headroom < s.headroom_at_move as i128;
        let rung = if headroom < worst {
            // The next action could break the budget: one rung per action,
            // without waiting for the last move to show.
            s.calm_steps = 0;
            s.rung.saturating_sub(1)
        } else if headroom < reserve {
            s.calm_steps = 0;
            if s.since_move >= self.relax_after && spending {
                s.rung.saturating_sub(1)
            } else {
                s.rung
            }
        } else {
            s.calm_steps = s.calm_steps.saturating_add(1);
            if headroom >= reserve + worst && s.calm_steps >= self.relax_after && !spending && s.rung + 1 < self.rungs {
                s.rung + 1
            } else {
                s.rung
            }
        };
        if rung == s.rung {
            return None;
        }
        s.rung = rung;
        s.calm_steps = 0;
        s.since_move = 0;
        s.headroom_at_move = headroom.clamp(i64::MIN as i128, i64::MAX as i128) as i64;
        s.moves = s.moves.saturating_add(1);
        Some(self.parameter())
    }

    /// What telemetry reports.
    pub fn status(&self) -> GovernorStatus {
        let steps = self.window_steps();
        let damage = damage_of_raw(self.window_damage_raw());
        let elapsed = steps as f64 * self.period_s;
        GovernorStatus {
            budget_s: self.budget_s,
            restricts: self.restricts,
            parameter: self.parameter(),
            rung: self.state.rung,
            rungs: self.rungs,
            window_steps: steps,
            damage_rate: if steps > 0 { (damage / elapsed) as f32 } else { 0.0 },
            window_mtbf_s: if damage > 0.0 { (elapsed / damage) as f32 } else { f32::INFINITY },
            moves: self.state.moves,
            over_budget_steps: self.state.over_budget_steps.min(u32::MAX as u64) as u32,
        }
    }

    /// The state as plain data.
    pub fn state(&self) -> GovernorState {
        self.state
    }

    /// Checks that `state` is one this governor could have reached; the
    /// error names the field and its valid range: the same budget and
    /// restriction, the rung on the ladder, the window's cursor, fill and
    /// bucket position in range, no damage for gearboxes it does not
    /// follow, no more moves or over-budget actions than actions.
    pub fn check_state(&self, state: &GovernorState) -> Result<(), ConfigError> {
        let s = state;
        if s.budget_bits != self.budget_s.to_bits() {
            return Err(ConfigError::new("governor.budget", s.budget_s(), "the running governor's budget"));
        }
        if s.restricts != self.restricts {
            return Err(ConfigError::new(
                "governor.restricts",
                s.restricts.code() as f32,
                "the running governor's (0 pada delta, 1 lowpass alpha)",
            ));
        }
        if s.rung >= self.rungs {
            return Err(ConfigError::new("governor.rung", s.rung as f32, "below the ladder's number of rungs"));
        }
        if s.cursor as usize >= WINDOW_BUCKETS {
            return Err(ConfigError::new("governor.cursor", s.cursor as f32, "0 ..= 11"));
        }
        if s.filled as usize >= WINDOW_BUCKETS {
            return Err(ConfigError::new("governor.filled", s.filled as f32, "0 ..= 11"));
        }
        if s.in_bucket as u32 >= BUCKET_STEPS {
            return Err(ConfigError::new("governor.in_bucket", s.in_bucket as f32, "0 ..= 99"));
        }
        if s.filled as u64 * BUCKET_STEPS as u64 + s.in_bucket as u64 > s.steps {
            return Err(ConfigError::new("governor.steps", s.steps as f32, "at least the actions the window covers"));
        }
        if s.moves as u64 > s.steps
            || s.over_budget_steps > s.steps
            || s.calm_steps as u64 > s.steps
            || s.since_move as u64 > s.steps
        {
            return Err(ConfigError::new(
                "governor.moves",
                s.moves as f32,
                "moves, over-budget, calm actions and actions since a move <= actions",
            ));
        }
        if let Some(j) = (self.joints as usize..GOVERNED_JOINTS).find(|&j| s.buckets[j].iter().any(|&b| b != 0)) {
            return Err(ConfigError::new("governor.buckets", j as f32, "0 for a gearbox the governor does not follow").at(j));
        }
        Ok(())
    }

    /// Restores a state that passes [`check_state`](Self::check_state); a
    /// refused one changes nothing. Set the policy's parameter to
    /// [`parameter`](Self::parameter) afterwards.
    pub fn restore(&mut self, state: &GovernorState) -> Result<(), ConfigError> {
        self.check_state(state)?;
        self.state = *state;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::action_space::ActionDim;
    use proptest::prelude::*;

    fn pendulum() -> ActionSpace {
        ActionSpace::new(&[ActionDim::from_levels(&[-1.5, 0.0, 1.5]).unwrap()]).unwrap()
    }

    fn leo() -> ActionSpace {
        ActionSpace::repeated(ActionDim::uniform(-10.7, 10.7, 7).unwrap(), 3).unwrap()
    }

    fn config(budget_s: f32, joints: u8) -> GovernorConfig {
        GovernorConfig { budget_s, period_s: 0.05, gearbox: GearboxParams::TABLE_I, worst_torque_nm: 1.5, joints }
    }

    fn worst() -> u64 {
        FatigueModel::new(&GearboxParams::TABLE_I).unwrap().damage_raw(1.5)
    }

    #[test]
    fn pada_rungs_are_one_level_to_the_full_range() {
        let g = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &leo(), &config(2000.0, 4)).unwrap();
        assert_eq!(g.rungs(), 6);
        let deltas: std::vec::Vec<f32> = (0..6).map(|r| g.parameter_of(r)).collect();
        assert_eq!(deltas[0], 1.0 / 6.0);
        assert_eq!(deltas[5], 1.0);
        assert_eq!(g.parameter(), 1.0 / 6.0, "starts at the floor");
        let p = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &pendulum(), &config(2000.0, 1)).unwrap();
        assert_eq!((p.rungs(), p.parameter_of(0), p.parameter_of(1)), (2, 0.5, 1.0));
        let a = Governor::new(&PolicyKind::LowPass { alpha: 0.834 }, &pendulum(), &config(2000.0, 1)).unwrap();
        assert_eq!((a.rungs(), a.parameter(), a.parameter_of(6)), (7, 0.1, 1.0));
    }

    #[test]
    fn bad_configurations_name_the_parameter() {
        let m = pendulum();
        let pada = PolicyKind::Pada { delta: 0.5 };
        let param = |k: &PolicyKind, c: GovernorConfig| Governor::new(k, &m, &c).unwrap_err().param;
        assert_eq!(param(&PolicyKind::Sarsa, config(100.0, 1)), "mtbf budget policy");
        assert_eq!(param(&PolicyKind::Integrator { delta: 0.5 }, config(100.0, 1)), "mtbf budget policy");
        for b in [0.0, -1.0, f32::NAN, f32::INFINITY, 2e10] {
            assert_eq!(param(&pada, config(b, 1)), "mtbf budget", "{b}");
        }
        assert_eq!(param(&pada, config(100.0, 0)), "governed gearboxes");
        assert_eq!(param(&pada, config(100.0, 5)), "governed gearboxes");
        assert_eq!(param(&pada, GovernorConfig { worst_torque_nm: 0.0, ..config(100.0, 1) }), "worst torque");
        assert_eq!(param(&pada, GovernorConfig { period_s: 0.0, ..config(100.0, 1) }), "control period");
        let two = ActionSpace::new(&[ActionDim::from_levels(&[1.0]).unwrap()]).unwrap();
        assert_eq!(Governor::new(&pada, &two, &config(100.0, 1)).unwrap_err().param, "action levels");
    }

    #[test]
    fn it_starts_at_the_floor_and_relaxes_as_the_budget_pays() {
        let mut g = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &pendulum(), &config(2600.0, 1)).unwrap();
        // Allowance per action 0.05/2600 J; one 1.5 N·m re-engagement
        // 1.3289e-4 J: the budget earns one in ⌈6.9⌉ = 7 actions.
        assert_eq!(g.relax_after(), 7);
        let mut moves = std::vec::Vec::new();
        for k in 1..=20 {
            if let Some(p) = g.observe(&[0]) {
                moves.push((k, p));
            }
        }
        // N = 1200·0.05/2600/d = 173.7 worst re-engagements per window:
        // the reserve is d·(1 + 1.2816·√173.7) = 17.9·d, earned in 124
        // actions; relaxing needs r + d, 131 actions, and 7 calm ones.
        assert!((g.reserve_raw() as f64 / worst() as f64 - 17.89).abs() < 0.01);
        for k in 21..=140 {
            if let Some(p) = g.observe(&[0]) {
                moves.push((k, p));
            }
        }
        assert_eq!(moves, [(131, 1.0)]);
        // Headroom 19.4·d after 141 actions: worst re-engagements at every
        // action take it below r at the third (18.1·d − 3·d + 2·0.145·d).
        assert_eq!(g.observe(&[worst()]), None);
        assert_eq!(g.observe(&[worst()]), None);
        assert_eq!(g.observe(&[worst()]), Some(0.5));
        assert_eq!(g.status().moves, 2);
        assert_eq!(g.status().over_budget_steps, 0);
    }

    #[test]
    fn it_tightens_a_spending_rung_one_per_dwell_and_one_per_action_in_an_emergency() {
        let mut g = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &leo(), &config(500.0, 4)).unwrap();
        let m = g.relax_after();
        // A long calm: the governor climbs to the full range.
        for _ in 0..1000 {
            g.observe(&[0; 4]);
        }
        assert_eq!(g.parameter(), 1.0);
        // Damage that keeps the headroom between d and r and falling by one
        // unit an action (the rung spends): one rung per m actions.
        let target = g.reserve_raw() as i128 - g.worst_raw() as i128 / 2;
        let mut rungs = std::vec::Vec::new();
        for k in 0..3 * m as i128 {
            let need = (g.headroom_raw() + g.per_step as i128 - (target - k)).max(0) as u64;
            g.observe(&[need, 0, 0, 0]);
            rungs.push(g.rung());
        }
        assert_eq!(rungs[0], 4, "the first action below r moves one rung");
        assert_eq!(rungs[3 * m as usize - 1], 2, "then one per {m} actions: {rungs:?}");
        // Below d: one rung at every action, down to the floor.
        let flood = [g.reserve_raw() * 2, 0, 0, 0];
        assert_eq!(g.observe(&flood), Some(2.0 / 6.0));
        assert_eq!(g.observe(&flood), Some(1.0 / 6.0));
        assert_eq!(g.observe(&flood), None, "at the floor");
    }

    #[test]
    fn a_rung_that_earns_its_damage_is_kept_below_the_reserve() {
        let mut g = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &leo(), &config(500.0, 4)).unwrap();
        for _ in 0..1000 {
            g.observe(&[0; 4]);
        }
        assert_eq!(g.rung(), 5);
        // Push the headroom just below r once (one move down), then let it
        // rise by one unit an action: the rung in force earns more than it
        // costs, so the governor holds it however long it stays below r.
        let target = g.reserve_raw() as i128 - g.worst_raw() as i128 / 2;
        let need = (g.headroom_raw() + g.per_step as i128 - target).max(0) as u64;
        assert_eq!(g.observe(&[need, 0, 0, 0]), Some(5.0 / 6.0));
        for k in 1..=10 * g.relax_after() as i128 {
            let need = (g.headroom_raw() + g.per_step as i128 - (target + k)).max(0) as u64;
            assert_eq!(g.observe(&[need, 0, 0, 0]), None, "action {k}");
        }
        assert!(g.headroom_raw() < g.reserve_raw() as i128);
    }

    #[test]
    fn damage_leaves_the_window_after_1200_actions() {
        let mut g = Governor::new(&PolicyKind::LowPass { alpha: 0.5 }, &pendulum(), &config(1.0e6, 1)).unwrap();
        g.observe(&[1 << 40]);
        for _ in 1..WINDOW_STEPS - BUCKET_STEPS {
            g.observe(&[0]);
        }
        // 1100 actions: the first bucket is still in the window.
        assert_eq!(g.window_damage_raw(), 1 << 40);
        for _ in 0..BUCKET_STEPS {
            g.observe(&[0]);
        }
        assert_eq!(g.window_steps(), WINDOW_STEPS - BUCKET_STEPS);
        assert_eq!(g.window_damage_raw(), 0, "the first bucket left the window");
        assert_eq!(g.state().steps, WINDOW_STEPS as u64);
    }

    #[test]
    fn the_weakest_gearbox_decides() {
        let mut g = Governor::new(&PolicyKind::Pada { delta: 0.2 }, &leo(), &config(100.0, 4)).unwrap();
        g.observe(&[1, 500, 3, 0, 1_000_000]);
        assert_eq!(g.window_damage_raw(), 500, "the fifth entry is not a governed gearbox");
        let s = g.status();
        assert_eq!(s.window_steps, 1);
        let expected = 0.05 / damage_of_raw(500);
        assert!((s.window_mtbf_s as f64 - expected).abs() / expected < 1e-6);
    }

    #[test]
    fn a_budget_the_floor_cannot_hold_is_counted() {
        let mut g = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &pendulum(), &config(1.0e6, 1)).unwrap();
        for _ in 0..100 {
            assert_eq!(g.observe(&[worst()]), None, "at the floor already");
        }
        assert_eq!(g.status().over_budget_steps, 100);
        assert_eq!(g.rung(), 0);
    }

    #[test]
    fn states_round_trip_and_bad_ones_are_refused() {
        let mut g = Governor::new(&PolicyKind::Pada { delta: 0.2 }, &leo(), &config(300.0, 4)).unwrap();
        for k in 0..2345u64 {
            g.observe(&[k % 7 * 1000, 0, k % 3 * 10_000_000, 0]);
        }
        let s = g.state();
        let mut h = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &leo(), &config(300.0, 4)).unwrap();
        h.restore(&s).unwrap();
        assert_eq!(h, g);
        type Change = fn(&mut GovernorState);
        let cases: [(&str, Change); 7] = [
            ("governor.budget", |s| s.budget_bits = 301.0f32.to_bits()),
            ("governor.restricts", |s| s.restricts = Restricts::Alpha),
            ("governor.rung", |s| s.rung = 6),
            ("governor.cursor", |s| s.cursor = 12),
            ("governor.in_bucket", |s| s.in_bucket = 100),
            ("governor.steps", |s| s.steps = 3),
            ("governor.moves", |s| s.moves = u32::MAX),
        ];
        for (field, change) in cases {
            let mut bad = s;
            change(&mut bad);
            assert_eq!(h.restore(&bad).unwrap_err().param, field);
            assert_eq!(h, g, "{field}: a refused state changes nothing");
        }
        let mut two = Governor::new(&PolicyKind::Pada { delta: 0.2 }, &leo(), &config(300.0, 2)).unwrap();
        assert_eq!(two.restore(&s).unwrap_err().param, "governor.buckets");
    }

    proptest! {
        /// Whatever the damage, Δ stays on the ladder (one level to the
        /// full range) and a move is one rung up or down.
        #[test]
        fn delta_stays_within_one_level_and_the_full_range(
            budget in 1.0f32..1.0e6,
            damage in prop::collection::vec(prop_oneof![Just(0u64), 0u64..1 << 38, Just(u64::MAX / 4)], 1..3000),
        ) {
            let mut g = Governor::new(&PolicyKind::Pada { delta: 0.5 }, &leo(), &config(budget, 4)).unwrap();
            let mut rung = g.rung();
            for d in damage {
                if let Some(p) = g.observe(&[d, d / 3, 0, d / 2]) {
                    prop_assert!((1.0 / 6.0..=1.0).contains(&p), "{p}");
                    prop_assert!(g.rung() == rung + 1 || g.rung() + 1 == rung);
                    prop_assert_eq!(p, g.parameter());
                }
                prop_assert!(g.rung() < 6);
                rung = g.rung();
            }
        }
    }
}
