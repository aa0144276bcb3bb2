//! The Feetech STS3215 (the SO-100/SO-101 arm's servo) in the servo table
//! ([`super::SERVOS`]): its three gear variants, each a [`ServoModel`] on
//! the Feetech protocol ([`ServoProtocol::Feetech`]), with the
//! STS3215's encoding ([`super::encoding::STS3215`]: 4096 counts a turn,
//! Goal_Time in Operating_Mode 2) and the factory gains of its own
//! position loop ([`super::position_loop`]).
//!
//! - **STS3215** (C001, 1/345): the follower's six servos and the leader's
//!   shoulder lift. Figures from Feetech's listing and DFRobot's; the
//!   stall current from a third party's test (no Feetech page gives it).
//! - **STS3215-C044** (1/191) and **STS3215-C046** (1/147): the leader's
//!   other five. No listing gives their no-load speed or stall current, so
//!   their figures are **estimates**: the C001's motor behind a different
//!   gear ratio (same case, same supply, same product line), i.e. the
//!   C001's stall torque × G/345, its no-load speed × 345/G, its stall
//!   current. A Feetech representative's list gives "22 kg" (C044) and
//!   "14 kg" (C046); with the C001's motor those would need an efficiency
//!   above 1 at 1/191, so they are not used.
//!
//! The three variants share one gearbox entry, `STS3215` (an estimate:
//! Table I's gear scaled with the case width, which is the same), and one
//! model number, 777 (the bus cannot tell the gear ratio; a scan names the
//! C001). Every figure and its source is in `docs/reference/feetech.md`
//! ("The STS3215's motor and gears") and `docs/reference/servos.md` §1, §5;
//! the tests keep both equal to this data.

use super::encoding;
use super::position_loop::LoopGains;
use super::{Datasheet, MotorSource, ServoModel, ServoProtocol};

/// 19.5 kgf·cm in N·m (1 kgf·cm = 0.0980665 N·m).
const STALL_TORQUE_C001_NM: f32 = 19.5 * 0.0980665;
/// The C001's gear ratio and no-load speed \[rev/min\]: 0.192 s/60° at
/// 7.4 V is 60/(6 × 0.192) = 52.1 rev/min; the listing rounds it to 52.
const RATIO_C001: f32 = 345.0;
const NO_LOAD_C001_RPM: f32 = 52.0;

/// Where the C001's figures come from (docs/reference/feetech.md lists
/// every page).
const C001_SOURCE: &str = "Feetech STS3215 listing and DFRobot SER0069 (docs/reference/feetech.md, \"The STS3215's motor and gears\")";
/// Where the leader variants' gear ratios come from.
const LEADER_SOURCE: &str = "SO-ARM100 README, gear ratio only (docs/reference/feetech.md, \"The STS3215's motor and gears\")";

/// A leader variant's figures: the C001's motor behind `ratio` (module
/// documentation).
const fn leader_datasheet(ratio: f32) -> Datasheet {
    Datasheet {
        rated_voltage_v: 7.4,
        stall_torque_nm: STALL_TORQUE_C001_NM * ratio / RATIO_C001,
        stall_current_a: 2.7,
        no_load_speed_rpm: NO_LOAD_C001_RPM * RATIO_C001 / ratio,
        gear_ratio: ratio,
        max_voltage_v: 7.4,
        backlash_arcmin: Some(30.0),
        gear_material: "Metal (assumed as the C001's)",
        case_mm: [24.7, 45.2, 35.0],
    }
}

/// What is estimated in a leader variant's figures.
const LEADER_ESTIMATES: &str = "estimate: the C001's motor behind this gear ratio (stall torque × G/345, no-load speed × 345/G, stall current 2.7 A); backlash and gear material as the C001's";

/// The STS3215-C001: 7.4 V, 1/345 gears, the SO-101 follower's six servos
/// and the leader's shoulder_lift.
pub const STS3215: ServoModel = ServoModel {
    name: "STS3215",
    protocol: ServoProtocol::Feetech,
    model_number: 777,
    encoding: encoding::STS3215,
    source: C001_SOURCE,
    datasheet: Datasheet {
        rated_voltage_v: 7.4,
        stall_torque_nm: STALL_TORQUE_C001_NM,
        stall_current_a: 2.7,
        no_load_speed_rpm: NO_LOAD_C001_RPM,
        gear_ratio: RATIO_C001,
        max_voltage_v: 7.4,
        // "≤ 0.5°" (Feetech's datasheet as quoted by the SO-ARM100 issue
        // tracker and Robonine's test); measured ≈ 0.9–1°.
        backlash_arcmin: Some(30.0),
        gear_material: "Metal (copper and aluminium)",
        case_mm: [24.7, 45.2, 35.0],
    },
    resistance_ohm: None,
    torque_constant_nm_per_a: None,
    motor_constants_source: None,
    motor_source: MotorSource::Datasheet,
    gearbox: "STS3215",
    figure_notes: Some("stall current: Robonine's serial-servo driver board test (about 2.7 A); no Feetech page read gives it"),
    loop_gains: Some(LoopGains::FACTORY),
};

/// The STS3215-C044: 7.4 V, 1/191 gears, the SO-101 leader's shoulder pan
/// and elbow flex. Figures estimated (module documentation).
pub const STS3215_C044: ServoModel = ServoModel {
    name: "STS3215-C044",
    source: LEADER_SOURCE,
    datasheet: leader_datasheet(191.0),
    figure_notes: Some(LEADER_ESTIMATES),
    ..STS3215
};

/// The STS3215-C046: 7.4 V, 1/147 gears, the SO-101 leader's wrist flex,
/// wrist roll and gripper. Figures estimated (module documentation).
pub const STS3215_C046: ServoModel = ServoModel {
    name: "STS3215-C046",
    source: LEADER_SOURCE,
    datasheet: leader_datasheet(147.0),
    figure_notes: Some(LEADER_ESTIMATES),
    ..STS3215
};
