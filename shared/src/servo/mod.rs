//! Servos and gearboxes as data: the servo models pada knows, each with its
//! datasheet figures and their source, the DC-motor model derived from them,
//! and the gearbox whose last gear the fatigue counter follows (Section IV,
//! Eqs. 3–7, Table I).
//!
//! A robot's joint names its servo model ([`servo`], case-insensitive); the
//! model names its gearbox ([`ServoModel::gearbox`], [`gearbox::gearbox`]).
//! Every figure names where it comes from; `docs/reference/servos.md` shows
//! both tables and a test keeps that page and this data equal.
//!
//! | file | its one job |
//! |---|---|
//! | `mod.rs` | the servo models: datasheet figures, the DC motor, lookup by name |
//! | `gearbox.rs` | the gearboxes: the last gear's Eqs. 3–7 parameters, each with its source, estimates marked |
//! | `feetech.rs` | the Feetech STS3215's gear variants: their figures and sources, estimates marked |
//! | `position_loop.rs` | a servo's own position loop (the STS3215's in Operating_Mode 0): goal error to motor voltage |
//!
//! # The DC motor from a datasheet
//!
//! The motor model is the one GRL simulates the RX-28 with
//! (`docs/reference/grl.md` §2.1, [`crate::rx28`]): at the output shaft, in
//! steady motion, `τ = η·G·k·(U − G·k·q̇)/R`. ROBOTIS publishes, at a rated
//! voltage `V`, the stall torque `τ_s` and stall current `I_s` (both at the
//! output: after the gears) and the no-load speed `ω_0`, plus the gear ratio
//! `G`, but neither the torque constant `k` nor the resistance `R`. Three
//! equations of the model fix the three unknowns:
//!
//! - no-load speed `ω_0 = V/(G·k)` → `k = V/(G·ω_0)` (the back-EMF constant
//!   equals the torque constant in SI units);
//! - stall current `I_s = V/R` → `R = V/I_s` (the terminal resistance as the
//!   servo's driver sees it, its own drop included);
//! - stall torque `τ_s = η·G·k·V/R` → `η = τ_s/(G·k·I_s) = τ_s·ω_0/(V·I_s)`.
//!
//! So `η` is not a gear efficiency from a catalogue: it is the factor that
//! makes the model's stall torque, stall current and no-load speed at the
//! rated voltage equal the datasheet's all at once. It lumps the gear train's
//! losses with the driver's and the motor's friction (the no-load current is
//! not published, so friction is not separated). The tests check every
//! datasheet-derived entry against its three figures.
//!
//! The RX-28 is the exception: its motor is GRL's (G = 193, k = 0.00992 N·m/A,
//! R = 8.6 Ω, η = 0.75, [`crate::rx28`]), which LEO's simulation and the
//! paper's results rest on, bit for bit. GRL's model differs from the RX-28
//! datasheet: at 18.5 V it gives a no-load speed of 92.3 rev/min (datasheet
//! 85), a stall torque of 3.09 N·m (datasheet 3.7) and a stall current of
//! 2.15 A (datasheet 1.9). pada keeps GRL's, as the paper's framework does.
//!
//! Two motor figures are not published for any model and are estimates
//! wherever they are not GRL's (the RX-28 keeps GRL's):
//!
//! - the rotor inertia `J_a`: from the RX-28's mechanical time constant
//!   `τ_mech = J_a·R/k² = 7.55 ms` (GRL's constants), assumed the same for
//!   every motor, so `J_a = τ_mech·k²/R`;
//! - the dry friction at the joint: GRL's 0.2 N·m for the RX-28 is 5.4 % of
//!   the RX-28's datasheet stall torque (3.7 N·m); every other model is given
//!   the same fraction of its own stall torque.
//!
//! The supply clip is the top of the datasheet's input-voltage range (the
//! RX-28 keeps GRL's 13.6 V).

pub mod encoding;
pub mod feetech;
pub mod gearbox;
pub mod position_loop;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod feetech_tests;

use crate::rx28;
use core::fmt;

pub use encoding::{CommandKind, Drive, Encoding, PositionScale, Present};
pub use feetech::{STS3215, STS3215_C044, STS3215_C046};
pub use gearbox::{gearbox, Gearbox, GearboxSources, GEARBOXES};
pub use position_loop::{ControlMode, LoopGains, PositionLoop, PositionLoopSpec};

