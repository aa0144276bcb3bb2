//! The virtual bus: every virtual servo of a robot, in the protocol its
//! model speaks, and the sensor device, answering the instruction packets
//! that arrive on the line with the robot's simulated physics behind them
//! ([`Rig`]), as `pada sil` answers the firmware.
//!
//! Bytes are fed to a Protocol 1.0 and a Protocol 2.0 decoder at once, as
//! on a real bus where each servo listens for its own protocol's header.
//! A servo hears the line only at its own Baud Rate (within 3 %, the
//! e-Manual's tolerance for a UART): a client at another rate, or a
//! servo whose Baud Rate was just written, gets no answer.
//!
//! # Time
//!
//! - **Real time**: the instant of a packet is the wall clock's since
//!   start; an answer is due its return delay and its bytes' wire time
//!   after the request.
//! - **Lock step**: time stands still except that every SYNC WRITE (the
//!   controller's command, once a period) ends a control period: the next
//!   read finds the robot one period later. Writes that follow the sync
//!   write in the same period (Torque Enable, the operator's call) happen
//!   at the period's instant, as a board's whole period does. So a run
//!   over a pseudo-terminal depends on what was sent, never on how fast.

use super::p1::P1Servo;
use super::p2::P2Servo;
use super::sensor::SensorDevice;
use pada_sim::rig::Rig;
use crate::fault::{FaultKind, FaultSpec};
use pada_core::dynamixel::control_table::{self, rx28, x_series::HardwareError};
use pada_core::dynamixel::v2::{self as dxl2, ErrorNumber, StatusError};
use pada_core::dynamixel::{self as dxl1, ErrorFlags, BROADCAST_ID};
use pada_core::feetech::control_table::sts3215;
use pada_core::feetech::{self, Instruction as ft_ins};
use pada_core::robot::{JointSpec, RobotSpec};
use pada_core::servo::{ServoModel, ServoProtocol};
use pada_firmware::sensor_device::SENSOR_ID;
use serde::Serialize;

/// Bytes a decoder holds: the longest instruction a client sends.
use super::p2::PACKET_LEN;

/// An answer on its way to the line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reply {
    /// When its last byte is out \[µs\] (the instant of the request in lock
    /// step).
    pub at_us: u64,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// How time passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// The wall clock.
    RealTime,
    /// One control period per SYNC WRITE.
    LockStep,
}

/// Counters of the virtual bus.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct BusStats {
    /// Bytes received.
    pub bytes_in: u64,
    /// Bytes answered.
    pub bytes_out: u64,
    /// Instruction packets decoded (either protocol).
    pub packets: u64,
    /// Damaged packets (bad checksum or CRC).
    pub damaged: u64,
    /// Status packets sent.
    pub replies: u64,
    /// Control periods ended by a SYNC WRITE.
    pub sync_writes: u64,
    /// Answers a fault dropped, corrupted or delayed.
    pub faulted: u64,
}

/// Something a servo did that a test or a person wants to know when.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    /// Bus time \[µs\].
    pub at_us: u64,
    /// The servo.
    pub id: u8,
    /// What: `torque-on`, `torque-off`, `watchdog-tripped`, `alert`,
    /// `operator-ended`, `operator-started`.
    pub what: &'static str,
}

/// One device on the bus.
enum Device {
    P1(P1Servo),
    P2(P2Servo),
}

/// The virtual bus of one robot.
pub struct VirtualBus {
    rig: Box<dyn Rig>,
    supply_v: f64,
    devices: Vec<Device>,
    sensor: Option<SensorDevice>,
    /// Whether the sensor device answers (a robot with sensors off the
    /// servos); otherwise it only hears the operator's calls, silently.
    sensor_answers: bool,
    dec1: dxl1::InstructionDecoder<PACKET_LEN>,
    dec2: dxl2::InstructionDecoder<PACKET_LEN>,
    clock: Clock,
    period_us: u64,
    now_us: u64,
    /// A SYNC WRITE ended the period: the next read advances (lock step).
    period_ended: bool,
    faults: Vec<FaultSpec>,
    /// Whether each fault's onset has been logged.
    onsets: Vec<bool>,
    /// Whether each `error-bits` fault's alert has been raised (Protocol
    /// 2.0).
    raised: Vec<bool>,
    stats: BusStats,
    events: Vec<Event>,
    /// Torque of each device as last driven.
    driven: Vec<(bool, f64)>,
}

