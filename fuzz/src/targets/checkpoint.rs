//! Checkpoint loading from damaged or random slots, saves torn by a power
//! cut at any byte (of the erase or of the writes), and the flash wear of
//! a run of saves of any table.
//!
//! An input is a scenario: byte 0 picks the mode, bytes 1–8 seed the
//! states, weights and damage, bytes 9–12 are the power cut's byte budget.
//! So a failing input in `target/fuzz-failures/` replays exactly.
//!
//! The wear mode (4) saves one of six tables (2, 4, 6 or 8 bytes an entry:
//! weights alone, or claim tables of every weight and tag width) again and
//! again under a small erase budget, some saves cut by a power loss, as a
//! caller that keeps what each save reports. Invariants: a table of 6-byte
//! entries is refused with `SaveError::EntryBytes` and any other table is
//! not; a save that says it erased nothing left the store as it was; every
//! erase the flash saw is in the newest record or in what the caller kept
//! from a failed save's report; no sector is erased beyond the budget.

use super::{ensure, Outcome, Target};
use crate::gen::below;
use pada_core::checkpoint::*;
use pada_core::fatigue::JointFatigueState;
use pada_core::fixed::Q16;
use pada_core::policy::PolicyName;
use pada_core::weights::WeightStore;
use rand_core::{RngCore, SeedableRng};

const WEIGHTS: usize = 64;
const SLOT: usize = slot_len(WEIGHTS, 4) + 8;
type Store = RamStore<SLOT>;
const HASH: u32 = 42;

pub struct Checkpoints {
    name: &'static str,
}

impl Checkpoints {
    pub fn new(name: &'static str) -> Self {
        Checkpoints { name }
    }
}

/// A learner state whose record decodes: random counters, codes in range,
/// reserved bytes zero.
fn state(rng: &mut impl RngCore) -> LearnerState {
    let mut s = LearnerState::default();
    let a = &mut s.agent;
    a.stats.steps = rng.next_u64();
    a.stats.updates = rng.next_u64();
    a.stats.explorations = rng.next_u64();
    a.stats.episodes = rng.next_u32();
    a.stats.last_td_error = Q16(rng.next_u32() as i32);
    a.epsilon = f32::from_bits(rng.next_u32());
    let name = PolicyName::ALL[below(rng, 6)];
    a.policy.kind = name.with_parameter(if name == PolicyName::Sarsa {
        0.0
    } else {
        f32::from_bits(rng.next_u32())
    });
    a.policy.switched = rng.next_u32() & 1 == 1;
    a.policy.previous = (rng.next_u32()).to_le_bytes();
    a.policy.output = core::array::from_fn(|_| f32::from_bits(rng.next_u32()));
    s.rng.state = rng.next_u64();
    s.rng.increment = rng.next_u64();
    s.user = core::array::from_fn(|_| rng.next_u32());
    for _ in 0..below(rng, RECORD_JOINTS + 1) {
        let j = JointFatigueState {
            last_sign: [-1i8, 0, 1][below(rng, 3)],
            steps: rng.next_u64(),
            reengagements: rng.next_u64(),
            damage_raw: rng.next_u64(),
            window_reengagements: rng.next_u64(),
            window_damage_raw: rng.next_u64(),
        };
        let _ = s.joints.push(j);
    }
    s.wear = FlashWear {
        erases: [rng.next_u32() >> 8, rng.next_u32() >> 8],
        operating_s: rng.next_u64() >> 8,
    };
    s
}

fn weights(rng: &mut impl RngCore) -> Vec<Q16> {
    (0..WEIGHTS).map(|_| Q16(rng.next_u32() as i32)).collect()
}

/// A store that loses power after `budget` more bytes of work: a write is
/// cut at that byte, an erase (which costs `SLOT` bytes of budget) leaves
/// the erased prefix it reached; every later operation fails.
struct Torn {
    inner: Store,
    budget: usize,
    dead: bool,
    /// Erases begun per slot (a cut one included: it wore the sector).
    erases: [u32; 2],
}

impl Torn {
    fn new(inner: Store, budget: usize) -> Self {
        Torn { inner, budget, dead: false, erases: [0; 2] }
    }
}

