//! One control period, [`Controller::period`], in its six steps (the
//! module documentation of [`crate::control`]): readings into the safety
//! machine, the episode cycle, the observation, the agent's step, voltages
//! into Moving Speeds of the measured supply, gearbox torques into the
//! fatigue counter; with the period's readings and output and the fault
//! thresholds.

use super::{Controller, Phase};
use crate::bus::{BusConfig, ServoRead};
use crate::config::MAX_ROBOT_SERVOS;
use crate::io::CycleCounter;
use pada_core::robot::{RobotRules, Sensed};
use heapless::Vec;
use pada_core::servo::Drive;
use pada_core::safety::{Event, RunMode, Safety, SafetyConfig, Transition};
use pada_core::episodes::{is_learning_action, wear};
use pada_core::weights::WeightStore;
use pada_core::wire;

/// Everything the control loop read in one period.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Readings {
    /// Per servo, in the robot's joint order.
    pub servos: [ServoRead; MAX_ROBOT_SERVOS],
    /// The encoder's counter, if it could be read.
    pub encoder: Option<u16>,
    /// Foot switches (the robot's own bits, e.g. `pada_core::robot::leo::contact`).
    pub contacts: u8,
    /// Time since boot \[ms\].
    pub time_ms: u32,
    /// Whether the previous period's work overran its period.
    pub last_period_overran: bool,
}

/// What the control loop applies and reports after one period.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PeriodOutput {
    /// Torque Enable for every servo.
    pub torque: bool,
    /// The command of each servo (ID, Moving Speed or Goal PWM); all zero
    /// while torque is off.
    pub commands: Vec<(u8, Drive), MAX_ROBOT_SERVOS>,
    /// The agent's step, if one was taken (`loop_us` is the caller's to
    /// fill in).
    pub step: Option<wire::Step>,
    /// The episode that ended.
    pub episode: Option<wire::Episode>,
    /// Safety state changes of this period, in order.
    pub transitions: Vec<Transition, 8>,
    /// Cycles of the agent call, if there was one.
    pub agent_cycles: Option<u32>,
    /// The gearbox torque of each servo the fatigue counter saw this
    /// period \[N·m\] (the robot's estimate; 0 with torque off).
    pub torques: [f32; MAX_ROBOT_SERVOS],
    /// A `Policy` report to send: the wear governor moved Δ or α this
    /// period, or an episode ended while it runs.
    pub policy: Option<wire::PolicyReport>,
}

