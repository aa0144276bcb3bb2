//! A robot's hardware as its definition describes it: which servo drives
//! each joint and how its counts map to the joint's angle, the soft
//! limits that fault the robot, and the encoder. The firmware drives the
//! robot through these, and the host's simulated servos read in the same
//! frame, so an offset or flipped servo of the real robot is the same
//! offset or flip in simulation, and the calibration undoes it.

use crate::dynamixel::table;
use crate::safety::SoftLimit;
use crate::servo::{CommandKind, Drive, PositionScale, ServoModel};

/// Position unit of the RX-28: 300° over 1023 counts \[rad\].
pub const POSITION_UNIT_RAD: f32 = table::POSITION_RANGE_RAD / table::POSITION_MAX as f32;

/// One joint of a robot: its name, its servo and the servo's calibration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSpec {
    /// The joint's name (in a URDF robot, the URDF's joint name).
    pub name: &'static str,
    /// The servo model that drives it, from [`crate::servo`]'s table.
    pub servo: &'static ServoModel,
    /// Dynamixel ID.
    pub id: u8,
    /// Raw Present Position at joint angle 0.
    pub zero: u16,
    /// +1 if the joint angle grows with the servo's position counts
    /// (counter-clockwise), −1 otherwise.
    pub sign: i8,
    /// Past these joint angles the robot faults (torque off); `None` for a
    /// joint that turns freely.
    pub soft_limit: Option<SoftLimit>,
}

impl JointSpec {
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

    /// Joint angle \[rad\] of a Present Position in the counts of the
    /// joint's servo model ([`crate::servo::encoding`]); for the RX-28 the
    /// same value as [`angle`](Self::angle), bit for bit.
    pub fn angle_of(&self, counts: i32) -> f32 {
        let scale = self.servo.encoding.position;
        match scale {
            PositionScale::Span { max, .. } => {
                let counts = counts.clamp(0, max as i32) - self.zero as i32;
                self.sign as f32 * counts as f32 * scale.unit_rad()
            }
            PositionScale::Turns { per_turn } => {
                // In f64: a multi-turn count loses no turn to rounding.
                let counts = counts as i64 - self.zero as i64;
                (self.sign as f64 * counts as f64 * core::f64::consts::TAU / per_turn as f64) as f32
            }
        }
    }

    /// The Present Position, in the counts of the joint's servo model, at
    /// joint angle `angle` \[rad\]: the inverse of
    /// [`angle_of`](Self::angle_of), rounded to the nearest count (an
    /// absolute sensor's range clamps); for the RX-28 the value of
    /// [`position_of`](Self::position_of). What a simulated servo reads.
    pub fn counts_of(&self, angle: f64) -> i32 {
        let unit = match self.servo.encoding.position {
            PositionScale::Span { max, range_rad } => range_rad as f64 / max as f64,
            PositionScale::Turns { per_turn } => core::f64::consts::TAU / per_turn as f64,
        };
        self.servo.encoding.position.counts(self.zero as f64, self.sign as f64 * angle / unit)
    }

    /// The command that applies `voltage` \[V\] in the joint's positive
    /// direction with `supply` \[V\] on the servo, in the servo model's
    /// kind ([`CommandKind`]): Moving Speed as [`moving_speed`](Self::moving_speed)
    /// gives it, or Goal PWM of the same ratio. A missing or implausible
    /// supply reading (below 5 V) uses `fallback`.
    pub fn drive(&self, voltage: f32, supply: Option<f32>, fallback: f32) -> Drive {
        match self.servo.encoding.command {
            CommandKind::MovingSpeed => Drive::MovingSpeed(self.moving_speed(voltage, supply, fallback)),
            kind => {
                let supply = match supply {
                    Some(v) if v >= 5.0 && v.is_finite() => v,
                    _ => fallback,
                };
                Drive::from_ratio(kind, self.sign as f32 * voltage / supply)
            }
        }
    }

