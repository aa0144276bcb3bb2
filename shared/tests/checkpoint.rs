//! Checkpoints: round trip, alternating slots, torn writes at every byte
//! (state record, weights and header), configuration and size mismatches,
//! corruption. The learner-state record itself: `learner_state.rs`.

mod support;
use support::TornStore;
use pada_core::checkpoint::*;
use pada_core::fatigue::JointFatigueState;
use pada_core::fixed::Q16;

const N: usize = 100;
const SLOT: usize = slot_len(N, 4) + 16;
type Store = RamStore<SLOT>;

fn weights(seed: i32) -> Vec<Q16> {
    (0..N as i32).map(|i| Q16(i.wrapping_mul(0x0101_0101).wrapping_add(seed) ^ (seed << 7))).collect()
}

/// A learner state that differs with `seed` in every part of the record.
fn state(seed: u32) -> LearnerState {
    let mut s = LearnerState::default();
    s.agent.stats.steps = 1000 * seed as u64;
    s.agent.stats.episodes = seed;
    s.agent.epsilon = 0.05;
    s.rng.state = 0x1234_5678_9abc_def0 ^ seed as u64;
    s.rng.increment = 0x0f0f_0f0f_0f0f_0f0f | 1;
    s.user = [seed, 2 * seed, 0, 7];
    for j in 0..3u64 {
        let f = JointFatigueState { last_sign: 1, steps: 50 + seed as u64, reengagements: j + seed as u64, damage_raw: 99 * j, ..Default::default() };
        s.joints.push(f).unwrap();
    }
    s
}

/// Saves `weights(seed)` with `state(seed)`.
fn save_seed<S: CheckpointStore>(store: &mut S, hash: u32, seed: u32) -> Result<Saved, SaveError<S::Error>> {
    save(store, hash, &state(seed), &weights(seed as i32))
}

/// Loads into fresh buffers: (outcome, state, weights). The state's flash
/// wear, which `save` fills in, is cleared so that it compares with the
/// `state(seed)` saved (the wear has tests of its own).
fn load_all(store: &impl CheckpointStore, hash: u32) -> (LoadOutcome, LearnerState, Vec<Q16>) {
    let mut st = LearnerState::default();
    let mut out = vec![Q16(5); N];
    let outcome = load(store, hash, &mut st, &mut out).unwrap_or_else(|_| panic!("store error"));
    st.wear = FlashWear::default();
    (outcome, st, out)
}

#[test]
fn save_then_load_round_trips() {
    let mut store = Store::new();
    assert_eq!(save_seed(&mut store, 42, 1), Ok(Saved { generation: 1, slot: 0, erases: 1 }));
    let (outcome, st, out) = load_all(&store, 42);
    assert_eq!(outcome, LoadOutcome::Loaded { generation: 1, slot: 0 });
    assert_eq!(out, weights(1));
    assert_eq!(st, state(1));
}

#[test]
fn saves_alternate_slots_and_load_takes_the_newest() {
    let mut store = Store::new();
    for g in 1..=6u32 {
        let saved = save_seed(&mut store, 42, g).unwrap();
        assert_eq!(saved, Saved { generation: g, slot: ((g - 1) % 2) as u8, erases: g.div_ceil(2) });
        let (outcome, st, out) = load_all(&store, 42);
        assert_eq!(outcome, LoadOutcome::Loaded { generation: g, slot: saved.slot });
        assert_eq!(out, weights(g as i32));
        assert_eq!(st, state(g));
    }
}

#[test]
fn empty_store_has_no_checkpoint_and_weights_stay() {
    let store = Store::new();
    let (outcome, st, out) = load_all(&store, 42);
    assert_eq!(outcome, LoadOutcome::NoCheckpoint);
    assert!(out.iter().all(|w| *w == Q16(5)));
    assert_eq!(st, LearnerState::default());
}

#[test]
fn config_mismatch_is_reported_and_weights_stay() {
    let mut store = Store::new();
    save_seed(&mut store, config_hash(b"pendulum; tilings 16"), 1).unwrap();
    let running = config_hash(b"pendulum; tilings 8");
    let (outcome, st, out) = load_all(&store, running);
    assert_eq!(outcome, LoadOutcome::ConfigMismatch { expected: running, found: config_hash(b"pendulum; tilings 16") });
    assert!(out.iter().all(|w| *w == Q16(5)));
    assert_eq!(st, LearnerState::default());
}

