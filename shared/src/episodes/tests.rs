extern crate std;
use super::wear::{damage_raws, increments};
use super::*;
use crate::agent::Agent;
use crate::fatigue::{FatigueCounter, GearboxParams};
use crate::fixed::Q16;
use crate::policy::PolicyKind;
use crate::robot::{leo, pendulum};
use crate::tile_coding::Layout;
use rand_core::SeedableRng;
use rand_pcg::Pcg32;
use std::vec;
use std::vec::Vec;

type TestAgent = Agent<Vec<Q16>, 16, 64>;

fn pendulum_agent(policy: PolicyKind) -> TestAgent {
    pendulum::SPEC_33HZ.agent(policy, Layout::Hashed, vec![Q16::ZERO; 1 << 12]).unwrap()
}

fn rules(episode_steps: u32, test_interval: u32) -> EpisodeRules {
    EpisodeRules { episode_steps, test_interval, ..pendulum::SPEC_33HZ.episode_rules() }
}

/// Runs one episode to its end: `absorbing_at` ends it there; returns
/// every transition.
fn run_episode(e: &mut Episodes, agent: &mut TestAgent, requested: RunMode, absorbing_at: Option<u32>, rng: &mut Pcg32) -> Vec<Transition> {
    let mut out = vec![e.begin(agent, requested, &[0.1, 0.0], rng).unwrap()];
    for k in 1.. {
        let t = e.advance(agent, &[0.1, 0.0], -1.0, absorbing_at == Some(k), false, rng).unwrap();
        out.push(t);
        if t.ended.is_some() {
            return out;
        }
    }
    unreachable!()
}

#[test]
fn every_interval_learning_episodes_one_test_and_a_requested_test_keeps_the_cadence() {
    let (mut agent, mut rng) = (pendulum_agent(PolicyKind::Sarsa), Pcg32::seed_from_u64(1));
    let mut e = Episodes::new(rules(3, 4));
    let mut modes = Vec::new();
    for _ in 0..10 {
        modes.push(run_episode(&mut e, &mut agent, RunMode::Learning, None, &mut rng)[0].mode);
    }
    use RunMode::{Learning as L, Testing as T};
    assert_eq!(modes, [L, L, L, L, T, L, L, L, L, T]);
    // A requested test (the host's before learning, the board's Start in
    // test mode) is a test and does not count as the cadence's.
    let mut e = Episodes::new(rules(3, 2));
    let t = run_episode(&mut e, &mut agent, T, None, &mut rng);
    assert_eq!(t[0].mode, T);
    assert_eq!(agent.mode(), Mode::Testing);
    let next: Vec<_> = (0..3).map(|_| run_episode(&mut e, &mut agent, L, None, &mut rng)[0].mode).collect();
    assert_eq!(next, [L, L, T]);
    assert_eq!(e.started(), 4);
    // An interval of 0 still learns: every other episode is a test.
    let mut e = Episodes::new(rules(3, 0));
    let modes: Vec<_> = (0..4).map(|_| run_episode(&mut e, &mut agent, L, None, &mut rng)[0].mode).collect();
    assert_eq!(modes, [L, T, L, T]);
}

#[test]
fn an_episode_ends_at_the_time_limit_with_a_bootstrap_or_at_an_absorbing_state() {
    let (mut agent, mut rng) = (pendulum_agent(PolicyKind::Sarsa), Pcg32::seed_from_u64(2));
    let mut e = Episodes::new(rules(5, 10));
    let t = run_episode(&mut e, &mut agent, RunMode::Learning, None, &mut rng);
    let kinds: Vec<_> = t.iter().map(|t| t.kind).collect();
    use StepKind::*;
    assert_eq!(kinds, [Start, Step, Step, Step, Step, Timeout]);
    let report = t[5].ended.unwrap();
    assert_eq!((report.index, report.length, report.total_reward, report.mode), (0, 5, -5.0, RunMode::Learning));
    assert_eq!(t[5].episode_return, -5.0);
    assert_eq!(report.weights_checksum, agent.weights_checksum());
    assert!(!e.running());
    assert!(t.iter().take(5).all(|t| t.decision.is_some() && t.ended.is_none()));
    let t = run_episode(&mut e, &mut agent, RunMode::Learning, Some(2), &mut rng);
    let kinds: Vec<_> = t.iter().map(|t| t.kind).collect();
    assert_eq!(kinds, [Start, Step, Absorbing]);
    assert_eq!(t[2].ended.map(|r| (r.index, r.length)), Some((1, 2)));
    // Only learning Start and Step calls choose learning actions.
    assert_eq!(t.iter().map(|t| t.is_learning_action()).collect::<Vec<_>>(), [true, true, false]);
    assert!(!is_learning_action(RunMode::Testing, Start));
    assert!(!is_learning_action(RunMode::Learning, Timeout));
}

#[test]
fn a_non_finite_observation_spends_nothing_at_the_start_and_gives_the_episode_up_later() {
    let (mut agent, mut rng) = (pendulum_agent(PolicyKind::Sarsa), Pcg32::seed_from_u64(3));
    let mut e = Episodes::new(rules(5, 10));
    assert!(e.begin(&mut agent, RunMode::Learning, &[f32::NAN, 0.0], &mut rng).is_err());
    assert_eq!((e.started(), e.running()), (0, false));
    e.begin(&mut agent, RunMode::Learning, &[0.0, 0.0], &mut rng).unwrap();
    assert!(e.advance(&mut agent, &[0.0, 0.0], f32::INFINITY, false, false, &mut rng).is_err());
    assert!(!e.running());
    assert_eq!(e.advance(&mut agent, &[0.0, 0.0], 0.0, false, false, &mut rng).unwrap_err(), StepError::NoEpisode);
}

