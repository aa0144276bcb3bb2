//! The Dynamixel bus emulator: RX-28 servos and the sensor device,
//! answering the firmware's instruction packets at the times a real 1 Mbps
//! bus would, backed by a [`Rig`], with `--fault` injection.
//!
//! Timing: a byte takes [`BYTE_US`] on the wire (8N1 at 1 Mbps). The
//! firmware's bytes of one lock-step instant go out back to back; a packet
//! takes effect when its last byte is in, and a servo answers after its
//! Return Delay Time (2 µs units, control-table address 5) with a status
//! packet that is delivered whole when its last byte is in.

use super::fault::{FaultKind, FaultSpec};
use crate::rig::Rig;
use pada_core::dynamixel::{
    table, ErrorFlags, Instruction, InstructionDecoder, StatusPacket, BROADCAST_ID,
};
use pada_firmware::sil::{sensor_table, SENSOR_ID};
use serde::Serialize;

/// Microseconds per byte at 1 Mbps, 8N1.
pub const BYTE_US: u64 = 10;

/// A status packet on its way to the firmware.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reply {
    /// When its last byte is in \[µs\].
    pub at_us: u64,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// One emulated RX-28: its control table.
#[derive(Debug, Clone)]
struct Servo {
    id: u8,
    table: [u8; table::TABLE_LEN],
}

impl Servo {
    /// Factory settings of an RX-28 at 1 Mbps (the firmware writes wheel
    /// mode, return delay and status return level itself).
    fn new(id: u8) -> Self {
        let mut t = [0u8; table::TABLE_LEN];
        t[table::MODEL_NUMBER as usize..][..2].copy_from_slice(&table::RX28_MODEL.to_le_bytes());
        t[table::FIRMWARE_VERSION as usize] = 0x24;
        t[table::ID as usize] = id;
        t[table::BAUD_RATE as usize] = table::BAUD_1MBPS;
        t[table::RETURN_DELAY_TIME as usize] = 250;
        t[table::CCW_ANGLE_LIMIT as usize..][..2]
            .copy_from_slice(&table::POSITION_MAX.to_le_bytes());
        t[table::HIGHEST_LIMIT_TEMPERATURE as usize] = 80;
        t[table::LOWEST_LIMIT_VOLTAGE as usize] = 60;
        t[table::HIGHEST_LIMIT_VOLTAGE as usize] = 160;
        t[table::MAX_TORQUE as usize..][..2].copy_from_slice(&table::MAGNITUDE_MAX.to_le_bytes());
        t[table::STATUS_RETURN_LEVEL as usize] = 2;
        t[table::ALARM_LED as usize] = 0x24;
        t[table::ALARM_SHUTDOWN as usize] = 0x24;
        t[table::TORQUE_LIMIT as usize..][..2].copy_from_slice(&table::MAGNITUDE_MAX.to_le_bytes());
        Servo { id, table: t }
    }

    fn torque(&self) -> bool {
        self.table[table::TORQUE_ENABLE as usize] != 0
    }

    fn moving_speed(&self) -> u16 {
        u16::from_le_bytes([
            self.table[table::MOVING_SPEED as usize],
            self.table[table::MOVING_SPEED as usize + 1],
        ])
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
}

/// What a fault window did, for the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FaultTrace {
    /// The first answer the fault affected \[µs\].
    pub onset_us: Option<u64>,
    /// Whether the affected servo had torque at the onset.
    pub torque_at_onset: bool,
    /// The first time after the onset that the servo's torque went off
    /// \[µs\].
    pub torque_off_us: Option<u64>,
    /// The first time after the window that its torque came back on \[µs\].
    pub torque_on_again_us: Option<u64>,
}

/// The emulated bus.
pub struct BusEmulator {
    decoder: InstructionDecoder<64>,
    servos: Vec<Servo>,
    sensor: [u8; sensor_table::TABLE_LEN],
    faults: Vec<FaultSpec>,
    traces: Vec<FaultTrace>,
    stats: BusStats,
    supply_v: f64,
}

