//! The ERROR byte of a Feetech status packet, and the Status item (65) of
//! the memory table: one bit per condition. The byte is Protocol 1.0's
//! ([`ErrorFlags`], which [`super::StatusPacket::error`] carries); these
//! are its bits' Feetech meanings.
//!
//! Bits 0, 1, 2 and 5 mean what they mean in Dynamixel Protocol 1.0
//! (voltage, angle, overheating, overload); bit 3 is over-current, where
//! Dynamixel has its Range Error (Feetech's SDK: `ERRBIT_OVERELE`).
//! docs/reference/feetech.md § "Status".

use crate::dynamixel::ErrorFlags;

/// The conditions a Feetech servo reports, in Protocol 1.0's byte.
pub type ServoStatus = ErrorFlags;

/// Bit 0: the input voltage is outside Min/Max Input Voltage (15, 14).
pub const VOLTAGE: ServoStatus = ErrorFlags(0x01);
/// Bit 1: the angle (the magnetic encoder, or a goal past the limits).
pub const ANGLE: ServoStatus = ErrorFlags(0x02);
/// Bit 2: the temperature is above Max Temperature Limit (13).
pub const OVERHEAT: ServoStatus = ErrorFlags(0x04);
/// Bit 3: the current is above Protection Current (28).
pub const OVERCURRENT: ServoStatus = ErrorFlags(0x08);
/// Bit 5: the load stayed above Overload Torque (36) for Protection Time
/// (35).
pub const OVERLOAD: ServoStatus = ErrorFlags(0x20);
/// The conditions the factory Unloading Condition (19) names: voltage,
/// overheat, overcurrent and overload.
pub const HARDWARE: ServoStatus = ErrorFlags(0x01 | 0x04 | 0x08 | 0x20);

/// The Feetech names of the set bits, lowest first (undefined bits are
/// `"unknown"`).
pub fn names(status: ServoStatus) -> impl Iterator<Item = &'static str> {
    const NAMES: [&str; 8] = ["voltage", "angle", "overheat", "overcurrent", "unknown", "overload", "unknown", "unknown"];
    (0..8).filter(move |b| status.bits() & (1 << b) != 0).map(|b| NAMES[b])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sdks_bits() {
        let s = ErrorFlags(0x29);
        let got: heapless::Vec<&str, 8> = names(s).collect();
        assert_eq!(&got[..], &["voltage", "overcurrent", "overload"]);
        assert!(s.intersects(HARDWARE));
        assert!(!ANGLE.intersects(HARDWARE));
        assert_eq!(VOLTAGE.union(OVERLOAD).bits(), 0x21);
    }
}