#[derive(Debug)]
struct PowerLost;

impl CheckpointStore for Torn {
    type Error = PowerLost;
    fn capacity(&self) -> usize {
        SLOT
    }
    fn read(&self, slot: u8, offset: usize, buf: &mut [u8]) -> Result<(), PowerLost> {
        self.inner.read(slot, offset, buf).map_err(|_| PowerLost)
    }
    fn erase(&mut self, slot: u8) -> Result<(), PowerLost> {
        if self.dead {
            return Err(PowerLost);
        }
        if let Some(n) = self.erases.get_mut(slot as usize) {
            *n += 1;
        }
        if self.budget < SLOT {
            let s = self.inner.slot_mut(slot).ok_or(PowerLost)?;
            s[..self.budget].fill(0xFF);
            self.dead = true;
            return Err(PowerLost);
        }
        self.budget -= SLOT;
        self.inner.erase(slot).map_err(|_| PowerLost)
    }
    fn write(&mut self, slot: u8, offset: usize, data: &[u8]) -> Result<(), PowerLost> {
        if self.dead {
            return Err(PowerLost);
        }
        let n = data.len().min(self.budget);
        self.inner
            .write(slot, offset, &data[..n])
            .map_err(|_| PowerLost)?;
        self.budget -= n;
        if n < data.len() {
            self.dead = true;
            return Err(PowerLost);
        }
        Ok(())
    }
}

/// Loads into fresh buffers; `None` on a store error.
fn load_all(store: &impl CheckpointStore) -> Option<(LoadOutcome, LearnerState, Vec<Q16>)> {
    let mut st = LearnerState::default();
    let mut w = vec![Q16(7); WEIGHTS];
    let outcome = load(store, HASH, &mut st, &mut w).ok()?;
    Some((outcome, st, w))
}

/// Whether two states are the same, ignoring the flash wear (which `save`
/// writes itself); compared as records, so that a NaN ε equals itself.
fn same(a: &LearnerState, b: &LearnerState) -> bool {
    LearnerState {
        wear: b.wear,
        ..a.clone()
    }
    .to_bytes()
        == b.to_bytes()
}

/// Invariant 2 for checkpoints: a loaded record is the one in the slot,
/// byte for byte, and the weights are the slot's.
fn reencodes(store: &Store, outcome: &LoadOutcome, st: &LearnerState) -> Outcome {
    if let LoadOutcome::Loaded { slot, .. } = *outcome {
        let raw = store
            .slot(slot)
            .map(|s| &s[HEADER_LEN..HEADER_LEN + STATE_LEN]);
        ensure!(
            raw == Some(&st.to_bytes()[..]),
            "the loaded record re-encodes differently"
        );
    }
    Outcome::Ok
}

