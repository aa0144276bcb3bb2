//! Saved learning: the learner's state — agent counters, ε, mode,
//! policy, fatigue counters, generator, user counters — saved with the
//! weights and restored, so that a board that resets continues where it was.
//!
//! - the generator is bit-identical to `rand_pcg::Pcg32` and restorable;
//! - a learner restored from a checkpoint takes the same decisions as the
//!   one that saved it (between episodes and mid-episode);
//! - arbitrary valid states round-trip through save and load (proptest);
//! - each field out of range is refused, naming it, and changes nothing;
//! - a format-1 checkpoint is refused, not loaded without its state;
//! - a save torn inside the state record keeps the previous checkpoint;
//! - a configuration mismatch leaves weights and state untouched.

mod support;
use support::TornStore;
use pada_core::action_space::{ActionDim, ActionSpace};
use pada_core::agent::{Agent, AgentState, AgentStats, EpisodeEnd, Mode, SarsaParams};
use pada_core::checkpoint::*;
use pada_core::error::ConfigError;
use pada_core::fatigue::{FatigueCounter, FatigueError, GearboxParams, JointFatigueState};
use pada_core::fixed::Q16;
use pada_core::governor::{GovernorState, Restricts};
use pada_core::policy::{PolicyKind, PolicyState};
use pada_core::rng::{Pcg32, RngState};
use pada_core::tile_coding::{Layout, StateDim};
use proptest::prelude::*;
use rand_core::{RngCore, SeedableRng};

const WEIGHTS: usize = 1 << 10;
const SLOT: usize = slot_len(WEIGHTS, 4);
type Store = RamStore<SLOT>;
type TestAgent = Agent<Box<[Q16]>, 4, 64>;
const JOINTS: usize = 3;
const WINDOW: u32 = 40;
const HASH: u32 = 0x5EED_0005;

// ---------------------------------------------------------------------------
// The generator
// ---------------------------------------------------------------------------

proptest! {
    /// Same seed, same numbers as rand_pcg, whichever way they are drawn.
    #[test]
    fn pcg32_is_bit_identical_to_rand_pcg(seed in any::<u64>(), ops in prop::collection::vec((0u8..3, 0usize..41), 1..60)) {
        let mut mine = Pcg32::seed_from_u64(seed);
        let mut theirs = rand_pcg::Pcg32::seed_from_u64(seed);
        for (op, len) in ops {
            match op {
                0 => prop_assert_eq!(mine.next_u32(), theirs.next_u32()),
                1 => prop_assert_eq!(mine.next_u64(), theirs.next_u64()),
                _ => {
                    let (mut a, mut b) = (vec![0u8; len], vec![0u8; len]);
                    mine.fill_bytes(&mut a);
                    theirs.fill_bytes(&mut b);
                    prop_assert_eq!(a, b);
                }
            }
        }
    }

    /// `from_seed` and `new(state, stream)` as rand_pcg's.
    #[test]
    fn pcg32_constructors_match_rand_pcg(seed in any::<[u8; 16]>(), state in any::<u64>(), stream in any::<u64>()) {
        let mut a = Pcg32::from_seed(seed);
        let mut b = rand_pcg::Pcg32::from_seed(seed);
        let mut c = Pcg32::new(state, stream);
        let mut d = rand_pcg::Pcg32::new(state, stream);
        for _ in 0..20 {
            prop_assert_eq!(a.next_u32(), b.next_u32());
            prop_assert_eq!(c.next_u32(), d.next_u32());
        }
    }

    /// A restored generator continues with the next number of the original
    /// (and of rand_pcg's).
    #[test]
    fn pcg32_state_restores_mid_sequence(seed in any::<u64>(), before in 0usize..100) {
        let mut mine = Pcg32::seed_from_u64(seed);
        let mut theirs = rand_pcg::Pcg32::seed_from_u64(seed);
        for _ in 0..before {
            mine.next_u32();
            theirs.next_u32();
        }
        let mut restored = Pcg32::from_state(mine.state()).unwrap();
        for _ in 0..50 {
            let x = theirs.next_u32();
            prop_assert_eq!(restored.next_u32(), x);
            prop_assert_eq!(mine.next_u32(), x);
        }
    }
}

#[test]
fn an_even_increment_is_refused() {
    let e = Pcg32::from_state(RngState { state: 5, increment: 4 }).unwrap_err();
    assert_eq!((e.param, e.valid), ("rng.increment", "an odd increment"));
}

