extern crate std;

use super::*;
use crate::weights::{Half, WeightStore};
use proptest::prelude::*;
use std::collections::HashMap;
use std::vec;
use std::vec::Vec;

fn table(slots: usize) -> ClaimTable<Vec<Q16>, Tags32<Vec<u32>>> {
    let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags32(vec![0u32; slots])).unwrap();
    t.reset(InitialWeights { seed: 7, lo: 0, span: 1 << 16 });
    t
}

/// A key whose home is `home` in a table of `slots` and whose high bits
/// are `n` (distinct keys with one home).
fn key_at(home: u32, n: u32, slots: u32) -> u32 {
    home | (n * slots)
}

/// What the table must behave like: a map from key to weight, where a key
/// absent from the map reads its initial weight, and a full table refuses.
struct Model {
    weights: HashMap<u32, i32>,
    init: InitialWeights,
}

#[test]
fn an_unwritten_feature_reads_its_initial_weight_and_a_claim_starts_from_it() {
    let mut t = table(64);
    let key = 0xDEAD_BEEF;
    let before = t.read(key);
    assert_eq!(before, t.initial_weights().of(key));
    assert_eq!(t.occupancy().claimed, 0, "reading claims nothing");
    let Claim::Slot { slot, fresh: true } = t.claim(key) else { panic!("claim refused") };
    assert_eq!(t.get(slot as usize), before, "the claimed weight starts where the read was");
    assert_eq!(t.claim(key), Claim::Slot { slot, fresh: false }, "a second claim finds the slot");
    t.add(slot as usize, Q16(5), 0);
    assert_eq!(t.read(key), Q16(before.0 + 5));
    // Another seed, other initial weights; a constant init is constant.
    let other = InitialWeights { seed: 8, ..t.initial_weights() };
    assert_ne!(other.of(key), t.initial_weights().of(key));
    let c = InitialWeights { seed: 1, lo: 42, span: 1 };
    assert_eq!((c.of(1), c.of(2)), (Q16(42), Q16(42)));
}

#[test]
fn features_with_one_home_get_their_own_slots_across_the_end() {
    let mut t = table(16);
    // Five keys whose home is the last slot: their probes wrap to 0..3.
    let keys: Vec<u32> = (1..=5).map(|n| key_at(15, n, 16)).collect();
    let mut slots = Vec::new();
    for (i, &k) in keys.iter().enumerate() {
        let Claim::Slot { slot, fresh: true } = t.claim(k) else { panic!("refused") };
        t.set(slot as usize, Q16(100 + i as i32));
        slots.push(slot);
    }
    assert_eq!(slots, [15, 0, 1, 2, 3]);
    for (i, &k) in keys.iter().enumerate() {
        assert_eq!(t.read(k), Q16(100 + i as i32), "key {i} reads its own weight");
    }
    assert_eq!(t.occupancy().longest_probe, 4);
}

#[test]
fn a_full_table_refuses_and_counts_and_writes_nothing() {
    let mut t = table(8);
    for n in 0..8 {
        assert!(matches!(t.claim(key_at(n, 1, 8)), Claim::Slot { fresh: true, .. }));
    }
    let snapshot: Vec<(u32, Q16)> = (0..8).map(|i| (t.tag(i), t.get(i))).collect();
    let stranger = key_at(3, 99, 8);
    assert_eq!(t.claim(stranger), Claim::Refused);
    assert_eq!(t.claim(stranger), Claim::Refused);
    assert_eq!(t.read(stranger), t.initial_weights().of(stranger), "a refused feature reads its initial weight");
    let after: Vec<(u32, Q16)> = (0..8).map(|i| (t.tag(i), t.get(i))).collect();
    assert_eq!(snapshot, after, "a refusal changes no slot");
    let o = t.occupancy();
    assert_eq!((o.claimed, o.slots, o.refused), (8, 8, 2));
    assert_eq!(o.fraction(), 1.0);
}

