//! The X series on Protocol 2.0: the addresses the firmware uses (shared by
//! every X-series model and by the MX series on 2.0 firmware, so code reads
//! `x_series::GOAL_PWM`), the Hardware Error Status bits, the Operating
//! Modes, and the control tables of the XM430-W350, XL430-W250 and
//! XL330-M288.
//!
//! Sources (e-Manual, read through its source repository; the pages'
//! addresses and the choices where the e-Manual contradicts itself are in
//! docs/reference/dynamixel.md §§ 5–7):
//! <https://emanual.robotis.com/docs/en/dxl/x/xm430-w350/>,
//! <https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/>,
//! <https://emanual.robotis.com/docs/en/dxl/x/xl330-m288/>.
//! EEPROM is addresses 0–63, RAM from 64.

use super::{ControlTable, Item, Limit};

/// Model Number (2, R, EEPROM).
pub const MODEL_NUMBER: u16 = 0;
/// Firmware Version (1, R, EEPROM).
pub const FIRMWARE_VERSION: u16 = 6;
/// ID (1, RW, EEPROM): 0–252.
pub const ID: u16 = 7;
/// Baud Rate (1, RW, EEPROM): see [`ControlTable::baud_rate_bps`].
pub const BAUD_RATE: u16 = 8;
/// Return Delay Time (1, RW, EEPROM): 2 µs units.
pub const RETURN_DELAY_TIME: u16 = 9;
/// Drive Mode (1, RW, EEPROM): bit 0 reverse, bit 2 time-based profile,
/// bit 3 torque on by goal update.
pub const DRIVE_MODE: u16 = 10;
/// Operating Mode (1, RW, EEPROM): see [`mode`].
pub const OPERATING_MODE: u16 = 11;
/// Homing Offset (4, RW, EEPROM, signed): pulses added to Present Position.
pub const HOMING_OFFSET: u16 = 20;
/// Temperature Limit (1, RW, EEPROM): °C.
pub const TEMPERATURE_LIMIT: u16 = 31;
/// Max Voltage Limit (2, RW, EEPROM): 0.1 V.
pub const MAX_VOLTAGE_LIMIT: u16 = 32;
/// Min Voltage Limit (2, RW, EEPROM): 0.1 V.
pub const MIN_VOLTAGE_LIMIT: u16 = 34;
/// PWM Limit (2, RW, EEPROM): 0–885 (100 %); bounds Goal PWM.
pub const PWM_LIMIT: u16 = 36;
/// Current Limit (2, RW, EEPROM): bounds Goal Current. Not on the XL430 or
/// the MX-28, which have no current sensor.
pub const CURRENT_LIMIT: u16 = 38;
/// Velocity Limit (4, RW, EEPROM): 0.229 rev/min; bounds Goal Velocity.
pub const VELOCITY_LIMIT: u16 = 44;
/// Max Position Limit (4, RW, EEPROM): pulses, Position Control Mode.
pub const MAX_POSITION_LIMIT: u16 = 48;
/// Min Position Limit (4, RW, EEPROM).
pub const MIN_POSITION_LIMIT: u16 = 52;
/// Shutdown (1, RW, EEPROM): the [`HardwareError`] bits that switch torque
/// off.
pub const SHUTDOWN: u16 = 63;
/// Torque Enable (1, RW, RAM): 0 off, 1 on; EEPROM is locked while on.
pub const TORQUE_ENABLE: u16 = 64;
/// LED (1, RW, RAM).
pub const LED: u16 = 65;
/// Status Return Level (1, RW, RAM): 0 PING only, 1 PING and READ, 2 all.
pub const STATUS_RETURN_LEVEL: u16 = 68;
/// Registered Instruction (1, R, RAM): a REG WRITE waits for ACTION.
pub const REGISTERED_INSTRUCTION: u16 = 69;
/// Hardware Error Status (1, R, RAM): [`HardwareError`]; read it when a
/// status packet's Alert bit is set.
pub const HARDWARE_ERROR_STATUS: u16 = 70;
/// Bus Watchdog (1, RW, RAM, signed): 0 off, 1–127 in 20 ms units; the
/// servo stops and sets −1 when no instruction arrives for that long.
pub const BUS_WATCHDOG: u16 = 98;
/// Goal PWM (2, RW, RAM, signed): 0.113 % of the supply, within ±PWM
/// Limit; the command of PWM Control Mode.
pub const GOAL_PWM: u16 = 100;
/// Goal Current (2, RW, RAM, signed): within ±Current Limit.
pub const GOAL_CURRENT: u16 = 102;
/// Goal Velocity (4, RW, RAM, signed): 0.229 rev/min, within ±Velocity
/// Limit.
pub const GOAL_VELOCITY: u16 = 104;
/// Goal Position (4, RW, RAM, signed): pulses.
pub const GOAL_POSITION: u16 = 116;
/// Present PWM (2, R, RAM, signed).
pub const PRESENT_PWM: u16 = 124;
/// Present Current (2, R, RAM, signed) on models with a current sensor.
pub const PRESENT_CURRENT: u16 = 126;
/// Present Load (2, R, RAM, signed, 0.1 %) on the XL430 and MX-28: the
/// same address as Present Current, an estimate from the output.
pub const PRESENT_LOAD: u16 = 126;
/// Present Velocity (4, R, RAM, signed): 0.229 rev/min.
pub const PRESENT_VELOCITY: u16 = 128;
/// Present Position (4, R, RAM, signed): pulses, 4096 per revolution.
pub const PRESENT_POSITION: u16 = 132;
/// Present Input Voltage (2, R, RAM): 0.1 V.
pub const PRESENT_INPUT_VOLTAGE: u16 = 144;
/// Present Temperature (1, R, RAM): °C.
pub const PRESENT_TEMPERATURE: u16 = 146;
/// Indirect Address 1 (2 bytes each, RW, RAM): the address whose byte
/// Indirect Data 1 mirrors.
pub const INDIRECT_ADDRESS_1: u16 = 168;

