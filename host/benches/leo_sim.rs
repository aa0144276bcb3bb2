//! LEO simulation speed: simulated seconds per
//! wall-clock second on one core, with the default physics settings.
//!
//! `leo_sim/random_actions`: one iteration is one simulated second (30
//! control steps) of the walking task with uniformly random actions from
//! the 7 voltage levels per joint, episodes reset on every fall — the load
//! of early learning. Criterion's throughput ("elem/s") is the real-time
//! factor. `leo_sim_parts/control_step` (1/30 s) and `leo_sim_parts/reset` time
//! the two parts. `leo_sim_agent/{sarsa,pada}`: one simulated second of
//! learning, the plant and the agent of `pada run --task leo` together
//! (the runner's own agent and plant, ε-greedy, episodes reset on a fall or
//! after 25 s); its throughput is the real-time factor of a learning run.
//!
//! Run: `cargo bench -p pada --bench leo_sim`.
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pada::experiment::build_agent;
use pada::leo::rl::LeoTask;
use pada::leo::{LeoConfig, LeoEnv, Terminal};
use pada::experiment::task::{Plant, Task};
use pada_core::agent::EpisodeEnd;
use pada_core::policy::PolicyKind;
use rand_core::{RngCore, SeedableRng};

const LEVELS: [f32; 7] = [-10.7, -7.1333, -3.5667, 0.0, 3.5667, 7.1333, 10.7];

fn random_action(rng: &mut rand_pcg::Pcg32) -> [f32; 3] {
    [0, 1, 2].map(|_| LEVELS[(rng.next_u32() % 7) as usize])
}

fn leo_sim(c: &mut Criterion) {
    let mut group = c.benchmark_group("leo_sim");
    let Ok(mut env) = LeoEnv::new(LeoConfig::default()) else {
        eprintln!("leo_sim: the default LEO configuration was refused");
        return;
    };
    let mut rng = rand_pcg::Pcg32::seed_from_u64(1);
    env.reset(&mut rng);

    group.throughput(Throughput::Elements(1));
    group.bench_function("random_actions", |b| {
        b.iter(|| {
            for _ in 0..30 {
                let r = env.step(random_action(&mut rng));
                if r.terminal != Terminal::None {
                    env.reset(&mut rng);
                }
                black_box(r);
            }
        })
    });

    group.finish();

    // The parts, timed per call (no throughput).
    let mut group = c.benchmark_group("leo_sim_parts");
    group.bench_function("control_step", |b| {
        b.iter(|| {
            let r = env.step(random_action(&mut rng));
            if r.terminal != Terminal::None {
                env.reset(&mut rng);
            }
            black_box(r)
        })
    });

    group.bench_function("reset", |b| b.iter(|| black_box(env.reset(&mut rng))));
    group.finish();
}

/// One simulated second (30 steps) of learning per iteration: plant step,
/// then agent step, as the runner does.
fn leo_sim_agent(c: &mut Criterion) {
    let mut group = c.benchmark_group("leo_sim_agent");
    group.throughput(Throughput::Elements(1));
    let task = LeoTask::default();
    for (name, policy) in [("sarsa", PolicyKind::Sarsa), ("pada", PolicyKind::Pada { delta: 1.0 / 6.0 })] {
        let mut rng = rand_pcg::Pcg32::seed_from_u64(2);
        let Ok(mut agent) = build_agent(task.spec(), policy) else {
            eprintln!("leo_sim_agent: the LEO agent was refused");
            return;
        };
        agent.reset_weights(&mut rng);
        let mut plant = task.plant();
        let mut obs = [0.0f32; 10];
        plant.reset(&mut rng, &mut obs);
        let mut decision = agent.start_episode(&obs, &mut rng).expect("finite observation");
        let mut steps = 0u32;
        group.bench_function(name, |b| {
            b.iter(|| {
                for _ in 0..30 {
                    let s = plant.step(&decision.output[..3], &mut obs);
                    steps += 1;
                    if s.terminal || steps >= task.spec().episode_steps {
                        let end = if s.terminal { EpisodeEnd::Absorbing } else { EpisodeEnd::Timeout(&obs) };
                        agent.end_episode(s.reward, end, &mut rng).expect("finite");
                        plant.reset(&mut rng, &mut obs);
                        steps = 0;
                        decision = agent.start_episode(&obs, &mut rng).expect("finite");
                    } else {
                        decision = agent.step(s.reward, &obs, &mut rng).expect("finite");
                    }
                }
                black_box(&decision);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, leo_sim, leo_sim_agent);
criterion_main!(benches);