    /// The voltage \[V\] a command applies in the joint's direction with
    /// `supply` \[V\] (for Moving Speed, [`voltage_of`](Self::voltage_of)).
    pub fn voltage_of_drive(&self, drive: Drive, supply: f32) -> f32 {
        match drive {
            Drive::MovingSpeed(v) => self.voltage_of(v, supply),
            _ => self.sign as f32 * drive.ratio() * supply,
        }
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

/// A quadrature encoder on the robot (the pendulum's axis, LEO's boom).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EncoderSpec {
    /// Counts per revolution after the timer's ×4 decoding (a 1024-line
    /// encoder gives 4096).
    pub counts_per_rev: u32,
    /// +1 if counting up turns the measured angle positive.
    pub sign: i8,
}

impl EncoderSpec {
    /// Angle \[rad\] of `counts` since the reference.
    pub fn angle(&self, counts: i64) -> f32 {
        let turns = counts as f64 / self.counts_per_rev as f64;
        (self.sign as f64 * turns * core::f64::consts::TAU) as f32
    }

    /// The 16-bit timer count of `angle` \[rad\] from the reference: the
    /// inverse of [`angle`](Self::angle), wrapping as the timer does. What
    /// a simulated encoder of this configuration reads.
    pub fn count_of(&self, angle: f64) -> u16 {
        let counts = libm::round(self.sign as f64 * angle / core::f64::consts::TAU * self.counts_per_rev as f64) as i64;
        counts.rem_euclid(1 << 16) as u16
    }
}

/// A run of joints, `start..end` in joint order: the gearboxes a robot
/// counts for the paper's MTBF.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JointRange {
    /// The first joint.
    pub start: u8,
    /// One past the last joint.
    pub end: u8,
}

impl JointRange {
    /// The joints as a range of indices.
    pub const fn range(self) -> core::ops::Range<usize> {
        self.start as usize..self.end as usize
    }

    /// How many joints.
    pub const fn len(self) -> usize {
        self.end.saturating_sub(self.start) as usize
    }