/// The bus protocol a servo model speaks (its firmware's default): one of
/// ROBOTIS' two Dynamixel protocols, or Feetech's.
///
/// The number is what the e-Manual calls the protocol ("1.0", "2.0");
/// Feetech's packets are framed as Protocol 1.0's
/// ([`crate::feetech`]), but its instructions, byte orders and control
/// tables are its own, so a bus of Feetech servos is not a Protocol 1.0
/// bus.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServoProtocol {
    /// Dynamixel Protocol 1.0 (the RX and MX series as shipped).
    V1,
    /// Dynamixel Protocol 2.0 (every X-series servo).
    V2,
    /// Feetech's SCS/STS protocol (the STS3215): Protocol 1.0's framing.
    Feetech,
}

impl ServoProtocol {
    /// The framing's major number: 1 or 2 (Feetech's packets are framed
    /// as Protocol 1.0's: 1).
    pub const fn number(self) -> u8 {
        match self {
            ServoProtocol::V1 | ServoProtocol::Feetech => 1,
            ServoProtocol::V2 => 2,
        }
    }

    /// How the documentation names it: "1.0", "2.0" or "Feetech".
    pub const fn name(self) -> &'static str {
        match self {
            ServoProtocol::V1 => "1.0",
            ServoProtocol::V2 => "2.0",
            ServoProtocol::Feetech => "Feetech",
        }
    }

    /// The same protocol as the packet codec names it.
    pub const fn codec(self) -> crate::dynamixel::Protocol {
        match self {
            ServoProtocol::V1 => crate::dynamixel::Protocol::V1,
            ServoProtocol::V2 => crate::dynamixel::Protocol::V2,
            ServoProtocol::Feetech => crate::dynamixel::Protocol::Feetech,
        }
    }
}

/// The figures a maker's page gives for one servo model (a ROBOTIS
/// e-Manual page, Feetech's listing), in its units; where a figure is not
/// the page's, [`ServoModel::figure_notes`] says so. All torques are at the
/// output shaft (after the gears).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Datasheet {
    /// The voltage the figures below are given at \[V\] (the recommended
    /// one where the page gives several; the RX-28's page gives 18.5 V only).
    pub rated_voltage_v: f32,
    /// Stall torque at the rated voltage \[N·m\].
    pub stall_torque_nm: f32,
    /// Stall current at the rated voltage \[A\].
    pub stall_current_a: f32,
    /// No-load speed at the rated voltage \[rev/min\].
    pub no_load_speed_rpm: f32,
    /// Gear ratio G (motor turns per output turn).
    pub gear_ratio: f32,
    /// Top of the input-voltage range \[V\].
    pub max_voltage_v: f32,
    /// Backlash at the output \[arcmin\], where the page gives one.
    pub backlash_arcmin: Option<f32>,
    /// Gear material, as the page names it.
    pub gear_material: &'static str,
    /// Case width × height × depth \[mm\].
    pub case_mm: [f32; 3],
}

impl Datasheet {
    /// The no-load speed in rad/s.
    pub fn no_load_speed_rad_s(&self) -> f32 {
        (self.no_load_speed_rpm as f64 * core::f64::consts::PI / 30.0) as f32
    }
}

/// Where a servo model's motor constants come from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MotorSource {
    /// Given constants: the RX-28's are GRL's (`docs/reference/grl.md` §2.1,
    /// [`crate::rx28`]).
    Given(DcMotor),
    /// Derived from the datasheet figures (see the module documentation).
    Datasheet,
}

