//! A robot of files as a learning task of the experiment runner: the
//! body simulated in rapier, the robot's rules applied to what it senses.
//!
//! [`RulesPlant`] is generic over the rules ([`RobotRules`]): the same
//! code that the firmware runs on the chip turns the simulated joint angles
//! into observations, rewards and ends, and the learner's output into
//! every servo's voltage. The body only moves. Every reading is checked
//! against the joints' soft limits as the board's safety machine checks
//! it ([`Plant::fault`]).

use super::body::{UrdfBody, UrdfModel};
use crate::task::{Plant, Step, Task, TaskSpec};
use pada_core::action_space::Output;
use pada_core::limits::{MAX_ACTION_DIMS, MAX_SERVOS, MAX_STATE_DIMS};
use pada_core::profile::{Board, LearnerProfile};
use pada_core::robot::{PerServo, RobotRules, Sensed, Vocab};
use pada_core::safety::FaultCause;
use pada_robot_file::RobotFile;
use crate::variation::{PlantDraw, Sensor, Vary};
use rand_core::RngCore;

/// The body of a robot of files driven by the robot's rules `R`.
pub struct RulesPlant<R> {
    body: UrdfBody,
    rules: R,
    /// The voltages the last step applied.
    volts: PerServo,
    /// The soft-limit fault of the last reading, if any.
    fault: Option<FaultCause>,
    /// The joints' readings on a plant that is not its model (`None`: the
    /// simulated angles as they are).
    sensor: Option<Sensor>,
}

impl<R: RobotRules> RulesPlant<R> {
    /// `rules` driving `body`.
    pub fn new(body: UrdfBody, rules: R) -> Self {
        RulesPlant { body, rules, volts: [0.0; MAX_SERVOS], fault: None, sensor: None }
    }

    /// `rules` driving `body`, its joints read through `sensor` (play and
    /// noise).
    pub fn with_sensor(body: UrdfBody, rules: R, sensor: Option<Sensor>) -> Self {
        RulesPlant { sensor, ..RulesPlant::new(body, rules) }
    }

    /// The rules (for inspection).
    pub fn rules(&self) -> &R {
        &self.rules
    }

    /// The body (for inspection).
    pub fn body(&self) -> &UrdfBody {
        &self.body
    }

    fn sense(&mut self) {
        let q = self.body.angles();
        let n = self.rules.spec().joints.len().min(MAX_SERVOS);
        let mut angles = [None; MAX_SERVOS];
        for k in 0..n {
            angles[k] = Some(match self.sensor.as_mut() {
                Some(s) => s.read(k, q[k] as f64) as f32,
                None => q[k],
            });
        }
        // The board's safety machine sees every reading first.
        self.fault = self.rules.spec().soft_limit_fault(&angles[..n]);
        self.rules.sense(&Sensed { angles, encoder_angle: None, contacts: 0, applied: self.volts });
    }

    fn observe(&self, obs: &mut [f32]) {
        let mut all = [0.0; MAX_STATE_DIMS];
        let n = self.rules.observe(&mut all).min(obs.len());
        obs[..n].copy_from_slice(&all[..n]);
    }
}

impl<R: RobotRules + Send> Plant for RulesPlant<R> {
    /// The start pose, at rest (the operator's hands between episodes).
    fn reset(&mut self, _rng: &mut dyn RngCore, obs: &mut [f32]) {
        // The body was built from a model that resets (it did when built).
        let _ = self.body.reset();
        self.volts = [0.0; MAX_SERVOS];
        self.rules.start_episode();
        if let Some(s) = self.sensor.as_mut() {
            let q = self.body.angles();
            for (k, a) in q.iter().enumerate() {
                s.settle(k, *a as f64);
            }
        }
        self.sense();
        self.observe(obs);
    }

