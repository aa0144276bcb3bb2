//! A virtual Feetech STS3215: what is its own beside the instructions it
//! shares with the RX-28 ([`super::p1`], which executes those): its
//! factory memory table, SYNC READ, its position loop as a first-order
//! model, and its alarms (docs/reference/feetech.md).
//!
//! | instruction | answered (Response Status Level) | what it does |
//! |---|---|---|
//! | PING, READ | always | as the RX-28 |
//! | WRITE, REG WRITE, ACTION, RECOVERY | 1 | as the RX-28 (RECOVERY: ID 1, 1 Mbps) |
//! | SYNC WRITE | never | its own entry, as WRITE |
//! | SYNC READ | its turn, in the order of the IDs | its own block, as READ |
//! | another code, bad parameters | 1 | Instruction Error bit (bit 6) |
//! | a refused WRITE (read-only, out of range) | 1 | nothing written; no error bit (Feetech's bit 3 is over-current, not Protocol 1.0's Range Error) |
//!
//! Every answer's ERROR byte carries the Status bits in force ([`error_byte`]).
//!
//! # The position loop
//!
//! In Operating Mode 0 with torque on, the output follows Goal Position
//! (within the position limits) as a first-order lag of time constant
//! [`TAU_S`], at most Goal Velocity (0: the no-load speed,
//! [`NO_LOAD_STEPS_PER_S`]), and stops within half a step of it. It is the emulator's stand-in for the
//! servo's P/D/I loop, not a model of it: a bare chain has no load, and a
//! robot's plant models the loop where it learns through it.
//!
//! # A robot's STS3215
//!
//! Behind a robot's servo is its joint in the robot's simulated physics
//! ([`with_robot`]): the present block is the joint's, and in Operating
//! Mode 2 with torque on Goal Time's duty cycle is the motor's voltage
//! ([`volts`]), as `pada run --board` applies it.
//!
//! # Alarms
//!
//! Status (65) and every answer's ERROR byte carry the conditions in
//! force: voltage outside the limits (14, 15), temperature above its limit
//! (13), a goal outside the position limits (angle), and the bits a
//! `--fault error-bits` injects (overload, overheating, voltage). A
//! condition that Unloading Condition (19) names drops the torque, as the
//! servo does; it stays off until Torque Enable is written again.

use super::p1::{Layout, P1Servo};
use pada_core::feetech::control_table::sts3215::{self as sts, STS3215};
use pada_core::feetech::value::{
    from_sign_magnitude, to_sign_magnitude_saturating, HOMING_OFFSET_SIGN_BIT, LOAD_SIGN_BIT, POSITION_SIGN_BIT, VELOCITY_SIGN_BIT,
};
use pada_core::servo::Present;
use pada_core::dynamixel::ErrorFlags;
use pada_core::feetech::status::{self, ServoStatus};

/// The time constant of the emulated position loop \[s\].
pub const TAU_S: f64 = 0.05;
/// The STS3215's no-load speed at 7.4 V, in steps per second: 0.222 s per
/// 60° (Feetech's datasheet, docs/reference/feetech.md), 4096 steps a
/// turn.
pub const NO_LOAD_STEPS_PER_S: f64 = 4096.0 / 6.0 / 0.222;
/// The supply an emulated STS3215 reads \[0.1 V\] (the SO-101 follower's
/// 7.4 V variant).
pub const SUPPLY_DV: u8 = 74;
/// Present Temperature it reads \[°C\].
pub const TEMPERATURE_C: u8 = pada_sim::rig::TEMPERATURE_C;

/// The STS3215's layout on Protocol 1.0's framing.
pub static STS3215_LAYOUT: Layout = Layout {
    table: &STS3215,
    factory: factory_table,
    id: sts::ID,
    baud: sts::BAUD_RATE,
    return_delay: sts::RETURN_DELAY_TIME,
    level: sts::RESPONSE_STATUS_LEVEL,
    level_base: 1,
    registered: sts::ASYNC_WRITE_FLAG,
    torque: sts::TORQUE_ENABLE,
};

