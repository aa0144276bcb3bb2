//! One interface for the part of a robot's bus that each protocol drives
//! ([`ProtocolPart`]), and its implementations: Protocol 1.0 ([`V1Part`]),
//! Protocol 2.0 ([`V2Part`]), Feetech ([`FtPart`]). [`super::RobotBus`] holds one part per
//! protocol and calls, in that order, each part whose servos the robot
//! has: to stop them, set them up, read them and command them.
//!
//! A part is given only its own joints, as indices into the robot's
//! joints, and never a joint whose servo failed its set-up.

use super::v2::{fast_read_firmware, flags_of, Read2};
use super::{ServoBus, ServoRead, ServoSetup, SetupError};
use pada_core::feetech::command::{self, Command};
use pada_core::feetech::control_table::sts3215 as sts;
use pada_core::feetech::ByteOrder;
use crate::config::MAX_ROBOT_SERVOS;
use crate::io::BusPort;
use heapless::Vec;
use pada_core::dynamixel::control_table::x_series::HardwareError;
use pada_core::robot::JointSpec;
use pada_core::servo::{Drive, ServoProtocol};

/// Joint indices of one protocol, in joint order.
pub type Joints = Vec<usize, MAX_ROBOT_SERVOS>;

/// What one protocol does for its joints of a robot.
#[allow(async_fn_in_trait)]
pub trait ProtocolPart {
    /// The protocol its servos speak.
    const PROTOCOL: ServoProtocol;

    /// Torque off and a zero command on every servo of its protocol at
    /// once (broadcast), whatever the servos did before.
    async fn stop_all<P: BusPort>(&mut self, bus: &mut ServoBus<P>);

    /// Sets up joint `i`'s servo (torque is off) and checks its model.
    async fn setup<P: BusPort>(&mut self, bus: &mut ServoBus<P>, i: usize, joint: &JointSpec) -> Result<ServoSetup, SetupError>;

    /// Reads the joints `at` of `joints` into `out` (same indices).
    async fn read<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], at: &[usize], out: &mut [ServoRead; MAX_ROBOT_SERVOS]);

    /// Applies `torque` and the commands of its joints (`commands`: joint
    /// index and command). `rearm`: the period before overran.
    async fn write<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], torque: bool, commands: &[(usize, Drive)], rearm: bool);
}

/// Protocol 1.0 (RX-28, MX-28): a READ of the present block per servo;
/// the Moving Speeds in one SYNC_WRITE, then Torque Enable by broadcast.
#[derive(Debug, Default)]
pub struct V1Part;

impl ProtocolPart for V1Part {
    const PROTOCOL: ServoProtocol = ServoProtocol::V1;

    async fn stop_all<P: BusPort>(&mut self, bus: &mut ServoBus<P>) {
        bus.torque_all(false).await.ok();
        bus.stop_all().await.ok();
    }

    async fn setup<P: BusPort>(&mut self, bus: &mut ServoBus<P>, _i: usize, joint: &JointSpec) -> Result<ServoSetup, SetupError> {
        let expected = joint.servo.model_number;
        match bus.setup(joint.id).await {
            Ok(s) if s.model != expected => Err(SetupError::WrongModel { id: joint.id, found: s.model, expected }),
            other => other,
        }
    }

    async fn read<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], at: &[usize], out: &mut [ServoRead; MAX_ROBOT_SERVOS]) {
        for &i in at {
            let (state, exchange) = bus.read_present(joints[i].id).await;
            out[i] = ServoRead {
                state: state.map(Into::into),
                error: exchange.error(),
                hardware_error: None,
                timeouts: exchange.timeouts,
                checksum_errors: exchange.checksum_errors,
            };
        }
    }

    async fn write<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], torque: bool, commands: &[(usize, Drive)], _rearm: bool) {
        if torque {
            let mut speeds: Vec<(u8, u16), MAX_ROBOT_SERVOS> = Vec::new();
            for &(i, drive) in commands {
                if let Drive::MovingSpeed(v) = drive {
                    let _ = speeds.push((joints[i].id, v));
                }
            }
            bus.write_speeds(&speeds).await.ok();
            bus.torque_all(true).await.ok();
        } else {
            bus.torque_all(false).await.ok();
            bus.stop_all().await.ok();
        }
    }
}

/// Protocol 2.0 (the X series): one (FAST) SYNC READ of every servo's
/// present block, a Hardware Error Status READ after an alert; Torque
/// Enable by broadcast and the Goal PWMs in one SYNC WRITE; the Bus
/// Watchdog armed at every torque-on and after an overrun.
#[derive(Debug)]
pub struct V2Part {
    /// Whether every servo answers FAST SYNC READ.
    pub fast: bool,
    /// The Bus Watchdog value (20 ms units) for the robot's period.
    pub watchdog: u8,
    /// Torque as last written.
    torque_was: bool,
    /// Joints whose servo raised its Alert bit since it was last set up:
    /// rebooted when a fault is cleared.
    pub alerted: [bool; MAX_ROBOT_SERVOS],
}

impl V2Part {
    /// The part for a robot of period `period_us`.
    pub fn new(period_us: u32) -> Self {
        V2Part { fast: true, watchdog: super::v2::watchdog_units(period_us), torque_was: false, alerted: [false; MAX_ROBOT_SERVOS] }
    }
}

impl ProtocolPart for V2Part {
    const PROTOCOL: ServoProtocol = ServoProtocol::V2;

    async fn stop_all<P: BusPort>(&mut self, bus: &mut ServoBus<P>) {
        bus.torque_all2(false).await.ok();
        bus.stop_all2().await.ok();
        self.torque_was = false;
    }

