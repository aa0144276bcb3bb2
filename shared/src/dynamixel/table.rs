//! The RX-28 control table: addresses and value encodings.
//!
//! Source: Robotis e-Manual, "RX-28", section "Control Table" (EEPROM area
//! 0–23, RAM area 24–49). Two-byte items are little endian, at the address
//! given and the next.

/// Model Number (2 bytes, R); the RX-28 reads 28.
pub const MODEL_NUMBER: u8 = 0;
/// Firmware Version (1, R).
pub const FIRMWARE_VERSION: u8 = 2;
/// ID (1, RW, EEPROM): 0–253.
pub const ID: u8 = 3;
/// Baud Rate (1, RW, EEPROM): bps = 2 000 000 / (value + 1); see [`baud_rate_bps`].
pub const BAUD_RATE: u8 = 4;
/// Return Delay Time (1, RW, EEPROM): 2 µs per unit.
pub const RETURN_DELAY_TIME: u8 = 5;
/// CW Angle Limit (2, RW, EEPROM): 0–1023. Both limits 0 = wheel mode.
pub const CW_ANGLE_LIMIT: u8 = 6;
/// CCW Angle Limit (2, RW, EEPROM): 0–1023. Both limits 0 = wheel mode.
pub const CCW_ANGLE_LIMIT: u8 = 8;
/// Highest Limit Temperature (1, RW, EEPROM), °C.
pub const HIGHEST_LIMIT_TEMPERATURE: u8 = 11;
/// Lowest Limit Voltage (1, RW, EEPROM), 0.1 V.
pub const LOWEST_LIMIT_VOLTAGE: u8 = 12;
/// Highest Limit Voltage (1, RW, EEPROM), 0.1 V.
pub const HIGHEST_LIMIT_VOLTAGE: u8 = 13;
/// Max Torque (2, RW, EEPROM): 0–1023 of the maximum.
pub const MAX_TORQUE: u8 = 14;
/// Status Return Level (1, RW, EEPROM): 0 PING only, 1 READ too, 2 all.
pub const STATUS_RETURN_LEVEL: u8 = 16;
/// Alarm LED (1, RW, EEPROM): error bits that light the LED.
pub const ALARM_LED: u8 = 17;
/// Alarm Shutdown (1, RW, EEPROM): error bits that switch torque off.
pub const ALARM_SHUTDOWN: u8 = 18;
/// Torque Enable (1, RW, RAM): 0 off, 1 on.
pub const TORQUE_ENABLE: u8 = 24;
/// LED (1, RW, RAM).
pub const LED: u8 = 25;
/// CW Compliance Margin (1, RW, RAM).
pub const CW_COMPLIANCE_MARGIN: u8 = 26;
/// CCW Compliance Margin (1, RW, RAM).
pub const CCW_COMPLIANCE_MARGIN: u8 = 27;
/// CW Compliance Slope (1, RW, RAM).
pub const CW_COMPLIANCE_SLOPE: u8 = 28;
/// CCW Compliance Slope (1, RW, RAM).
pub const CCW_COMPLIANCE_SLOPE: u8 = 29;
/// Goal Position (2, RW, RAM): 0–1023 over 0–300°.
pub const GOAL_POSITION: u8 = 30;
/// Moving Speed (2, RW, RAM). Wheel mode: 0–1023 CCW, 1024–2047 CW, as
/// a ratio of the output (bit 10 = direction); see [`moving_speed_from_ratio`].
pub const MOVING_SPEED: u8 = 32;
/// Torque Limit (2, RW, RAM): 0–1023.
pub const TORQUE_LIMIT: u8 = 34;
/// Present Position (2, R, RAM): 0–1023 over 0–300°.
pub const PRESENT_POSITION: u8 = 36;
/// Present Speed (2, R, RAM): 0–1023 CCW, 1024–2047 CW (bit 10 = direction).
pub const PRESENT_SPEED: u8 = 38;
/// Present Load (2, R, RAM): 0–1023 CCW, 1024–2047 CW (bit 10 = direction).
pub const PRESENT_LOAD: u8 = 40;
/// Present Voltage (1, R, RAM): 0.1 V units.
pub const PRESENT_VOLTAGE: u8 = 42;
/// Present Temperature (1, R, RAM): °C.
pub const PRESENT_TEMPERATURE: u8 = 43;
/// Registered (1, R, RAM): a REG_WRITE is pending.
pub const REGISTERED: u8 = 44;
/// Moving (1, R, RAM).
pub const MOVING: u8 = 46;
/// Lock (1, RW, RAM): locks the EEPROM area.
pub const LOCK: u8 = 47;
/// Punch (2, RW, RAM).
pub const PUNCH: u8 = 48;
/// Size of the control table in bytes (addresses 0–49).
pub const TABLE_LEN: usize = 50;

