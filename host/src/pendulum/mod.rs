//! The two pendulum tasks of Section VII: the simulated inverted pendulum
//! ([`simulated`]) and a model of the physical pendulum of the paper's
//! experiment ([`physical`]), both swung up from hanging down.

pub mod physical;
pub mod simulated;

pub use physical::{PhysicalPendulum, PhysicalPendulumParams, PhysicalPendulumTask};
pub use simulated::{SimulatedPendulum, SimulatedPendulumParams, SimulatedPendulumTask};

use std::f64::consts::PI;

/// An angle wrapped to (−π, π].
pub fn wrap_angle(theta: f64) -> f64 {
    let w = theta.rem_euclid(2.0 * PI); // [0, 2π)
    if w > PI {
        w - 2.0 * PI
    } else {
        w
    }
}

/// The Section VII reward on a state and the applied action:
/// `−5θ² − 0.1θ̇² − a²` (θ wrapped, 0 upright).
pub fn swing_up_reward(theta: f64, omega: f64, action: f64) -> f64 {
    -5.0 * theta * theta - 0.1 * omega * omega - action * action
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_angle_range() {
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-0.1) + 0.1).abs() < 1e-15);
        assert!((wrap_angle(4.0 * PI + 0.25) - 0.25).abs() < 1e-12);
        for k in -100..100 {
            let w = wrap_angle(k as f64 * 0.37);
            assert!(w > -PI && w <= PI, "{w}");
        }
    }

    #[test]
    fn reward_is_the_papers() {
        assert_eq!(swing_up_reward(0.0, 0.0, 0.0), 0.0);
        assert!((swing_up_reward(PI, 0.0, 0.0) + 5.0 * PI * PI).abs() < 1e-12);
        assert!((swing_up_reward(0.1, 2.0, 1.5) - (-0.05 - 0.4 - 2.25)).abs() < 1e-12);
    }
}
