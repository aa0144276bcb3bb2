//! `robot.toml` as serde reads it: every table and field, with its unit in
//! its name. docs/your-robot.md describes each once, in one table; a test
//! checks that every field named here is in it.
//!
//! Values that a later check may refuse are [`Spanned`], so that the error
//! points at their line.

use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

/// The whole file.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotToml {
    /// `[robot]`: name, body, timing, supply.
    pub robot: RobotSection,
    /// `[[joint]]`: one per moving joint of the URDF, in the robot's joint
    /// order.
    #[serde(rename = "joint")]
    pub joints: Vec<Spanned<JointSection>>,
    /// `[point.NAME]`: points of links that signals and rewards name.
    #[serde(default, rename = "point")]
    pub points: BTreeMap<String, Spanned<PointSection>>,
    /// `[[observe]]`: the observation, one signal per dimension.
    #[serde(rename = "observe")]
    pub observe: Vec<Spanned<ObserveSection>>,
    /// `[action]`: the voltage levels of each learned joint.
    pub action: Spanned<ActionSection>,
    /// `[learning]`: SARSA(λ)'s parameters.
    #[serde(default)]
    pub learning: LearningSection,
    /// `[[reward]]`: the reward's terms.
    #[serde(default, rename = "reward")]
    pub rewards: Vec<Spanned<RewardSection>>,
    /// `[[end]]`: limits that end an episode.
    #[serde(default, rename = "end")]
    pub ends: Vec<Spanned<EndSection>>,
    /// `[reset]`: how the robot is brought back between episodes.
    #[serde(default)]
    pub reset: ResetSection,
    /// `[simulation]`: how the host simulates the body.
    #[serde(default)]
    pub simulation: SimulationSection,
    /// `[plant]`: how far the real robot may differ from this model.
    #[serde(default)]
    pub plant: PlantSection,
}

/// `[robot]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotSection {
    /// The robot's name: lowercase letters, digits and `-`, at most 32
    /// bytes.
    pub name: Spanned<String>,
    /// The URDF, relative to the `robot.toml`.
    pub urdf: Spanned<String>,
    /// The control period \[ms\].
    pub period_ms: Spanned<f64>,
    /// The episode's length \[s\] (a time limit, not absorbing).
    pub episode_s: Spanned<f64>,
    /// A greedy test episode after this many learning episodes.
    #[serde(default = "default_test_interval")]
    pub test_interval: Spanned<u32>,
    /// The servos' supply, assumed until they report it \[V\].
    pub supply_v: Spanned<f64>,
    /// Learned and held voltages are clipped to ±this \[V\].
    pub voltage_limit_v: Spanned<f64>,
    /// `exact` or `claim`: the learner's table; by default exact if it
    /// fits an F405, else a claim table.
    #[serde(default)]
    pub table: Option<Spanned<String>>,
    /// 16-bit weights hold ±2^(shift−1) (the chips' claim tables).
    #[serde(default = "default_half_shift")]
    pub half_shift: Spanned<u8>,
}

fn default_test_interval() -> Spanned<u32> {
    Spanned::new(0..0, 10)
}

fn default_half_shift() -> Spanned<u8> {
    Spanned::new(0..0, 12)
}

/// `[[joint]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointSection {
    /// The URDF joint's name (a `revolute` or `continuous` joint).
    pub urdf: Spanned<String>,
    /// The servo model (pada's table: `pada servos --list`, docs/reference/servos.md).
    pub servo: Spanned<String>,
    /// The servo's bus ID, 0–252.
    pub id: Spanned<u8>,
    /// The servo's position count at joint angle 0, within its encoder's
    /// counts.
    pub zero_count: Spanned<u16>,
    /// +1 if the joint angle grows with the servo's counts, −1 if not.
    #[serde(default = "default_sign")]
    pub sign: Spanned<i8>,
    /// Past these angles the robot faults, torque off \[rad\]; within
    /// the URDF joint's limits.
    #[serde(default)]
    pub soft_limit_rad: Option<Spanned<[f64; 2]>>,
    /// The angle of the start pose \[rad\], inside the soft limits.
    #[serde(default = "default_start")]
    pub start_rad: Spanned<f64>,
    /// Whether the learner drives it (a motor dimension); else it is held.
    #[serde(default = "default_true")]
    pub learned: bool,
    /// A learned joint's own voltage levels \[V\], increasing (default:
    /// `[action]`'s).
    #[serde(default)]
    pub levels_v: Option<Spanned<Vec<f64>>>,
    /// A held joint's P gain \[V/rad\].
    #[serde(default)]
    pub hold_gain_v_per_rad: Option<Spanned<f64>>,
    /// A held joint's set point \[rad\] (default: its start angle).
    #[serde(default)]
    pub hold_target_rad: Option<f64>,
    /// Whether its gearbox's wear counts in the robot's MTBF (default: if
    /// learned). The counted joints follow each other in joint order.
    #[serde(default)]
    pub counted: Option<bool>,
}

