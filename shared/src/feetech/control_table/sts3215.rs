//! The STS3215's memory table (the SO-100/SO-101 arm's servo), with the
//! value ranges and units of Feetech's STS memory-table document where it
//! gives them; docs/reference/feetech.md § "Memory map" cites each source
//! and says where they disagree.
//!
//! Two-byte items are little endian (the STS series). Signed items are
//! sign-magnitude ([`crate::feetech::value`]): their ranges here are of
//! the raw bits. EEPROM (addresses 0–39) is written whatever Torque Enable
//! and Lock say: Lock (55) decides only whether a write survives a power
//! cycle, which no emulator needs, so no item locks it
//! ([`NO_EEPROM_LOCK`]).

use crate::dynamixel::control_table::{ControlTable, Item};
use crate::dynamixel::Protocol;

/// Firmware Major Version (1, R).
pub const FIRMWARE_MAJOR: u8 = 0;
/// Firmware Minor Version (1, R).
pub const FIRMWARE_MINOR: u8 = 1;
/// END (1, R): the byte order, 0 for little endian.
pub const END: u8 = 2;
/// Model Number (2, R): 777 on the STS3215 (Feetech's document names its
/// two bytes the servo's major and minor version).
pub const MODEL_NUMBER: u8 = 3;
/// ID (1, RW, EEPROM): 0–253.
pub const ID: u8 = 5;
/// Baud Rate (1, RW, EEPROM): 0–7, [`BAUD_RATES`].
pub const BAUD_RATE: u8 = 6;
/// Return Delay Time (1, RW, EEPROM): 2 µs per unit.
pub const RETURN_DELAY_TIME: u8 = 7;
/// Response Status Level (1, RW, EEPROM): 0 answers only READ and PING,
/// 1 answers every instruction.
pub const RESPONSE_STATUS_LEVEL: u8 = 8;
/// Min Position Limit (2, RW, EEPROM): 0–4094 steps.
pub const MIN_POSITION_LIMIT: u8 = 9;
/// Max Position Limit (2, RW, EEPROM): 1–4095 steps.
pub const MAX_POSITION_LIMIT: u8 = 11;
/// Max Temperature Limit (1, RW, EEPROM): °C.
pub const MAX_TEMPERATURE_LIMIT: u8 = 13;
/// Max Input Voltage (1, RW, EEPROM): 0.1 V.
pub const MAX_INPUT_VOLTAGE: u8 = 14;
/// Min Input Voltage (1, RW, EEPROM): 0.1 V.
pub const MIN_INPUT_VOLTAGE: u8 = 15;
/// Max Torque Limit (2, RW, EEPROM): 0–1000, 0.1 % of the stall torque.
pub const MAX_TORQUE_LIMIT: u8 = 16;
/// Phase (1, RW, EEPROM): direction and feedback options, bit per option.
pub const PHASE: u8 = 18;
/// Unloading Condition (1, RW, EEPROM): the status bits that drop torque.
pub const UNLOADING_CONDITION: u8 = 19;
/// LED Alarm Condition (1, RW, EEPROM): the status bits that light the LED.
pub const LED_ALARM_CONDITION: u8 = 20;
/// P Coefficient (1, RW, EEPROM): the position loop's proportional gain.
pub const P_COEFFICIENT: u8 = 21;
/// D Coefficient (1, RW, EEPROM): its derivative gain.
pub const D_COEFFICIENT: u8 = 22;
/// I Coefficient (1, RW, EEPROM): its integral gain.
pub const I_COEFFICIENT: u8 = 23;
/// Minimum Startup Force (2, RW, EEPROM): 0.1 % of the stall torque.
pub const MINIMUM_STARTUP_FORCE: u8 = 24;
/// CW Dead Zone (1, RW, EEPROM): steps.
pub const CW_DEAD_ZONE: u8 = 26;
/// CCW Dead Zone (1, RW, EEPROM): steps.
pub const CCW_DEAD_ZONE: u8 = 27;
/// Protection Current (2, RW, EEPROM): 6.5 mA per unit.
pub const PROTECTION_CURRENT: u8 = 28;
/// Angular Resolution (1, RW, EEPROM).
pub const ANGULAR_RESOLUTION: u8 = 30;
/// Homing Offset (2, RW, EEPROM): steps, sign bit 11.
pub const HOMING_OFFSET: u8 = 31;
/// Operating Mode (1, RW, EEPROM): [`MODE_POSITION`] … [`MODE_STEP`].
pub const OPERATING_MODE: u8 = 33;
/// Protective Torque (1, RW, EEPROM): % of the stall torque after an
/// overload.
pub const PROTECTIVE_TORQUE: u8 = 34;
/// Protection Time (1, RW, EEPROM): 10 ms per unit of overload before the
/// overload condition.
pub const PROTECTION_TIME: u8 = 35;
/// Overload Torque (1, RW, EEPROM): % of the stall torque that counts as
/// overload.
pub const OVERLOAD_TORQUE: u8 = 36;
/// Velocity P Coefficient (1, RW, EEPROM): the speed loop's (mode 1).
pub const VELOCITY_P_COEFFICIENT: u8 = 37;
/// Over Current Protection Time (1, RW, EEPROM): 10 ms per unit.
pub const OVER_CURRENT_PROTECTION_TIME: u8 = 38;
/// Velocity I Coefficient (1, RW, EEPROM).
pub const VELOCITY_I_COEFFICIENT: u8 = 39;
/// Torque Enable (1, RW, RAM): 0 off, 1 on, 128 makes the present
/// position the middle (2048).
pub const TORQUE_ENABLE: u8 = 40;
/// Acceleration (1, RW, RAM): 100 steps/s² per unit (0: the largest).
pub const ACCELERATION: u8 = 41;
/// Goal Position (2, RW, RAM): steps, sign bit 15.
pub const GOAL_POSITION: u8 = 42;
/// Goal Time (2, RW, RAM): ms.
pub const GOAL_TIME: u8 = 44;
/// Goal Velocity (2, RW, RAM): steps/s, sign bit 15 (mode 1: the
/// velocity; mode 0: the speed limit of the move, 0 for the largest).
pub const GOAL_VELOCITY: u8 = 46;
/// Torque Limit (2, RW, RAM): 0–1000, 0.1 % of the stall torque.
pub const TORQUE_LIMIT: u8 = 48;
/// Lock (1, RW, RAM): 1 keeps EEPROM writes from being saved.
pub const LOCK: u8 = 55;
/// Present Position (2, R): steps, 4096 per turn.
pub const PRESENT_POSITION: u8 = 56;
/// Present Velocity (2, R): steps/s, sign bit 15.
pub const PRESENT_VELOCITY: u8 = 58;
/// Present Load (2, R): 0.1 % of the stall torque, sign bit 10.
pub const PRESENT_LOAD: u8 = 60;
/// Present Voltage (1, R): 0.1 V.
pub const PRESENT_VOLTAGE: u8 = 62;
/// Present Temperature (1, R): °C.
pub const PRESENT_TEMPERATURE: u8 = 63;
/// Async Write Flag (1, R): a REG WRITE is held.
pub const ASYNC_WRITE_FLAG: u8 = 64;
/// Status (1, R): [`crate::feetech::ServoStatus`] bits.
pub const STATUS: u8 = 65;
/// Moving (1, R): 1 while the servo moves.
pub const MOVING: u8 = 66;
/// Present Current (2, R): 6.5 mA per unit, sign bit 15.
pub const PRESENT_CURRENT: u8 = 69;
/// One past the last address pada emulates (the factory block ends at 86).
pub const TABLE_LEN: usize = 87;