#[test]
fn size_mismatch_is_reported() {
    let mut store = Store::new();
    save(&mut store, 42, &state(1), &weights(1)[..50]).unwrap();
    let (outcome, st, out) = load_all(&store, 42);
    assert_eq!(outcome, LoadOutcome::SizeMismatch { expected: N as u32, found: 50 });
    assert!(out.iter().all(|w| *w == Q16(5)));
    assert_eq!(st, LearnerState::default());
}

#[test]
fn too_large_is_refused_before_touching_the_store() {
    let mut store = RamStore::<600>::new();
    assert_eq!(save_seed(&mut store, 1, 1), Err(SaveError::TooLarge { needed: slot_len(N, 4), capacity: 600 }));
    assert!(store.slot(0).unwrap().iter().all(|&b| b == 0xFF));
}

#[test]
fn a_corrupted_payload_is_rejected() {
    // The only checkpoint: a single-bit flip in the state record or the
    // weights is caught.
    let state_at = HEADER_LEN;
    let weights_at = HEADER_LEN + STATE_LEN;
    for byte in [state_at, state_at + 1, state_at + 33, state_at + 200, weights_at - 1, weights_at, weights_at + 200, slot_len(N, 4) - 1] {
        let mut store = Store::new();
        save_seed(&mut store, 42, 1).unwrap();
        store.slot_mut(0).unwrap()[byte] ^= 0x10;
        let (outcome, st, out) = load_all(&store, 42);
        assert_eq!(outcome, LoadOutcome::Corrupt, "flip at {byte}");
        assert!(out.iter().all(|w| *w == Q16(5)));
        assert_eq!(st, LearnerState::default());
        assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
    }
}

#[test]
fn a_corrupted_newest_checkpoint_falls_back_to_the_older() {
    for byte in [HEADER_LEN + 17, HEADER_LEN + STATE_LEN + 17] {
        let mut store = Store::new();
        save_seed(&mut store, 42, 1).unwrap();
        save_seed(&mut store, 42, 2).unwrap();
        store.slot_mut(1).unwrap()[byte] ^= 0x01;
        let (outcome, st, out) = load_all(&store, 42);
        assert_eq!(outcome, LoadOutcome::Loaded { generation: 1, slot: 0 }, "flip at {byte}");
        assert_eq!(out, weights(1));
        assert_eq!(st, state(1));
        // The next save overwrites the corrupted slot, not the good one.
        assert_eq!(save_seed(&mut store, 42, 2), Ok(Saved { generation: 2, slot: 1, erases: 1 }));
    }
}

#[test]
fn a_future_format_is_reported() {
    let mut store = Store::new();
    let h = Header {
        version: FORMAT_VERSION + 1,
        config_hash: 1,
        weight_count: 0,
        generation: 1,
        payload_crc: 0,
        state_len: 0,
        weight_bytes: 4,
    };
    store.write_bytes(0, &h.to_bytes());
    let (outcome, ..) = load_all(&store, 1);
    assert_eq!(outcome, LoadOutcome::UnsupportedVersion { found: FORMAT_VERSION + 1 });
}

/// Helper: raw writes into a RAM store.
trait WriteBytes {
    fn write_bytes(&mut self, slot: u8, data: &[u8]);
}
impl WriteBytes for Store {
    fn write_bytes(&mut self, slot: u8, data: &[u8]) {
        self.slot_mut(slot).unwrap()[..data.len()].copy_from_slice(data);
    }
}

/// Bytes `save` writes, in order: the state record, the weights, the header.
const WRITTEN: usize = STATE_LEN + N * 4 + HEADER_LEN;

