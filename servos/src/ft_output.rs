//! The state of an STS3215's output shaft, which its position loop
//! ([`super::ft`]) moves and a virtual servo ([`super::p1`]) keeps: a leaf
//! module, so that the two import it without importing each other.

use pada_core::feetech::command::{DUTY_SIGN_BIT, MAX_DUTY};
use pada_core::feetech::control_table::sts3215 as sts;
use pada_core::feetech::status::ServoStatus;
use pada_core::feetech::value::from_sign_magnitude;

/// The state of an STS3215's output, for its position loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Output {
    /// Position \[steps\].
    pub position: f64,
    /// Velocity \[steps/s\].
    pub velocity: f64,
    /// Bus time of the state \[µs\].
    pub at_us: u64,
    /// Conditions injected by faults (kept until the next RECOVERY).
    pub injected: ServoStatus,
}

impl Default for Output {
    fn default() -> Self {
        Output { position: 2048.0, velocity: 0.0, at_us: 0, injected: ServoStatus::NONE }
    }
}


/// The voltage a robot's STS3215 with control table `table` applies on
/// `supply_v` \[V\]: in Operating Mode 2 with torque on, Goal Time's duty
/// cycle (0.1 % of the supply, sign bit 10, at most 100 %), as the ratio
/// `pada run --board` applies (`pada_core::servo::Drive::ratio`); in the
/// other modes none (the position loop moves only a bare chain's output).
pub fn volts(table: &[u8], supply_v: f64) -> f64 {
    if table[sts::TORQUE_ENABLE as usize] != 1 || table[sts::OPERATING_MODE as usize] != sts::MODE_PWM {
        return 0.0;
    }
    let at = sts::GOAL_TIME as usize;
    let raw = u16::from_le_bytes([table[at], table[at + 1]]);
    let duty = from_sign_magnitude(raw, DUTY_SIGN_BIT).clamp(-MAX_DUTY, MAX_DUTY);
    (duty as f32 / MAX_DUTY as f32) as f64 * supply_v
}
