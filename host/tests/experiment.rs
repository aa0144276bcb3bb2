//! The experiment runner on short trials: reproducibility, PADA Δ = 1 as
//! SARSA(λ), learning that improves, and the fatigue window.

use pada::experiment::algo::{policy_kind, Algo};
use pada::experiment::task::Task;
use pada::experiment::{run_trials, RunConfig, TrialResult};
use pada::pendulum::{PhysicalPendulumTask, SimulatedPendulumTask};
use pada_core::fatigue::PAPER_WINDOW_STEPS;
use pada_core::policy::PolicyKind;

fn run<T: Task>(
    task: &T,
    policy: PolicyKind,
    seconds: f64,
    trials: u32,
    seed: u64,
) -> Vec<TrialResult> {
    let cfg = RunConfig {
        policy,
        switch_at_s: None,
        mtbf_budget_s: None,
        seconds,
        trials,
        seed,
    };
    run_trials(task, &cfg, &|_| {}).expect("trials run")
}

#[test]
fn a_seed_reproduces_a_run_bit_for_bit() {
    let task = SimulatedPendulumTask::default();
    let pada = PolicyKind::Pada { delta: 0.5 };
    let a = run(&task, pada, 90.0, 2, 7);
    let b = run(&task, pada, 90.0, 2, 7);
    assert_eq!(a, b);
    let c = run(&task, pada, 90.0, 2, 8);
    assert_ne!(a, c, "another master seed gives another run");
    assert_ne!(a[0].seed, a[1].seed);
}

#[test]
fn pada_with_delta_one_is_sarsa_bit_for_bit() {
    // With Δ = 1 every torque is within reach of every other, so PADA's
    // candidates are SARSA's and, with the same seed, so is everything else.
    let task = SimulatedPendulumTask::default();
    let sarsa = run(&task, PolicyKind::Sarsa, 90.0, 2, 3);
    let pada = run(&task, PolicyKind::Pada { delta: 1.0 }, 90.0, 2, 3);
    assert_eq!(sarsa, pada);
    // Δ = 0.5 does restrict.
    assert_ne!(
        sarsa,
        run(&task, PolicyKind::Pada { delta: 0.5 }, 90.0, 2, 3)
    );
}

#[test]
fn learning_improves_the_test_return() {
    let task = SimulatedPendulumTask::default();
    let results = run(&task, PolicyKind::Sarsa, 450.0, 2, 1);
    for r in &results {
        let first = r.curve[0].test_return;
        assert!(
            r.end_performance > first + 200.0,
            "trial {}: first {first}, end {}",
            r.trial,
            r.end_performance
        );
        // Test runs every 10 episodes of 3 s, plus one before learning.
        assert_eq!(r.curve.len(), 1 + 150 / 10);
        assert_eq!(r.curve[1].learning_time_s, 30.0);
        assert_eq!(r.learning_steps, 9000);
        assert_eq!(r.test_steps, 16 * 60);
        assert!(r.rise_time_s >= 0.0 && r.rise_time_s <= 450.0);
        assert_eq!(r.saturations, 0);
        assert_eq!(r.trace_drops, 0);
    }
}

#[test]
fn the_mtbf_counts_the_first_1200_learning_actions() {
    let task = SimulatedPendulumTask::default();
    // 1200 actions at 20 Hz = 60 s; learning longer must not change the MTBF.
    let short = run(&task, PolicyKind::Sarsa, 60.0, 1, 5);
    let long = run(&task, PolicyKind::Sarsa, 120.0, 1, 5);
    assert_eq!(short[0].mtbf_s, long[0].mtbf_s);
    assert_eq!(short[0].window_reengagements, long[0].window_reengagements);
    assert!(
        short[0].window_reengagements > 0
            && short[0].window_reengagements < PAPER_WINDOW_STEPS as u64
    );
    // Each re-engagement at 1.5 N·m costs the same damage, so the MTBF is
    // 60 s over that many times one event's damage (Eqs. 3–7).
    let per_event = pada_core::fatigue::GearboxParams::TABLE_I.damage_per_reengagement(1.5);
    let expected = 60.0 / (short[0].window_reengagements as f64 * per_event);
    assert!(
        (short[0].mtbf_s / expected - 1.0).abs() < 1e-6,
        "{} vs {expected}",
        short[0].mtbf_s
    );
}

