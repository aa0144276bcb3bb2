//! How a Feetech servo writes its multi-byte values: the byte order of its
//! series, and sign-magnitude for the signed ones (docs/reference/
//! feetech.md § "Values").
//!
//! A signed item keeps its magnitude in the bits below a sign bit and sets
//! the sign bit for a negative value, as Feetech's SDK does
//! (`SCS_TOHOST(a, b)`: `-(a & ~(1 << b))` if bit `b` is set) and as its
//! STS library reads Present Load (bit 10). Which bit, per item:
//! [`VELOCITY_SIGN_BIT`], [`POSITION_SIGN_BIT`], [`HOMING_OFFSET_SIGN_BIT`],
//! [`LOAD_SIGN_BIT`].

/// The sign bit of Goal Velocity (46) and Present Velocity (58), and of
/// Present Current (69): bit 15.
pub const VELOCITY_SIGN_BIT: u8 = 15;
/// The sign bit of Goal Position (42) and Present Position (56) in the
/// modes that turn past one revolution: bit 15.
pub const POSITION_SIGN_BIT: u8 = 15;
/// The sign bit of Homing Offset (31): bit 11 (its magnitude is 0–2047).
pub const HOMING_OFFSET_SIGN_BIT: u8 = 11;
/// The sign bit of Present Load (60): bit 10 (its magnitude is 0–1000,
/// in 0.1 % of the maximum torque).
pub const LOAD_SIGN_BIT: u8 = 10;

/// The order of a two-byte value's bytes on the wire and in the memory
/// table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ByteOrder {
    /// Low byte first, at the lower address: the STS and SMS series
    /// (the STS3215; Feetech's SDK `PacketHandler(0)`).
    Little,
    /// High byte first: the SCS series (`PacketHandler(1)`).
    Big,
}

impl ByteOrder {
    /// The two bytes of `v`, in this order.
    pub const fn u16_bytes(self, v: u16) -> [u8; 2] {
        match self {
            ByteOrder::Little => v.to_le_bytes(),
            ByteOrder::Big => v.to_be_bytes(),
        }
    }

    /// The value of two bytes in this order.
    pub const fn u16_of(self, b: [u8; 2]) -> u16 {
        match self {
            ByteOrder::Little => u16::from_le_bytes(b),
            ByteOrder::Big => u16::from_be_bytes(b),
        }
    }

    /// The value at `bytes[i..i + 2]`, if it is there.
    pub fn u16_at(self, bytes: &[u8], i: usize) -> Option<u16> {
        Some(self.u16_of(*bytes.get(i..)?.first_chunk()?))
    }
}

/// The signed value of a sign-magnitude `raw` with its sign at `sign_bit`
/// (0–15); bits above the sign bit are ignored, as the servo ignores them.
pub const fn from_sign_magnitude(raw: u16, sign_bit: u8) -> i32 {
    let bit = 1u32 << (sign_bit as u32 & 15);
    let magnitude = raw as u32 & (bit - 1);
    if raw as u32 & bit != 0 {
        -(magnitude as i32)
    } else {
        magnitude as i32
    }
}

/// The sign-magnitude encoding of `v` with its sign at `sign_bit`, or
/// `None` if `|v|` does not fit in the bits below it. Zero is never
/// written negative.
pub const fn to_sign_magnitude(v: i32, sign_bit: u8) -> Option<u16> {
    let bit = 1u32 << (sign_bit as u32 & 15);
    let magnitude = v.unsigned_abs();
    if magnitude >= bit {
        return None;
    }
    Some(if v < 0 { (magnitude | bit) as u16 } else { magnitude as u16 })
}

/// [`to_sign_magnitude`], saturating at the largest magnitude.
pub const fn to_sign_magnitude_saturating(v: i32, sign_bit: u8) -> u16 {
    let max = (1i32 << (sign_bit as u32 & 15)) - 1;
    let clamped = if v > max {
        max
    } else if v < -max {
        -max
    } else {
        v
    };
    match to_sign_magnitude(clamped, sign_bit) {
        Some(raw) => raw,
        None => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_orders() {
        assert_eq!(ByteOrder::Little.u16_bytes(0x0310), [0x10, 0x03]);
        assert_eq!(ByteOrder::Big.u16_bytes(0x0310), [0x03, 0x10]);
        for order in [ByteOrder::Little, ByteOrder::Big] {
            for v in [0u16, 1, 777, 4095, 0x8000, u16::MAX] {
                assert_eq!(order.u16_of(order.u16_bytes(v)), v);
            }
        }
        assert_eq!(ByteOrder::Little.u16_at(&[9, 0x09, 0x03], 1), Some(777));
        assert_eq!(ByteOrder::Big.u16_at(&[0x03, 0x09], 0), Some(777));
        assert_eq!(ByteOrder::Big.u16_at(&[0x03], 0), None);
    }

    #[test]
    fn sign_magnitude_as_feetech_writes_it() {
        // Homing Offset, bit 11: -2047 is 0x0FFF, 2047 is 0x07FF.
        assert_eq!(to_sign_magnitude(-2047, HOMING_OFFSET_SIGN_BIT), Some(0x0FFF));
        assert_eq!(to_sign_magnitude(2047, HOMING_OFFSET_SIGN_BIT), Some(0x07FF));
        assert_eq!(to_sign_magnitude(2048, HOMING_OFFSET_SIGN_BIT), None);
        assert_eq!(from_sign_magnitude(0x0FFF, HOMING_OFFSET_SIGN_BIT), -2047);
        // Velocity, bit 15: -100 steps/s is 0x8064.
        assert_eq!(to_sign_magnitude(-100, VELOCITY_SIGN_BIT), Some(0x8064));
        assert_eq!(from_sign_magnitude(0x8064, VELOCITY_SIGN_BIT), -100);
        // Load, bit 10: 0x0464 is -100 (10 % against the direction).
        assert_eq!(from_sign_magnitude(0x0464, LOAD_SIGN_BIT), -100);
        assert_eq!(to_sign_magnitude(0, VELOCITY_SIGN_BIT), Some(0));
        assert_eq!(from_sign_magnitude(0x8000, VELOCITY_SIGN_BIT), 0);
        assert_eq!(to_sign_magnitude_saturating(-5000, HOMING_OFFSET_SIGN_BIT), 0x0FFF);
        assert_eq!(to_sign_magnitude_saturating(i32::MIN, VELOCITY_SIGN_BIT), 0xFFFF);
        for bit in [10u8, 11, 15] {
            let max = (1i32 << bit) - 1;
            for v in [-max, -1, 0, 1, max] {
                assert_eq!(from_sign_magnitude(to_sign_magnitude(v, bit).unwrap(), bit), v);
            }
        }
    }
}