/// Present Position through Present Temperature: the block one SYNC READ
/// returns per control period (position, velocity, load, voltage,
/// temperature).
pub const PRESENT_BLOCK: u8 = PRESENT_POSITION;
/// Length of [`PRESENT_BLOCK`].
pub const PRESENT_BLOCK_LEN: u8 = 8;

/// Operating Mode 0: position, through the servo's own position loop.
pub const MODE_POSITION: u8 = 0;
/// Operating Mode 1: constant velocity (Goal Velocity).
pub const MODE_VELOCITY: u8 = 1;
/// Operating Mode 2: open-loop PWM (Goal Time holds the duty, sign bit 10).
pub const MODE_PWM: u8 = 2;
/// Operating Mode 3: step (Goal Position relative to the present one).
pub const MODE_STEP: u8 = 3;

/// The STS3215's model number.
pub const STS3215_MODEL: u16 = 777;
/// Steps per turn of Present Position.
pub const STEPS_PER_TURN: u16 = 4096;
/// No item locks EEPROM (see the module's docs): the table's
/// `torque_enable` names an address past the table.
pub const NO_EEPROM_LOCK: u16 = TABLE_LEN as u16;

/// Baud Rate values 0–7 (Feetech's STS memory table).
pub static BAUD_RATES: [u32; 8] = [1_000_000, 500_000, 250_000, 128_000, 115_200, 76_800, 57_600, 38_400];