/// The Baud Rate value of `bps` for a servo table (the nearest rate), and
/// whether it is within 3 %.
pub fn baud_value(table: &control_table::ControlTable, bps: u32) -> Option<u8> {
    let (value, rate) = table.baud_rates.iter().enumerate().min_by_key(|(_, r)| (**r as i64 - bps as i64).unsigned_abs())?;
    same_rate(*rate, bps).then_some(value as u8)
}

/// Whether two bit rates are within 3 % of each other.
pub fn same_rate(a: u32, b: u32) -> bool {
    (a as f64 - b as f64).abs() <= 0.03 * b as f64
}

impl VirtualBus {
    /// The servos of `robot` (each joint's, of the model its definition
    /// names) at `bps`, the sensor device if the robot has sensors off the
    /// servos, behind `rig`.
    pub fn new(robot: &'static RobotSpec, rig: Box<dyn Rig>, bps: u32, clock: Clock, faults: Vec<FaultSpec>) -> Result<Self, String> {
        let mut devices = Vec::new();
        for joint in robot.joints {
            devices.push(device(joint.servo, joint.id, bps, Some(*joint))?);
        }
        for f in &faults {
            if !robot.joints.iter().any(|j| j.id == f.servo) {
                let ids: Vec<String> = robot.joints.iter().map(|j| j.id.to_string()).collect();
                return Err(format!("--fault {f}: no servo {} on {}'s bus (its servos: {})", f.servo, robot.name, ids.join(", ")));
            }
        }
        // The sensor device answers for a robot with sensors off the
        // servos (the pendulum's and LEO's encoders, LEO's foot switches);
        // every robot's operator hears the controller's calls at its ID.
        let sensor_answers = robot.encoder.is_some();
        Ok(Self::assemble(rig, devices, Some(SensorDevice::new()), sensor_answers, clock, robot.period_us as u64, faults))
    }

    /// The bus of `devices` behind `rig`, at time 0.
    fn assemble(
        rig: Box<dyn Rig>,
        devices: Vec<Device>,
        sensor: Option<SensorDevice>,
        sensor_answers: bool,
        clock: Clock,
        period_us: u64,
        faults: Vec<FaultSpec>,
    ) -> Self {
        VirtualBus {
            supply_v: rig.supply_v(),
            rig,
            driven: vec![(false, 0.0); devices.len()],
            devices,
            sensor,
            sensor_answers,
            dec1: dxl1::InstructionDecoder::new(),
            dec2: dxl2::InstructionDecoder::new(),
            clock,
            period_us,
            now_us: 0,
            period_ended: false,
            onsets: vec![false; faults.len()],
            raised: vec![false; faults.len()],
            faults,
            stats: BusStats::default(),
            events: Vec::new(),
        }
    }

    /// A bare chain of STS3215s at `ids` (no robot: [`super::chain`]),
    /// at `bps`; lock step ends a period of `period_us` at each SYNC WRITE.
    pub fn chain(ids: &[u8], bps: u32, clock: Clock, faults: Vec<FaultSpec>, period_us: u64) -> Result<Self, String> {
        let table = &sts3215::STS3215;
        let baud = baud_value(table, bps).ok_or_else(|| baud_error(table, bps))?;
        let devices: Vec<Device> = ids.iter().map(|&id| Device::P1(P1Servo::of(&super::ft::STS3215_LAYOUT, id, baud, None))).collect();
        if let Some(f) = faults.iter().find(|f| !ids.contains(&f.servo)) {
            return Err(format!("--fault {f}: no servo {} on the chain (its servos: {ids:?})", f.servo));
        }
        let rig = Box::new(super::chain::NoPlant::new(ids.to_vec()));
        Ok(Self::assemble(rig, devices, None, false, clock, period_us, faults))
    }

