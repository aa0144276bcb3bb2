//! The Protocol 2.0 side of the emulated bus: a robot's X-series servos,
//! each the virtual servo of `pada servos` ([`P2Servo`]: its control
//! table, every instruction, alerts, the Bus Watchdog), and the sensor
//! device in Protocol 2.0. This file decides which servos an instruction
//! concerns and what they answer; when the answer arrives, the faults and
//! the counters are the bus's ([`super::BusEmulator`]).
//!
//! A FAST SYNC READ (the firmware's read of every servo, once a period)
//! gets one status packet with each servo's block, after the first servo's
//! Return Delay Time.

use pada_sim::rig::{JointState, Rig};
use crate::bus::{baud_value, hardware_error_of};
use crate::p2::{self, P2Servo, PACKET_LEN};
use crate::sensor::SensorDevice;
use crate::fault::{FaultKind, FaultSpec};
use pada_core::dynamixel::control_table;
use pada_core::dynamixel::v2::{self as dxl2, Instruction as I, StatusError};
use pada_core::dynamixel::BROADCAST_ID;
use pada_core::robot::{JointSpec, RobotSpec};
use pada_core::servo::ServoProtocol;
use pada_firmware::sil::SENSOR_ID;

/// The rate the firmware's bus runs at (the Baud Rate value the servos
/// start with; under QEMU the UART's rate is not modelled).
const BUS_BPS: u32 = 1_000_000;

/// What a packet to the X-series servos gets.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct XAnswer {
    /// The servos whose answer it carries (a fast read's: every block's,
    /// the first sends it).
    pub ids: Vec<u8>,
    /// The status packet.
    pub bytes: Vec<u8>,
    /// That servo's Return Delay Time \[µs\] (the sensor device: 50).
    pub return_delay_us: u64,
    /// Whether its Alert bit is set.
    pub alert: bool,
    /// Whether it is the sensor device's (never faulted).
    pub sensor: bool,
}

/// A robot's Protocol 2.0 servos.
#[derive(Debug, Clone)]
pub struct XServos {
    decoder: dxl2::InstructionDecoder<PACKET_LEN>,
    servos: Vec<P2Servo>,
    sensor: SensorDevice,
    /// Whether the sensor device answers (a robot with an encoder).
    sensor_answers: bool,
    supply_v: f64,
}

impl XServos {
    /// The Protocol 2.0 servos among `ids` (each of the model its joint of
    /// `robot` names), at the bus's rate; `None` if there are none.
    pub fn new(robot: &RobotSpec, ids: &[u8], supply_v: f64) -> Result<Option<Self>, String> {
        let mut servos = Vec::new();
        for &id in ids {
            let Some(joint) = robot.joints.iter().find(|j| j.id == id) else { continue };
            if joint.servo.protocol != ServoProtocol::V2 {
                continue;
            }
            let table = control_table::by_model_number(joint.servo.model_number)
                .ok_or_else(|| format!("no control table of {} (model {})", joint.servo.name, joint.servo.model_number))?;
            let baud = baud_value(table, BUS_BPS).ok_or_else(|| format!("the {} takes no {BUS_BPS} bps", joint.servo.name))?;
            servos.push(P2Servo::new(joint.servo, table, id, baud, Some(*joint)));
        }
        if servos.is_empty() {
            return Ok(None);
        }
        let sensor_answers = robot.encoder.is_some() && robot.joints.first().is_some_and(|j| j.servo.protocol == ServoProtocol::V2);
        Ok(Some(XServos { decoder: dxl2::InstructionDecoder::new(), servos, sensor: SensorDevice::new(), sensor_answers, supply_v }))
    }

    /// Bytes of an unfinished packet held.
    pub fn buffered(&self) -> usize {
        self.decoder.buffered()
    }

    /// Feeds one byte; a whole packet (or a damaged one: `Err`) when it
    /// ends.
    pub fn push(&mut self, b: u8) -> Option<Result<dxl2::InstructionPacket<PACKET_LEN>, ()>> {
        self.decoder.push(b).map(|r| r.map_err(|_| ()))
    }

