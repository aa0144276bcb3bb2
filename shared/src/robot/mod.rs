//! A robot, defined once for the simulator and the chip alike: its data
//! ([`RobotSpec`]: what the learner observes — dimensions, ranges, tile
//! widths —, its motor's levels, its learning parameters, the control
//! period, the episode length and the test interval; its joints with their
//! servos and calibration, the encoder, the gearboxes whose wear counts)
//! and its rules ([`RobotRules`]: observation, reward, falls, held joints,
//! start pose, commands between episodes, gearbox torque).
//!
//! | module | what |
//! |---|---|
//! | [`rules`] | the trait every robot's rules implement, and what a controller senses |
//! | [`hardware`] | joints, servos and their calibration, the encoder |
//! | [`registry`] | the robots pada brings, the one list of them |
//! | [`pendulum`] | the physical inverted pendulum of Section VII (33 or 20 Hz) |
//! | [`leo`] | the biped LEO walking on its boom (Section VIII) |
//! | [`filter`] | GRL's rate filter, used by LEO |
//! | `soft_limits.rs` | the soft-limit check of every reading, on the board and the host |
//!
//! A robot is identified by its name and the hash of its definition
//! ([`RobotSpec::definition_hash`]), never by a number from a closed list:
//! a robot of the user's own is a third [`RobotSpec`] and [`RobotRules`]
//! that live outside pada. The host's simulations produce the rules'
//! quantities from physics and the firmware from servo counts and encoder
//! readings; both build their learner from the same [`RobotSpec`] and a
//! board's learner profile ([`crate::profile`]), and
//! [`crate::profile::config_hash`] of the two agents is the same (a test
//! checks it).

pub mod filter;
pub mod hardware;
pub mod leo;
pub mod pendulum;
pub mod registry;
pub mod rules;
mod soft_limits;
pub mod vocabulary;

pub use hardware::{EncoderSpec, JointRange, JointSpec};
pub use rules::{PerServo, RobotRules, Sensed};
pub use vocabulary::{Vocab, Vocabulary};

use crate::action_space::{ActionDim, ActionSpace, MAX_ACTION_DIMS};
use crate::agent::{coder_for, exact_table_len, Agent, SarsaParams, WeightInit};
use crate::crc::ConfigHasher;
use crate::error::ConfigError;
use crate::policy::{Policy, PolicyKind};
use crate::tile_coding::{Layout, StateDim};
use crate::weights::WeightStore;

/// Longest robot name, in bytes: what the wire's `Hello` and the
/// software-in-the-loop link carry.
pub use crate::limits::MAX_ROBOT_NAME as MAX_NAME;

/// How the paper turns a commanded voltage into the gearbox torque of its
/// MTBF (Section IV: "a linear relationship between voltage and torque").
#[derive(Debug, Clone, Copy)]
pub enum TorqueLaw {
    /// The robot's own law, the same for each of its counted joints (the
    /// pendulum's K/R, LEO's RX-28 stall torque per volt).
    Rule(fn(f32) -> f32),
    /// Each counted joint's servo at stall: `η·G·k·U/R` of its motor model
    /// ([`crate::servo::DcMotor::stall_torque`]), the datasheet's stall
    /// torque per volt.
    ServoStall,
}

/// What kind of weight table a robot's learner needs; a board's profile
/// ([`crate::profile::Board::profile`]) sizes it to the board's memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TableNeed {
    /// One weight per (tiling, tile, action): this many for SARSA(λ) and
    /// every policy without state of its own (a test checks it against the
    /// tile coder).
    Exact {
        /// Weights of the exact table.
        weights: usize,
    },
    /// Too many tiles for an exact table: hashed features in a claim table
    /// as large as the board's memory allows.
    Claimed,
}

/// The levels of each learned motor: the same for every motor dimension,
/// or each its own.
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
    /// Each motor dimension's own values (in motor order), each list in
    /// increasing order: a strong shoulder and a weak wrist.
    PerMotor(&'static [&'static [f32]]),
}

