//! The Feetech STS3215 (the SO-100/SO-101 arm's servo) as data: its gear
//! variants with their sources, the DC-motor model of the follower's
//! variant from its listing's stall torque, stall current and no-load
//! speed ([`super::DcMotor::from_datasheet`], the same derivation as every
//! ROBOTIS model but the RX-28's), and the defaults of its position loop
//! ([`super::position_loop`]).
//!
//! The table is kept apart from [`super::SERVOS`] because a
//! [`super::ServoModel`] names a Dynamixel protocol and command encoding,
//! and the STS3215 speaks neither: its packets share Dynamixel 1.0's
//! framing, but its control table (Goal_Position at 42, Operating_Mode at
//! 33, …) and its voltage command (Goal_Time at 44 in Operating_Mode 2,
//! bit 10 the direction) are its own. It joins [`super::SERVOS`] once
//! pada-core speaks the Feetech protocol.
//!
//! Every figure and its source is in `docs/reference/feetech.md` ("The
//! STS3215's motor and gears") and `docs/reference/servos.md`; the tests
//! keep both equal to this data.

use super::gearbox::STS3215_GEARBOX;
use super::position_loop::{LoopGains, PositionLoopSpec};
use super::{Datasheet, DcMotor, Gearbox, UnknownName};

/// One STS3215 variant: what a joint of an SO-101 names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeetechModel {
    /// The name as users write it (matched case-insensitively by [`feetech_servo`]).
    pub name: &'static str,
    /// Feetech's variant code (C001: 7.4 V, 1/345).
    pub variant: &'static str,
    /// Model_Number (address 3) as LeRobot's table reads it.
    pub model_number: u16,
    /// Where the datasheet figures are taken from.
    pub source: &'static str,
    /// The figures; the stall current's source is weaker than the
    /// others' (see `stall_current_source`).
    pub datasheet: Datasheet,
    /// Where the stall current comes from.
    pub stall_current_source: &'static str,
    /// The position loop's coefficients as the servo ships (P_Coefficient
    /// at 21, D at 22, I at 23).
    pub factory_gains: LoopGains,
    /// Its gearbox.
    pub gearbox: &'static Gearbox,
}

impl FeetechModel {
    /// The motor model from the datasheet figures ([`DcMotor::from_datasheet`]).
    pub fn motor(&self) -> DcMotor {
        DcMotor::from_datasheet(&self.datasheet)
    }

    /// Its position loop with `gains` (LeRobot's are [`LoopGains::LEROBOT`]).
    pub fn position_loop(&self, gains: LoopGains) -> PositionLoopSpec {
        PositionLoopSpec::sts3215(gains)
    }
}

/// 19.5 kgf·cm in N·m (1 kgf·cm = 0.0980665 N·m).
const STALL_TORQUE_C001_NM: f32 = 19.5 * 0.0980665;

/// The STS3215-C001: 7.4 V, 1/345 gears, the SO-101 follower's six servos
/// and the leader's shoulder_lift.
pub const STS3215: FeetechModel = FeetechModel {
    name: "STS3215",
    variant: "C001",
    model_number: 777,
    source: "Feetech STS3215 listing (https://www.feetech.cn/en/74v-19-kgcm-plastic-case-metal-tooth-magnetic-code-double-axis-ttl-series-steering-gear.html) and DFRobot SER0069 (https://littlebirdelectronics.com.au/products/st3215-serial-bus-servo-19-5kg-7-4v-360-magnetic-encoder)",
    datasheet: Datasheet {
        rated_voltage_v: 7.4,
        stall_torque_nm: STALL_TORQUE_C001_NM,
        stall_current_a: 2.7,
        // 0.192 s/60° at 7.4 V: 60/(6 × 0.192) = 52.1 rev/min; the
        // listing rounds it to 52.
        no_load_speed_rpm: 52.0,
        gear_ratio: 345.0,
        max_voltage_v: 7.4,
        // "≤ 0.5°" (Feetech's datasheet as quoted by the SO-ARM100 issue
        // tracker and Robonine's test); measured ≈ 0.9–1°.
        backlash_arcmin: Some(30.0),
        gear_material: "Metal (copper and aluminium)",
        case_mm: [24.7, 45.2, 35.0],
    },
    stall_current_source: "Robonine, serial-servo driver board test (https://robonine.com/?p=1177): about 2.7 A; no Feetech page read gives it",
    factory_gains: LoopGains::FACTORY,
    gearbox: &STS3215_GEARBOX,
};

/// Every Feetech model pada knows.
pub static FEETECH_SERVOS: [FeetechModel; 1] = [STS3215];

/// The names of [`FEETECH_SERVOS`], in order.
pub static FEETECH_NAMES: [&str; 1] = [STS3215.name];

/// The Feetech model called `name` (ASCII case-insensitive); an unknown
/// name's error lists the valid ones.
pub fn feetech_servo(name: &str) -> Result<&'static FeetechModel, UnknownName<'_>> {
    FEETECH_SERVOS.iter().find(|s| s.name.eq_ignore_ascii_case(name.trim())).ok_or(UnknownName {
        kind: "Feetech servo model",
        name,
        valid: &FEETECH_NAMES,
    })
}
