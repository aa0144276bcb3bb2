//! The action policies as one concept: Section V's six and the four gentle
//! explorations (`kind.rs`).
//!
//! A [`Policy`] sits between the learner and the motor. It decides
//! 1. which actions the learner may choose from ([`Policy::candidates`] for
//!    the greedy choice, [`Policy::explore_candidates`] for an exploratory
//!    draw): all of them, or for PADA only those within Δ of the previous
//!    one (Eq. 9), for ε-PADA only the exploratory draws;
//! 2. what the learner's action means for the motor ([`Policy::apply`]):
//!    the level itself, a low-pass filtered level (Eq. 8) or an increment of
//!    an integrated command;
//! 3. whether the state is extended by the policy's memory
//!    ([`Policy::extension`]): the Markov variants append the previous
//!    filtered or integrated output so the learner's state stays Markov;
//! 4. for the noise explorations (`ou`, `pink`), how the greedy level is
//!    moved ([`Policy::perturb`], [`crate::exploration`]); for the
//!    action-change penalty, what the last action costs in the reward
//!    ([`Policy::penalty`]).
//!
//! | kind | learner chooses | applied output | state extended |
//! |---|---|---|---|
//! | [`PolicyKind::Sarsa`] | any level | the level | no |
//! | [`PolicyKind::LowPass`] | any level | `α·a + (1 − α)·prev` (Eq. 8) | no |
//! | [`PolicyKind::MarkovLowPass`] | any level | as low-pass | by `prev` |
//! | [`PolicyKind::Integrator`] | −Δ, 0, +Δ | `clip(prev + inc)` | no |
//! | [`PolicyKind::MarkovIntegrator`] | −Δ, 0, +Δ | as integrator | by `prev` |
//! | [`PolicyKind::Pada`] | levels within Δ of the previous (Eq. 9) | the level | no |
//! | [`PolicyKind::EpsilonPada`] | greedy: any level; explore: within Δ | the level | no |
//! | [`PolicyKind::OrnsteinUhlenbeck`] | the greedy level moved by OU noise | the level | no |
//! | [`PolicyKind::PinkNoise`] | the greedy level moved by pink noise | the level | no |
//! | [`PolicyKind::ActionPenalty`] | any level (reward less the change penalty) | the level | no |
//!
//! Δ is relative to the size of each action range (`max − min`), as in
//! Section V: on the pendulum's {−1.5, 0, 1.5} Nm, Δ = 0.5 is a step of
//! 1.5 Nm, one level.
//!
//! At the start of an episode the motor is at rest: PADA's previous action
//! is the level nearest zero, and the filter and integrator outputs are zero
//! (clipped into the range). The paper's reference code lets PADA pick any
//! first action; starting from rest keeps Eq. 9 true across episode
//! boundaries, which is what the gearbox sees.
//!
//! Every policy that chooses motor levels on the plain state can be
//! switched back to plain SARSA (Section VIII) without changing the
//! learner's action set or state; PADA's Δ and the filters' α can be moved
//! while learning ([`Policy::set_parameter`], the wear governor
//! [`crate::governor`]).

mod candidates;
mod kind;

pub use candidates::{uniform_below, Candidates};
pub use kind::{
    kind_code, kind_from_code, kind_parameter, kind_second_parameter, Exploration, PolicyKind, PolicyName,
    POLICY_COUNT,
};

use crate::action_space::{ActionDim, ActionSpace, Levels, Output, MAX_ACTION_DIMS, MAX_LEVELS};
use crate::error::{ConfigError, StepError};
use crate::exploration::Noise;
use crate::tile_coding::StateDim;
use kind::family;
use rand_core::RngCore;

/// A policy's state as plain data ([`Policy::state`], [`Policy::restore`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PolicyState {
    /// The kind the policy was built as, with its parameters (PADA's Δ and
    /// the filters' α as last set, [`Policy::set_parameter`]).
    pub kind: PolicyKind,
    /// Whether it was switched back to plain SARSA.
    pub switched: bool,
    /// The learner's previous action, as levels of the learner's action
    /// space (0 in unused dimensions).
    pub previous: Levels,
    /// The last applied output, the low-pass filter's or integrator's memory
    /// (0 in unused dimensions).
    pub output: Output,
}

/// PADA's reach per dimension and level: the contiguous levels within Δ.
type Reach = [[(u8, u8); MAX_LEVELS]; MAX_ACTION_DIMS];