    async fn setup<P: BusPort>(&mut self, bus: &mut ServoBus<P>, i: usize, joint: &JointSpec) -> Result<ServoSetup, SetupError> {
        let r = bus.setup2(joint.id, joint.servo.model_number, self.watchdog).await;
        if let Ok(s) = r {
            self.fast &= s.firmware >= fast_read_firmware(s.model);
        }
        // An alert found at set-up: rebooted when that fault is cleared.
        if let Some(a) = self.alerted.get_mut(i) {
            *a = matches!(r, Err(SetupError::Alert { .. }));
        }
        r
    }

    async fn read<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], at: &[usize], out: &mut [ServoRead; MAX_ROBOT_SERVOS]) {
        let ids: Vec<u8, MAX_ROBOT_SERVOS> = at.iter().map(|&i| joints[i].id).collect();
        let mut reads = [Read2::default(); MAX_ROBOT_SERVOS];
        bus.read_present2(&ids, self.fast, &mut reads).await;
        for ((&i, &id), r) in at.iter().zip(&ids).zip(&reads) {
            // The Alert bit: which hardware error (one more READ, only
            // then).
            let hardware_error = match (r.state, r.error.alert()) {
                (Some(_), true) => Some(bus.hardware_error(id).await.unwrap_or(HardwareError(0))),
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

    async fn write<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], torque: bool, commands: &[(usize, Drive)], rearm: bool) {
        if torque && (!self.torque_was || rearm) {
            bus.arm_watchdog2(self.watchdog).await.ok();
        }
        bus.torque_all2(torque).await.ok();
        let mut pwms: Vec<(u8, i16), MAX_ROBOT_SERVOS> = Vec::new();
        for &(i, drive) in commands {
            if let Drive::GoalPwm { pwm, .. } = drive {
                let _ = pwms.push((joints[i].id, if torque { pwm } else { 0 }));
            }
        }
        bus.sync_write_pwm(&pwms).await.ok();
        self.torque_was = torque;
    }
}

/// Feetech (the STS series, in Operating Mode 2): one SYNC READ of every
/// servo's present block; torque and every duty cycle (Goal Time) in one
/// SYNC WRITE. Feetech documents no bus watchdog: a servo keeps its last
/// duty cycle while the controller is silent, so torque goes off in the
/// period a fault is found, in that same SYNC WRITE.
#[derive(Debug)]
pub struct FtPart {
    /// Each joint's byte order and Acceleration, from its set-up.
    order: [ByteOrder; MAX_ROBOT_SERVOS],
    acceleration: [u8; MAX_ROBOT_SERVOS],
    /// Each joint's Present Position as last read \[steps\]: the Goal
    /// Position the SYNC WRITE carries (which Operating Mode 2 does not
    /// use), so that the block moves nothing if it were used.
    position: [i32; MAX_ROBOT_SERVOS],
}

impl Default for FtPart {
    fn default() -> Self {
        FtPart { order: [ByteOrder::Little; MAX_ROBOT_SERVOS], acceleration: [0; MAX_ROBOT_SERVOS], position: [0; MAX_ROBOT_SERVOS] }
    }
}

/// A duty cycle in 0.1 % of the supply from the controller's command.
fn duty_of(drive: Drive) -> i32 {
    match drive {
        Drive::GoalTime { time, full } => time as i32 * command::MAX_DUTY / full.max(1) as i32,
        other => libm::roundf(other.ratio() * command::MAX_DUTY as f32) as i32,
    }
}

impl ProtocolPart for FtPart {
    const PROTOCOL: ServoProtocol = ServoProtocol::Feetech;

    async fn stop_all<P: BusPort>(&mut self, bus: &mut ServoBus<P>) {
        bus.stop_all_ft().await.ok();
    }

    async fn setup<P: BusPort>(&mut self, bus: &mut ServoBus<P>, i: usize, joint: &JointSpec) -> Result<ServoSetup, SetupError> {
        let s = bus.setup_ft(joint.id, joint.servo.model_number, sts::MODE_PWM).await?;
        if i < MAX_ROBOT_SERVOS {
            self.order[i] = s.order;
            self.acceleration[i] = s.acceleration;
        }
        Ok(s.setup)
    }

    async fn read<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], at: &[usize], out: &mut [ServoRead; MAX_ROBOT_SERVOS]) {
        let ids: Vec<u8, MAX_ROBOT_SERVOS> = at.iter().map(|&i| joints[i].id).collect();
        let mut reads = [ServoRead::default(); MAX_ROBOT_SERVOS];
        // One SYNC READ decodes every answer in one byte order: the first
        // servo's (every STS servo's is little endian).
        let order = at.first().map_or(ByteOrder::Little, |&i| self.order[i]);
        bus.read_present_ft(&ids, order, &mut reads).await;
        for (&i, r) in at.iter().zip(&reads) {
            if let Some(p) = r.state {
                self.position[i] = p.position;
            }
            out[i] = *r;
        }
    }

    async fn write<P: BusPort>(&mut self, bus: &mut ServoBus<P>, joints: &[JointSpec], torque: bool, commands: &[(usize, Drive)], _rearm: bool) {
        let mut entries: Vec<(u8, Command), MAX_ROBOT_SERVOS> = Vec::new();
        let mut order = None;
        for &(i, drive) in commands {
            let command = Command {
                torque,
                acceleration: self.acceleration[i],
                goal_position: self.position[i],
                duty: if torque { duty_of(drive) } else { 0 },
            };
            let _ = entries.push((joints[i].id, command));
            order.get_or_insert(self.order[i]);
        }
        bus.sync_write_ft(&entries, order.unwrap_or(ByteOrder::Little)).await.ok();
    }
}
