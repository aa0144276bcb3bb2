//! The robots pada learns on, each defined once, for the simulator and the
//! chip alike: what the learner observes (dimensions, ranges, tile
//! widths), its motor's levels, its learning parameters, the control
//! period, the episode length and the test interval ([`RobotSpec`]), and
//! the robot's rules (observation, reward, falls, held joints, start pose,
//! rate filter, gearbox torque) in its module:
//!
//! | module | robot |
//! |---|---|
//! | [`pendulum`] | the physical inverted pendulum of Section VII (33 or 20 Hz) |
//! | [`leo`] | the biped LEO walking on its boom (Section VIII) |
//! | [`filter`] | GRL's rate filter, used by LEO |
//!
//! The host's simulations produce these quantities from physics and the
//! firmware from servo counts and encoder readings; both build their
//! learner from the same [`RobotSpec`] and a board's learner profile
//! ([`crate::profile`]), and [`crate::profile::config_hash`] of the two
//! agents is the same (a test checks it).

pub mod filter;
pub mod leo;
pub mod pendulum;

use crate::action_space::{ActionDim, ActionSpace, MAX_ACTION_DIMS};
use crate::agent::{coder_for, exact_table_len, Agent, SarsaParams};
use crate::error::ConfigError;
use crate::policy::{Policy, PolicyKind};
use crate::tile_coding::{Layout, StateDim};
use crate::weights::WeightStore;

/// A robot with a board.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Robot {
    /// The physical pendulum of Section VII at the paper's 33 Hz (30 ms).
    Pendulum33,
    /// The same pendulum at 20 Hz (50 ms).
    Pendulum20,
    /// LEO at 30 Hz.
    Leo,
}

impl Robot {
    /// Every robot, for iteration.
    pub const ALL: [Robot; 3] = [Robot::Pendulum33, Robot::Pendulum20, Robot::Leo];

    /// The robot's name as the command line, telemetry and the
    /// configuration hash spell it.
    pub const fn name(self) -> &'static str {
        match self {
            Robot::Pendulum33 => "physical-pendulum",
            Robot::Pendulum20 => "physical-pendulum-20hz",
            Robot::Leo => "leo",
        }
    }

    /// A stable number for the wire.
    pub const fn code(self) -> u8 {
        match self {
            Robot::Pendulum33 => 1,
            Robot::Pendulum20 => 2,
            Robot::Leo => 3,
        }
    }

    /// The robot with this [`code`](Self::code).
    pub fn from_code(code: u8) -> Option<Robot> {
        Robot::ALL.into_iter().find(|r| r.code() == code)
    }

    /// The robot with this [`name`](Self::name).
    pub fn from_name(name: &str) -> Option<Robot> {
        Robot::ALL.into_iter().find(|r| r.name() == name)
    }

    /// The gearbox torque \[N·m\] of a commanded voltage as the paper takes
    /// it (Section IV: "a linear relationship between voltage and
    /// torque"): the pendulum's K/R, LEO's RX-28 stall torque per volt. The
    /// input of the paper's MTBF on the host and on the board alike.
    pub fn commanded_gear_torque(self, voltage: f32) -> f32 {
        match self {
            Robot::Pendulum33 | Robot::Pendulum20 => pendulum::gearbox_torque(voltage as f64) as f32,
            Robot::Leo => leo::commanded_gear_torque(voltage),
        }
    }

    /// The learning task's definition.
    pub const fn spec(self) -> &'static RobotSpec {
        match self {
            Robot::Pendulum33 => &pendulum::SPEC_33HZ,
            Robot::Pendulum20 => &pendulum::SPEC_20HZ,
            Robot::Leo => &leo::SPEC,
        }
    }
}

/// The levels of each learned motor (every motor dimension has the same).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotorLevels {
    /// These values, in increasing order.
    Listed(&'static [f32]),
    /// `count` evenly spaced values from `min` to `max`
    /// ([`ActionDim::uniform`]).
    Uniform {
        /// The lowest level.
        min: f32,
        /// The highest level.
        max: f32,
        /// How many.
        count: u8,
    },
}

/// Everything that defines one robot's learning task.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotSpec {
    /// Which robot.
    pub robot: Robot,
    /// Control period \[µs\].
    pub period_us: u32,
    /// Control steps of an episode before its time limit (a non-absorbing
    /// end).
    pub episode_steps: u32,
    /// One greedy test episode after this many learning episodes
    /// (Section VI).
    pub test_interval: u32,
    /// The observation's dimensions as the tile coder sees them.
    pub state: &'static [StateDim],
    /// Learned motor dimensions.
    pub motor_dims: u8,
    /// Each motor dimension's levels.
    pub levels: MotorLevels,
    /// Tile widths of the motor dimensions when the agent generalises over
    /// actions ([`crate::action_tiles`]); `None` for one set of weights per
    /// joint action.
    pub action_tiles: Option<&'static [f32]>,
    /// SARSA(λ) parameters.
    pub params: SarsaParams,
    /// Physical gearboxes whose fatigue decides the robot's MTBF: the
    /// pendulum's one; LEO's two hips and two knees (Section VIII), the
    /// joints the learned actions drive as stance and swing roles trade
    /// legs. Their servos are the firmware's reported joints.
    pub gearboxes: u8,
    /// How the policy's memory (PADA's previous action, the low-pass
    /// filter's output, the integrated command) moves between the motor
    /// dimensions at a footstep, when the joints they drive trade roles
    /// ([`crate::agent::Agent::remap_memory`]); `None` for a robot without
    /// stance.
    pub footstep_remap: Option<[Option<u8>; MAX_ACTION_DIMS]>,
    /// The shift of 16-bit weights ([`crate::weights::WeightFormat::Half`])
    /// for this robot: its Q-values stay within ±2^(shift − 1).
    pub half_shift: u8,
}