/// The STS3215's factory table at `id` and Baud Rate value `baud`: the
/// initial values of Feetech's memory table where it gives them, LeRobot's
/// defaults for the gains (P 32, D 32, I 0), and the emulator's choices
/// for the rest (docs/reference/feetech.md § "Memory map").
pub fn factory_table(id: u8, baud: u8) -> Vec<u8> {
    let mut t = vec![0u8; sts::TABLE_LEN];
    let mut put = |address: u8, bytes: &[u8]| t[address as usize..address as usize + bytes.len()].copy_from_slice(bytes);
    put(sts::FIRMWARE_MAJOR, &[3]);
    put(sts::FIRMWARE_MINOR, &[10]);
    put(sts::MODEL_NUMBER, &sts::STS3215_MODEL.to_le_bytes());
    put(sts::ID, &[id]);
    put(sts::BAUD_RATE, &[baud]);
    put(sts::RESPONSE_STATUS_LEVEL, &[1]);
    put(sts::MAX_POSITION_LIMIT, &4095u16.to_le_bytes());
    put(sts::MAX_TEMPERATURE_LIMIT, &[70]);
    put(sts::MAX_INPUT_VOLTAGE, &[140]);
    put(sts::MIN_INPUT_VOLTAGE, &[40]);
    put(sts::MAX_TORQUE_LIMIT, &1000u16.to_le_bytes());
    put(sts::UNLOADING_CONDITION, &[status::HARDWARE.bits()]);
    put(sts::LED_ALARM_CONDITION, &[status::HARDWARE.bits() | status::ANGLE.bits()]);
    put(sts::P_COEFFICIENT, &[32]);
    put(sts::D_COEFFICIENT, &[32]);
    put(sts::CW_DEAD_ZONE, &[1]);
    put(sts::CCW_DEAD_ZONE, &[1]);
    put(sts::PROTECTION_CURRENT, &500u16.to_le_bytes());
    put(sts::ANGULAR_RESOLUTION, &[1]);
    put(sts::PROTECTIVE_TORQUE, &[20]);
    put(sts::PROTECTION_TIME, &[200]);
    put(sts::OVERLOAD_TORQUE, &[80]);
    put(sts::OVER_CURRENT_PROTECTION_TIME, &[200]);
    put(sts::TORQUE_LIMIT, &1000u16.to_le_bytes());
    put(sts::GOAL_POSITION, &2048u16.to_le_bytes());
    put(sts::PRESENT_POSITION, &2048u16.to_le_bytes());
    put(sts::PRESENT_VOLTAGE, &[SUPPLY_DV]);
    put(sts::PRESENT_TEMPERATURE, &[TEMPERATURE_C]);
    t
}

pub use super::ft_output::Output;

fn u16_at(t: &[u8], address: u8) -> u16 {
    u16::from_le_bytes([t[address as usize], t[address as usize + 1]])
}

/// Goal Position in steps, within the position limits (both 0: none).
fn target(t: &[u8]) -> (f64, bool) {
    let goal = from_sign_magnitude(u16_at(t, sts::GOAL_POSITION), POSITION_SIGN_BIT) as f64;
    let (min, max) = (u16_at(t, sts::MIN_POSITION_LIMIT) as f64, u16_at(t, sts::MAX_POSITION_LIMIT) as f64);
    if min == 0.0 && max == 0.0 {
        return (goal, false);
    }
    (goal.clamp(min, max), goal < min || goal > max)
}

/// The conditions in force in `t`, besides the injected ones.
fn conditions(t: &[u8]) -> ServoStatus {
    let mut s = ServoStatus::NONE;
    let volts = t[sts::PRESENT_VOLTAGE as usize];
    if volts > t[sts::MAX_INPUT_VOLTAGE as usize] || volts < t[sts::MIN_INPUT_VOLTAGE as usize] {
        s = s.union(status::VOLTAGE);
    }
    if t[sts::PRESENT_TEMPERATURE as usize] > t[sts::MAX_TEMPERATURE_LIMIT as usize] {
        s = s.union(status::OVERHEAT);
    }
    if target(t).1 {
        s = s.union(status::ANGLE);
    }
    s
}