/// Present PWM through Present Temperature: the block one (fast) sync read
/// returns per control period.
pub const PRESENT_BLOCK: u16 = PRESENT_PWM;
/// Length of [`PRESENT_BLOCK`] (addresses 124–146).
pub const PRESENT_BLOCK_LEN: u16 = PRESENT_TEMPERATURE + 1 - PRESENT_PWM;
/// Pulses of Present Position per revolution.
pub const PULSES_PER_REV: u32 = 4096;

/// Operating Mode values (address 11).
pub mod mode {
    /// Current (torque) control.
    pub const CURRENT: u8 = 0;
    /// Velocity control.
    pub const VELOCITY: u8 = 1;
    /// Position control within one turn and the position limits (default).
    pub const POSITION: u8 = 3;
    /// Multi-turn position control.
    pub const EXTENDED_POSITION: u8 = 4;
    /// Position control with a current limit.
    pub const CURRENT_BASED_POSITION: u8 = 5;
    /// PWM (voltage) control: Goal PWM drives the motor directly, the
    /// nearest to the paper's voltage actions.
    pub const PWM: u8 = 16;
}

/// Hardware Error Status (address 70) and Shutdown (63) bits of the X
/// series and MX(2.0) (e-Manual, "Shutdown").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
#[derive(serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HardwareError(pub u8);

impl HardwareError {
    /// Bit 0: input voltage outside the voltage limits.
    pub const INPUT_VOLTAGE: HardwareError = HardwareError(0x01);
    /// Bit 2: internal temperature above the Temperature Limit.
    pub const OVERHEATING: HardwareError = HardwareError(0x04);
    /// Bit 3: the motor encoder malfunctions.
    pub const MOTOR_ENCODER: HardwareError = HardwareError(0x08);
    /// Bit 4: an electrical shock on the circuit or too little power.
    pub const ELECTRICAL_SHOCK: HardwareError = HardwareError(0x10);
    /// Bit 5: a persistent load beyond the maximum output.
    pub const OVERLOAD: HardwareError = HardwareError(0x20);
    /// Every bit the e-Manual defines.
    pub const ALL: HardwareError = HardwareError(0x3D);

