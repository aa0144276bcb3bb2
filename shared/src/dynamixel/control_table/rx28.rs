//! The RX-28's control table (Protocol 1.0; e-Manual,
//! <https://emanual.robotis.com/docs/en/dxl/rx/rx-28/>, "Control Table of
//! EEPROM Area" and "Control Table of RAM Area", with the value ranges of
//! the descriptions it includes), as the same data as the Protocol 2.0
//! tables: what a virtual RX-28 accepts. The addresses are
//! [`crate::dynamixel::table`]'s.
//!
//! Protocol 1.0 has one error bit for every refused write, Range Error
//! (bit 3: "When an instruction is out of the range for use"); a servo
//! answers a write of a value outside an item's range, of a read-only or
//! undefined address, or of part of a two-byte item with it and writes
//! nothing. EEPROM (addresses 0–23) is locked while Lock (47) is 1, not by
//! Torque Enable as on the X series, so this table names Lock as the item
//! that locks it.

use super::{ControlTable, Item};
use crate::dynamixel::table as t;
use crate::dynamixel::Protocol;

/// Baud Rate values 0–254: 2 000 000 / (value + 1) bps.
pub static BAUD_RATES: [u32; 255] = {
    let mut a = [0u32; 255];
    let mut i = 0;
    while i < 255 {
        a[i] = t::baud_rate_bps(i as u8);
        i += 1;
    }
    a
};

/// The RX-28 (model 28).
pub static RX28: ControlTable = ControlTable {
    model: "RX-28",
    model_number: t::RX28_MODEL,
    protocol: Protocol::V1,
    items: &[
        Item::eeprom("Model Number", t::MODEL_NUMBER as u16, 2).read_only(),
        Item::eeprom("Firmware Version", t::FIRMWARE_VERSION as u16, 1).read_only(),
        Item::eeprom("ID", t::ID as u16, 1).range(0, 253),
        Item::eeprom("Baud Rate", t::BAUD_RATE as u16, 1).range(0, 254),
        Item::eeprom("Return Delay Time", t::RETURN_DELAY_TIME as u16, 1).range(0, 254).unit(2.0, "µs"),
        Item::eeprom("CW Angle Limit", t::CW_ANGLE_LIMIT as u16, 2).range(0, 1023),
        Item::eeprom("CCW Angle Limit", t::CCW_ANGLE_LIMIT as u16, 2).range(0, 1023),
        Item::eeprom("Temperature Limit", t::HIGHEST_LIMIT_TEMPERATURE as u16, 1).range(0, 100).unit(1.0, "°C"),
        Item::eeprom("Min Voltage Limit", t::LOWEST_LIMIT_VOLTAGE as u16, 1).range(50, 250).unit(0.1, "V"),
        Item::eeprom("Max Voltage Limit", t::HIGHEST_LIMIT_VOLTAGE as u16, 1).range(50, 250).unit(0.1, "V"),
        Item::eeprom("Max Torque", t::MAX_TORQUE as u16, 2).range(0, 1023),
        Item::eeprom("Status Return Level", t::STATUS_RETURN_LEVEL as u16, 1).range(0, 2),
        Item::eeprom("Alarm LED", t::ALARM_LED as u16, 1).mask(0x7F),
        Item::eeprom("Shutdown", t::ALARM_SHUTDOWN as u16, 1).mask(0x7F),
        Item::ram("Torque Enable", t::TORQUE_ENABLE as u16, 1).range(0, 1),
        Item::ram("LED", t::LED as u16, 1).range(0, 1),
        Item::ram("CW Compliance Margin", t::CW_COMPLIANCE_MARGIN as u16, 1),
        Item::ram("CCW Compliance Margin", t::CCW_COMPLIANCE_MARGIN as u16, 1),
        Item::ram("CW Compliance Slope", t::CW_COMPLIANCE_SLOPE as u16, 1),
        Item::ram("CCW Compliance Slope", t::CCW_COMPLIANCE_SLOPE as u16, 1),
        Item::ram("Goal Position", t::GOAL_POSITION as u16, 2).range(0, 1023),
        Item::ram("Moving Speed", t::MOVING_SPEED as u16, 2).range(0, 2047),
        Item::ram("Torque Limit", t::TORQUE_LIMIT as u16, 2).range(0, 1023),
        Item::ro("Present Position", t::PRESENT_POSITION as u16, 2),
        Item::ro("Present Speed", t::PRESENT_SPEED as u16, 2),
        Item::ro("Present Load", t::PRESENT_LOAD as u16, 2),
        Item::ro("Present Voltage", t::PRESENT_VOLTAGE as u16, 1).unit(0.1, "V"),
        Item::ro("Present Temperature", t::PRESENT_TEMPERATURE as u16, 1).unit(1.0, "°C"),
        Item::ro("Registered", t::REGISTERED as u16, 1),
        Item::ro("Moving", t::MOVING as u16, 1),
        Item::ram("Lock", t::LOCK as u16, 1).range(0, 1),
        Item::ram("Punch", t::PUNCH as u16, 2).range(0, 1023),
    ],
    baud_rates: &BAUD_RATES,
    end: t::TABLE_LEN as u16,
    // The item that locks EEPROM (see the module documentation).
    torque_enable: t::LOCK as u16,
    // No operating mode: no item's limit depends on one.
    operating_mode: u16::MAX,
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamixel::control_table::TableError;

    #[test]
    fn writes_the_rx28_refuses() {
        let mem = [0u8; t::TABLE_LEN];
        assert_eq!(RX28.check_write(t::MOVING_SPEED as u16, &2047u16.to_le_bytes(), &mem), Ok(()));
        assert!(matches!(RX28.check_write(t::MOVING_SPEED as u16, &2048u16.to_le_bytes(), &mem), Err(TableError::OutOfRange { .. })));
        assert!(matches!(RX28.check_write(t::ID as u16, &[254], &mem), Err(TableError::OutOfRange { value: 254, .. })));
        assert!(matches!(RX28.check_write(t::PRESENT_POSITION as u16, &[0, 0], &mem), Err(TableError::ReadOnly { .. })));
        assert!(matches!(RX28.check_write(10, &[0], &mem), Err(TableError::Undefined { address: 10 })));
        assert!(matches!(RX28.check_write(t::MOVING_SPEED as u16, &[1], &mem), Err(TableError::Partial { .. })));
        // Lock locks EEPROM, not Torque Enable.
        let mut locked = mem;
        locked[t::TORQUE_ENABLE as usize] = 1;
        assert_eq!(RX28.check_write(t::RETURN_DELAY_TIME as u16, &[25], &locked), Ok(()));
        locked[t::LOCK as usize] = 1;
        assert!(matches!(RX28.check_write(t::RETURN_DELAY_TIME as u16, &[25], &locked), Err(TableError::EepromLocked { .. })));
        assert_eq!(RX28.baud_rate_bps(1), Some(1_000_000));
        assert_eq!(RX28.baud_rate_bps(34), Some(57_142));
    }
}