// ---------------------------------------------------------------------------
// A small learner: grid world, agent, fatigue counter, generator
// ---------------------------------------------------------------------------

/// What the firmware keeps: the agent, the fatigue counter of its joints,
/// the generator and its own counters.
struct Learner {
    agent: TestAgent,
    fatigue: FatigueCounter<JOINTS>,
    rng: Pcg32,
    /// The caller's counters: episodes started, and three that only ride along.
    user: [u32; 4],
    /// A governor's state, carried as a checkpoint carries it.
    governor: Option<GovernorState>,
    /// Grid position while an episode runs.
    pos: Option<(f32, f32)>,
}

fn motor() -> ActionSpace {
    ActionSpace::repeated(ActionDim::from_levels(&[-1.0, 0.0, 1.0]).unwrap(), 2).unwrap()
}

fn new_learner(policy: PolicyKind, seed: u64) -> Learner {
    let obs = [StateDim::new(0.0, 4.0, 1.0).unwrap(), StateDim::new(0.0, 4.0, 1.0).unwrap()];
    let params = SarsaParams { epsilon: 0.2, ..SarsaParams::default() };
    let mut agent =
        Agent::new(&obs, motor(), policy, params, Layout::Hashed, vec![Q16::ZERO; WEIGHTS].into_boxed_slice()).unwrap();
    let mut rng = Pcg32::seed_from_u64(seed);
    agent.reset_weights(&mut rng);
    let fatigue = FatigueCounter::new(GearboxParams::TABLE_I, 0.05, Some(WINDOW)).unwrap();
    Learner { agent, fatigue, rng, user: [0; 4], governor: None, pos: None }
}

impl Learner {
    /// One step of the grid (start, step or end of an episode); returns the
    /// action taken, if any.
    fn tick(&mut self) -> Option<u32> {
        let Some((x, y)) = self.pos else {
            self.pos = Some((0.0, 0.0));
            self.user[0] += 1;
            let d = self.agent.start_episode(&[0.0, 0.0], &mut self.rng).unwrap();
            self.apply(d.output);
            return Some(d.action);
        };
        if (x, y) == (4.0, 4.0) {
            self.agent.end_episode(-1.0, EpisodeEnd::Absorbing, &mut self.rng).unwrap();
            self.pos = None;
            return None;
        }
        let d = self.agent.step(-1.0, &[x, y], &mut self.rng).unwrap();
        self.apply(d.output);
        Some(d.action)
    }

    fn apply(&mut self, out: [f32; 4]) {
        let (x, y) = self.pos.unwrap();
        self.pos = Some(((x + out[0]).clamp(0.0, 4.0), (y + out[1]).clamp(0.0, 4.0)));
        self.fatigue.update(&[out[0], out[1], out[0] - out[1]]).unwrap();
    }

    /// Ticks until between episodes.
    fn finish_episode(&mut self) {
        for _ in 0..10_000 {
            if self.pos.is_none() {
                return;
            }
            self.tick();
        }
        panic!("episode does not end");
    }

    fn state(&self) -> LearnerState {
        LearnerState {
            agent: self.agent.state(),
            rng: self.rng.state(),
            joints: heapless::Vec::from_slice(&self.fatigue.state()).unwrap(),
            user: self.user,
            wear: FlashWear::default(),
            governor: self.governor,
        }
    }

    fn check(&self, s: &LearnerState) -> Result<(), &'static str> {
        self.agent.check_state(&s.agent).map_err(|e| e.param)?;
        self.fatigue.check_state(&s.joints).map_err(fatigue_param)?;
        s.rng.check().map_err(|e| e.param)?;
        Ok(())
    }

    /// Restores `s` (checked first: all or nothing).
    fn restore(&mut self, s: &LearnerState) -> Result<(), &'static str> {
        self.check(s)?;
        self.agent.restore_state(&s.agent).map_err(|e| e.param)?;
        self.fatigue.restore(&s.joints).map_err(fatigue_param)?;
        self.rng = Pcg32::from_state(s.rng).map_err(|e| e.param)?;
        self.user = s.user;
        self.governor = s.governor;
        self.pos = None;
        Ok(())
    }

    fn save(&self, store: &mut Store) -> Saved {
        save(store, HASH, &self.state(), self.agent.weights()).unwrap()
    }

    /// As the firmware loads: find, check the state, copy the weights,
    /// restore; a refused state changes nothing.
    fn load(&mut self, store: &Store, hash: u32) -> LoadOutcome {
        let found = match find(store, hash, self.agent.weights().len()).unwrap() {
            Ok(found) => found,
            Err(outcome) => return outcome,
        };
        if self.check(&found.state).is_err() {
            return LoadOutcome::InvalidState;
        }
        let outcome = read_weights(store, &found, self.agent.weights_mut()).unwrap();
        if let LoadOutcome::Loaded { .. } = outcome {
            self.restore(&found.state).unwrap();
        }
        outcome
    }

    /// Everything observable, to compare two learners.
    fn fingerprint(&self) -> (LearnerState, u32) {
        (self.state(), self.agent.weights_checksum())
    }
}