#[test]
fn a_torn_second_save_at_every_byte_keeps_the_first() {
    // Budgets 0..STATE_LEN cut the save inside the state record, then inside
    // the weights, then inside the header.
    assert_eq!(WRITTEN, slot_len(N, 4));
    for budget in 0..WRITTEN {
        let mut base = Store::new();
        save_seed(&mut base, 42, 1).unwrap();
        let mut torn = TornStore::new(base, budget);
        let r = save_seed(&mut torn, 42, 2);
        assert!(r.is_err(), "budget {budget}: a torn save must not report success");
        // After the power cut: the first checkpoint loads, state and weights.
        let (outcome, st, out) = load_all(&torn.inner, 42);
        assert_eq!(outcome, LoadOutcome::Loaded { generation: 1, slot: 0 }, "budget {budget}");
        assert_eq!(out, weights(1), "budget {budget}");
        assert_eq!(st, state(1), "budget {budget}");
        // And the next save goes to the torn slot again and succeeds.
        let mut store = torn.inner;
        assert_eq!(save_seed(&mut store, 42, 2), Ok(Saved { generation: 2, slot: 1, erases: 1 }), "budget {budget}");
        assert_eq!(load_all(&store, 42).1, state(2), "budget {budget}");
    }
    // With the whole budget the save completes.
    let mut base = Store::new();
    save_seed(&mut base, 42, 1).unwrap();
    let mut full = TornStore::new(base, WRITTEN);
    assert_eq!(save_seed(&mut full, 42, 2), Ok(Saved { generation: 2, slot: 1, erases: 1 }));
}

#[test]
fn a_torn_third_save_keeps_the_second() {
    // The same from the other slot: torn writes into slot 0 while slot 1
    // holds the newest.
    for budget in (0..WRITTEN).step_by(7) {
        let mut base = Store::new();
        save_seed(&mut base, 42, 1).unwrap();
        save_seed(&mut base, 42, 2).unwrap();
        let mut torn = TornStore::new(base, budget);
        assert!(save_seed(&mut torn, 42, 3).is_err());
        let (outcome, st, out) = load_all(&torn.inner, 42);
        assert_eq!(outcome, LoadOutcome::Loaded { generation: 2, slot: 1 });
        assert_eq!(out, weights(2));
        assert_eq!(st, state(2));
    }
}

#[test]
fn garbage_slots_are_corrupt_not_empty() {
    let mut store = Store::new();
    store.slot_mut(0).unwrap().fill(0x00);
    assert_eq!(load_all(&store, 1).0, LoadOutcome::Corrupt);
    // A valid checkpoint next to garbage still loads.
    save_seed(&mut store, 1, 9).unwrap();
    assert!(matches!(load_all(&store, 1).0, LoadOutcome::Loaded { generation: 1, .. }));
}

#[test]
fn header_claiming_more_weights_than_fit_is_corrupt() {
    let mut store = Store::new();
    let h = Header {
        version: FORMAT_VERSION,
        config_hash: 1,
        weight_count: u32::MAX,
        generation: 5,
        payload_crc: 0,
        state_len: STATE_LEN as u32,
        weight_bytes: 4,
    };
    store.write_bytes(0, &h.to_bytes());
    assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
    let h = Header { weight_count: 0, state_len: u16::MAX as u32, ..h };
    store.write_bytes(0, &h.to_bytes());
    assert_eq!(inspect(&store, 0), Ok(SlotStatus::Invalid(HeaderError::Corrupt)));
}

#[test]
fn saving_goes_on_past_the_largest_generation() {
    // Regression: the generation saturated at u32::MAX
    // and, with a strict `>`, every later save was lost and loading
    // returned the older slot. Start just below the wrap by writing a
    // checkpoint of generation u32::MAX - 2 by hand.
    let mut store = Store::new();
    save_seed(&mut store, 42, 1).unwrap();
    let mut h = Header::parse(store.slot(0).unwrap()[..HEADER_LEN].try_into().unwrap()).unwrap();
    h.generation = u32::MAX - 2;
    store.slot_mut(0).unwrap()[..HEADER_LEN].copy_from_slice(&h.to_bytes());
    let mut expected = u32::MAX - 2;
    for seed in 2..=8u32 {
        expected = expected.wrapping_add(1);
        let saved = save_seed(&mut store, 42, seed).unwrap();
        assert_eq!(saved.generation, expected, "seed {seed}");
        let (outcome, st, out) = load_all(&store, 42);
        assert_eq!(outcome, LoadOutcome::Loaded { generation: expected, slot: saved.slot }, "seed {seed}");
        assert_eq!((st, out), (state(seed), weights(seed as i32)), "seed {seed}: the newest loads");
    }
    assert_eq!(expected, 4, "wrapped through u32::MAX and 0");
    assert!(is_newer(0, u32::MAX) && is_newer(1, u32::MAX - 1) && !is_newer(u32::MAX, 0) && !is_newer(5, 5));
}