    /// Counters so far.
    pub fn stats(&self) -> BusStats {
        self.stats
    }

    /// What the servos did, in order.
    pub fn events(&self) -> &[Event] {
        &self.events
    }

    /// The bus time now \[µs\].
    pub fn now_us(&self) -> u64 {
        self.now_us
    }

    /// Whether servo `id` has torque (and its motor a voltage).
    pub fn torque(&self, id: u8) -> Option<bool> {
        self.devices.iter().find(|d| dev_id(d) == id).map(|d| match d {
            Device::P1(s) => s.torque(),
            Device::P2(s) => s.torque() && !s.watchdog_tripped(),
        })
    }

    /// Every servo's ID.
    pub fn ids(&self) -> Vec<u8> {
        self.devices.iter().map(dev_id).collect()
    }

    /// The rig behind the bus.
    pub fn rig(&self) -> &dyn Rig {
        self.rig.as_ref()
    }

    /// Real time: the clock moves to `now_us`; Bus Watchdogs that ran out
    /// trip, and faults whose window opened act (an alert is raised).
    pub fn tick(&mut self, now_us: u64) {
        if self.clock == Clock::RealTime {
            self.now_us = self.now_us.max(now_us);
        }
        let now = self.now_us;
        for d in &mut self.devices {
            if let Device::P2(s) = d {
                if let (true, Some(limit)) = (s.torque(), s.watchdog_us()) {
                    if now.saturating_sub(s.heard_us) > limit && !s.watchdog_tripped() {
                        s.trip_watchdog();
                        self.events.push(Event { at_us: s.heard_us + limit, id: s.id(), what: "watchdog-tripped" });
                    }
                }
            }
        }
        self.raise_alerts();
        self.drive_all();
    }

    /// Hardware alerts of `error-bits` faults on Protocol 2.0 servos: raised
    /// at the window's opening, kept until a REBOOT (as the e-Manual's
    /// hardware errors are).
    fn raise_alerts(&mut self) {
        let now = self.now_us;
        for (k, f) in self.faults.iter().enumerate() {
            let FaultKind::ErrorBits { bits } = f.kind else { continue };
            if self.raised[k] || now < f.start_us {
                continue;
            }
            for d in &mut self.devices {
                match d {
                    Device::P2(s) if s.id() == f.servo => s.raise(hardware_error_of(bits)),
                    // An STS3215's Status has the bits at the same places.
                    Device::P1(s) if s.id() == f.servo && s.own_loop.is_some() => {
                        if let Some(out) = s.own_loop.as_mut() {
                            out.injected = out.injected.union(bits);
                        }
                    }
                    _ => continue,
                }
                self.raised[k] = true;
                self.events.push(Event { at_us: now, id: f.servo, what: "alert" });
            }
        }
    }

    /// Drives the rig with every servo whose torque or voltage changed.
    fn drive_all(&mut self) {
        let now = self.now_us;
        for (i, d) in self.devices.iter().enumerate() {
            let (id, torque, volts) = match d {
                Device::P1(s) => (s.id(), s.torque(), s.volts(self.supply_v)),
                Device::P2(s) => (s.id(), s.torque(), s.volts(self.supply_v)),
            };
            let joint_id = match d {
                Device::P1(s) => s.joint.map_or(id, |j| j.id),
                Device::P2(s) => s.joint.map_or(id, |j| j.id),
            };
            if self.driven[i] != (torque, volts) {
                if self.driven[i].0 != torque {
                    self.events.push(Event { at_us: now, id, what: if torque { "torque-on" } else { "torque-off" } });
                }
                self.driven[i] = (torque, volts);
            }
            self.rig.drive(now, joint_id, torque, volts);
        }
    }