fn fatigue_param(e: FatigueError) -> &'static str {
    match e {
        FatigueError::InvalidParameter { param, .. } => param,
        _ => "fatigue",
    }
}

fn trained(policy: PolicyKind, seed: u64, ticks: usize) -> Learner {
    let mut l = new_learner(policy, seed);
    for _ in 0..ticks {
        l.tick();
    }
    l
}

// ---------------------------------------------------------------------------
// Continuing where it was
// ---------------------------------------------------------------------------

#[test]
fn a_restored_learner_continues_exactly_where_the_saved_one_was() {
    for policy in [PolicyKind::Sarsa, PolicyKind::Pada { delta: 0.5 }, PolicyKind::LowPass { alpha: 0.7 }] {
        let mut a = trained(policy, 1, 3000);
        a.finish_episode();
        a.agent.set_epsilon(0.1).unwrap();
        let mut store = Store::new();
        assert_eq!(a.save(&mut store), Saved { generation: 1, slot: 0, erases: 1 });
        // A board after a reset: another seed, fresh weights, SARSA at boot.
        let mut b = new_learner(PolicyKind::Sarsa, 99);
        assert_ne!(b.fingerprint(), a.fingerprint());
        assert_eq!(b.load(&store, HASH), LoadOutcome::Loaded { generation: 1, slot: 0 });
        assert_eq!(b.fingerprint(), a.fingerprint(), "{policy:?}");
        assert_eq!(b.agent.policy().built_kind(), policy);
        for t in 0..3000 {
            assert_eq!(a.tick(), b.tick(), "{policy:?}, tick {t}");
        }
        assert_eq!(b.fingerprint(), a.fingerprint(), "{policy:?}");
    }
}

#[test]
fn a_switched_policy_stays_switched() {
    let mut a = trained(PolicyKind::Pada { delta: 0.5 }, 4, 500);
    a.finish_episode();
    a.agent.switch_to_sarsa().unwrap();
    assert!(a.agent.policy().switched());
    let mut store = Store::new();
    a.save(&mut store);
    let mut b = new_learner(PolicyKind::Sarsa, 5);
    assert!(matches!(b.load(&store, HASH), LoadOutcome::Loaded { .. }));
    assert!(b.agent.policy().switched());
    assert_eq!(b.agent.policy().kind(), PolicyKind::Sarsa);
    assert_eq!(b.agent.policy().built_kind(), PolicyKind::Pada { delta: 0.5 });
    assert_eq!(b.agent.policy().candidates().count(), 9, "plain SARSA's candidates");
    for _ in 0..500 {
        assert_eq!(a.tick(), b.tick());
    }
}

#[test]
fn restoring_mid_episode_ends_the_episode() {
    let mut a = trained(PolicyKind::Pada { delta: 0.5 }, 2, 777);
    assert!(a.pos.is_some(), "saved in the middle of an episode");
    let mut store = Store::new();
    a.save(&mut store);
    let mut b = new_learner(PolicyKind::Pada { delta: 0.5 }, 3);
    assert!(matches!(b.load(&store, HASH), LoadOutcome::Loaded { .. }));
    // The restored agent has no episode: a step is refused.
    assert!(b.agent.step(-1.0, &[1.0, 1.0], &mut b.rng).is_err());
    // The saver gives up its episode the same way (its traces are not in
    // the checkpoint); from then on both learn alike.
    let own = a.state();
    a.restore(&own).unwrap();
    assert!(a.agent.step(-1.0, &[1.0, 1.0], &mut a.rng).is_err());
    for _ in 0..2000 {
        assert_eq!(a.tick(), b.tick());
    }
    assert_eq!(a.fingerprint(), b.fingerprint());
}