/// The fault thresholds: a request that fails every attempt of its period
/// is a fault in that period, so torque goes off within one control period
/// of a servo falling silent or its answers arriving damaged:
/// [`BusConfig::attempts`] timeouts in a row (the retry budget is one less)
/// or as many checksum errors within a second. The cause tells which
/// (servo-timeout or checksum-errors); a damaged answer counts as both, and
/// checksum errors are seen first.
pub fn safety_config(soft_limits: Vec<pada_core::safety::SoftLimit, { pada_core::safety::MAX_SOFT_LIMITS }>) -> SafetyConfig {
    let attempts = BusConfig::default().attempts.max(1);
    SafetyConfig {
        soft_limits,
        servo_retry_budget: attempts - 1,
        checksum_threshold: attempts,
        checksum_window_ms: 1000,
        ..SafetyConfig::default()
    }
}

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// One control period (see the module documentation). `cycles` times
    /// the agent call.
    pub fn period(&mut self, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        out.step = None;
        out.episode = None;
        out.transitions.clear();
        out.commands.clear();
        out.agent_cycles = None;
        out.torques = [0.0; MAX_ROBOT_SERVOS];
        out.policy = None;
        self.steps = self.steps.wrapping_add(1);
        self.periods = self.periods.saturating_add(1);
        let now = readings.time_ms;
        let joints = self.spec.joints;
        let n = joints.len();

        // 1. Safety sees everything that was read.
        fn feed(safety: &mut Safety, out: &mut Vec<Transition, 8>, event: Event) {
            let t = safety.on(event);
            if t.changed() {
                let _ = out.push(t);
            }
        }
        let overrun = Event::LoopTiming { overrun: readings.last_period_overran };
        feed(&mut self.safety, &mut out.transitions, overrun);
        let mut angles = [None; MAX_ROBOT_SERVOS];
        for (i, (joint, read)) in joints.iter().zip(&readings.servos).enumerate() {
            for _ in 0..read.checksum_errors {
                feed(&mut self.safety, &mut out.transitions, Event::ChecksumError { at_ms: now });
            }
            for _ in 0..read.timeouts {
                feed(&mut self.safety, &mut out.transitions, Event::ServoTimeout { servo: joint.id });
            }
            if let Some(error) = read.hardware_error {
                feed(&mut self.safety, &mut out.transitions, Event::HardwareAlert { servo: joint.id, error });
            }
            if let Some(state) = read.state {
                let status = Event::ServoStatus { servo: joint.id, error: read.error, at_ms: now };
                feed(&mut self.safety, &mut out.transitions, status);
                self.supply[i] = Some(state.voltage_v());
                self.temps[i] = state.temperature;
                let angle = joint.angle_of(state.position);
                angles[i] = Some(angle);
                if joint.soft_limit.is_some() {
                    let position = Event::JointPosition { joint: i as u8, position: angle };
                    feed(&mut self.safety, &mut out.transitions, position);
                }
            }
        }

        // 2. Where the episode cycle goes this period. The reset's end is
        // judged on the last period's observation, so that an episode's
        // first observation is taken after the observer was restarted.
        let torque = self.safety.torque_enabled();
        let state = self.safety.state();
        let mut starting = false;
        if !torque {
            self.phase = Phase::Stopped;
        } else {
            if state != self.last_state {
                // Just started, resumed or switched mode: the robot is
                // wherever it is; bring it to its start first.
                self.begin_reset();
            } else if self.phase == Phase::Resetting && self.robot.reset_done() {
                starting = true;
                self.robot.start_episode();
            }
        }
        self.last_state = state;

        // 3. Observe.
        let encoder_angle = match (self.spec.encoder, readings.encoder) {
            (Some(encoder), Some(count)) => Some(encoder.angle(self.encoder.update(count))),
            _ => None,
        };
        self.robot.sense(&Sensed { angles, encoder_angle, contacts: readings.contacts, applied: self.applied });

        // 4. The agent's step, and the voltages.
        let mut volts = [0.0f32; MAX_ROBOT_SERVOS];
        if torque {
            let mode = state.run_mode().unwrap_or(RunMode::Learning);
            if starting {
                self.start_episode(mode, readings, cycles, out);
            } else if self.phase == Phase::Running {
                self.continue_episode(readings, cycles, out);
            }
            match self.phase {
                Phase::Running => {
                    let dims = self.spec.motor_dims as usize;
                    self.robot.commands(&self.last_output[..dims], &mut volts)
                }
                _ => self.robot.reset_commands(&mut volts),
            }
        }

        // 5. Voltages → each servo's command (Moving Speed, Goal PWM) as
        // a fraction of its measured supply.
        let nominal = self.spec.supply_nominal_v;
        for (i, joint) in joints.iter().enumerate() {
            let v = if torque { volts[i] } else { 0.0 };
            let supply = self.supply[i].filter(|s| *s >= 5.0).unwrap_or(nominal);
            let drive = joint.drive(v, self.supply[i], nominal);
            self.applied[i] = joint.voltage_of_drive(drive, supply);
            let _ = out.commands.push((joint.id, drive));
        }

        // 6. Fatigue from the estimated gearbox torque (servos past the
        // robot's count stay at 0); the governor sees a learning action's.
        if torque {
            let mut torques = [0.0f32; MAX_ROBOT_SERVOS];
            self.robot.gear_torques(&self.applied, &mut torques);
            torques[n..].fill(0.0);
            let before = wear::damage_raws(&self.fatigue);
            let _ = self.fatigue.update(&torques);
            out.torques = torques;
            let learning_action = out.step.as_ref().is_some_and(|s| is_learning_action(s.mode, s.kind));
            if learning_action {
                self.govern(&before, out);
            }
        }
        if out.episode.is_some() && self.governor.is_some() {
            out.policy = Some(self.policy_report());
        }
        out.torque = torque;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use core::cell::Cell;
    use pada_core::policy::PolicyKind;
    use pada_core::safety::{FaultCause, State};
    use pada_core::dynamixel::ErrorFlags;
    use pada_core::wire::NackReason;

    #[test]
    fn idle_means_torque_off_and_zero_speed() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 1).unwrap();
        let mut out = PeriodOutput::default();
        c.period(&pendulum_readings(0, 0), &Clock(Cell::new(0)), &mut out);
        assert!(!out.torque);
        assert_eq!(out.commands.as_slice(), &[(1, Drive::MovingSpeed(0))]);
        assert!(out.step.is_none());
    }

    #[test]
    fn a_silent_servo_faults_and_torque_goes_off_in_the_same_period() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        c.period(&pendulum_readings(0, 0), &clock, &mut out);
        assert!(out.torque);
        // One attempt of two lost: the retry answered, no fault.
        let mut r = pendulum_readings(0, 30);
        r.servos[0].timeouts = 1;
        c.period(&r, &clock, &mut out);
        assert!(out.torque);
        // Both attempts of a period time out: a fault in that period.
        r.servos[0] = ServoRead { state: None, timeouts: 2, ..ServoRead::default() };
        c.period(&r, &clock, &mut out);
        assert!(!out.torque, "torque off in the period the fault is found");
        assert_eq!(out.commands.as_slice(), &[(1, Drive::MovingSpeed(0))]);
        let t = out.transitions.iter().find_map(|t| t.entered_fault()).unwrap();
        assert_eq!(t, FaultCause::ServoTimeout { servo: 1, attempts: 2 });
        // Start is refused until the host clears the fault.
        let (result, _) = c.command(&wire::ToChip::Start(RunMode::Learning));
        assert_eq!(result, Err(NackReason::State(pada_core::safety::Rejection::InFault)));
        assert_eq!(c.command(&wire::ToChip::ClearFault).0, Ok(()));
        start(&mut c, RunMode::Learning);
    }

    #[test]
    fn damaged_answers_fault_as_checksum_errors_in_the_period() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        // Both answers of the period damaged (each also counts as a timeout).
        let mut r = pendulum_readings(0, 30);
        r.servos[0] = ServoRead { state: None, timeouts: 2, checksum_errors: 2, ..ServoRead::default() };
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        let t = out.transitions.iter().find_map(|t| t.entered_fault()).unwrap();
        assert_eq!(t, FaultCause::ChecksumErrors { count: 2, window_ms: 1000 });
    }

    #[test]
    fn servo_error_bits_and_overrun_streaks_fault() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut r = pendulum_readings(0, 0);
        r.servos[0].error = ErrorFlags::OVERHEATING;
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        assert!(matches!(c.state(), State::Fault(FaultCause::ServoError { servo: 1, .. })));

        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let mut r = pendulum_readings(0, 0);
        r.last_period_overran = true;
        for _ in 0..2 {
            c.period(&r, &clock, &mut out);
            assert!(out.torque);
        }
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        assert!(matches!(c.state(), State::Fault(FaultCause::OverrunStreak { count: 3 })));
    }

    #[test]
    fn leo_soft_limit_faults() {
        let mut c = Controller::new(Leo::new(), profile(&leo::SPEC), PolicyKind::Sarsa, leo_table(), 1).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut r = Readings { encoder: Some(0), contacts: leo::contact::LEFT, ..Readings::default() };
        for s in r.servos.iter_mut() {
            s.state = Some(pada_core::dynamixel::table::PresentState { position: 512, speed: 0, load: 0, voltage: 140, temperature: 30 }.into());
        }
        c.period(&r, &clock, &mut out);
        assert!(out.torque);
        assert_eq!(out.commands.len(), 7);
        // Right knee bent forward by 40 counts ≈ +0.2 rad: beyond +2° + margin.
        let knee_r = pada_core::robot::leo::Joint::KneeRight as usize;
        r.servos[knee_r].state.as_mut().unwrap().position = 512 + 40;
        c.period(&r, &clock, &mut out);
        assert!(!out.torque);
        assert!(matches!(c.state(), State::Fault(FaultCause::SoftLimit { joint: 4, .. })));
    }
}
