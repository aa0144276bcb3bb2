//! SARSA(λ) with tile coding, ε-greedy selection over the policy's
//! candidates, and bounded traces (Section III; reference semantics in
//! `docs/reference/grl.md` §5).
//!
//! - `Q(s, a)` is the **mean** of the `TILINGS` active weights, and an update
//!   moves every active weight by `α·δ·e`, so that `Q` itself moves by `α·δ`
//!   for the current pair: α = 0.2 means what it means in the paper.
//! - `δ = r + γ·Q(s', a') − Q(s, a)` on-policy: `a'` is chosen (by the
//!   policy, among its candidates) before the update; an absorbing end has
//!   no bootstrap term, a timeout does.
//! - Traces: [`crate::trace`], cleared at every episode start.
//! - ε-greedy: with probability ε a uniformly random candidate, else the
//!   best candidate, ties broken uniformly at random. The caller's
//!   [`RngCore`] is the only source of randomness, so a seed reproduces a
//!   run bit for bit on any machine.
//!
//! Floats enter only as observations and rewards, checked for finiteness
//! before anything changes: a NaN state is an error that changes no weight.
//!
//! What the agent carries between episodes besides its weights — counters,
//! ε, mode, the policy's state — is plain data ([`AgentState`]): a
//! checkpoint saves it ([`crate::checkpoint`]) and
//! [`Agent::restore_state`] puts it back after [`Agent::check_state`].

use crate::action_space::{ActionSpace, Levels, Output, MAX_ACTION_DIMS};
use crate::claim_table::InitialWeights;
use crate::error::{check_range, ConfigError, StepError};
use crate::fixed::{Frac, Q16};
use crate::policy::{Candidates, Policy, PolicyKind, PolicyState};
use crate::tile_coding::{Layout, StateDim, TileCoder};
use crate::trace::Trace;
use crate::weights::WeightStore;
use rand_core::RngCore;
use tiled::TileBoxes;

mod choice;
mod coder;
mod params;
mod tiled;
mod update;
pub use coder::{coder_for, exact_table_len};
pub use params::{SarsaParams, WeightInit};

/// Learning (ε-greedy, updates) or testing (greedy, no updates: the test
/// runs of Section VI).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Mode {
    /// ε-greedy selection and SARSA(λ) updates.
    Learning,
    /// Greedy selection among the policy's candidates, no updates.
    Testing,
}

/// What the agent decided for one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Joint index of the learner's action.
    pub action: u32,
    /// The learner's action as levels per dimension.
    pub levels: Levels,
    /// What to apply to each motor (torque, voltage …), after the policy.
    pub output: Output,
    /// Whether the action was an exploratory draw.
    pub explored: bool,
    /// `Q(s, a)` of the chosen action.
    pub q: Q16,
}

/// How an episode ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EpisodeEnd<'a> {
    /// An absorbing state (a fall): no bootstrap.
    Absorbing,
    /// A time limit in a non-terminal state: bootstrap from this observation.
    Timeout(&'a [f32]),
}

/// Counters for telemetry and reports.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AgentStats {
    /// Decisions taken (learning and testing).
    pub steps: u64,
    /// SARSA updates made.
    pub updates: u64,
    /// Exploratory decisions.
    pub explorations: u64,
    /// Episodes started.
    pub episodes: u32,
    /// Weight writes that hit the Q16 range and saturated.
    pub saturations: u32,
    /// Trace entries dropped for lack of capacity.
    pub trace_drops: u32,
    /// Claims a full claim table refused ([`crate::claim_table`]): each
    /// is one feature's update dropped. 0 for plain tables.
    pub claims_refused: u32,
    /// The last TD error δ.
    pub last_td_error: Q16,
}

/// What an agent carries from one episode to the next, besides its
/// weights, as plain data: what a checkpoint saves so that a reset board
/// continues learning where it was ([`Agent::state`],
/// [`Agent::restore_state`]).
///
/// Not in it: the eligibility trace and the pair being played, which live
/// only within an episode (restoring ends the episode), and what the
/// configuration fixes (α, γ, λ, the tile coder, the action space).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AgentState {
    /// The counters (steps, updates, explorations, episodes, saturations,
    /// trace drops, last TD error).
    pub stats: AgentStats,
    /// The exploration rate ε, `0 ≤ ε ≤ 1`.
    pub epsilon: f32,
    /// Learning or testing.
    pub mode: Mode,
    /// The policy: its kind with Δ or α, the switch back to SARSA, the
    /// previous action and the filter's or integrator's memory.
    pub policy: PolicyState,
    /// A claim table's seed of its unclaimed features' initial weights
    /// ([`crate::claim_table::InitialWeights`]); 0 for plain tables.
    pub table_seed: u64,
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Current<const TILINGS: usize> {
    /// Feature indices of the (state, action) pair being played.
    features: [u32; TILINGS],
}

