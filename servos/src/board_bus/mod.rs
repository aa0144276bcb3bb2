//! The Dynamixel bus emulator: RX-28 servos (Protocol 1.0), X-series
//! servos (Protocol 2.0, [`v2`]), Feetech's STS3215 ([`ft`]) and the sensor device,
//! answering the firmware's instruction packets at the times a real 1 Mbps
//! bus would, backed by a [`Rig`], with `--fault` injection.
//!
//! Timing: a byte takes [`BYTE_US`] on the wire (8N1 at 1 Mbps). The
//! firmware's bytes of one lock-step instant go out back to back; a packet
//! takes effect when its last byte is in, and a servo answers after its
//! Return Delay Time (2 µs units, control-table address 5) with a status
//! packet that is delivered whole when its last byte is in.
//!
//! [`BusEmulator::forecast`] computes the answer a request would get,
//! without changing anything (the rig is only peeked at): the SIL run's
//! forecasts. [`BusEmulator::receive`] computes the same answer when the
//! request comes, with its effects (counters, fault traces, the present
//! values in the control table).

pub mod carried;
pub mod ft;
pub mod v2;

use ft::{FtAnswer, FtServos};
use v2::{self as bus_v2, XServos};
use crate::fault::{FaultKind, FaultSpec};
use pada_sim::rig::Rig;
use pada_core::dynamixel::table::PresentState;
use pada_core::dynamixel::{table, ErrorFlags, Instruction, InstructionDecoder, StatusPacket, BROADCAST_ID};
use pada_core::robot::RobotSpec;
use pada_core::safety::SoftLimit;
use pada_core::robot::JointSpec as Joint;
use pada_firmware::sil::{sensor_table, SENSOR_ID};
use serde::Serialize;

/// Microseconds per byte at 1 Mbps, 8N1.
pub const BYTE_US: u64 = 10;

pub use crate::fault::PAST_LIMIT_RAD;

/// A status packet on its way to the firmware.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reply {
    /// When its last byte is in \[µs\].
    pub at_us: u64,
    /// The bytes.
    pub bytes: Vec<u8>,
    /// The request it answers.
    pub request: Vec<u8>,
}

/// One emulated RX-28: its control table, and the joint it drives.
#[derive(Debug, Clone)]
struct Servo {
    id: u8,
    table: [u8; table::TABLE_LEN],
    /// The firmware's calibration of the joint and its soft limit.
    joint: Option<(Joint, Option<SoftLimit>)>,
}

impl Servo {
    /// Factory settings of an RX-28 at 1 Mbps, as `pada servos`' RX-28 has
    /// them (the firmware writes wheel mode, return delay and status return
    /// level itself).
    fn new(id: u8, joint: Option<(Joint, Option<SoftLimit>)>) -> Self {
        let t = crate::p1::factory_table(id, table::BAUD_1MBPS);
        Servo { id, table: t, joint }
    }

    fn torque(&self) -> bool {
        self.table[table::TORQUE_ENABLE as usize] != 0
    }

    fn moving_speed(&self) -> u16 {
        u16::from_le_bytes([self.table[table::MOVING_SPEED as usize], self.table[table::MOVING_SPEED as usize + 1]])
    }

    fn return_delay_us(&self) -> u64 {
        self.table[table::RETURN_DELAY_TIME as usize] as u64 * 2
    }

    fn status_return_level(&self) -> u8 {
        self.table[table::STATUS_RETURN_LEVEL as usize]
    }

    /// The voltage its Moving Speed applies in wheel mode \[V\].
    fn volts(&self, supply: f64) -> f64 {
        table::ratio_from_moving_speed(self.moving_speed()) as f64 * supply
    }

    /// `table` with the present values `p`.
    fn with_present(mut table: [u8; table::TABLE_LEN], p: &PresentState) -> [u8; table::TABLE_LEN] {
        let mut put16 = |addr: u8, v: u16| table[addr as usize..addr as usize + 2].copy_from_slice(&v.to_le_bytes());
        put16(table::PRESENT_POSITION, p.position);
        put16(table::PRESENT_SPEED, p.speed);
        put16(table::PRESENT_LOAD, p.load);
        table[table::PRESENT_VOLTAGE as usize] = p.voltage;
        table[table::PRESENT_TEMPERATURE as usize] = p.temperature;
        table
    }
}

