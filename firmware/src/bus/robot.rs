//! One robot's period on the bus: every joint read and commanded in the
//! protocol its servo speaks (`JointSpec::servo.protocol`), the sensor
//! device, the operator's call, and the boot (torque off, set-up).
//!
//! Per period, with the robot's joints grouped by protocol:
//!
//! | | Protocol 1.0 (RX-28, MX-28) | Protocol 2.0 (X series) |
//! |---|---|---|
//! | read | one READ of the present block per servo | one FAST SYNC READ (or SYNC READ) of every servo's present block; a Hardware Error Status READ after an alert |
//! | write, torque on | SYNC_WRITE of Moving Speed, then Torque Enable 1 (broadcast) | Torque Enable 1 (broadcast), SYNC WRITE of Goal PWM; the Bus Watchdog cleared and armed first at every torque-on and after an overrun |
//! | write, torque off | Torque Enable 0, Moving Speed 0 (broadcast) | Torque Enable 0 (broadcast), SYNC WRITE of Goal PWM 0 |
//!
//! Everything is sent every period, so a servo that missed a packet (or
//! browned out) gets it again one period later. A robot of Protocol 1.0
//! servos only sends exactly what the firmware sent before Protocol 2.0
//! came (the software-in-the-loop runs replay it bit for bit).
//!
//! A joint whose servo failed its set-up (no answer, another model than
//! the definition names, an alert) is never commanded and reads as
//! silent, so the safety machine faults on it and torque stays off.
//!
//! An X-series servo that raised its Alert bit keeps its torque off until
//! a REBOOT (docs/reference/dynamixel.md, "Shutdown"). The safety machine faults on the alert;
//! when the operator clears that fault, each servo that alerted is
//! rebooted and set up again ([`RobotBus::reboot_alerted`]). If its cause
//! persists, it alerts again and the robot faults again.

use super::v2::{fast_read_firmware, flags_of, watchdog_units, Read2};
use super::{BusConfig, BusStats, ServoBus, ServoRead, ServoSetup, SetupError};
use crate::config::MAX_ROBOT_SERVOS;
use crate::io::BusPort;
use crate::sensor_device::{parse_sensor_read, sensor_table, SENSOR_ID};
use heapless::Vec;
use pada_core::dynamixel::control_table::x_series::HardwareError;
use pada_core::robot::{JointSpec, RobotSpec};
use pada_core::servo::{Drive, ServoProtocol};

/// What the controller tells whoever brings the robot back to its start,
/// written to the sensor device's [`sensor_table::OPERATOR`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum OperatorCall {
    /// An episode ended: put the robot back at its start and hold it.
    EpisodeEnded = 1,
    /// An episode started: let go.
    EpisodeStarted = 2,
}

/// The set-up of every joint's servo, in joint order: its ID and what came
/// of it.
pub type SetupReport = Vec<(u8, Result<ServoSetup, SetupError>), MAX_ROBOT_SERVOS>;

/// One robot's bus.
pub struct RobotBus<P> {
    bus: ServoBus<P>,
    joints: &'static [JointSpec],
    /// Joints whose servo failed its set-up: never commanded, read as
    /// silent.
    refused: [bool; MAX_ROBOT_SERVOS],
    /// Whether every Protocol 2.0 servo answers FAST SYNC READ.
    fast: bool,
    /// The Bus Watchdog value (20 ms units) for the robot's period.
    watchdog: u8,
    /// Torque as last written.
    torque_was: bool,
    /// Joints whose Protocol 2.0 servo raised its Alert bit since it was
    /// last set up: rebooted when a fault is cleared.
    alerted: [bool; MAX_ROBOT_SERVOS],
}

impl<P: BusPort> RobotBus<P> {
    /// The bus of `robot` on `port`.
    pub fn new(port: P, config: BusConfig, robot: &'static RobotSpec) -> Self {
        RobotBus {
            bus: ServoBus::new(port, config),
            joints: robot.joints,
            refused: [false; MAX_ROBOT_SERVOS],
            fast: true,
            watchdog: watchdog_units(robot.period_us),
            torque_was: false,
            alerted: [false; MAX_ROBOT_SERVOS],
        }
    }

    /// Counters since start.
    pub fn stats(&self) -> BusStats {
        self.bus.stats()
    }

    /// The bus underneath (the board's own checks, a scan).
    pub fn bus_mut(&mut self) -> &mut ServoBus<P> {
        &mut self.bus
    }

    /// The Bus Watchdog value armed on Protocol 2.0 servos \[20 ms\].
    pub fn watchdog_units(&self) -> u8 {
        self.watchdog
    }