/// The reach of `delta` on `motor`: for each level, the contiguous levels
/// within Δ·range of it (all of them for `f32::INFINITY`).
fn reach_of(delta: f32, motor: &ActionSpace) -> Reach {
    let mut reach = [[(0u8, 0u8); MAX_LEVELS]; MAX_ACTION_DIMS];
    for i in 0..motor.dims() {
        let d = motor.dim(i);
        // A tolerance of 1e-4 of the range absorbs float rounding of
        // levels computed as min + k·step.
        let limit = delta * d.range() * (1.0 + 1e-4);
        for p in 0..d.len() {
            let vp = d.value(p as u8);
            let lo = (0..d.len()).find(|&l| (d.value(l as u8) - vp).abs() <= limit).unwrap_or(p);
            let hi = (0..d.len()).rev().find(|&l| (d.value(l as u8) - vp).abs() <= limit).unwrap_or(p);
            reach[i][p] = (lo as u8, hi as u8);
        }
    }
    reach
}

/// The noise process of `kind` (none for the policies without one).
fn noise_of(kind: &PolicyKind) -> Noise {
    match *kind {
        PolicyKind::OrnsteinUhlenbeck { theta, sigma } => Noise::ou(theta, sigma),
        PolicyKind::PinkNoise { sigma } => Noise::pink(sigma),
        _ => Noise::None,
    }
}

/// An action policy with its memory (previous action, filter state or
/// integrated command, noise).
#[derive(Debug, Clone)]
pub struct Policy {
    /// The kind in force (plain SARSA after a switch back).
    kind: PolicyKind,
    /// The kind the policy was built (or restored) as.
    built: PolicyKind,
    motor: ActionSpace,
    learner: ActionSpace,
    /// PADA's and ε-PADA's reach per dimension and level.
    reach: Reach,
    prev: Levels,
    output: Output,
    /// The noise process of `ou` and `pink`.
    noise: Noise,
    /// What the last applied action costs in the reward (the
    /// action-change penalty; 0 for the other kinds).
    penalty: f32,
}

impl Policy {
    /// A policy of `kind` driving motors with the levels of `motor`.
    pub fn new(kind: PolicyKind, motor: ActionSpace) -> Result<Policy, ConfigError> {
        kind.validate()?;
        let learner = match kind {
            PolicyKind::Integrator { delta } | PolicyKind::MarkovIntegrator { delta } => {
                let mut dims: heapless::Vec<ActionDim, MAX_ACTION_DIMS> = heapless::Vec::new();
                for i in 0..motor.dims() {
                    let step = delta * motor.dim(i).range();
                    let _ = dims.push(ActionDim::from_levels(&[-step, 0.0, step])?);
                }
                ActionSpace::new(&dims)?
            }
            _ => motor.clone(),
        };
        let reach = reach_of(kind.reach_delta().unwrap_or(f32::INFINITY), &motor);
        let mut policy = Policy {
            kind,
            built: kind,
            motor,
            learner,
            reach,
            prev: [0; MAX_ACTION_DIMS],
            output: [0.0; MAX_ACTION_DIMS],
            noise: noise_of(&kind),
            penalty: 0.0,
        };
        policy.reset();
        Ok(policy)
    }

    /// The kind in force, with its parameters ([`PolicyKind::Sarsa`] after
    /// [`switch_to_sarsa`](Self::switch_to_sarsa)).
    pub fn kind(&self) -> PolicyKind {
        self.kind
    }

    /// The kind the policy was built (or restored) as, with its parameters
    /// as last set; unchanged by a switch back to SARSA.
    pub fn built_kind(&self) -> PolicyKind {
        self.built
    }

    /// How the policy in force explores.
    pub fn exploration(&self) -> crate::policy::Exploration {
        PolicyName::of(&self.kind).exploration()
    }

    /// Whether the policy was switched back to plain SARSA (Section VIII).
    pub fn switched(&self) -> bool {
        self.kind != self.built
    }

