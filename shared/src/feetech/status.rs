//! The ERROR byte of a Feetech status packet, and the Status item (65) of
//! the memory table: one bit per condition. The byte is the one
//! [`super::StatusPacket::error`] carries; this is its Feetech reading.
//!
//! Bits 0, 1, 2 and 5 mean what they mean in Dynamixel Protocol 1.0
//! (voltage, angle, overheating, overload); bit 3 is over-current, where
//! Dynamixel has its Range Error (Feetech's SDK: `ERRBIT_OVERELE`).
//! docs/reference/feetech.md § "Status".

/// The conditions a Feetech servo reports.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ServoStatus(pub u8);

impl ServoStatus {
    /// No condition.
    pub const NONE: ServoStatus = ServoStatus(0);
    /// Bit 0: the input voltage is outside Min/Max Input Voltage (14, 15).
    pub const VOLTAGE: ServoStatus = ServoStatus(0x01);
    /// Bit 1: the angle (the magnetic encoder's reading, or a goal past
    /// the angle limits).
    pub const ANGLE: ServoStatus = ServoStatus(0x02);
    /// Bit 2: the temperature is above Max Temperature Limit (13).
    pub const OVERHEAT: ServoStatus = ServoStatus(0x04);
    /// Bit 3: the current is above Protection Current (28).
    pub const OVERCURRENT: ServoStatus = ServoStatus(0x08);
    /// Bit 5: the load stayed above Overload Torque (36) for Protection
    /// Time (35).
    pub const OVERLOAD: ServoStatus = ServoStatus(0x20);
    /// The conditions after which the servo drops its torque when its
    /// Unloading Condition (19) names them (factory: voltage, overheat,
    /// overcurrent and overload).
    pub const HARDWARE: ServoStatus = ServoStatus(0x01 | 0x04 | 0x08 | 0x20);

    /// The raw byte.
    pub const fn bits(self) -> u8 {
        self.0
    }
    /// Whether no bit is set.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }
    /// Whether any bit of `other` is set in `self`.
    pub const fn intersects(self, other: ServoStatus) -> bool {
        self.0 & other.0 != 0
    }
    /// Bits set in either.
    pub const fn union(self, other: ServoStatus) -> ServoStatus {
        ServoStatus(self.0 | other.0)
    }

    /// The names of the set bits, lowest first (undefined bits are
    /// `"unknown"`).
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        const NAMES: [&str; 8] = ["voltage", "angle", "overheat", "overcurrent", "unknown", "overload", "unknown", "unknown"];
        (0..8).filter(move |b| self.0 & (1 << b) != 0).map(|b| NAMES[b])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sdks_bits() {
        let s = ServoStatus(0x29);
        let names: heapless::Vec<&str, 8> = s.names().collect();
        assert_eq!(&names[..], &["voltage", "overcurrent", "overload"]);
        assert!(s.intersects(ServoStatus::HARDWARE));
        assert!(!ServoStatus::ANGLE.intersects(ServoStatus::HARDWARE));
        assert_eq!(ServoStatus::VOLTAGE.union(ServoStatus::OVERLOAD).bits(), 0x21);
    }
}