#[test]
fn a_footstep_moves_the_policys_memory_only_for_a_robot_with_a_remap() {
    let mut rng = Pcg32::seed_from_u64(4);
    let spec = &leo::SPEC;
    let weights = vec![Q16::ZERO; 1 << 14];
    let mut agent: TestAgent = spec.agent(PolicyKind::Pada { delta: 1.0 / 6.0 }, Layout::Hashed, weights).unwrap();
    let obs = vec![0.0; spec.state.len()];
    let mut e = Episodes::new(spec.episode_rules());
    e.begin(&mut agent, RunMode::Learning, &obs, &mut rng).unwrap();
    let before = agent.policy().previous();
    let t = e.advance(&mut agent, &obs, 0.0, false, true, &mut rng).unwrap();
    assert!(t.footstep);
    // The decision was taken from the swapped hips' memory: each hip
    // moved at most one level from the other hip's last level.
    let after = t.decision.unwrap().levels;
    for (i, j) in [(0, 1), (1, 0)] {
        assert!(after[i].abs_diff(before[j]) <= 1, "hip {i}: {} from {}", after[i], before[j]);
    }
    // The pendulum has no remap: a footstep is ignored.
    let mut agent = pendulum_agent(PolicyKind::Sarsa);
    let mut e = Episodes::new(pendulum::SPEC_33HZ.episode_rules());
    e.begin(&mut agent, RunMode::Learning, &[0.0, 0.0], &mut rng).unwrap();
    assert!(!e.advance(&mut agent, &[0.0, 0.0], 0.0, false, true, &mut rng).unwrap().footstep);
}

#[test]
fn the_record_of_an_end_carries_the_last_action_and_no_output() {
    let (mut agent, mut rng) = (pendulum_agent(PolicyKind::Sarsa), Pcg32::seed_from_u64(5));
    let mut e = Episodes::new(rules(2, 10));
    let fatigue = FatigueCounter::<1>::new(GearboxParams::TABLE_I, 0.03, None).unwrap();
    let stamp = record::Stamp { step: 7, time_ms: 210, agent_cycles: 3 };
    let start = e.begin(&mut agent, RunMode::Learning, &[0.5, 1.0], &mut rng).unwrap();
    let r = e.record(&start, &agent, &[0.5, 1.0], fatigue.joints(), stamp);
    assert_eq!((r.kind, r.episode, r.td_error, r.step, r.time_ms, r.agent_cycles), (StepKind::Start, 0, 0, 7, 210, 3));
    assert_eq!(r.state.as_slice(), &[0.5, 1.0]);
    assert_eq!(r.output.as_slice(), &start.decision.unwrap().output[..1]);
    assert_eq!(r.joints.len(), 1);
    let step = e.advance(&mut agent, &[0.4, 1.0], -2.0, false, false, &mut rng).unwrap();
    let end = e.advance(&mut agent, &[0.3, 1.0], -3.0, false, false, &mut rng).unwrap();
    let r = e.record(&end, &agent, &[0.3, 1.0], fatigue.joints(), stamp);
    assert_eq!(r.kind, StepKind::Timeout);
    assert_eq!(r.action, step.decision.unwrap().action);
    assert!(r.output.is_empty());
    assert_eq!(r.reward, -3.0);
    assert_ne!(r.td_error, 0, "a learning update's TD error");
}

#[test]
fn the_governors_feed_is_the_damage_since_before_and_never_wraps() {
    let mut f = FatigueCounter::<2>::new(GearboxParams::TABLE_I, 0.03, None).unwrap();
    let before = damage_raws(&f);
    for k in 0..50 {
        let torque = if k % 2 == 0 { 1.5 } else { -1.5 };
        f.update(&[torque, 0.0]).unwrap();
    }
    let inc = increments(&before, &f, 0..2);
    assert!(inc[0] > 0);
    assert_eq!(inc[1], 0);
    assert_eq!(inc[0], f.joints()[0].damage_raw() - before[0]);
    // A counter behind `before` (restored from an older checkpoint).
    let ahead = [u64::MAX; 2];
    assert_eq!(increments(&ahead, &f, 0..2)[0], 0);
    // Joints past the counter's are left out.
    assert_eq!(increments(&before, &f, 1..9)[1..], [0; crate::governor::GOVERNED_JOINTS - 1][..]);
}

#[test]
fn the_position_names_the_episode_in_progress_and_its_transitions() {
    let (mut agent, mut rng) = (pendulum_agent(PolicyKind::Sarsa), Pcg32::seed_from_u64(3));
    let mut e = Episodes::new(rules(5, 10));
    assert_eq!(e.position(), None);
    run_episode(&mut e, &mut agent, RunMode::Testing, None, &mut rng);
    assert_eq!(e.position(), None, "no episode between episodes");
    e.begin(&mut agent, RunMode::Learning, &[0.1, 0.0], &mut rng).unwrap();
    assert_eq!(e.position(), Some(EpisodeAt { index: 1, mode: RunMode::Learning, steps: 0 }));
    e.advance(&mut agent, &[0.1, 0.0], -1.0, false, false, &mut rng).unwrap();
    e.advance(&mut agent, &[0.1, 0.0], -1.0, false, false, &mut rng).unwrap();
    assert_eq!(e.position(), Some(EpisodeAt { index: 1, mode: RunMode::Learning, steps: 2 }));
    e.abandon();
    assert_eq!(e.position(), None);
}