/// Counters of the emulated bus.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct BusStats {
    /// Bytes the firmware sent.
    pub bytes_in: u64,
    /// Instruction packets decoded.
    pub packets: u64,
    /// Bytes skipped or packets rejected by the instruction decoder.
    pub bad_packets: u64,
    /// Status packets sent (after faults).
    pub replies: u64,
    /// Answers dropped by a fault.
    pub dropped: u64,
    /// Answers corrupted by a fault.
    pub corrupted: u64,
    /// Answers delayed by a fault.
    pub delayed: u64,
    /// Answers with injected error bits.
    pub error_bits: u64,
    /// Readings past a joint's soft limit (a `past-limit` fault).
    pub past_limit: u64,
}

/// What a fault window did, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FaultTrace {
    /// The first answer the fault affected \[µs\].
    pub onset_us: Option<u64>,
    /// Whether every servo had torque at the onset.
    pub torque_at_onset: bool,
    /// The first time after the onset that every servo had torque off
    /// \[µs\].
    pub torque_off_us: Option<u64>,
    /// The first time after the window that every servo had torque on
    /// again \[µs\].
    pub torque_on_again_us: Option<u64>,
}

/// An answer, and what giving it changes besides.
#[derive(Debug, Clone, Default)]
struct Answer {
    reply: Option<Reply>,
    /// Fault windows whose first affected answer this is.
    onsets: Vec<usize>,
    dropped: bool,
    corrupted: bool,
    delayed: bool,
    flagged: bool,
    past_limit: bool,
}

/// Servos `ids` with the calibration and soft limits of `robot`'s joints.
fn servos(robot: &RobotSpec, ids: &[u8]) -> Vec<Servo> {
    let joint_of = |id: u8| {
        let joint = robot.joints.iter().find(|j| j.id == id)?;
        Some((*joint, joint.soft_limit))
    };
    ids.iter().map(|&id| Servo::new(id, joint_of(id))).collect()
}

/// Why a fault cannot apply to `servos`: no such servo, or a `past-limit`
/// fault on a joint without a soft limit.
fn check_faults_on(servos: &[Servo], robot: &RobotSpec, faults: &[FaultSpec]) -> Result<(), String> {
    for f in faults {
        let Some(servo) = servos.iter().find(|s| s.id == f.servo) else {
            let ids: Vec<String> = servos.iter().map(|s| s.id.to_string()).collect();
            return Err(format!("--fault {f}: no servo {} on {}'s bus (its servos: {})", f.servo, robot.name, ids.join(", ")));
        };
        let feetech = servo.joint.is_some_and(|(j, _)| j.servo.protocol == pada_core::servo::ServoProtocol::Feetech);
        if f.kind == FaultKind::PastLimit && feetech {
            let valid = "valid: drop, corrupt, delay, error-bits";
            return Err(format!("--fault {f}: past-limit is not emulated on servo {}'s Feetech STS3215 ({valid})", f.servo));
        }
        if f.kind == FaultKind::PastLimit && servo.joint.is_none_or(|(_, l)| l.is_none()) {
            return Err(format!("--fault {f}: servo {}'s joint has no soft limit on {}", f.servo, robot.name));
        }
    }
    Ok(())
}

/// Checks `faults` against `robot`'s servos (the IDs of its hardware
/// configuration, which the rigs use) before a run, so that a fault that
/// cannot apply is bad input, not a failed run.
pub fn check_faults(robot: &RobotSpec, faults: &[FaultSpec]) -> Result<(), String> {
    let ids: Vec<u8> = robot.joints.iter().map(|j| j.id).collect();
    check_faults_on(&servos(robot, &ids), robot, faults)
}

/// The emulated bus.
#[derive(Debug)]
pub struct BusEmulator {
    decoder: InstructionDecoder<64>,
    servos: Vec<Servo>,
    /// The Protocol 2.0 servos, if the robot has any.
    x: Option<XServos>,
    /// The Feetech servos, if the robot has any.
    ft: Option<FtServos>,
    /// Whether Protocol 1.0 is spoken (an RX-28, or the sensor device).
    p1: bool,
    /// Where the Protocol 2.0 packet being received started in the bytes.
    x_start: usize,
    sensor: [u8; sensor_table::TABLE_LEN],
    faults: Vec<FaultSpec>,
    traces: Vec<FaultTrace>,
    stats: BusStats,
    supply_v: f64,
    /// Watching for every servo's torque off from this instant (a reset).
    off_watch: Option<(u64, Option<u64>)>,
}