    /// Moves the policy's first parameter while it learns: PADA's or
    /// ε-PADA's Δ (the reach is recomputed), a low-pass filter's α (its
    /// memory stays, so Eq. 8 runs on), OU's θ, pink noise's σ or the
    /// penalty's weight — never an integrator's Δ, which is the learner's
    /// action set. The new value gets the kind's own check
    /// ([`PolicyKind::validate`]); a refused value changes nothing. After a
    /// switch back to SARSA the built kind's parameter changes and SARSA
    /// stays in force.
    pub fn set_parameter(&mut self, value: f32) -> Result<(), ConfigError> {
        let name = PolicyName::of(&self.built);
        if name == PolicyName::Sarsa || self.built.is_integrator() {
            return Err(ConfigError::new(
                "policy parameter",
                value,
                "a policy whose parameter leaves the learner's actions alone (not sarsa or an integrator)",
            ));
        }
        let mut parameters = self.built.parameters();
        parameters[0] = value;
        let kind = name.with_parameters(parameters);
        kind.validate()?;
        if let Some(delta) = kind.reach_delta() {
            self.reach = reach_of(delta, &self.motor);
        }
        match (&mut self.noise, kind) {
            (Noise::Ou { theta, .. }, PolicyKind::OrnsteinUhlenbeck { theta: t, .. }) => *theta = t,
            (Noise::Pink { sigma, .. }, PolicyKind::PinkNoise { sigma: s }) => *sigma = s,
            _ => {}
        }
        if !self.switched() {
            self.kind = kind;
        }
        self.built = kind;
        Ok(())
    }

    /// The policy's state as plain data (for a checkpoint).
    pub fn state(&self) -> PolicyState {
        PolicyState { kind: self.built, switched: self.switched(), previous: self.prev, output: self.output }
    }

    /// Checks that `state` can be restored into this policy; the error names
    /// the field and its valid range. See [`restore`](Self::restore).
    pub fn check_state(&self, state: &PolicyState) -> Result<(), ConfigError> {
        self.restored(state).map(|_| ())
    }

    /// Restores a policy state: the kind with its parameters, the switch
    /// back to SARSA, the previous action and the filter's or integrator's
    /// memory. The kind may differ from the one built when its learner means
    /// the same by an action and a state: every kind that chooses motor
    /// levels on the plain state (SARSA, PADA, the low-pass filter, ε-PADA,
    /// the noise explorations, the penalty) stands in for the others, as do
    /// Markov low-pass filters of any α, and integrators of a Δ that gives
    /// the same increments; otherwise, or with any field out of range,
    /// nothing changes.
    pub fn restore(&mut self, state: &PolicyState) -> Result<(), ConfigError> {
        *self = self.restored(state)?;
        Ok(())
    }

    /// This policy with `state` restored, or why it cannot be.
    fn restored(&self, state: &PolicyState) -> Result<Policy, ConfigError> {
        let mut p = if state.kind == self.built {
            let mut p = self.clone();
            p.kind = p.built;
            p
        } else {
            let p = Policy::new(state.kind, self.motor.clone())?;
            if family(&state.kind) != family(&self.built)
                || p.learner != self.learner
                || p.extension_len() != self.extension_len()
            {
                return Err(ConfigError::new(
                    "policy.kind",
                    kind_code(&state.kind) as f32,
                    "a policy with the running learner's actions and state (sarsa, pada, lowpass and the gentle explorations alike; the integrators and Markov variants only as configured)",
                ));
            }
            p
        };
        if state.switched {
            let name = PolicyName::of(&state.kind);
            if name == PolicyName::Sarsa || !name.can_switch() {
                return Err(ConfigError::new(
                    "policy.switched",
                    1.0,
                    "false unless the policy can switch back to sarsa (not sarsa itself, the integrators or markov-lowpass)",
                ));
            }
            p.kind = PolicyKind::Sarsa;
        }
        for i in 0..MAX_ACTION_DIMS {
            let level = state.previous[i];
            if i < p.learner.dims() {
                if level as usize >= p.learner.dim(i).len() {
                    return Err(ConfigError::new(
                        "policy.previous",
                        level as f32,
                        "a level index below the dimension's number of levels",
                    )
                    .at(i));
                }
            } else if level != 0 {
                return Err(ConfigError::new("policy.previous", level as f32, "0 for an unused action dimension").at(i));
            }
            let out = state.output[i];
            if i < p.motor.dims() {
                let d = p.motor.dim(i);
                if !(out.is_finite() && out >= d.min() && out <= d.max()) {
                    return Err(ConfigError::new(
                        "policy.output",
                        out,
                        "finite and inside the motor's range [min, max]",
                    )
                    .at(i));
                }
            } else if out.to_bits() != 0 {
                return Err(ConfigError::new("policy.output", out, "0 for an unused action dimension").at(i));
            }
        }
        p.prev = state.previous;
        p.output = state.output;
        Ok(p)
    }