#[test]
fn the_probe_is_bounded_before_the_table_is_full() {
    // MAX_PROBE + 1 keys with one home in a table much larger than that:
    // the last is refused although most slots are free.
    let slots = 4 * MAX_PROBE as usize;
    let mut t = table(slots);
    for n in 1..=MAX_PROBE {
        assert!(matches!(t.claim(key_at(5, n, slots as u32)), Claim::Slot { .. }));
    }
    assert_eq!(t.claim(key_at(5, MAX_PROBE + 1, slots as u32)), Claim::Refused);
    assert_eq!(t.occupancy().claimed, MAX_PROBE);
}

#[test]
fn sixteen_bit_tags_tell_apart_every_key_of_one_home() {
    // 2^21 slots: keys with one home differ only in their top 11 bits,
    // and every one of the 2048 gets a tag of its own.
    let slots = 1u32 << 21;
    let tags: std::collections::BTreeSet<u32> = (0..2048).map(|n| tag_of(key_at(77, n, slots), 16)).collect();
    assert_eq!(tags.len(), 2048);
    assert!(!tags.contains(&EMPTY));
    // 32-bit tags are a bijection of the key (but for the empty mark).
    assert_ne!(tag_of(1, 32), tag_of(2, 32));
    assert_ne!(tag_of(0, 32), EMPTY);
}

#[test]
fn tags_and_weights_round_trip_through_their_stored_bytes() {
    let mut t = ClaimTable::new(Half::<_, 12>::new(vec![0i16; 32]), Tags16(vec![0u16; 32])).unwrap();
    t.reset(InitialWeights { seed: 3, lo: 0, span: 1 << 12 });
    assert_eq!(t.entry_bytes(), 4);
    for k in [11u32, 0xFFFF_0000, 12345678] {
        if let Claim::Slot { slot, .. } = t.claim(k) {
            t.add(slot as usize, Q16(3 << 12), 0);
        }
    }
    let mut bytes = vec![0u8; 32 * 4];
    for i in 0..32 {
        t.stored_le(i, &mut bytes[4 * i..4 * i + 4]);
    }
    let mut u = ClaimTable::new(Half::<_, 12>::new(vec![0i16; 32]), Tags16(vec![0u16; 32])).unwrap();
    for i in 0..32 {
        u.load_le(i, &bytes[4 * i..4 * i + 4]);
    }
    u.restore_claims(t.initial_weights(), 0);
    assert_eq!(u.occupancy().claimed, 3);
    for k in [11u32, 0xFFFF_0000, 12345678, 999] {
        assert_eq!(u.read(k), t.read(k), "key {k}");
    }
    assert_eq!(u.checksum(), t.checksum());
}

#[test]
fn construction_errors_name_the_lengths() {
    let e = ClaimTable::new(vec![Q16::ZERO; 8], Tags32(vec![0u32; 4])).unwrap_err();
    assert_eq!(e, ClaimTableError::LengthMismatch { weights: 8, tags: 4 });
    let e = ClaimTable::new(vec![Q16::ZERO; 12], Tags32(vec![0u32; 12])).unwrap_err();
    assert!(std::format!("{e}").contains("power of two"));
}

#[derive(Debug, Clone)]
enum Op {
    Read(u32),
    Claim(u32, i32),
}

/// Keys drawn from few homes and few high parts, so that probe runs meet,
/// wrap the end and fill the table.
fn op(slots: u32) -> impl Strategy<Value = Op> {
    let key = (0..slots, 0u32..6).prop_map(move |(h, n)| key_at(h, n, slots));
    prop_oneof![
        key.clone().prop_map(Op::Read),
        (key, -1000i32..1000).prop_map(|(k, inc)| Op::Claim(k, inc)),
    ]
}

