//! The block of the STS memory table a controller writes every period, in
//! one SYNC WRITE to every servo: Torque Enable (40), Acceleration (41),
//! Goal Position (42–43) and Goal Time (44–45), contiguous, so that torque
//! and command travel in the same packet (docs/reference/feetech.md §
//! "Which mode pada uses and why").
//!
//! - In Operating Mode 2 (open-loop PWM), Goal Time is the duty cycle in
//!   0.1 % of the supply, sign bit 10; the documented range is 50–1000, so
//!   a smaller magnitude is written as 0 ([`goal_time_of_duty`]).
//! - In Operating Mode 0 (position), Goal Position is the goal in steps
//!   and Goal Time 0 (the move at the servo's own speed).
//! - Acceleration is written as the servo had it at set-up, so that the
//!   block leaves it as it was.

use super::control_table::sts3215::TORQUE_ENABLE;
use super::value::{to_sign_magnitude_saturating, POSITION_SIGN_BIT};
use super::ByteOrder;

/// The block's first address: Torque Enable.
pub const COMMAND_BLOCK: u8 = TORQUE_ENABLE;
/// The block's length: Torque Enable … Goal Time.
pub const COMMAND_LEN: u8 = 6;
/// The least duty cycle Feetech documents for Operating Mode 2 \[0.1 %\].
pub const MIN_DUTY: i32 = 50;
/// The largest, 100 % \[0.1 %\].
pub const MAX_DUTY: i32 = 1000;
/// Goal Time's sign bit in Operating Mode 2.
pub const DUTY_SIGN_BIT: u8 = 10;

/// What one servo is told in a period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Command {
    /// Torque Enable.
    pub torque: bool,
    /// Acceleration, as the servo had it (0: the largest).
    pub acceleration: u8,
    /// Goal Position \[steps\] (Operating Mode 0).
    pub goal_position: i32,
    /// Duty cycle \[0.1 % of the supply\] (Operating Mode 2), counter-clockwise
    /// positive.
    pub duty: i32,
}

impl Command {
    /// The block's bytes in `order`.
    pub fn block(&self, order: ByteOrder) -> [u8; COMMAND_LEN as usize] {
        let [p0, p1] = order.u16_bytes(to_sign_magnitude_saturating(self.goal_position, POSITION_SIGN_BIT));
        let [t0, t1] = order.u16_bytes(goal_time_of_duty(self.duty));
        [self.torque as u8, self.acceleration, p0, p1, t0, t1]
    }
}

/// Goal Time's raw value for a duty cycle in 0.1 %: saturated at ±1000,
/// 0 below the documented 50, sign bit 10.
pub const fn goal_time_of_duty(duty: i32) -> u16 {
    let magnitude = duty.unsigned_abs();
    if magnitude < MIN_DUTY as u32 {
        return 0;
    }
    let m = if magnitude > MAX_DUTY as u32 { MAX_DUTY as u16 } else { magnitude as u16 };
    if duty < 0 {
        m | (1 << DUTY_SIGN_BIT)
    } else {
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_duty_floor_sign_and_block() {
        // (duty in 0.1 %, Goal Time's raw bits): the floor, the sign, the
        // saturation.
        let cases = [(0, 0), (49, 0), (-49, 0), (50, 50), (-500, 0x0400 | 500), (5000, 1000), (i32::MIN, 0x0400 | 1000)];
        for (duty, raw) in cases {
            assert_eq!(goal_time_of_duty(duty), raw, "duty {duty}");
        }
        let c = Command { torque: true, acceleration: 254, goal_position: 2048, duty: -300 };
        assert_eq!(c.block(ByteOrder::Little), [1, 254, 0x00, 0x08, 0x2C, 0x05]);
        assert_eq!(c.block(ByteOrder::Big), [1, 254, 0x08, 0x00, 0x05, 0x2C]);
        assert_eq!(Command::default().block(ByteOrder::Little), [0; 6]);
    }
}
