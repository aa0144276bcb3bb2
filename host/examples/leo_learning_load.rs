//! A fixed learning workload for profiling: N simulated seconds of LEO
//! learning from scratch (plant + agent, as `leo_sim_agent` in
//! `benches/leo_sim.rs`), deterministic, so that an instruction count is
//! repeatable on a shared machine where wall-clock times are not:
//!
//! ```text
//! cargo build --release -p pada --example leo_learning_load
//! valgrind --tool=callgrind target/release/examples/leo_learning_load 60 pada   # or sarsa
//! callgrind_annotate --inclusive=yes callgrind.out.<pid> | head -60
//! ```
use pada::experiment::build_agent;
use pada::experiment::task::{Plant, Task};
use pada::leo::rl::LeoTask;
use pada_core::agent::EpisodeEnd;
use pada_core::policy::PolicyKind;
use rand_core::SeedableRng;
fn main() {
    let secs: u32 = match std::env::args().nth(1).map(|s| s.parse()) {
        None => 20,
        Some(Ok(s)) if (1..=100_000).contains(&s) => s,
        Some(_) => {
            eprintln!("error: the first argument is simulated seconds, 1..=100000");
            std::process::exit(2);
        }
    };
    let policy = match std::env::args().nth(2).as_deref() {
        None | Some("pada") => PolicyKind::Pada { delta: 1.0 / 6.0 },
        Some("sarsa") => PolicyKind::Sarsa,
        Some(other) => {
            eprintln!("error: unknown algorithm {other:?}: valid are pada (Δ = 1/6) and sarsa");
            std::process::exit(2);
        }
    };
    let task = LeoTask::default();
    let mut rng = rand_pcg::Pcg32::seed_from_u64(2);
    let mut agent = build_agent(task.spec(), policy).expect("the LEO agent builds");
    agent.reset_weights(&mut rng);
    let mut plant = task.plant();
    let mut obs = [0.0f32; 10];
    plant.reset(&mut rng, &mut obs);
    let mut decision = agent
        .start_episode(&obs, &mut rng)
        .expect("finite observation");
    let (mut steps, mut eps) = (0u32, 0u32);
    for _ in 0..secs * 30 {
        let s = plant.step(&decision.output[..3], &mut obs);
        steps += 1;
        if s.terminal || steps >= task.spec().episode_steps {
            let end = if s.terminal {
                EpisodeEnd::Absorbing
            } else {
                EpisodeEnd::Timeout(&obs)
            };
            agent
                .end_episode(s.reward, end, &mut rng)
                .expect("finite reward");
            plant.reset(&mut rng, &mut obs);
            steps = 0;
            eps += 1;
            decision = agent
                .start_episode(&obs, &mut rng)
                .expect("finite observation");
        } else {
            decision = agent.step(s.reward, &obs, &mut rng).expect("finite step");
        }
    }
    // The checksum tells whether a change to the physics kept every
    // trajectory bit for bit (same checksum) or not.
    println!("{secs} s of learning: {eps} episodes, weights checksum {:08x}", agent.weights_checksum());
}
