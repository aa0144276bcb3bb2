//! The gearboxes: each servo model's last gear, with the parameters of
//! Eqs. 3–7 ([`GearboxParams`]) and the source of each.
//!
//! Table I is the RX-28's and stays the only measured entry. Every other
//! entry is an estimate ([`Gearbox::estimate`]) until someone measures its
//! last gear; `pada mtbf` and `pada.Fatigue` say so in every report that
//! uses one. The estimates follow stated rules, never a wanted MTBF:
//!
//! - **geometry** (d_w, b, m_n): no ROBOTIS page, spare-part list or
//!   teardown found gives the last gear's module, width or teeth. The last
//!   gear is assumed geometrically similar to Table I's, scaled with the
//!   case width (RX-28 35.6 mm; XM430/XL430 28.5 mm → ×0.8006; XL330
//!   20.0 mm → ×0.5618), rounded to three significant figures, with the
//!   same 45 teeth (Eq. 7) and so the same Y factors (Eq. 4: Y_Fa and Y_Sa
//!   depend on the tooth count and profile, Y_ε on the contact ratio);
//! - **backlash** θ_bl: the e-Manual's where it gives one (XM430: 15 arcmin),
//!   Table I's 0.01 rad where it gives none (XL430, XL330: "N/A");
//! - **k**: the stiffness of LEO's elastic coupling (Table I). It belongs
//!   to the robot, not to the servo; a robot without a coupling should give
//!   its own drive-train stiffness;
//! - **fatigue constants** σ'_f and d: metal gears keep Table I's (the same
//!   material as the RX-28's last gear assumed). Plastic gears keep Table
//!   I's exponent d = −0.262 (no S-N slope of a servo gear plastic is
//!   published) and take σ'_f such that the curve of Eq. 6 passes through a
//!   published fully-reversed bending fatigue limit of an engineering
//!   plastic: Toray's Amilan CM1017 (nylon 6), 19 MPa at 10⁷ cycles (35 Hz,
//!   23 °C; <https://www.plastics.toray/ja/technical/amilan/tec_006.html>).
//!   Eq. 6 gives σ_ar = σ'_f·(2N_f)^d, so σ'_f = 19·(2·10⁷)^0.262 ≈ 1555 MPa
//!   (Table I's own curve gives 53.8 MPa at 10⁷ cycles). ROBOTIS does not
//!   name the plastic; a polyacetal's limit would differ.

use super::UnknownName;
use crate::fatigue::GearboxParams;

/// The source of each parameter of a [`Gearbox`] (Eqs. 3–7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GearboxSources {
    /// θ_bl (Eq. 3).
    pub theta_bl: &'static str,
    /// k (Eqs. 1–3).
    pub k: &'static str,
    /// d and σ'_f (Eq. 6).
    pub fatigue: &'static str,
    /// d_w, b and m_n (Eq. 4).
    pub geometry: &'static str,
    /// Y_Fa, Y_Sa, Y_ε, Y_β (Eq. 4).
    pub y_factors: &'static str,
    /// The number of teeth (Eq. 7).
    pub teeth: &'static str,
}

/// One gearbox's last gear: the parameters of Eqs. 3–7, their sources,
/// and whether they are an estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gearbox {
    /// Its name: the servo model it belongs to (matched case-insensitively
    /// by [`gearbox`]).
    pub name: &'static str,
    /// The parameters of Eqs. 3–7 (valid: a test validates each entry).
    pub params: GearboxParams,
    /// The source of each parameter.
    pub sources: GearboxSources,
    /// True while the last gear's geometry or material is not measured:
    /// every report that uses it says so.
    pub estimate: bool,
    /// Why the numbers are what they are, in one paragraph.
    pub note: &'static str,
}

/// The paper, as a source.
const TABLE_I: &str = "the paper, Table I";
/// The robot's coupling, as a source.
const COUPLING: &str = "the paper, Table I: LEO's elastic coupling (a property of the robot, not the servo)";
/// The rule for estimated geometry.
const SCALED: &str = "estimate: Table I's scaled with the case width (module docs)";
/// The rule for Y factors and teeth of estimated gears.
const AS_TABLE_I: &str = "estimate: Table I's (same 45-tooth gear assumed)";
/// The rule for plastic gears' fatigue constants.
const PLASTIC: &str = "estimate: d of Table I; sigma'_f through nylon 6's 19 MPa at 1e7 cycles (Toray Amilan CM1017)";

