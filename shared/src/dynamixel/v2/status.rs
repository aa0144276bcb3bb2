//! The status packet's ERROR byte and the parameters of the replies
//! (e-Manual, "DYNAMIXEL Protocol 2.0", § "Status Packet" → "Error", and
//! § "Ping").
//!
//! ```text
//! ERROR: bit 7 = Alert, bits 6–0 = Error Number
//! ```
//!
//! The Error Number says what went wrong with *this* instruction (one
//! value, not bits, unlike Protocol 1.0's error byte). The Alert bit says
//! the servo itself has a hardware problem: a master then reads Hardware
//! Error Status (address 70 on the X series and MX(2.0),
//! [`crate::dynamixel::control_table::x_series::HARDWARE_ERROR_STATUS`]) to
//! learn which, and only a REBOOT clears it.

/// The Error Number of a status packet (bits 0–6 of ERROR).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum ErrorNumber {
    /// 0x01: the instruction packet could not be processed (e.g. CLEAR
    /// while the servo moves).
    ResultFail = 0x01,
    /// 0x02: an undefined instruction, or ACTION without REG WRITE.
    Instruction = 0x02,
    /// 0x03: the instruction packet's CRC does not match.
    Crc = 0x03,
    /// 0x04: the value to write is outside the item's minimum/maximum.
    DataRange = 0x04,
    /// 0x05: fewer bytes written than the item is long (e.g. 2 bytes of a
    /// 4-byte item).
    DataLength = 0x05,
    /// 0x06: the value to write is outside the limit another item sets
    /// (e.g. Goal PWM beyond PWM Limit).
    DataLimit = 0x06,
    /// 0x07: a write to a read-only or undefined address, a read of an
    /// undefined one, or a write to EEPROM while torque is on.
    Access = 0x07,
}

impl ErrorNumber {
    /// The error number for a value of bits 0–6, if the e-Manual defines
    /// it.
    pub const fn from_u8(n: u8) -> Option<Self> {
        Some(match n {
            0x01 => Self::ResultFail,
            0x02 => Self::Instruction,
            0x03 => Self::Crc,
            0x04 => Self::DataRange,
            0x05 => Self::DataLength,
            0x06 => Self::DataLimit,
            0x07 => Self::Access,
            _ => return None,
        })
    }

    /// The e-Manual's name of the error.
    pub const fn name(self) -> &'static str {
        match self {
            Self::ResultFail => "result fail",
            Self::Instruction => "instruction error",
            Self::Crc => "CRC error",
            Self::DataRange => "data range error",
            Self::DataLength => "data length error",
            Self::DataLimit => "data limit error",
            Self::Access => "access error",
        }
    }
}

/// The ERROR byte of a status packet, kept whole (numbers the e-Manual
/// does not define are kept, not dropped).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StatusError(pub u8);

impl StatusError {
    /// No error, no alert.
    pub const NONE: StatusError = StatusError(0);
    /// The Alert bit (bit 7).
    pub const ALERT_BIT: u8 = 0x80;

    /// The ERROR byte for an error number (or none) and the alert bit.
    pub const fn new(number: Option<ErrorNumber>, alert: bool) -> Self {
        let n = match number {
            Some(e) => e as u8,
            None => 0,
        };
        StatusError(n | if alert { Self::ALERT_BIT } else { 0 })
    }

    /// Whether the servo reports a hardware problem (read Hardware Error
    /// Status next).
    pub const fn alert(self) -> bool {
        self.0 & Self::ALERT_BIT != 0
    }

    /// The raw Error Number, bits 0–6 (0: the instruction succeeded).
    pub const fn number_raw(self) -> u8 {
        self.0 & !Self::ALERT_BIT
    }

    /// The Error Number, if it is one the e-Manual defines (`None` for 0,
    /// success, and for undefined numbers: see [`Self::number_raw`]).
    pub const fn number(self) -> Option<ErrorNumber> {
        ErrorNumber::from_u8(self.number_raw())
    }

    /// Whether the instruction succeeded (Error Number 0), whatever the
    /// alert bit.
    pub const fn succeeded(self) -> bool {
        self.number_raw() == 0
    }
}

/// The parameters of the status packet that answers PING: Model Number
/// (little endian) and Firmware Version (e-Manual § "Ping").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PingReply {
    /// Model Number (XM430-W350: 1020; see
    /// [`crate::dynamixel::control_table::by_model_number`]).
    pub model_number: u16,
    /// Firmware Version.
    pub firmware: u8,
}

impl PingReply {
    /// Parameter bytes of a PING's status packet.
    pub const PARAMS: usize = 3;

    /// Parses a PING reply's parameters (exactly three bytes).
    pub fn from_params(params: &[u8]) -> Option<Self> {
        match *params {
            [lo, hi, firmware] => Some(PingReply { model_number: u16::from_le_bytes([lo, hi]), firmware }),
            _ => None,
        }
    }

    /// The three parameter bytes (the servo's side).
    pub const fn to_params(self) -> [u8; 3] {
        let [lo, hi] = self.model_number.to_le_bytes();
        [lo, hi, self.firmware]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_byte_splits_into_alert_and_number() {
        let e = StatusError(0x84);
        assert!(e.alert());
        assert_eq!(e.number(), Some(ErrorNumber::DataRange));
        assert!(!e.succeeded());
        assert_eq!(StatusError::new(Some(ErrorNumber::Access), false), StatusError(0x07));
        assert_eq!(StatusError::new(None, true), StatusError(0x80));
        let alert_only = StatusError(0x80);
        assert!(alert_only.succeeded() && alert_only.alert() && alert_only.number().is_none());
        // Undefined numbers are kept, not mapped.
        assert_eq!(StatusError(0x29).number(), None);
        assert_eq!(StatusError(0x29).number_raw(), 0x29);
        for n in 1..=7u8 {
            let e = ErrorNumber::from_u8(n).unwrap();
            assert_eq!(e as u8, n);
            assert!(!e.name().is_empty());
        }
        assert_eq!(ErrorNumber::from_u8(0), None);
        assert_eq!(ErrorNumber::from_u8(8), None);
    }

    #[test]
    fn ping_reply_matches_the_manual() {
        // e-Manual § "Ping" Example 1: XM430-W210, model 1030 (0x0406),
        // firmware 38 (0x26): parameters 06 04 26.
        let r = PingReply::from_params(&[0x06, 0x04, 0x26]).unwrap();
        assert_eq!(r, PingReply { model_number: 1030, firmware: 38 });
        assert_eq!(r.to_params(), [0x06, 0x04, 0x26]);
        assert_eq!(PingReply::from_params(&[0x06, 0x04]), None);
    }
}
