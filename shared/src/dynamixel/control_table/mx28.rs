//! The MX-28 on Protocol 2.0 firmware, "MX-28(2.0)" (e-Manual,
//! <https://emanual.robotis.com/docs/en/dxl/mx/mx-28-2/>): the successor of
//! the RX-28 with the same 193:1 gear train, listed for completeness of
//! the model list. Its control table has the X series' layout for every
//! item pada uses, so the addresses are [`super::x_series`]'s; it has no
//! current sensor (Present Load at 126, no Current Limit or Goal Current)
//! and no current-based modes.

use super::x_series::{
    BAUD_RATES_X430, FIRMWARE, GOAL_POSITION_ITEM, GOAL_PWM_ITEM, HOMING, HW_ERROR, ID_ITEM, INDIRECT_56, LED_ITEM, MAX_POSITION,
    MIN_POSITION, MODEL, OPERATING_MODES_NO_CURRENT, PRESENT_LOAD_ITEM, PRESENT_POSITION_ITEM, PRESENT_PWM_ITEM,
    PRESENT_TEMPERATURE_ITEM, PRESENT_VELOCITY_ITEM, PRESENT_VOLTAGE_ITEM, PWM_LIMIT_ITEM, REGISTERED, RETURN_DELAY, RETURN_LEVEL,
    SHUTDOWN_ITEM, TEMP_LIMIT, TORQUE, WATCHDOG,
};
use super::x_series::{
    BAUD_RATE, DRIVE_MODE, GOAL_VELOCITY, MAX_VOLTAGE_LIMIT, MIN_VOLTAGE_LIMIT, OPERATING_MODE, TORQUE_ENABLE, VELOCITY_LIMIT,
};
use super::{ControlTable, Item, Limit};
use crate::dynamixel::Protocol;

/// MX-28 with Protocol 2.0 firmware (model 30): 10–14.8 V.
pub static MX28_V2: ControlTable = ControlTable {
    model: "MX-28(2.0)",
    model_number: 30,
    protocol: Protocol::V2,
    items: &[
        MODEL,
        FIRMWARE,
        ID_ITEM,
        Item::eeprom("Baud Rate", BAUD_RATE, 1).range(0, 7),
        RETURN_DELAY,
        // Bit 0 reverse, bit 2 time-based profile; no bit 3 on the MX(2.0).
        Item::eeprom("Drive Mode", DRIVE_MODE, 1).mask(0x05),
        Item::eeprom("Operating Mode", OPERATING_MODE, 1).one_of(OPERATING_MODES_NO_CURRENT),
        HOMING,
        TEMP_LIMIT,
        Item::eeprom("Max Voltage Limit", MAX_VOLTAGE_LIMIT, 2).range(95, 160).unit(0.1, "V"),
        Item::eeprom("Min Voltage Limit", MIN_VOLTAGE_LIMIT, 2).range(95, 160).unit(0.1, "V"),
        PWM_LIMIT_ITEM,
        Item::eeprom("Velocity Limit", VELOCITY_LIMIT, 4).range(0, 1023).unit(0.229, "rev/min"),
        MAX_POSITION,
        MIN_POSITION,
        SHUTDOWN_ITEM,
        TORQUE,
        LED_ITEM,
        RETURN_LEVEL,
        REGISTERED,
        HW_ERROR,
        WATCHDOG,
        GOAL_PWM_ITEM,
        Item::ram("Goal Velocity", GOAL_VELOCITY, 4)
            .signed()
            .range(-1023, 1023)
            .limit(Limit::Magnitude(VELOCITY_LIMIT))
            .unit(0.229, "rev/min"),
        GOAL_POSITION_ITEM,
        PRESENT_PWM_ITEM,
        PRESENT_LOAD_ITEM,
        PRESENT_VELOCITY_ITEM,
        PRESENT_POSITION_ITEM,
        PRESENT_VOLTAGE_ITEM,
        PRESENT_TEMPERATURE_ITEM,
        INDIRECT_56[0],
        INDIRECT_56[1],
        INDIRECT_56[2],
        INDIRECT_56[3],
    ],
    baud_rates: &BAUD_RATES_X430,
    end: 662,
    torque_enable: TORQUE_ENABLE,
    operating_mode: OPERATING_MODE,
};