/// One servo model: what a robot's joint names.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoModel {
    /// The name as users write it, e.g. "XM430-W350" (matched
    /// case-insensitively by [`servo`]).
    pub name: &'static str,
    /// The protocol its firmware speaks as shipped.
    pub protocol: ServoProtocol,
    /// The Model Number its control table reads (address 0).
    pub model_number: u16,
    /// How its control table says position, speed and the voltage command
    /// ([`encoding`]).
    pub encoding: Encoding,
    /// The page every datasheet figure (and the model number) is taken
    /// from: the e-Manual page of a Dynamixel; for a Feetech servo the
    /// listings, as `docs/reference/feetech.md` names them.
    pub source: &'static str,
    /// The datasheet figures.
    pub datasheet: Datasheet,
    /// The motor's terminal resistance \[Ω\], where a source publishes it.
    pub resistance_ohm: Option<f32>,
    /// The motor's torque constant \[N·m/A\], where a source publishes it.
    pub torque_constant_nm_per_a: Option<f32>,
    /// The source of `resistance_ohm` and `torque_constant_nm_per_a`.
    pub motor_constants_source: Option<&'static str>,
    /// Where the motor model comes from.
    pub motor_source: MotorSource,
    /// The name of its gearbox in [`GEARBOXES`].
    pub gearbox: &'static str,
    /// The figures not taken from `source`: where each comes from, and
    /// "estimate: …" first where pada estimated them. `None` when every
    /// figure is the source's.
    pub figure_notes: Option<&'static str>,
    /// The factory gains of the servo's own position loop, where pada
    /// models it ([`position_loop`]: the STS3215's in Operating_Mode 0);
    /// `None` for a servo whose position mode pada does not model.
    pub loop_gains: Option<LoopGains>,
}

/// A voltage-driven DC motor behind a gearbox, the model GRL simulates the
/// RX-28 with (`docs/reference/grl.md` §2.1), for any servo model.
///
/// In steady motion the joint torque is `η·G·k·(U_c − G·k·q̇)/R` with
/// `U_c = clip(U, ±supply_clip)`; the rotor's inertia and the dry friction
/// act besides (see [`crate::rx28`] for the full model with the armature).
/// All functions are total: a non-finite voltage or rate reads as 0.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DcMotor {
    /// Gear ratio G.
    pub gear_ratio: f32,
    /// Torque (and back-EMF) constant k \[N·m/A\].
    pub torque_constant_nm_per_a: f32,
    /// Terminal resistance R \[Ω\].
    pub resistance_ohm: f32,
    /// Efficiency η; it multiplies the joint torque.
    pub efficiency: f32,
    /// Rotor inertia J_a before the gearbox \[kg·m²\].
    pub armature_inertia: f32,
    /// Dry friction at the joint \[N·m\].
    pub dry_friction: f32,
    /// The clip applied to every commanded voltage \[V\].
    pub supply_clip: f32,
}

/// A non-finite input is read as 0 (as in [`crate::rx28`]).
#[inline]
fn finite_or_zero(x: f32) -> f32 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// The RX-28's mechanical time constant `J_a·R/k²` \[s\] from GRL's
/// constants (≈ 7.55 ms); the rotor inertia of a motor whose datasheet gives
/// none is estimated with it (module documentation).
pub fn rx28_mechanical_time_constant_s() -> f64 {
    let k = rx28::TORQUE_CONSTANT as f64;
    rx28::ARMATURE_INERTIA as f64 * rx28::RESISTANCE as f64 / (k * k)
}

/// The RX-28's dry friction as a fraction of its datasheet stall torque,
/// 0.2 N·m / 3.7 N·m; the dry friction of a motor whose datasheet gives none
/// is estimated with it (module documentation).
pub fn rx28_friction_fraction() -> f64 {
    rx28::DRY_FRICTION as f64 / RX28.datasheet.stall_torque_nm as f64
}

impl DcMotor {
    /// The RX-28 exactly as GRL simulates it: [`crate::rx28`]'s constants.
    pub const RX28: DcMotor = DcMotor {
        gear_ratio: rx28::GEAR_RATIO,
        torque_constant_nm_per_a: rx28::TORQUE_CONSTANT,
        resistance_ohm: rx28::RESISTANCE,
        efficiency: rx28::EFFICIENCY,
        armature_inertia: rx28::ARMATURE_INERTIA,
        dry_friction: rx28::DRY_FRICTION,
        supply_clip: rx28::SUPPLY_CLIP,
    };