    /// Takes bytes that arrived on a line at `line_bps` at `now_us` (real
    /// time; lock step keeps its own clock); returns the answers, in order.
    pub fn receive(&mut self, bytes: &[u8], now_us: u64, line_bps: u32) -> Vec<Reply> {
        if self.clock == Clock::RealTime {
            self.now_us = self.now_us.max(now_us);
        }
        let mut replies = Vec::new();
        for &b in bytes {
            self.stats.bytes_in += 1;
            // Each byte to both protocols' decoders: what it completes in
            // each, in order.
            for r in self.dec1.feed(&[b]).collect::<Vec<_>>() {
                match r {
                    Ok(p) => self.packet1(p, line_bps, &mut replies),
                    Err(dxl1::DecodeError::BadChecksum { id, .. }) => self.damaged(id, ServoProtocol::V1, line_bps, &mut replies),
                    Err(_) => {}
                }
            }
            for r in self.dec2.feed(&[b]).collect::<Vec<_>>() {
                match r {
                    Ok(p) => self.packet2(p, line_bps, &mut replies),
                    Err(dxl2::DecodeError::BadCrc { id, .. }) => self.damaged(id, ServoProtocol::V2, line_bps, &mut replies),
                    Err(_) => {}
                }
            }
        }
        self.stats.replies += replies.len() as u64;
        self.stats.bytes_out += replies.iter().map(|r| r.bytes.len() as u64).sum::<u64>();
        replies
    }

    /// Whether any servo hears a line at `bps` (the sensor device hears
    /// the servos' rate; a bus without servos, any).
    pub fn anyone_hears(&self, bps: u32) -> bool {
        self.devices.is_empty() || (0..self.devices.len()).any(|i| self.hears(i, bps))
    }

    /// Whether device `i` hears a line at `bps`.
    fn hears(&self, i: usize, bps: u32) -> bool {
        match &self.devices[i] {
            Device::P1(s) => same_rate(s.baud_bps(), bps),
            Device::P2(s) => same_rate(s.table.baud_rate_bps(s.baud()).unwrap_or(0), bps),
        }
    }

    /// A damaged packet addressed to a servo that hears it: Checksum Error
    /// (1.0) or CRC Error (2.0), as its Status Return Level allows.
    fn damaged(&mut self, id: u8, protocol: ServoProtocol, bps: u32, replies: &mut Vec<Reply>) {
        self.stats.damaged += 1;
        let Some(i) = self.devices.iter().position(|d| dev_id(d) == id) else { return };
        if !self.hears(i, bps) {
            return;
        }
        let answer = match (&self.devices[i], protocol) {
            (Device::P1(s), ServoProtocol::V1) => {
                let error = if s.own_loop.is_some() { super::ft::answer_error(s, ErrorFlags::CHECKSUM) } else { ErrorFlags::CHECKSUM };
                s.refuse(false, error).map(|a| encode1(id, a))
            }
            (Device::P2(s), ServoProtocol::V2) => s.refuse(false, ErrorNumber::Crc).map(|a| encode2(id, a)),
            _ => None,
        };
        if let Some(bytes) = answer {
            self.push_reply(i, bytes, replies);
        }
    }

    /// Lock step: a read after the period's SYNC WRITE finds the robot one
    /// period later.
    fn before_read(&mut self) {
        if self.clock == Clock::LockStep && self.period_ended {
            self.period_ended = false;
            self.now_us += self.period_us;
            self.rig.advance_to(self.now_us);
            self.tick(self.now_us);
        }
    }

    /// Refreshes device `i`'s present values from the robot now.
    fn refresh(&mut self, i: usize) {
        let now = self.now_us;
        let supply = self.supply_v;
        if let Device::P1(s) = &mut self.devices[i] {
            if let Some(mut out) = s.own_loop.take() {
                // A robot's STS3215 reads its joint; a bare one, its own loop.
                let dropped = match s.joint {
                    Some(joint) => {
                        let state = self.rig.joint_state(now, joint.id);
                        let present = pada_sim::rig::x_reading(&joint, state, 0, supply).into();
                        super::ft::with_robot(s, &mut out, &present, now)
                    }
                    None => super::ft::advance(s, &mut out, now),
                };
                s.own_loop = Some(out);
                if dropped {
                    self.events.push(Event { at_us: now, id: s.id(), what: "unloaded" });
                }
                return;
            }
        }
        let joint = match &self.devices[i] {
            Device::P1(s) => s.joint,
            Device::P2(s) => s.joint,
        };
        let Some(joint) = joint else { return };
        match &self.devices[i] {
            Device::P1(_) => {
                let p = self.rig.present(now, joint.id);
                let p = self.plant(now, joint, p);
                if let Device::P1(s) = &mut self.devices[i] {
                    super::p1::with_present(&mut s.table, &p);
                }
            }
            Device::P2(_) => {
                let state = self.rig.joint_state(now, joint.id);
                if let Device::P2(s) = &mut self.devices[i] {
                    s.set_present(&joint, state, supply);
                }
            }
        }
    }