impl BusEmulator {
    /// Servos with the rig's IDs (the calibration and soft limits of
    /// `robot`'s joints), the sensor device, and `faults`; the error says
    /// why a fault cannot apply.
    pub fn new(rig: &dyn Rig, robot: &RobotSpec, faults: Vec<FaultSpec>) -> Result<Self, String> {
        carried::check_servos(robot)?;
        let mut servos = servos(robot, rig.servo_ids());
        check_faults_on(&servos, robot, &faults)?;
        let x = XServos::new(robot, rig.servo_ids(), rig.supply_v())?;
        let ft = FtServos::new(robot, rig.servo_ids(), rig.supply_v())?;
        let v1 = |id: u8| robot.joints.iter().all(|j| j.id != id || j.servo.protocol == pada_core::servo::ServoProtocol::V1);
        servos.retain(|s| v1(s.id));
        let p1 = x.is_none() || !servos.is_empty() || ft.is_some();
        let mut sensor = [0u8; sensor_table::TABLE_LEN];
        sensor[sensor_table::MODEL_NUMBER as usize..][..2].copy_from_slice(&sensor_table::MODEL.to_le_bytes());
        sensor[table::ID as usize] = SENSOR_ID;
        let traces = vec![FaultTrace::default(); faults.len()];
        Ok(BusEmulator {
            decoder: InstructionDecoder::new(),
            servos,
            x,
            ft,
            p1,
            x_start: 0,
            sensor,
            faults,
            traces,
            stats: BusStats::default(),
            supply_v: rig.supply_v(),
            off_watch: None,
        })
    }

    /// A power cut at `t_us`: every servo loses its supply and comes back
    /// with its factory control table (torque off, Moving Speed 0); the
    /// joints go limp.
    pub fn power_off(&mut self, t_us: u64, rig: &mut dyn Rig) {
        for s in &mut self.servos {
            *s = Servo::new(s.id, s.joint);
            rig.drive(t_us, s.id, false, 0.0);
        }
        if let Some(x) = &mut self.x {
            x.power_off(t_us, rig);
        }
        if let Some(ft) = &mut self.ft {
            ft.power_off(t_us, rig);
        }
    }

    /// Every servo's torque (both protocols).
    fn torques(&self) -> Vec<bool> {
        let mut all: Vec<bool> = self.servos.iter().map(Servo::torque).collect();
        all.extend(self.x.iter().flat_map(|x| x.torques().map(|(_, on)| on)));
        all.extend(self.ft.iter().flat_map(|ft| ft.torques().map(|(_, on)| on)));
        all
    }

    /// From `t_us` on (a reset), notes the first instant every servo has
    /// torque off ([`all_off_since`](Self::all_off_since)).
    pub fn watch_torque_off(&mut self, t_us: u64) {
        let now = self.torques().iter().all(|on| !on).then_some(t_us);
        self.off_watch = Some((t_us, now));
    }

    /// The first instant every servo had torque off since the last
    /// [`watch_torque_off`](Self::watch_torque_off).
    pub fn all_off_since(&self) -> Option<u64> {
        self.off_watch.and_then(|w| w.1)
    }

    /// Counters so far.
    pub fn stats(&self) -> BusStats {
        self.stats
    }

    /// The faults and what each did.
    pub fn faults(&self) -> impl Iterator<Item = (&FaultSpec, &FaultTrace)> {
        self.faults.iter().zip(&self.traces)
    }

    /// Whether servo `id` has torque.
    pub fn torque(&self, id: u8) -> Option<bool> {
        let x = self.x.iter().flat_map(|x| x.torques()).chain(self.ft.iter().flat_map(|f| f.torques())).find(|s| s.0 == id).map(|s| s.1);
        self.servos.iter().find(|s| s.id == id).map(Servo::torque).or(x)
    }