const fn a(address: u8) -> u16 {
    address as u16
}

/// The STS3215 (model 777).
pub static STS3215: ControlTable = ControlTable {
    model: "STS3215",
    model_number: STS3215_MODEL,
    protocol: Protocol::Feetech,
    items: &[
        Item::eeprom("Firmware Major Version", a(FIRMWARE_MAJOR), 1).read_only(),
        Item::eeprom("Firmware Minor Version", a(FIRMWARE_MINOR), 1).read_only(),
        Item::eeprom("END", a(END), 1).read_only(),
        Item::eeprom("Model Number", a(MODEL_NUMBER), 2).read_only(),
        Item::eeprom("ID", a(ID), 1).range(0, 253),
        Item::eeprom("Baud Rate", a(BAUD_RATE), 1).range(0, 7),
        Item::eeprom("Return Delay Time", a(RETURN_DELAY_TIME), 1).range(0, 254).unit(2.0, "µs"),
        Item::eeprom("Response Status Level", a(RESPONSE_STATUS_LEVEL), 1).range(0, 1),
        Item::eeprom("Min Position Limit", a(MIN_POSITION_LIMIT), 2).range(0, 4094).unit(0.087, "°"),
        Item::eeprom("Max Position Limit", a(MAX_POSITION_LIMIT), 2).range(1, 4095).unit(0.087, "°"),
        Item::eeprom("Max Temperature Limit", a(MAX_TEMPERATURE_LIMIT), 1).range(0, 100).unit(1.0, "°C"),
        Item::eeprom("Max Input Voltage", a(MAX_INPUT_VOLTAGE), 1).range(0, 254).unit(0.1, "V"),
        Item::eeprom("Min Input Voltage", a(MIN_INPUT_VOLTAGE), 1).range(0, 254).unit(0.1, "V"),
        Item::eeprom("Max Torque Limit", a(MAX_TORQUE_LIMIT), 2).range(0, 1000).unit(0.1, "%"),
        Item::eeprom("Phase", a(PHASE), 1),
        Item::eeprom("Unloading Condition", a(UNLOADING_CONDITION), 1),
        Item::eeprom("LED Alarm Condition", a(LED_ALARM_CONDITION), 1),
        Item::eeprom("P Coefficient", a(P_COEFFICIENT), 1).range(0, 254),
        Item::eeprom("D Coefficient", a(D_COEFFICIENT), 1).range(0, 254),
        Item::eeprom("I Coefficient", a(I_COEFFICIENT), 1).range(0, 254),
        Item::eeprom("Minimum Startup Force", a(MINIMUM_STARTUP_FORCE), 2).range(0, 1000).unit(0.1, "%"),
        Item::eeprom("CW Dead Zone", a(CW_DEAD_ZONE), 1).range(0, 32),
        Item::eeprom("CCW Dead Zone", a(CCW_DEAD_ZONE), 1).range(0, 32),
        Item::eeprom("Protection Current", a(PROTECTION_CURRENT), 2).range(0, 511).unit(6.5, "mA"),
        Item::eeprom("Angular Resolution", a(ANGULAR_RESOLUTION), 1).range(1, 3),
        Item::eeprom("Homing Offset", a(HOMING_OFFSET), 2).range(0, 4095),
        Item::eeprom("Operating Mode", a(OPERATING_MODE), 1).range(0, 3),
        Item::eeprom("Protective Torque", a(PROTECTIVE_TORQUE), 1).range(0, 100).unit(1.0, "%"),
        Item::eeprom("Protection Time", a(PROTECTION_TIME), 1).range(0, 254).unit(10.0, "ms"),
        Item::eeprom("Overload Torque", a(OVERLOAD_TORQUE), 1).range(0, 100).unit(1.0, "%"),
        Item::eeprom("Velocity P Coefficient", a(VELOCITY_P_COEFFICIENT), 1),
        Item::eeprom("Over Current Protection Time", a(OVER_CURRENT_PROTECTION_TIME), 1).range(0, 254).unit(10.0, "ms"),
        Item::eeprom("Velocity I Coefficient", a(VELOCITY_I_COEFFICIENT), 1),
        Item::ram("Torque Enable", a(TORQUE_ENABLE), 1).one_of(&[0, 1, 128]),
        Item::ram("Acceleration", a(ACCELERATION), 1).range(0, 254).unit(100.0, "step/s²"),
        Item::ram("Goal Position", a(GOAL_POSITION), 2),
        Item::ram("Goal Time", a(GOAL_TIME), 2),
        Item::ram("Goal Velocity", a(GOAL_VELOCITY), 2),
        Item::ram("Torque Limit", a(TORQUE_LIMIT), 2).range(0, 1000).unit(0.1, "%"),
        Item::ram("Lock", a(LOCK), 1).range(0, 1),
        Item::ro("Present Position", a(PRESENT_POSITION), 2),
        Item::ro("Present Velocity", a(PRESENT_VELOCITY), 2),
        Item::ro("Present Load", a(PRESENT_LOAD), 2).unit(0.1, "%"),
        Item::ro("Present Voltage", a(PRESENT_VOLTAGE), 1).unit(0.1, "V"),
        Item::ro("Present Temperature", a(PRESENT_TEMPERATURE), 1).unit(1.0, "°C"),
        Item::ro("Async Write Flag", a(ASYNC_WRITE_FLAG), 1),
        Item::ro("Status", a(STATUS), 1),
        Item::ro("Moving", a(MOVING), 1),
        Item::ro("Present Current", a(PRESENT_CURRENT), 2).unit(6.5, "mA"),
    ],
    baud_rates: &BAUD_RATES,
    end: TABLE_LEN as u16,
    torque_enable: NO_EEPROM_LOCK,
    operating_mode: OPERATING_MODE as u16,
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_addresses_the_issue_and_lerobot_name() {
        assert_eq!((MODEL_NUMBER, OPERATING_MODE, TORQUE_ENABLE, GOAL_POSITION), (3, 33, 40, 42));
        assert_eq!((PRESENT_POSITION, PRESENT_TEMPERATURE), (56, 63));
        assert_eq!((P_COEFFICIENT, D_COEFFICIENT, I_COEFFICIENT), (21, 22, 23));
        assert_eq!(PRESENT_TEMPERATURE - PRESENT_POSITION + 1, PRESENT_BLOCK_LEN);
        assert_eq!(STS3215.item_named("Homing Offset").map(|i| (i.address, i.size)), Some((31, 2)));
        assert_eq!(STS3215.baud_rate_bps(0), Some(1_000_000));
        assert_eq!(STS3215.baud_rate_bps(8), None);
        // Items in address order, none overlapping, all inside the table.
        for w in STS3215.items.windows(2) {
            assert!(w[0].end() <= w[1].address, "{} overlaps {}", w[0].name, w[1].name);
        }
        assert!(STS3215.items.iter().all(|i| i.end() <= STS3215.end && !i.signed));
    }

    #[test]
    fn writes_are_checked_on_raw_values() {
        let mut memory = [0u8; TABLE_LEN];
        memory[TORQUE_ENABLE as usize] = 1;
        // EEPROM with torque on: accepted (no item locks it).
        assert_eq!(STS3215.check_write(a(P_COEFFICIENT), &[16], &memory), Ok(()));
        assert!(STS3215.check_write(a(ID), &[254], &memory).is_err());
        assert!(STS3215.check_write(a(GOAL_POSITION), &[0x00], &memory).is_err(), "half an item");
        assert!(STS3215.check_write(a(PRESENT_POSITION), &[0, 0], &memory).is_err(), "read only");
        assert_eq!(STS3215.check_write(a(GOAL_POSITION), &[0x00, 0x08], &memory), Ok(()));
        assert!(STS3215.check_write(a(TORQUE_ENABLE), &[2], &memory).is_err());
        assert_eq!(STS3215.check_write(a(TORQUE_ENABLE), &[128], &memory), Ok(()));
        assert!(STS3215.check_read(a(PRESENT_POSITION), 8).is_ok());
        assert!(STS3215.check_read(80, 8).is_err());
    }
}