proptest! {
    /// Against a map from key to weight: a claimed key reads what was
    /// written to it, an unclaimed one its initial weight, and a claim is
    /// refused only when no slot is free within the probe bound (here: the
    /// table is full, since it is smaller than the bound).
    #[test]
    fn behaves_as_a_map(ops in prop::collection::vec(op(16), 1..200)) {
        let mut t = table(16);
        let mut m = Model { weights: HashMap::new(), init: t.initial_weights() };
        for op in ops {
            match op {
                Op::Read(k) => {
                    let want = m.weights.get(&k).copied().unwrap_or(m.init.of(k).0);
                    prop_assert_eq!(t.read(k).0, want);
                }
                Op::Claim(k, inc) => match t.claim(k) {
                    Claim::Slot { slot, fresh } => {
                        prop_assert_eq!(fresh, !m.weights.contains_key(&k));
                        t.add(slot as usize, Q16(inc), 0);
                        let w = m.weights.entry(k).or_insert(m.init.of(k).0);
                        *w = w.saturating_add(inc);
                    }
                    Claim::Refused => {
                        prop_assert!(!m.weights.contains_key(&k), "a claimed key was refused");
                        prop_assert_eq!(m.weights.len(), 16, "refused with free slots");
                    }
                    Claim::Replaced { .. } => prop_assert!(false, "a refusing table replaced"),
                },
            }
            prop_assert_eq!(t.occupancy().claimed as usize, m.weights.len());
        }
    }
}

/// A 16-bit-tag table of `slots` slots with 16-bit weights (as the chips').
fn chip_table(slots: usize) -> ClaimTable<Half<Vec<i16>, 12>, Tags16<Vec<u16>>> {
    let mut t = ClaimTable::new(Half::<_, 12>::new(vec![0i16; slots]), Tags16(vec![0u16; slots])).unwrap();
    t.reset(InitialWeights { seed: 11, lo: 0, span: 1 << 12 });
    t
}

#[test]
fn two_features_of_one_home_keep_their_own_weights_in_the_f405s_table() {
    // Found by an independent fuzz harness: both keys have home 11990 in
    // 2^14 slots, and the old 16-bit tag (the remix's top bits) was 0x6cf5
    // for both, so the second read the first's learned weight.
    let mut t = chip_table(1 << 14);
    let (a, b) = (0xd438_2ed6u32, 0x3c8f_aed6u32);
    assert_eq!((a & 0x3FFF, b & 0x3FFF), (11990, 11990));
    let Claim::Slot { slot, fresh: true } = t.claim(a) else { panic!("claim refused") };
    t.set(slot as usize, Q16(1000 << 16));
    assert_eq!(t.read(a), Q16(1000 << 16));
    assert_eq!(t.read(b), t.initial_weight(b), "b holds no slot: it reads its initial weight, not a's");
    let Claim::Slot { slot: sb, fresh: true } = t.claim(b) else { panic!("b found a's slot") };
    assert_ne!(sb, slot);
}

/// A SplitMix64 step, for reproducible keys.
fn splitmix(state: &mut u64) -> u32 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) as u32
}

#[test]
fn at_every_size_features_of_one_home_never_share_a_slot() {
    // Tables of 2^1 … 2^18 slots with 16-bit tags; in each, homes spaced
    // so that their probe runs do not meet, and up to 64 keys per home
    // with random high bits that differ in the bits the table keeps of a
    // key (the low min(32, log2 + 15)). Every claim must take a slot of
    // its own, and every key read its own weight back.
    let mut rng = 7u64;
    for log2 in 1..=18u32 {
        let slots = 1usize << log2;
        let mut t = chip_table(slots);
        let per_home = slots.min(MAX_PROBE as usize);
        let key_mask = if log2 + 15 >= 32 { u32::MAX } else { (1u32 << (log2 + 15)) - 1 };
        let mut written: Vec<(u32, Q16)> = Vec::new();
        for home in (0..slots).step_by(per_home).take(64) {
            let mut seen = std::collections::BTreeSet::new();
            while seen.len() < per_home {
                let key = (splitmix(&mut rng) & !(slots as u32 - 1)) | home as u32;
                if !seen.insert(key & key_mask) {
                    continue;
                }
                let w = Q16((written.len() as i32 + 1) << 12);
                match t.claim(key) {
                    Claim::Slot { slot, fresh: true } => t.set(slot as usize, w),
                    other => panic!("2^{log2} slots: key {key:#x} (home {home}): {other:?}, another key's slot"),
                }
                written.push((key, w));
            }
        }
        for &(key, w) in &written {
            assert_eq!(t.read(key), w, "2^{log2} slots: key {key:#x} reads another weight");
        }
    }
}

