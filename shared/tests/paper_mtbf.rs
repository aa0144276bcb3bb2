//! The paper's MTBF of LEO (Section IV: T_m from the commanded action,
//! linear in the voltage) checked against a hand calculation.
//!
//! Uniform random actions over LEO's 7 levels {−10.7, …, 0, …, +10.7} V at
//! 30 Hz, one gearbox, the first 1200 actions:
//! - 0 V carries no sign, so 6/7 of the actions are signed and a sign
//!   flips between two signed ones with probability 1/2: about
//!   1200 · 6/7 · 1/2 ≈ 514 re-engagements;
//! - each at T_m = |V| · 0.1669 N·m/V (the RX-28's stall torque per volt,
//!   η·G·k/R), |V| uniform over {3.57, 7.13, 10.7} V;
//! - MTBF = 1200 · T / (514 · mean damage per re-engagement).
//!
//! The three stall torques one may take give 250–770 s, against the
//! paper's 362 s for SARSA(λ).

use pada_core::fatigue::{FatigueCounter, FatigueModel, GearboxParams, PAPER_WINDOW_STEPS};
use pada_core::robot::leo::{commanded_gear_torque, ACTION_VOLTAGE_LIMIT, CONTROL_PERIOD_US, SPEC};
use rand_core::{RngCore, SeedableRng};

#[test]
fn random_leo_actions_give_the_hand_calculated_mtbf() {
    let period = CONTROL_PERIOD_US as f64 * 1e-6;
    let level = |k: u32| -ACTION_VOLTAGE_LIMIT + k as f32 * ACTION_VOLTAGE_LIMIT / 3.0;
    let model = FatigueModel::new(&GearboxParams::TABLE_I).unwrap();
    let mean_damage =
        (1..=3).map(|k| model.damage(commanded_gear_torque(level(3 + k)) as f64)).sum::<f64>() / 3.0;
    let expected_reengagements = 1200.0 * 6.0 / 7.0 / 2.0;
    let expected_mtbf = 1200.0 * period / (expected_reengagements * mean_damage);
    assert!((250.0..800.0).contains(&expected_mtbf), "hand calculation {expected_mtbf} s");
    assert!((commanded_gear_torque(10.7) - 1.786).abs() < 0.01);
    assert_eq!(SPEC.paper_gear_torque(0, -5.0), commanded_gear_torque(-5.0));

    let mut mtbfs = Vec::new();
    for seed in 0..20 {
        let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
        let mut c = FatigueCounter::<1>::new(GearboxParams::TABLE_I, period, Some(PAPER_WINDOW_STEPS)).unwrap();
        for _ in 0..PAPER_WINDOW_STEPS {
            let k = rng.next_u32() % 7;
            c.update(&[commanded_gear_torque(level(k))]).unwrap();
        }
        let n = c.joints()[0].window_reengagements().unwrap() as f64;
        assert!((n - expected_reengagements).abs() < 60.0, "seed {seed}: {n} re-engagements");
        mtbfs.push(c.robot_windowed_mtbf_s().unwrap());
    }
    let mean = mtbfs.iter().sum::<f64>() / mtbfs.len() as f64;
    assert!(
        (mean / expected_mtbf - 1.0).abs() < 0.1,
        "counted {mean:.0} s against the hand calculation's {expected_mtbf:.0} s"
    );
}