/// Advances `servo`'s output to `now_us` and writes its present values,
/// Status and Moving; drops torque on a condition Unloading Condition
/// names. Returns whether the torque was dropped now.
pub fn advance(servo: &mut P1Servo, out: &mut Output, now_us: u64) -> bool {
    let t = &mut servo.table;
    let dt = now_us.saturating_sub(out.at_us) as f64 * 1e-6;
    out.at_us = out.at_us.max(now_us);
    let torque = t[sts::TORQUE_ENABLE as usize] == 1;
    let mode = t[sts::OPERATING_MODE as usize];
    let before = out.position;
    if torque && mode == sts::MODE_POSITION && dt > 0.0 {
        let (goal, _) = target(t);
        let limit = from_sign_magnitude(u16_at(t, sts::GOAL_VELOCITY), 15).unsigned_abs() as f64;
        let vmax = if limit > 0.0 { limit.min(NO_LOAD_STEPS_PER_S) } else { NO_LOAD_STEPS_PER_S };
        let step = (goal - out.position) * (1.0 - (-dt / TAU_S).exp());
        out.position += step.clamp(-vmax * dt, vmax * dt);
        if (goal - out.position).abs() < 0.5 {
            // Within a step of the goal: there (the loop's dead zone).
            out.position = goal;
        }
    }
    out.velocity = if dt > 0.0 { (out.position - before) / dt } else { out.velocity };
    let position = out.position.round().clamp(0.0, 4095.0) as u16;
    let velocity = to_sign_magnitude_saturating(out.velocity.round() as i32, VELOCITY_SIGN_BIT);
    t[sts::PRESENT_POSITION as usize..][..2].copy_from_slice(&position.to_le_bytes());
    t[sts::PRESENT_VELOCITY as usize..][..2].copy_from_slice(&velocity.to_le_bytes());
    t[sts::MOVING as usize] = u8::from(out.velocity.abs() > 1.0);
    alarms(servo, out)
}

/// A robot's STS3215: its present values are its joint's in the robot's
/// simulated physics (`present`, in the servo's own units: steps through
/// the joint's calibration, steps/s, load in 0.1 %, the supply), less the
/// Homing Offset; then Status and Moving as [`advance`] writes them.
/// Returns whether the torque was dropped now.
pub fn with_robot(servo: &mut P1Servo, out: &mut Output, present: &Present, now_us: u64) -> bool {
    let t = &mut servo.table;
    out.at_us = out.at_us.max(now_us);
    // The raw steps, before the Homing Offset (Torque Enable 128 takes
    // the middle from them).
    out.position = present.position as f64;
    out.velocity = present.speed as f64;
    let offset = from_sign_magnitude(u16_at(t, sts::HOMING_OFFSET), HOMING_OFFSET_SIGN_BIT);
    let signed = |v: i32, bit: u8| to_sign_magnitude_saturating(v, bit).to_le_bytes();
    t[sts::PRESENT_POSITION as usize..][..2].copy_from_slice(&signed(present.position - offset, POSITION_SIGN_BIT));
    t[sts::PRESENT_VELOCITY as usize..][..2].copy_from_slice(&signed(present.speed, VELOCITY_SIGN_BIT));
    t[sts::PRESENT_LOAD as usize..][..2].copy_from_slice(&signed(present.load.clamp(-1000, 1000), LOAD_SIGN_BIT));
    t[sts::PRESENT_VOLTAGE as usize] = present.voltage_dv.min(255) as u8;
    t[sts::PRESENT_TEMPERATURE as usize] = present.temperature;
    t[sts::MOVING as usize] = u8::from(present.speed != 0);
    alarms(servo, out)
}

/// Status from the conditions in force and the injected ones; the torque
/// dropped on one that Unloading Condition names.
fn alarms(servo: &mut P1Servo, out: &Output) -> bool {
    let t = &mut servo.table;
    let status = conditions(t).union(out.injected);
    t[sts::STATUS as usize] = status.bits();
    let unload = status.intersects(ErrorFlags(t[sts::UNLOADING_CONDITION as usize]));
    let dropped = unload && t[sts::TORQUE_ENABLE as usize] != 0;
    if dropped {
        t[sts::TORQUE_ENABLE as usize] = 0;
    }
    dropped
}

/// Its answer's ERROR byte: the Status bits in force.
pub fn error_byte(servo: &P1Servo) -> u8 {
    servo.table[sts::STATUS as usize]
}