    /// Every servo's ID and torque (with a motor voltage: a tripped Bus
    /// Watchdog stops it).
    pub fn torques(&self) -> impl Iterator<Item = (u8, bool)> + '_ {
        self.servos.iter().map(|s| (s.id(), s.torque() && !s.watchdog_tripped()))
    }

    /// A power cut at `t_us`: every servo back to its initial values, its
    /// joint limp.
    pub fn power_off(&mut self, t_us: u64, rig: &mut dyn Rig) {
        for s in &mut self.servos {
            *s = P2Servo::new(s.model, s.table, s.id(), s.baud(), s.joint);
            rig.drive(t_us, s.id(), false, 0.0);
        }
    }

    /// Executes packet `p`, complete at `t`, with `faults` in force:
    /// the answers, in order. `read` is the rig's joint at `t` (changing
    /// the rig or not).
    pub fn execute(
        &mut self,
        p: &dxl2::InstructionPacket<PACKET_LEN>,
        t: u64,
        faults: &[FaultSpec],
        read: &mut dyn FnMut(u8) -> Option<JointState>,
        sensors: &mut dyn FnMut() -> Option<(u16, u8)>,
    ) -> Option<Vec<XAnswer>> {
        // The Bus Watchdog: a servo with torque that heard nothing for its
        // time stops; every instruction packet resets its time.
        for s in &mut self.servos {
            if let (true, Some(limit)) = (s.torque(), s.watchdog_us()) {
                if t.saturating_sub(s.heard_us) > limit && !s.watchdog_tripped() {
                    s.trip_watchdog();
                }
            }
            s.heard_us = t;
        }
        // An `error-bits` fault raises its hardware alert while it applies.
        for f in faults {
            if let FaultKind::ErrorBits { bits } = f.kind {
                for s in self.servos.iter_mut().filter(|s| f.applies(t, s.id())) {
                    s.raise(hardware_error_of(bits));
                }
            }
        }
        if p.id == SENSOR_ID {
            if p.instruction == 0x02 {
                let (count, contacts) = sensors()?;
                self.sensor.set(count, contacts);
            }
            let (answer, _call) = self.sensor.execute(ServoProtocol::V2, p.instruction, &p.params);
            let answers = match (answer, self.sensor_answers) {
                (Some(bytes), true) => vec![XAnswer { ids: vec![SENSOR_ID], bytes, return_delay_us: 50, alert: false, sensor: true }],
                _ => Vec::new(),
            };
            return Some(answers);
        }
        let Ok(ins) = p.instruction() else { return Some(Vec::new()) };
        let broadcast = p.id == BROADCAST_ID;
        let at = |ss: &[P2Servo], id: u8| ss.iter().position(|s| s.id() == id);
        let order: Vec<usize> = match ins {
            I::SyncRead { ids, .. } | I::FastSyncRead { ids, .. } => ids.iter().filter_map(|&id| at(&self.servos, id)).collect(),
            I::BulkRead { .. } | I::FastBulkRead { .. } => ins.bulk_read_entries().filter_map(|e| at(&self.servos, e.id)).collect(),
            _ if broadcast => {
                let mut all: Vec<usize> = (0..self.servos.len()).collect();
                all.sort_by_key(|&i| self.servos[i].id());
                all
            }
            _ => at(&self.servos, p.id).into_iter().collect(),
        };
        let reads = matches!(ins, I::Read { .. } | I::SyncRead { .. } | I::FastSyncRead { .. } | I::BulkRead { .. } | I::FastBulkRead { .. });
        let fast = matches!(ins, I::FastSyncRead { .. } | I::FastBulkRead { .. });
        let multi = ins.code().is_multi();
        let mut answers = Vec::new();
        let mut blocks: Vec<(u8, StatusError, Vec<u8>)> = Vec::new();
        for &i in &order {
            let joint = self.servos[i].joint;
            let mut turning = false;
            if let (true, Some(j)) = (reads || matches!(ins, I::ClearMultiTurn), joint) {
                let state = planted(read(j.id)?, &j, t, faults);
                turning = state.rate.abs() > 1e-3;
                self.servos[i].set_present(&j, state, self.supply_v);
            }
            let s = &mut self.servos[i];
            let quiet = broadcast && !multi && !matches!(ins, I::Ping);
            match (s.execute(&ins, quiet, turning), fast) {
                (Some((e, data)), true) => blocks.push((s.id(), e, data)),
                (Some(a), false) => {
                    let alert = a.0.alert();
                    answers.push(XAnswer { ids: vec![s.id()], bytes: p2::encode(s.id(), a), return_delay_us: s.return_delay_us(), alert, sensor: false });
                }
                (None, _) => {}
            }
        }
        let expected = match ins {
            I::FastSyncRead { ids, .. } => ids.len(),
            _ => ins.bulk_read_entries().count(),
        };
        // A servo missing from the chain: the combined reply never completes.
        if fast && blocks.len() == expected && !blocks.is_empty() {
            if let Some(bytes) = p2::fast_reply(&blocks) {
                let first = at(&self.servos, blocks[0].0).unwrap_or(0);
                let alert = blocks.iter().any(|b| b.1.alert());
                let ids = blocks.iter().map(|b| b.0).collect();
                answers.push(XAnswer { ids, bytes, return_delay_us: self.servos[first].return_delay_us(), alert, sensor: false });
            }
        }
        Some(answers)
    }

    /// Drives the rig at `t` with every servo's torque and voltage.
    pub fn drive(&self, t: u64, rig: &mut dyn Rig) {
        for s in &self.servos {
            let id = s.joint.map_or(s.id(), |j| j.id);
            rig.drive(t, id, s.torque(), s.volts(self.supply_v));
        }
    }
}