    /// Takes the bytes the firmware sent at `now_us`; returns the answers
    /// they cause, in time order.
    pub fn receive(&mut self, now_us: u64, bytes: &[u8], rig: &mut dyn Rig) -> Vec<Reply> {
        let mut replies = Vec::new();
        let mut start = 0;
        self.x_start = 0;
        for (i, &b) in bytes.iter().enumerate() {
            self.stats.bytes_in += 1;
            if let Some(reply) = self.receive2(now_us, bytes, i, rig) {
                replies.extend(reply);
            }
            if !self.p1 {
                continue;
            }
            let Some(result) = self.decoder.push(b) else {
                continue;
            };
            let request = bytes[start..=i].to_vec();
            start = i + 1;
            let Ok(packet) = result else {
                self.stats.bad_packets += 1;
                continue;
            };
            if self.ft.as_ref().is_some_and(|ft| packet.id != SENSOR_ID && ft.concerns(packet.id, packet.code)) {
                self.stats.packets += 1;
                let done = now_us + (i as u64 + 1) * BYTE_US;
                replies.extend(self.receive_ft(done, packet.id, packet.code, &packet.params, &request, rig));
                continue;
            }
            let Ok(instruction) = packet.instruction() else {
                self.stats.bad_packets += 1;
                continue;
            };
            self.stats.packets += 1;
            // The packet's last byte is in.
            let done = now_us + (i as u64 + 1) * BYTE_US;
            if let Some(reply) = self.execute(packet.id, &instruction, done, &request, rig) {
                replies.push(reply);
            }
        }
        replies.sort_by_key(|r| r.at_us);
        replies
    }

    /// The answer `request` would get if the firmware sent it at `at_us`
    /// (one whole READ or PING of one device), without changing anything;
    /// `None` if it gets none or the rig cannot tell yet.
    pub fn forecast(&self, at_us: u64, request: &[u8], rig: &dyn Rig) -> Option<Reply> {
        // The rigs cannot tell an X-series reading without simulating
        // ahead: no forecasts on Protocol 2.0.
        if self.x.is_some() || self.ft.is_some() || self.decoder.buffered() > 0 {
            // Bytes of an unfinished packet would come first.
            return None;
        }
        let mut decoder: InstructionDecoder<64> = InstructionDecoder::new();
        let packets: Vec<_> = decoder.feed(request).collect();
        let [Ok(packet)] = packets.as_slice() else { return None };
        if decoder.buffered() > 0 {
            return None;
        }
        let done = at_us + request.len() as u64 * BYTE_US;
        let ins = packet.instruction().ok()?;
        if packet.id == SENSOR_ID {
            let (count, contacts) = rig.peek_sensors(done)?;
            return self.sensor_answer(&ins, done, count, contacts, request);
        }
        let i = self.servos.iter().position(|s| s.id == packet.id)?;
        let answer = match ins {
            Instruction::Ping => self.answer(i, done, ErrorFlags::NONE, &[], request),
            Instruction::Read { addr, len } => {
                let present = self.plant_present(i, done, rig.peek_present(done, packet.id)?);
                let table = Servo::with_present(self.servos[i].table, &present.0);
                self.read_answer(i, &table, addr, len, done, request, present.1)?
            }
            _ => return None,
        };
        answer.reply
    }

    fn execute(&mut self, id: u8, ins: &Instruction<'_>, t: u64, request: &[u8], rig: &mut dyn Rig) -> Option<Reply> {
        if id == SENSOR_ID {
            let (count, contacts) = rig.sensors(t);
            let enc = sensor_table::ENCODER_COUNT as usize;
            self.sensor[enc..enc + 2].copy_from_slice(&count.to_le_bytes());
            self.sensor[sensor_table::CONTACTS as usize] = contacts;
            let reply = self.sensor_answer(ins, t, count, contacts, request);
            self.stats.replies += reply.is_some() as u64;
            return reply;
        }
        let targets: Vec<usize> = self
            .servos
            .iter()
            .enumerate()
            .filter(|(_, s)| s.id == id || id == BROADCAST_ID)
            .map(|(i, _)| i)
            .collect();
        match *ins {
            Instruction::Ping => {
                let &[i] = targets.as_slice() else {
                    return None;
                };
                let a = self.answer(i, t, ErrorFlags::NONE, &[], request);
                self.apply(i, t, a)
            }
            Instruction::Read { addr, len } => {
                let &[i] = targets.as_slice() else {
                    return None;
                };
                let (present, past_limit) = self.plant_present(i, t, rig.present(t, id));
                self.servos[i].table = Servo::with_present(self.servos[i].table, &present);
                let table = self.servos[i].table;
                let a = self.read_answer(i, &table, addr, len, t, request, past_limit)?;
                self.apply(i, t, a)
            }
            Instruction::Write { addr, data } | Instruction::RegWrite { addr, data } => {
                for &i in &targets {
                    self.write(i, addr, data, t, rig);
                }
                let &[i] = targets.as_slice() else {
                    return None;
                };
                if id == BROADCAST_ID || self.servos[i].status_return_level() < 2 {
                    return None;
                }
                let a = self.answer(i, t, ErrorFlags::NONE, &[], request);
                self.apply(i, t, a)
            }
            Instruction::SyncWrite { addr, .. } => {
                let entries: Vec<(u8, Vec<u8>)> = ins.sync_entries().map(|(sid, d)| (sid, d.to_vec())).collect();
                for (sid, data) in entries {
                    if let Some(i) = self.servos.iter().position(|s| s.id == sid) {
                        self.write(i, addr, &data, t, rig);
                    }
                }
                None
            }
            Instruction::Action | Instruction::Reset | Instruction::BulkRead { .. } => None,
        }
    }