#[test]
fn a_never_written_store_smaller_than_a_header_is_empty() {
    // Regression: it loaded as Corrupt.
    let tiny = RamStore::<{ HEADER_LEN - 1 }>::new();
    let mut st = LearnerState::default();
    let mut out = vec![Q16(5); N];
    assert_eq!(load(&tiny, 42, &mut st, &mut out), Ok(LoadOutcome::NoCheckpoint));
    let mut tiny = RamStore::<4>::new();
    tiny.slot_mut(1).unwrap()[2] = 0;
    assert_eq!(load(&tiny, 42, &mut st, &mut out), Ok(LoadOutcome::Corrupt), "a written byte is not erased flash");
    let mut tiny = RamStore::<4>::new();
    assert!(matches!(save_seed(&mut tiny, 42, 1), Err(SaveError::TooLarge { .. })));
}

#[test]
fn erases_are_counted_in_the_record_across_configurations() {
    let mut store = Store::new();
    for g in 1..=5u32 {
        save_seed(&mut store, 42, g).unwrap();
    }
    let wear = stored_wear(&store).unwrap();
    assert_eq!(wear.erases, [3, 2]);
    // Another configuration's save carries the counts on; so does a state
    // that brings its own (higher) counts and operating time.
    let mut s = state(9);
    s.wear = FlashWear { erases: [1, 7], operating_s: 3600 };
    let saved = save(&mut store, 7, &s, &weights(9)).unwrap();
    assert_eq!(saved, Saved { generation: 6, slot: 1, erases: 8 });
    assert_eq!(stored_wear(&store).unwrap(), FlashWear { erases: [3, 8], operating_s: 3600 });
    // The loaded state reports them.
    let mut st = LearnerState::default();
    let mut out = vec![Q16::ZERO; N];
    load(&store, 7, &mut st, &mut out).unwrap();
    assert_eq!(st.wear.erases, [3, 8]);
}

#[test]
fn a_save_beyond_the_wear_budget_is_refused_before_anything_is_erased() {
    let budget = WearBudget::new(6, 2, 4000).unwrap();
    let mut store = Store::new();
    let mut s = state(1);
    // The reserve: two erases per slot at operating time 0.
    for _ in 0..4 {
        save_within(&mut store, 42, &s, &weights(1), &budget).unwrap();
    }
    let before = store.clone();
    let r = save_within(&mut store, 42, &s, &weights(1), &budget);
    assert_eq!(r, Err(SaveError::Wear(WearRefusal::TooSoon { erases: 2, allowed: 2, retry_in_s: 1000 })));
    assert_eq!(store.slot(0), before.slot(0));
    assert_eq!(store.slot(1), before.slot(1));
    // After 1000 s of operation one more erase per slot is allowed.
    s.wear.operating_s = 1000;
    assert_eq!(save_within(&mut store, 42, &s, &weights(1), &budget).unwrap().erases, 3);
    // At the end of the lifetime the endurance is reached, and then refused.
    s.wear.operating_s = 10_000;
    while save_within(&mut store, 42, &s, &weights(1), &budget).is_ok() {}
    assert_eq!(stored_wear(&store).unwrap().erases, [6, 6]);
    assert_eq!(save_within(&mut store, 42, &s, &weights(1), &budget), Err(SaveError::Wear(WearRefusal::WornOut { erases: 6 })));
}

/// A RAM store that counts the erases of each slot's sector, as the flash
/// wears whatever a save makes of them.
#[derive(Clone)]
struct Counting {
    inner: Store,
    erases: [u32; 2],
}