    /// Whether every bit of `other` is set.
    pub const fn contains(self, other: HardwareError) -> bool {
        self.0 & other.0 == other.0
    }

    /// The names of the set bits, lowest first (undefined bits as
    /// `"unknown"`).
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        const NAMES: [&str; 8] =
            ["input voltage", "unknown", "overheating", "motor encoder", "electrical shock", "overload", "unknown", "unknown"];
        (0..8).filter(move |b| self.0 & (1 << b) != 0).filter_map(|b| NAMES.get(b).copied())
    }
}

/// The decoded [`PRESENT_BLOCK`] of one servo.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PresentState {
    /// Present PWM (0.113 %).
    pub pwm: i16,
    /// Present Current (model's unit) or Present Load (0.1 %).
    pub current: i16,
    /// Present Velocity (0.229 rev/min).
    pub velocity: i32,
    /// Present Position (pulses).
    pub position: i32,
    /// Velocity Trajectory (0.229 rev/min).
    pub velocity_trajectory: i32,
    /// Position Trajectory (pulses).
    pub position_trajectory: i32,
    /// Present Input Voltage (0.1 V).
    pub input_voltage: u16,
    /// Present Temperature (°C).
    pub temperature: u8,
}

impl PresentState {
    /// Parses the 23 bytes of a read of [`PRESENT_BLOCK`]; `None` if
    /// `bytes` is shorter.
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let b: &[u8; PRESENT_BLOCK_LEN as usize] = bytes.get(..PRESENT_BLOCK_LEN as usize)?.try_into().ok()?;
        let i32_at = |i: usize| i32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
        Some(PresentState {
            pwm: i16::from_le_bytes([b[0], b[1]]),
            current: i16::from_le_bytes([b[2], b[3]]),
            velocity: i32_at(4),
            position: i32_at(8),
            velocity_trajectory: i32_at(12),
            position_trajectory: i32_at(16),
            input_voltage: u16::from_le_bytes([b[20], b[21]]),
            temperature: b[22],
        })
    }

    /// The 23 bytes of the block (the bus emulator's side).
    pub fn to_bytes(&self) -> [u8; PRESENT_BLOCK_LEN as usize] {
        let mut out = [0u8; PRESENT_BLOCK_LEN as usize];
        let parts: [&[u8]; 8] = [
            &self.pwm.to_le_bytes(),
            &self.current.to_le_bytes(),
            &self.velocity.to_le_bytes(),
            &self.position.to_le_bytes(),
            &self.velocity_trajectory.to_le_bytes(),
            &self.position_trajectory.to_le_bytes(),
            &self.input_voltage.to_le_bytes(),
            &[self.temperature],
        ];
        let mut at = 0;
        for p in parts {
            if let Some(dst) = out.get_mut(at..at + p.len()) {
                dst.copy_from_slice(p);
            }
            at += p.len();
        }
        out
    }
}

/// Baud Rate values 0–7 of the X430 series and MX(2.0), in bps.
pub const BAUD_RATES_X430: [u32; 8] = [9_600, 57_600, 115_200, 1_000_000, 2_000_000, 3_000_000, 4_000_000, 4_500_000];

/// Baud Rate values 0–6 of the XL330 (the X430's without 4.5 Mbps), in bps.
pub const BAUD_RATES_XL330: [u32; 7] = [9_600, 57_600, 115_200, 1_000_000, 2_000_000, 3_000_000, 4_000_000];