/// The ERROR byte of its answer whose Protocol 1.0 error bits are
/// `protocol_1`: the Status bits, and the instruction and checksum bits
/// (the others have Feetech meanings of their own).
pub fn answer_error(servo: &P1Servo, protocol_1: ErrorFlags) -> ErrorFlags {
    let kept = protocol_1.intersection(ErrorFlags::INSTRUCTION.union(ErrorFlags::CHECKSUM));
    ErrorFlags(error_byte(servo)).union(kept)
}

/// Torque Enable 128: the present position becomes the middle, 2048, by
/// the Homing Offset (Feetech's calibration); Torque Enable reads 0 after.
pub fn calibrate_middle(servo: &mut P1Servo, out: &mut Output) {
    let t = &mut servo.table;
    if t[sts::TORQUE_ENABLE as usize] != 128 {
        return;
    }
    t[sts::TORQUE_ENABLE as usize] = 0;
    let offset = out.position.round() as i32 - 2048;
    let raw = to_sign_magnitude_saturating(offset, pada_core::feetech::value::HOMING_OFFSET_SIGN_BIT);
    t[sts::HOMING_OFFSET as usize..][..2].copy_from_slice(&raw.to_le_bytes());
    out.position = 2048.0;
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::dynamixel::Instruction;

    fn servo() -> (P1Servo, Output) {
        (P1Servo::of(&STS3215_LAYOUT, 1, 0, None), Output::default())
    }

    #[test]
    fn it_answers_as_feetechs_memory_table_says() {
        let (mut s, _) = servo();
        assert_eq!(s.baud_bps(), 1_000_000);
        let model = s.execute(&Instruction::Read { addr: sts::MODEL_NUMBER, len: 2 }, false);
        assert_eq!(model, Some((ErrorFlags::NONE, 777u16.to_le_bytes().to_vec())));
        // Response Status Level 1 answers a WRITE; 0 answers only READ and PING.
        let w = Instruction::Write { addr: sts::TORQUE_ENABLE, data: &[1] };
        assert_eq!(s.execute(&w, false), Some((ErrorFlags::NONE, vec![])));
        s.table[sts::RESPONSE_STATUS_LEVEL as usize] = 0;
        assert_eq!(s.execute(&w, false), None);
        assert!(s.execute(&Instruction::Ping, false).is_some());
        assert!(s.execute(&Instruction::Read { addr: sts::ID, len: 1 }, false).is_some());
        // REG WRITE sets the Async Write Flag until ACTION.
        s.table[sts::RESPONSE_STATUS_LEVEL as usize] = 1;
        s.execute(&Instruction::RegWrite { addr: sts::GOAL_POSITION, data: &[0, 4] }, false);
        assert_eq!(s.table[sts::ASYNC_WRITE_FLAG as usize], 1);
        s.execute(&Instruction::Action, true);
        assert_eq!((s.table[sts::ASYNC_WRITE_FLAG as usize], u16_at(&s.table, sts::GOAL_POSITION)), (0, 1024));
        // RECOVERY: the factory table at ID 1, 1 Mbps.
        s.table[sts::ID as usize] = 9;
        s.execute(&Instruction::Reset, false);
        assert_eq!((s.id(), s.baud()), (1, 0));
    }

    #[test]
    fn the_position_loop_reaches_its_goal_and_reports_its_speed() {
        let (mut s, mut out) = servo();
        s.table[sts::TORQUE_ENABLE as usize] = 1;
        s.table[sts::GOAL_POSITION as usize..][..2].copy_from_slice(&3000u16.to_le_bytes());
        advance(&mut s, &mut out, 20_000);
        let v = from_sign_magnitude(u16_at(&s.table, sts::PRESENT_VELOCITY), 15);
        assert!(v > 0 && (v as f64) <= NO_LOAD_STEPS_PER_S + 1.0, "{v}");
        assert_eq!(s.table[sts::MOVING as usize], 1);
        advance(&mut s, &mut out, 2_000_000);
        assert_eq!(u16_at(&s.table, sts::PRESENT_POSITION), 3000);
        // Torque off: it stays where it is.
        s.table[sts::TORQUE_ENABLE as usize] = 0;
        s.table[sts::GOAL_POSITION as usize..][..2].copy_from_slice(&100u16.to_le_bytes());
        advance(&mut s, &mut out, 3_000_000);
        assert_eq!(u16_at(&s.table, sts::PRESENT_POSITION), 3000);
    }

    #[test]
    fn alarms_show_in_status_and_unload_the_servo() {
        let (mut s, mut out) = servo();
        s.table[sts::TORQUE_ENABLE as usize] = 1;
        // A goal past the limits: the angle bit, torque kept (not an
        // unloading condition by default).
        s.table[sts::MAX_POSITION_LIMIT as usize..][..2].copy_from_slice(&3000u16.to_le_bytes());
        s.table[sts::GOAL_POSITION as usize..][..2].copy_from_slice(&3500u16.to_le_bytes());
        assert!(!advance(&mut s, &mut out, 10_000));
        assert_eq!(error_byte(&s), status::ANGLE.bits());
        // An injected overload: Status, and the torque drops.
        out.injected = status::OVERLOAD;
        assert!(advance(&mut s, &mut out, 20_000));
        assert!(!s.torque());
        assert!(ErrorFlags(error_byte(&s)).intersects(status::OVERLOAD));
        // Overheating from the table.
        let (mut s, mut out) = servo();
        s.table[sts::MAX_TEMPERATURE_LIMIT as usize] = 30;
        advance(&mut s, &mut out, 1);
        assert_eq!(error_byte(&s), status::OVERHEAT.bits());
    }

    #[test]
    fn a_robots_servo_reads_its_joint_and_applies_its_duty_cycle() {
        let (mut s, mut out) = servo();
        // Torque on in Operating Mode 0: no voltage (only a bare chain's
        // output follows the position loop).
        s.table[sts::TORQUE_ENABLE as usize] = 1;
        s.table[sts::GOAL_TIME as usize..][..2].copy_from_slice(&(0x0400u16 | 300).to_le_bytes());
        assert_eq!(crate::ft_output::volts(&s.table, 5.0), 0.0);
        // Mode 2: −30 % of 5 V; past 100 %, 100 %; torque off, none.
        s.table[sts::OPERATING_MODE as usize] = sts::MODE_PWM;
        assert!((crate::ft_output::volts(&s.table, 5.0) + 1.5).abs() < 1e-6, "{}", crate::ft_output::volts(&s.table, 5.0));
        s.table[sts::GOAL_TIME as usize..][..2].copy_from_slice(&1023u16.to_le_bytes());
        assert_eq!(crate::ft_output::volts(&s.table, 5.0), 5.0);
        s.table[sts::TORQUE_ENABLE as usize] = 0;
        assert_eq!(crate::ft_output::volts(&s.table, 5.0), 0.0);
        // The joint's values in the servo's units and sign bits, less the
        // Homing Offset.
        s.table[sts::HOMING_OFFSET as usize..][..2].copy_from_slice(&(0x0800u16 | 10).to_le_bytes());
        let p = Present { position: 2100, speed: -40, load: -1500, voltage_dv: 50, temperature: 40 };
        assert!(!with_robot(&mut s, &mut out, &p, 30_000));
        let block = &s.table[sts::PRESENT_BLOCK as usize..][..8];
        let back = pada_core::feetech::present(block, pada_core::feetech::ByteOrder::Little).unwrap();
        assert_eq!(back, Present { position: 2110, load: -1000, ..p });
        assert_eq!((s.table[sts::MOVING as usize], out.position), (1, 2100.0));
        // 5 V is inside the factory's 4–14 V: no alarm.
        assert_eq!(error_byte(&s), 0);
    }

    #[test]
    fn torque_enable_128_makes_here_the_middle() {
        let (mut s, mut out) = servo();
        out.position = 3000.0;
        s.table[sts::TORQUE_ENABLE as usize] = 128;
        calibrate_middle(&mut s, &mut out);
        assert_eq!(out.position, 2048.0);
        assert_eq!(from_sign_magnitude(u16_at(&s.table, sts::HOMING_OFFSET), 11), 952);
        assert_eq!(s.table[sts::TORQUE_ENABLE as usize], 0);
    }
}
