//! The six action policies of Section V as one concept.
//!
//! A [`Policy`] sits between the learner and the motor. It decides
//! 1. which actions the learner may choose from ([`Policy::candidates`]):
//!    all of them, or for PADA only those within Δ of the previous one
//!    (Eq. 9);
//! 2. what the learner's action means for the motor ([`Policy::apply`]):
//!    the level itself, a low-pass filtered level (Eq. 8) or an increment of
//!    an integrated command;
//! 3. whether the state is extended by the policy's memory
//!    ([`Policy::extension`]): the Markov variants append the previous
//!    filtered or integrated output so the learner's state stays Markov.
//!
//! | kind | learner chooses | applied output | state extended |
//! |---|---|---|---|
//! | [`PolicyKind::Sarsa`] | any level | the level | no |
//! | [`PolicyKind::LowPass`] | any level | `α·a + (1 − α)·prev` (Eq. 8) | no |
//! | [`PolicyKind::MarkovLowPass`] | any level | as low-pass | by `prev` |
//! | [`PolicyKind::Integrator`] | −Δ, 0, +Δ | `clip(prev + inc)` | no |
//! | [`PolicyKind::MarkovIntegrator`] | −Δ, 0, +Δ | as integrator | by `prev` |
//! | [`PolicyKind::Pada`] | levels within Δ of the previous (Eq. 9) | the level | no |
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
//! PADA and the low-pass filter can be switched back to plain SARSA
//! (Section VIII) without changing the learner's action set or state.

use crate::action_space::{ActionDim, ActionSpace, Levels, Output, MAX_ACTION_DIMS, MAX_LEVELS};
use crate::error::{check_range, ConfigError, StepError};
use crate::tile_coding::StateDim;
use rand_core::RngCore;

/// The six policies of Section V by name, without their parameter: the one
/// list that the policy kind ([`PolicyKind`]), the checkpoint's policy code
/// ([`PolicyName::code`]), the wire's `SetPolicy` (which carries a
/// [`PolicyKind`]) and the host's `--algo` names all derive from.
///
/// The discriminant is the checkpoint code and the variant index on the
/// wire, so the order is a stored format: append, never reorder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum PolicyName {
    /// SARSA(λ): the chosen level is applied.
    #[serde(rename = "sarsa")]
    Sarsa = 0,
    /// Low-pass filtered actions (Eq. 8).
    #[serde(rename = "lowpass")]
    LowPass = 1,
    /// Low-pass filter with the previous output in the state.
    #[serde(rename = "markov-lowpass")]
    MarkovLowPass = 2,
    /// Integrating controller: the learner chooses −Δ, 0 or +Δ.
    #[serde(rename = "integrator")]
    Integrator = 3,
    /// Integrating controller with the integrated command in the state.
    #[serde(rename = "markov-integrator")]
    MarkovIntegrator = 4,
    /// Previous-action-dependent actions (Eq. 9).
    #[serde(rename = "pada")]
    Pada = 5,
}

impl PolicyName {
    /// Every policy, in the paper's order (which is the code order).
    pub const ALL: [PolicyName; 6] = [
        PolicyName::Sarsa,
        PolicyName::LowPass,
        PolicyName::MarkovLowPass,
        PolicyName::Integrator,
        PolicyName::MarkovIntegrator,
        PolicyName::Pada,
    ];

    /// The name of `kind`.
    pub const fn of(kind: &PolicyKind) -> PolicyName {
        match kind {
            PolicyKind::Sarsa => PolicyName::Sarsa,
            PolicyKind::LowPass { .. } => PolicyName::LowPass,
            PolicyKind::MarkovLowPass { .. } => PolicyName::MarkovLowPass,
            PolicyKind::Integrator { .. } => PolicyName::Integrator,
            PolicyKind::MarkovIntegrator { .. } => PolicyName::MarkovIntegrator,
            PolicyKind::Pada { .. } => PolicyName::Pada,
        }
    }