fn default_sign() -> Spanned<i8> {
    Spanned::new(0..0, 1)
}

fn default_start() -> Spanned<f64> {
    Spanned::new(0..0, 0.0)
}

fn default_true() -> bool {
    true
}

/// `[point.NAME]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSection {
    /// The URDF link it is on.
    pub link: Spanned<String>,
    /// Where on the link, in its frame \[m\].
    #[serde(default)]
    pub offset_m: [f64; 3],
}

/// `[[observe]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserveSection {
    /// The signal: `JOINT.angle`, `JOINT.rate`, `POINT.x|y|z`,
    /// `POINT.x_rate|y_rate|z_rate`.
    pub signal: Spanned<String>,
    /// The range the tile coder covers (values outside are clamped).
    pub range: Spanned<[f64; 2]>,
    /// The width of one tile, in the signal's unit.
    pub tile: Spanned<f64>,
    /// Whether the range is one turn of an angle that wraps.
    #[serde(default)]
    pub wrap: bool,
}

/// `[action]`: either `levels_v` or `uniform_v`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActionSection {
    /// The voltage levels of each learned joint \[V\], increasing.
    #[serde(default)]
    pub levels_v: Option<Vec<f64>>,
    /// `count` levels evenly from `min` to `max` \[V\].
    #[serde(default)]
    pub uniform_v: Option<UniformLevels>,
    /// Generalise over actions with tiles of this width \[V\].
    #[serde(default)]
    pub tile_v: Option<f64>,
}

/// `uniform_v = { min = …, max = …, count = … }`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UniformLevels {
    /// The lowest level \[V\].
    pub min: f64,
    /// The highest level \[V\].
    pub max: f64,
    /// How many.
    pub count: u8,
}

/// `[learning]`: SARSA(λ), Section VII's values by default.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearningSection {
    /// α.
    #[serde(default = "d_alpha")]
    pub alpha: Spanned<f64>,
    /// γ per step.
    #[serde(default = "d_gamma")]
    pub gamma: Spanned<f64>,
    /// λ per step.
    #[serde(default = "d_lambda")]
    pub lambda: Spanned<f64>,
    /// ε.
    #[serde(default = "d_epsilon")]
    pub epsilon: Spanned<f64>,
    /// Traces below this are dropped.
    #[serde(default = "d_threshold")]
    pub trace_threshold: Spanned<f64>,
    /// The initial weights, uniform in \[min, max\].
    #[serde(default = "d_init")]
    pub initial_weights: Spanned<[f64; 2]>,
}

impl Default for LearningSection {
    fn default() -> Self {
        LearningSection {
            alpha: d_alpha(),
            gamma: d_gamma(),
            lambda: d_lambda(),
            epsilon: d_epsilon(),
            trace_threshold: d_threshold(),
            initial_weights: d_init(),
        }
    }
}

fn d_alpha() -> Spanned<f64> {
    Spanned::new(0..0, 0.2)
}
fn d_gamma() -> Spanned<f64> {
    Spanned::new(0..0, 0.99)
}
fn d_lambda() -> Spanned<f64> {
    Spanned::new(0..0, 0.92)
}
fn d_epsilon() -> Spanned<f64> {
    Spanned::new(0..0, 0.05)
}
fn d_threshold() -> Spanned<f64> {
    Spanned::new(0..0, 0.01)
}
fn d_init() -> Spanned<[f64; 2]> {
    Spanned::new(0..0, [0.0, 1.0])
}

