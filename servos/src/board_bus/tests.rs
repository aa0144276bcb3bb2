//! The emulated board's bus's tests.

use super::*;
use pada_sim::leo::model::ModelOptions;
use pada_sim::pendulum::PhysicalPendulumParams;
use pada_sim::rig::{LeoRig, PendulumRig};
use crate::fault;
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

fn pendulum_bus(faults: &[&str]) -> (PendulumRig, BusEmulator) {
    let rig = PendulumRig::new(PhysicalPendulumParams::default());
    let faults = faults.iter().map(|f| fault::parse(f).unwrap()).collect();
    let bus = BusEmulator::new(&rig, &pada_core::robot::pendulum::SPEC_33HZ, faults).unwrap();
    (rig, bus)
}

#[test]
fn answers_reads_after_the_wire_time_and_return_delay() {
    let (mut rig, mut bus) = pendulum_bus(&[]);
    let req = read(1, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN);
    let forecast = bus.forecast(1000, &req, &rig).unwrap();
    let replies = bus.receive(1000, &req, &mut rig);
    assert_eq!(replies.len(), 1);
    let r = &replies[0];
    assert_eq!(*r, forecast, "the forecast is the answer");
    assert_eq!(r.request, req);
    // 8 bytes out, factory return delay 500 µs, 14 bytes back.
    assert_eq!(r.at_us, 1000 + 80 + 500 + 140);
    let status = decode(&r.bytes).unwrap();
    assert_eq!(status.id, 1);
    let present = table::PresentState::from_bytes(&status.params).unwrap();
    assert_eq!((present.voltage, present.temperature), (120, 40));
    // The sensor device: encoder 0 hanging at boot.
    let sensor_read = read(SENSOR_ID, sensor_table::ENCODER_COUNT, 3);
    let forecast = bus.forecast(2000, &sensor_read, &rig).unwrap();
    let replies = bus.receive(2000, &sensor_read, &mut rig);
    assert_eq!(replies, vec![forecast]);
    assert_eq!(decode(&replies[0].bytes).unwrap().params.as_slice(), &[0, 0, 0]);
    // Nobody answers an unknown ID; a write gets no forecast.
    assert!(bus.receive(3000, &read(9, 0, 2), &mut rig).is_empty());
    assert!(bus.forecast(3000, &read(9, 0, 2), &rig).is_none());
    let torque = packet(|b| dynamixel::write_data(1, table::TORQUE_ENABLE, &[1], b).unwrap().len());
    assert!(bus.forecast(4000, &torque, &rig).is_none());
    let stats = bus.stats();
    assert_eq!((stats.packets, stats.replies), (3, 2), "forecasts count nothing");
}

#[test]
fn speed_and_torque_writes_drive_the_rig_with_its_supply() {
    let (mut rig, mut bus) = pendulum_bus(&[]);
    let speed = packet(|b| dynamixel::sync_write_u16(table::MOVING_SPEED, &[(1, 256)], b).unwrap().len());
    let torque = packet(|b| dynamixel::write_data(BROADCAST_ID, table::TORQUE_ENABLE, &[1], b).unwrap().len());
    assert!(bus.receive(0, &[speed, torque].concat(), &mut rig).is_empty());
    assert_eq!(bus.torque(1), Some(true));
    assert!((rig.gear_torque(1) - pada_core::robot::pendulum::gearbox_torque(256.0 / 1023.0 * 12.0) as f32).abs() < 1e-6);
    rig.advance_to(30_000);
    assert!(rig.state()[1] > 0.0, "256/1023 of 12 V turns it");
    // LEO's servos run on its 14 V.
    let leo = LeoRig::new(ModelOptions::default()).unwrap();
    assert_eq!(BusEmulator::new(&leo, &pada_core::robot::leo::SPEC, vec![]).unwrap().supply_v, 14.0);
}

#[test]
fn faults_drop_corrupt_delay_and_flag_answers_in_their_window() {
    let req = read(1, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN);
    let run = |spec: &str, t: u64| {
        let (mut rig, mut bus) = pendulum_bus(&[spec]);
        let forecast = bus.forecast(t, &req, &rig);
        let replies = bus.receive(t, &req, &mut rig);
        assert_eq!(forecast.into_iter().collect::<Vec<_>>(), replies, "{spec}: forecast and answer");
        (replies, bus)
    };
    let (r, bus) = run("drop:at=1:for=1", 1_500_000);
    assert!(r.is_empty());
    assert_eq!(bus.faults().next().unwrap().1.onset_us, Some(1_500_080));
    let (r, _) = run("drop:at=1:for=1", 2_000_000);
    assert_eq!(r.len(), 1, "the window is over");
    let (r, _) = run("corrupt:at=1", 1_000_000);
    assert!(matches!(decode(&r[0].bytes), Err(dynamixel::DecodeError::BadChecksum { .. })));
    let (r, _) = run("delay:at=1:ms=5", 1_000_000);
    assert_eq!(r[0].at_us, 1_000_000 + 80 + 500 + 140 + 5000);
    let (r, _) = run("error-bits:at=1", 1_000_000);
    assert_eq!(decode(&r[0].bytes).unwrap().error, ErrorFlags::OVERHEATING);
    // Another servo's fault leaves servo 1 alone (LEO has seven).
    let mut leo = LeoRig::new(ModelOptions::default()).unwrap();
    let mut bus = BusEmulator::new(&leo, &pada_core::robot::leo::SPEC, vec![fault::parse("drop:at=1:servo=4").unwrap()]).unwrap();
    assert_eq!(bus.receive(1_000_000, &req, &mut leo).len(), 1);
    assert!(bus.receive(1_001_000, &read(4, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN), &mut leo).is_empty());
    // No servo 9 on LEO's bus; the pendulum's joint has no soft limit.
    assert!(BusEmulator::new(&leo, &pada_core::robot::leo::SPEC, vec![fault::parse("drop:servo=9").unwrap()]).unwrap_err().contains("no servo 9"));
    let pendulum = PendulumRig::new(PhysicalPendulumParams::default());
    let e = BusEmulator::new(&pendulum, &pada_core::robot::pendulum::SPEC_33HZ, vec![fault::parse("past-limit").unwrap()]).unwrap_err();
    assert!(e.contains("no soft limit"), "{e}");
}

