//! How a servo model's control table says position, speed, load and the
//! voltage command: the per-model units that turn a reading into a joint's
//! angle and a commanded voltage into the command the servo takes.
//!
//! | model | protocol | position | speed unit | voltage command |
//! |---|---|---|---|---|
//! | RX-28 | 1.0 | 0–1023 over 300° (clamped) | 0.111 rev/min | Moving Speed in wheel mode: a ratio of the output, 0–1023 CCW, 1024–2047 CW |
//! | MX-28 | 1.0 | 0–4095 at 0.088° (4096 per turn; clamped) | 0.114 rev/min | Moving Speed in wheel mode, as the RX-28 |
//! | XM430-W350, XL430-W250, XL330-M288 | 2.0 | 4096 per turn, multi-turn (signed 32 bits) in PWM Control Mode | 0.229 rev/min | Goal PWM in PWM Control Mode (Operating Mode 16): ±885 = ±100 % of the supply |
//! | STS3215 (every gear variant) | Feetech | 0–4095 (4096 per turn) | 1 count/s = 60/4096 rev/min | Goal_Time in Operating_Mode 2 (PWM open loop): ±1000 = ±100 % of the supply, 50 the least non-zero |
//!
//! Sources: each model's e-Manual page (the [`super::ServoModel::source`]
//! of its entry): the RX-28's and MX-28's "Present Position", "Moving
//! Speed" (wheel mode: "the unit is about 0.1 %", bit 10 the direction)
//! and "Present Speed"; the X series' "Present Position" (4096 pulses per
//! revolution; outside Position Control Mode it counts turns), "Present
//! Velocity" (0.229 rev/min) and "PWM Limit"/"Goal PWM" (0–885 = 0–100 %,
//! docs/reference/dynamixel.md § 5); the STS3215's memory table (Present
//! Position 0–4095, Present Velocity in steps per second, Goal_Time in
//! 0.1 % "in the PWM open-loop speed control mode the value range is from
//! 50 to 1000", docs/reference/feetech.md, "How pada acts through a
//! Feetech servo"). All three commands are the paper's voltage actions: a
//! fraction of the measured supply that the servo's H-bridge applies to
//! its motor.
//!
//! [`Present`] is one servo's reading in its model's raw units, whatever
//! its protocol, so that the controller reads every servo the same way;
//! [`Drive`] is the command it is sent.

use crate::dynamixel::control_table::x_series;
use crate::dynamixel::table;

/// How Present Position counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PositionScale {
    /// `0..=max` counts over `range_rad`, clamped at both ends: an absolute
    /// sensor (the RX-28's potentiometer reads its dead zone as the nearest
    /// end).
    Span {
        /// The largest count.
        max: u16,
        /// The angle the largest count stands for \[rad\].
        range_rad: f32,
    },
    /// `per_turn` counts per revolution, signed, counting whole turns (the
    /// X series' magnetic encoder outside Position Control Mode).
    Turns {
        /// Counts per revolution.
        per_turn: u32,
    },
}

impl PositionScale {
    /// Radians per count.
    pub fn unit_rad(&self) -> f32 {
        match *self {
            PositionScale::Span { max, range_rad } => range_rad / max as f32,
            PositionScale::Turns { per_turn } => (core::f64::consts::TAU / per_turn as f64) as f32,
        }
    }

    /// The count a joint angle's worth of counts from `zero` rounds to, in
    /// the scale's range (f64, so that a simulation's angle is rounded
    /// once).
    pub fn counts(&self, zero: f64, delta_counts: f64) -> i32 {
        let c = libm::round(zero + delta_counts);
        match *self {
            PositionScale::Span { max, .. } => c.clamp(0.0, max as f64) as i32,
            PositionScale::Turns { .. } => c.clamp(i32::MIN as f64, i32::MAX as f64) as i32,
        }
    }
}