impl RobotSpec {
    /// The robot's name.
    pub const fn name(&self) -> &'static str {
        self.robot.name()
    }

    /// The rules of the robot's episodes, for [`crate::episodes::Episodes`].
    pub const fn episode_rules(&self) -> crate::episodes::EpisodeRules {
        crate::episodes::EpisodeRules {
            episode_steps: self.episode_steps,
            test_interval: self.test_interval,
            footstep_remap: self.footstep_remap,
        }
    }

    /// The control period \[s\].
    pub fn period_s(&self) -> f64 {
        // Divided, not multiplied by 1e-6: 30 000 µs is then exactly the
        // double nearest 0.03.
        self.period_us as f64 / 1e6
    }

    /// The learner's motor: [`motor_dims`](Self::motor_dims) dimensions of
    /// [`levels`](Self::levels). The specs of this module are checked by
    /// its tests, so for them this cannot fail.
    pub fn motor(&self) -> Result<ActionSpace, ConfigError> {
        let dim = match self.levels {
            MotorLevels::Listed(values) => ActionDim::from_levels(values)?,
            MotorLevels::Uniform { min, max, count } => ActionDim::uniform(min, max, count as usize)?,
        };
        ActionSpace::repeated(dim, self.motor_dims as usize)
    }

    /// The largest gearbox torque one learning action can command \[N·m\]:
    /// the paper's torque law ([`Robot::commanded_gear_torque`]) at the level
    /// of largest magnitude. Its re-engagement is the most damage one action
    /// can do (the wear governor's reserve, [`crate::governor`]).
    pub fn worst_commanded_torque(&self) -> f32 {
        let Ok(motor) = self.motor() else { return 0.0 };
        let mut worst = 0.0f32;
        for i in 0..motor.dims() {
            for &v in motor.dim(i).values() {
                worst = worst.max(self.robot.commanded_gear_torque(v).abs());
            }
        }
        worst
    }

    /// Whether an agent with `policy` on a table of `table_len` weights laid
    /// out as `layout` builds, without building it (the firmware checks a
    /// new policy before it hands its only table to the new agent): the
    /// error names what does not fit, e.g. an exact table too small for a
    /// Markov policy's extra state dimension.
    pub fn check<const TILINGS: usize>(
        &self,
        policy: PolicyKind,
        layout: Layout,
        table_len: usize,
    ) -> Result<(), ConfigError> {
        self.params.validate()?;
        let policy = Policy::new(policy, self.motor()?)?;
        let coder = coder_for::<TILINGS>(self.state, &policy, layout, table_len)?;
        if let Some(widths) = self.action_tiles {
            coder.with_action_tiles(policy.learner_space(), widths)?;
        }
        Ok(())
    }

    /// Weights of the robot's exact table with `policy` (tilings × tiles ×
    /// learner actions): what a board's exact profile or the host allocates.
    pub fn exact_table_len<const TILINGS: usize>(&self, policy: PolicyKind) -> Result<usize, ConfigError> {
        exact_table_len::<TILINGS>(self.state, self.motor()?, policy)
    }

    /// The robot's agent learning with `policy` on `weights` laid out as
    /// `layout` (weights not yet initialised): the one place where the
    /// firmware, the host's runners and the replays build it.
    pub fn agent<W, const TILINGS: usize, const TRACE: usize>(
        &self,
        policy: PolicyKind,
        layout: Layout,
        weights: W,
    ) -> Result<Agent<W, TILINGS, TRACE>, ConfigError>
    where
        W: WeightStore,
    {
        let mut agent = Agent::new(self.state, self.motor()?, policy, self.params, layout, weights)?;
        if let Some(widths) = self.action_tiles {
            agent.generalise_actions(widths)?;
        }
        Ok(agent)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_spec_builds_its_motor_and_validates() {
        for robot in Robot::ALL {
            let spec = robot.spec();
            assert_eq!(spec.robot, robot);
            assert!(spec.motor().is_ok(), "{robot:?}");
            assert!(spec.params.validate().is_ok(), "{robot:?}");
            for (i, d) in spec.state.iter().enumerate() {
                assert!(d.validate().is_ok(), "{robot:?} dimension {i}: {d:?}");
            }
            if let Some(w) = spec.action_tiles {
                assert_eq!(w.len(), spec.motor_dims as usize);
            }
            assert_eq!(Robot::from_code(robot.code()), Some(robot));
            assert_eq!(Robot::from_name(robot.name()), Some(robot));
        }
        assert_eq!(Robot::Leo.spec().motor().unwrap().joint_count(), 343);
        assert_eq!(Robot::Leo.spec().state.len(), leo::OBS_DIM);
    }
}
