//! The Feetech bus against a fake chain of STS3215s that answers as
//! Feetech's memory table says (Response Status Level, SYNC READ in the
//! order of the IDs, SYNC WRITE without an answer).

use super::*;
use crate::bus::{BusConfig, BusStats};
use embassy_futures::block_on;
use pada_core::dynamixel::InstructionDecoder;
use pada_core::feetech::{Instruction, StatusPacket};
use pada_core::servo::Present;
use std::collections::VecDeque;

/// A fake chain: decodes what the firmware sends, answers from a memory
/// table per servo; time advances only by the bytes and by waiting.
pub struct FtFake {
    pub tables: std::vec::Vec<(u8, [u8; sts::TABLE_LEN])>,
    pub inbox: VecDeque<u8>,
    pub sent: std::vec::Vec<std::vec::Vec<u8>>,
    pub now: u64,
    /// Bytes handed to the bus's receiver.
    pub received: u64,
    /// Servos whose answers are dropped, and answers to corrupt.
    pub silent: std::vec::Vec<u8>,
    pub corrupt_next: u32,
    decoder: InstructionDecoder<64>,
}

/// Servo `id`'s memory as it leaves the factory (Response Status Level
/// 1), at 2000 + `id` steps, moving at -20 steps/s against a load of
/// -30 (0.1 %): the sign bits.
fn factory(id: u8) -> [u8; sts::TABLE_LEN] {
    let mut t = [0u8; sts::TABLE_LEN];
    let mut put = |addr: u8, bytes: &[u8]| t[addr as usize..][..bytes.len()].copy_from_slice(bytes);
    put(sts::FIRMWARE_MAJOR, &[3]);
    put(sts::MODEL_NUMBER, &sts::STS3215_MODEL.to_le_bytes());
    put(sts::ID, &[id]);
    put(sts::RESPONSE_STATUS_LEVEL, &[1]);
    put(sts::ACCELERATION, &[254]);
    put(sts::LOCK, &[1]);
    put(sts::PRESENT_POSITION, &(2000 + id as u16).to_le_bytes());
    put(sts::PRESENT_VELOCITY, &0x8014u16.to_le_bytes());
    put(sts::PRESENT_LOAD, &0x041Eu16.to_le_bytes());
    put(sts::PRESENT_VOLTAGE, &[74, 33]);
    t
}

impl FtFake {
    pub fn with_servos(ids: &[u8]) -> Self {
        FtFake {
            tables: ids.iter().map(|&id| (id, factory(id))).collect(),
            inbox: VecDeque::new(),
            sent: std::vec::Vec::new(),
            now: 0,
            received: 0,
            silent: std::vec::Vec::new(),
            corrupt_next: 0,
            decoder: InstructionDecoder::new(),
        }
    }

    pub fn table(&self, id: u8) -> &[u8; sts::TABLE_LEN] {
        &self.tables.iter().find(|(i, _)| *i == id).unwrap().1
    }

    fn table_mut(&mut self, id: u8) -> Option<&mut [u8; sts::TABLE_LEN]> {
        self.tables.iter_mut().find(|(i, _)| *i == id).map(|(_, t)| t)
    }

    fn answer(&mut self, id: u8, params: &[u8]) {
        if self.silent.contains(&id) {
            return;
        }
        let mut buf = [0u8; 64];
        let mut bytes = StatusPacket::<64>::new(id, ErrorFlags::NONE, params).unwrap().encode(&mut buf).unwrap().to_vec();
        if self.corrupt_next > 0 {
            self.corrupt_next -= 1;
            *bytes.last_mut().unwrap() ^= 0x55;
        }
        self.inbox.extend(bytes);
    }

    fn write(&mut self, id: u8, addr: u8, data: &[u8]) {
        for (i, t) in self.tables.iter_mut() {
            if *i == id || id == BROADCAST_ID {
                t[addr as usize..addr as usize + data.len()].copy_from_slice(data);
            }
        }
    }
}

impl BusPort for FtFake {
    fn discard_input(&mut self) {
        self.inbox.clear();
    }