/// What a servo takes as the voltage command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommandKind {
    /// Moving Speed in wheel mode (Protocol 1.0, both angle limits 0):
    /// 0–1023 counter-clockwise, 1024–2047 clockwise, a ratio of the
    /// output ([`table::moving_speed_from_ratio`]).
    MovingSpeed,
    /// Goal PWM in PWM Control Mode (Operating Mode 16): `±full` is ±100 %
    /// of the supply.
    GoalPwm {
        /// Goal PWM of 100 % (the X series' PWM Limit range, 885).
        full: i16,
    },
    /// Goal_Time in Operating_Mode 2, a Feetech servo's PWM open loop:
    /// `±full` is ±100 % of the supply; a magnitude below `floor` is
    /// outside the documented range and is sent as 0. On the wire the
    /// sign is bit 10 (sign and magnitude), the bus's business.
    GoalTime {
        /// Goal_Time of 100 % (1000, in 0.1 %).
        full: i16,
        /// The least non-zero magnitude (50, 5 %).
        floor: i16,
    },
}

/// A servo model's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Encoding {
    /// Present Position.
    pub position: PositionScale,
    /// One count of Present Speed / Present Velocity \[rev/min\].
    pub speed_unit_rpm: f32,
    /// The voltage command.
    pub command: CommandKind,
}

/// The RX-28 (the paper's): 1023 counts over 300°, Moving Speed.
pub const RX28: Encoding = Encoding {
    position: PositionScale::Span { max: table::POSITION_MAX, range_rad: table::POSITION_RANGE_RAD },
    speed_unit_rpm: table::SPEED_UNIT_RPM,
    command: CommandKind::MovingSpeed,
};

/// The MX-28 on Protocol 1.0: 0–4095 at 0.088° (4096 counts per turn),
/// Moving Speed.
pub const MX28: Encoding = Encoding {
    position: PositionScale::Span { max: 4095, range_rad: core::f32::consts::TAU * (4095.0 / 4096.0) },
    speed_unit_rpm: 0.114,
    command: CommandKind::MovingSpeed,
};

/// Goal PWM of 100 % on every X-series model pada knows (PWM Limit's range,
/// docs/reference/dynamixel.md § 5).
pub const X_PWM_FULL: i16 = 885;

/// The X series in PWM Control Mode: 4096 counts per turn, Goal PWM.
pub const X_SERIES: Encoding = Encoding {
    position: PositionScale::Turns { per_turn: x_series::PULSES_PER_REV },
    speed_unit_rpm: 0.229,
    command: CommandKind::GoalPwm { full: X_PWM_FULL },
};

/// Goal_Time of 100 % on the STS3215 in Operating_Mode 2 (0.1 % units).
pub const FT_TIME_FULL: i16 = 1000;

/// The least non-zero Goal_Time the memory table documents in
/// Operating_Mode 2 (5 %).
pub const FT_TIME_FLOOR: i16 = 50;

/// The STS3215 (Feetech): 0–4095 over one turn (4096 per turn, clamped as
/// the MX-28's), Present Velocity in steps per second, Goal_Time in
/// Operating_Mode 2.
pub const STS3215: Encoding = Encoding {
    position: PositionScale::Span { max: 4095, range_rad: core::f32::consts::TAU * (4095.0 / 4096.0) },
    speed_unit_rpm: 60.0 / 4096.0,
    command: CommandKind::GoalTime { full: FT_TIME_FULL, floor: FT_TIME_FLOOR },
};

/// The command sent to one servo in a control period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Drive {
    /// Moving Speed (wheel mode).
    MovingSpeed(u16),
    /// Goal PWM (PWM Control Mode), within `±full`.
    GoalPwm {
        /// The value written.
        pwm: i16,
        /// Goal PWM of 100 %.
        full: i16,
    },
    /// Goal_Time (a Feetech servo's Operating_Mode 2), signed, within
    /// `±full`; 0 or at least the floor in magnitude.
    GoalTime {
        /// The value, signed (the sign becomes bit 10 on the wire).
        time: i16,
        /// Goal_Time of 100 %.
        full: i16,
    },
}