// Items shared by the models (each table lists them by address).
pub(super) const MODEL: Item = Item::eeprom("Model Number", MODEL_NUMBER, 2).read_only();
pub(super) const FIRMWARE: Item = Item::eeprom("Firmware Version", FIRMWARE_VERSION, 1).read_only();
pub(super) const ID_ITEM: Item = Item::eeprom("ID", ID, 1).range(0, 252);
pub(super) const RETURN_DELAY: Item = Item::eeprom("Return Delay Time", RETURN_DELAY_TIME, 1).range(0, 254).unit(2.0, "µs");
pub(super) const OPERATING_MODES_ALL: &[i64] = &[0, 1, 3, 4, 5, 16];
pub(super) const OPERATING_MODES_NO_CURRENT: &[i64] = &[1, 3, 4, 16];
pub(super) const HOMING: Item =
    Item::eeprom("Homing Offset", HOMING_OFFSET, 4).signed().range(-1_044_479, 1_044_479).unit(1.0, "pulse");
pub(super) const TEMP_LIMIT: Item = Item::eeprom("Temperature Limit", TEMPERATURE_LIMIT, 1).range(0, 100).unit(1.0, "°C");
pub(super) const PWM_LIMIT_ITEM: Item = Item::eeprom("PWM Limit", PWM_LIMIT, 2).range(0, 885).unit(0.113, "%");
pub(super) const MAX_POSITION: Item = Item::eeprom("Max Position Limit", MAX_POSITION_LIMIT, 4).range(0, 4095).unit(1.0, "pulse");
pub(super) const MIN_POSITION: Item = Item::eeprom("Min Position Limit", MIN_POSITION_LIMIT, 4).range(0, 4095).unit(1.0, "pulse");
pub(super) const SHUTDOWN_ITEM: Item = Item::eeprom("Shutdown", SHUTDOWN, 1).mask(HardwareError::ALL.0 as u32);
pub(super) const TORQUE: Item = Item::ram("Torque Enable", TORQUE_ENABLE, 1).range(0, 1);
pub(super) const LED_ITEM: Item = Item::ram("LED", LED, 1).range(0, 1);
pub(super) const RETURN_LEVEL: Item = Item::ram("Status Return Level", STATUS_RETURN_LEVEL, 1).range(0, 2);
pub(super) const REGISTERED: Item = Item::ro("Registered Instruction", REGISTERED_INSTRUCTION, 1);
pub(super) const HW_ERROR: Item = Item::ro("Hardware Error Status", HARDWARE_ERROR_STATUS, 1);
pub(super) const WATCHDOG: Item = Item::ram("Bus Watchdog", BUS_WATCHDOG, 1).signed().range(0, 127).unit(20.0, "ms");
pub(super) const GOAL_PWM_ITEM: Item =
    Item::ram("Goal PWM", GOAL_PWM, 2).signed().range(-885, 885).limit(Limit::Magnitude(PWM_LIMIT)).unit(0.113, "%");
pub(super) const GOAL_POSITION_ITEM: Item = Item::ram("Goal Position", GOAL_POSITION, 4)
    .signed()
    .range(-1_048_575, 1_048_575)
    .limit(Limit::Between { min: MIN_POSITION_LIMIT, max: MAX_POSITION_LIMIT, mode: mode::POSITION })
    .unit(1.0, "pulse");
pub(super) const PRESENT_PWM_ITEM: Item = Item::ro("Present PWM", PRESENT_PWM, 2).signed().unit(0.113, "%");
pub(super) const PRESENT_LOAD_ITEM: Item =
    Item::ro("Present Load", PRESENT_LOAD, 2).signed().range(-1000, 1000).unit(0.1, "%");