    /// The kind of this name with `parameter` as its α or Δ (ignored for
    /// SARSA); the parameter is not checked here ([`PolicyKind::validate`]).
    pub const fn with_parameter(self, parameter: f32) -> PolicyKind {
        match self {
            PolicyName::Sarsa => PolicyKind::Sarsa,
            PolicyName::LowPass => PolicyKind::LowPass { alpha: parameter },
            PolicyName::MarkovLowPass => PolicyKind::MarkovLowPass { alpha: parameter },
            PolicyName::Integrator => PolicyKind::Integrator { delta: parameter },
            PolicyName::MarkovIntegrator => PolicyKind::MarkovIntegrator { delta: parameter },
            PolicyName::Pada => PolicyKind::Pada { delta: parameter },
        }
    }

    /// The number that stands for the policy in a checkpoint (0 sarsa, 1
    /// lowpass, 2 markov-lowpass, 3 integrator, 4 markov-integrator, 5 pada).
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The policy of a [`code`](Self::code); `None` for an unknown code.
    pub fn from_code(code: u8) -> Option<PolicyName> {
        PolicyName::ALL.get(code as usize).copied()
    }

    /// The name as the command line spells it.
    pub const fn name(self) -> &'static str {
        match self {
            PolicyName::Sarsa => "sarsa",
            PolicyName::LowPass => "lowpass",
            PolicyName::MarkovLowPass => "markov-lowpass",
            PolicyName::Integrator => "integrator",
            PolicyName::MarkovIntegrator => "markov-integrator",
            PolicyName::Pada => "pada",
        }
    }

    /// The policy of a command-line name.
    pub fn from_name(name: &str) -> Option<PolicyName> {
        PolicyName::ALL.into_iter().find(|n| n.name() == name)
    }

    /// The name used in the paper's figures.
    pub const fn title(self) -> &'static str {
        match self {
            PolicyName::Sarsa => "SARSA(λ)",
            PolicyName::LowPass => "low-pass filter",
            PolicyName::MarkovLowPass => "Markov low-pass filter",
            PolicyName::Integrator => "integrating controller",
            PolicyName::MarkovIntegrator => "Markov integrating controller",
            PolicyName::Pada => "PADA",
        }
    }

    /// Whether the policy takes α (the low-pass filters, Eq. 8).
    pub const fn takes_alpha(self) -> bool {
        matches!(self, PolicyName::LowPass | PolicyName::MarkovLowPass)
    }

    /// Whether the policy takes Δ (the integrators and PADA).
    pub const fn takes_delta(self) -> bool {
        matches!(self, PolicyName::Integrator | PolicyName::MarkovIntegrator | PolicyName::Pada)
    }

    /// Whether a learner of this policy can run as (or switch back to)
    /// plain SARSA(λ) without changing its actions or state (Section VIII):
    /// SARSA itself, PADA and the low-pass filter.
    pub const fn can_switch(self) -> bool {
        matches!(self, PolicyName::Sarsa | PolicyName::LowPass | PolicyName::Pada)
    }
}

impl core::fmt::Display for PolicyName {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which of the six policies of Section V, with its parameter. Its variants
/// are [`PolicyName`]'s in the same order, so its postcard encoding (the
/// variant index, then the `f32` parameter if any) is what the wire's
/// `SetPolicy` carries.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PolicyKind {
    /// Plain SARSA(λ): the chosen level is applied.
    Sarsa,
    /// First-order low-pass filter on the applied output (Eq. 8), `0 < alpha ≤ 1`.
    LowPass {
        /// Filter coefficient α of Eq. 8 (1 = no filtering).
        alpha: f32,
    },
    /// Low-pass filter with the previous filtered output in the state.
    MarkovLowPass {
        /// Filter coefficient α of Eq. 8.
        alpha: f32,
    },
    /// The learner chooses −Δ, 0 or +Δ on an integrated command.
    Integrator {
        /// Increment relative to the action range, `0 < delta ≤ 1`.
        delta: f32,
    },
    /// Integrating controller with the integrated command in the state.
    MarkovIntegrator {
        /// Increment relative to the action range, `0 < delta ≤ 1`.
        delta: f32,
    },
    /// Previous-action-dependent actions (Eq. 9): the next level is within Δ
    /// of the previous one, for greedy choice and exploration alike.
    Pada {
        /// Reach relative to the action range, `delta ≥ 0` (≥ 1 allows all).
        delta: f32,
    },
}