#[test]
fn a_stored_tag_tells_apart_every_kept_key_of_one_home_at_every_size() {
    // Exhaustively, for several homes of every size 2^1 … 2^31: the keys
    // of one home that differ in their kept bits (all 2^(key_bits − k) of
    // them, at most 2^15) get distinct stored tags, none of them EMPTY.
    for bits in [16u32, 32] {
        for log2 in 1..=31u32 {
            let kept = key_bits(bits, log2);
            assert_eq!(kept, (log2 + bits - 1).min(32));
            let varying = (kept - log2).min(15);
            for home in [0x2ed6u32, u32::MAX] {
                let home = home & ((1u32 << log2) - 1);
                let mut tags: Vec<u32> = (0..1u32 << varying).map(|n| stored_tag(home | (n << log2), bits, log2)).collect();
                assert!(!tags.contains(&EMPTY));
                tags.sort_unstable();
                let repeated = tags.windows(2).find(|w| w[0] == w[1]);
                assert_eq!(repeated, None, "{bits}-bit tags, 2^{log2} slots, home {home:#x}: a tag repeats");
            }
        }
    }
}

#[test]
fn large_tables_store_the_tags_they_always_stored() {
    // The F429's 2^21 slots with 16-bit tags and the host's 2^22 with
    // 32-bit tags keep every bit of a key: their stored tags are the
    // remix of the whole key, as before key_bits, so they learn bit for
    // bit as they did.
    let mut state = 3u64;
    for _ in 0..10_000 {
        let key = splitmix(&mut state);
        for log2 in 17..=31 {
            assert_eq!(stored_tag(key, 16, log2), tag_of(key, 16));
        }
        for log2 in 1..=31 {
            assert_eq!(stored_tag(key, 32, log2), tag_of(key, 32));
        }
    }
    let t = chip_table(1 << 17);
    assert_eq!((t.key_bits(), t.tag_for(0xd438_2ed6)), (32, tag_of(0xd438_2ed6, 16)));
    let t = table(1 << 4);
    assert_eq!(t.key_bits(), 32);
    assert_eq!(t.initial_weight(0xFFFF_FFF0), t.initial_weights().of(0xFFFF_FFF0));
}

#[test]
fn keys_that_agree_in_the_kept_bits_are_one_feature_to_a_small_table() {
    // 2^14 slots keep 29 bits: keys that differ only in bits 29–31 are
    // one feature, with one initial weight and one slot.
    let mut t = chip_table(1 << 14);
    assert_eq!(t.key_bits(), 29);
    let a = 0x0438_2ed6u32;
    let b = a | 0xE000_0000;
    assert_eq!(t.initial_weight(a), t.initial_weight(b));
    assert_eq!(t.read(a), t.read(b));
    let Claim::Slot { slot, fresh: true } = t.claim(a) else { panic!("refused") };
    t.set(slot as usize, Q16(3 << 16));
    assert_eq!(t.claim(b), Claim::Slot { slot, fresh: false });
    assert_eq!(t.read(b), Q16(3 << 16));
    // One kept bit apart (bit 28): two features.
    assert!(matches!(t.claim(a ^ 1 << 28), Claim::Slot { fresh: true, .. }));
}

