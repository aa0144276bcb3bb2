//! The claim table ([`pada_core::claim_table`]) under any sequence of
//! reads, claims and writes. The input's first byte picks the scenario:
//!
//! - **a few homes** (bit 2 clear): 16 or 32 slots (bit 0), 16- or 32-bit
//!   tags (bit 1); then every 5 bytes are one operation on a key drawn from
//!   a small pool whose keys share homes, so that probe runs meet, wrap the
//!   end and fill the table; bit 3 set makes it a table that replaces
//!   when full ([`WhenFull::Replace`]) instead of refusing;
//! - **one home** (bit 2 set): a table of 2^1 … 2^17 slots (bits 3–7) with
//!   16- or 32-bit tags (bit 1), a home from the next 4 bytes, then every 5
//!   bytes one operation on a key of that home with random high bits (or
//!   an earlier key with its top byte changed). Keys of one home are where
//!   a 16-bit tag of a small table once let two features share a slot.
//!
//! Invariants, checked after every operation:
//! - a read changes nothing, the occupancy included;
//! - a refused claim changes no slot, and is counted;
//! - a replacing table never refuses a single claim; it gives away a slot
//!   that was held by another feature, within the probe bound of the new
//!   one, changes no other slot, counts it, and the feature it took the
//!   slot from reads its initial weight again;
//! - a claim is refused only when no slot is free within the probe bound;
//! - the claimed count is the number of tagged slots, never above the size;
//! - the longest probe is the longest a claim took (a refusal's is
//!   `MAX_PROBE`); reads do not count, and a restored table starts from 0;
//! - with 32-bit tags the table is a map: every claimed key reads what was
//!   written to it, every other key its initial weight (the model);
//! - with one home, with either tag width, the table is a map from a key's
//!   low min(32, log2 slots + tag bits − 1) bits (the bits the module
//!   documentation says a table keeps) to its weight: two keys that differ
//!   in those never share a slot, two that agree are one feature;
//! - the table's running checksum (as the agent keeps it) is its checksum.

use super::{ensure, Outcome, Target};
use crate::gen::{below, bytes};
use pada_core::claim_table::{tag_of, Claim, ClaimTable, InitialWeights, TagStore, Tags16, Tags32, WhenFull, MAX_PROBE};
use pada_core::fixed::Q16;
use pada_core::weights::{entry_factor, WeightStore};
use std::collections::HashMap;

/// The target.
pub struct Claims {
    name: &'static str,
}

impl Claims {
    pub fn new(name: &'static str) -> Self {
        Claims { name }
    }
}

/// Keys with few homes in a table of up to 32 slots: home `i % 5 * 7`,
/// high parts 0 … 5.
fn key(pool_index: u8) -> u32 {
    let i = pool_index as u32 % 30;
    (i % 5) * 7 + (i / 5) * 64 + (i / 5) * 0x0101_0000
}

impl Target for Claims {
    fn name(&self) -> &'static str {
        self.name
    }

    fn generate(&mut self, rng: &mut rand_pcg::Pcg64) -> Vec<u8> {
        let ops = 1 + below(rng, 120);
        bytes(rng, 1 + 5 * ops)
    }

    fn check(&self, input: &[u8]) -> Outcome {
        let Some((&config, ops)) = input.split_first() else { return Outcome::Ok };
        if config & 4 != 0 {
            return one_home(config, ops);
        }
        let slots = if config & 1 == 0 { 16 } else { 32 };
        let init = InitialWeights { seed: config as u64 * 0x9E37_79B9, lo: -(1 << 16), span: 1 << 17 };
        let when_full = if config & 8 == 0 { WhenFull::Refuse } else { WhenFull::Replace };
        if config & 2 == 0 {
            let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags16(vec![0u16; slots])).unwrap().on_full(when_full);
            t.reset(init);
            run(&mut t, ops, false)
        } else {
            let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags32(vec![0u32; slots])).unwrap().on_full(when_full);
            t.reset(init);
            run(&mut t, ops, true)
        }
    }
}

fn snapshot<T: TagStore>(t: &ClaimTable<Vec<Q16>, T>) -> Vec<(u32, Q16)> {
    (0..WeightStore::len(t)).map(|i| (t.tag(i), t.get(i))).collect()
}