    /// A Protocol 1.0 reading with a `past-limit` fault applied.
    fn plant(&self, t: u64, joint: JointSpec, mut p: pada_core::dynamixel::table::PresentState) -> pada_core::dynamixel::table::PresentState {
        let past = self.faults.iter().any(|f| f.kind == FaultKind::PastLimit && f.applies(t, joint.id));
        if let (true, Some(limit)) = (past, joint.soft_limit) {
            p.position = joint.position_of((limit.max + crate::fault::PAST_LIMIT_RAD) as f64);
        }
        p
    }

    /// A packet in Protocol 1.0's framing: a Dynamixel 1.0 instruction to
    /// the RX-28s, a Feetech one to the STS3215s (the tables differ in
    /// SYNC READ and BULK READ only).
    fn packet1(&mut self, p: dxl1::InstructionPacket<PACKET_LEN>, bps: u32, replies: &mut Vec<Reply>) {
        self.stats.packets += 1;
        let broadcast = p.id == BROADCAST_ID;
        if p.id == SENSOR_ID {
            self.sensor_packet(ServoProtocol::V1, &p.params, p.code, replies);
            return;
        }
        let dx = p.instruction().map(ft_ins::Shared);
        let ft = feetech::Instruction::parse(p.code, &p.params);
        let feetech = |d: &Device| matches!(d, Device::P1(s) if s.own_loop.is_some());
        if let (Err(_), Err(_)) = (&dx, &ft) {
            if let Some(i) = self.p1_at(p.id, bps) {
                self.answer1(i, broadcast, Some(ErrorFlags::INSTRUCTION), replies);
            }
            return;
        }
        let reads = matches!(
            (&dx, &ft),
            (Ok(ft_ins::Shared(dxl1::Instruction::Read { .. } | dxl1::Instruction::BulkRead { .. })), _)
                | (_, Ok(ft_ins::SyncRead { .. }))
        );
        if reads {
            self.before_read();
        }
        // The servos it concerns, in the order they answer.
        let order: Vec<usize> = match (&dx, &ft) {
            (Ok(ft_ins::Shared(ins @ dxl1::Instruction::BulkRead { .. })), _) => {
                ins.bulk_read_entries().filter_map(|(id, _, _)| self.p1_at(id, bps)).filter(|&i| !feetech(&self.devices[i])).collect()
            }
            (_, Ok(ft_ins::SyncRead { ids, .. })) => {
                ids.iter().filter_map(|&id| self.p1_at(id, bps)).filter(|&i| feetech(&self.devices[i])).collect()
            }
            _ if broadcast => (0..self.devices.len()).filter(|&i| matches!(self.devices[i], Device::P1(_)) && self.hears(i, bps)).collect(),
            _ => self.p1_at(p.id, bps).into_iter().collect(),
        };
        for i in order {
            if reads {
                self.refresh(i);
            }
            let ins = if feetech(&self.devices[i]) { ft } else { dx };
            let Device::P1(s) = &mut self.devices[i] else { continue };
            // It answers from the ID it was asked at (RESET changes it).
            let id = s.id();
            let answer = match ins {
                Err(_) => {
                    self.answer1(i, broadcast, Some(ErrorFlags::INSTRUCTION), replies);
                    continue;
                }
                Ok(ft_ins::Shared(ins)) => s.execute(&ins, broadcast && !matches!(ins, dxl1::Instruction::BulkRead { .. })),
                // Its turn in the chain.
                Ok(ft_ins::SyncRead { addr, len, .. }) => Some(s.read(addr, len)),
            };
            if let Some(mut out) = s.own_loop.take() {
                super::ft::calibrate_middle(s, &mut out);
                s.own_loop = Some(out);
            }
            if let Some((error, data)) = answer {
                let error = if s.own_loop.is_some() { super::ft::answer_error(s, error) } else { error };
                let bytes = encode1(id, (error, data));
                self.push_reply(i, bytes, replies);
            }
        }
        if let Ok(ft_ins::Shared(dxl1::Instruction::SyncWrite { .. })) = dx {
            self.stats.sync_writes += 1;
            self.period_ended = true;
        }
        self.drive_all();
    }