    async fn send(&mut self, bytes: &[u8]) -> Result<(), PortError> {
        self.sent.push(bytes.to_vec());
        self.now += bytes.len() as u64 * 10;
        let packets: std::vec::Vec<_> = self.decoder.feed(bytes).collect();
        for p in packets {
            let p = p.expect("the firmware sends valid packets");
            let level = self.table_mut(p.id).map(|t| t[sts::RESPONSE_STATUS_LEVEL as usize]);
            match Instruction::parse(p.code, &p.params).expect("a Feetech instruction") {
                Instruction::Shared(pada_core::dynamixel::Instruction::Read { addr, len }) => {
                    if let Some(t) = self.table_mut(p.id) {
                        let data = t[addr as usize..(addr + len) as usize].to_vec();
                        self.answer(p.id, &data);
                    }
                }
                Instruction::Shared(pada_core::dynamixel::Instruction::Write { addr, data }) => {
                    self.write(p.id, addr, data);
                    if p.id != BROADCAST_ID && level == Some(1) {
                        self.answer(p.id, &[]);
                    }
                }
                Instruction::Shared(i @ pada_core::dynamixel::Instruction::SyncWrite { addr, .. }) => {
                    let entries: std::vec::Vec<(u8, std::vec::Vec<u8>)> = i.sync_entries().map(|(id, d)| (id, d.to_vec())).collect();
                    for (id, d) in entries {
                        if let Some(t) = self.table_mut(id) {
                            t[addr as usize..addr as usize + d.len()].copy_from_slice(&d);
                        }
                    }
                }
                Instruction::SyncRead { addr, len, ids } => {
                    for &id in ids {
                        if let Some(t) = self.table_mut(id) {
                            let data = t[addr as usize..(addr + len) as usize].to_vec();
                            self.answer(id, &data);
                        }
                    }
                }
                other => panic!("not expected on the bus: {other:?}"),
            }
        }
        Ok(())
    }

    async fn receive(&mut self, buf: &mut [u8], deadline_us: u64) -> Result<usize, PortError> {
        // Chunks that cut packets, and hold several.
        let n = crate::bus::fake_receive(&mut self.inbox, &mut self.now, buf, deadline_us, 23);
        self.received += n as u64;
        Ok(n)
    }

    fn now_us(&self) -> u64 {
        self.now
    }
}

fn bus(ids: &[u8]) -> ServoBus<FtFake> {
    ServoBus::new(FtFake::with_servos(ids), BusConfig::default())
}

#[test]
fn one_sync_read_reads_every_servo_with_its_signs() {
    let mut bus = bus(&[1, 2, 3, 4, 5, 6]);
    let mut out = [ServoRead::default(); 6];
    block_on(bus.read_present_ft(&[1, 2, 3, 4, 5, 6], ByteOrder::Little, &mut out));
    for (i, r) in out.iter().enumerate() {
        let p = r.state.unwrap();
        assert_eq!(p, Present { position: 2001 + i as i32, speed: -20, load: -30, voltage_dv: 74, temperature: 33 });
        assert_eq!((r.timeouts, r.checksum_errors), (0, 0));
    }
    // One packet out: the SYNC READ.
    assert_eq!(bus.port_mut().sent.len(), 1);
    assert_eq!(bus.port_mut().sent[0][4], 0x82);
    assert_eq!(bus.stats(), BusStats { requests: 1, replies: 6, ..BusStats::default() });
}

#[test]
fn a_silent_servo_is_asked_again_alone_and_named() {
    let mut bus = bus(&[1, 2, 3]);
    bus.port_mut().silent = vec![2];
    let mut out = [ServoRead::default(); 3];
    block_on(bus.read_present_ft(&[1, 2, 3], ByteOrder::Little, &mut out));
    assert!(out[0].state.is_some() && out[2].state.is_some(), "the servo after the silent one is read");
    assert_eq!(out[1].state, None);
    // The SYNC READ's wait and the one READ of the attempts left.
    assert_eq!(out[1].timeouts, 2);
    assert_eq!(bus.port_mut().sent.len(), 2);
    assert_eq!(bus.port_mut().sent[1][2], 2, "the READ asks servo 2");
    // A damaged answer counts against the servo whose turn it was.
    let mut bus = self::bus(&[1, 2]);
    bus.port_mut().corrupt_next = 1;
    block_on(bus.read_present_ft(&[1, 2], ByteOrder::Little, &mut out[..2]));
    assert_eq!(out[0].checksum_errors, 1);
    assert!(out[0].state.is_some() && out[1].state.is_some(), "read again alone");
    assert_eq!(bus.stats().checksum_errors, 1);
}