// The variant order of the two enums is one format (checkpoint code, wire
// variant index): keep them in step.
const _: () = {
    let kinds = [
        PolicyKind::Sarsa,
        PolicyKind::LowPass { alpha: 0.0 },
        PolicyKind::MarkovLowPass { alpha: 0.0 },
        PolicyKind::Integrator { delta: 0.0 },
        PolicyKind::MarkovIntegrator { delta: 0.0 },
        PolicyKind::Pada { delta: 0.0 },
    ];
    let mut i = 0;
    while i < kinds.len() {
        assert!(PolicyName::of(&kinds[i]) as usize == i);
        i += 1;
    }
};

impl PolicyKind {
    /// The policy's name as the command line spells it.
    pub fn name(&self) -> &'static str {
        PolicyName::of(self).name()
    }

    /// Its parameter (α of the low-pass filters, Δ of the others); `None`
    /// for SARSA.
    pub fn parameter(&self) -> Option<f32> {
        match *self {
            PolicyKind::Sarsa => None,
            PolicyKind::LowPass { alpha } | PolicyKind::MarkovLowPass { alpha } => Some(alpha),
            PolicyKind::Integrator { delta } | PolicyKind::MarkovIntegrator { delta } | PolicyKind::Pada { delta } => {
                Some(delta)
            }
        }
    }

    /// Checks the parameter's range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        match *self {
            PolicyKind::Sarsa => Ok(()),
            PolicyKind::LowPass { alpha } | PolicyKind::MarkovLowPass { alpha } => {
                if alpha.is_finite() && alpha > 0.0 && alpha <= 1.0 {
                    Ok(())
                } else {
                    Err(ConfigError::new("lowpass alpha", alpha, "0 < alpha <= 1"))
                }
            }
            PolicyKind::Integrator { delta } | PolicyKind::MarkovIntegrator { delta } => {
                if delta.is_finite() && delta > 0.0 && delta <= 1.0 {
                    Ok(())
                } else {
                    Err(ConfigError::new("delta", delta, "0 < delta <= 1 (relative to the action range)"))
                }
            }
            PolicyKind::Pada { delta } => {
                check_range("delta", delta, 0.0, f32::MAX, "delta >= 0 (relative to the action range)")
            }
        }
    }

    fn is_integrator(&self) -> bool {
        matches!(self, PolicyKind::Integrator { .. } | PolicyKind::MarkovIntegrator { .. })
    }

    fn is_markov(&self) -> bool {
        matches!(self, PolicyKind::MarkovLowPass { .. } | PolicyKind::MarkovIntegrator { .. })
    }
}

/// The set of level combinations the learner may choose from: per dimension
/// a contiguous range of levels `lo..=hi` (all levels, or PADA's
/// neighbourhood, Eq. 9). The joint candidates are the product of the
/// ranges.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Candidates {
    /// Lowest allowed level per dimension.
    pub lo: Levels,
    /// Highest allowed level per dimension.
    pub hi: Levels,
    /// Number of dimensions in use.
    pub dims: u8,
}

impl Candidates {
    /// Number of joint candidates.
    pub fn count(&self) -> u32 {
        (0..self.dims as usize).map(|i| (self.hi[i] - self.lo[i]) as u32 + 1).product()
    }

    /// Whether `levels` is a candidate.
    pub fn contains(&self, levels: &Levels) -> bool {
        (0..self.dims as usize).all(|i| levels[i] >= self.lo[i] && levels[i] <= self.hi[i])
    }

    /// A uniformly random candidate: the product set is uniform when each
    /// dimension is drawn uniformly and independently.
    pub fn random<R: RngCore + ?Sized>(&self, rng: &mut R) -> Levels {
        let mut levels = [0u8; MAX_ACTION_DIMS];
        for i in 0..self.dims as usize {
            let n = (self.hi[i] - self.lo[i]) as u32 + 1;
            levels[i] = self.lo[i] + uniform_below(rng, n) as u8;
        }
        levels
    }