/// The RX-28's last gear: Table I of the paper, measured (not an estimate).
pub const RX28_GEARBOX: Gearbox = Gearbox {
    name: "RX-28",
    params: GearboxParams::TABLE_I,
    sources: GearboxSources {
        theta_bl: TABLE_I,
        k: COUPLING,
        fatigue: TABLE_I,
        geometry: TABLE_I,
        y_factors: TABLE_I,
        teeth: "the paper, Eq. 7 (45 teeth)",
    },
    estimate: false,
    note: "Table I of the paper: the last gear of LEO's RX-28 gearboxes.",
};

/// The MX-28's last gear: Table I's, as an estimate.
pub const MX28_GEARBOX: Gearbox = Gearbox {
    name: "MX-28",
    params: GearboxParams::TABLE_I,
    sources: GearboxSources {
        theta_bl: "estimate: Table I's (the e-Manual gives 20 arcmin = 0.0058 rad for the gear train alone)",
        k: COUPLING,
        fatigue: "estimate: Table I's (same gear material assumed)",
        geometry: "estimate: Table I's (same last gear assumed)",
        y_factors: AS_TABLE_I,
        teeth: AS_TABLE_I,
    },
    estimate: true,
    note: "The MX-28 succeeded the RX-28 in the same case (35.6 x 50.6 x 35.5 mm, \
           the RX-28's frames and horns), with the same 193:1 ratio and full metal \
           gears, so its last gear is taken to be the RX-28's. No source says the \
           part is the same, hence an estimate. Its datasheet backlash (20 arcmin) \
           is less than Table I's 0.01 rad; Table I's is kept because it is what \
           the paper's MTBF was computed with for this gear train.",
};

/// Table I's gear with a model's own backlash `theta_bl_rad`, fatigue
/// coefficient `sigma_f_mpa` and geometry `[b, m_n, d_w]` (mm), the rest
/// Table I's: LEO's coupling k (the robot's, not the servo's), the exponent
/// d, and the Y factors of the same 45-tooth profile. The estimates scale
/// the geometry with the case width (the module docs), to three
/// significant figures.
const fn table_i_with(theta_bl_rad: f64, sigma_f_mpa: f64, geometry: [f64; 3]) -> GearboxParams {
    let [b_mm, m_n_mm, d_w_mm] = geometry;
    GearboxParams { theta_bl_rad, sigma_f_mpa, b_mm, m_n_mm, d_w_mm, ..GearboxParams::TABLE_I }
}

/// σ'_f of the plastic gears: 19 MPa·(2·10⁷)^0.262 (nylon 6, Toray), on
/// Table I's exponent.
const PLASTIC_SIGMA_F_MPA: f64 = 1555.0;

/// The sources of a geometry scaled with the case width.
const fn scaled_sources(theta_bl: &'static str, fatigue: &'static str) -> GearboxSources {
    GearboxSources { theta_bl, k: COUPLING, fatigue, geometry: SCALED, y_factors: AS_TABLE_I, teeth: AS_TABLE_I }
}

/// A plastic X-series gear (an estimate): its case is `$width` mm wide,
/// so its geometry `[b, m_n, d_w]` is Table I's scaled by `$width`/35.6;
/// the e-Manual gives no backlash ("N/A"), so Table I's; σ'_f
/// [`PLASTIC_SIGMA_F_MPA`].
macro_rules! plastic_x_gearbox {
    ($name:literal, width: $width:literal, $geometry:expr) => {
        Gearbox {
            name: $name,
            params: table_i_with(0.01, PLASTIC_SIGMA_F_MPA, $geometry),
            sources: scaled_sources("estimate: Table I's (the e-Manual gives none)", PLASTIC),
            estimate: true,
            note: concat!(
                "Engineering-plastic gears (e-Manual); the plastic is not named. \
           Table I's gear scaled with the case width (",
                $width,
                "/35.6); fatigue \
           curve with Table I's slope through nylon 6's 19 MPa at 1e7 cycles; \
           Table I's backlash."
            ),
        }
    };
}