/// Present Position through Present Temperature: the block one READ
/// returns per control period (position, speed, load, voltage, temperature).
pub const PRESENT_BLOCK: u8 = PRESENT_POSITION;
/// Length of [`PRESENT_BLOCK`].
pub const PRESENT_BLOCK_LEN: u8 = 8;

/// The RX-28's model number.
pub const RX28_MODEL: u16 = 28;
/// Baud Rate value for 1 Mbps.
pub const BAUD_1MBPS: u8 = 1;
/// Position units over the 0–300° range: 0–1023.
pub const POSITION_MAX: u16 = 1023;
/// The angle Present Position 1023 stands for: 300°, in radians.
pub const POSITION_RANGE_RAD: f32 = 300.0 * core::f32::consts::PI / 180.0;
/// Magnitude units of the 11-bit speed and load encodings: 0–1023.
pub const MAGNITUDE_MAX: u16 = 1023;
/// Direction bit of Moving Speed (wheel mode), Present Speed and Present
/// Load: set = clockwise.
pub const DIRECTION_BIT: u16 = 1 << 10;
/// Present Speed unit in joint mode: about 0.111 rpm.
pub const SPEED_UNIT_RPM: f32 = 0.111;

/// The bit rate of a Baud Rate value: 2 000 000 / (value + 1) bps.
pub const fn baud_rate_bps(value: u8) -> u32 {
    2_000_000 / (value as u32 + 1)
}

/// Wheel-mode Moving Speed for a signed output ratio in −1..1: positive is
/// counter-clockwise (0–1023), negative clockwise (1024 + magnitude).
/// Values outside −1..1 saturate; NaN gives 0 (stop).
pub fn moving_speed_from_ratio(ratio: f32) -> u16 {
    encode_signed(ratio)
}

/// The signed ratio a Moving Speed value commands (the inverse of
/// [`moving_speed_from_ratio`], for the bus emulator).
pub fn ratio_from_moving_speed(value: u16) -> f32 {
    decode_signed(value)
}

/// Present Speed as a signed ratio of the maximum, −1..1 (CCW positive).
pub fn present_speed_ratio(value: u16) -> f32 {
    decode_signed(value)
}

/// Present Speed in rpm (joint-mode unit), CCW positive.
pub fn present_speed_rpm(value: u16) -> f32 {
    decode_magnitude(value) * SPEED_UNIT_RPM
}

/// Present Load as a signed ratio of the maximum torque, −1..1 (CCW
/// positive).
pub fn present_load_ratio(value: u16) -> f32 {
    decode_signed(value)
}

/// The 11-bit direction/magnitude encoding of a signed ratio (Present
/// Speed and Present Load too, for the bus emulator).
pub fn encode_signed(ratio: f32) -> u16 {
    if ratio.is_nan() {
        return 0;
    }
    let r = ratio.clamp(-1.0, 1.0);
    let m = libm::roundf(libm::fabsf(r) * MAGNITUDE_MAX as f32) as u16;
    let m = m.min(MAGNITUDE_MAX);
    if r < 0.0 && m > 0 {
        DIRECTION_BIT | m
    } else {
        m
    }
}

fn decode_magnitude(value: u16) -> f32 {
    let m = (value & 0x3FF) as f32;
    if value & DIRECTION_BIT != 0 {
        -m
    } else {
        m
    }
}

fn decode_signed(value: u16) -> f32 {
    decode_magnitude(value) / MAGNITUDE_MAX as f32
}

/// Present/Goal Position in radians, 0 at position 0 and 300° at 1023
/// (values above 1023 saturate).
pub fn position_rad(value: u16) -> f32 {
    value.min(POSITION_MAX) as f32 * (POSITION_RANGE_RAD / POSITION_MAX as f32)
}

/// Position in radians relative to the centre (512 = 150°), the
/// natural zero of a joint.
pub fn position_rad_centered(value: u16) -> f32 {
    position_rad(value) - position_rad(512)
}

/// The position value for an angle in radians from position 0, rounded
/// and saturated to 0–1023 (NaN gives 0); for the bus emulator.
pub fn position_from_rad(rad: f32) -> u16 {
    if rad.is_nan() {
        return 0;
    }
    let v = libm::roundf(rad * (POSITION_MAX as f32 / POSITION_RANGE_RAD));
    v.clamp(0.0, POSITION_MAX as f32) as u16
}

/// Present Voltage in volts (0.1 V units).
pub fn voltage_v(value: u8) -> f32 {
    value as f32 * 0.1
}

/// Present Temperature in °C.
pub fn temperature_c(value: u8) -> f32 {
    value as f32
}