    /// The actions the learner chooses among (the motor's levels, or the
    /// integrator's increments).
    pub fn learner_space(&self) -> &ActionSpace {
        &self.learner
    }

    /// The motor's action space.
    pub fn motor_space(&self) -> &ActionSpace {
        &self.motor
    }

    /// Back to the state of an episode start: the motor at rest, the noise
    /// at its start, no penalty pending.
    pub fn reset(&mut self) {
        self.prev = if self.kind.is_integrator() {
            // The middle increment, 0.
            let mut l = [0u8; MAX_ACTION_DIMS];
            l[..self.learner.dims()].fill(1);
            l
        } else {
            self.motor.rest_levels()
        };
        for i in 0..self.motor.dims() {
            let d = self.motor.dim(i);
            self.output[i] = 0.0f32.clamp(d.min(), d.max());
        }
        self.noise.reset();
        self.penalty = 0.0;
    }

    /// The learner's previous action (levels of the learner's space).
    pub fn previous(&self) -> Levels {
        self.prev
    }

    /// The last applied output (the filter's or integrator's memory).
    pub fn output(&self) -> Output {
        self.output
    }

    /// The neighbourhood of the previous action within the reach, or every
    /// action.
    fn neighbourhood(&self, local: bool) -> Candidates {
        let dims = self.learner.dims();
        let mut c = Candidates { lo: [0; MAX_ACTION_DIMS], hi: [0; MAX_ACTION_DIMS], dims: dims as u8 };
        for i in 0..dims {
            if local {
                let (lo, hi) = self.reach[i][self.prev[i] as usize];
                c.lo[i] = lo;
                c.hi[i] = hi;
            } else {
                c.hi[i] = self.learner.dim(i).len() as u8 - 1;
            }
        }
        c
    }

    /// The candidates of the greedy choice: PADA's neighbourhood of the
    /// previous action (Eq. 9), otherwise every action.
    pub fn candidates(&self) -> Candidates {
        self.neighbourhood(matches!(self.kind, PolicyKind::Pada { .. }))
    }

    /// The candidates of an exploratory draw: PADA's and ε-PADA's
    /// neighbourhood of the previous action, otherwise every action.
    pub fn explore_candidates(&self) -> Candidates {
        self.neighbourhood(self.kind.reach_delta().is_some())
    }

    /// The greedy action's levels moved by the noise process (`ou`,
    /// `pink`): each dimension's value plus the noise times the largest
    /// distance from 0 to a bound of its range (GRL's scaling), rounded to
    /// the nearest level (which clips at the ends). Advances the noise; the
    /// levels are returned unchanged by a policy without noise.
    pub fn perturb<R: RngCore + ?Sized>(&mut self, greedy: &Levels, rng: &mut R) -> Levels {
        if matches!(self.noise, Noise::None) || self.exploration() != Exploration::Noise {
            return *greedy;
        }
        let dims = self.learner.dims();
        let noise = self.noise.sample(dims, rng);
        let mut levels = *greedy;
        for i in 0..dims {
            let d = self.learner.dim(i);
            let scale = d.min().abs().max(d.max().abs());
            levels[i] = d.nearest(d.value(greedy[i]) + noise[i] * scale);
        }
        levels
    }

    /// What the last applied action costs the learner's reward: the
    /// action-change penalty `w·Σᵢ((aᵢ − a⁻ᵢ)/rangeᵢ)²` (a⁻ the output
    /// before it, at rest at an episode's start), 0 for every other kind.
    pub fn penalty(&self) -> f32 {
        self.penalty
    }

    /// Applies the learner's choice and returns the motor output.
    pub fn apply(&mut self, levels: &Levels) -> Output {
        self.prev = *levels;
        let mut change = 0.0f32;
        for i in 0..self.motor.dims() {
            let chosen = self.learner.dim(i).value(levels[i]);
            let before = self.output[i];
            self.output[i] = match self.kind {
                // Eq. 8.
                PolicyKind::LowPass { alpha } | PolicyKind::MarkovLowPass { alpha } => {
                    alpha * chosen + (1.0 - alpha) * before
                }
                PolicyKind::Integrator { .. } | PolicyKind::MarkovIntegrator { .. } => {
                    let d = self.motor.dim(i);
                    (before + chosen).clamp(d.min(), d.max())
                }
                _ => chosen,
            };
            let step = (self.output[i] - before) / self.motor.dim(i).range();
            change += step * step;
        }
        self.penalty = match self.kind {
            PolicyKind::ActionPenalty { weight } => weight * change,
            _ => 0.0,
        };
        self.output
    }