    /// Visits every candidate once, first dimension fastest.
    pub fn for_each(&self, mut visit: impl FnMut(&Levels)) {
        let d = self.dims as usize;
        let mut l = self.lo;
        loop {
            visit(&l);
            // Odometer increment.
            let mut i = 0;
            loop {
                if i == d {
                    return;
                }
                if l[i] < self.hi[i] {
                    l[i] += 1;
                    break;
                }
                l[i] = self.lo[i];
                i += 1;
            }
        }
    }
}

/// A uniform integer in `0..n` (`n ≥ 1`) by Lemire's multiply-shift: one
/// `u32` per draw, no division, bias below 2⁻³² · n.
pub fn uniform_below<R: RngCore + ?Sized>(rng: &mut R, n: u32) -> u32 {
    ((rng.next_u32() as u64 * n as u64) >> 32) as u32
}

/// A policy's state as plain data ([`Policy::state`], [`Policy::restore`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PolicyState {
    /// The kind the policy was built as, with its Δ or α.
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

/// The number that stands for a policy kind in a checkpoint
/// ([`PolicyName::code`]).
pub fn kind_code(kind: &PolicyKind) -> u8 {
    PolicyName::of(kind).code()
}

/// Kinds whose learners mean the same by an action and a state: SARSA, PADA
/// and the low-pass filter choose motor levels on the plain state; each of
/// the others is a family of its own.
fn family(kind: &PolicyKind) -> u8 {
    match kind {
        PolicyKind::Sarsa | PolicyKind::Pada { .. } | PolicyKind::LowPass { .. } => 0,
        PolicyKind::MarkovLowPass { .. } => 1,
        PolicyKind::Integrator { .. } => 2,
        PolicyKind::MarkovIntegrator { .. } => 3,
    }
}

/// The parameter of a kind (α or Δ; 0 for SARSA), as a checkpoint stores it.
pub fn kind_parameter(kind: &PolicyKind) -> f32 {
    kind.parameter().unwrap_or(0.0)
}

/// The kind of a [`kind_code`] with its parameter; `None` for an unknown
/// code. The parameter is not checked here ([`PolicyKind::validate`]).
pub fn kind_from_code(code: u8, parameter: f32) -> Option<PolicyKind> {
    PolicyName::from_code(code).map(|n| n.with_parameter(parameter))
}