    /// Whether the Protocol 2.0 servos are read with FAST SYNC READ.
    pub fn fast_reads(&self) -> bool {
        self.fast
    }

    fn speaks(&self, protocol: ServoProtocol) -> bool {
        self.joints.iter().any(|j| j.servo.protocol == protocol)
    }

    /// The protocol of the robot's first servo: the sensor device's.
    fn sensor_protocol(&self) -> ServoProtocol {
        self.joints.first().map_or(ServoProtocol::V1, |j| j.servo.protocol)
    }

    /// Torque off and a zero command on every servo at once, in each
    /// protocol the robot's servos speak (at boot, whatever the servos did
    /// before; and on the way out).
    pub async fn stop_all(&mut self) {
        if self.speaks(ServoProtocol::V1) {
            self.bus.torque_all(false).await.ok();
            self.bus.stop_all().await.ok();
        }
        if self.speaks(ServoProtocol::V2) {
            self.bus.torque_all2(false).await.ok();
            self.bus.stop_all2().await.ok();
        }
        self.torque_was = false;
    }

    /// Sets up every joint's servo (torque must be off:
    /// [`stop_all`](Self::stop_all)) and checks its model against the
    /// definition; a servo that fails is refused from now on.
    pub async fn setup(&mut self) -> SetupReport {
        let mut report = SetupReport::new();
        self.fast = true;
        for (i, joint) in self.joints.iter().enumerate() {
            let expected = joint.servo.model_number;
            let result = match joint.servo.protocol {
                ServoProtocol::V1 => match self.bus.setup(joint.id).await {
                    Ok(s) if s.model != expected => Err(SetupError::WrongModel { id: joint.id, found: s.model, expected }),
                    other => other,
                },
                ServoProtocol::V2 => {
                    let r = self.bus.setup2(joint.id, expected, self.watchdog).await;
                    if let Ok(s) = r {
                        self.fast &= s.firmware >= fast_read_firmware(s.model);
                    }
                    r
                }
                // This bus does not speak Feetech's instructions: such a
                // servo is refused (read as silent, so the safety machine
                // faults on it) rather than driven blind.
                ServoProtocol::Feetech => Err(SetupError::NoAnswer { id: joint.id }),
            };
            if let Some(r) = self.refused.get_mut(i) {
                *r = result.is_err();
            }
            // An alert found at set-up: rebooted when that fault is cleared.
            if let Some(a) = self.alerted.get_mut(i) {
                *a = matches!(result, Err(SetupError::Alert { .. }));
            }
            let _ = report.push((joint.id, result));
        }
        report
    }

    /// Every joint's present state, in joint order, into `out`.
    pub async fn read(&mut self, out: &mut [ServoRead; MAX_ROBOT_SERVOS]) {
        let attempts = self.bus.config().attempts.max(1);
        let mut ids2: Vec<u8, MAX_ROBOT_SERVOS> = Vec::new();
        let mut at2: Vec<usize, MAX_ROBOT_SERVOS> = Vec::new();
        for (i, (joint, read)) in self.joints.iter().zip(out.iter_mut()).enumerate() {
            if self.refused[i] {
                *read = ServoRead { timeouts: attempts, ..ServoRead::default() };
                continue;
            }
            match joint.servo.protocol {
                ServoProtocol::V1 => {
                    let (state, exchange) = self.bus.read_present(joint.id).await;
                    *read = ServoRead {
                        state: state.map(Into::into),
                        error: exchange.error(),
                        hardware_error: None,
                        timeouts: exchange.timeouts,
                        checksum_errors: exchange.checksum_errors,
                    };
                }
                ServoProtocol::V2 => {
                    let _ = ids2.push(joint.id);
                    let _ = at2.push(i);
                }
                // Refused at set-up (see `setup`).
                ServoProtocol::Feetech => *read = ServoRead { timeouts: attempts, ..ServoRead::default() },
            }
        }
        if ids2.is_empty() {
            return;
        }
        let mut reads = [Read2::default(); MAX_ROBOT_SERVOS];
        self.bus.read_present2(&ids2, self.fast, &mut reads).await;
        for ((&i, &id), r) in at2.iter().zip(&ids2).zip(&reads) {
            // The Alert bit: which hardware error (one more READ, only
            // then).
            let hardware_error = match (r.state, r.error.alert()) {
                (Some(_), true) => Some(self.bus.hardware_error(id).await.unwrap_or(HardwareError(0))),
                _ => None,
            };
            if hardware_error.is_some() {
                self.alerted[i] = true;
            }
            out[i] = ServoRead {
                state: r.state.map(Into::into),
                error: flags_of(r.error),
                hardware_error,
                timeouts: r.timeouts,
                checksum_errors: r.checksum_errors,
            };
        }
    }