/// A SARSA(λ) agent with `TILINGS` tilings and a trace of at most `TRACE`
/// entries, on weights stored in `W`.
///
/// The weights live in any [`WeightStore`]: an array owned by the agent, a
/// `&'static mut [Q16; N]` in a chosen RAM section on the chip
/// (compile-time size), a boxed slice on the host, a table split over two
/// memories, or 16-bit weights ([`crate::weights`]). The hashed layout
/// needs a power-of-two length.
pub struct Agent<W, const TILINGS: usize, const TRACE: usize> {
    coder: TileCoder<TILINGS>,
    policy: Policy,
    weights: W,
    trace: Trace<TILINGS, TRACE>,
    params: SarsaParams,
    alpha: Frac,
    gamma: Frac,
    /// ε scaled to 2³²: explore when a `u32` draw is below it.
    epsilon: u64,
    mode: Mode,
    obs_dims: usize,
    current: Option<Current<TILINGS>>,
    stats: AgentStats,
    /// The table's checksum, kept up to date write by write
    /// ([`WeightStore::checksum`]); `None` after the weights were handed
    /// out mutably, until [`rehash`](Agent::rehash).
    checksum: Option<u32>,
    /// With action tiles, the tiled greedy choice's boxes and the
    /// candidates they were made for: SARSA's candidates are the same at
    /// every step, PADA's move with its previous action.
    boxes: Option<(Candidates, TileBoxes<TILINGS>)>,
}