impl BusEmulator {
    /// Servos with the rig's IDs, the sensor device, and `faults`.
    pub fn new(rig: &dyn Rig, supply_v: f64, faults: Vec<FaultSpec>) -> Self {
        let mut sensor = [0u8; sensor_table::TABLE_LEN];
        sensor[sensor_table::MODEL_NUMBER as usize..][..2]
            .copy_from_slice(&sensor_table::MODEL.to_le_bytes());
        sensor[table::ID as usize] = SENSOR_ID;
        let traces = vec![FaultTrace::default(); faults.len()];
        BusEmulator {
            decoder: InstructionDecoder::new(),
            servos: rig.servo_ids().iter().map(|&id| Servo::new(id)).collect(),
            sensor,
            faults,
            traces,
            stats: BusStats::default(),
            supply_v,
        }
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
        self.servos.iter().find(|s| s.id == id).map(Servo::torque)
    }

    /// Takes the bytes the firmware sent at `now_us`; returns the answers
    /// they cause, in time order.
    pub fn receive(&mut self, now_us: u64, bytes: &[u8], rig: &mut dyn Rig) -> Vec<Reply> {
        let mut replies = Vec::new();
        for (i, &b) in bytes.iter().enumerate() {
            self.stats.bytes_in += 1;
            let Some(result) = self.decoder.push(b) else {
                continue;
            };
            let Ok(packet) = result else {
                self.stats.bad_packets += 1;
                continue;
            };
            let Ok(instruction) = packet.instruction() else {
                self.stats.bad_packets += 1;
                continue;
            };
            self.stats.packets += 1;
            // The packet's last byte is in.
            let done = now_us + (i as u64 + 1) * BYTE_US;
            if let Some(reply) = self.execute(packet.id, &instruction, done, rig) {
                replies.push(reply);
            }
        }
        replies.sort_by_key(|r| r.at_us);
        replies
    }