// ---------------------------------------------------------------------------
// Arbitrary valid states round-trip
// ---------------------------------------------------------------------------

fn joint_state(steps: u64) -> impl Strategy<Value = JointFatigueState> {
    let max_reeng = steps.saturating_sub(1);
    (0..=max_reeng, any::<u64>(), any::<bool>(), any::<bool>(), any::<u64>(), any::<u64>()).prop_map(
        move |(reengagements, damage, plus, zero_sign, wr, wd)| {
            let last_sign = if reengagements == 0 && zero_sign { 0 } else if plus { 1 } else { -1 };
            let damage_raw = if reengagements == 0 { 0 } else { damage };
            let window_max = steps.min(WINDOW as u64).saturating_sub(1).min(reengagements);
            let window_reengagements = if window_max == 0 { 0 } else { wr % (window_max + 1) };
            let window_damage_raw =
                if window_reengagements == 0 { 0 } else { wd % damage_raw.saturating_add(1).max(1) };
            JointFatigueState {
                last_sign,
                steps,
                reengagements,
                damage_raw,
                window_reengagements,
                window_damage_raw: window_damage_raw.min(damage_raw),
            }
        },
    )
}

fn policy_state() -> impl Strategy<Value = PolicyState> {
    let kind = prop_oneof![
        Just(PolicyKind::Sarsa),
        (0.0f32..3.0).prop_map(|delta| PolicyKind::Pada { delta }),
        (0.001f32..=1.0).prop_map(|alpha| PolicyKind::LowPass { alpha }),
        (0.0f32..1.0).prop_map(|delta| PolicyKind::EpsilonPada { delta }),
        (0.01f32..=1.0, 0.01f32..=4.0).prop_map(|(theta, sigma)| PolicyKind::OrnsteinUhlenbeck { theta, sigma }),
        (0.01f32..=4.0).prop_map(|sigma| PolicyKind::PinkNoise { sigma }),
        (0.01f32..=100.0).prop_map(|weight| PolicyKind::ActionPenalty { weight }),
    ];
    (kind, any::<bool>(), [0u8..3, 0u8..3], [-1.0f32..=1.0, -1.0f32..=1.0]).prop_map(|(kind, sw, prev, out)| {
        PolicyState {
            kind,
            switched: sw && kind != PolicyKind::Sarsa,
            previous: [prev[0], prev[1], 0, 0],
            output: [out[0], out[1], 0.0, 0.0],
        }
    })
}

fn agent_state() -> impl Strategy<Value = AgentState> {
    (
        any::<u64>(),
        any::<u64>(),
        any::<u64>(),
        any::<(u32, u32, u32, i32)>(),
        0.0f32..=1.0,
        any::<bool>(),
        policy_state(),
        // The learner these states go into has a plain table, which holds
        // no claims (a claim table's are tested in claim_table's tests).
        Just((0u64, 0u32)),
    )
        .prop_map(|(steps, u, e, (episodes, saturations, trace_drops, td), epsilon, testing, policy, (table_seed, claims_refused))| AgentState {
            stats: AgentStats {
                steps,
                updates: if steps == 0 { 0 } else { u % (steps.saturating_add(1)) },
                explorations: if steps == 0 { 0 } else { e % (steps.saturating_add(1)) },
                episodes,
                saturations,
                trace_drops,
                claims_refused,
                last_td_error: Q16(td),
            },
            epsilon,
            mode: if testing { Mode::Testing } else { Mode::Learning },
            policy,
            table_seed,
        })
}

/// Any governor state the record can hold (the ranges that depend on the
/// running governor are the restorer's to check).
fn governor_state() -> impl Strategy<Value = Option<GovernorState>> {
    proptest::option::of(
        (
            any::<u32>(),
            any::<bool>(),
            any::<[u8; 4]>(),
            any::<(u32, u32, u64, u64)>(),
            (any::<u32>(), any::<i64>()),
            any::<[[u64; 12]; 4]>(),
        )
            .prop_map(|(budget_bits, alpha, [rung, cursor, filled, in_bucket], (calm_steps, moves, steps, over), (since_move, headroom_at_move), buckets)| {
                GovernorState {
                    budget_bits,
                    restricts: if alpha { Restricts::Alpha } else { Restricts::Delta },
                    rung,
                    cursor,
                    filled,
                    in_bucket,
                    calm_steps,
                    since_move,
                    headroom_at_move,
                    moves,
                    steps,
                    over_budget_steps: over,
                    buckets,
                }
            }),
    )
}