    /// Whether there are none.
    pub const fn is_empty(self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const J: JointSpec = JointSpec { name: "j", servo: &crate::servo::RX28, id: 1, zero: 512, sign: 1, soft_limit: None };

    #[test]
    fn angle_follows_calibration() {
        assert_eq!(J.angle(512), 0.0);
        assert!((J.angle(612) - 100.0 * POSITION_UNIT_RAD).abs() < 1e-6);
        let flipped = JointSpec { sign: -1, ..J };
        assert!((flipped.angle(612) + 100.0 * POSITION_UNIT_RAD).abs() < 1e-6);
        // Out-of-range readings saturate at the table's maximum.
        assert_eq!(J.angle(5000), J.angle(1023));
    }

    #[test]
    fn position_of_inverts_angle_for_any_calibration() {
        for j in [J, JointSpec { id: 2, zero: 300, sign: -1, ..J }] {
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
        // 6 V of 12 V: half output, counter-clockwise.
        assert_eq!(J.moving_speed(6.0, Some(12.0), 14.0), 512);
        // Negative: clockwise bit set.
        assert_eq!(J.moving_speed(-6.0, Some(12.0), 14.0), 1024 | 512);
        // The joint's sign flips the direction.
        let flipped = JointSpec { sign: -1, ..J };
        assert_eq!(flipped.moving_speed(6.0, Some(12.0), 14.0), 1024 | 512);
        // No reading, or a silly one: the nominal supply.
        assert_eq!(J.moving_speed(7.0, None, 14.0), 512);
        assert_eq!(J.moving_speed(7.0, Some(0.0), 14.0), 512);
        // More than the supply saturates.
        assert_eq!(J.moving_speed(30.0, Some(12.0), 14.0), 1023);
        assert_eq!(J.moving_speed(0.0, Some(12.0), 14.0), 0);
        // And back.
        assert!((J.voltage_of(512, 12.0) - 6.0).abs() < 0.01);
        assert!((J.voltage_of(1024 | 512, 12.0) + 6.0).abs() < 0.01);
    }

    #[test]
    fn counts_of_each_model_invert_the_angle_and_the_rx28_is_unchanged() {
        for raw in 0u16..=1023 {
            assert_eq!(J.angle_of(raw as i32).to_bits(), J.angle(raw).to_bits(), "{raw}");
            assert_eq!(J.counts_of(J.angle(raw) as f64), raw as i32);
        }
        assert_eq!(J.angle_of(5000), J.angle(1023));
        assert_eq!(J.angle_of(-3), J.angle(0));
        let x = JointSpec { servo: &crate::servo::XM430_W350, zero: 2048, sign: -1, ..J };
        for counts in [-100_000, -4097, 0, 1, 2048, 4095, 4096 * 30 + 7] {
            assert_eq!(x.counts_of(x.angle_of(counts) as f64), counts, "{counts}");
        }
        // A whole turn is 4096 counts, past the single turn's range.
        assert!((x.angle_of(2048 - 4096) - core::f32::consts::TAU).abs() < 1e-6);
        let mx = JointSpec { servo: &crate::servo::MX28, zero: 2048, ..J };
        assert!((mx.angle_of(3072) - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert_eq!(mx.counts_of(10.0), 4095);
    }

    #[test]
    fn commands_are_the_models_own() {
        for v in [-14.0f32, -6.0, -0.01, 0.0, 3.0, 6.0, 30.0] {
            let d = J.drive(v, Some(12.0), 14.0);
            assert_eq!(d, Drive::MovingSpeed(J.moving_speed(v, Some(12.0), 14.0)));
            assert_eq!(J.voltage_of_drive(d, 12.0).to_bits(), J.voltage_of(J.moving_speed(v, Some(12.0), 14.0), 12.0).to_bits());
        }
        let x = JointSpec { servo: &crate::servo::XL430_W250, zero: 2048, sign: -1, ..J };
        assert_eq!(x.drive(6.0, Some(12.0), 14.0), Drive::GoalPwm { pwm: -443, full: 885 });
        assert_eq!(x.drive(6.0, None, 12.0), Drive::GoalPwm { pwm: -443, full: 885 });
        assert_eq!(x.drive(99.0, Some(12.0), 12.0), Drive::GoalPwm { pwm: -885, full: 885 });
        assert!((x.voltage_of_drive(x.drive(6.0, Some(12.0), 14.0), 12.0) - 6.0).abs() < 12.0 / 885.0);
    }

    #[test]
    fn angle_of_a_turn() {
        use core::f32::consts::PI;
        let e = EncoderSpec { counts_per_rev: 4096, sign: 1 };
        assert!((e.angle(4096) - 2.0 * PI).abs() < 1e-6);
        assert!((e.angle(-1024) + PI / 2.0).abs() < 1e-6);
        let flipped = EncoderSpec { sign: -1, ..e };
        assert!((flipped.angle(1024) + PI / 2.0).abs() < 1e-6);
    }

    #[test]
    fn count_of_inverts_angle_and_wraps_like_the_timer() {
        use core::f64::consts::TAU;
        for e in [EncoderSpec { counts_per_rev: 4096, sign: 1 }, EncoderSpec { counts_per_rev: 2000, sign: -1 }] {
            assert_eq!(e.count_of(0.0), 0);
            for counts in [1i64, 100, -100, 4095, -30_000] {
                assert_eq!(e.count_of(e.angle(counts) as f64), counts.rem_euclid(1 << 16) as u16, "{e:?} at {counts}");
            }
        }
        // Sixteen whole turns of 4096 counts are 65 536: the timer's wrap.
        let e = EncoderSpec { counts_per_rev: 4096, sign: 1 };
        assert_eq!(e.count_of(16.0 * TAU), 0);
        assert_eq!(e.count_of(-TAU / 4096.0), 65_535);
    }

    #[test]
    fn a_joint_range() {
        let r = JointRange { start: 1, end: 5 };
        assert_eq!((r.range(), r.len(), r.is_empty()), (1..5, 4, false));
        assert!(JointRange { start: 2, end: 2 }.is_empty());
    }
}