pub(super) const PRESENT_VELOCITY_ITEM: Item = Item::ro("Present Velocity", PRESENT_VELOCITY, 4).signed().unit(0.229, "rev/min");
pub(super) const PRESENT_POSITION_ITEM: Item = Item::ro("Present Position", PRESENT_POSITION, 4).signed().unit(1.0, "pulse");
pub(super) const PRESENT_VOLTAGE_ITEM: Item = Item::ro("Present Input Voltage", PRESENT_INPUT_VOLTAGE, 2).unit(0.1, "V");
pub(super) const PRESENT_TEMPERATURE_ITEM: Item = Item::ro("Present Temperature", PRESENT_TEMPERATURE, 1).unit(1.0, "°C");
/// The X430's and MX(2.0)'s 56 indirect addresses and data, in two rows of
/// 28 each (the second row only reachable by Protocol 2.0).
pub(super) const INDIRECT_56: [Item; 4] = [
    Item::ram("Indirect Address 1–28", INDIRECT_ADDRESS_1, 2).range(64, 661).times(28),
    Item::ram("Indirect Data 1–28", 224, 1).times(28),
    Item::ram("Indirect Address 29–56", 578, 2).range(64, 661).times(28),
    Item::ram("Indirect Data 29–56", 634, 1).times(28),
];

/// Max and Min Voltage Limit, both within `min..=max` (0.1 V).
pub(super) const fn voltage_limits(min: i64, max: i64) -> [Item; 2] {
    [
        Item::eeprom("Max Voltage Limit", MAX_VOLTAGE_LIMIT, 2).range(min, max).unit(0.1, "V"),
        Item::eeprom("Min Voltage Limit", MIN_VOLTAGE_LIMIT, 2).range(min, max).unit(0.1, "V"),
    ]
}

/// Velocity Limit up to `max` and Goal Velocity within ±`max`.
pub(super) const fn velocity_items(max: i64) -> [Item; 2] {
    [
        Item::eeprom("Velocity Limit", VELOCITY_LIMIT, 4).range(0, max).unit(0.229, "rev/min"),
        Item::ram("Goal Velocity", GOAL_VELOCITY, 4)
            .signed()
            .range(-max, max)
            .limit(Limit::Magnitude(VELOCITY_LIMIT))
            .unit(0.229, "rev/min"),
    ]
}

/// Current Limit, Goal Current and Present Current of a model with a
/// current sensor whose unit is `ma` mA.
const fn current_items(max: i64, ma: f32) -> [Item; 3] {
    [
        Item::eeprom("Current Limit", CURRENT_LIMIT, 2).range(0, max).unit(ma, "mA"),
        Item::ram("Goal Current", GOAL_CURRENT, 2).signed().range(-max, max).limit(Limit::Magnitude(CURRENT_LIMIT)).unit(ma, "mA"),
        Item::ro("Present Current", PRESENT_CURRENT, 2).signed().unit(ma, "mA"),
    ]
}

