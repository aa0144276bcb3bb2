//! The model's switches and step size, and what can go wrong building or
//! stepping it.

use pada_core::rx28::ReducedJoint;

use super::super::constants::*;

/// Switches of the physics, for the sanity checks (all on for LEO).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelOptions {
    /// Physics steps per control period (h = (1/30)/substeps).
    pub substeps: u32,
    /// Rapier solver iterations per physics step.
    pub solver_iterations: usize,
    /// Contact softness: natural frequency (Hz).
    pub contact_frequency: f32,
    /// Contact softness: damping ratio.
    pub contact_damping_ratio: f32,
    /// Floor contacts on.
    pub contacts: bool,
    /// Dry friction of 0.2 N m in every servo joint (§1.5).
    pub dry_friction: bool,
    /// Back-EMF damping of the servos (§2.1). Off = "torque off"
    /// (free-wheeling windings); the armature inertia stays.
    pub back_emf: bool,
    /// Soft joint stops (§1.5).
    pub joint_stops: bool,
    /// Dampers of the joint stops (§1.5).
    pub stop_damping: bool,
    /// The boom's extra vertical force on the torso (§1.4).
    pub boom_force: bool,
    /// Gravity on.
    pub gravity: bool,
    /// Correct the servos' response lag of a coarse step (see
    /// `LeoModel::correct_motor_lag`); on by default.
    pub motor_lag_correction: bool,
    /// Weld the torso to the world in its starting pose instead of the
    /// root joint (for the energy and joint-limit checks: the legs and
    /// the arm become a tree of pendulums).
    pub fixed_torso: bool,
}

impl Default for ModelOptions {
    fn default() -> Self {
        Self {
            substeps: SUBSTEPS,
            solver_iterations: SOLVER_ITERATIONS,
            contact_frequency: CONTACT_NATURAL_FREQUENCY,
            contact_damping_ratio: CONTACT_DAMPING_RATIO,
            contacts: true,
            dry_friction: true,
            back_emf: true,
            joint_stops: true,
            stop_damping: true,
            boom_force: true,
            gravity: true,
            fixed_torso: false,
            motor_lag_correction: true,
        }
    }
}

/// Why a model could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelError {
    /// An option is out of range (name and reason).
    InvalidOption(&'static str, &'static str),
    /// The starting pose has a non-finite pitch.
    InvalidPose,
    /// Rapier refused a joint (should not happen with the fixed topology).
    Topology,
}

impl core::fmt::Display for ModelError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            ModelError::InvalidOption(name, why) => {
                write!(f, "invalid LEO model option `{name}`: {why}")
            }
            ModelError::InvalidPose => write!(f, "the starting pose has a non-finite angle"),
            ModelError::Topology => write!(f, "rapier refused LEO's joint tree"),
        }
    }
}

impl std::error::Error for ModelError {}

impl ModelOptions {
    /// Checks the ranges: 1 ≤ substeps ≤ 1000, 1 ≤ iterations ≤ 100,
    /// finite positive contact frequency, finite non-negative damping ratio.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(1..=1000).contains(&self.substeps) {
            return Err(ModelError::InvalidOption("substeps", "must be in 1..=1000"));
        }
        if !(1..=100).contains(&self.solver_iterations) {
            return Err(ModelError::InvalidOption(
                "solver_iterations",
                "must be in 1..=100",
            ));
        }
        if !(self.contact_frequency.is_finite() && self.contact_frequency > 0.0) {
            return Err(ModelError::InvalidOption(
                "contact_frequency",
                "must be finite and > 0",
            ));
        }
        if !(self.contact_damping_ratio.is_finite() && self.contact_damping_ratio >= 0.0) {
            return Err(ModelError::InvalidOption(
                "contact_damping_ratio",
                "must be finite and >= 0",
            ));
        }
        Ok(())
    }

    /// The physics step h in seconds.
    pub fn dt(&self) -> f32 {
        CONTROL_PERIOD / self.substeps as f32
    }
}

/// What went wrong when the simulation blew up (bad input).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BlowUp {
    /// A coordinate or velocity is NaN or infinite.
    NonFinite,
    /// A body left the workspace ([`BLOWUP_DISTANCE`]).
    FarAway,
    /// A joint turns faster than [`BLOWUP_JOINT_RATE`].
    JointRate,
}

/// The servo of §2.1 in rigid-armature form, with the options' switches.
pub(super) fn options_servo(options: &ModelOptions) -> ReducedJoint {
    let mut servo = SERVO.reduced();
    if !options.back_emf {
        servo.damping = 0.0;
    }
    if !options.dry_friction {
        servo.dry_friction = 0.0;
    }
    servo
}