/// The joint's state as read at `t`: past its soft limit while a
/// `past-limit` fault applies to it.
fn planted(mut s: JointState, joint: &JointSpec, t: u64, faults: &[FaultSpec]) -> JointState {
    let past = faults.iter().any(|f| f.kind == FaultKind::PastLimit && f.applies(t, joint.id));
    if let (true, Some(limit)) = (past, joint.soft_limit) {
        s.angle = (limit.max + crate::fault::PAST_LIMIT_RAD) as f64;
    }
    s
}

/// Whether the instruction packet `p` is a write of the servos' state
/// (what drives the rig).
pub fn drives(p: &dxl2::InstructionPacket<PACKET_LEN>) -> bool {
    !matches!(p.instruction(), Ok(I::Ping | I::Read { .. } | I::SyncRead { .. } | I::FastSyncRead { .. } | I::BulkRead { .. } | I::FastBulkRead { .. }))
        && p.id != SENSOR_ID
}

#[cfg(test)]
mod tests {
    use super::super::{BusEmulator, BYTE_US};
    use crate::fault;
    use pada_core::dynamixel::control_table::x_series;
    use pada_core::dynamixel::v2::encoders;
    use pada_core::dynamixel::BROADCAST_ID;
    use pada_firmware::bus::v2::{fast_reply_len, PRESENT_LEN};

    /// arm2, as `pada sil` runs it: its robot and the rig behind its bus.
    fn arm() -> (&'static pada_core::robot::RobotSpec, Box<dyn pada_sim::rig::Rig>) {
        let file = pada_robot_file::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/arm2/robot.toml")).unwrap();
        (file.spec, pada_sim::robots::from_file(&file).unwrap().sil_rig().unwrap())
    }

    fn packet(f: impl FnOnce(&mut [u8]) -> usize) -> Vec<u8> {
        let mut buf = [0u8; 256];
        let n = f(&mut buf);
        buf[..n].to_vec()
    }

    #[test]
    fn the_arms_x_series_servos_answer_a_fast_sync_read_and_drive_the_rig() {
        let (robot, mut rig) = arm();
        // The operator lets go of the arm (it holds it until a start).
        rig.episode_started(0);
        let faults = vec![fault::parse("drop:at=1:for=1:servo=1").unwrap()];
        let mut bus = BusEmulator::new(rig.as_ref(), robot, faults).unwrap();
        let read = packet(|b| encoders::fast_sync_read(x_series::PRESENT_BLOCK, PRESENT_LEN, &[1, 2], b).unwrap().len());
        let replies = bus.receive(1000, &read, rig.as_mut());
        assert_eq!(replies.len(), 1, "one reply for both servos");
        let n = fast_reply_len(2);
        assert_eq!(replies[0].bytes.len(), n);
        // The factory Return Delay Time: 500 µs.
        assert_eq!(replies[0].at_us, 1000 + read.len() as u64 * BYTE_US + 500 + n as u64 * BYTE_US);
        assert!(bus.forecast(2000, &read, rig.as_ref()).is_none(), "no forecasts on Protocol 2.0");
        // PWM mode, torque on, Goal PWM: the servos drive their joints.
        let mode = packet(|b| encoders::write(BROADCAST_ID, x_series::OPERATING_MODE, &[16], b).unwrap().len());
        let torque = packet(|b| encoders::write(BROADCAST_ID, x_series::TORQUE_ENABLE, &[1], b).unwrap().len());
        let pwm = packet(|b| encoders::sync_write_values(x_series::GOAL_PWM, &[(1, 300i16.to_le_bytes()), (2, 0i16.to_le_bytes())], b).unwrap().len());
        assert!(bus.receive(3000, &[mode, torque, pwm].concat(), rig.as_mut()).is_empty());
        assert_eq!((bus.torque(1), bus.torque(2)), (Some(true), Some(true)));
        let before = rig.joint_state(3000, 1).angle;
        rig.advance_to(300_000);
        assert!((rig.joint_state(300_000, 1).angle - before).abs() > 1e-3, "Goal PWM 300 turns the shoulder");
        // servo 1's answers dropped from 1 s to 2 s: the fast reply (its
        // block) with them.
        assert!(bus.receive(1_500_000, &read, rig.as_mut()).is_empty());
        assert_eq!(bus.receive(2_500_000, &read, rig.as_mut()).len(), 1);
        let stats = bus.stats();
        assert_eq!((stats.packets, stats.replies, stats.dropped, stats.bad_packets), (6, 2, 1, 0));
    }
}