/// A metal gear scaled with the case width (an estimate): Table I's
/// material, so Table I's σ'_f; its own backlash `theta_bl_rad` (with its
/// source `theta_bl`), geometry `[b, m_n, d_w]` (mm), the source of its
/// fatigue constants `fatigue`, and `note`.
const fn metal_scaled_gearbox(
    name: &'static str,
    theta_bl_rad: f64,
    geometry: [f64; 3],
    [theta_bl, fatigue]: [&'static str; 2],
    note: &'static str,
) -> Gearbox {
    let params = table_i_with(theta_bl_rad, GearboxParams::TABLE_I.sigma_f_mpa, geometry);
    Gearbox { name, params, sources: scaled_sources(theta_bl, fatigue), estimate: true, note }
}

/// The XM430-W350's last gear: an estimate (metal). The e-Manual's
/// backlash, 15 arcmin = 15/60·π/180 rad; 28.5/35.6 of Table I's geometry.
pub const XM430_W350_GEARBOX: Gearbox = metal_scaled_gearbox(
    "XM430-W350",
    0.004363323129985824,
    [3.2, 0.32, 14.8],
    ["e-Manual, XM430-W350: backlash 15 arcmin", "estimate: Table I's (full metal gear; same material assumed)"],
    "Full metal gears (e-Manual). No module, width or tooth count of its \
     last gear is published: Table I's gear scaled with the case width \
     (28.5/35.6), Table I's material, the e-Manual's 15 arcmin backlash.",
);

/// The XL430-W250's last gear: an estimate (engineering plastic).
pub const XL430_W250_GEARBOX: Gearbox = plastic_x_gearbox!("XL430-W250", width: "28.5", [3.2, 0.32, 14.8]);

/// The XL330-M288's last gear: an estimate (engineering plastic).
pub const XL330_M288_GEARBOX: Gearbox = plastic_x_gearbox!("XL330-M288", width: "20.0", [2.25, 0.225, 10.4]);

/// The Feetech STS3215's last gear: an estimate (metal gears, the metal
/// not steel by the one listing that names it). "≤ 0.5°" (Feetech's
/// datasheet as quoted): 0.5·π/180 rad; 24.7/35.6 of Table I's geometry.
pub const STS3215_GEARBOX: Gearbox = metal_scaled_gearbox(
    "STS3215",
    0.008726646259971648,
    [2.78, 0.278, 12.8],
    [
        "Feetech datasheet as quoted (SO-ARM100 issue 134, Robonine): backlash <= 0.5 deg",
        "estimate: Table I's (metal gear; the listing's copper and aluminium may be weaker than the RX-28's steel)",
    ],
    "Metal gears, 1/345 (Feetech's listing: \"metal tooth\"; DFRobot's: copper and \
     aluminium). No module, width or tooth count is published: Table I's gear scaled \
     with the case width (24.7/35.6), Table I's fatigue curve (a copper alloy's would \
     lie lower, so the MTBF is optimistic), the datasheet's 0.5 deg backlash.",
);

/// Every gearbox pada knows.
pub static GEARBOXES: [Gearbox; 6] = [
    RX28_GEARBOX,
    MX28_GEARBOX,
    XM430_W350_GEARBOX,
    XL430_W250_GEARBOX,
    XL330_M288_GEARBOX,
    STS3215_GEARBOX,
];

/// The names of [`GEARBOXES`], in order.
pub static GEARBOX_NAMES: [&str; 6] = [
    RX28_GEARBOX.name,
    MX28_GEARBOX.name,
    XM430_W350_GEARBOX.name,
    XL430_W250_GEARBOX.name,
    XL330_M288_GEARBOX.name,
    STS3215_GEARBOX.name,
];

/// The gearbox called `name` (ASCII case-insensitive, surrounding spaces
/// ignored); an unknown name's error lists the valid ones.
pub fn gearbox(name: &str) -> Result<&'static Gearbox, UnknownName<'_>> {
    GEARBOXES
        .iter()
        .find(|g| g.name.eq_ignore_ascii_case(name.trim()))
        .ok_or(UnknownName {
            kind: "gearbox",
            name,
            valid: &GEARBOX_NAMES,
        })
}