impl Drive {
    /// Nothing: the command that applies 0 V.
    pub const fn zero(kind: CommandKind) -> Drive {
        match kind {
            CommandKind::MovingSpeed => Drive::MovingSpeed(0),
            CommandKind::GoalPwm { full } => Drive::GoalPwm { pwm: 0, full },
            CommandKind::GoalTime { full, .. } => Drive::GoalTime { time: 0, full },
        }
    }

    /// The command of the same kind that applies 0 V.
    pub const fn zeroed(self) -> Drive {
        match self {
            Drive::MovingSpeed(_) => Drive::MovingSpeed(0),
            Drive::GoalPwm { full, .. } => Drive::GoalPwm { pwm: 0, full },
            Drive::GoalTime { full, .. } => Drive::GoalTime { time: 0, full },
        }
    }

    /// The command of a signed output ratio in −1..1 (saturated; NaN is 0).
    pub fn from_ratio(kind: CommandKind, ratio: f32) -> Drive {
        match kind {
            CommandKind::MovingSpeed => Drive::MovingSpeed(table::moving_speed_from_ratio(ratio)),
            CommandKind::GoalPwm { full } => {
                let r = if ratio.is_nan() { 0.0 } else { ratio.clamp(-1.0, 1.0) };
                let pwm = libm::roundf(r * full as f32).clamp(-(full as f32), full as f32) as i16;
                Drive::GoalPwm { pwm, full }
            }
            CommandKind::GoalTime { full, floor } => {
                let r = if ratio.is_nan() { 0.0 } else { ratio.clamp(-1.0, 1.0) };
                let time = libm::roundf(r * full as f32).clamp(-(full as f32), full as f32) as i16;
                // Below the floor the mode's behaviour is undocumented: 0.
                let time = if time.unsigned_abs() < floor.unsigned_abs() { 0 } else { time };
                Drive::GoalTime { time, full }
            }
        }
    }

    /// The signed output ratio the command applies, −1..1 (counter-clockwise
    /// positive).
    pub fn ratio(&self) -> f32 {
        match *self {
            Drive::MovingSpeed(v) => table::ratio_from_moving_speed(v),
            Drive::GoalPwm { pwm, full } => pwm as f32 / full.max(1) as f32,
            Drive::GoalTime { time, full } => time as f32 / full.max(1) as f32,
        }
    }
}

/// One servo's reading in its model's raw units, whatever its protocol:
/// what the controller reads every period.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Present {
    /// Present Position (RX-28: 0–1023; X series: signed, multi-turn).
    pub position: i32,
    /// Present Speed (Protocol 1.0: bit 10 the direction, as received) or
    /// Present Velocity (X series, signed).
    pub speed: i32,
    /// Present Load (Protocol 1.0, raw) or Present Current / Load (X
    /// series, signed).
    pub load: i32,
    /// Supply \[0.1 V\].
    pub voltage_dv: u16,
    /// Temperature \[°C\].
    pub temperature: u8,
}

impl Present {
    /// The supply \[V\] (0.1 V units; the RX-28's one-byte reading gives
    /// the same value as [`table::voltage_v`]).
    pub fn voltage_v(&self) -> f32 {
        self.voltage_dv as f32 * 0.1
    }
}

impl From<table::PresentState> for Present {
    fn from(p: table::PresentState) -> Self {
        Present {
            position: p.position as i32,
            speed: p.speed as i32,
            load: p.load as i32,
            voltage_dv: p.voltage as u16,
            temperature: p.temperature,
        }
    }
}

