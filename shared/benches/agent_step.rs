//! One agent step (ε-greedy selection + SARSA(λ) update) for the pendulum
//! and LEO configurations, with plain SARSA and with PADA.
//!
//! Run: `cargo bench -p pada-core --bench agent_step`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use pada_core::action_space::{ActionDim, ActionSpace};
use pada_core::agent::{Agent, SarsaParams, WeightInit};
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use pada_core::tile_coding::{Layout, StateDim};
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;
use std::f32::consts::PI;
use std::hint::black_box;

const TILINGS: usize = 16;
const TRACE: usize = 64;

fn params() -> SarsaParams {
    SarsaParams { init: WeightInit::Uniform { min: 0.0, max: 0.01 }, ..SarsaParams::default() }
}

/// Pendulum: (θ wrapped, θ̇), 3 torques, 16 tilings, 2^16 weights.
fn pendulum(policy: PolicyKind) -> (Agent<Box<[Q16]>, TILINGS, TRACE>, Vec<[f32; 10]>) {
    let obs = [StateDim::wrapping(-PI, PI, 20).unwrap(), StateDim::new(-12.0 * PI, 12.0 * PI, 3.1).unwrap()];
    let space = ActionSpace::new(&[ActionDim::from_levels(&[-1.5, 0.0, 1.5]).unwrap()]).unwrap();
    let weights = vec![Q16::ZERO; 1 << 16].into_boxed_slice();
    let agent = Agent::new(&obs, space, policy, params(), Layout::Hashed, weights).unwrap();
    (agent, states(2, &[PI, 12.0 * PI]))
}

/// LEO: 10-D state, 3 × 7 voltages (343 joint actions) tile-coded with
/// 6.67 V action tiles (GRL's `generalizeActions`), 16 tilings, 2^22
/// weights (GRL used 2^23).
fn leo(policy: PolicyKind) -> (Agent<Box<[Q16]>, TILINGS, TRACE>, Vec<[f32; 10]>) {
    let (mut agent, xs) = leo_untiled(policy);
    agent.generalise_actions(&[6.67; 3]).unwrap();
    (agent, xs)
}

/// LEO without generalisation over actions (one weight set per joint
/// action): the greedy choice hashes all 343 × 16 (action, tiling) pairs.
fn leo_untiled(policy: PolicyKind) -> (Agent<Box<[Q16]>, TILINGS, TRACE>, Vec<[f32; 10]>) {
    let angle = StateDim::new(-PI, PI, 0.28).unwrap();
    let rate = StateDim::new(-30.0, 30.0, 10.0).unwrap();
    let obs = [
        StateDim::new(-1.0, 1.0, 0.14).unwrap(),
        StateDim::new(-30.0, 30.0, 5.0).unwrap(),
        angle, rate, angle, rate, angle, rate, angle, rate,
    ];
    let space = ActionSpace::repeated(ActionDim::uniform(-10.7, 10.7, 7).unwrap(), 3).unwrap();
    let weights = vec![Q16::ZERO; 1 << 22].into_boxed_slice();
    let agent = Agent::new(&obs, space, policy, params(), Layout::Hashed, weights).unwrap();
    (agent, states(10, &[1.0, 30.0, 2.0, 30.0, 2.0, 30.0, 2.0, 30.0, 2.0, 30.0]))
}

/// A fixed, smooth-ish sequence of states (a random walk), so successive
/// steps share tiles as in a real rollout.
fn states(dims: usize, scale: &[f32]) -> Vec<[f32; 10]> {
    let mut rng = Pcg32::seed_from_u64(7);
    let mut x = [0.0f32; 10];
    (0..4096)
        .map(|_| {
            for i in 0..dims {
                let u = rng.next_u32() as f32 / u32::MAX as f32 - 0.5;
                x[i] = (x[i] + 0.05 * scale[i] * u).clamp(-scale[i], scale[i]);
            }
            x
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("agent_step");
    type Build = fn(PolicyKind) -> (Agent<Box<[Q16]>, TILINGS, TRACE>, Vec<[f32; 10]>);
    let configs: [(&str, Build, usize, PolicyKind); 5] = [
        ("pendulum/sarsa", pendulum, 2, PolicyKind::Sarsa),
        ("pendulum/pada", pendulum, 2, PolicyKind::Pada { delta: 0.5 }),
        ("leo/sarsa", leo, 10, PolicyKind::Sarsa),
        ("leo/pada", leo, 10, PolicyKind::Pada { delta: 1.0 / 6.0 }),
        ("leo/sarsa-untiled-actions", leo_untiled, 10, PolicyKind::Sarsa),
    ];
    for (name, build, dims, policy) in configs {
        let (mut agent, xs) = build(policy);
        let mut rng = Pcg32::seed_from_u64(1);
        agent.reset_weights(&mut rng);
        agent.start_episode(&xs[0][..dims], &mut rng).unwrap();
        let mut i = 0usize;
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                i = (i + 1) % xs.len();
                black_box(agent.step(-1.0, &xs[i][..dims], &mut rng).unwrap())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
