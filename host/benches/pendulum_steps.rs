//! Pendulum learning throughput on one core: environment steps per second
//! of a whole trial (agent and plant, learning and test runs), for SARSA(λ)
//! and PADA on the simulated pendulum, and the plant alone.
//!
//! `cargo bench -p pada --bench pendulum_steps`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use pada::experiment::task::{Plant, Task};
use pada::experiment::{run_trial, RunConfig};
use pada::pendulum::{
    PhysicalPendulumTask, SimulatedPendulum, SimulatedPendulumParams, SimulatedPendulumTask,
};
use pada_core::policy::PolicyKind;
use std::hint::black_box;

/// Learning time of the benchmarked trial: 300 s = 6000 learning steps at
/// 20 Hz plus 11 test runs of 60 steps.
const SECONDS: f64 = 300.0;

fn trial_steps<T: Task>(task: &T, policy: PolicyKind) -> u64 {
    let cfg = RunConfig {
        policy,
        switch_at_s: None,
        mtbf_budget_s: None,
        seconds: SECONDS,
        trials: 1,
        seed: 1,
    };
    let r = run_trial(task, &cfg, 0, &|_| {}).expect("trial runs");
    r.learning_steps + r.test_steps
}

fn bench_trials(c: &mut Criterion) {
    let mut g = c.benchmark_group("pendulum_env_steps");
    let sim = SimulatedPendulumTask::default();
    let phys = PhysicalPendulumTask::default();
    for (name, policy) in [
        ("sarsa", PolicyKind::Sarsa),
        ("pada_0.5", PolicyKind::Pada { delta: 0.5 }),
    ] {
        let steps = trial_steps(&sim, policy);
        g.throughput(Throughput::Elements(steps));
        g.bench_with_input(BenchmarkId::new("simulated", name), &policy, |b, &p| {
            b.iter(|| black_box(trial_steps(&sim, p)))
        });
    }
    let steps = trial_steps(&phys, PolicyKind::Sarsa);
    g.throughput(Throughput::Elements(steps));
    g.bench_function(BenchmarkId::new("physical", "sarsa"), |b| {
        b.iter(|| black_box(trial_steps(&phys, PolicyKind::Sarsa)))
    });
    g.finish();
}

fn bench_plant(c: &mut Criterion) {
    let mut g = c.benchmark_group("pendulum_plant");
    g.throughput(Throughput::Elements(60));
    g.bench_function("simulated_episode_60_steps", |b| {
        let mut plant = SimulatedPendulum::new(SimulatedPendulumParams::default());
        let mut rng = rand_pcg::Pcg64::new(1, 1);
        let mut obs = [0.0f32; 2];
        b.iter(|| {
            plant.reset(&mut rng, &mut obs);
            for k in 0..60 {
                let u = if (k / 7) % 2 == 0 { 1.5 } else { -1.5 };
                black_box(plant.step(&[u], &mut obs));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench_trials, bench_plant);
criterion_main!(benches);
