//! The agent with generalisation over actions (LEO's 3 × 7 voltages with
//! 6.67 V action tiles, docs/reference/grl.md §3.9): the fast greedy choice agrees with
//! evaluating every action, and learning one voltage teaches its neighbours.

use pada_core::action_space::{ActionDim, ActionSpace};
use pada_core::agent::{Agent, EpisodeEnd, Mode, SarsaParams, WeightInit};
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use pada_core::tile_coding::{Layout, StateDim};
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg32;

type LeoLike = Agent<Box<[Q16]>, 16, 64>;

fn leo_like(policy: PolicyKind) -> LeoLike {
    leo_like_with(policy, WeightInit::Uniform { min: -1.0, max: 1.0 })
}

fn leo_like_with(policy: PolicyKind, init: WeightInit) -> LeoLike {
    let obs: Vec<StateDim> = (0..10).map(|_| StateDim::new(-3.0, 3.0, 0.5).unwrap()).collect();
    let volts = ActionDim::uniform(-10.7, 10.7, 7).unwrap();
    let space = ActionSpace::repeated(volts, 3).unwrap();
    let params = SarsaParams { init, ..SarsaParams::default() };
    let weights = vec![Q16::ZERO; 1 << 20].into_boxed_slice();
    let mut a = Agent::new(&obs, space, policy, params, Layout::Hashed, weights).unwrap();
    a.generalise_actions(&[6.67; 3]).unwrap();
    a
}

fn random_obs(rng: &mut Pcg32) -> [f32; 10] {
    let mut o = [0.0; 10];
    for x in &mut o {
        *x = (rng.next_u32() as f32 / u32::MAX as f32) * 6.0 - 3.0;
    }
    o
}

#[test]
fn tiled_greedy_choice_is_the_argmax_over_every_action() {
    let mut rng = Pcg32::seed_from_u64(5);
    let mut agent = leo_like(PolicyKind::Sarsa);
    agent.reset_weights(&mut rng);
    agent.set_mode(Mode::Testing);
    for _ in 0..50 {
        let obs = random_obs(&mut rng);
        let d = agent.start_episode(&obs, &mut rng).unwrap();
        let q: Vec<Q16> = (0..343).map(|a| agent.q_value(&obs, a).unwrap()).collect();
        let best = q.iter().copied().max().unwrap();
        assert_eq!(d.q, best, "the choice is a best action");
        assert_eq!(q[d.action as usize], best);
        agent.end_episode(0.0, EpisodeEnd::Absorbing, &mut rng).unwrap();
    }
}

#[test]
fn pada_candidates_with_action_tiles_stay_within_delta() {
    // Δ = 1/6 of the range, one level (3.57 V): 27 candidates, fewer than
    // the combinations, so the direct path runs.
    let mut rng = Pcg32::seed_from_u64(6);
    let mut agent = leo_like(PolicyKind::Pada { delta: 1.0 / 6.0 });
    agent.reset_weights(&mut rng);
    agent.set_mode(Mode::Testing);
    let obs = random_obs(&mut rng);
    let first = agent.start_episode(&obs, &mut rng).unwrap();
    let obs2 = random_obs(&mut rng);
    let next = agent.step(0.0, &obs2, &mut rng).unwrap();
    for d in 0..3 {
        assert!((next.output[d] - first.output[d]).abs() <= 3.57, "{:?} {:?}", first.output, next.output);
    }
}

#[test]
fn learning_one_voltage_teaches_its_neighbour_but_not_a_far_one() {
    // All weights 0; only the target action is rewarded. Actions are drawn
    // at random (ε = 1), so the target is played a few times in 3000 tries.
    let mut rng = Pcg32::seed_from_u64(7);
    let mut agent = leo_like_with(PolicyKind::Sarsa, WeightInit::Constant(0.0));
    agent.reset_weights(&mut rng);
    agent.set_epsilon(1.0).unwrap();
    let obs = [0.1; 10];
    let space = agent.policy().learner_space().clone();
    let target = space.encode(&[3, 3, 3, 0]);
    let mut taught = 0;
    for _ in 0..3000 {
        let d = agent.start_episode(&obs, &mut rng).unwrap();
        let reward = if d.action == target { 50.0 } else { 0.0 };
        taught += (d.action == target) as u32;
        agent.end_episode(reward, EpisodeEnd::Absorbing, &mut rng).unwrap();
    }
    assert!(taught > 0, "the target action was never played");
    let q = |l: [u8; 4]| agent.q_value(&obs, space.encode(&l)).unwrap().to_f32();
    // 3.57 V away in one dimension: shares about half the tilings.
    assert!(q([3, 3, 4, 0]) > 2.0, "neighbour {}", q([3, 3, 4, 0]));
    assert!(q([3, 3, 4, 0]) < q([3, 3, 3, 0]));
    // 10.7 V away: shares no tile with the target; it moves only through
    // the chain of neighbours' corrections, far less.
    let (near, far) = (q([3, 3, 4, 0]), q([3, 3, 6, 0]));
    assert!(far.abs() < near / 4.0, "near {near}, far {far}, target {}", q([3, 3, 3, 0]));
}

#[test]
fn tiled_greedy_breaks_ties_as_the_plain_candidate_walk() {
    // Weights from {0, 16, 32} raw units: many exact ties, and Q (the sum
    // over 16 tilings / 16) is exact, so equal Q means equal sums. The
    // reference walks the joint actions in index order (first dimension
    // fastest, as Candidates::for_each) with the same reservoir rule.
    let mut rng = Pcg32::seed_from_u64(11);
    let mut agent = leo_like(PolicyKind::Sarsa);
    for w in agent.weights_mut().iter_mut() {
        *w = Q16((rng.next_u32() % 3) as i32 * 16);
    }
    agent.set_mode(Mode::Testing);
    let mut tied_choices = 0;
    for _ in 0..40 {
        let obs = random_obs(&mut rng);
        let mut reference_rng = rng.clone();
        let (mut best, mut best_q, mut ties) = (0u32, Q16(i32::MIN), 0u32);
        for a in 0..343 {
            let q = agent.q_value(&obs, a).unwrap();
            if q > best_q {
                (best, best_q, ties) = (a, q, 1);
            } else if q == best_q {
                ties += 1;
                if pada_core::policy::uniform_below(&mut reference_rng, ties) == 0 {
                    best = a;
                }
            }
        }
        let d = agent.start_episode(&obs, &mut rng).unwrap();
        assert_eq!(d.action, best, "ties {ties}");
        tied_choices += (ties > 1) as u32;
        agent.end_episode(0.0, EpisodeEnd::Absorbing, &mut rng).unwrap();
    }
    assert!(tied_choices > 10, "only {tied_choices} of 40 choices were among ties");
}
