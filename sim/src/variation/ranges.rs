//! The ranges pada states for its own pendulums (a robot of files states
//! its own in `robot.toml`'s `[plant]`). No datasheet of the pendulum's
//! motor lies in docs/reference, so every range here is a guess, sized
//! like the published tolerances of the servos that do have figures
//! (docs/reference/servos.md): the one servo measured against its
//! datasheet model, the STS3215, has a torque constant 0.89 times the
//! model's and twice the play its datasheet gives.

use super::{PlantRanges, Span};

/// The physical pendulum's (GRL's constants, docs/reference/grl.md §4):
///
/// | parameter | range | why |
/// |---|---|---|
/// | mass | 0.9–1.1 | guess: a disc and its weight, ±10 % |
/// | motor_constant | 0.85–1.05 | guess, after the STS3215's 0.89 (servos.md) |
/// | friction_nm | 0–0.002 N·m | guess: up to a tenth of gravity's moment m·g·l = 0.023 N·m |
/// | backlash_rad | 0–0.0175 rad | guess: up to 1°, the STS3215's measured play (servos.md) |
/// | delay_periods | 0–1 | guess: a command a period late (a serial link's latency) |
/// | noise_rad | 0–0.0015 rad | guess: one count of a 4096-count encoder |
pub fn physical_pendulum_ranges() -> PlantRanges {
    PlantRanges {
        mass: Span { lo: 0.9, hi: 1.1 },
        motor_constant: Span { lo: 0.85, hi: 1.05 },
        friction_nm: Span { lo: 0.0, hi: 0.002 },
        backlash_rad: Span { lo: 0.0, hi: 0.0175 },
        delay_periods: Span { lo: 0.0, hi: 1.0 },
        noise_rad: Span { lo: 0.0, hi: 0.0015 },
    }
}

/// The simulated pendulum's (Section VII's 2 kg at 0.2 m): the physical
/// one's guesses, friction scaled to its gravity moment (3.9 N·m).
pub fn simulated_pendulum_ranges() -> PlantRanges {
    PlantRanges { friction_nm: Span { lo: 0.0, hi: 0.4 }, ..physical_pendulum_ranges() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stated_ranges_pass_the_checks_of_a_robot_file() {
        for r in [physical_pendulum_ranges(), simulated_pendulum_ranges()] {
            assert_eq!(PlantRanges::MODEL.with_arg(&r.to_arg()).unwrap(), r);
        }
    }
}