    /// Moves the memory between action dimensions when the joints they
    /// drive swap roles (LEO's footstep: stance and swing trade legs):
    /// dimension `i` takes dimension `map[i]`'s previous action and filter
    /// or integrator output, or, for `None`, starts at rest (the level and
    /// output of 0, as at an episode's start). Unused dimensions are left
    /// alone; an index out of range counts as `None`. (The noise of `ou`
    /// and `pink` belongs to the action dimension, not the joint, and stays.)
    pub fn remap(&mut self, map: &[Option<u8>; MAX_ACTION_DIMS]) {
        let (prev, output) = (self.prev, self.output);
        let mut rest = self.clone();
        rest.reset();
        for i in 0..self.learner.dims() {
            match map[i].map(|j| j as usize).filter(|&j| j < self.learner.dims()) {
                Some(j) => {
                    self.prev[i] = prev[j];
                    self.output[i] = output[j];
                }
                None => {
                    self.prev[i] = rest.prev[i];
                    self.output[i] = rest.output[i];
                }
            }
        }
    }

    /// Number of state dimensions the policy appends (0, or one per motor
    /// for the Markov variants).
    pub fn extension_len(&self) -> usize {
        if self.kind.is_markov() {
            self.motor.dims()
        } else {
            0
        }
    }

    /// The appended dimensions: each motor's range, one tile per level step.
    pub fn extension_dim(&self, i: usize) -> Result<StateDim, ConfigError> {
        let d = self.motor.dim(i);
        StateDim::new(d.min(), d.max(), d.range() / (d.len().max(2) - 1) as f32)
    }

    /// The values appended to the state: the previous applied output.
    pub fn extension(&self) -> &[f32] {
        &self.output[..self.extension_len()]
    }