    /// The motor that reproduces a datasheet's stall torque, stall current
    /// and no-load speed at its rated voltage (module documentation):
    /// `k = V/(G·ω_0)`, `R = V/I_s`, `η = τ_s·ω_0/(V·I_s)`; `J_a` and the dry
    /// friction estimated from the RX-28's, the supply clip the top of the
    /// input range. Computed in f64, stored in f32.
    pub fn from_datasheet(d: &Datasheet) -> DcMotor {
        let v = d.rated_voltage_v as f64;
        let g = d.gear_ratio as f64;
        let w0 = d.no_load_speed_rpm as f64 * core::f64::consts::PI / 30.0;
        let k = v / (g * w0);
        let r = v / d.stall_current_a as f64;
        let eta = d.stall_torque_nm as f64 * w0 / (v * d.stall_current_a as f64);
        DcMotor {
            gear_ratio: d.gear_ratio,
            torque_constant_nm_per_a: k as f32,
            resistance_ohm: r as f32,
            efficiency: eta as f32,
            armature_inertia: (rx28_mechanical_time_constant_s() * k * k / r) as f32,
            dry_friction: (rx28_friction_fraction() * d.stall_torque_nm as f64) as f32,
            supply_clip: d.max_voltage_v,
        }
    }

    /// Whether every constant is finite and in its physical range (all
    /// positive, friction ≥ 0, 0 < η ≤ 1).
    pub fn is_valid(&self) -> bool {
        let pos = |x: f32| x.is_finite() && x > 0.0;
        pos(self.gear_ratio)
            && pos(self.torque_constant_nm_per_a)
            && pos(self.resistance_ohm)
            && pos(self.efficiency)
            && self.efficiency <= 1.0
            && pos(self.armature_inertia)
            && self.dry_friction.is_finite()
            && self.dry_friction >= 0.0
            && pos(self.supply_clip)
    }

    /// Back-EMF constant at the joint, G·k \[V·s/rad\].
    pub fn back_emf_constant(&self) -> f32 {
        self.gear_ratio * self.torque_constant_nm_per_a
    }

    /// The commanded voltage after the supply clip; non-finite → 0.
    pub fn clip_voltage(&self, voltage: f32) -> f32 {
        finite_or_zero(voltage).clamp(-self.supply_clip, self.supply_clip)
    }

    /// Winding current `(U_c − G·k·q̇)/R` \[A\].
    pub fn current(&self, voltage: f32, joint_rate: f32) -> f32 {
        (self.clip_voltage(voltage) - self.back_emf_constant() * finite_or_zero(joint_rate))
            / self.resistance_ohm
    }

    /// The joint torque in steady motion, `η·G·k·(U_c − G·k·q̇)/R` \[N·m\]:
    /// the same arithmetic as [`rx28::Rx28::estimate_joint_torque`], so the
    /// RX-28 entry gives its results bit for bit.
    pub fn joint_torque(&self, voltage: f32, joint_rate: f32) -> f32 {
        let gk = self.back_emf_constant();
        let motor = gk * (self.clip_voltage(voltage) - gk * finite_or_zero(joint_rate))
            / self.resistance_ohm;
        self.efficiency * motor
    }

    /// Stall torque at the output, η included: `η·G·k·U_c/R` \[N·m\] (what a
    /// datasheet's stall torque is). Unlike [`rx28::Rx28::stall_torque`],
    /// which is before η.
    pub fn stall_torque(&self, voltage: f32) -> f32 {
        self.joint_torque(voltage, 0.0)
    }

    /// No-load speed `U_c/(G·k)` \[rad/s\].
    pub fn no_load_speed(&self, voltage: f32) -> f32 {
        self.clip_voltage(voltage) / self.back_emf_constant()
    }

    /// This motor in [`crate::rx28`]'s form (for the armature tracker and the
    /// reduced joint), with GRL's tracker stiffness and damping.
    pub fn to_rx28(&self) -> rx28::Rx28 {
        rx28::Rx28 {
            gear_ratio: self.gear_ratio,
            torque_constant: self.torque_constant_nm_per_a,
            resistance: self.resistance_ohm,
            efficiency: self.efficiency,
            armature_inertia: self.armature_inertia,
            tracker_stiffness: rx28::TRACKER_STIFFNESS,
            tracker_damping: rx28::TRACKER_DAMPING,
            dry_friction: self.dry_friction,
            supply_clip: self.supply_clip,
        }
    }
}

impl ServoModel {
    /// The motor model: GRL's for the RX-28, derived from the datasheet for
    /// the others ([`DcMotor::from_datasheet`]).
    pub fn motor(&self) -> DcMotor {
        match self.motor_source {
            MotorSource::Given(m) => m,
            MotorSource::Datasheet => DcMotor::from_datasheet(&self.datasheet),
        }
    }