fn learner_state() -> impl Strategy<Value = LearnerState> {
    (agent_state(), any::<u64>(), any::<u64>(), any::<[u32; 4]>(), 0u64..5000, [0u32..1_000_000, 0u32..1_000_000], any::<u64>())
        .prop_flat_map(|(agent, state, inc, user, steps, erases, operating_s)| {
            (
                Just(agent),
                Just(RngState { state, increment: inc | 1 }),
                Just(user),
                [joint_state(steps), joint_state(steps), joint_state(steps)],
                Just(FlashWear { erases, operating_s }),
                governor_state(),
            )
        })
        .prop_map(|(agent, rng, user, joints, wear, governor)| LearnerState {
            agent,
            rng,
            joints: heapless::Vec::from_slice(&joints).unwrap(),
            user,
            wear,
            governor,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Any valid state, saved with any weights, loads back equal — and
    /// restored into a learner, reads back equal.
    #[test]
    fn valid_states_round_trip_through_save_and_load(
        state in learner_state(),
        seed in any::<i32>(),
        earlier in any::<bool>(),
    ) {
        let weights: Vec<Q16> = (0..WEIGHTS as i32).map(|i| Q16(i.wrapping_mul(0x9E37_79B9u32 as i32) ^ seed)).collect();
        let mut store = Store::new();
        if earlier {
            // Another checkpoint before: the newer one loads.
            save(&mut store, HASH, &LearnerState { user: [1, 2, 3, 4], ..state.clone() }, &weights[..]).unwrap();
        }
        save(&mut store, HASH, &state, &weights).unwrap();
        let mut st = LearnerState::default();
        let mut out = vec![Q16::ZERO; WEIGHTS];
        let outcome = load(&store, HASH, &mut st, &mut out).unwrap();
        let loaded = matches!(outcome, LoadOutcome::Loaded { generation, .. } if generation == 1 + earlier as u32);
        prop_assert!(loaded, "outcome {:?}", outcome);
        // Every save counted its erase on top of the counts it found.
        let e = state.wear.erases;
        let erases = if earlier { [e[0] + 1, e[1] + 1] } else { [e[0] + 1, e[1]] };
        prop_assert_eq!(st.wear, FlashWear { erases, ..state.wear });
        prop_assert_eq!(&LearnerState { wear: state.wear, ..st.clone() }, &state);
        prop_assert_eq!(&out, &weights);
        // The record alone.
        prop_assert_eq!(LearnerState::from_bytes(&state.to_bytes()).unwrap(), state.clone());

        let mut l = new_learner(PolicyKind::Sarsa, 0);
        prop_assert_eq!(l.load(&store, HASH), outcome);
        prop_assert_eq!(l.state(), LearnerState { wear: FlashWear::default(), ..state });
        prop_assert_eq!(&l.agent.weights()[..], &weights[..]);
    }

    /// Reachable fatigue states pass the check (the invariants the check
    /// enforces hold along any torque sequence).
    #[test]
    fn reachable_fatigue_states_are_valid(torques in prop::collection::vec(prop_oneof![Just(0.0f32), -2.0f32..2.0], 0..200)) {
        let mut c = FatigueCounter::<1>::new(GearboxParams::TABLE_I, 0.05, Some(WINDOW)).unwrap();
        for t in torques {
            c.update(&[t]).unwrap();
            prop_assert_eq!(c.check_state(&c.state()), Ok(()));
        }
    }
}

// ---------------------------------------------------------------------------
// Refused states
// ---------------------------------------------------------------------------

/// A state saved by a learner, then changed by `change`, is refused naming
/// `field`: directly, through a checkpoint (outcome `InvalidState`), and in
/// both cases the learner — state and weights — is unchanged.
fn assert_refused(change: impl Fn(&mut LearnerState), field: &str) {
    let mut saver = trained(PolicyKind::Pada { delta: 0.5 }, 8, 400);
    saver.finish_episode();
    let mut bad = saver.state();
    change(&mut bad);

    let mut l = trained(PolicyKind::Sarsa, 9, 200);
    let before = l.fingerprint();
    assert_eq!(l.check(&bad), Err(field), "check of {field}");
    assert_eq!(l.restore(&bad), Err(field), "restore of {field}");
    assert_eq!(l.fingerprint(), before, "{field}: a refused restore changed the learner");

    let mut store = Store::new();
    save(&mut store, HASH, &bad, saver.agent.weights()).unwrap();
    assert_eq!(l.load(&store, HASH), LoadOutcome::InvalidState, "{field}");
    assert_eq!(l.fingerprint(), before, "{field}: a refused checkpoint changed the learner");
}

#[test]
fn each_field_out_of_range_is_refused_by_name() {
    // ε.
    for e in [-0.01, 1.01, f32::NAN, f32::INFINITY] {
        assert_refused(|s| s.agent.epsilon = e, "epsilon");
    }
    // Δ and α of the policy.
    assert_refused(|s| s.agent.policy.kind = PolicyKind::Pada { delta: -0.5 }, "delta");
    assert_refused(|s| s.agent.policy.kind = PolicyKind::Pada { delta: f32::NAN }, "delta");
    assert_refused(|s| s.agent.policy.kind = PolicyKind::LowPass { alpha: 0.0 }, "lowpass alpha");
    assert_refused(|s| s.agent.policy.kind = PolicyKind::LowPass { alpha: 1.5 }, "lowpass alpha");
    // A policy whose learner means something else by an action or a state.
    assert_refused(|s| s.agent.policy.kind = PolicyKind::Integrator { delta: 0.5 }, "policy.kind");
    assert_refused(|s| s.agent.policy.kind = PolicyKind::MarkovLowPass { alpha: 0.5 }, "policy.kind");
    // Only PADA and the low-pass filter switch back.
    assert_refused(
        |s| {
            s.agent.policy.kind = PolicyKind::Sarsa;
            s.agent.policy.switched = true;
        },
        "policy.switched",
    );
    // Action indices within the action space (3 levels, 2 dimensions).
    assert_refused(|s| s.agent.policy.previous[0] = 3, "policy.previous");
    assert_refused(|s| s.agent.policy.previous[1] = 200, "policy.previous");
    assert_refused(|s| s.agent.policy.previous[2] = 1, "policy.previous");
    // The filter's memory inside the motor's range.
    assert_refused(|s| s.agent.policy.output[0] = 1.5, "policy.output");
    assert_refused(|s| s.agent.policy.output[1] = f32::NAN, "policy.output");
    assert_refused(|s| s.agent.policy.output[3] = 0.5, "policy.output");
    // Counters that cannot have happened.
    assert_refused(|s| s.agent.stats.explorations = s.agent.stats.steps + 1, "stats.explorations");
    assert_refused(|s| s.agent.stats.updates = s.agent.stats.steps + 1, "stats.updates");
    // The generator.
    assert_refused(|s| s.rng.increment &= !1, "rng.increment");
    // Fatigue, per joint and across joints.
    assert_refused(|s| s.joints[1].last_sign = 2, "last_sign");
    assert_refused(|s| s.joints[0].reengagements = s.joints[0].steps, "reengagements");
    assert_refused(
        |s| {
            s.joints[2].reengagements = 0;
            s.joints[2].window_reengagements = 0;
            s.joints[2].window_damage_raw = 0;
            s.joints[2].damage_raw = 5;
        },
        "damage_raw",
    );
    assert_refused(|s| s.joints[0].window_reengagements = WINDOW as u64, "window_reengagements");
    assert_refused(|s| s.joints[0].window_damage_raw = s.joints[0].damage_raw + 1, "window_damage_raw");
    assert_refused(|s| s.joints[1].steps += 1, "steps");
    assert_refused(|s| { s.joints.pop(); }, "joints");
}

/// Writes a slot by hand: header of `version` (its own CRC right), then the
/// payload with a correct payload CRC.
fn write_raw(store: &mut Store, slot: u8, version: u16, generation: u32, record: &[u8], weights: &[Q16]) {
    let mut payload = record.to_vec();
    for w in weights {
        payload.extend_from_slice(&w.0.to_le_bytes());
    }
    let header = Header {
        version,
        config_hash: HASH,
        weight_count: weights.len() as u32,
        generation,
        payload_crc: crc32(&payload),
        state_len: record.len() as u32,
        weight_bytes: 4,
    };
    let s = store.slot_mut(slot).unwrap();
    s.fill(0xFF);
    s[..HEADER_LEN].copy_from_slice(&header.to_bytes());
    s[HEADER_LEN..HEADER_LEN + payload.len()].copy_from_slice(&payload);
}

#[test]
fn records_that_cannot_be_decoded_are_refused_by_name() {
    let good = trained(PolicyKind::Pada { delta: 0.5 }, 3, 300).state().to_bytes();
    let cases: [(usize, u8, &str); 11] = [
        (0, 2, "state.version"),   // record version 2 (before the governor)
        (2, 2, "mode"),            // mode 2
        (3, 10, "policy.kind"),    // kind 10
        (8, 2, "policy.switched"), // switched 2
        (9, 9, "joints"),          // 9 joints
        (14, 1, "state.reserved"),
        (77, 1, "policy.parameter2"), // a second parameter for PADA
        (112 + 3, 1, "fatigue.reserved"),
        (112 + 3 * 48 + 8, 1, "fatigue"), // an unused entry not 0
        (512, 2, "governor"),             // governor flag 2
        (700, 1, "governor"),             // governor bytes without a governor
    ];
    for (offset, value, field) in cases {
        let mut record = good;
        record[offset] = value;
        assert_eq!(LearnerState::from_bytes(&record).map(|_| ()).unwrap_err().param, field, "byte {offset}");
        // In a checkpoint with correct CRCs: refused, nothing written.
        let mut store = Store::new();
        let w = vec![Q16(3); WEIGHTS];
        write_raw(&mut store, 0, FORMAT_VERSION, 1, &record, &w);
        let mut st = LearnerState::default();
        let mut out = vec![Q16(5); WEIGHTS];
        assert_eq!(load(&store, HASH, &mut st, &mut out), Ok(LoadOutcome::InvalidState), "{field}");
        assert_eq!(st, LearnerState::default());
        assert!(out.iter().all(|w| *w == Q16(5)));
    }
    // A governor's block: its restriction code and reserved bytes.
    let mut governed = trained(PolicyKind::Pada { delta: 0.5 }, 3, 300).state();
    governed.governor = Some(GovernorState {
        budget_bits: 2600.0f32.to_bits(),
        restricts: Restricts::Delta,
        rung: 1,
        cursor: 3,
        filled: 3,
        in_bucket: 7,
        calm_steps: 2,
        since_move: 4,
        headroom_at_move: -3,
        moves: 5,
        steps: 307,
        over_budget_steps: 0,
        buckets: [[1 << 30; 12], [0; 12], [0; 12], [0; 12]],
    });
    let bytes = governed.to_bytes();
    assert_eq!(LearnerState::from_bytes(&bytes).unwrap(), governed);
    for (offset, value, field) in [(513, 2, "governor.restricts"), (518, 1, "governor.reserved"), (1000, 1, "state.reserved")] {
        let mut record = bytes;
        record[offset] = value;
        assert_eq!(LearnerState::from_bytes(&record).map(|_| ()).unwrap_err().param, field, "byte {offset}");
    }
    // SARSA has no parameter: one stored is not silently dropped.
    let mut record = good;
    record[3] = 0;
    let e: ConfigError = LearnerState::from_bytes(&record).unwrap_err();
    assert_eq!(e.param, "policy.parameter");
    // A record of another length.
    let mut store = Store::new();
    write_raw(&mut store, 0, FORMAT_VERSION, 1, &good[..STATE_LEN - 4], &vec![Q16(3); WEIGHTS]);
    let mut st = LearnerState::default();
    let mut out = vec![Q16(5); WEIGHTS];
    assert_eq!(load(&store, HASH, &mut st, &mut out), Ok(LoadOutcome::InvalidState));
    assert!(out.iter().all(|w| *w == Q16(5)));
}

// ---------------------------------------------------------------------------
// Format 1
// ---------------------------------------------------------------------------

#[test]
fn a_version_1_checkpoint_is_refused_not_loaded_without_its_state() {
    // Format 1: the header with bytes 24..28 reserved 0, then the weights.
    let v1_weights = vec![Q16(77); WEIGHTS];
    let mut store = Store::new();
    write_raw(&mut store, 0, 1, 1, &[], &v1_weights);
    assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::UnsupportedVersion { found: 1 })));
    let mut l = trained(PolicyKind::Sarsa, 1, 100);
    let before = l.fingerprint();
    assert_eq!(l.load(&store, HASH), LoadOutcome::UnsupportedVersion { found: 1 });
    assert_eq!(l.fingerprint(), before);
    let mut st = LearnerState::default();
    let mut out = vec![Q16(5); WEIGHTS];
    assert_eq!(load(&store, HASH, &mut st, &mut out), Ok(LoadOutcome::UnsupportedVersion { found: 1 }));
    assert_eq!(st, LearnerState::default());
    assert!(out.iter().all(|w| *w == Q16(5)));

    // Next to a format-2 checkpoint, even an older one, the format-2 one loads.
    let mut store = Store::new();
    write_raw(&mut store, 0, 1, 7, &[], &v1_weights);
    let saver = trained(PolicyKind::Sarsa, 2, 300);
    write_raw(&mut store, 1, FORMAT_VERSION, 3, &saver.state().to_bytes(), saver.agent.weights());
    assert_eq!(l.load(&store, HASH), LoadOutcome::Loaded { generation: 3, slot: 1 });
    assert_eq!(l.fingerprint(), saver.fingerprint());

    // A save where only a format-1 checkpoint is starts over at generation 1
    // in slot 0.
    let mut store = Store::new();
    write_raw(&mut store, 1, 1, 7, &[], &v1_weights);
    assert_eq!(saver.save(&mut store), Saved { generation: 1, slot: 0, erases: 1 });
    assert_eq!(l.load(&store, HASH), LoadOutcome::Loaded { generation: 1, slot: 0 });
}