impl Target for Checkpoints {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let mut input = vec![below(rng, 5) as u8];
        input.extend(rng.next_u64().to_le_bytes());
        // A cut anywhere in the erase and the writes of one save.
        input.extend((below(rng, 2 * SLOT + 16) as u32).to_le_bytes());
        input
    }

    fn check(&self, input: &[u8]) -> Outcome {
        let Some((&[mode], rest)) = input.split_first_chunk::<1>() else {
            return Outcome::Ok;
        };
        let Some((seed, rest)) = rest.split_first_chunk::<8>() else {
            return Outcome::Ok;
        };
        let budget = rest
            .first_chunk::<4>()
            .map_or(0, |b| u32::from_le_bytes(*b) as usize);
        let mut rng = rand_pcg::Pcg64::seed_from_u64(u64::from_le_bytes(*seed));
        let (a, wa) = (state(&mut rng), weights(&mut rng));
        let (b, wb) = (state(&mut rng), weights(&mut rng));
        let mut store = Store::new();
        ensure!(
            save(&mut store, HASH, &a, &wa).is_ok(),
            "the first save failed"
        );
        if below(&mut rng, 2) == 0 {
            // A generation about to wrap (a long-lived board, or a counter
            // that started high): the next saves must still be the newer.
            let gen = u32::MAX - below(&mut rng, 3) as u32;
            if let Some(s) = store.slot_mut(0) {
                let head: [u8; HEADER_LEN] = s[..HEADER_LEN].try_into().unwrap_or([0; HEADER_LEN]);
                if let Ok(h) = Header::parse(&head) {
                    s[..HEADER_LEN].copy_from_slice(
                        &Header {
                            generation: gen,
                            ..h
                        }
                        .to_bytes(),
                    );
                }
            }
        }
        match mode {
            // Invariant 4: a save torn at any byte keeps the old or the new.
            0 | 1 => {
                if mode == 1 {
                    // A second checkpoint first, so the torn save overwrites
                    // the older of two.
                    ensure!(
                        save(&mut store, HASH, &a, &wa).is_ok(),
                        "the second save failed"
                    );
                }
                let mut torn = Torn::new(store, budget);
                let saved = save(&mut torn, HASH, &b, &wb).is_ok();
                let Some((outcome, st, w)) = load_all(&torn.inner) else {
                    return Outcome::Failed("load failed on a RAM store".into());
                };
                ensure!(
                    matches!(outcome, LoadOutcome::Loaded { .. }),
                    "cut after {budget} bytes: {outcome:?}"
                );
                let old = same(&st, &a) && w == wa;
                let new = same(&st, &b) && w == wb;
                ensure!(
                    old || new,
                    "cut after {budget} bytes: neither the old nor the new checkpoint loaded"
                );
                ensure!(
                    !saved || new,
                    "the save reported success but the old checkpoint loaded"
                );
                if let Outcome::Failed(f) = reencodes(&torn.inner, &outcome, &st) {
                    return Outcome::Failed(f);
                }
                // The next save after the power cut succeeds and loads.
                let mut store = torn.inner;
                ensure!(
                    save(&mut store, HASH, &b, &wb).is_ok(),
                    "saving after the cut failed"
                );
                let loaded = load_all(&store);
                ensure!(
                    loaded.is_some_and(|(_, st, w)| same(&st, &b) && w == wb),
                    "the save after the cut does not load"
                );
            }
            // Damaged slots: anything that loads is one of the saved
            // checkpoints, byte for byte.
            2 => {
                ensure!(
                    save(&mut store, HASH, &b, &wb).is_ok(),
                    "the second save failed"
                );
                for _ in 0..1 + below(&mut rng, 8) {
                    let slot = below(&mut rng, 2) as u8;
                    let at = below(&mut rng, SLOT);
                    if let Some(s) = store.slot_mut(slot) {
                        s[at] = rng.next_u32() as u8;
                    }
                }
                let Some((outcome, st, w)) = load_all(&store) else {
                    return Outcome::Failed("load failed on a RAM store".into());
                };
                if let LoadOutcome::Loaded { .. } = outcome {
                    ensure!(
                        (same(&st, &a) && w == wa) || (same(&st, &b) && w == wb),
                        "a damaged slot loaded"
                    );
                }
                return reencodes(&store, &outcome, &st);
            }
            4 => return wear(&mut rng),
            // Random slots, some with a valid header over random bytes.
            _ => {
                for slot in 0..2u8 {
                    if let Some(s) = store.slot_mut(slot) {
                        s.iter_mut().for_each(|x| *x = rng.next_u32() as u8);
                    }
                }
                if below(&mut rng, 2) == 0 {
                    let payload: Vec<u8> = store
                        .slot(0)
                        .map(|s| s[HEADER_LEN..slot_len(WEIGHTS, 4)].to_vec())
                        .unwrap_or_default();
                    let h = Header {
                        version: FORMAT_VERSION,
                        config_hash: HASH,
                        weight_count: WEIGHTS as u32,
                        generation: rng.next_u32(),
                        payload_crc: crc32(&payload),
                        state_len: STATE_LEN as u32,
                        weight_bytes: 4,
                    };
                    if let Some(s) = store.slot_mut(0) {
                        s[..HEADER_LEN].copy_from_slice(&h.to_bytes());
                    }
                }
                let Some((outcome, st, _)) = load_all(&store) else {
                    return Outcome::Failed("load failed on a RAM store".into());
                };
                return reencodes(&store, &outcome, &st);
            }
        }
        Outcome::Ok
    }
}