    /// What servo `i` reads at `t`: the rig's state, or a joint past its
    /// soft limit while a `past-limit` fault applies (and whether it did).
    fn plant_present(&self, i: usize, t: u64, mut p: PresentState) -> (PresentState, bool) {
        let s = &self.servos[i];
        let past = self.faults.iter().any(|f| f.kind == FaultKind::PastLimit && f.applies(t, s.id));
        if let (true, Some((joint, Some(limit)))) = (past, s.joint) {
            let angle = limit.max + PAST_LIMIT_RAD;
            p.position = joint.position_of(angle as f64);
        }
        (p, past)
    }

    /// Servo `i`'s answer to READ `addr`, `len` with its control table
    /// `table`, if it answers reads.
    #[allow(clippy::too_many_arguments)]
    fn read_answer(
        &self,
        i: usize,
        table: &[u8; table::TABLE_LEN],
        addr: u8,
        len: u8,
        t: u64,
        request: &[u8],
        past_limit: bool,
    ) -> Option<Answer> {
        let (addr, len) = (addr as usize, len as usize);
        let (error, params) = match table.get(addr..addr + len) {
            Some(data) => (ErrorFlags::NONE, data.to_vec()),
            None => (ErrorFlags::RANGE, Vec::new()),
        };
        if self.servos[i].status_return_level() == 0 {
            return None;
        }
        let mut a = self.answer(i, t, error, &params, request);
        a.past_limit = past_limit;
        Some(a)
    }

    /// The sensor device's answer: READ of its table with the encoder and
    /// contacts of this instant, or PING; it never faults (it stands for
    /// timer and GPIO peripherals).
    fn sensor_answer(&self, ins: &Instruction<'_>, t: u64, count: u16, contacts: u8, request: &[u8]) -> Option<Reply> {
        let mut sensor = self.sensor;
        let enc = sensor_table::ENCODER_COUNT as usize;
        sensor[enc..enc + 2].copy_from_slice(&count.to_le_bytes());
        sensor[sensor_table::CONTACTS as usize] = contacts;
        let params = match *ins {
            Instruction::Ping => Vec::new(),
            Instruction::Read { addr, len } => sensor.get(addr as usize..addr as usize + len as usize).map(<[u8]>::to_vec)?,
            _ => return None,
        };
        let status = StatusPacket::<64>::new(SENSOR_ID, ErrorFlags::NONE, &params).ok()?;
        let mut buf = [0u8; 80];
        let bytes = status.encode(&mut buf).ok()?.to_vec();
        // The sensor device answers after the servos' 50 µs.
        Some(Reply { at_us: t + 50 + bytes.len() as u64 * BYTE_US, bytes, request: request.to_vec() })
    }

    fn write(&mut self, i: usize, addr: u8, data: &[u8], t: u64, rig: &mut dyn Rig) {
        let start = addr as usize;
        let end = (start + data.len()).min(table::TABLE_LEN);
        if start >= end {
            return;
        }
        self.servos[i].table[start..end].copy_from_slice(&data[..end - start]);
        let s = &self.servos[i];
        rig.drive(t, s.id, s.torque(), s.volts(self.supply_v));
        self.torque_changed(t);
    }

