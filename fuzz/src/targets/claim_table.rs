//! The claim table ([`pada_core::claim_table`]) under any sequence of
//! reads, claims and writes: the input's first byte picks the table (16 or
//! 32 slots, 16- or 32-bit tags), then every 5 bytes are one operation on
//! a key drawn from a small pool whose keys share homes, so that probe
//! runs meet, wrap the end and fill the table.
//!
//! Invariants, checked after every operation:
//! - a read changes nothing;
//! - a refused claim changes no slot, and is counted;
//! - a claim is refused only when no slot is free within the probe bound;
//! - the claimed count is the number of tagged slots, never above the size;
//! - with 32-bit tags the table is a map: every claimed key reads what was
//!   written to it, every other key its initial weight (the model);
//! - the table's running checksum (as the agent keeps it) is its checksum.

use super::{ensure, Outcome, Target};
use crate::gen::{below, bytes};
use pada_core::claim_table::{tag_of, Claim, ClaimTable, InitialWeights, TagStore, Tags16, Tags32, MAX_PROBE};
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
        let slots = if config & 1 == 0 { 16 } else { 32 };
        let init = InitialWeights { seed: config as u64 * 0x9E37_79B9, lo: -(1 << 16), span: 1 << 17 };
        if config & 2 == 0 {
            let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags16(vec![0u16; slots])).unwrap();
            t.reset(init);
            run(&mut t, ops, false)
        } else {
            let mut t = ClaimTable::new(vec![Q16::ZERO; slots], Tags32(vec![0u32; slots])).unwrap();
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
    let mut checksum = t.checksum();
    for op in ops.chunks_exact(5) {
        let k = key(op[1]);
        let inc = i16::from_le_bytes([op[2], op[3]]) as i32;
        match op[0] % 3 {
            0 => {
                let before = snapshot(t);
                let w = t.read(k);
                ensure!(snapshot(t) == before, "a read changed the table");
                if exact {
                    let want = model.get(&tag_of(k, 32)).copied().unwrap_or(init.of(k).0);
                    ensure!(w.0 == want, "key {k:#x} reads {} but the model has {want}", w.0);
                }
            }
            _ => {
                let before = snapshot(t);
                match t.claim(k) {
                    Claim::Slot { slot, fresh } => {
                        let i = slot as usize;
                        ensure!(i < slots, "slot {i} outside the table of {slots}");
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
                    Claim::Refused => {
                        refused += 1;
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
        ensure!(checksum == t.checksum(), "running checksum {checksum:#x}, table {:#x}", t.checksum());
    }
    Outcome::Ok
}
