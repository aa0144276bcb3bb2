//! The two pendulum tasks of Section VII: the simulated inverted pendulum
//! ([`simulated`]) and a model of the physical pendulum of the paper's
//! experiment ([`physical`]), both swung up from hanging down.

pub mod physical;
pub mod simulated;

pub use physical::{PhysicalPendulum, PhysicalPendulumParams, PhysicalPendulumTask};
pub use simulated::{SimulatedPendulum, SimulatedPendulumParams, SimulatedPendulumTask};

/// The angle wrap and the Section VII reward are the physical pendulum's
/// one definition in pada-core (the simulated pendulum's reward is the
/// same, on its torque instead of a voltage).
pub use pada_core::robot::pendulum::{swing_up_reward, wrap_angle};