    /// Notes every servo's torque at `t` for the reset watch and the fault
    /// traces.
    fn torque_changed(&mut self, t: u64) {
        let torques = self.torques();
        let all_off = torques.iter().all(|on| !on);
        let all_on = torques.iter().all(|on| *on);
        if let Some((from, None)) = self.off_watch {
            if all_off && t >= from {
                self.off_watch = Some((from, Some(t)));
            }
        }
        for (f, trace) in self.faults.iter().zip(self.traces.iter_mut()) {
            let Some(onset) = trace.onset_us else { continue };
            if all_off && trace.torque_off_us.is_none() && t >= onset {
                trace.torque_off_us = Some(t);
            }
            if all_on && trace.torque_off_us.is_some() && trace.torque_on_again_us.is_none() && t >= f.end_us {
                trace.torque_on_again_us = Some(t);
            }
        }
    }

    /// The faults in force on an answer, those `hit` says apply to it (at
    /// its time, to its servos), in the order given, up to the first that drops it: the answer
    /// with its onsets, `dropped`, `corrupted` and `past_limit` set, the
    /// longest delay \[µs\] and the error bits of every `error-bits` fault.
    fn in_force(&self, hit: impl Fn(&FaultSpec) -> bool) -> (Answer, u64, ErrorFlags) {
        let (mut a, mut delay, mut bits) = (Answer::default(), 0, ErrorFlags::NONE);
        for (k, (f, trace)) in self.faults.iter().zip(&self.traces).enumerate() {
            if !hit(f) {
                continue;
            }
            if trace.onset_us.is_none() {
                a.onsets.push(k);
            }
            match f.kind {
                FaultKind::Drop => {
                    a.dropped = true;
                    break;
                }
                FaultKind::Corrupt => a.corrupted = true,
                FaultKind::Delay { us } => delay = delay.max(us),
                FaultKind::ErrorBits { bits: b } => bits = bits | b,
                FaultKind::PastLimit => a.past_limit = true,
            }
        }
        (a, delay, bits)
    }

    /// Servo `i`'s status packet at `t`, after the faults in force then;
    /// changes nothing ([`apply`](Self::apply) does).
    fn answer(&self, i: usize, t: u64, mut error: ErrorFlags, params: &[u8], request: &[u8]) -> Answer {
        let id = self.servos[i].id;
        let (mut a, delay, bits) = self.in_force(|f| f.applies(t, id));
        if a.dropped {
            return a;
        }
        // On Protocol 1.0 the error bits ride on the answer; a `past-limit`
        // fault makes the reading itself past the limit (`plant_present`).
        error = error | bits;
        a.past_limit = false;
        let Ok(status) = StatusPacket::<64>::new(id, error, params) else { return a };
        let mut buf = [0u8; 80];
        let Ok(bytes) = status.encode(&mut buf) else { return a };
        let mut bytes = bytes.to_vec();
        if a.corrupted {
            // Flip bits of the first parameter (or the error byte): the
            // checksum no longer matches.
            let k = if bytes.len() > 6 { 5 } else { 4 };
            bytes[k] ^= 0x5A;
        }
        a.delayed = delay > 0;
        a.flagged = !error.is_empty();
        let at_us = t + self.servos[i].return_delay_us() + bytes.len() as u64 * BYTE_US + delay;
        a.reply = Some(Reply { at_us, bytes, request: request.to_vec() });
        a
    }

    /// A Protocol 2.0 answer at `t` after the faults in force then on any
    /// servo whose answer it carries (a fast reply is lost with any block;
    /// the hardware alert was raised by the servo itself); changes nothing.
    fn answer2(&self, t: u64, x: bus_v2::XAnswer, request: &[u8]) -> Answer {
        // The sensor device's answers are never faulted; a servo's hardware
        // alert was raised by the servo itself (`bus_v2`), not here.
        let (mut a, delay, _) = if x.sensor {
            (Answer::default(), 0, ErrorFlags::NONE)
        } else {
            self.in_force(|f| x.ids.iter().any(|&id| f.applies(t, id)))
        };
        if a.dropped {
            return a;
        }
        let mut bytes = x.bytes;
        if a.corrupted {
            // The first parameter (or the ERROR byte): the CRC no longer
            // matches.
            let k = if bytes.len() > 11 { 9 } else { 8 };
            bytes[k] ^= 0x5A;
        }
        a.delayed = delay > 0;
        a.flagged = x.alert;
        let at_us = t + x.return_delay_us + bytes.len() as u64 * BYTE_US + delay;
        a.reply = Some(Reply { at_us, bytes, request: request.to_vec() });
        a
    }