/// An action policy with its memory (previous action, filter state or
/// integrated command).
#[derive(Debug, Clone)]
pub struct Policy {
    /// The kind in force (plain SARSA after a switch back).
    kind: PolicyKind,
    /// The kind the policy was built (or restored) as.
    built: PolicyKind,
    motor: ActionSpace,
    learner: ActionSpace,
    /// PADA's reach per dimension and level: the contiguous levels within Δ.
    reach: [[(u8, u8); MAX_LEVELS]; MAX_ACTION_DIMS],
    prev: Levels,
    output: Output,
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
        let mut reach = [[(0u8, 0u8); MAX_LEVELS]; MAX_ACTION_DIMS];
        let delta = match kind {
            PolicyKind::Pada { delta } => delta,
            _ => f32::INFINITY,
        };
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
        let mut policy =
            Policy { kind, built: kind, motor, learner, reach, prev: [0; MAX_ACTION_DIMS], output: [0.0; MAX_ACTION_DIMS] };
        policy.reset();
        Ok(policy)
    }

    /// The kind in force, with its parameter ([`PolicyKind::Sarsa`] after
    /// [`switch_to_sarsa`](Self::switch_to_sarsa)).
    pub fn kind(&self) -> PolicyKind {
        self.kind
    }

    /// The kind the policy was built (or restored) as, with its parameter;
    /// unchanged by a switch back to SARSA.
    pub fn built_kind(&self) -> PolicyKind {
        self.built
    }

    /// Whether PADA or the low-pass filter was switched back to plain SARSA
    /// (Section VIII).
    pub fn switched(&self) -> bool {
        self.kind != self.built
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

    /// Restores a policy state: the kind with its parameter, the switch back
    /// to SARSA, the previous action and the filter's or integrator's
    /// memory. The kind may differ from the one built when its learner means
    /// the same by an action and a state: SARSA, PADA and the low-pass
    /// filter (any Δ or α) stand in for each other, as do Markov low-pass
    /// filters of any α, and integrators of a Δ that gives the same
    /// increments; otherwise, or with any field out of range, nothing
    /// changes.
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
                    "a policy with the running learner's actions and state (sarsa, pada, lowpass alike; the integrators and Markov variants only as configured)",
                ));
            }
            p
        };
        if state.switched {
            if !matches!(state.kind, PolicyKind::Pada { .. } | PolicyKind::LowPass { .. }) {
                return Err(ConfigError::new(
                    "policy.switched",
                    1.0,
                    "false unless the policy is pada or lowpass (only they switch back to sarsa)",
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

    /// Back to the state of an episode start: the motor at rest.
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
    }

    /// The learner's previous action (levels of the learner's space).
    pub fn previous(&self) -> Levels {
        self.prev
    }

    /// The last applied output (the filter's or integrator's memory).
    pub fn output(&self) -> Output {
        self.output
    }

    /// The candidates for the next action: PADA's neighbourhood of the
    /// previous action (Eq. 9), otherwise every action.
    pub fn candidates(&self) -> Candidates {
        let dims = self.learner.dims();
        let mut c = Candidates { lo: [0; MAX_ACTION_DIMS], hi: [0; MAX_ACTION_DIMS], dims: dims as u8 };
        for i in 0..dims {
            if let PolicyKind::Pada { .. } = self.kind {
                let (lo, hi) = self.reach[i][self.prev[i] as usize];
                c.lo[i] = lo;
                c.hi[i] = hi;
            } else {
                c.hi[i] = self.learner.dim(i).len() as u8 - 1;
            }
        }
        c
    }

    /// Applies the learner's choice and returns the motor output.
    pub fn apply(&mut self, levels: &Levels) -> Output {
        self.prev = *levels;
        for i in 0..self.motor.dims() {
            let chosen = self.learner.dim(i).value(levels[i]);
            self.output[i] = match self.kind {
                PolicyKind::Sarsa | PolicyKind::Pada { .. } => chosen,
                // Eq. 8.
                PolicyKind::LowPass { alpha } | PolicyKind::MarkovLowPass { alpha } => {
                    alpha * chosen + (1.0 - alpha) * self.output[i]
                }
                PolicyKind::Integrator { .. } | PolicyKind::MarkovIntegrator { .. } => {
                    let d = self.motor.dim(i);
                    (self.output[i] + chosen).clamp(d.min(), d.max())
                }
            };
        }
        self.output
    }

    /// Moves the memory between action dimensions when the joints they
    /// drive swap roles (LEO's footstep: stance and swing trade legs):
    /// dimension `i` takes dimension `map[i]`'s previous action and filter
    /// or integrator output, or, for `None`, starts at rest (the level and
    /// output of 0, as at an episode's start). Unused dimensions are left
    /// alone; an index out of range counts as `None`.
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

    /// Switches PADA or the low-pass filter back to plain SARSA
    /// (Section VIII); the learner's actions and state stay the same, so the
    /// learned values carry over. Plain SARSA switches to itself.
    pub fn switch_to_sarsa(&mut self) -> Result<(), StepError> {
        match self.built {
            PolicyKind::Sarsa | PolicyKind::Pada { .. } | PolicyKind::LowPass { .. } => {
                self.kind = PolicyKind::Sarsa;
                Ok(())
            }
            _ => Err(StepError::CannotSwitch),
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
    fn parameters_are_validated() {
        let m = pendulum_motor;
        assert_eq!(Policy::new(PolicyKind::Pada { delta: -0.1 }, m()).unwrap_err().param, "delta");
        assert_eq!(Policy::new(PolicyKind::Integrator { delta: 0.0 }, m()).unwrap_err().param, "delta");
        assert_eq!(Policy::new(PolicyKind::LowPass { alpha: 0.0 }, m()).unwrap_err().param, "lowpass alpha");
        assert_eq!(Policy::new(PolicyKind::MarkovLowPass { alpha: 1.5 }, m()).unwrap_err().param, "lowpass alpha");
        assert_eq!(Policy::new(PolicyKind::LowPass { alpha: f32::NAN }, m()).unwrap_err().param, "lowpass alpha");
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