/// Everything that defines one robot: its learning task and its hardware.
///
/// Two definitions are the same robot ([`PartialEq`]) when their names and
/// [`definition_hash`](Self::definition_hash)es are equal.
#[derive(Debug, Clone, Copy)]
pub struct RobotSpec {
    /// The robot's name as the command line, telemetry and the
    /// configuration hash spell it (at most [`MAX_NAME`] bytes).
    pub name: &'static str,
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
    /// The joints, in the robot's joint order: each one's servo, its ID
    /// and calibration and its soft limit.
    pub joints: &'static [JointSpec],
    /// The joints whose gearboxes' fatigue decides the robot's MTBF: the
    /// pendulum's one; LEO's two hips and two knees (Section VIII), the
    /// joints the learned actions drive as stance and swing roles trade
    /// legs. Each `Step` record reports their fatigue.
    pub counted: JointRange,
    /// The robot's encoder, if it has one.
    pub encoder: Option<EncoderSpec>,
    /// Supply voltage assumed until a servo reports it \[V\].
    pub supply_nominal_v: f32,
    /// The paper's law from a commanded voltage to a counted gearbox's
    /// torque (Section IV), the input of the paper's MTBF on the host and
    /// on the board alike.
    pub paper_torque: TorqueLaw,
    /// How the policy's memory (PADA's previous action, the low-pass
    /// filter's output, the integrated command) moves between the motor
    /// dimensions at a footstep, when the joints they drive trade roles
    /// ([`crate::agent::Agent::remap_memory`]); `None` for a robot without
    /// stance.
    pub footstep_remap: Option<[Option<u8>; MAX_ACTION_DIMS]>,
    /// The shift of 16-bit weights ([`crate::weights::WeightFormat::Half`])
    /// for this robot: its Q-values stay within ±2^(shift − 1).
    pub half_shift: u8,
    /// The kind of weight table its learner needs.
    pub table: TableNeed,
    /// Its rules said in the vocabulary of a `robot.toml` ([`Vocab`]
    /// applies them); `None` for a robot whose rules are code (the
    /// pendulum, LEO).
    pub vocabulary: Option<&'static Vocabulary>,
}

impl PartialEq for RobotSpec {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name && self.definition_hash() == other.definition_hash()
    }
}

impl Eq for RobotSpec {}

#[cfg(feature = "defmt")]
impl defmt::Format for RobotSpec {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=str}", self.name)
    }
}