    /// Byte `i` of `bytes` (sent from `now_us`) to the Protocol 2.0
    /// servos: the answers to the packet it ends, if it ends one.
    fn receive2(&mut self, now_us: u64, bytes: &[u8], i: usize, rig: &mut dyn Rig) -> Option<Vec<Reply>> {
        let result = self.x.as_mut()?.push(bytes[i])?;
        let request = bytes[self.x_start.min(i)..=i].to_vec();
        self.x_start = i + 1;
        let Ok(packet) = result else {
            self.stats.bad_packets += 1;
            return None;
        };
        self.stats.packets += 1;
        let done = now_us + (i as u64 + 1) * BYTE_US;
        // Torque as the packet found it: an alert it raises shuts its servo
        // down at once (Shutdown), and the onset is judged before that.
        let all_on_before = self.torques().iter().all(|on| *on);
        let x = self.x.as_mut()?;
        let answers = {
            let rig_cell = std::cell::RefCell::new(&mut *rig);
            let mut read = |id: u8| Some(rig_cell.borrow_mut().joint_state(done, id));
            let mut sensors = || Some(rig_cell.borrow_mut().sensors(done));
            x.execute(&packet, done, &self.faults, &mut read, &mut sensors).unwrap_or_default()
        };
        if bus_v2::drives(&packet) {
            x.drive(done, rig);
            self.torque_changed(done);
        }
        let mut replies = Vec::new();
        for answer in answers {
            let sensor = answer.sensor;
            let a = self.answer2(done, answer, &request);
            let reply = if sensor {
                self.stats.replies += a.reply.is_some() as u64;
                a.reply
            } else {
                self.apply_with(done, a, all_on_before)
            };
            replies.extend(reply);
        }
        Some(replies)
    }

    /// A packet to the Feetech servos, complete at `t`: their answers one
    /// after the other, after the faults in force on each (error bits ride
    /// on the Status byte, whose bits are Protocol 1.0's there).
    fn receive_ft(&mut self, t: u64, id: u8, code: u8, params: &[u8], request: &[u8], rig: &mut dyn Rig) -> Vec<Reply> {
        let all_on = self.torques().iter().all(|on| *on);
        let answers = self.ft.as_mut().map(|ft| ft.execute(id, code, params, t, rig)).unwrap_or_default();
        self.torque_changed(t);
        let mut replies = Vec::new();
        let mut at = t;
        for FtAnswer { id, mut bytes, return_delay_us } in answers {
            let (mut a, delay, bits) = self.in_force(|f| f.applies(t, id));
            if !a.dropped && bytes.len() > 5 {
                let n = bytes.len();
                bytes[4] |= bits.bits();
                bytes[n - 1] = pada_core::dynamixel::checksum(&bytes[2..n - 1]);
                bytes[if n > 6 { 5 } else { 4 }] ^= if a.corrupted { 0x5A } else { 0 };
                (a.delayed, a.flagged, a.past_limit) = (delay > 0, bytes[4] != 0, false);
                at += return_delay_us + bytes.len() as u64 * BYTE_US + delay;
                a.reply = Some(Reply { at_us: at, bytes, request: request.to_vec() });
            }
            replies.extend(self.apply_with(t, a, all_on));
        }
        replies
    }

    /// Counts `a` and opens the fault windows it is the onset of.
    fn apply(&mut self, _i: usize, t: u64, a: Answer) -> Option<Reply> {
        let all_on = self.torques().iter().all(|on| *on);
        self.apply_with(t, a, all_on)
    }

    /// [`Self::apply`] with the torque at the onset given (`all_on`: every
    /// servo's torque was on).
    fn apply_with(&mut self, t: u64, a: Answer, all_on: bool) -> Option<Reply> {
        for k in a.onsets {
            self.traces[k].onset_us = Some(t);
            self.traces[k].torque_at_onset = all_on;
        }
        self.stats.dropped += a.dropped as u64;
        self.stats.corrupted += a.corrupted as u64;
        self.stats.delayed += a.delayed as u64;
        self.stats.error_bits += a.flagged as u64;
        self.stats.past_limit += a.past_limit as u64;
        self.stats.replies += a.reply.is_some() as u64;
        a.reply
    }
}

#[cfg(test)]
mod tests;