fn run<T: TagStore>(t: &mut ClaimTable<Vec<Q16>, T>, ops: &[u8], exact: bool) -> Outcome {
    let slots = WeightStore::len(t);
    let init = t.initial_weights();
    // The model of a 32-bit-tag table: key identity is the tag.
    let mut model: HashMap<u32, i32> = HashMap::new();
    let mut refused = 0u32;
    let mut replaced = 0u32;
    let mut longest = 0u32;
    let mut checksum = t.checksum();
    for op in ops.chunks_exact(5) {
        let k = key(op[1]);
        let inc = i16::from_le_bytes([op[2], op[3]]) as i32;
        match op[0] % 3 {
            0 => {
                let before = (snapshot(t), t.occupancy());
                let w = t.read(k);
                ensure!((snapshot(t), t.occupancy()) == before, "a read changed the table or its occupancy");
                if exact {
                    let want = model.get(&tag_of(k, 32)).copied().unwrap_or(init.of(k).0);
                    ensure!(w.0 == want, "key {k:#x} reads {} but the model has {want}", w.0);
                }
            }
            _ => {
                let before = snapshot(t);
                let raws: Vec<u32> = (0..slots).map(|i| t.raw(i)).collect();
                match t.claim(k) {
                    Claim::Slot { slot, fresh } => {
                        let i = slot as usize;
                        ensure!(i < slots, "slot {i} outside the table of {slots}");
                        longest = longest.max(slot.wrapping_sub(k) & (slots as u32 - 1));
                        if fresh {
                            checksum = checksum.wrapping_add(t.raw(i).wrapping_mul(entry_factor(i)));
                        }
                        let old = t.raw(i);
                        t.add(i, Q16(inc), 0);
                        checksum = checksum.wrapping_add(t.raw(i).wrapping_sub(old).wrapping_mul(entry_factor(i)));
                        if exact {
                            let held = model.contains_key(&tag_of(k, 32));
                            ensure!(fresh != held, "key {k:#x}: fresh {fresh}, but held {held} in the model");
                            let w = model.entry(tag_of(k, 32)).or_insert(init.of(k).0);
                            *w = w.saturating_add(inc);
                        }
                    }
                    Claim::Replaced { slot, old_raw } => {
                        let i = slot as usize;
                        ensure!(WeightStore::when_full(t) == WhenFull::Replace, "a refusing table replaced");
                        ensure!(i < slots, "slot {i} outside the table of {slots}");
                        ensure!(slot.wrapping_sub(k) & (slots as u32 - 1) < MAX_PROBE, "slot {i} beyond the probe of {k:#x}");
                        let (old_tag, _) = before[i];
                        ensure!(old_tag != 0, "replaced the free slot {i}");
                        ensure!(old_raw == raws[i], "old raw {old_raw:#x} is not the slot's {:#x}", raws[i]);
                        let after = snapshot(t);
                        ensure!(
                            after.iter().zip(&before).enumerate().all(|(j, (a, b))| j == i || a == b),
                            "a replacement changed another slot"
                        );
                        replaced += 1;
                        longest = MAX_PROBE;
                        checksum = checksum.wrapping_add(t.raw(i).wrapping_sub(old_raw).wrapping_mul(entry_factor(i)));
                        let old = t.raw(i);
                        t.add(i, Q16(inc), 0);
                        checksum = checksum.wrapping_add(t.raw(i).wrapping_sub(old).wrapping_mul(entry_factor(i)));
                        if exact {
                            // 32-bit tags: a feature's stored tag is its model key.
                            ensure!(model.remove(&old_tag).is_some(), "replaced a slot the model does not hold");
                            ensure!(!model.contains_key(&tag_of(k, 32)), "key {k:#x} held a slot and replaced another");
                            model.insert(tag_of(k, 32), init.of(k).0.saturating_add(inc));
                        }
                    }
                    Claim::Refused => {
                        refused += 1;
                        longest = MAX_PROBE;
                        ensure!(WeightStore::when_full(t) == WhenFull::Refuse, "a replacing table refused a single claim");
                        ensure!(snapshot(t) == before, "a refused claim changed the table");
                        let free = before.iter().filter(|(tag, _)| *tag == 0).count();
                        // Every slot is within the bound of a table this small.
                        ensure!(slots as u32 > MAX_PROBE || free == 0, "refused with {free} free slots");
                    }
                }
            }
        }
        let o = t.occupancy();
        let tagged = snapshot(t).iter().filter(|(tag, _)| *tag != 0).count() as u32;
        ensure!(o.claimed == tagged && o.claimed as usize <= slots, "claimed {} but {tagged} slots tagged", o.claimed);
        ensure!(o.refused == refused, "refused {} counted, {refused} seen", o.refused);
        ensure!(o.replaced == replaced, "replaced {} counted, {replaced} seen", o.replaced);
        ensure!(o.longest_probe == longest, "longest probe {} reported, {longest} taken by a claim", o.longest_probe);
        ensure!(checksum == t.checksum(), "running checksum {checksum:#x}, table {:#x}", t.checksum());
    }
    Outcome::Ok
}

/// The bits of a key a table of 2^`log2` slots with `tag_bits`-bit tags
/// keeps, as the module documentation states them (written out here, not
/// taken from the table, so that the target checks the promise).
fn kept_mask(log2: u32, tag_bits: u32) -> u32 {
    let bits = (log2 + tag_bits - 1).min(32);
    if bits == 32 {
        u32::MAX
    } else {
        (1 << bits) - 1
    }
}