    /// Its gearbox (always present: a test checks every name).
    pub fn gearbox(&self) -> Result<&'static Gearbox, UnknownName<'static>> {
        gearbox::gearbox(self.gearbox)
    }

    /// Its own position loop with `gains` (LeRobot's are
    /// [`LoopGains::LEROBOT`], the factory's [`Self::loop_gains`]); `None`
    /// for a servo whose position loop pada does not model.
    pub fn position_loop(&self, gains: LoopGains) -> Option<PositionLoopSpec> {
        match (self.protocol, self.loop_gains) {
            (ServoProtocol::Feetech, Some(_)) => Some(PositionLoopSpec::sts3215(gains)),
            _ => None,
        }
    }
}

/// An unknown servo or gearbox name; it prints the valid ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnknownName<'a> {
    /// What was asked for: "servo model" or "gearbox".
    pub kind: &'static str,
    /// The name given.
    pub name: &'a str,
    /// The valid names.
    pub valid: &'static [&'static str],
}

impl fmt::Display for UnknownName<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown {} \"{}\": valid are ", self.kind, self.name)?;
        for (i, n) in self.valid.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(n)?;
        }
        Ok(())
    }
}

/// The e-Manual pages (one per model).
const RX28_PAGE: &str = "https://emanual.robotis.com/docs/en/dxl/rx/rx-28/";
const MX28_PAGE: &str = "https://emanual.robotis.com/docs/en/dxl/mx/mx-28/";
const XM430_W350_PAGE: &str = "https://emanual.robotis.com/docs/en/dxl/x/xm430-w350/";
const XL430_W250_PAGE: &str = "https://emanual.robotis.com/docs/en/dxl/x/xl430-w250/";
const XL330_M288_PAGE: &str = "https://emanual.robotis.com/docs/en/dxl/x/xl330-m288/";

/// The RX-28 (discontinued; LEO's servo, the paper's): Protocol 1.0, model
/// number 28. The page gives its figures at 18.5 V only.
pub const RX28: ServoModel = ServoModel {
    name: "RX-28",
    protocol: ServoProtocol::V1,
    model_number: 28,
    encoding: encoding::RX28,
    source: RX28_PAGE,
    datasheet: Datasheet {
        rated_voltage_v: 18.5,
        stall_torque_nm: 3.7,
        stall_current_a: 1.9,
        no_load_speed_rpm: 85.0,
        gear_ratio: 193.0,
        max_voltage_v: 18.5,
        backlash_arcmin: None,
        gear_material: "Full Metal Gear",
        case_mm: [35.6, 50.6, 35.5],
    },
    resistance_ohm: Some(rx28::RESISTANCE),
    torque_constant_nm_per_a: Some(rx28::TORQUE_CONSTANT),
    motor_constants_source: Some("docs/reference/grl.md §2.1 (GRL's DynamixelSpecs.h)"),
    motor_source: MotorSource::Given(DcMotor::RX28),
    gearbox: "RX-28",
    figure_notes: None,
    loop_gains: None,
};

/// The MX-28 (MX-28T/R/AT/AR) with its Protocol 1.0 firmware: model number
/// 29 (30 after a recovery to Protocol 2.0).
pub const MX28: ServoModel = ServoModel {
    name: "MX-28",
    protocol: ServoProtocol::V1,
    model_number: 29,
    encoding: encoding::MX28,
    source: MX28_PAGE,
    datasheet: Datasheet {
        rated_voltage_v: 12.0,
        stall_torque_nm: 2.5,
        stall_current_a: 1.4,
        no_load_speed_rpm: 55.0,
        gear_ratio: 193.0,
        max_voltage_v: 14.8,
        backlash_arcmin: Some(20.0),
        gear_material: "Full Metal Gear",
        case_mm: [35.6, 50.6, 35.5],
    },
    resistance_ohm: None,
    torque_constant_nm_per_a: None,
    motor_constants_source: None,
    motor_source: MotorSource::Datasheet,
    gearbox: "MX-28",
    figure_notes: None,
    loop_gains: None,
};

