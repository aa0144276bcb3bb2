//! One RX-28 as a joint: calibration, and the commanded voltage as a
//! wheel-mode Moving Speed. (Its torque estimate for the fatigue counter is
//! the RX-28 model of `pada_core::rx28`, through the robot's definition.)
//!
//! In wheel mode the RX-28's Moving Speed is not a speed but the motor's
//! output ratio (PWM duty): bits 0–9 the magnitude out of 1023, bit 10 the
//! direction (set = clockwise). A voltage `U` is therefore sent as the ratio
//! `U / V_supply` of the supply the servo measures itself (Present Voltage),
//! which keeps the motor's voltage right while the battery sags.

use pada_core::dynamixel::table;

/// Position unit of the RX-28: 300° over 1023 counts \[rad\].
pub const POSITION_UNIT_RAD: f32 = table::POSITION_RANGE_RAD / table::POSITION_MAX as f32;

/// One joint's servo and its calibration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Joint {
    /// Dynamixel ID.
    pub id: u8,
    /// Raw Present Position at joint angle 0.
    pub zero: u16,
    /// +1 if the joint angle grows with the servo's position counts
    /// (counter-clockwise), −1 otherwise.
    pub sign: i8,
}

impl Joint {
    /// Joint angle \[rad\] of a raw Present Position.
    pub fn angle(&self, position: u16) -> f32 {
        let counts = position.min(table::POSITION_MAX) as i32 - self.zero as i32;
        self.sign as f32 * counts as f32 * POSITION_UNIT_RAD
    }

    /// The raw Present Position at joint angle `angle` \[rad\]: the
    /// inverse of [`angle`](Self::angle), rounded to the nearest count and
    /// clamped to the table's range (the potentiometer's dead zone reads as
    /// the nearest end). What a simulated servo of this calibration reads.
    /// In f64, so that a simulation's angle is not rounded twice.
    pub fn position_of(&self, angle: f64) -> u16 {
        let unit = table::POSITION_RANGE_RAD as f64 / table::POSITION_MAX as f64;
        let counts = self.zero as f64 + self.sign as f64 * angle / unit;
        libm::round(counts).clamp(0.0, table::POSITION_MAX as f64) as u16
    }

    /// Moving Speed (wheel mode) that applies `voltage` \[V\] in the joint's
    /// positive direction with `supply` \[V\] on the servo. The ratio is
    /// clipped to ±1 (the servo cannot give more than its supply); a
    /// missing or implausible supply reading (below 5 V) uses `fallback`.
    pub fn moving_speed(&self, voltage: f32, supply: Option<f32>, fallback: f32) -> u16 {
        let supply = match supply {
            Some(v) if v >= 5.0 && v.is_finite() => v,
            _ => fallback,
        };
        table::moving_speed_from_ratio(self.sign as f32 * voltage / supply)
    }

    /// The voltage \[V\] a Moving Speed applies in the joint's direction.
    pub fn voltage_of(&self, moving_speed: u16, supply: f32) -> f32 {
        self.sign as f32 * table::ratio_from_moving_speed(moving_speed) * supply
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_follows_calibration() {
        let j = Joint { id: 1, zero: 512, sign: 1 };
        assert_eq!(j.angle(512), 0.0);
        assert!((j.angle(612) - 100.0 * POSITION_UNIT_RAD).abs() < 1e-6);
        let flipped = Joint { sign: -1, ..j };
        assert!((flipped.angle(612) + 100.0 * POSITION_UNIT_RAD).abs() < 1e-6);
        // Out-of-range readings saturate at the table's maximum.
        assert_eq!(j.angle(5000), j.angle(1023));
    }

    #[test]
    fn position_of_inverts_angle_for_any_calibration() {
        for j in [Joint { id: 1, zero: 512, sign: 1 }, Joint { id: 2, zero: 300, sign: -1 }] {
            for raw in [0u16, 1, 299, 300, 512, 700, 1023] {
                assert_eq!(j.position_of(j.angle(raw) as f64), raw, "{j:?} at {raw}");
            }
            // Past the range: the nearest end.
            assert_eq!(j.position_of(j.sign as f64 * 10.0), table::POSITION_MAX);
            assert_eq!(j.position_of(-j.sign as f64 * 10.0), 0);
        }
    }

    #[test]
    fn voltage_is_a_ratio_of_the_measured_supply() {
        let j = Joint { id: 1, zero: 512, sign: 1 };
        // 6 V of 12 V: half output, counter-clockwise.
        assert_eq!(j.moving_speed(6.0, Some(12.0), 14.0), 512);
        // Negative: clockwise bit set.
        assert_eq!(j.moving_speed(-6.0, Some(12.0), 14.0), 1024 | 512);
        // The joint's sign flips the direction.
        let flipped = Joint { sign: -1, ..j };
        assert_eq!(flipped.moving_speed(6.0, Some(12.0), 14.0), 1024 | 512);
        // No reading, or a silly one: the nominal supply.
        assert_eq!(j.moving_speed(7.0, None, 14.0), 512);
        assert_eq!(j.moving_speed(7.0, Some(0.0), 14.0), 512);
        // More than the supply saturates.
        assert_eq!(j.moving_speed(30.0, Some(12.0), 14.0), 1023);
        assert_eq!(j.moving_speed(0.0, Some(12.0), 14.0), 0);
        // And back.
        assert!((j.voltage_of(512, 12.0) - 6.0).abs() < 0.01);
        assert!((j.voltage_of(1024 | 512, 12.0) + 6.0).abs() < 0.01);
    }
}