/// The decoded [`PRESENT_BLOCK`] of one servo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PresentState {
    /// Present Position (raw 0–1023).
    pub position: u16,
    /// Present Speed (raw, bit 10 = CW).
    pub speed: u16,
    /// Present Load (raw, bit 10 = CW).
    pub load: u16,
    /// Present Voltage (0.1 V).
    pub voltage: u8,
    /// Present Temperature (°C).
    pub temperature: u8,
}

impl PresentState {
    /// Parses the 8 bytes of a READ of [`PRESENT_BLOCK`]; `None` if
    /// `bytes` is shorter.
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let b: &[u8; 8] = bytes.get(..8)?.try_into().ok()?;
        Some(PresentState {
            position: u16::from_le_bytes([b[0], b[1]]),
            speed: u16::from_le_bytes([b[2], b[3]]),
            load: u16::from_le_bytes([b[4], b[5]]),
            voltage: b[6],
            temperature: b[7],
        })
    }

    /// The 8 bytes of the block (bus-emulator side).
    pub fn to_bytes(&self) -> [u8; 8] {
        let [p0, p1] = self.position.to_le_bytes();
        let [s0, s1] = self.speed.to_le_bytes();
        let [l0, l1] = self.load.to_le_bytes();
        [p0, p1, s0, s1, l0, l1, self.voltage, self.temperature]
    }

    /// Position in radians from position 0.
    pub fn position_rad(&self) -> f32 {
        position_rad(self.position)
    }
    /// Speed as a signed ratio.
    pub fn speed_ratio(&self) -> f32 {
        present_speed_ratio(self.speed)
    }
    /// Load as a signed ratio.
    pub fn load_ratio(&self) -> f32 {
        present_load_ratio(self.load)
    }
    /// Supply voltage in volts.
    pub fn voltage_v(&self) -> f32 {
        voltage_v(self.voltage)
    }
    /// Temperature in °C.
    pub fn temperature_c(&self) -> f32 {
        temperature_c(self.temperature)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_speed_encoding() {
        assert_eq!(moving_speed_from_ratio(0.0), 0);
        assert_eq!(moving_speed_from_ratio(1.0), 1023);
        assert_eq!(moving_speed_from_ratio(-1.0), 2047);
        assert_eq!(moving_speed_from_ratio(2.0), 1023);
        assert_eq!(moving_speed_from_ratio(-7.0), 2047);
        assert_eq!(moving_speed_from_ratio(f32::NAN), 0);
        assert_eq!(moving_speed_from_ratio(0.5), 512);
        assert_eq!(moving_speed_from_ratio(-0.5), 1024 + 512);
        assert_eq!(moving_speed_from_ratio(-0.0001), 0, "no negative zero");
        for v in 0..2048u16 {
            if v == 1024 {
                continue; // "CW, magnitude 0" encodes as plain 0
            }
            assert_eq!(moving_speed_from_ratio(ratio_from_moving_speed(v)), v);
        }
    }

    #[test]
    fn feedback_decoding() {
        assert_eq!(present_load_ratio(1023), 1.0);
        assert_eq!(present_load_ratio(2047), -1.0);
        assert_eq!(present_speed_ratio(1024), -0.0);
        assert!((present_speed_rpm(100) - 11.1).abs() < 1e-4);
        assert!((present_speed_rpm(1124) + 11.1).abs() < 1e-4);
        assert_eq!(position_rad(0), 0.0);
        assert!((position_rad(1023) - 300f32.to_radians()).abs() < 1e-6);
        assert!((position_rad(1) - 0.005_118_268).abs() < 1e-7);
        assert!(position_rad_centered(512).abs() < 1e-7);
        assert_eq!(position_rad(5000), position_rad(1023));
        for v in 0..=1023u16 {
            assert_eq!(position_from_rad(position_rad(v)), v);
        }
        assert!((voltage_v(148) - 14.8).abs() < 1e-5);
        assert_eq!(temperature_c(45), 45.0);
        assert_eq!(baud_rate_bps(BAUD_1MBPS), 1_000_000);
        assert_eq!(baud_rate_bps(34), 57_142);
    }

    #[test]
    fn present_block_round_trip() {
        let s = PresentState { position: 700, speed: 1024 + 30, load: 200, voltage: 148, temperature: 41 };
        assert_eq!(PresentState::from_bytes(&s.to_bytes()), Some(s));
        assert_eq!(PresentState::from_bytes(&[0; 7]), None);
        assert_eq!(PRESENT_BLOCK_LEN as usize, s.to_bytes().len());
        assert_eq!(PRESENT_TEMPERATURE - PRESENT_POSITION + 1, PRESENT_BLOCK_LEN);
    }
}