#[test]
fn one_sync_write_carries_torque_and_command() {
    let mut bus = bus(&[1, 2]);
    let on = |duty, goal_position| Command { torque: true, acceleration: 254, goal_position, duty };
    block_on(bus.sync_write_ft(&[(1, on(-300, 2048)), (2, on(20, 100))], ByteOrder::Little)).unwrap();
    assert_eq!(bus.port_mut().sent.len(), 1);
    let t1 = *bus.port_mut().table(1);
    let t2 = *bus.port_mut().table(2);
    assert_eq!((t1[sts::TORQUE_ENABLE as usize], t2[sts::TORQUE_ENABLE as usize]), (1, 1));
    assert_eq!(u16::from_le_bytes([t1[44], t1[45]]), 0x0400 | 300);
    // Below 5 %: 0, as Feetech documents no smaller duty cycle.
    assert_eq!(u16::from_le_bytes([t2[44], t2[45]]), 0);
    assert_eq!(u16::from_le_bytes([t2[42], t2[43]]), 100);
    assert_eq!(t1[sts::ACCELERATION as usize], 254);
    block_on(bus.stop_all_ft()).unwrap();
    let t1 = *bus.port_mut().table(1);
    assert_eq!((t1[sts::TORQUE_ENABLE as usize], t1[44], t1[45]), (0, 0, 0));
}

#[test]
fn setup_checks_the_model_and_writes_the_mode_once() {
    let mut bus = bus(&[3]);
    let s = block_on(bus.setup_ft(3, sts::STS3215_MODEL, sts::MODE_PWM)).unwrap();
    assert_eq!(s, FtSetup { setup: ServoSetup { model: 777, firmware: 3, wrote: true }, order: ByteOrder::Little, acceleration: 254 });
    let t = *bus.port_mut().table(3);
    assert_eq!(t[sts::OPERATING_MODE as usize], sts::MODE_PWM);
    assert_eq!(t[sts::RESPONSE_STATUS_LEVEL as usize], RESPONSE_STATUS_LEVEL);
    assert_eq!(t[sts::RETURN_DELAY_TIME as usize], RETURN_DELAY);
    assert_eq!(t[sts::LOCK as usize], 1, "locked again");
    // No answer to a WRITE is left on the bus for the next request.
    assert!(bus.port_mut().inbox.is_empty());
    let s = block_on(bus.setup_ft(3, sts::STS3215_MODEL, sts::MODE_PWM)).unwrap();
    assert!(!s.setup.wrote);
    assert_eq!(block_on(bus.setup_ft(3, 1020, sts::MODE_PWM)), Err(SetupError::WrongModel { id: 3, found: 777, expected: 1020 }));
    assert_eq!(block_on(bus.setup_ft(4, sts::STS3215_MODEL, sts::MODE_PWM)), Err(SetupError::NoAnswer { id: 4 }));
}

#[test]
fn over_current_is_a_hardware_condition_for_the_safety_machine() {
    assert_eq!(flags_of_ft(status::OVERCURRENT), ErrorFlags::OVERLOAD);
    assert!(flags_of_ft(status::OVERCURRENT).intersects(ErrorFlags::HARDWARE));
    assert_eq!(flags_of_ft(status::OVERHEAT | status::ANGLE), ErrorFlags::OVERHEATING | ErrorFlags::ANGLE_LIMIT);
    assert_eq!(flags_of_ft(status::VOLTAGE), ErrorFlags::INPUT_VOLTAGE);
}