#[test]
fn pada_and_lowpass_reengage_less_harshly_than_sarsa() {
    let task = SimulatedPendulumTask::default();
    let mean = |p| {
        let r = run(&task, p, 60.0, 4, 11);
        r.iter().map(|t| t.mtbf_s).sum::<f64>() / r.len() as f64
    };
    let sarsa = mean(PolicyKind::Sarsa);
    let pada = mean(policy_kind(Algo::Pada, None, Some(0.5)).unwrap());
    let lowpass = mean(policy_kind(Algo::LowPass, Some(0.5), None).unwrap());
    assert!(pada > 1.5 * sarsa, "PADA {pada} vs SARSA {sarsa}");
    assert!(lowpass > 5.0 * sarsa, "low-pass {lowpass} vs SARSA {sarsa}");
}

#[test]
fn the_physical_pendulum_runs_with_its_own_timing() {
    let task = PhysicalPendulumTask::default();
    let r = run(&task, PolicyKind::Sarsa, 36.0, 1, 2);
    // 36 s at 0.03 s = 1200 steps = 12 episodes of 100 steps.
    assert_eq!(r[0].learning_steps, 1200);
    // Torques of at most 3 V × K/R: the MTBF is in the paper's 10⁷–10⁸ s range.
    assert!(r[0].mtbf_s > 1e7 && r[0].mtbf_s < 1e9, "{}", r[0].mtbf_s);
}

#[test]
fn switching_to_sarsa_changes_the_run_only_after_the_switch() {
    let task = SimulatedPendulumTask::default();
    let pada = PolicyKind::Pada { delta: 0.5 };
    let plain = run(&task, pada, 120.0, 1, 4);
    let cfg = RunConfig {
        policy: pada,
        switch_at_s: Some(60.0),
        mtbf_budget_s: None,
        seconds: 120.0,
        trials: 1,
        seed: 4,
    };
    let switched = run_trials(&task, &cfg, &|_| {}).unwrap();
    // Same first 60 s: the window MTBF (first 1200 actions = 60 s) agrees …
    assert_eq!(plain[0].mtbf_s, switched[0].mtbf_s);
    // … and the test runs up to 60 s too; afterwards the runs part.
    let upto = plain[0]
        .curve
        .iter()
        .filter(|p| p.learning_time_s <= 60.0)
        .count();
    assert_eq!(plain[0].curve[..upto], switched[0].curve[..upto]);
    assert_ne!(plain[0].curve, switched[0].curve);
}

#[test]
fn a_governed_run_reproduces_bit_for_bit_and_its_governor_moves() {
    let task = SimulatedPendulumTask::default();
    let cfg = |seed| RunConfig {
        policy: PolicyKind::LowPass { alpha: 0.834 },
        switch_at_s: None,
        mtbf_budget_s: Some(2600.0),
        seconds: 120.0,
        trials: 2,
        seed,
    };
    let a = run_trials(&task, &cfg(5), &|_| {}).unwrap();
    let b = run_trials(&task, &cfg(5), &|_| {}).unwrap();
    assert_eq!(a, b);
    for r in &a {
        let g = r.governor.as_ref().expect("a governed trial has a record");
        assert!(g.moves > 2, "moves {}", g.moves);
        assert_eq!(g.budget_s, 2600.0);
        assert_eq!(g.held, r.mtbf_s >= 2600.0);
        assert!((0.1..=1.0).contains(&g.mean_parameter));
    }
    // Without a budget the same policy runs with its own α: another run.
    let fixed = run_trials(&task, &RunConfig { mtbf_budget_s: None, ..cfg(5) }, &|_| {}).unwrap();
    assert_ne!(fixed, a);
    assert!(fixed.iter().all(|r| r.governor.is_none()));
}