    /// Device `i`'s answer to an instruction it cannot execute, or a
    /// damaged packet (`error`), as its level allows.
    fn answer1(&mut self, i: usize, broadcast: bool, error: Option<ErrorFlags>, replies: &mut Vec<Reply>) {
        let Device::P1(s) = &self.devices[i] else { return };
        let error = error.unwrap_or(ErrorFlags::CHECKSUM);
        let error = if s.own_loop.is_some() { super::ft::answer_error(s, error) } else { error };
        if let Some(a) = s.refuse(broadcast, error) {
            let bytes = encode1(s.id(), a);
            self.push_reply(i, bytes, replies);
        }
    }

    fn packet2(&mut self, p: dxl2::InstructionPacket<PACKET_LEN>, bps: u32, replies: &mut Vec<Reply>) {
        self.stats.packets += 1;
        // The Bus Watchdog counts every instruction packet on the bus.
        let now = self.now_us;
        for d in &mut self.devices {
            if let Device::P2(s) = d {
                s.heard_us = now;
            }
        }
        let broadcast = p.id == BROADCAST_ID;
        if p.id == SENSOR_ID {
            self.sensor_packet(ServoProtocol::V2, &p.params, p.instruction, replies);
            return;
        }
        let ins = match p.instruction() {
            Ok(ins) => ins,
            Err(e) => {
                let Some(number) = e.error_number() else { return };
                if let Some(i) = self.p2_at(p.id, bps) {
                    if let Device::P2(s) = &self.devices[i] {
                        if let Some(a) = s.refuse(broadcast, number) {
                            let bytes = encode2(p.id, a);
                            self.push_reply(i, bytes, replies);
                        }
                    }
                }
                return;
            }
        };
        use dxl2::Instruction as I;
        let reads = matches!(ins, I::Read { .. } | I::SyncRead { .. } | I::FastSyncRead { .. } | I::BulkRead { .. } | I::FastBulkRead { .. });
        if reads {
            self.before_read();
        }
        let multi = ins.code().is_multi();
        let order: Vec<usize> = match ins {
            I::SyncRead { ids, .. } | I::FastSyncRead { ids, .. } => ids.iter().filter_map(|&id| self.p2_at(id, bps)).collect(),
            I::BulkRead { .. } | I::FastBulkRead { .. } => ins.bulk_read_entries().filter_map(|e| self.p2_at(e.id, bps)).collect(),
            _ if broadcast => {
                let mut all: Vec<usize> =
                    (0..self.devices.len()).filter(|&i| matches!(self.devices[i], Device::P2(_)) && self.hears(i, bps)).collect();
                // A broadcast PING is answered in the order of the IDs.
                all.sort_by_key(|&i| dev_id(&self.devices[i]));
                all
            }
            _ => self.p2_at(p.id, bps).into_iter().collect(),
        };
        let fast = matches!(ins, I::FastSyncRead { .. } | I::FastBulkRead { .. });
        let mut blocks: Vec<(u8, StatusError, Vec<u8>)> = Vec::new();
        for i in order {
            if reads {
                self.refresh(i);
            }
            // CLEAR fails while the joint turns (faster than a count a
            // period).
            let joint = match &self.devices[i] {
                Device::P2(s) => s.joint,
                Device::P1(_) => None,
            };
            let turning = matches!(ins, I::ClearMultiTurn)
                && joint.is_some_and(|j| self.rig.joint_state(now, j.id).rate.abs() > 1e-3);
            let Device::P2(s) = &mut self.devices[i] else { continue };
            let id = s.id();
            // A PING to the broadcast ID is answered by every servo.
            let quiet = broadcast && !multi && !matches!(ins, I::Ping);
            let answer = s.execute(&ins, quiet, turning);
            match (answer, fast) {
                (Some((e, data)), true) => blocks.push((id, e, data)),
                (Some(a), false) => {
                    let bytes = encode2(id, a);
                    self.push_reply(i, bytes, replies);
                }
                (None, _) => {}
            }
        }
        if fast {
            let expected = match ins {
                I::FastSyncRead { ids, .. } => ids.len(),
                _ => ins.bulk_read_entries().count(),
            };
            // A servo missing from the chain: its successors wait for its
            // block that never comes, so the combined reply never completes.
            if blocks.len() == expected && !blocks.is_empty() {
                if let Some(bytes) = super::p2::fast_reply(&blocks) {
                    let first = blocks[0].0;
                    let i = self.devices.iter().position(|d| dev_id(d) == first).unwrap_or(0);
                    self.push_reply(i, bytes, replies);
                }
            }
        }
        if let I::SyncWrite { .. } = ins {
            self.stats.sync_writes += 1;
            self.period_ended = true;
        }
        self.drive_all();
    }

