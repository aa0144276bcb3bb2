//! What the experiment runner needs from a learning task: a [`Task`]
//! describes the problem (state, motor, timing, learning parameters) and
//! builds [`Plant`]s, the simulated systems the agent drives.
//!
//! The pendulums of Section VII implement these traits in
//! [`crate::pendulum`]; a further task (LEO, Section VIII) implements the
//! same two traits and is run by the same [`crate::experiment`] code.

use pada_core::action_space::{ActionSpace, Output};
use pada_core::agent::SarsaParams;
use pada_core::profile::{LearnerProfile, TableSize};
use pada_core::tile_coding::{Layout, StateDim};
use rand_core::RngCore;

/// The result of one control period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// The reward earned by the command just applied.
    pub reward: f32,
    /// Whether the plant reached an absorbing state (a fall): the episode
    /// ends without bootstrapping.
    pub terminal: bool,
}

/// A simulated system driven at a fixed control period.
///
/// Observations are written into caller-provided buffers of
/// [`TaskSpec::state`]`.len()` values, so a step allocates nothing.
pub trait Plant: Send {
    /// Puts the plant in the start state of an episode and writes the first
    /// observation. `rng` is for tasks with random starts.
    fn reset(&mut self, rng: &mut dyn RngCore, obs: &mut [f32]);

    /// Applies `command` (one value per motor of [`TaskSpec::motor`], after
    /// the policy) for one control period, writes the next observation and
    /// returns the reward and whether the state is absorbing.
    fn step(&mut self, command: &[f32], obs: &mut [f32]) -> Step;

    /// The torque on each physical gearbox \[N·m\] in the step just taken
    /// under `command` (the runner asks after [`Plant::step`]), as the
    /// simulation computes it: the **physical** MTBF's input (Eqs. 3–7).
    /// One entry per gearbox ([`TaskSpec::gearboxes`]), the rest 0.
    fn gearbox_torques(&self, command: &[f32]) -> Output;

    /// The torque on each physical gearbox as **the paper** takes it
    /// (Section IV): from the commanded action, "a linear relationship
    /// between voltage and torque" — the stall torque of the commanded
    /// voltage, back-EMF left out. The same as
    /// [`gearbox_torques`](Self::gearbox_torques) for a plant whose action
    /// is the torque or whose torque is linear in the voltage.
    fn commanded_torques(&self, command: &[f32]) -> Output {
        self.gearbox_torques(command)
    }

    /// The fault the robot's safety machine raises at the plant's last
    /// reading (after [`Plant::reset`] or [`Plant::step`]): a joint past
    /// its soft limit ([`pada_core::robot::RobotSpec::soft_limit_fault`]).
    /// On the board torque goes off there until an operator clears it;
    /// the runner ends the trial there as well. `None` for a plant without
    /// soft limits.
    fn fault(&self) -> Option<pada_core::safety::FaultCause> {
        None
    }

    /// Distance walked in the current episode \[m\], for walking tasks
    /// (LEO); `None` for the others.
    fn walked_distance_m(&self) -> Option<f64> {
        None
    }

    /// Whether the step just taken was a footstep (the stance leg changed),
    /// when the policy's memory moves with the joints
    /// ([`TaskSpec::footstep_remap`]).
    fn footstep(&self) -> bool {
        false
    }
}

/// The weight table of a task's agents.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeightTable {
    /// One weight per (tiling, tile, action), sized to fit exactly: no
    /// collisions, and small enough for the cache on low-dimensional tasks.
    Exact,
    /// The exact layout in a table of a fixed size (a board's): a policy
    /// whose exact table is larger does not build.
    ExactOf {
        /// Weights in the table.
        weights: usize,
    },
    /// A hashed table of `2^log2_size` weights (collisions allowed), for
    /// tasks with many state dimensions.
    Hashed {
        /// Base-2 logarithm of the table size.
        log2_size: u32,
    },
    /// A claim table of `2^log2_size` slots ([`pada_core::claim_table`]):
    /// hashed features without collisions; Q16 weights with 32-bit tags on
    /// the host, 16-bit weights and tags on the chips.
    Claimed {
        /// Base-2 logarithm of the table size.
        log2_size: u32,
        /// How each weight is stored.
        format: pada_core::weights::WeightFormat,
        /// Bytes per tag (2 or 4).
        tag_bytes: usize,
        /// What a claim that finds the table full does.
        when_full: pada_core::claim_table::WhenFull,
    },
}