#[test]
fn the_longest_probe_counts_claims_and_not_reads() {
    let mut t = table(64);
    // Three keys of home 9 in slots 9, 10, 11; a fourth key of home 9
    // that holds no slot probes four slots to read.
    for n in 1..=3 {
        assert!(matches!(t.claim(key_at(9, n, 64)), Claim::Slot { fresh: true, .. }));
    }
    assert_eq!(t.occupancy().longest_probe, 2);
    let before = t.occupancy();
    assert_eq!(t.read(key_at(9, 4, 64)), t.initial_weights().of(key_at(9, 4, 64)));
    assert_eq!(t.occupancy(), before, "a read leaves the occupancy as it was");
    // Its claim probes three slots (9, 10, 11) before the free one.
    assert!(matches!(t.claim(key_at(9, 4, 64)), Claim::Slot { slot: 12, fresh: true }));
    assert_eq!(t.occupancy().longest_probe, 3);
    // Finding a claimed slot again counts its probe too (never more than
    // it took to claim it).
    assert!(matches!(t.claim(key_at(9, 2, 64)), Claim::Slot { slot: 10, fresh: false }));
    assert_eq!(t.occupancy().longest_probe, 3);
    // A table restored from a checkpoint starts again from 0: the
    // checkpoint does not keep it, and the probes before belong to the
    // learner that was replaced.
    t.restore_claims(t.initial_weights(), 0);
    assert_eq!((t.occupancy().claimed, t.occupancy().longest_probe), (4, 0));
}

/// `pre`'s claims (each followed by a write of its increment), then checks
/// that `read_then_claim` of `batch` sums, claims, counts and leaves the
/// slots as reading every key and then claiming each in order does.
fn batch_is_the_reads_then_the_claims<W, T>(mut t: ClaimTable<W, T>, pre: &[(u32, i32)], batch: &[u32]) -> Result<(), TestCaseError>
where
    W: WeightStore + Clone,
    T: TagStore + Clone,
{
    for &(k, inc) in pre {
        if let Claim::Slot { slot, .. } = t.claim(k) {
            t.add(slot as usize, Q16(inc << 8), 0);
        }
    }
    let mut one_by_one = t.clone();
    let want_sum: i64 = batch.iter().map(|&k| one_by_one.read(k).0 as i64).sum();
    let want: Vec<Claim> = batch.iter().map(|&k| one_by_one.claim(k)).collect();
    let mut claims = vec![Claim::Refused; batch.len()];
    let sum = t.read_then_claim(batch, &mut claims);
    prop_assert_eq!(sum, want_sum);
    prop_assert_eq!(claims, want);
    prop_assert_eq!(t.occupancy(), one_by_one.occupancy());
    for i in 0..WeightStore::len(&t) {
        prop_assert_eq!((t.tag(i), t.get(i)), (one_by_one.tag(i), one_by_one.get(i)), "slot {}", i);
    }
    Ok(())
}

/// What `add_each` must do: `add` of each slot in the table in order, one
/// dither per weight written if the table is dithered, the checksum's
/// change taken from `raw` before and after.
fn add_one_by_one<S: WeightStore>(t: &mut S, slots: &[u32], inc: Q16, rng: &mut rand_pcg::Pcg32) -> crate::weights::Added {
    use rand_core::RngCore;
    let mut out = crate::weights::Added::default();
    for &s in slots {
        let i = s as usize;
        if i < t.len() {
            let d = if t.dithered() { rng.next_u32() } else { 0 };
            let old = t.raw(i);
            out.saturations += t.add(i, inc, d) as u32;
            let change = t.raw(i).wrapping_sub(old).wrapping_mul(crate::weights::entry_factor(i));
            out.checksum_change = out.checksum_change.wrapping_add(change);
        }
    }
    out
}

/// `pre`'s claims, then checks `add_each` of `slots` (claimed, free or
/// outside the table) against `add_one_by_one`: the weights, what it
/// returns, the table's checksum and the dithers drawn.
fn add_each_is_one_by_one<W, T>(mut t: ClaimTable<W, T>, pre: &[(u32, i32)], slots: &[u32], inc: i32, seed: u64) -> Result<(), TestCaseError>
where
    W: WeightStore + Clone,
    T: TagStore + Clone,
{
    use rand_core::{RngCore, SeedableRng};
    for &(k, _) in pre {
        t.claim(k);
    }
    let mut one_by_one = t.clone();
    let (mut r1, mut r2) = (rand_pcg::Pcg32::seed_from_u64(seed), rand_pcg::Pcg32::seed_from_u64(seed));
    let before = t.checksum();
    let want = add_one_by_one(&mut one_by_one, slots, Q16(inc), &mut r2);
    let got = t.add_each(slots, Q16(inc), || r1.next_u32());
    prop_assert_eq!(got, want);
    prop_assert_eq!(before.wrapping_add(got.checksum_change), t.checksum());
    prop_assert_eq!(r1.next_u32(), r2.next_u32(), "the same dithers drawn");
    for i in 0..WeightStore::len(&t) {
        prop_assert_eq!(t.raw(i), one_by_one.raw(i), "slot {}", i);
    }
    Ok(())
}