    /// The sensor device's packet (either protocol).
    fn sensor_packet(&mut self, protocol: ServoProtocol, params: &[u8], code: u8, replies: &mut Vec<Reply>) {
        let Some(mut sensor) = self.sensor.take() else { return };
        if code == 0x02 {
            self.before_read();
            let (count, contacts) = self.rig.sensors(self.now_us);
            sensor.set(count, contacts);
        }
        let (answer, call) = sensor.execute(protocol, code, params);
        if let Some(call) = call {
            let what = match call {
                1 => {
                    self.rig.episode_ended(self.now_us);
                    "operator-ended"
                }
                _ => {
                    self.rig.episode_started(self.now_us);
                    "operator-started"
                }
            };
            self.events.push(Event { at_us: self.now_us, id: SENSOR_ID, what });
        }
        if let (Some(bytes), true) = (answer, self.sensor_answers) {
            let at_us = self.now_us + self.wire_us(bytes.len(), 50);
            replies.push(Reply { at_us, bytes });
        }
        self.sensor = Some(sensor);
    }

    /// The device of a Protocol 1.0 servo `id` that hears `bps`.
    fn p1_at(&self, id: u8, bps: u32) -> Option<usize> {
        (0..self.devices.len()).find(|&i| matches!(&self.devices[i], Device::P1(s) if s.id() == id) && self.hears(i, bps))
    }

    /// The device of a Protocol 2.0 servo `id` that hears `bps`.
    fn p2_at(&self, id: u8, bps: u32) -> Option<usize> {
        (0..self.devices.len()).find(|&i| matches!(&self.devices[i], Device::P2(s) if s.id() == id) && self.hears(i, bps))
    }

    /// The time an answer of `bytes` takes after its request at 1 Mbps
    /// plus the return delay, in real time (lock step: none).
    fn wire_us(&self, bytes: usize, return_delay_us: u64) -> u64 {
        match self.clock {
            Clock::RealTime => return_delay_us + bytes as u64 * 10,
            Clock::LockStep => 0,
        }
    }

    /// Queues device `i`'s answer, after the faults in force.
    fn push_reply(&mut self, i: usize, mut bytes: Vec<u8>, replies: &mut Vec<Reply>) {
        let id = dev_id(&self.devices[i]);
        let delay = match &self.devices[i] {
            Device::P1(s) => s.return_delay_us(),
            Device::P2(s) => s.return_delay_us(),
        };
        let mut extra = 0;
        for (k, f) in self.faults.iter().enumerate() {
            if !f.applies(self.now_us, id) {
                continue;
            }
            if !self.onsets[k] {
                self.onsets[k] = true;
                self.events.push(Event { at_us: self.now_us, id, what: f.kind.name() });
            }
            match f.kind {
                FaultKind::Drop => {
                    self.stats.faulted += 1;
                    return;
                }
                FaultKind::Corrupt => {
                    self.stats.faulted += 1;
                    let k = bytes.len().saturating_sub(3);
                    bytes[k] ^= 0x5A;
                }
                FaultKind::Delay { us } => {
                    self.stats.faulted += 1;
                    extra = extra.max(us);
                }
                FaultKind::ErrorBits { bits } => {
                    // Protocol 1.0: the error bits in the answer (Protocol
                    // 2.0's alert is raised by `raise_alerts`).
                    if let (Device::P1(_), Some(e)) = (&self.devices[i], bytes.get_mut(4)) {
                        *e |= bits.bits();
                        let n = bytes.len();
                        bytes[n - 1] = dxl1::checksum(&bytes[2..n - 1]);
                    }
                }
                FaultKind::PastLimit => {}
            }
        }
        let at_us = self.now_us + self.wire_us(bytes.len(), delay) + extra;
        replies.push(Reply { at_us, bytes });
    }
}

