//! Memory tables of the Feetech servos pada supports, as data, in the
//! same type as the Dynamixel control tables
//! ([`crate::dynamixel::control_table::ControlTable`]): what is at which
//! address, how long, who may write it, which raw values are valid, in
//! which unit. The sources and the choices where they disagree are in
//! docs/reference/feetech.md § "Memory map", whose table a test compares
//! with this one.
//!
//! | model | model number | byte order | module |
//! |---|---|---|---|
//! | STS3215 | 777 | little endian | [`sts3215::STS3215`] |
//!
//! Values are raw: a sign-magnitude item ([`super::value`]) is checked
//! on its raw bits, and its `signed` flag (two's complement, for the
//! Dynamixel tables) is never set.

use crate::dynamixel::control_table::ControlTable;

pub mod sts3215;

/// Every Feetech table pada knows.
pub static TABLES: [&ControlTable; 1] = [&sts3215::STS3215];

/// The table of the model whose Model Number (address 3) is
/// `model_number`.
pub fn by_model_number(model_number: u16) -> Option<&'static ControlTable> {
    TABLES.iter().copied().find(|t| t.model_number == model_number)
}