/// Slots of a 16-slot table, and some outside it (a refused claim's).
fn slot16() -> impl Strategy<Value = u32> {
    prop_oneof![4 => 0u32..16, 1 => Just(u32::MAX)]
}

proptest! {
    /// One probe per key for a learning update's read and claims changes
    /// nothing: keys of few homes (probe runs that meet, wrap and fill the
    /// table), repeated keys, a batch that takes the free slot another of
    /// its keys stopped at, full tables that refuse.
    #[test]
    fn the_batch_read_and_claim_is_the_reads_then_the_claims(
        pre in prop::collection::vec((0u32..16, 0u32..6, -100i32..100), 0..24),
        batch in prop::collection::vec((0u32..16, 0u32..6), 1..20),
    ) {
        let pre: Vec<(u32, i32)> = pre.iter().map(|&(h, n, inc)| (key_at(h, n, 16), inc)).collect();
        let batch: Vec<u32> = batch.iter().map(|&(h, n)| key_at(h, n, 16)).collect();
        batch_is_the_reads_then_the_claims(table(16), &pre, &batch)?;
        batch_is_the_reads_then_the_claims(chip_table(16), &pre, &batch)?;
    }

    /// A trace entry's writes in one call are the writes one by one, for
    /// full-width and 16-bit (dithered) weights, claimed and free slots.
    #[test]
    fn a_trace_entry_s_writes_are_the_writes_one_by_one(
        pre in prop::collection::vec((0u32..16, 0u32..6), 0..12),
        slots in prop::collection::vec(slot16(), 0..20),
        inc in prop_oneof![-70_000i32..70_000, Just(i32::MAX), Just(i32::MIN)],
        seed in any::<u64>(),
    ) {
        let pre: Vec<(u32, i32)> = pre.iter().map(|&(h, n)| (key_at(h, n, 16), 0)).collect();
        add_each_is_one_by_one(table(16), &pre, &slots, inc, seed)?;
        add_each_is_one_by_one(chip_table(16), &pre, &slots, inc, seed)?;
    }
}

/// A table of `slots` that replaces when full, with a constant initial
/// weight of 0 (the centre is 0).
fn replacing(slots: usize) -> ClaimTable<Vec<Q16>, Tags32<Vec<u32>>> {
    let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags32(vec![0u32; slots])).unwrap().on_full(WhenFull::Replace);
    t.reset(InitialWeights { seed: 7, lo: 0, span: 1 });
    t
}

#[test]
fn a_full_table_that_replaces_gives_away_the_least_learned_slot() {
    let mut t = replacing(8);
    for n in 0..8u32 {
        let Claim::Slot { slot, fresh: true } = t.claim(key_at(n, 1, 8)) else { panic!("not fresh") };
        // Slot 5 has learned least (closest to the initial 0).
        t.set(slot as usize, Q16(if slot == 5 { -3 } else { 100 + slot as i32 }));
    }
    let loser = key_at(5, 1, 8);
    let before = t.checksum();
    let stranger = key_at(3, 99, 8);
    let old_raw = WeightStore::raw(&t, 5);
    assert_eq!(t.claim(stranger), Claim::Replaced { slot: 5, old_raw });
    assert_eq!(t.read(stranger), Q16::ZERO, "the new feature starts from its initial weight");
    assert_eq!(t.read(loser), Q16::ZERO, "the evicted feature reads its initial weight again");
    assert_eq!(t.claim(stranger), Claim::Slot { slot: 5, fresh: false }, "found again by its probe");
    for n in [0u32, 1, 2, 3, 4, 6, 7] {
        assert_eq!(t.read(key_at(n, 1, 8)), Q16(100 + n as i32), "key of home {n} keeps its weight");
    }
    let o = t.occupancy();
    assert_eq!((o.claimed, o.refused, o.replaced), (8, 0, 1));
    // The checksum's change is the slot's new raw less its old.
    let change = WeightStore::raw(&t, 5).wrapping_sub(old_raw).wrapping_mul(entry_factor(5));
    assert_eq!(t.checksum(), before.wrapping_add(change));
    // A refusing table of the same content refuses instead.
    let mut r = table(8);
    for n in 0..8u32 {
        r.claim(key_at(n, 1, 8));
    }
    assert_eq!(r.claim(stranger), Claim::Refused);
}