    fn execute(
        &mut self,
        id: u8,
        ins: &Instruction<'_>,
        t: u64,
        rig: &mut dyn Rig,
    ) -> Option<Reply> {
        if id == SENSOR_ID {
            return self.sensor_device(ins, t, rig);
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
                self.answer(i, t, ErrorFlags::NONE, &[])
            }
            Instruction::Read { addr, len } => {
                let &[i] = targets.as_slice() else {
                    return None;
                };
                self.refresh_present(i, t, rig);
                let (addr, len) = (addr as usize, len as usize);
                let table = &self.servos[i].table;
                let (error, params) = match table.get(addr..addr + len) {
                    Some(data) => (ErrorFlags::NONE, data.to_vec()),
                    None => (ErrorFlags::RANGE, Vec::new()),
                };
                if self.servos[i].status_return_level() == 0 {
                    return None;
                }
                self.answer(i, t, error, &params)
            }
            Instruction::Write { addr, data } | Instruction::RegWrite { addr, data } => {
                for &i in &targets {
                    self.write(i, addr, data, t, rig);
                }
                let &[i] = targets.as_slice() else {
                    return None;
                };
                (id != BROADCAST_ID && self.servos[i].status_return_level() >= 2)
                    .then(|| self.answer(i, t, ErrorFlags::NONE, &[]))
                    .flatten()
            }
            Instruction::SyncWrite { addr, .. } => {
                let entries: Vec<(u8, Vec<u8>)> = ins
                    .sync_entries()
                    .map(|(sid, d)| (sid, d.to_vec()))
                    .collect();
                for (sid, data) in entries {
                    if let Some(i) = self.servos.iter().position(|s| s.id == sid) {
                        self.write(i, addr, &data, t, rig);
                    }
                }
                None
            }
            Instruction::Action | Instruction::Reset => None,
        }
    }

    /// The sensor device: READ of its table, with the encoder and contacts
    /// of this instant; it never faults (it stands for timer and GPIO
    /// peripherals).
    fn sensor_device(&mut self, ins: &Instruction<'_>, t: u64, rig: &mut dyn Rig) -> Option<Reply> {
        let (count, contacts) = rig.sensors(t);
        let enc = sensor_table::ENCODER_COUNT as usize;
        self.sensor[enc..enc + 2].copy_from_slice(&count.to_le_bytes());
        self.sensor[sensor_table::CONTACTS as usize] = contacts;
        let params = match *ins {
            Instruction::Ping => Vec::new(),
            Instruction::Read { addr, len } => self
                .sensor
                .get(addr as usize..addr as usize + len as usize)
                .map(<[u8]>::to_vec)?,
            _ => return None,
        };
        let status = StatusPacket::<64>::new(SENSOR_ID, ErrorFlags::NONE, &params).ok()?;
        let mut buf = [0u8; 80];
        let bytes = status.encode(&mut buf).ok()?.to_vec();
        self.stats.replies += 1;
        // The sensor device answers after the servos' 50 µs.
        Some(Reply {
            at_us: t + 50 + bytes.len() as u64 * BYTE_US,
            bytes,
        })
    }

    fn refresh_present(&mut self, i: usize, t: u64, rig: &mut dyn Rig) {
        let id = self.servos[i].id;
        let p = rig.present(t, id);
        let tab = &mut self.servos[i].table;
        let put16 = |tab: &mut [u8; table::TABLE_LEN], addr: u8, v: u16| {
            tab[addr as usize..addr as usize + 2].copy_from_slice(&v.to_le_bytes())
        };
        put16(tab, table::PRESENT_POSITION, p.position);
        put16(tab, table::PRESENT_SPEED, p.speed);
        put16(tab, table::PRESENT_LOAD, p.load);
        tab[table::PRESENT_VOLTAGE as usize] = p.voltage;
        tab[table::PRESENT_TEMPERATURE as usize] = p.temperature;
    }

    fn write(&mut self, i: usize, addr: u8, data: &[u8], t: u64, rig: &mut dyn Rig) {
        let before = self.servos[i].torque();
        let start = addr as usize;
        let end = (start + data.len()).min(table::TABLE_LEN);
        if start >= end {
            return;
        }
        self.servos[i].table[start..end].copy_from_slice(&data[..end - start]);
        let s = &self.servos[i];
        let (id, torque) = (s.id, s.torque());
        rig.drive(t, id, torque, s.volts(self.supply_v));
        for (f, trace) in self.faults.iter().zip(self.traces.iter_mut()) {
            if f.servo != id {
                continue;
            }
            if let Some(onset) = trace.onset_us {
                if before && !torque && trace.torque_off_us.is_none() && t >= onset {
                    trace.torque_off_us = Some(t);
                }
                if !before && torque && trace.torque_on_again_us.is_none() && t >= f.end_us {
                    trace.torque_on_again_us = Some(t);
                }
            }
        }
    }

    /// Servo `i`'s status packet, after the faults in force at `t`.
    fn answer(&mut self, i: usize, t: u64, mut error: ErrorFlags, params: &[u8]) -> Option<Reply> {
        let id = self.servos[i].id;
        let torque = self.servos[i].torque();
        let mut delay = 0;
        let mut corrupt = false;
        for (f, trace) in self.faults.iter().zip(self.traces.iter_mut()) {
            if !f.applies(t, id) {
                continue;
            }
            if trace.onset_us.is_none() {
                trace.onset_us = Some(t);
                trace.torque_at_onset = torque;
            }
            match f.kind {
                FaultKind::Drop => {
                    self.stats.dropped += 1;
                    return None;
                }
                FaultKind::Corrupt => corrupt = true,
                FaultKind::Delay { us } => delay = delay.max(us),
                FaultKind::ErrorBits { bits } => error = error | bits,
            }
        }
        let status = StatusPacket::<64>::new(id, error, params).ok()?;
        let mut buf = [0u8; 80];
        let mut bytes = status.encode(&mut buf).ok()?.to_vec();
        if corrupt {
            // Flip bits of the first parameter (or the error byte): the
            // checksum no longer matches.
            let k = if bytes.len() > 6 { 5 } else { 4 };
            bytes[k] ^= 0x5A;
            self.stats.corrupted += 1;
        }
        if delay > 0 {
            self.stats.delayed += 1;
        }
        if !error.is_empty() {
            self.stats.error_bits += 1;
        }
        self.stats.replies += 1;
        let at_us = t + self.servos[i].return_delay_us() + bytes.len() as u64 * BYTE_US + delay;
        Some(Reply { at_us, bytes })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pendulum::PhysicalPendulumParams;
    use crate::sil::fault;
    use crate::rig::PendulumRig;
    use pada_core::dynamixel::{self, StatusDecoder};

    fn packet(f: impl FnOnce(&mut [u8]) -> usize) -> Vec<u8> {
        let mut buf = [0u8; 64];
        let n = f(&mut buf);
        buf[..n].to_vec()
    }

    fn read(id: u8, addr: u8, len: u8) -> Vec<u8> {
        packet(|b| dynamixel::read_data(id, addr, len, b).unwrap().len())
    }

    fn decode(bytes: &[u8]) -> Result<StatusPacket<64>, dynamixel::DecodeError> {
        let mut d: StatusDecoder<64> = StatusDecoder::new();
        d.feed(bytes).next().expect("a whole packet")
    }

    #[test]
    fn answers_reads_after_the_wire_time_and_return_delay() {
        let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
        let mut bus = BusEmulator::new(&rig, 12.0, vec![]);
        let req = read(1, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN);
        let replies = bus.receive(1000, &req, &mut rig);
        assert_eq!(replies.len(), 1);
        let r = &replies[0];
        // 8 bytes out, factory return delay 500 µs, 14 bytes back.
        assert_eq!(r.at_us, 1000 + 80 + 500 + 140);
        let status = decode(&r.bytes).unwrap();
        assert_eq!(status.id, 1);
        let present = table::PresentState::from_bytes(&status.params).unwrap();
        assert_eq!((present.voltage, present.temperature), (120, 40));
        // The sensor device: encoder 0 hanging at boot.
        let replies = bus.receive(
            2000,
            &read(SENSOR_ID, sensor_table::ENCODER_COUNT, 3),
            &mut rig,
        );
        assert_eq!(
            decode(&replies[0].bytes).unwrap().params.as_slice(),
            &[0, 0, 0]
        );
        // Nobody answers an unknown ID.
        assert!(bus.receive(3000, &read(9, 0, 2), &mut rig).is_empty());
    }

    #[test]
    fn speed_and_torque_writes_drive_the_rig() {
        let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
        let mut bus = BusEmulator::new(&rig, 12.0, vec![]);
        let speed = packet(|b| {
            dynamixel::sync_write_u16(table::MOVING_SPEED, &[(1, 256)], b)
                .unwrap()
                .len()
        });
        let torque = packet(|b| {
            dynamixel::write_data(BROADCAST_ID, table::TORQUE_ENABLE, &[1], b)
                .unwrap()
                .len()
        });
        assert!(bus
            .receive(0, &[speed, torque].concat(), &mut rig)
            .is_empty());
        assert_eq!(bus.torque(1), Some(true));
        rig.advance_to(30_000);
        assert!(rig.state()[1] > 0.0, "256/1023 of 12 V turns it");
    }

    #[test]
    fn faults_drop_corrupt_delay_and_flag_answers_in_their_window() {
        let req = read(1, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN);
        let run = |spec: &str, t: u64| {
            let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
            let mut bus = BusEmulator::new(&rig, 12.0, vec![fault::parse(spec).unwrap()]);
            let replies = bus.receive(t, &req, &mut rig);
            (replies, bus)
        };
        let (r, bus) = run("drop:at=1:for=1", 1_500_000);
        assert!(r.is_empty());
        assert_eq!(bus.faults().next().unwrap().1.onset_us, Some(1_500_080));
        let (r, _) = run("drop:at=1:for=1", 2_000_000);
        assert_eq!(r.len(), 1, "the window is over");
        let (r, _) = run("corrupt:at=1", 1_000_000);
        assert!(matches!(
            decode(&r[0].bytes),
            Err(dynamixel::DecodeError::BadChecksum { .. })
        ));
        let (r, _) = run("delay:at=1:ms=5", 1_000_000);
        assert_eq!(r[0].at_us, 1_000_000 + 80 + 500 + 140 + 5000);
        let (r, _) = run("error-bits:at=1", 1_000_000);
        assert_eq!(decode(&r[0].bytes).unwrap().error, ErrorFlags::OVERHEATING);
        // Another servo's fault leaves servo 1 alone.
        let (r, _) = run("drop:at=1:servo=2", 1_000_000);
        assert_eq!(r.len(), 1);
    }
}