/// The fixed description of a task.
#[derive(Debug, Clone)]
pub struct TaskSpec {
    /// The task's name as the command line spells it.
    pub name: &'static str,
    /// A one-line description for reports.
    pub title: &'static str,
    /// Seconds per control step (1/sampling rate).
    pub control_period_s: f64,
    /// Control steps of an episode before the time limit (a non-absorbing
    /// end), at least 1.
    pub episode_steps: u32,
    /// The observed state, with ranges and tile widths.
    pub state: Vec<StateDim>,
    /// The motor's discrete levels (torques or voltages).
    pub motor: ActionSpace,
    /// How the weight table is laid out.
    pub table: WeightTable,
    /// Tile widths of the action dimensions when the agent generalises over
    /// actions (hashed tables only; [`pada_core::action_tiles`]), `None` for
    /// one independent set of weights per joint action.
    pub action_tiles: Option<Vec<f32>>,
    /// SARSA(λ) parameters shared by all six algorithms.
    pub params: SarsaParams,
    /// One greedy test episode after this many learning episodes
    /// (Section VI's test runs); 0 is taken as 1.
    pub test_interval: u32,
    /// Default learning time of a trial \[s of simulated time\].
    pub default_seconds: f64,
    /// Default number of trials (the paper's count for this task).
    pub default_trials: u32,
    /// How [`Plant::gearbox_torques`] is obtained from the command, for
    /// reports.
    pub torque_note: &'static str,
    /// Physical gearboxes whose fatigue is counted (the entries of
    /// [`Plant::gearbox_torques`]): the pendulum's one; LEO's two hips and
    /// two knees (not the three learned roles, which move between
    /// gearboxes at every footstep).
    pub gearboxes: usize,
    /// How the policy's memory moves between motor dimensions at a footstep
    /// (the robot's definition, `pada_core::robot::RobotSpec::footstep_remap`).
    pub footstep_remap: Option<[Option<u8>; pada_core::action_space::MAX_ACTION_DIMS]>,
    /// The board learner profile the table follows, for the robots of
    /// `pada_core::robot` (`None` for the simulated pendulum, which has no
    /// board).
    pub profile: Option<LearnerProfile>,
    /// The largest gearbox torque one learning action can command, as
    /// [`Plant::commanded_torques`] takes it \[N·m\]: the torque law at the
    /// motor's largest level. Its re-engagement is the most damage one
    /// action can do, the wear governor's reserve
    /// ([`pada_core::governor`]).
    pub worst_torque_nm: f32,
}

impl WeightTable {
    /// The table a board's learner profile describes.
    pub fn of_profile(profile: &LearnerProfile) -> WeightTable {
        match (profile.layout, profile.size) {
            (Layout::Exact, TableSize::FitExact) => WeightTable::Exact,
            (Layout::Exact, TableSize::Weights(weights)) => WeightTable::ExactOf { weights },
            // Hashed tables have a power-of-two size (checked by the tile
            // coder); FitExact is an exact-layout size only.
            (Layout::Hashed, TableSize::Weights(n)) => WeightTable::Hashed { log2_size: n.trailing_zeros() },
            (Layout::Hashed, TableSize::FitExact) => WeightTable::Hashed { log2_size: 0 },
            (Layout::Claimed, TableSize::Weights(n)) => WeightTable::Claimed {
                log2_size: n.trailing_zeros(),
                format: profile.format,
                tag_bytes: profile.tag_bytes,
                when_full: profile.when_full,
            },
            (Layout::Claimed, TableSize::FitExact) => WeightTable::Claimed {
                log2_size: 0,
                format: profile.format,
                tag_bytes: profile.tag_bytes,
                when_full: profile.when_full,
            },
        }
    }
}

impl TaskSpec {
    /// The gearbox of counted joint `counted` (Eqs. 3–7): the robot's
    /// servo's, Table I for a task without a robot.
    pub fn gearbox(&self, counted: usize) -> pada_core::fatigue::GearboxParams {
        self.profile.map_or(pada_core::fatigue::GearboxParams::TABLE_I, |p| p.robot.gearbox(counted))
    }

    /// The counted gearbox the worst action damages most (the wear
    /// governor's): Table I for a task without a robot.
    pub fn weakest_gearbox(&self) -> pada_core::fatigue::GearboxParams {
        self.profile.map_or(pada_core::fatigue::GearboxParams::TABLE_I, |p| p.robot.weakest_gearbox())
    }

    /// The rules of the task's episodes, for the shared episode cycle
    /// ([`pada_core::episodes::Episodes`]).
    pub fn episode_rules(&self) -> pada_core::episodes::EpisodeRules {
        pada_core::episodes::EpisodeRules {
            episode_steps: self.episode_steps,
            test_interval: self.test_interval,
            footstep_remap: self.footstep_remap,
        }
    }

    /// The task of a robot of `pada_core::robot` on a board's learner
    /// `profile`: name, timing, state, motor, action tiles and learning
    /// parameters from the robot's one definition, the table from the
    /// profile. Defaults for the runner (learning time, trials) are the
    /// caller's to set.
    pub fn of_robot(profile: LearnerProfile, title: &'static str, torque_note: &'static str) -> TaskSpec {
        let robot = profile.robot;
        TaskSpec {
            name: robot.name,
            title,
            control_period_s: robot.period_s(),
            episode_steps: robot.episode_steps,
            state: robot.state.to_vec(),
            // The definitions are checked by pada-core's tests.
            motor: robot.motor().expect("a robot definition's motor builds"),
            table: WeightTable::of_profile(&profile),
            action_tiles: robot.action_tiles.map(|w| w.to_vec()),
            params: robot.params,
            test_interval: robot.test_interval,
            default_seconds: 1500.0,
            default_trials: 8,
            torque_note,
            gearboxes: robot.gearboxes(),
            footstep_remap: robot.footstep_remap,
            profile: Some(profile),
            worst_torque_nm: robot.worst_commanded_torque(),
        }
    }
}

/// A learning task: its description and a factory of plants.
pub trait Task: Sync {
    /// The plant type.
    type Plant: Plant;

    /// The task's description.
    fn spec(&self) -> &TaskSpec;

    /// A new plant (one per trial; trials run in parallel).
    fn plant(&self) -> Self::Plant;
}