/// A control table with the X series' layout (the X series and the
/// MX(2.0)): the items every such model has, listed once by address; the
/// arguments are what differs between models. `current: [limit, goal,
/// present]` gives a current sensor's three items ([`current_items`]);
/// `load` puts Present Load at 126 instead and no current items.
macro_rules! x_layout_table {
    (
        $model:literal, $number:literal, baud: $baud_max:literal of $bauds:expr, drive_mask: $mask:literal,
        modes: $modes:expr, volts: $volts:expr, velocity: $vel:expr, current: $cur:expr,
        indirect: [$($ind:expr),+], end: $end:literal $(,)?
    ) => {
        x_layout_table!(@table $model, $number, $baud_max, $bauds, $mask, $modes, $volts, $vel,
            [$cur[0],], [$cur[1],], $cur[2], [$($ind),+], $end)
    };
    (
        $model:literal, $number:literal, baud: $baud_max:literal of $bauds:expr, drive_mask: $mask:literal,
        modes: $modes:expr, volts: $volts:expr, velocity: $vel:expr, load,
        indirect: [$($ind:expr),+], end: $end:literal $(,)?
    ) => {
        x_layout_table!(@table $model, $number, $baud_max, $bauds, $mask, $modes, $volts, $vel,
            [], [], $crate::dynamixel::control_table::x_series::PRESENT_LOAD_ITEM, [$($ind),+], $end)
    };
    (
        @table $model:literal, $number:literal, $baud_max:literal, $bauds:expr, $mask:literal, $modes:expr,
        $volts:expr, $vel:expr, [$($cur_limit:expr,)?], [$($cur_goal:expr,)?], $present_126:expr,
        [$($ind:expr),+], $end:literal
    ) => {{
        use $crate::dynamixel::control_table::{x_series as x, ControlTable, Item};
        ControlTable {
            model: $model,
            model_number: $number,
            protocol: $crate::dynamixel::Protocol::V2,
            items: &[
                x::MODEL,
                x::FIRMWARE,
                x::ID_ITEM,
                Item::eeprom("Baud Rate", x::BAUD_RATE, 1).range(0, $baud_max),
                x::RETURN_DELAY,
                Item::eeprom("Drive Mode", x::DRIVE_MODE, 1).mask($mask),
                Item::eeprom("Operating Mode", x::OPERATING_MODE, 1).one_of($modes),
                x::HOMING,
                x::TEMP_LIMIT,
                $volts[0],
                $volts[1],
                x::PWM_LIMIT_ITEM,
                $($cur_limit,)?
                $vel[0],
                x::MAX_POSITION,
                x::MIN_POSITION,
                x::SHUTDOWN_ITEM,
                x::TORQUE,
                x::LED_ITEM,
                x::RETURN_LEVEL,
                x::REGISTERED,
                x::HW_ERROR,
                x::WATCHDOG,
                x::GOAL_PWM_ITEM,
                $($cur_goal,)?
                $vel[1],
                x::GOAL_POSITION_ITEM,
                x::PRESENT_PWM_ITEM,
                $present_126,
                x::PRESENT_VELOCITY_ITEM,
                x::PRESENT_POSITION_ITEM,
                x::PRESENT_VOLTAGE_ITEM,
                x::PRESENT_TEMPERATURE_ITEM,
                $($ind),+
            ],
            baud_rates: &$bauds,
            end: $end,
            torque_enable: x::TORQUE_ENABLE,
            operating_mode: x::OPERATING_MODE,
        }
    }};
}
pub(super) use x_layout_table;

/// XM430-W350 (model 1020): current sensor (2.69 mA units), 10–14.8 V.
pub static XM430_W350: ControlTable = x_layout_table!(
    "XM430-W350", 1020, baud: 7 of BAUD_RATES_X430, drive_mask: 0x0D, modes: OPERATING_MODES_ALL,
    volts: voltage_limits(95, 160), velocity: velocity_items(1023), current: current_items(1193, 2.69),
    indirect: [INDIRECT_56[0], INDIRECT_56[1], INDIRECT_56[2], INDIRECT_56[3]], end: 662,
);

/// XL430-W250 (model 1060): no current sensor, so no Current Limit or Goal
/// Current, and Present Load (0.1 %) at 126; 6.5–12 V.
pub static XL430_W250: ControlTable = x_layout_table!(
    "XL430-W250", 1060, baud: 7 of BAUD_RATES_X430, drive_mask: 0x0D, modes: OPERATING_MODES_NO_CURRENT,
    volts: voltage_limits(60, 140), velocity: velocity_items(1023), load,
    indirect: [INDIRECT_56[0], INDIRECT_56[1], INDIRECT_56[2], INDIRECT_56[3]], end: 662,
);

/// XL330-M288 (model 1200): current sensor (1 mA units), 3.7–6 V, baud
/// rates to 4 Mbps, 20 indirect addresses.
pub static XL330_M288: ControlTable = x_layout_table!(
    "XL330-M288", 1200, baud: 6 of BAUD_RATES_XL330, drive_mask: 0x0D, modes: OPERATING_MODES_ALL,
    volts: voltage_limits(31, 70), velocity: velocity_items(2047), current: current_items(1750, 1.0),
    indirect: [
        Item::ram("Indirect Address 1–20", INDIRECT_ADDRESS_1, 2).range(64, 227).times(20),
        Item::ram("Indirect Data 1–20", 208, 1).times(20)
    ],
    end: 228,
);