#[test]
fn past_limit_reads_the_joint_beyond_its_soft_limit() {
    let mut leo = LeoRig::new(ModelOptions::default()).unwrap();
    let mut bus = BusEmulator::new(&leo, &pada_core::robot::leo::SPEC, vec![fault::parse("past-limit:at=1:servo=4").unwrap()]).unwrap();
    let req = read(4, table::PRESENT_BLOCK, table::PRESENT_BLOCK_LEN);
    let angle = |bus: &mut BusEmulator, leo: &mut LeoRig, t: u64| {
        let r = bus.receive(t, &req, leo);
        let p = table::PresentState::from_bytes(&decode(&r[0].bytes).unwrap().params).unwrap();
        let hw = pada_core::robot::leo::SPEC;
        let k = hw.joints.iter().position(|j| j.id == 4).unwrap();
        (hw.joints[k].angle(p.position), hw.joints[k].soft_limit.unwrap())
    };
    let (before, limit) = angle(&mut bus, &mut leo, 500_000);
    assert!(before < limit.max, "{before} inside {limit:?}");
    let (during, _) = angle(&mut bus, &mut leo, 1_200_000);
    assert!(during > limit.max + 0.5 * PAST_LIMIT_RAD, "{during} past {limit:?}");
    let (after, _) = angle(&mut bus, &mut leo, 2_100_000);
    assert_eq!(after, before);
    assert_eq!(bus.stats().past_limit, 1);
    assert_eq!(bus.faults().next().unwrap().1.onset_us, Some(1_200_080));
}

/// A robot's STS3215 on the emulated bus: the firmware's SYNC READ of the
/// present block gets its status packet after its Return Delay and wire
/// time, its SYNC WRITE of torque and duty cycle drives the rig, and no
/// read is forecast (the rigs cannot tell one without simulating ahead).
#[test]
fn an_sts3215_answers_the_sync_read_and_its_sync_write_drives_the_rig() {
    use pada_core::feetech::command::{Command, COMMAND_BLOCK, COMMAND_LEN};
    use pada_core::feetech::control_table::sts3215 as sts;
    let so101 = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/robots/so101/robot.toml");
    let spec = pada_robot_file::load(&so101).unwrap().spec;
    // The pendulum rig's one joint (ID 1) stands behind the so101's servo 1.
    let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
    let mut bus = BusEmulator::new(&rig, spec, vec![]).unwrap();
    let read = packet(|b| pada_core::feetech::sync_read(sts::PRESENT_BLOCK, sts::PRESENT_BLOCK_LEN, &[1], b).unwrap().len());
    let replies = bus.receive(0, &read, &mut rig);
    assert_eq!(replies.len(), 1, "{replies:?}");
    let status = decode(&replies[0].bytes).unwrap();
    assert_eq!((status.id, status.params.len()), (1, 8));
    // The factory Return Delay (0) and 14 bytes after the request's last.
    assert_eq!(replies[0].at_us, read.len() as u64 * BYTE_US + 14 * BYTE_US);
    assert_eq!(bus.forecast(1_000, &read, &rig), None);
    assert_eq!(bus.torque(1), Some(false));
    let block = Command { torque: true, acceleration: 0, goal_position: 2048, duty: 500 }.block(pada_core::feetech::ByteOrder::Little);
    let write = packet(|b| pada_core::dynamixel::sync_write(COMMAND_BLOCK, COMMAND_LEN, &[(1, &block[..])], b).unwrap().len());
    assert!(bus.receive(1_000, &write, &mut rig).is_empty());
    assert_eq!(bus.torque(1), Some(true));
    assert_eq!(bus.stats().packets, 2);
    // A fault the STS3215 does not emulate is refused before the run.
    let past = vec![fault::parse("past-limit:at=1:servo=1").unwrap()];
    let e = BusEmulator::new(&rig, spec, past).unwrap_err();
    assert!(e.contains("past-limit is not emulated") && e.contains("valid: drop"), "{e}");
}