/// The tables the wear mode saves: (entry bytes, table).
fn table(kind: usize, rng: &mut impl RngCore) -> (usize, Box<dyn WeightStore>) {
    use pada_core::claim_table::{ClaimTable, InitialWeights, TagStore, Tags16, Tags32};
    use pada_core::weights::Half;
    fn claimed<W: WeightStore + 'static, T: TagStore + 'static>(
        weights: W,
        tags: T,
        rng: &mut impl RngCore,
    ) -> Box<dyn WeightStore> {
        let mut t = ClaimTable::new(weights, tags).unwrap();
        t.reset(InitialWeights { seed: rng.next_u64(), lo: 0, span: 1 << 16 });
        for _ in 0..below(rng, WEIGHTS) {
            t.claim(rng.next_u32());
        }
        Box::new(t)
    }
    let n = WEIGHTS / 2;
    match kind {
        0 => (4, Box::new(weights(rng))),
        1 => (2, Box::new(Half::<_, 12>::new((0..WEIGHTS).map(|_| rng.next_u32() as i16).collect::<Vec<_>>()))),
        2 => (8, claimed(vec![Q16::ZERO; n], Tags32(vec![0u32; n]), rng)),
        3 => (4, claimed(Half::<_, 12>::new(vec![0i16; n]), Tags16(vec![0u16; n]), rng)),
        4 => (6, claimed(vec![Q16::ZERO; n], Tags16(vec![0u16; n]), rng)),
        _ => (6, claimed(Half::<_, 12>::new(vec![0i16; n]), Tags32(vec![0u32; n]), rng)),
    }
}

/// The wear mode (see the module documentation).
fn wear(rng: &mut impl RngCore) -> Outcome {
    let (entry, table) = table(below(rng, 6), rng);
    ensure!(table.entry_bytes() == entry, "a table of {} bytes an entry, {entry} expected", table.entry_bytes());
    let endurance = 2 + below(rng, 10) as u32;
    let reserve = below(rng, endurance as usize + 1) as u32;
    let Ok(budget) = WearBudget::new(endurance, reserve, 1000) else {
        return Outcome::Failed("a valid budget refused".into());
    };
    let mut store = Store::new();
    // What the flash saw, and what the caller kept of each save's report.
    let mut erased = [0u32; 2];
    let mut kept = FlashWear::default();
    let mut state = state(rng);
    for i in 0..2 + below(rng, 12) {
        state.wear = FlashWear { erases: kept.erases, operating_s: 100 * i as u64 };
        // A third of the saves lose power somewhere in the erase or writes.
        let cut = if below(rng, 3) == 0 { below(rng, 2 * SLOT) } else { usize::MAX };
        let before = store.clone();
        let mut torn = Torn::new(store, cut);
        let r = save_within(&mut torn, HASH, &state, &*table, &budget);
        store = torn.inner;
        for (e, n) in erased.iter_mut().zip(torn.erases) {
            *e += n;
        }
        ensure!(
            (entry == 6) == matches!(r, Err(SaveError::EntryBytes { found: 6 })),
            "a table of {entry}-byte entries: {r:?}"
        );
        let reported = match &r {
            Ok(saved) => Some((saved.slot, saved.erases)),
            Err(e) => e.erased(),
        };
        match reported {
            Some((slot, n)) => {
                let s = slot as usize & 1;
                ensure!(n == erased[s], "save {i} reports {n} erases of slot {slot}, the flash saw {}", erased[s]);
                kept.erases[s] = kept.erases[s].max(n);
            }
            None => {
                ensure!(torn.erases == [0, 0], "save {i} ({r:?}) reports no erase but erased {:?}", torn.erases);
                ensure!(
                    store.slot(0) == before.slot(0) && store.slot(1) == before.slot(1),
                    "save {i} ({r:?}) reports no erase but changed the store"
                );
            }
        }
        let Ok(stored) = stored_wear(&store) else {
            return Outcome::Failed("stored_wear failed on a RAM store".into());
        };
        let known = stored.max(&kept);
        ensure!(known.erases == erased, "save {i}: the flash saw {erased:?} erases, records and reports know {:?}", known.erases);
        ensure!(erased.iter().all(|&n| n <= endurance), "save {i}: {erased:?} erases, beyond the budget of {endurance}");
    }
    Outcome::Ok
}