impl RobotSpec {
    /// The robot's name.
    pub const fn name(&self) -> &'static str {
        self.name
    }

    /// Gearboxes whose fatigue is counted.
    pub const fn gearboxes(&self) -> usize {
        self.counted.len()
    }

    /// The hash of everything in the definition (FNV-1a): the name, the
    /// timing, the observation, the motor, the learning parameters, the
    /// joints with their servos, IDs, calibration and limits, the encoder,
    /// the counted gearboxes, the footstep remap, the weight shift and the
    /// table. It identifies a robot on the wire, in checkpoints and in
    /// recordings beside its name: a definition changed under the same
    /// name is another robot. (The rules are code; a change of them that
    /// changes no data is not seen here.)
    pub fn definition_hash(&self) -> u32 {
        let mut h = ConfigHasher::new();
        h.write_str(self.name).write_u32(self.period_us).write_u32(self.episode_steps).write_u32(self.test_interval);
        h.write_u32(self.state.len() as u32);
        for d in self.state {
            h.write_f32(d.min).write_f32(d.max).write_f32(d.tile_width).write_u32(d.wrap as u32);
        }
        h.write_u32(self.motor_dims as u32);
        match self.levels {
            MotorLevels::Listed(values) => {
                h.write_u32(1).write_u32(values.len() as u32);
                for v in values {
                    h.write_f32(*v);
                }
            }
            MotorLevels::Uniform { min, max, count } => {
                h.write_u32(2).write_f32(min).write_f32(max).write_u32(count as u32);
            }
            MotorLevels::PerMotor(dims) => {
                h.write_u32(3).write_u32(dims.len() as u32);
                for values in dims {
                    h.write_u32(values.len() as u32);
                    for v in *values {
                        h.write_f32(*v);
                    }
                }
            }
        }
        match self.action_tiles {
            None => h.write_u32(0),
            Some(widths) => {
                h.write_u32(widths.len() as u32 + 1);
                for w in widths {
                    h.write_f32(*w);
                }
                &mut h
            }
        };
        let p = &self.params;
        h.write_f32(p.alpha).write_f32(p.gamma).write_f32(p.lambda).write_f32(p.epsilon).write_f32(p.trace_threshold);
        h.write_u32(p.trace_kind.code());
        match p.init {
            WeightInit::Constant(v) => h.write_u32(1).write_f32(v),
            WeightInit::Uniform { min, max } => h.write_u32(2).write_f32(min).write_f32(max),
        };
        h.write_u32(self.joints.len() as u32);
        for j in self.joints {
            h.write_str(j.name).write_str(j.servo.name).write_u32(j.id as u32).write_u32(j.zero as u32);
            h.write_u32(j.sign as u32);
            match j.soft_limit {
                None => h.write_u32(0),
                Some(l) => h.write_u32(1).write_f32(l.min).write_f32(l.max),
            };
        }
        h.write_u32(self.counted.start as u32).write_u32(self.counted.end as u32);
        match self.encoder {
            None => h.write_u32(0),
            Some(e) => h.write_u32(1).write_u32(e.counts_per_rev).write_u32(e.sign as u32),
        };
        h.write_f32(self.supply_nominal_v);
        match self.footstep_remap {
            None => h.write_u32(0),
            Some(remap) => {
                h.write_u32(1);
                for r in remap {
                    h.write_u32(r.map_or(u32::MAX, |d| d as u32));
                }
                &mut h
            }
        };
        h.write_u32(self.half_shift as u32);
        match self.table {
            TableNeed::Exact { weights } => h.write_u32(1).write_u32(weights as u32),
            TableNeed::Claimed => h.write_u32(2),
        };
        match self.paper_torque {
            // The rule is code, named by the robot's name.
            TorqueLaw::Rule(_) => h.write_u32(1),
            TorqueLaw::ServoStall => h.write_u32(2),
        };
        if let Some(words) = self.vocabulary {
            words.hash_into(&mut h);
        }
        h.finish()
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
            MotorLevels::PerMotor(dims) => {
                if dims.len() != self.motor_dims as usize {
                    return Err(ConfigError::new("levels", dims.len() as f32, "one list of levels per motor dimension"));
                }
                let mut each: heapless::Vec<ActionDim, MAX_ACTION_DIMS> = heapless::Vec::new();
                for values in dims {
                    each.push(ActionDim::from_levels(values)?)
                        .map_err(|_| ConfigError::new("levels", dims.len() as f32, "at most 4 motor dimensions"))?;
                }
                return ActionSpace::new(&each);
            }
        };
        ActionSpace::repeated(dim, self.motor_dims as usize)
    }

    /// The paper's gearbox torque \[N·m\] of `voltage` on counted joint
    /// `counted` (the `counted`-th joint of [`counted`](Self::counted))
    /// ([`paper_torque`](Self::paper_torque)).
    pub fn paper_gear_torque(&self, counted: usize, voltage: f32) -> f32 {
        match self.paper_torque {
            TorqueLaw::Rule(law) => law(voltage),
            TorqueLaw::ServoStall => {
                let joint = self.joints.get(self.counted.start as usize + counted);
                joint.map_or(0.0, |j| j.servo.motor().stall_torque(voltage))
            }
        }
    }

    /// The gearbox of counted joint `counted` (Eqs. 3–7): its servo's
    /// ([`crate::servo::ServoModel::gearbox`]); Table I where the servo
    /// names none.
    pub fn gearbox(&self, counted: usize) -> crate::fatigue::GearboxParams {
        self.joints
            .get(self.counted.start as usize + counted)
            .and_then(|j| j.servo.gearbox().ok())
            .map_or(crate::fatigue::GearboxParams::TABLE_I, |g| g.params)
    }

    /// The gearbox of joint `joint` (any joint, counted or not).
    pub fn joint_gearbox(&self, joint: usize) -> crate::fatigue::GearboxParams {
        self.joints
            .get(joint)
            .and_then(|j| j.servo.gearbox().ok())
            .map_or(crate::fatigue::GearboxParams::TABLE_I, |g| g.params)
    }

    /// The counted gearbox one worst re-engagement damages most: the wear
    /// governor's reserve is taken for it.
    pub fn weakest_gearbox(&self) -> crate::fatigue::GearboxParams {
        let worst = self.worst_commanded_torque() as f64;
        let damage = |g: &crate::fatigue::GearboxParams| {
            crate::fatigue::FatigueModel::new(g).map_or(0.0, |m| m.damage(worst))
        };
        let mut weakest = self.gearbox(0);
        for c in 1..self.gearboxes() {
            let g = self.gearbox(c);
            if damage(&g) > damage(&weakest) {
                weakest = g;
            }
        }
        weakest
    }

    /// The largest gearbox torque one learning action can command \[N·m\]:
    /// the paper's torque law ([`RobotSpec::paper_torque`]) at the level of
    /// largest magnitude, on the counted joint where it is largest. Its
    /// re-engagement is the most damage one action can do (the wear
    /// governor's reserve, [`crate::governor`]).
    pub fn worst_commanded_torque(&self) -> f32 {
        let Ok(motor) = self.motor() else { return 0.0 };
        let mut worst = 0.0f32;
        for joint in 0..self.gearboxes() {
            for i in 0..motor.dims() {
                for &v in motor.dim(i).values() {
                    worst = worst.max(self.paper_gear_torque(joint, v).abs());
                }
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
    use crate::profile::TILINGS;

    #[test]
    fn every_spec_builds_its_motor_and_validates() {
        for spec in registry::specs() {
            let name = spec.name;
            assert!(spec.motor().is_ok(), "{name}");
            assert!(spec.params.validate().is_ok(), "{name}");
            assert!(name.len() <= MAX_NAME, "{name}");
            for (i, d) in spec.state.iter().enumerate() {
                assert!(d.validate().is_ok(), "{name} dimension {i}: {d:?}");
            }
            if let Some(w) = spec.action_tiles {
                assert_eq!(w.len(), spec.motor_dims as usize);
            }
            assert!(spec.counted.end as usize <= spec.joints.len(), "{name}");
            assert!(spec.joints.len() <= crate::limits::MAX_SERVOS, "{name}");
            assert!(spec.gearboxes() <= crate::limits::MAX_GEARBOXES, "{name}");
            if let TableNeed::Exact { weights } = spec.table {
                assert_eq!(spec.exact_table_len::<TILINGS>(PolicyKind::Sarsa), Ok(weights), "{name}");
            }
        }
        assert_eq!(leo::SPEC.motor().unwrap().joint_count(), 343);
        assert_eq!(leo::SPEC.state.len(), leo::OBS_DIM);
    }

    #[test]
    fn a_definition_is_its_name_and_hash() {
        let hashes: heapless::Vec<u32, 8> = registry::specs().map(|s| s.definition_hash()).collect();
        for (i, a) in hashes.iter().enumerate() {
            for b in &hashes[i + 1..] {
                assert_ne!(a, b);
            }
        }
        // Any changed field is another robot, even under the same name.
        let moved = RobotSpec { supply_nominal_v: 11.0, ..pendulum::SPEC_33HZ };
        assert_ne!(moved.definition_hash(), pendulum::SPEC_33HZ.definition_hash());
        assert_ne!(moved, pendulum::SPEC_33HZ);
        let renamed = RobotSpec { name: "my-pendulum", ..pendulum::SPEC_33HZ };
        assert_ne!(renamed, pendulum::SPEC_33HZ);
        assert_eq!(RobotSpec { ..pendulum::SPEC_33HZ }, pendulum::SPEC_33HZ);
    }
}
