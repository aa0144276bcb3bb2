//! Tests of the whole controller: its generator draws as the host's, and
//! what it reports replays on a host agent action for action.

use super::*;
use crate::control::test_support::*;
use crate::config::{TILINGS, TRACE};
use core::cell::Cell;
use core::f32::consts::PI;
use pada_core::agent::{EpisodeEnd, Mode};
use pada_core::safety::RunMode;
use pada_core::wire::StepKind;

#[test]
fn replaying_the_reported_steps_on_a_host_agent_gives_the_same_actions() {
    // What `pada sil` does with the firmware's telemetry, in miniature: a
    // pendulum that moves with the commands, the Step records replayed
    // through a plain agent with the same seed.
    let seed = 11;
    let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), seed).unwrap();
    start(&mut c, RunMode::Learning);
    let clock = Clock(Cell::new(0));
    let mut out = PeriodOutput::default();
    let mut steps = std::vec::Vec::new();
    let mut angle: f32 = 0.0;
    for k in 0..1500u32 {
        let counts = (angle / (2.0 * PI) * 4096.0).round() as i64;
        c.period(&pendulum_readings(counts.rem_euclid(65536) as u16, k * 30), &clock, &mut out);
        if let Some(s) = out.step.take() {
            steps.push(s);
        }
        // A crude plant: the voltage turns the pendulum.
        let u = c.applied[0];
        angle += 0.02 * u - 0.05 * libm::sinf(angle);
    }
    assert!(steps.len() > 300);

    // The host's generator: the firmware's own must draw the same.
    let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
    let mut agent = SPEC_33HZ.agent::<_, TILINGS, TRACE>(PolicyKind::Pada { delta: 0.5 }, profile(&SPEC_33HZ).layout, table()).unwrap();
    agent.reset_weights(&mut rng);
    for s in &steps {
        agent.set_mode(if s.mode == RunMode::Testing { Mode::Testing } else { Mode::Learning });
        match s.kind {
            StepKind::Start => {
                let d = agent.start_episode(&s.state, &mut rng).unwrap();
                assert_eq!(d.action, s.action);
            }
            StepKind::Step => {
                let d = agent.step(s.reward, &s.state, &mut rng).unwrap();
                assert_eq!(d.action, s.action, "step {}", s.step);
            }
            StepKind::Absorbing => agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).unwrap(),
            StepKind::Timeout => {
                agent.end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng).unwrap()
            }
        }
    }
    assert_eq!(agent.weights_checksum(), c.agent().weights_checksum());
}

#[test]
fn the_generator_draws_as_the_hosts_rand_pcg() {
    use rand_core::RngCore;
    for seed in [0, 1, 11, crate::config::DEFAULT_SEED, u64::MAX] {
        let mut mine = Pcg32::seed_from_u64(seed);
        let mut host = rand_pcg::Pcg32::seed_from_u64(seed);
        for _ in 0..10_000 {
            assert_eq!(mine.next_u32(), host.next_u32());
        }
        assert_eq!(mine.next_u64(), host.next_u64());
    }
}