/// A robot of two STS3215s on the fake chain, set up.
fn robot_bus() -> crate::bus::RobotBus<FtFake> {
    use pada_core::robot::{leo, JointSpec, RobotSpec};
    static JOINTS: [JointSpec; 2] = {
        let j = JointSpec { name: "s", servo: &pada_core::servo::STS3215, id: 1, zero: 2048, sign: 1, soft_limit: None };
        [j, JointSpec { id: 2, ..j }]
    };
    let robot: &'static RobotSpec = Box::leak(Box::new(RobotSpec { joints: &JOINTS, ..leo::SPEC }));
    let mut rb = crate::bus::RobotBus::new(FtFake::with_servos(&[1, 2]), BusConfig::default(), robot);
    block_on(rb.stop_all());
    let report = block_on(rb.setup());
    assert!(report.iter().all(|(_, r)| r.is_ok()), "{report:?}");
    rb.bus_mut().port_mut().sent.clear();
    rb
}

#[test]
fn a_robot_of_sts3215s_is_one_sync_read_and_one_sync_write_a_period() {
    use crate::config::MAX_ROBOT_SERVOS;
    use pada_core::servo::Drive;
    let mut rb = robot_bus();
    for id in [1, 2] {
        assert_eq!(rb.bus_mut().port_mut().table(id)[sts::OPERATING_MODE as usize], sts::MODE_PWM);
    }
    let mut out = [ServoRead::default(); MAX_ROBOT_SERVOS];
    block_on(rb.read(&mut out));
    assert_eq!((out[0].state.unwrap().position, out[1].state.unwrap().position), (2001, 2002));
    let commands = [(1, Drive::GoalTime { time: 500, full: 1000 }), (2, Drive::GoalTime { time: -300, full: 1000 })];
    block_on(rb.write(true, &commands, false));
    let fake = rb.bus_mut().port_mut();
    assert_eq!(fake.sent.iter().map(|p| p[4]).collect::<std::vec::Vec<_>>(), [0x82, 0x83], "one SYNC READ, one SYNC WRITE");
    let (t1, t2) = (*fake.table(1), *fake.table(2));
    assert_eq!((t1[sts::TORQUE_ENABLE as usize], t2[sts::TORQUE_ENABLE as usize]), (1, 1));
    assert_eq!(u16::from_le_bytes([t1[44], t1[45]]), 500);
    assert_eq!(u16::from_le_bytes([t2[44], t2[45]]), 0x0400 | 300);
    // Goal Position: where the servo is (unused in Operating Mode 2).
    assert_eq!(u16::from_le_bytes([t2[42], t2[43]]), 2002);
    // A fault: the same SYNC WRITE with torque off and no duty cycle.
    block_on(rb.write(false, &commands, false));
    let fake = rb.bus_mut().port_mut();
    assert_eq!(fake.sent.len(), 3);
    for id in [1, 2] {
        let t = fake.table(id);
        assert_eq!((t[sts::TORQUE_ENABLE as usize], t[44], t[45]), (0, 0, 0), "servo {id}");
    }
}

#[test]
fn a_silent_or_foreign_servo_is_refused_and_never_commanded() {
    use pada_core::servo::Drive;
    let mut rb = robot_bus();
    // Servo 2 stops answering: read as silent, named.
    rb.bus_mut().port_mut().silent = vec![2];
    let mut out = [ServoRead::default(); crate::config::MAX_ROBOT_SERVOS];
    block_on(rb.read(&mut out));
    assert!(out[0].state.is_some() && out[1].state.is_none() && out[1].timeouts == 2);
    // At set-up it is refused: the SYNC WRITE leaves it out.
    let report = block_on(rb.setup());
    assert_eq!(report[1], (2, Err(SetupError::NoAnswer { id: 2 })));
    rb.bus_mut().port_mut().sent.clear();
    block_on(rb.write(true, &[(1, Drive::GoalTime { time: 100, full: 1000 }), (2, Drive::GoalTime { time: 100, full: 1000 })], false));
    let fake = rb.bus_mut().port_mut();
    assert_eq!(fake.table(2)[sts::TORQUE_ENABLE as usize], 0);
    assert_eq!(fake.table(1)[sts::TORQUE_ENABLE as usize], 1);
}