    /// Switches a policy that chooses motor levels on the plain state back
    /// to plain SARSA (Section VIII: PADA, the low-pass filter, the gentle
    /// explorations); the learner's actions and state stay the same, so the
    /// learned values carry over. Plain SARSA switches to itself.
    pub fn switch_to_sarsa(&mut self) -> Result<(), StepError> {
        if PolicyName::of(&self.built).can_switch() {
            self.kind = PolicyKind::Sarsa;
            self.penalty = 0.0;
            Ok(())
        } else {
            Err(StepError::CannotSwitch)
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use proptest::prelude::*;
    use rand_pcg::Pcg32;
    use rand_core::SeedableRng;

    fn leo_motor() -> ActionSpace {
        ActionSpace::repeated(ActionDim::uniform(-10.7, 10.7, 7).unwrap(), 3).unwrap()
    }

    fn pendulum_motor() -> ActionSpace {
        ActionSpace::new(&[ActionDim::from_levels(&[-1.5, 0.0, 1.5]).unwrap()]).unwrap()
    }

    #[test]
    fn pada_on_leo_evaluates_27_of_343() {
        let mut p = Policy::new(PolicyKind::Pada { delta: 1.0 / 6.0 }, leo_motor()).unwrap();
        p.apply(&[3, 3, 3, 0]);
        assert_eq!(p.candidates().count(), 27);
        p.apply(&[0, 6, 3, 0]);
        assert_eq!(p.candidates().count(), 2 * 2 * 3);
        let s = Policy::new(PolicyKind::Sarsa, leo_motor()).unwrap();
        assert_eq!(s.candidates().count(), 343);
    }

    #[test]
    fn pada_delta_half_on_pendulum_is_one_level() {
        let mut p = Policy::new(PolicyKind::Pada { delta: 0.5 }, pendulum_motor()).unwrap();
        // Episode start: at rest (0 Nm), every torque is within 1.5 Nm.
        assert_eq!(p.candidates().count(), 3);
        p.apply(&[0, 0, 0, 0]);
        let c = p.candidates();
        assert_eq!((c.lo[0], c.hi[0]), (0, 1));
        let p0 = Policy::new(PolicyKind::Pada { delta: 0.0 }, pendulum_motor()).unwrap();
        assert_eq!(p0.candidates().count(), 1);
    }

    #[test]
    fn integrator_integrates_and_clips() {
        let mut p = Policy::new(PolicyKind::Integrator { delta: 0.25 }, pendulum_motor()).unwrap();
        assert_eq!(p.learner_space().dim(0).values(), &[-0.75, 0.0, 0.75]);
        assert_eq!(p.apply(&[2, 0, 0, 0])[0], 0.75);
        assert_eq!(p.apply(&[2, 0, 0, 0])[0], 1.5);
        assert_eq!(p.apply(&[2, 0, 0, 0])[0], 1.5);
        assert_eq!(p.apply(&[1, 0, 0, 0])[0], 1.5);
        assert_eq!(p.apply(&[0, 0, 0, 0])[0], 0.75);
        assert_eq!(p.extension_len(), 0);
        let m = Policy::new(PolicyKind::MarkovIntegrator { delta: 0.25 }, pendulum_motor()).unwrap();
        assert_eq!(m.extension_len(), 1);
    }

    #[test]
    fn markov_lowpass_extends_state_with_previous_output() {
        let mut p = Policy::new(PolicyKind::MarkovLowPass { alpha: 0.5 }, pendulum_motor()).unwrap();
        assert_eq!(p.extension(), &[0.0]);
        p.apply(&[2, 0, 0, 0]);
        assert_eq!(p.extension(), &[0.75]);
        assert_eq!(p.extension_dim(0).unwrap().tile_width, 1.5);
    }

    #[test]
    fn switching_back_to_sarsa() {
        let mut p = Policy::new(PolicyKind::Pada { delta: 0.2 }, leo_motor()).unwrap();
        p.switch_to_sarsa().unwrap();
        assert_eq!(p.candidates().count(), 343);
        let mut l = Policy::new(PolicyKind::LowPass { alpha: 0.3 }, leo_motor()).unwrap();
        l.switch_to_sarsa().unwrap();
        assert_eq!(l.apply(&[6, 0, 3, 0])[..3], [10.7, -10.7, 0.0]);
        for k in [PolicyKind::Integrator { delta: 0.1 }, PolicyKind::MarkovLowPass { alpha: 0.5 }] {
            let mut p = Policy::new(k, leo_motor()).unwrap();
            assert_eq!(p.switch_to_sarsa(), Err(StepError::CannotSwitch));
        }
    }

    #[test]
    fn epsilon_pada_restricts_only_exploration() {
        let mut p = Policy::new(PolicyKind::EpsilonPada { delta: 1.0 / 6.0 }, leo_motor()).unwrap();
        p.apply(&[3, 0, 6, 0]);
        assert_eq!(p.candidates().count(), 343, "the greedy choice is free");
        let e = p.explore_candidates();
        assert_eq!(e.count(), 3 * 2 * 2);
        assert_eq!((e.lo, e.hi), ([2, 0, 5, 0], [4, 1, 6, 0]));
        // PADA restricts both.
        let mut q = Policy::new(PolicyKind::Pada { delta: 1.0 / 6.0 }, leo_motor()).unwrap();
        q.apply(&[3, 0, 6, 0]);
        assert_eq!(q.candidates(), q.explore_candidates());
    }

    #[test]
    fn noise_moves_the_greedy_level_and_clips_at_the_ends() {
        let mut rng = Pcg32::seed_from_u64(4);
        let mut p = Policy::new(PolicyKind::OrnsteinUhlenbeck { theta: 0.15, sigma: 0.3 }, leo_motor()).unwrap();
        let (mut moved, mut steps) = (0, 0);
        let mut previous = [3u8, 3, 3, 0];
        let mut flips = 0;
        for _ in 0..5000 {
            let l = p.perturb(&[3, 0, 6, 0], &mut rng);
            assert!(l[..3].iter().all(|&x| x < 7) && l[3] == 0);
            moved += (l != [3, 0, 6, 0]) as u32;
            // Correlated noise: consecutive choices of a dimension rarely
            // jump from one side of the greedy level to the other.
            flips += ((l[0] as i32 - 3).signum() * (previous[0] as i32 - 3).signum() < 0) as u32;
            previous = l;
            steps += 1;
        }
        assert!(moved > steps / 2, "{moved} of {steps} moved");
        assert!(flips < steps / 20, "{flips} sign flips");
        // A policy without noise returns the greedy levels as they are.
        let mut s = Policy::new(PolicyKind::Sarsa, leo_motor()).unwrap();
        assert_eq!(s.perturb(&[1, 2, 3, 0], &mut rng), [1, 2, 3, 0]);
    }

    #[test]
    fn the_action_change_penalty_is_its_weight_times_the_squared_relative_change() {
        let mut p = Policy::new(PolicyKind::ActionPenalty { weight: 2.0 }, pendulum_motor()).unwrap();
        p.apply(&[2, 0, 0, 0]); // 0 → +1.5 N·m: half the range.
        assert_eq!(p.penalty(), 2.0 * 0.25);
        p.apply(&[0, 0, 0, 0]); // +1.5 → −1.5: the full range.
        assert_eq!(p.penalty(), 2.0);
        p.apply(&[0, 0, 0, 0]);
        assert_eq!(p.penalty(), 0.0);
        p.reset();
        assert_eq!(p.penalty(), 0.0);
        let mut s = Policy::new(PolicyKind::Sarsa, pendulum_motor()).unwrap();
        s.apply(&[2, 0, 0, 0]);
        assert_eq!(s.penalty(), 0.0, "only the penalty policy has one");
    }

    #[test]
    fn set_parameter_moves_delta_and_alpha_and_refuses_the_rest() {
        let mut p = Policy::new(PolicyKind::Pada { delta: 1.0 / 6.0 }, leo_motor()).unwrap();
        p.apply(&[3, 3, 3, 0]);
        assert_eq!(p.candidates().count(), 27);
        p.set_parameter(2.0 / 6.0).unwrap();
        assert_eq!(p.candidates().count(), 125);
        assert_eq!(p.built_kind(), PolicyKind::Pada { delta: 2.0 / 6.0 });
        assert_eq!(p.state().kind, PolicyKind::Pada { delta: 2.0 / 6.0 }, "a checkpoint keeps the Δ in force");
        assert_eq!(p.set_parameter(-1.0).unwrap_err().param, "delta");
        assert_eq!(p.candidates().count(), 125, "a refused value changes nothing");
        let mut l = Policy::new(PolicyKind::LowPass { alpha: 0.9 }, pendulum_motor()).unwrap();
        l.apply(&[2, 0, 0, 0]);
        l.set_parameter(0.5).unwrap();
        let before = l.output()[0];
        assert_eq!(l.apply(&[2, 0, 0, 0])[0], 0.5 * 1.5 + 0.5 * before, "Eq. 8 runs on with the new α");
        for k in [PolicyKind::Sarsa, PolicyKind::Integrator { delta: 0.5 }] {
            assert_eq!(Policy::new(k, pendulum_motor()).unwrap().set_parameter(0.5).unwrap_err().param, "policy parameter");
        }
    }

    #[test]
    fn the_gentle_explorations_switch_back_to_sarsa() {
        for k in [
            PolicyKind::EpsilonPada { delta: 0.2 },
            PolicyKind::OrnsteinUhlenbeck { theta: 0.2, sigma: 0.2 },
            PolicyKind::PinkNoise { sigma: 0.3 },
            PolicyKind::ActionPenalty { weight: 1.0 },
        ] {
            let mut p = Policy::new(k, leo_motor()).unwrap();
            p.switch_to_sarsa().unwrap();
            assert_eq!(p.kind(), PolicyKind::Sarsa, "{k:?}");
            assert_eq!(p.exploration(), Exploration::EpsilonGreedy);
            p.apply(&[6, 0, 3, 0]);
            assert_eq!(p.penalty(), 0.0);
            // Their checkpoints restore into a SARSA learner and back.
            let mut s = Policy::new(PolicyKind::Sarsa, leo_motor()).unwrap();
            s.restore(&p.state()).unwrap();
            assert_eq!((s.built_kind(), s.switched()), (k, true));
        }
    }

    #[test]
    fn parameters_are_validated() {
        let m = pendulum_motor;
        assert_eq!(Policy::new(PolicyKind::Pada { delta: -0.1 }, m()).unwrap_err().param, "delta");
        assert_eq!(Policy::new(PolicyKind::Integrator { delta: 0.0 }, m()).unwrap_err().param, "delta");
        assert_eq!(Policy::new(PolicyKind::LowPass { alpha: 0.0 }, m()).unwrap_err().param, "lowpass alpha");
        assert_eq!(Policy::new(PolicyKind::MarkovLowPass { alpha: 1.5 }, m()).unwrap_err().param, "lowpass alpha");
        assert_eq!(Policy::new(PolicyKind::LowPass { alpha: f32::NAN }, m()).unwrap_err().param, "lowpass alpha");
        assert_eq!(Policy::new(PolicyKind::EpsilonPada { delta: f32::NAN }, m()).unwrap_err().param, "delta");
        for (theta, sigma, param) in [(0.0, 0.2, "theta"), (1.5, 0.2, "theta"), (0.2, 0.0, "sigma"), (0.2, 4.5, "sigma")] {
            let k = PolicyKind::OrnsteinUhlenbeck { theta, sigma };
            assert_eq!(Policy::new(k, m()).unwrap_err().param, param, "{k:?}");
        }
        assert_eq!(Policy::new(PolicyKind::PinkNoise { sigma: f32::INFINITY }, m()).unwrap_err().param, "sigma");
        assert_eq!(Policy::new(PolicyKind::ActionPenalty { weight: -1.0 }, m()).unwrap_err().param, "weight");
        assert_eq!(Policy::new(PolicyKind::ActionPenalty { weight: 1e5 }, m()).unwrap_err().param, "weight");
    }

    #[test]
    fn for_each_visits_exactly_the_candidates() {
        let c = Candidates { lo: [1, 0, 2, 0], hi: [2, 1, 4, 0], dims: 3 };
        let mut n = 0;
        let mut seen = std::collections::BTreeSet::new();
        c.for_each(|l| {
            assert!(c.contains(l));
            seen.insert(*l);
            n += 1;
        });
        assert_eq!(n, c.count());
        assert_eq!(seen.len() as u32, c.count());
    }

    proptest! {
        /// Eq. 8: the low-pass output is α·a_k + (1 − α)·a_filtered,k−1.
        #[test]
        fn lowpass_output_is_eq8(alpha in 0.01f32..=1.0, choices in prop::collection::vec(0u8..3, 1..50)) {
            let mut p = Policy::new(PolicyKind::LowPass { alpha }, pendulum_motor()).unwrap();
            let mut expected = 0.0f32;
            for &c in &choices {
                let a = [-1.5f32, 0.0, 1.5][c as usize];
                expected = alpha * a + (1.0 - alpha) * expected;
                let out = p.apply(&[c, 0, 0, 0])[0];
                prop_assert_eq!(out, expected);
            }
        }

        /// Eq. 9: PADA never proposes an action more than Δ·range from the
        /// previous one, in any dimension, random or enumerated.
        #[test]
        fn pada_stays_within_delta(delta in 0.0f32..1.2, seed in any::<u64>(), steps in 1usize..200) {
            let mut p = Policy::new(PolicyKind::Pada { delta }, leo_motor()).unwrap();
            let mut rng = Pcg32::seed_from_u64(seed);
            let limit = delta * 21.4 * (1.0 + 1e-4);
            for _ in 0..steps {
                let prev = p.output();
                let c = p.candidates();
                let mut ok = true;
                c.for_each(|l| {
                    let v = p.motor_space().values(l);
                    ok &= (0..3).all(|i| (v[i] - prev[i]).abs() <= limit);
                });
                prop_assert!(ok);
                let pick = c.random(&mut rng);
                prop_assert!(c.contains(&pick));
                let out = p.apply(&pick);
                for i in 0..3 {
                    prop_assert!((out[i] - prev[i]).abs() <= limit);
                }
            }
        }
    }

    #[test]
    fn remap_moves_memory_between_dimensions_and_rests_the_rest() {
        let level = ActionDim::uniform(-10.7, 10.7, 7).unwrap();
        let motor = ActionSpace::repeated(level, 3).unwrap();
        for kind in [PolicyKind::Pada { delta: 1.0 / 6.0 }, PolicyKind::LowPass { alpha: 0.5 }] {
            let mut p = Policy::new(kind, motor.clone()).unwrap();
            p.reset();
            let out = p.apply(&[6, 0, 5, 0]);
            p.remap(&[Some(1), Some(0), None, None]);
            assert_eq!(&p.previous()[..3], &[0, 6, 3], "{kind:?}: hips swap, the knee rests at 0 V");
            assert_eq!(p.output()[0], out[1]);
            assert_eq!(p.output()[1], out[0]);
            assert_eq!(p.output()[2], 0.0);
            // PADA's next candidates follow the moved memory.
            if let PolicyKind::Pada { .. } = kind {
                let c = p.candidates();
                assert_eq!((c.lo[0], c.hi[0]), (0, 1));
                assert_eq!((c.lo[1], c.hi[1]), (5, 6));
                assert_eq!((c.lo[2], c.hi[2]), (2, 4));
            }
        }
    }
}