#[test]
fn a_replacing_batch_never_takes_a_slot_of_its_own_features() {
    // Slots 0..7 full; keys 0 and 1 of the batch hold 0 and 1 (both at
    // the initial weight 0, the most attractive victims); two strangers
    // must take other slots.
    let mut t = replacing(8);
    for n in 0..8u32 {
        let Claim::Slot { slot, .. } = t.claim(key_at(n, 1, 8)) else { panic!() };
        t.set(slot as usize, Q16(if slot < 2 { 0 } else { 50 + slot as i32 }));
    }
    let batch = [key_at(0, 1, 8), key_at(1, 1, 8), key_at(0, 7, 8), key_at(0, 8, 8)];
    let mut claims = [Claim::Refused; 4];
    t.read_then_claim(&batch, &mut claims);
    assert_eq!(claims[0], Claim::Slot { slot: 0, fresh: false });
    assert_eq!(claims[1], Claim::Slot { slot: 1, fresh: false });
    let (Claim::Replaced { slot: a, .. }, Claim::Replaced { slot: b, .. }) = (claims[2], claims[3]) else {
        panic!("{claims:?}")
    };
    assert!(a >= 2 && b >= 2 && a != b, "{claims:?}");
    for (k, c) in batch.iter().zip(claims) {
        assert_eq!(t.tag(c.slot().unwrap() as usize), t.tag_for(*k), "each feature of the batch holds its slot");
    }
    assert_eq!(t.occupancy().replaced, 2);
}

proptest! {
    /// A replacing table against a model that knows which feature each
    /// slot holds: a feature that holds a slot reads its own weight, one
    /// that lost it (or never had one) reads its initial weight, and no
    /// claim ever lands in another held feature's slot.
    #[test]
    fn a_replacing_table_reads_what_its_features_learned(
        ops in proptest::collection::vec((0u32..40, -50i32..50), 1..400),
    ) {
        let slots = 16usize;
        let mut t = replacing(slots);
        let mut owner: HashMap<u32, u32> = HashMap::new(); // slot -> key
        let mut learned: HashMap<u32, i32> = HashMap::new(); // key -> weight
        for (k, inc) in ops {
            // Keys spread over a few homes, so that probes run long.
            let key = key_at(k % 5, k, slots as u32);
            match t.claim(key) {
                Claim::Slot { slot, fresh } => {
                    if fresh {
                        prop_assert!(!owner.contains_key(&slot));
                    } else {
                        prop_assert_eq!(owner.get(&slot), Some(&key));
                    }
                    owner.insert(slot, key);
                }
                Claim::Replaced { slot, .. } => {
                    let old = owner.insert(slot, key).expect("a replaced slot was held");
                    prop_assert_ne!(old, key);
                    learned.remove(&old);
                }
                Claim::Refused => prop_assert!(false, "a replacing table refused"),
            }
            let slot = owner.iter().find(|(_, &v)| v == key).map(|(&s, _)| s).unwrap();
            t.add(slot as usize, Q16(inc), 0);
            *learned.entry(key).or_insert(0) += inc;
            for (&s, &k2) in &owner {
                prop_assert_eq!(t.read(k2), Q16(learned[&k2]), "slot {}", s);
            }
        }
        prop_assert_eq!(t.occupancy().refused, 0);
    }
}