/// `[[reward]]`: one term, named by `term`, with the fields it takes:
///
/// | `term` | fields | value |
/// |---|---|---|
/// | `quadratic` | `signal`, `target` (0), `weight`, `wrap` (false) | `weight · (signal − target)²` |
/// | `distance` | `point`, `target_m`, `weight` | `weight · ‖point − target_m‖` |
/// | `distance_squared` | `point`, `target_m`, `weight` | `weight · ‖point − target_m‖²` |
/// | `progress` | `point`, `axis`, `weight` | `weight · Δ(point's coordinate)` per step |
/// | `action` | `weight` | `weight · Σ u²` over the learned joints |
/// | `action_change` | `weight` | `weight · Σ (u − u_prev)²` |
/// | `constant` | `value` | `value` |
///
/// (A flat table rather than a serde enum: serde's tagged enums lose the
/// positions errors point at.)
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RewardSection {
    /// Which term.
    pub term: Spanned<String>,
    /// The signal (`quadratic`).
    #[serde(default)]
    pub signal: Option<Spanned<String>>,
    /// The target value (`quadratic`).
    #[serde(default)]
    pub target: Option<f64>,
    /// The difference is an angle's, taken in (−π, π] (`quadratic`).
    #[serde(default)]
    pub wrap: Option<bool>,
    /// The point (`distance`, `distance_squared`, `progress`).
    #[serde(default)]
    pub point: Option<Spanned<String>>,
    /// The target point \[m\] (`distance`, `distance_squared`).
    #[serde(default)]
    pub target_m: Option<[f64; 3]>,
    /// `x`, `y` or `z` (`progress`).
    #[serde(default)]
    pub axis: Option<Spanned<String>>,
    /// The weight (every term but `constant`).
    #[serde(default)]
    pub weight: Option<f64>,
    /// The value (`constant`).
    #[serde(default)]
    pub value: Option<f64>,
}

/// `[[end]]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EndSection {
    /// The signal watched.
    pub signal: Spanned<String>,
    /// The allowed range; leaving it ends the episode.
    pub range: Spanned<[f64; 2]>,
    /// The reward of leaving it.
    #[serde(default)]
    pub reward: f64,
}

/// `[reset]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResetSection {
    /// The P gain towards the start pose \[V/rad\].
    #[serde(default = "d_reset_gain")]
    pub gain_v_per_rad: f64,
    /// Close enough to the start \[rad\].
    #[serde(default = "d_tolerance")]
    pub tolerance_rad: f64,
    /// Still enough \[rad/s\].
    #[serde(default = "d_still")]
    pub still_rad_s: f64,
    /// For this long \[s\].
    #[serde(default = "d_settle")]
    pub settle_s: f64,
    /// The longest wait \[s\].
    #[serde(default = "d_timeout")]
    pub timeout_s: f64,
}

impl Default for ResetSection {
    fn default() -> Self {
        ResetSection {
            gain_v_per_rad: d_reset_gain(),
            tolerance_rad: d_tolerance(),
            still_rad_s: d_still(),
            settle_s: d_settle(),
            timeout_s: d_timeout(),
        }
    }
}

fn d_reset_gain() -> f64 {
    5.0
}
fn d_tolerance() -> f64 {
    0.05
}
fn d_still() -> f64 {
    0.2
}
fn d_settle() -> f64 {
    0.5
}
fn d_timeout() -> f64 {
    10.0
}

/// `[simulation]`: how finely rapier steps the body (the defaults were
/// chosen by measuring the error against a fine reference: docs/your-robot.md).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSection {
    /// Physics steps per control period.
    #[serde(default = "d_substeps")]
    pub substeps: Spanned<u32>,
    /// rapier's solver iterations per physics step (each integrates a
    /// fraction of the step).
    #[serde(default = "d_iterations")]
    pub solver_iterations: Spanned<u32>,
}

impl Default for SimulationSection {
    fn default() -> Self {
        SimulationSection { substeps: d_substeps(), solver_iterations: d_iterations() }
    }
}

/// One physics step a period: a servo-driven arm is damped within a
/// period (its back-EMF and rotor inertia are implicit in rapier), and on
/// the example arm one step with two solver iterations stays within
/// 0.8 mm of a 64-step reference at the tip (`pada-sim`'s example
/// `urdf_step_accuracy`; docs/your-robot.md).
fn d_substeps() -> Spanned<u32> {
    Spanned::new(0..0, 1)
}

fn d_iterations() -> Spanned<u32> {
    Spanned::new(0..0, 2)
}

/// `[plant]`: the ranges within which the real robot may differ from its
/// model, each `[low, high]` (`crate::plant`; docs/your-robot.md, "A
/// robot that is not its model"). Absent: the model's value.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlantSection {
    /// Factor on every link's mass and inertia.
    pub mass: Option<Spanned<[f64; 2]>>,
    /// Factor on each motor's torque constant.
    pub motor_constant: Option<Spanned<[f64; 2]>>,
    /// Dry friction added at each joint \[N·m\].
    pub friction_nm: Option<Spanned<[f64; 2]>>,
    /// Play between each joint's sensor and its link \[rad\].
    pub backlash_rad: Option<Spanned<[f64; 2]>>,
    /// Control periods each command arrives late.
    pub delay_periods: Option<Spanned<[f64; 2]>>,
    /// Noise on each angle reading, standard deviation \[rad\].
    pub noise_rad: Option<Spanned<[f64; 2]>>,
}