// ---------------------------------------------------------------------------
// Torn writes
// ---------------------------------------------------------------------------

#[test]
fn a_save_torn_inside_the_state_record_keeps_the_previous_checkpoint() {
    let mut a = trained(PolicyKind::Pada { delta: 0.5 }, 6, 500);
    let mut base = Store::new();
    a.save(&mut base);
    let first = a.fingerprint();
    for _ in 0..500 {
        a.tick();
    }
    let second = a.state();
    assert_ne!(second, first.0);
    // Every byte of the state record (written first), then a few of the
    // weights and of the header (written last).
    let budgets = (0..=STATE_LEN).chain([STATE_LEN + 1, STATE_LEN + 2000, slot_len(WEIGHTS, 4) - HEADER_LEN + 5, slot_len(WEIGHTS, 4) - 1]);
    for budget in budgets {
        let mut torn = TornStore::new(base.clone(), budget);
        assert!(save(&mut torn, HASH, &second, a.agent.weights()).is_err(), "budget {budget}");
        let mut b = new_learner(PolicyKind::Sarsa, 42);
        assert_eq!(b.load(&torn.inner, HASH), LoadOutcome::Loaded { generation: 1, slot: 0 }, "budget {budget}");
        assert_eq!(b.fingerprint(), first, "budget {budget}");
    }
    // Uninterrupted, the second save loads.
    let mut store = base;
    assert_eq!(a.save(&mut store), Saved { generation: 2, slot: 1, erases: 1 });
    let mut b = new_learner(PolicyKind::Sarsa, 42);
    assert_eq!(b.load(&store, HASH), LoadOutcome::Loaded { generation: 2, slot: 1 });
    assert_eq!(b.state(), second);
}

// ---------------------------------------------------------------------------
// Configuration mismatch
// ---------------------------------------------------------------------------

#[test]
fn a_configuration_mismatch_leaves_weights_and_state_untouched() {
    let a = trained(PolicyKind::Pada { delta: 0.5 }, 11, 1000);
    let mut store = Store::new();
    a.save(&mut store);
    let mut l = trained(PolicyKind::Sarsa, 12, 300);
    let before = l.fingerprint();
    let other = HASH ^ 1;
    assert_eq!(l.load(&store, other), LoadOutcome::ConfigMismatch { expected: other, found: HASH });
    assert_eq!(l.fingerprint(), before);
    let mut st = LearnerState::default();
    let mut out = vec![Q16(5); WEIGHTS];
    assert_eq!(load(&store, other, &mut st, &mut out), Ok(LoadOutcome::ConfigMismatch { expected: other, found: HASH }));
    assert_eq!(st, LearnerState::default());
    assert!(out.iter().all(|w| *w == Q16(5)));
    // And with the right hash it loads.
    assert!(matches!(l.load(&store, HASH), LoadOutcome::Loaded { .. }));
    assert_eq!(l.fingerprint(), a.fingerprint());
}