/// The XM430-W350 (-T/-R): Protocol 2.0, model number 1020.
pub const XM430_W350: ServoModel = ServoModel {
    name: "XM430-W350",
    protocol: ServoProtocol::V2,
    model_number: 1020,
    encoding: encoding::X_SERIES,
    source: XM430_W350_PAGE,
    datasheet: Datasheet {
        rated_voltage_v: 12.0,
        stall_torque_nm: 4.1,
        stall_current_a: 2.3,
        no_load_speed_rpm: 46.0,
        gear_ratio: 353.5,
        max_voltage_v: 14.8,
        backlash_arcmin: Some(15.0),
        gear_material: "Full Metal Gear",
        case_mm: [28.5, 46.5, 34.0],
    },
    resistance_ohm: None,
    torque_constant_nm_per_a: None,
    motor_constants_source: None,
    motor_source: MotorSource::Datasheet,
    gearbox: "XM430-W350",
    figure_notes: None,
    loop_gains: None,
};

/// The XL430-W250-T: Protocol 2.0, model number 1060.
pub const XL430_W250: ServoModel = ServoModel {
    name: "XL430-W250",
    protocol: ServoProtocol::V2,
    model_number: 1060,
    encoding: encoding::X_SERIES,
    source: XL430_W250_PAGE,
    datasheet: Datasheet {
        rated_voltage_v: 11.1,
        stall_torque_nm: 1.4,
        stall_current_a: 1.3,
        no_load_speed_rpm: 57.0,
        gear_ratio: 258.5,
        max_voltage_v: 12.0,
        backlash_arcmin: None,
        gear_material: "Engineering Plastic",
        case_mm: [28.5, 46.5, 34.0],
    },
    resistance_ohm: None,
    torque_constant_nm_per_a: None,
    motor_constants_source: None,
    motor_source: MotorSource::Datasheet,
    gearbox: "XL430-W250",
    figure_notes: None,
    loop_gains: None,
};

/// The XL330-M288-T: Protocol 2.0, model number 1200.
pub const XL330_M288: ServoModel = ServoModel {
    name: "XL330-M288",
    protocol: ServoProtocol::V2,
    model_number: 1200,
    encoding: encoding::X_SERIES,
    source: XL330_M288_PAGE,
    datasheet: Datasheet {
        rated_voltage_v: 5.0,
        stall_torque_nm: 0.52,
        stall_current_a: 1.47,
        no_load_speed_rpm: 103.0,
        gear_ratio: 288.4,
        max_voltage_v: 6.0,
        backlash_arcmin: None,
        gear_material: "Engineering Plastic",
        case_mm: [20.0, 34.0, 26.0],
    },
    resistance_ohm: None,
    torque_constant_nm_per_a: None,
    motor_constants_source: None,
    motor_source: MotorSource::Datasheet,
    gearbox: "XL330-M288",
    figure_notes: None,
    loop_gains: None,
};

/// Every servo model pada knows. New models go at the end: a robot
/// built from files names its servo by its index here.
pub static SERVOS: [ServoModel; 8] = [RX28, MX28, XM430_W350, XL430_W250, XL330_M288, STS3215, STS3215_C044, STS3215_C046];

/// The names of [`SERVOS`], in order.
pub static SERVO_NAMES: [&str; 8] = [
    RX28.name,
    MX28.name,
    XM430_W350.name,
    XL430_W250.name,
    XL330_M288.name,
    STS3215.name,
    STS3215_C044.name,
    STS3215_C046.name,
];

/// The servo model called `name` (ASCII case-insensitive); an unknown name's
/// error lists the valid ones.
pub fn servo(name: &str) -> Result<&'static ServoModel, UnknownName<'_>> {
    SERVOS
        .iter()
        .find(|s| s.name.eq_ignore_ascii_case(name.trim()))
        .ok_or(UnknownName {
            kind: "servo model",
            name,
            valid: &SERVO_NAMES,
        })
}

/// The servo model whose control table reads `model_number` (Model Number,
/// address 0; a Feetech servo's at address 3), if pada knows it. The
/// STS3215's gear variants read the same number (777): this gives the
/// first, the C001.
pub fn servo_by_model_number(model_number: u16) -> Option<&'static ServoModel> {
    SERVOS.iter().find(|s| s.model_number == model_number)
}