impl Counting {
    fn new() -> Self {
        Counting { inner: Store::new(), erases: [0; 2] }
    }
}

impl CheckpointStore for Counting {
    type Error = OutOfRange;
    fn capacity(&self) -> usize {
        self.inner.capacity()
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), OutOfRange> {
        self.inner.read(slot, offset, buf)
    }
    fn erase(&mut self, slot: u8) -> Result<(), OutOfRange> {
        if let Some(n) = self.erases.get_mut(slot as usize) {
            *n += 1;
        }
        self.inner.erase(slot)
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), OutOfRange> {
        self.inner.write(slot, offset, data)
    }
}

#[test]
fn a_table_of_six_byte_entries_is_refused_before_anything_is_erased() {
    use pada_core::claim_table::{ClaimTable, Tags16, Tags32};
    use pada_core::weights::{Half, WeightStore};
    // Q16 weights with 16-bit tags, and 16-bit weights with 32-bit tags:
    // 6 bytes an entry, which no header can describe.
    let mut q16_tag16 = ClaimTable::new(vec![Q16::ZERO; 16], Tags16(vec![0u16; 16])).unwrap();
    q16_tag16.claim(77);
    let half_tag32 = ClaimTable::new(Half::<_, 12>::new(vec![0i16; 16]), Tags32(vec![0u32; 16])).unwrap();
    assert_eq!((q16_tag16.entry_bytes(), half_tag32.entry_bytes()), (6, 6));
    let budget = WearBudget::new(5, 2, 1_000_000).unwrap();
    let mut store = Counting::new();
    let s = state(1);
    for _ in 0..10 {
        for r in [
            save_within(&mut store, 42, &s, &q16_tag16, &budget),
            save_within(&mut store, 42, &s, &half_tag32, &budget),
            save(&mut store, 42, &s, &q16_tag16),
        ] {
            assert_eq!(r, Err(SaveError::EntryBytes { found: 6 }));
        }
    }
    assert_eq!(store.erases, [0, 0], "a save that cannot be written erased a sector");
    let why = SaveError::<OutOfRange>::EntryBytes { found: 6 }.to_string();
    assert!(why.contains("6 bytes") && why.contains("valid are 2, 4 or 8"), "{why}");
    // Every erase the store saw is in the record of the next good save.
    save(&mut store, 42, &s, &weights(1)).unwrap();
    assert_eq!(stored_wear(&store).unwrap().erases, store.erases);
}

#[test]
fn an_erase_made_by_a_save_that_fails_afterwards_is_counted() {
    // A save cut after its erase (the store fails on the 10th byte
    // written) leaves no valid record of that erase in the slot: the error
    // carries the count, and a caller that keeps it (as the firmware's
    // controller does) has it recorded by its next save.
    let mut store = Counting::new();
    let mut s = state(1);
    let first = save(&mut store, 42, &s, &weights(1)).unwrap();
    assert_eq!((first.slot, first.erases), (0, 1));
    let mut torn = TornStore::new(store.clone(), 10);
    let r = save(&mut torn, 42, &s, &weights(2));
    assert!(matches!(r, Err(SaveError::StoreAfterErase { slot: 1, erases: 1, .. })), "{r:?}");
    let (slot, erases) = r.unwrap_err().erased().unwrap();
    store = torn.inner;
    assert_eq!(store.erases, [1, 1]);
    assert_eq!(stored_wear(&store).unwrap().erases, [1, 0], "the slot holds no record of the erase");
    s.wear.erases[slot as usize] = s.wear.erases[slot as usize].max(erases);
    let next = save(&mut store, 42, &s, &weights(2)).unwrap();
    assert_eq!((next.slot, next.erases), (1, 2));
    assert_eq!(stored_wear(&store).unwrap().erases, [1, 2], "every erase the flash saw is in the record");
    // Saves that erase nothing say so.
    assert_eq!(SaveError::<()>::EntryBytes { found: 6 }.erased(), None);
    assert_eq!(SaveError::<()>::Store(()).erased(), None);
    assert_eq!(SaveError::<()>::VerifyFailed { slot: 0, erases: 3 }.erased(), Some((0, 3)));
}
