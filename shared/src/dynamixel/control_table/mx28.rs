//! The MX-28 on Protocol 2.0 firmware, "MX-28(2.0)" (e-Manual,
//! <https://emanual.robotis.com/docs/en/dxl/mx/mx-28-2/>): the successor of
//! the RX-28 with the same 193:1 gear train, listed for completeness of
//! the model list. Its control table has the X series' layout for every
//! item pada uses, so the addresses are [`super::x_series`]'s; it has no
//! current sensor (Present Load at 126, no Current Limit or Goal Current)
//! and no current-based modes.

use super::x_series::{
    velocity_items, voltage_limits, x_layout_table, BAUD_RATES_X430, INDIRECT_56, OPERATING_MODES_NO_CURRENT,
};
use super::ControlTable;

/// MX-28 with Protocol 2.0 firmware (model 30): 10–14.8 V. Drive Mode has
/// bit 0 (reverse) and bit 2 (time-based profile); no bit 3 on the MX(2.0).
pub static MX28_V2: ControlTable = x_layout_table!(
    "MX-28(2.0)", 30, baud: 7 of BAUD_RATES_X430, drive_mask: 0x05, modes: OPERATING_MODES_NO_CURRENT,
    volts: voltage_limits(95, 160), velocity: velocity_items(1023), load,
    indirect: [INDIRECT_56[0], INDIRECT_56[1], INDIRECT_56[2], INDIRECT_56[3]], end: 662,
);