/// The one-home scenario (see the module documentation).
fn one_home(config: u8, input: &[u8]) -> Outcome {
    let Some((home, ops)) = input.split_first_chunk::<4>() else { return Outcome::Ok };
    let log2 = 1 + (config >> 3) as u32 % 17;
    let slots = 1usize << log2;
    let init = InitialWeights { seed: config as u64 * 0x9E37_79B9, lo: -(1 << 16), span: 1 << 17 };
    let home = u32::from_le_bytes(*home) & (slots as u32 - 1);
    if config & 2 == 0 {
        let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags16(vec![0u16; slots])).unwrap();
        t.reset(init);
        run_one_home(&mut t, home, log2, ops)
    } else {
        let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags32(vec![0u32; slots])).unwrap();
        t.reset(init);
        run_one_home(&mut t, home, log2, ops)
    }
}

fn run_one_home<T: TagStore>(t: &mut ClaimTable<Vec<Q16>, T>, home: u32, log2: u32, ops: &[u8]) -> Outcome {
    let slots = 1u32 << log2;
    let kept = kept_mask(log2, T::BITS);
    let init = t.initial_weights();
    // Kept key -> weight, and kept key -> its slot.
    let mut model: HashMap<u32, (i32, u32)> = HashMap::new();
    let mut keys: Vec<u32> = Vec::new();
    let (mut refused, mut longest) = (0u32, 0u32);
    // Every key of one home probes from it: at most this many can hold a
    // slot before claims are refused.
    let room = slots.min(MAX_PROBE) as usize;
    for op in ops.chunks_exact(5) {
        let high = u32::from_le_bytes([op[1], op[2], op[3], op[4]]);
        let k = match keys.get(op[1] as usize % keys.len().max(1)) {
            // An earlier key with its top byte changed: the same feature
            // where the table keeps at most 24 bits of a key, another one
            // elsewhere.
            Some(&old) if (op[0] >> 2) % 4 == 0 => old ^ ((op[2] as u32 | 1) << 24),
            _ => (high << log2) | home,
        };
        ensure!(k & (slots - 1) == home, "key {k:#x} is not of home {home}");
        keys.push(k);
        let want = model.get(&(k & kept)).map_or(init.of(k & kept).0, |&(w, _)| w);
        if op[0] % 3 == 0 {
            let before = t.occupancy();
            let w = t.read(k);
            ensure!(w.0 == want, "2^{log2} slots: key {k:#x} reads {} but the model has {want}", w.0);
            ensure!(t.occupancy() == before, "a read changed the occupancy");
        } else {
            let inc = i16::from_le_bytes([op[3], op[4]]) as i32;
            match t.claim(k) {
                Claim::Slot { slot, fresh } => {
                    let held = model.get(&(k & kept)).map(|&(_, s)| s);
                    ensure!(
                        held.is_none_or(|s| s == slot) && fresh == held.is_none(),
                        "2^{log2} slots: key {k:#x} got slot {slot} (fresh {fresh}), the model has {held:?}"
                    );
                    ensure!(
                        !fresh || model.values().all(|&(_, s)| s != slot),
                        "2^{log2} slots: key {k:#x} took slot {slot}, another feature's"
                    );
                    longest = longest.max(slot.wrapping_sub(home) & (slots - 1));
                    t.add(slot as usize, Q16(inc), 0);
                    let e = model.entry(k & kept).or_insert((want, slot));
                    e.0 = e.0.saturating_add(inc);
                    ensure!(t.read(k).0 == e.0, "key {k:#x} reads {} after a write, the model {}", t.read(k).0, e.0);
                }
                Claim::Replaced { slot, .. } => {
                    return Outcome::Failed(format!("2^{log2} slots: a refusing table replaced slot {slot} for {k:#x}"));
                }
                Claim::Refused => {
                    refused += 1;
                    longest = MAX_PROBE;
                    ensure!(
                        !model.contains_key(&(k & kept)) && model.len() == room,
                        "2^{log2} slots: key {k:#x} refused with {} of {room} slots of its home held",
                        model.len()
                    );
                }
            }
        }
        let o = t.occupancy();
        ensure!(o.claimed as usize == model.len(), "claimed {} but the model holds {}", o.claimed, model.len());
        ensure!(o.refused == refused, "refused {} counted, {refused} seen", o.refused);
        ensure!(o.longest_probe == longest, "longest probe {} reported, {longest} taken by a claim", o.longest_probe);
    }
    // Restored as from a checkpoint: the same claims and refusals, and the
    // longest probe from 0 (a checkpoint does not keep it).
    t.restore_claims(init, refused);
    let o = t.occupancy();
    ensure!(
        (o.claimed as usize, o.refused, o.longest_probe) == (model.len(), refused, 0),
        "restored: {o:?}, the model holds {} with {refused} refused",
        model.len()
    );
    Outcome::Ok
}