impl<W, const TILINGS: usize, const TRACE: usize> Agent<W, TILINGS, TRACE>
where
    W: WeightStore,
{
    /// Builds an agent that observes `obs` (the policy may append its own
    /// dimensions), drives `motor` through `policy`, and learns with
    /// `params` on `weights` laid out as `layout`. Weights are set from
    /// `params.init` with [`reset_weights`](Self::reset_weights).
    pub fn new(
        obs: &[StateDim],
        motor: ActionSpace,
        policy: PolicyKind,
        params: SarsaParams,
        layout: Layout,
        weights: W,
    ) -> Result<Self, ConfigError> {
        params.validate()?;
        if TRACE == 0 {
            return Err(ConfigError::new("trace capacity", 0.0, "at least 1 entry"));
        }
        if (layout == Layout::Claimed) != weights.claims() {
            return Err(ConfigError::new(
                "layout",
                layout.code() as f32,
                "a claim table (pada_core::claim_table) for the claim layout, a plain table for the others",
            ));
        }
        let policy = Policy::new(policy, motor)?;
        let coder = coder_for(obs, &policy, layout, weights.len())?;
        let decay = Frac::from_f32(params.gamma).times(Frac::from_f32(params.lambda));
        Ok(Agent {
            coder,
            policy,
            weights,
            trace: Trace::new(params.trace_kind, decay, Frac::from_f32(params.trace_threshold)),
            alpha: Frac::from_f32(params.alpha),
            gamma: Frac::from_f32(params.gamma),
            epsilon: (params.epsilon as f64 * 4_294_967_296.0) as u64,
            params,
            mode: Mode::Learning,
            obs_dims: obs.len(),
            current: None,
            stats: AgentStats::default(),
            checksum: None,
            boxes: None,
        })
    }

    /// Generalises over actions from now on: the learner's action values are
    /// tile-coded with these widths, one per action dimension
    /// ([`crate::action_tiles`]; the paper's LEO learner uses 6.67 V). Call
    /// it before learning: weights learned without it mean something else.
    ///
    /// Errors: those of [`TileCoder::with_action_tiles`]; the agent is
    /// unchanged then.
    pub fn generalise_actions(&mut self, widths: &[f32]) -> Result<(), ConfigError> {
        self.coder = self.coder.clone().with_action_tiles(self.policy.learner_space(), widths)?;
        self.boxes = None;
        Ok(())
    }

    /// Sets every weight from `params.init` (draws from `rng` if uniform).
    /// A claim table is emptied instead, and one draw from `rng` seeds the
    /// initial weights its unclaimed features read.
    pub fn reset_weights<R: RngCore + ?Sized>(&mut self, rng: &mut R) {
        if self.weights.claims() {
            let init = self.initial_weights(rng.next_u64());
            self.weights.reset_claims(init);
            self.rehash();
            return;
        }
        match self.params.init {
            WeightInit::Constant(c) => {
                for i in 0..self.weights.len() {
                    self.weights.set(i, Q16::from_f32(c));
                }
            }
            WeightInit::Uniform { min, max } => {
                let (lo, hi) = (Q16::from_f32(min).0 as i64, Q16::from_f32(max).0 as i64);
                let span = (hi - lo + 1) as u64;
                for i in 0..self.weights.len() {
                    let r = ((rng.next_u64() as u128 * span as u128) >> 64) as i64;
                    self.weights.set(i, Q16((lo + r) as i32));
                }
            }
        }
        self.rehash();
    }

    /// The initial weights of a claim table's unclaimed features under
    /// `seed`: `params.init`'s constant or uniform range.
    fn initial_weights(&self, seed: u64) -> InitialWeights {
        match self.params.init {
            WeightInit::Constant(c) => InitialWeights { seed, lo: Q16::from_f32(c).0, span: 1 },
            WeightInit::Uniform { min, max } => {
                let (lo, hi) = (Q16::from_f32(min).0 as i64, Q16::from_f32(max).0 as i64);
                InitialWeights { seed, lo: lo as i32, span: (hi - lo + 1) as u64 }
            }
        }
    }

    /// Starts an episode in observation `obs`: clears the trace, puts the
    /// policy at rest, and chooses the first action.
    pub fn start_episode<R: RngCore + ?Sized>(&mut self, obs: &[f32], rng: &mut R) -> Result<Decision, StepError> {
        self.check_obs(obs)?;
        self.trace.clear();
        self.policy.reset();
        self.stats.episodes = self.stats.episodes.wrapping_add(1);
        let (decision, features) = self.decide(obs, rng);
        Ok(self.commit(decision, features))
    }

    /// One step: the previous action earned `reward` and led to `obs`.
    /// Chooses the next action and, when learning, updates the weights.
    pub fn step<R: RngCore + ?Sized>(
        &mut self,
        reward: f32,
        obs: &[f32],
        rng: &mut R,
    ) -> Result<Decision, StepError> {
        let current = self.current.ok_or(StepError::NoEpisode)?;
        self.check_obs(obs)?;
        if !reward.is_finite() {
            return Err(StepError::NonFiniteReward);
        }
        let (decision, features) = self.decide(obs, rng);
        if self.mode == Mode::Learning {
            self.update(&current, reward, Some(decision.q), rng);
        }
        Ok(self.commit(decision, features))
    }

    /// Ends the episode: the last action earned `reward`; `end` says whether
    /// to bootstrap. The next call must be [`start_episode`](Self::start_episode).
    pub fn end_episode<R: RngCore + ?Sized>(
        &mut self,
        reward: f32,
        end: EpisodeEnd<'_>,
        rng: &mut R,
    ) -> Result<(), StepError> {
        let current = self.current.ok_or(StepError::NoEpisode)?;
        if let EpisodeEnd::Timeout(obs) = end {
            self.check_obs(obs)?;
        }
        if !reward.is_finite() {
            return Err(StepError::NonFiniteReward);
        }
        if self.mode == Mode::Learning {
            let q_next = match end {
                EpisodeEnd::Absorbing => None,
                EpisodeEnd::Timeout(obs) => {
                    // The on-policy successor: the action the policy would
                    // take in the timed-out state (not applied).
                    let (successor, _) = self.decide(obs, rng);
                    Some(successor.q)
                }
            };
            self.update(&current, reward, q_next, rng);
        }
        self.current = None;
        self.trace.clear();
        Ok(())
    }

    /// Learning or testing.
    pub fn set_mode(&mut self, mode: Mode) {
        self.mode = mode;
    }

    /// The current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Changes ε (`0 ≤ ε ≤ 1`).
    pub fn set_epsilon(&mut self, epsilon: f32) -> Result<(), ConfigError> {
        check_range("epsilon", epsilon, 0.0, 1.0, "0 <= epsilon <= 1")?;
        self.params.epsilon = epsilon;
        self.epsilon = (epsilon as f64 * 4_294_967_296.0) as u64;
        Ok(())
    }

    /// Switches PADA, the low-pass filter or a gentle exploration back to
    /// plain SARSA (Section VIII).
    pub fn switch_to_sarsa(&mut self) -> Result<(), StepError> {
        self.policy.switch_to_sarsa()
    }

    /// Moves the policy's parameter while learning — PADA's Δ, the low-pass
    /// filter's α ([`Policy::set_parameter`]; the wear governor,
    /// [`crate::governor`]). It restricts the next decision; the weights
    /// mean the same, since these kinds share SARSA's learner. A refused
    /// value changes nothing.
    pub fn set_policy_parameter(&mut self, value: f32) -> Result<(), ConfigError> {
        self.policy.set_parameter(value)
    }

    /// Moves the policy's memory between action dimensions when the joints
    /// they drive swap roles ([`Policy::remap`]; LEO's footstep,
    /// [`crate::robot::RobotSpec::footstep_remap`]). Call it after the
    /// observation that shows the swap and before the next decision.
    pub fn remap_memory(&mut self, map: &[Option<u8>; MAX_ACTION_DIMS]) {
        self.policy.remap(map);
    }

    /// The agent's state besides its weights, as plain data
    /// ([`AgentState`]).
    pub fn state(&self) -> AgentState {
        AgentState {
            stats: self.stats(),
            epsilon: self.params.epsilon,
            mode: self.mode,
            policy: self.policy.state(),
            table_seed: self.weights.table_seed(),
        }
    }

    /// Checks that `state` can be restored into this agent; the error names
    /// the first field out of range and the valid range:
    ///
    /// - `epsilon`: finite, `0 ≤ ε ≤ 1`;
    /// - `stats.explorations`, `stats.updates`: at most `stats.steps` (each
    ///   is counted with a decision);
    /// - `table_seed` and `stats.claims_refused`: 0 unless the table is a
    ///   claim table;
    /// - the policy ([`Policy::check_state`]): its kind's Δ or α in range
    ///   ([`PolicyKind::validate`]: `delta`, `lowpass alpha`), a kind whose
    ///   learner means the same as the running one (`policy.kind`), the
    ///   switch back only for PADA and the low-pass filter
    ///   (`policy.switched`), the previous action's level in each dimension
    ///   below that dimension's number of levels (`policy.previous[i]`), the
    ///   filter's or integrator's memory inside the motor's range
    ///   (`policy.output[i]`).
    pub fn check_state(&self, state: &AgentState) -> Result<(), ConfigError> {
        check_range("epsilon", state.epsilon, 0.0, 1.0, "0 <= epsilon <= 1")?;
        let s = &state.stats;
        if s.explorations > s.steps {
            return Err(ConfigError::new("stats.explorations", s.explorations as f32, "explorations <= steps"));
        }
        if s.updates > s.steps {
            return Err(ConfigError::new("stats.updates", s.updates as f32, "updates <= steps"));
        }
        if !self.weights.claims() && (state.table_seed != 0 || s.claims_refused != 0) {
            return Err(ConfigError::new(
                "table_seed",
                state.table_seed as f32,
                "0 with no claims refused: this learner's table is not a claim table",
            ));
        }
        self.policy.check_state(&state.policy)
    }

    /// Restores a state taken by [`state`](Self::state) (of this agent or
    /// of one with the same configuration, e.g. from a checkpoint), after
    /// [`check_state`](Self::check_state); a refused state changes nothing.
    ///
    /// Restoring **ends the current episode**: eligibility traces are not
    /// saved (they only matter within an episode, and an episode cut by a
    /// reset cannot be continued anyway), so the trace is cleared and the
    /// next call must be [`start_episode`](Self::start_episode), which also
    /// puts the policy back at rest. The weights are not touched here, but a
    /// claim table (whose slots must be loaded first) gets its initial
    /// weights' seed and its refusals back and counts its claimed slots.
    pub fn restore_state(&mut self, state: &AgentState) -> Result<(), ConfigError> {
        self.check_state(state)?;
        self.policy.restore(&state.policy)?;
        self.set_epsilon(state.epsilon)?;
        self.mode = state.mode;
        self.stats = state.stats;
        let init = self.initial_weights(state.table_seed);
        self.weights.restore_claims(init, state.stats.claims_refused);
        self.trace.set_drops(state.stats.trace_drops);
        self.current = None;
        self.trace.clear();
        Ok(())
    }

    /// Writes what gives this agent's weights their meaning into a
    /// configuration hash ([`crate::profile::config_hash`]): the tile
    /// coder ([`TileCoder::write_config`]), the trace's capacity and
    /// settings, the learner's action levels (all levels, or an
    /// integrator's −Δ/0/+Δ), α, γ and λ. Not ε, the initialisation or the
    /// policy's own parameter when it leaves the learner unchanged (PADA,
    /// low-pass: they share SARSA's weights).
    pub fn write_config(&self, h: &mut crate::checkpoint::ConfigHasher) {
        self.coder.write_config(h);
        h.write_u32(TRACE as u32);
        let space = self.policy.learner_space();
        h.write_u32(space.dims() as u32);
        for i in 0..space.dims() {
            h.write_u32(space.dim(i).len() as u32);
            for &v in space.dim(i).values() {
                h.write_f32(v);
            }
        }
        h.write_f32(self.params.alpha)
            .write_f32(self.params.gamma)
            .write_f32(self.params.lambda)
            .write_f32(self.params.trace_threshold)
            .write_u32(self.params.trace_kind.code());
    }

    /// The action policy.
    pub fn policy(&self) -> &Policy {
        &self.policy
    }

    /// The tile coder.
    pub fn coder(&self) -> &TileCoder<TILINGS> {
        &self.coder
    }

    /// The learning parameters.
    pub fn params(&self) -> &SarsaParams {
        &self.params
    }

    /// Counters.
    pub fn stats(&self) -> AgentStats {
        let claims_refused = self.weights.occupancy().map_or(0, |o| o.refused);
        AgentStats { trace_drops: self.trace.drops(), claims_refused, ..self.stats }
    }

    /// The weights.
    pub fn weights(&self) -> &W {
        &self.weights
    }

    /// The weights, mutably (loading a checkpoint). The running checksum is
    /// dropped; [`rehash`](Self::rehash) computes it again.
    pub fn weights_mut(&mut self) -> &mut W {
        self.checksum = None;
        &mut self.weights
    }

    /// Computes the table's checksum from every weight (after the weights
    /// were changed from outside, e.g. loaded), to be kept up to date from
    /// then on.
    pub fn rehash(&mut self) {
        self.checksum = Some(self.weights.checksum());
    }

    /// Gives the weight storage back (to build an agent with another
    /// policy on the same table, e.g. the firmware's `&'static mut` table).
    pub fn into_weights(self) -> W {
        self.weights
    }

    /// The table's checksum ([`WeightStore::checksum`]): equal on every
    /// machine for equal weights. Kept up to date by every update, so it
    /// costs nothing per call; only after [`weights_mut`](Self::weights_mut)
    /// without a [`rehash`](Self::rehash) is it computed from every weight.
    pub fn weights_checksum(&self) -> u32 {
        self.checksum.unwrap_or_else(|| self.weights.checksum())
    }

    /// `Q(s, a)` for an observation and a joint action of the learner, with
    /// the policy's current extension appended (for inspection and tests).
    pub fn q_value(&self, obs: &[f32], action: u32) -> Result<Q16, StepError> {
        self.check_obs(obs)?;
        let code = self.code(obs);
        Ok(self.q_of(&self.coder.features(&code, action)))
    }

    fn check_obs(&self, obs: &[f32]) -> Result<(), StepError> {
        if obs.len() != self.obs_dims {
            return Err(StepError::WrongStateLength { expected: self.obs_dims as u8, got: obs.len() as u8 });
        }
        match obs.iter().position(|x| !x.is_finite()) {
            Some(dim) => Err(StepError::NonFiniteState { dim: dim as u8 }),
            None => Ok(()),
        }
    }

    fn commit(&mut self, mut decision: Decision, features: [u32; TILINGS]) -> Decision {
        decision.output = self.policy.apply(&decision.levels);
        self.current = Some(Current { features });
        self.stats.steps += 1;
        if decision.explored {
            self.stats.explorations += 1;
        }
        decision
    }
}
