//! One robot's period on the bus: every joint read and commanded in the
//! protocol its servo speaks (`JointSpec::servo.protocol`), the sensor
//! device, the operator's call, and the boot (torque off, set-up).
//!
//! Per period, with the robot's joints grouped by protocol:
//!
//! | | Protocol 1.0 (RX-28, MX-28) | Protocol 2.0 (X series) | Feetech (STS3215) |
//! |---|---|---|---|
//! | read | one READ of the present block per servo | one FAST SYNC READ (or SYNC READ) of every servo's present block; a Hardware Error Status READ after an alert | one SYNC READ of every servo's present block |
//! | write, torque on | SYNC_WRITE of Moving Speed, then Torque Enable 1 (broadcast) | Torque Enable 1 (broadcast), SYNC WRITE of Goal PWM; the Bus Watchdog cleared and armed first at every torque-on and after an overrun | one SYNC WRITE of Torque Enable 1 and Goal Time (the duty cycle, Operating Mode 2) |
//! | write, torque off | Torque Enable 0, Moving Speed 0 (broadcast) | Torque Enable 0 (broadcast), SYNC WRITE of Goal PWM 0 | one SYNC WRITE of Torque Enable 0 and Goal Time 0 |
//!
//! Each protocol's part is an implementation of one interface
//! ([`super::parts::ProtocolPart`]).
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

use super::parts::{FtPart, Joints, ProtocolPart, V1Part, V2Part};
use super::{BusConfig, BusStats, ServoBus, ServoRead, ServoSetup, SetupError};
use crate::config::MAX_ROBOT_SERVOS;
use crate::io::BusPort;
use crate::sensor_device::{parse_sensor_read, sensor_table, SENSOR_ID};
use heapless::Vec;
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
    /// Each protocol's part, in the order they are called.
    v1: V1Part,
    v2: V2Part,
    ft: FtPart,
}

impl<P: BusPort> RobotBus<P> {
    /// The bus of `robot` on `port`.
    pub fn new(port: P, config: BusConfig, robot: &'static RobotSpec) -> Self {
        RobotBus {
            bus: ServoBus::new(port, config),
            joints: robot.joints,
            refused: [false; MAX_ROBOT_SERVOS],
            v1: V1Part,
            v2: V2Part::new(robot.period_us),
            ft: FtPart::default(),
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
        self.v2.watchdog
    }

    /// Whether the Protocol 2.0 servos are read with FAST SYNC READ.
    pub fn fast_reads(&self) -> bool {
        self.v2.fast
    }

    /// Whether any of the robot's servos speaks `protocol`.
    fn speaks(&self, protocol: ServoProtocol) -> bool {
        self.joints.iter().any(|j| j.servo.protocol == protocol)
    }

    /// The joints whose servo speaks `protocol` and passed its set-up.
    fn usable(&self, protocol: ServoProtocol) -> Joints {
        let mut at = Joints::new();
        for (i, j) in self.joints.iter().enumerate() {
            if j.servo.protocol == protocol && !self.refused[i] {
                let _ = at.push(i);
            }
        }
        at
    }

    /// The protocol of the robot's first servo: the sensor device's.
    fn sensor_protocol(&self) -> ServoProtocol {
        self.joints.first().map_or(ServoProtocol::V1, |j| j.servo.protocol)
    }

    /// Torque off and a zero command on every servo at once, in each
    /// protocol the robot's servos speak (at boot, whatever the servos did
    /// before; and on the way out).
    pub async fn stop_all(&mut self) {
        if self.speaks(V1Part::PROTOCOL) {
            self.v1.stop_all(&mut self.bus).await;
        }
        if self.speaks(V2Part::PROTOCOL) {
            self.v2.stop_all(&mut self.bus).await;
        }
        if self.speaks(FtPart::PROTOCOL) {
            self.ft.stop_all(&mut self.bus).await;
        }
    }

    /// Sets up every joint's servo (torque must be off:
    /// [`stop_all`](Self::stop_all)) and checks its model against the
    /// definition; a servo that fails is refused from now on.
    pub async fn setup(&mut self) -> SetupReport {
        let mut report = SetupReport::new();
        self.v2.fast = true;
        for (i, joint) in self.joints.iter().enumerate() {
            let result = match joint.servo.protocol {
                ServoProtocol::V1 => self.v1.setup(&mut self.bus, i, joint).await,
                ServoProtocol::V2 => self.v2.setup(&mut self.bus, i, joint).await,
                ServoProtocol::Feetech => self.ft.setup(&mut self.bus, i, joint).await,
            };
            if let Some(r) = self.refused.get_mut(i) {
                *r = result.is_err();
            }
            let _ = report.push((joint.id, result));
        }
        report
    }

    /// Every joint's present state, in joint order, into `out`.
    pub async fn read(&mut self, out: &mut [ServoRead; MAX_ROBOT_SERVOS]) {
        let attempts = self.bus.config().attempts.max(1);
        for (read, _) in out.iter_mut().zip(self.refused).filter(|(_, refused)| *refused) {
            *read = ServoRead { timeouts: attempts, ..ServoRead::default() };
        }
        let at = self.usable(V1Part::PROTOCOL);
        if !at.is_empty() {
            self.v1.read(&mut self.bus, self.joints, &at, out).await;
        }
        let at = self.usable(V2Part::PROTOCOL);
        if !at.is_empty() {
            self.v2.read(&mut self.bus, self.joints, &at, out).await;
        }
        let at = self.usable(FtPart::PROTOCOL);
        if !at.is_empty() {
            self.ft.read(&mut self.bus, self.joints, &at, out).await;
        }
    }

    /// Applies `torque` and each joint's command (`commands`: ID and
    /// command, as the controller gives them). `rearm` clears and arms the
    /// Protocol 2.0 servos' Bus Watchdog before torque goes on (after an
    /// overrun, which may have tripped it: a tripped servo takes no goal).
    pub async fn write(&mut self, torque: bool, commands: &[(u8, Drive)], rearm: bool) {
        // Each protocol's allowed joints' commands, as joint index and
        // command, in the controller's order.
        let of = |protocol: ServoProtocol| {
            let mut own: Vec<(usize, Drive), MAX_ROBOT_SERVOS> = Vec::new();
            for &(id, drive) in commands {
                let i = self.joints.iter().position(|j| j.id == id);
                if let Some(i) = i.filter(|&i| !self.refused[i] && self.joints[i].servo.protocol == protocol) {
                    let _ = own.push((i, drive));
                }
            }
            own
        };
        if self.speaks(V1Part::PROTOCOL) {
            let own = of(V1Part::PROTOCOL);
            self.v1.write(&mut self.bus, self.joints, torque, &own, rearm).await;
        }
        if self.speaks(V2Part::PROTOCOL) {
            let own = of(V2Part::PROTOCOL);
            self.v2.write(&mut self.bus, self.joints, torque, &own, rearm).await;
        }
        if self.speaks(FtPart::PROTOCOL) {
            let own = of(FtPart::PROTOCOL);
            self.ft.write(&mut self.bus, self.joints, torque, &own, rearm).await;
        }
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
            if !self.v2.alerted[i] || joint.servo.protocol != ServoProtocol::V2 {
                continue;
            }
            self.bus.reboot2(joint.id).await.ok();
            let back = self.bus.setup2(joint.id, joint.servo.model_number, self.v2.watchdog).await.is_ok();
            self.v2.alerted[i] = !back;
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