    /// Applies `torque` and each joint's command (`commands`: ID and
    /// command, as the controller gives them). `rearm` clears and arms the
    /// Protocol 2.0 servos' Bus Watchdog before torque goes on (after an
    /// overrun, which may have tripped it: a tripped servo takes no goal).
    pub async fn write(&mut self, torque: bool, commands: &[(u8, Drive)], rearm: bool) {
        let allowed = |id: u8, joints: &[JointSpec], refused: &[bool; MAX_ROBOT_SERVOS]| {
            joints.iter().position(|j| j.id == id).is_some_and(|i| !refused[i])
        };
        if self.speaks(ServoProtocol::V1) {
            if torque {
                let mut speeds: Vec<(u8, u16), MAX_ROBOT_SERVOS> = Vec::new();
                for &(id, drive) in commands {
                    if let (Drive::MovingSpeed(v), true) = (drive, allowed(id, self.joints, &self.refused)) {
                        let _ = speeds.push((id, v));
                    }
                }
                self.bus.write_speeds(&speeds).await.ok();
                self.bus.torque_all(true).await.ok();
            } else {
                self.bus.torque_all(false).await.ok();
                self.bus.stop_all().await.ok();
            }
        }
        if self.speaks(ServoProtocol::V2) {
            if torque && (!self.torque_was || rearm) {
                self.bus.arm_watchdog2(self.watchdog).await.ok();
            }
            self.bus.torque_all2(torque).await.ok();
            let mut pwms: Vec<(u8, i16), MAX_ROBOT_SERVOS> = Vec::new();
            for &(id, drive) in commands {
                if let (Drive::GoalPwm { pwm, .. }, true) = (drive, allowed(id, self.joints, &self.refused)) {
                    let _ = pwms.push((id, if torque { pwm } else { 0 }));
                }
            }
            self.bus.sync_write_pwm(&pwms).await.ok();
        }
        self.torque_was = torque;
    }

    /// Reboots every Protocol 2.0 servo that alerted (since its set-up, or
    /// at it) and sets it up again; torque must be off (it is, in a fault,
    /// and a REBOOT leaves it off). Returns each rebooted servo's ID and
    /// whether it came back; one that did not is refused (never commanded,
    /// read as silent: the safety machine faults on it) and is rebooted
    /// again at the next call.
    pub async fn reboot_alerted(&mut self) -> Vec<(u8, bool), MAX_ROBOT_SERVOS> {
        let mut rebooted = Vec::new();
        for (i, joint) in self.joints.iter().enumerate() {
            if !self.alerted[i] || joint.servo.protocol != ServoProtocol::V2 {
                continue;
            }
            self.bus.reboot2(joint.id).await.ok();
            let back = self.bus.setup2(joint.id, joint.servo.model_number, self.watchdog).await.is_ok();
            self.alerted[i] = !back;
            self.refused[i] = !back;
            let _ = rebooted.push((joint.id, back));
        }
        rebooted
    }

    /// The sensor device's encoder count and foot contacts, in the
    /// protocol of the robot's servos; `None` if it did not answer.
    pub async fn sensors(&mut self) -> Option<(u16, u8)> {
        match self.sensor_protocol() {
            // A Feetech READ or WRITE is Protocol 1.0's packet to the byte.
            ServoProtocol::V1 | ServoProtocol::Feetech => {
                let e = self.bus.read(SENSOR_ID, sensor_table::ENCODER_COUNT, sensor_table::READ_LEN).await;
                e.status.as_ref().and_then(|s| parse_sensor_read(&s.params))
            }
            ServoProtocol::V2 => {
                let e = self.bus.read2(SENSOR_ID, sensor_table::ENCODER_COUNT as u16, sensor_table::READ_LEN as u16).await;
                e.status.as_ref().and_then(|s| parse_sensor_read(&s.params))
            }
        }
    }

    /// Tells the operator (the sensor device's OPERATOR register, no
    /// reply).
    pub async fn call_operator(&mut self, call: OperatorCall) {
        let data = [call as u8];
        match self.sensor_protocol() {
            // A Feetech READ or WRITE is Protocol 1.0's packet to the byte.
            ServoProtocol::V1 | ServoProtocol::Feetech => {
                self.bus.write_no_reply(SENSOR_ID, sensor_table::OPERATOR, &data).await.ok();
            }
            ServoProtocol::V2 => {
                self.bus.write2(SENSOR_ID, sensor_table::OPERATOR as u16, &data, false).await.ok();
            }
        }
    }
}