/// A device of `model` at `id`, hearing `bps`.
fn device(model: &'static ServoModel, id: u8, bps: u32, joint: Option<JointSpec>) -> Result<Device, String> {
    match model.protocol {
        ServoProtocol::V1 if model.model_number == rx28::RX28.model_number => {
            let baud = baud_value(&rx28::RX28, bps).ok_or_else(|| baud_error(&rx28::RX28, bps))?;
            Ok(Device::P1(P1Servo::new(id, baud, joint)))
        }
        ServoProtocol::V1 => Err(format!(
            "a virtual {} is not emulated on Protocol 1.0: valid models are RX-28, XM430-W350, XL430-W250, XL330-M288",
            model.name
        )),
        ServoProtocol::Feetech if model.model_number == sts3215::STS3215_MODEL => {
            let baud = baud_value(&sts3215::STS3215, bps).ok_or_else(|| baud_error(&sts3215::STS3215, bps))?;
            Ok(Device::P1(P1Servo::of(&super::ft::STS3215_LAYOUT, id, baud, joint)))
        }
        ServoProtocol::Feetech => Err(format!("a virtual {} is not emulated on Feetech's protocol: the valid model is STS3215", model.name)),
        ServoProtocol::V2 => {
            let table = control_table::by_model_number(model.model_number)
                .ok_or_else(|| format!("no control table of {} (model {})", model.name, model.model_number))?;
            let baud = baud_value(table, bps).ok_or_else(|| baud_error(table, bps))?;
            Ok(Device::P2(P2Servo::new(model, table, id, baud, joint)))
        }
    }
}

fn baud_error(table: &control_table::ControlTable, bps: u32) -> String {
    let valid: Vec<String> = match table.protocol {
        pada_core::dynamixel::Protocol::V1 => vec!["9600".into(), "57600".into(), "115200".into(), "1000000".into(), "2000000/(n+1)".into()],
        pada_core::dynamixel::Protocol::V2 | pada_core::dynamixel::Protocol::Feetech => {
            table.baud_rates.iter().map(u32::to_string).collect()
        }
    };
    format!("--baud {bps}: the {} takes no such rate; valid are {}", table.model, valid.join(", "))
}

fn dev_id(d: &Device) -> u8 {
    match d {
        Device::P1(s) => s.id(),
        Device::P2(s) => s.id(),
    }
}

/// The Hardware Error Status bit of an `error-bits` fault's name.
pub(crate) fn hardware_error_of(bits: ErrorFlags) -> HardwareError {
    match bits {
        ErrorFlags::OVERLOAD => HardwareError::OVERLOAD,
        ErrorFlags::INPUT_VOLTAGE => HardwareError::INPUT_VOLTAGE,
        _ => HardwareError::OVERHEATING,
    }
}

fn encode1(id: u8, (error, params): (ErrorFlags, Vec<u8>)) -> Vec<u8> {
    let mut buf = vec![0u8; params.len() + 16];
    dxl1::StatusPacket::<PACKET_LEN>::new(id, error, &params)
        .and_then(|p| p.encode(&mut buf).map(<[u8]>::to_vec))
        .unwrap_or_default()
}

fn encode2(id: u8, answer: (StatusError, Vec<u8>)) -> Vec<u8> {
    super::p2::encode(id, answer)
}