impl From<x_series::PresentState> for Present {
    fn from(p: x_series::PresentState) -> Self {
        Present {
            position: p.position,
            speed: p.velocity,
            load: p.current as i32,
            voltage_dv: p.input_voltage,
            temperature: p.temperature,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_speed_is_the_rx28_encoding_and_goal_pwm_a_fraction_of_885() {
        for r in [-1.5f32, -1.0, -0.5, -0.0001, 0.0, 0.25, 0.5, 1.0, 2.0, f32::NAN] {
            assert_eq!(Drive::from_ratio(CommandKind::MovingSpeed, r), Drive::MovingSpeed(table::moving_speed_from_ratio(r)));
        }
        let pwm = |r| Drive::from_ratio(X_SERIES.command, r);
        assert_eq!(pwm(1.0), Drive::GoalPwm { pwm: 885, full: 885 });
        assert_eq!(pwm(-3.0), Drive::GoalPwm { pwm: -885, full: 885 });
        assert_eq!(pwm(0.5), Drive::GoalPwm { pwm: 443, full: 885 });
        assert_eq!(pwm(f32::NAN), Drive::zero(X_SERIES.command));
        assert!((pwm(0.25).ratio() - 0.25).abs() < 0.5 / 885.0);
        assert_eq!(Drive::zero(CommandKind::MovingSpeed).ratio(), 0.0);
    }

    #[test]
    fn goal_time_is_a_fraction_of_1000_with_the_5_percent_floor() {
        let t = |r| Drive::from_ratio(STS3215.command, r);
        assert_eq!(t(1.0), Drive::GoalTime { time: 1000, full: 1000 });
        assert_eq!(t(-2.0), Drive::GoalTime { time: -1000, full: 1000 });
        assert_eq!(t(0.5), Drive::GoalTime { time: 500, full: 1000 });
        assert_eq!(t(0.05), Drive::GoalTime { time: 50, full: 1000 });
        assert_eq!(t(-0.05), Drive::GoalTime { time: -50, full: 1000 });
        // Below 5 % of the supply: 0, not an undocumented command.
        assert_eq!(t(0.049), Drive::zero(STS3215.command));
        assert_eq!(t(-0.0494), Drive::zero(STS3215.command));
        assert_eq!(t(f32::NAN), Drive::zero(STS3215.command));
        assert!((t(-0.25).ratio() + 0.25).abs() < 0.5 / 1000.0);
        assert_eq!(t(0.7).zeroed(), Drive::zero(STS3215.command));
        assert_eq!(Drive::MovingSpeed(300).zeroed(), Drive::MovingSpeed(0));
        assert!((STS3215.position.unit_rad() - 0.001_533_98).abs() < 1e-8);
        assert_eq!(STS3215.position.counts(2048.0, 3000.0), 4095);
        assert!((STS3215.speed_unit_rpm - 0.014_648_437).abs() < 1e-9);
    }

    #[test]
    fn scales() {
        assert_eq!(RX28.position.unit_rad(), crate::robot::hardware::POSITION_UNIT_RAD);
        assert!((X_SERIES.position.unit_rad() - 0.001_533_98).abs() < 1e-8);
        assert_eq!(RX28.position.counts(512.0, 600.0), 1023);
        assert_eq!(RX28.position.counts(512.0, -600.0), 0);
        assert_eq!(X_SERIES.position.counts(2048.0, -5000.4), -2952);
        assert_eq!(MX28.position.counts(2048.0, 3000.0), 4095);
    }

    #[test]
    fn readings_of_both_protocols() {
        let p1 = table::PresentState { position: 700, speed: 1024 + 30, load: 200, voltage: 121, temperature: 41 };
        let p = Present::from(p1);
        assert_eq!((p.position, p.speed, p.load, p.voltage_dv, p.temperature), (700, 1054, 200, 121, 41));
        assert_eq!(p.voltage_v(), p1.voltage_v());
        let x = x_series::PresentState { position: -5000, velocity: -12, current: 30, input_voltage: 120, temperature: 39, ..Default::default() };
        let p = Present::from(x);
        assert_eq!((p.position, p.speed, p.load, p.voltage_dv), (-5000, -12, 30, 120));
        assert!((p.voltage_v() - 12.0).abs() < 1e-6);
        assert!((Present { voltage_dv: 300, ..p }.voltage_v() - 30.0).abs() < 1e-5);
    }
}
