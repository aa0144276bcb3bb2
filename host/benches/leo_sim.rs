//! LEO simulation speed (issue 4, "Performance"): simulated seconds per
//! wall-clock second on one core, with the default physics settings.
//!
//! `leo_sim/random_actions`: one iteration is one simulated second (30
//! control steps) of the walking task with uniformly random actions from
//! the 7 voltage levels per joint, episodes reset on every fall — the load
//! of early learning. Criterion's throughput ("elem/s") is the real-time
//! factor. `leo_sim_parts/control_step` (1/30 s) and `leo_sim_parts/reset` time
//! the two parts.
//!
//! Run: `cargo bench -p pada --bench leo_sim`.
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pada::leo::{LeoConfig, LeoEnv, Terminal};
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

criterion_group!(benches, leo_sim);
criterion_main!(benches);