    fn step(&mut self, command: &[f32], obs: &mut [f32]) -> Step {
        let mut volts = [0.0; MAX_SERVOS];
        self.rules.commands(command, &mut volts);
        self.body.set_voltages(&volts);
        let blew_up = self.body.step_period().is_err();
        self.volts = volts;
        self.sense();
        if blew_up {
            // The simulation's failure, not the robot's: the board's rig
            // puts such a body back, and its servos never read NaN.
            self.fault = None;
        }
        self.observe(obs);
        Step {
            reward: self.rules.reward(&self.volts),
            // A body that blew up reads NaN angles, which end the episode
            // (an end's signal leaves its range) and are counted as such.
            terminal: self.rules.absorbing() || blew_up,
        }
    }

    /// A joint past its soft limit at the last reading.
    fn fault(&self) -> Option<FaultCause> {
        self.fault
    }

    /// The simulation's torque on each counted gearbox over the step.
    fn gearbox_torques(&self, _command: &[f32]) -> Output {
        let spec = self.rules.spec();
        let t = self.body.gear_torques();
        let mut out: Output = [0.0; MAX_ACTION_DIMS];
        for (o, j) in out.iter_mut().zip(spec.counted.range()) {
            *o = t[j];
        }
        out
    }

    /// The paper's: each counted joint's servo at stall under the voltage
    /// applied.
    fn commanded_torques(&self, _command: &[f32]) -> Output {
        let spec = self.rules.spec();
        let mut out: Output = [0.0; MAX_ACTION_DIMS];
        for (c, (o, j)) in out.iter_mut().zip(spec.counted.range()).enumerate() {
            *o = spec.paper_gear_torque(c, self.volts[j]);
        }
        out
    }
}

/// A robot of files as a task of the experiment runner.
#[derive(Clone)]
pub struct UrdfTask {
    spec: TaskSpec,
    model: UrdfModel,
    robot: &'static pada_core::robot::RobotSpec,
}

impl UrdfTask {
    /// The task of `robot` with the host's learner.
    pub fn new(robot: &RobotFile) -> anyhow::Result<UrdfTask> {
        let profile = Board::Host.profile(robot.spec).map_err(|e| anyhow::anyhow!("{}: {e}", robot.path.display()))?;
        Self::with_profile(robot, profile)
    }

    /// The task of `robot` with `profile`'s table.
    pub fn with_profile(robot: &RobotFile, profile: LearnerProfile) -> anyhow::Result<UrdfTask> {
        Ok(Self::of_model(&UrdfModel::load(robot)?, profile))
    }

    /// The same from its body as read.
    pub fn of_model(model: &UrdfModel, profile: LearnerProfile) -> UrdfTask {
        let robot = model.spec();
        let title: &'static str = Box::leak(format!("{}, simulated in rapier3d from its URDF", robot.name).into_boxed_str());
        let mut spec = TaskSpec::of_robot(profile, title, "each counted joint's servo at stall, linear in the commanded voltage");
        spec.default_seconds = 600.0;
        spec.default_trials = 10;
        UrdfTask { spec, model: model.clone(), robot }
    }
}

impl Task for UrdfTask {
    type Plant = RulesPlant<Vocab>;

    fn spec(&self) -> &TaskSpec {
        &self.spec
    }

    fn plant(&self) -> RulesPlant<Vocab> {
        // The model and the rules were both checked when the task was made.
        let body = UrdfBody::new(&self.model).unwrap_or_else(|e| unreachable!("the body built at load: {e}"));
        let rules = Vocab::new(self.robot).unwrap_or_else(|e| unreachable!("checked at load: {e}"));
        RulesPlant::new(body, rules)
    }
}

impl Vary for UrdfTask {
    fn plant_with(&self, draw: &PlantDraw, seed: u64) -> RulesPlant<Vocab> {
        // The model's body built at load; its masses scaled stay positive.
        let body = UrdfBody::new(&self.model.varied(draw)).unwrap_or_else(|e| unreachable!("the body built at load: {e}"));
        let rules = Vocab::new(self.robot).unwrap_or_else(|e| unreachable!("checked at load: {e}"));
        RulesPlant::with_sensor(body, rules, Sensor::of(draw, seed))
    }
}
