//! Weights learned on the host, in a board's table: its layout, size,
//! weight format and tags ([`export`]), and what the move changed
//! ([`ExportReport`]).
//!
//! The rules, which `docs/board.md` ("Weights from the host") states for
//! a person:
//!
//! - **Features.** Each learned weight of the host belongs to a feature:
//!   an index of an exact table, the low bits of a hashed feature (a
//!   hashed table's index), or the whole 32-bit hashed key (a claim table
//!   with 32-bit tags, whose tag is the key times an odd constant, so the
//!   key comes back from it). A board's exact table takes an exact table
//!   of its size index by index; its hashed table of 2^b entries takes the
//!   key's low b bits as the index (a hashed host table of 2^a ≥ 2^b
//!   entries folds); its claim table claims each key in its own layout.
//!   Any other pair is refused with one line.
//! - **Dropped features.** Where two or more learned features meet in one
//!   board entry (a hashed table's collision), or a claim finds the
//!   board's claim table full, the features farthest from their initial
//!   weight are kept: a claim table is filled in that order, and a
//!   hashed entry keeps its farthest feature. A feature is learned when
//!   its weight is not its initial weight (a claim table's features that
//!   hold a slot; in a plain table, a weight off the initial range's
//!   centre when the initial weights are one constant, every weight
//!   otherwise).
//! - **Quantisation.** A board's 16-bit weights hold multiples of
//!   2^(shift − 16) within ±2^(shift − 1): each weight is rounded to the
//!   nearest (counted when it changes) and clipped to the range (counted).
//! - **Unlearned entries.** A board entry no learned feature reaches
//!   holds the initial range's centre (plain tables); a claim table's free
//!   slots stay free, and their features read the board's own initial
//!   weights.

use crate::board::trial::{with_table, TableVisitor};
use crate::experiment::task::{TaskSpec, WeightTable};
use crate::start_weights::StartWeights;
use pada_core::agent::WeightInit;
use pada_core::claim_table::{Claim, InitialWeights, WhenFull, MAX_PROBE};
use pada_core::fixed::Q16;
use pada_core::profile::LearnerProfile;
use pada_core::tile_coding::Layout;
use pada_core::weights::{WeightFormat, WeightStore};
use serde::Serialize;

/// The multiplier a 32-bit claim tag is the key times
/// (`pada_core::claim_table::tag_of` with 32 bits).
const TAG_MIX: u32 = 0x9E37_79B1;

/// The inverse of an odd `a` modulo 2^32 (Newton's iteration: each step
/// doubles the correct low bits).
const fn inverse(a: u32) -> u32 {
    let mut x = a; // correct to 3 bits for odd a
    let mut i = 0;
    while i < 5 {
        x = x.wrapping_mul(2u32.wrapping_sub(a.wrapping_mul(x)));
        i += 1;
    }
    x
}

/// What an export changed, for the one summary it prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ExportReport {
    /// The host's table, as its file's header names it.
    pub from_table: String,
    /// The board's table.
    pub to_table: String,
    /// Features the host had learned.
    pub learned: usize,
    /// Of them, in the board's table.
    pub kept: usize,
    /// Of them, left out: they met a farther-learned feature in one board
    /// entry, or found the board's claim table full.
    pub dropped: usize,
    /// Board entries where two or more learned features met.
    pub collisions: usize,
    /// Claims the board's table refused as full.
    pub refused: usize,
    /// Kept weights whose value changed by rounding to the board's format.
    pub rounded: usize,
    /// Kept weights outside the board's range, clipped to it.
    pub clipped: usize,
    /// The largest change of a kept weight that was not clipped.
    pub max_rounding: f64,
}

impl ExportReport {
    /// The summary's lines.
    pub fn lines(&self, board: &str) -> Vec<String> {
        vec![
            format!(
                "weights: {} learned features of the host's {} into {board}'s {}: {} kept, {} dropped \
                 ({} entries shared by two or more, the farthest-learned kept; {} refused by a full table)",
                self.learned, self.from_table, self.to_table, self.kept, self.dropped, self.collisions, self.refused
            ),
            format!(
                "weights: quantised to the board's format: {} rounded (by at most {:.6}), {} clipped to its range",
                self.rounded, self.max_rounding, self.clipped
            ),
        ]
    }
}

/// A host table's learned features: where the board finds them, and
/// their weights.
struct Source {
    /// How far each learned feature's weight is from its initial weight,
    /// its key (full or as many low bits as the host kept) and its raw
    /// Q16 weight, farthest first.
    features: Vec<(u64, u32, i32)>,
    /// Bits of each key the host kept (32 for a claim table's keys).
    key_bits: u32,
    /// Whether the keys are exact indices rather than hashed keys.
    exact: bool,
    /// The initial range's centre (raw Q16), for the entries no feature
    /// reaches.
    centre: i32,
}

/// The initial weights of `spec`'s learner under `seed` (a claim table's).
fn initial_weights(init: WeightInit, seed: u64) -> InitialWeights {
    match init {
        WeightInit::Constant(c) => InitialWeights { seed, lo: Q16::from_f32(c).0, span: 1 },
        WeightInit::Uniform { min, max } => {
            let (lo, hi) = (Q16::from_f32(min).0 as i64, Q16::from_f32(max).0 as i64);
            InitialWeights { seed, lo: lo as i32, span: (hi - lo + 1) as u64 }
        }
    }
}

/// The learned features of the host's table.
fn source(w: &StartWeights, spec: &TaskSpec) -> anyhow::Result<Source> {
    let h = &w.header;
    let init = initial_weights(spec.params.init, h.table_seed);
    let centre = (init.lo as i64 + (init.span as i64 - 1) / 2) as i32;
    let constant = init.span == 1;
    let raw = |e: &[u8]| i32::from_le_bytes(e[..4].try_into().expect("4 bytes"));
    let mut features = Vec::new();
    let (key_bits, exact) = match (spec.table, h.entry_bytes) {
        (WeightTable::Claimed { tag_bytes: 4, format: WeightFormat::Q16, log2_size, .. }, 8) => {
            let mask = (1u32 << log2_size) - 1;
            let back = inverse(TAG_MIX);
            for (i, e) in w.entries().chunks_exact(8).enumerate() {
                let tag = u32::from_le_bytes(e[4..8].try_into().expect("4 bytes"));
                if tag == 0 {
                    continue;
                }
                // A key's slot lies within its probe from its home: that
                // tells the two keys whose tag is 1 (0 and 1/TAG_MIX) apart.
                let fits = |key: u32| (i as u32).wrapping_sub(key & mask) & mask < MAX_PROBE;
                let key = match tag.wrapping_mul(back) {
                    k if fits(k) => k,
                    _ if tag == 1 && fits(0) => 0,
                    _ => anyhow::bail!("{}: entry {i}'s tag {tag:#010x} belongs to no key near it (a damaged table)", w.path.display()),
                };
                let v = raw(e);
                features.push(((v as i64 - init.of(key).0 as i64).unsigned_abs(), key, v));
            }
            (32, false)
        }
        (WeightTable::Hashed { log2_size }, 4) | (WeightTable::Claimed { log2_size, .. }, 4) => {
            for (i, e) in w.entries().chunks_exact(4).enumerate() {
                let v = raw(e);
                if !constant || v != centre {
                    features.push(((v as i64 - centre as i64).unsigned_abs(), i as u32, v));
                }
            }
            (log2_size, false)
        }
        (WeightTable::Exact | WeightTable::ExactOf { .. }, 4) => {
            for (i, e) in w.entries().chunks_exact(4).enumerate() {
                let v = raw(e);
                if !constant || v != centre {
                    features.push(((v as i64 - centre as i64).unsigned_abs(), i as u32, v));
                }
            }
            (32, true)
        }
        _ => anyhow::bail!(
            "{}: a host table of {} with {}-byte entries has no export (the host's own tables: Q16 weights, 32-bit tags)",
            w.path.display(),
            h.table,
            h.entry_bytes
        ),
    };
    // Farthest first; ties by key, so the order is the same everywhere.
    features.sort_unstable_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
    Ok(Source { features, key_bits, exact, centre })
}

/// The host's weights `w` (read for `host`, the same robot's task with
/// the host's table) in a table of `profile` of `n` entries: each entry's
/// stored bytes, and what changed.
pub fn export(w: &StartWeights, host: &TaskSpec, profile: &LearnerProfile, n: usize) -> anyhow::Result<(Vec<u8>, ExportReport)> {
    let src = source(w, host)?;
    let to_table = match profile.layout {
        Layout::Exact => format!("exact table of {n}"),
        l => format!("{} 2^{}", l.name(), n.trailing_zeros()),
    } + &format!(
        " ({}-bit weights{})",
        profile.format.bytes() * 8,
        if profile.tag_bytes > 0 { format!(", {}-bit tags", profile.tag_bytes * 8) } else { String::new() }
    );
    let refuse = |why: String| anyhow::anyhow!("{}: {why}", w.path.display());
    match profile.layout {
        Layout::Exact if !(src.exact && w.header.weights == n) => {
            return Err(refuse(format!(
                "the host's {} does not go into board {}'s {to_table}: an exact board table takes an exact host table of its size",
                w.header.table,
                profile.board.name()
            )))
        }
        Layout::Hashed if src.exact || n.trailing_zeros() > src.key_bits => {
            return Err(refuse(format!(
                "the host's {} does not go into board {}'s {to_table}: its features' keys are not known to the {} bits it needs",
                w.header.table,
                profile.board.name(),
                n.trailing_zeros()
            )))
        }
        Layout::Claimed if src.exact || src.key_bits < 32 => {
            return Err(refuse(format!(
                "the host's {} does not go into board {}'s {to_table}: a claim table needs whole 32-bit keys (the host's claim table keeps them)",
                w.header.table,
                profile.board.name()
            )))
        }
        _ => {}
    }
    struct Fill<'a> {
        src: &'a Source,
        layout: Layout,
        report: ExportReport,
    }
    impl TableVisitor for Fill<'_> {
        type Output = (Vec<u8>, ExportReport);
        fn visit<W: WeightStore>(mut self, mut table: W) -> anyhow::Result<(Vec<u8>, ExportReport)> {
            let n = table.len();
            let mut placed = vec![false; n];
            let mut met = vec![false; n];
            if self.layout != Layout::Claimed {
                for i in 0..n {
                    table.set(i, Q16(self.src.centre));
                }
            }
            let step = match table.format() {
                WeightFormat::Q16 => 1i64,
                WeightFormat::Half { shift } => 1i64 << shift,
            };
            for &(_, key, v) in &self.src.features {
                let slot = match self.layout {
                    Layout::Claimed => match table.claim(key) {
                        Claim::Slot { slot, .. } => slot as usize,
                        _ => {
                            self.report.refused += 1;
                            self.report.dropped += 1;
                            continue;
                        }
                    },
                    // An exact host table of the board's size, index by index.
                    Layout::Exact => key as usize,
                    _ => (key as usize) & (n - 1),
                };
                if placed[slot] {
                    // A farther-learned feature holds it.
                    if !met[slot] {
                        met[slot] = true;
                        self.report.collisions += 1;
                    }
                    self.report.dropped += 1;
                    continue;
                }
                placed[slot] = true;
                table.set(slot, Q16(v));
                self.report.kept += 1;
                let got = table.get(slot).0 as i64;
                let change = (got - v as i64).abs();
                if change * 2 > step {
                    self.report.clipped += 1;
                } else if change > 0 {
                    self.report.rounded += 1;
                    self.report.max_rounding = self.report.max_rounding.max(change as f64 / 65536.0);
                }
            }
            let eb = table.entry_bytes();
            let mut bytes = vec![0u8; n * eb];
            for (i, dst) in bytes.chunks_exact_mut(eb).enumerate() {
                table.stored_le(i, dst);
            }
            Ok((bytes, self.report))
        }
    }
    let report = ExportReport {
        from_table: w.header.table.clone(),
        to_table,
        learned: src.features.len(),
        kept: 0,
        dropped: 0,
        collisions: 0,
        refused: 0,
        rounded: 0,
        clipped: 0,
        max_rounding: 0.0,
    };
    // Filled farthest first: a full claim table refuses the nearest.
    let profile = profile.when_full(WhenFull::Refuse);
    with_table(&profile, n, Fill { src: &src, layout: profile.layout, report })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::table::HostTable;
    use crate::weights::WeightsHeader;
    use pada_core::profile::Board;
    use pada_core::robot::leo;

    /// A host claim table holding `keys` with `values`, exported into
    /// `board`'s table: the board reads each key's weight, rounded to its
    /// 16 bits, and the report counts them.
    fn exported_reads_back(board: Board) {
        let sim = crate::robots::sim_robot(&leo::SPEC).unwrap();
        let spec = sim.task_spec(Board::Host.profile(&leo::SPEC).unwrap()).unwrap();
        let WeightTable::Claimed { log2_size, .. } = spec.table else { panic!("LEO's host table is a claim table") };
        let n = 1usize << log2_size;
        let mut host = HostTable::claimed(n, WeightFormat::Q16, 4).unwrap();
        // Keys with distinct low 15 bits (no collision in the F405's
        // 2^15), their high bits varied; weights of both signs, one beyond
        // the 16-bit range of ±2048.
        let keys: Vec<u32> = (0..200u32).map(|i| (i * 97) | (i.wrapping_mul(0x9e37_79b9) & 0xffff_8000)).collect();
        let values: Vec<f32> = (0..200).map(|i| (i as f32 - 100.0) * 0.37 + 0.01).collect();
        let mut values = values;
        values[7] = 3000.0;
        for (k, v) in keys.iter().zip(&values) {
            let Claim::Slot { slot, .. } = host.claim(*k) else { panic!("claimed") };
            host.set(slot as usize, Q16::from_f32(*v));
        }
        let mut entries = vec![0u8; n * 8];
        for (i, d) in entries.chunks_exact_mut(8).enumerate() {
            host.stored_le(i, d);
        }
        let policy = pada_core::policy::PolicyKind::Pada { delta: 0.5 };
        let header = WeightsHeader::new(&spec, policy, false, n);
        let w = StartWeights::from_parts(std::path::Path::new("w.wts"), header, entries);
        let profile = board.profile(&leo::SPEC).unwrap();
        let m = profile.weights().unwrap();
        let (bytes, report) = export(&w, &spec, &profile, m).unwrap();
        assert_eq!((report.learned, report.kept, report.dropped, report.collisions), (200, 200, 0, 0), "{report:?}");
        assert_eq!(report.clipped, 1, "{report:?}");
        // Read back through the board's own table.
        struct Read<'a>(&'a [u8], &'a [u32]);
        impl TableVisitor for Read<'_> {
            type Output = Vec<f32>;
            fn visit<W: WeightStore>(self, mut t: W) -> anyhow::Result<Vec<f32>> {
                let eb = t.entry_bytes();
                for (i, s) in self.0.chunks_exact(eb).enumerate() {
                    t.load_le(i, s);
                }
                t.restore_claims(InitialWeights { seed: 0, lo: 0, span: 1 }, 0);
                // A plain table's feature is the key masked to its size (the
                // tile coder's); a claim table's the whole key.
                let mask = if t.claims() { u32::MAX } else { t.len() as u32 - 1 };
                Ok(self.1.iter().map(|k| t.read(*k & mask).to_f32()).collect())
            }
        }
        let read = with_table(&profile, m, Read(&bytes, &keys)).unwrap();
        for (i, (r, v)) in read.iter().zip(&values).enumerate() {
            let want = if i == 7 { 2048.0 - 1.0 / 16.0 } else { (v * 16.0).round() / 16.0 };
            assert!((r - want).abs() <= 1.0 / 16.0, "{}: key {:#x}: {r} read, {v} exported", board.name(), keys[i]);
        }
    }

    #[test]
    fn the_f405s_hashed_table_reads_each_exported_feature() {
        exported_reads_back(Board::F405);
    }

    #[test]
    fn the_f429s_claim_table_reads_each_exported_feature() {
        exported_reads_back(Board::F429Sdram);
    }

    #[test]
    fn the_tag_multiplier_has_its_inverse() {
        assert_eq!(TAG_MIX.wrapping_mul(inverse(TAG_MIX)), 1);
        for key in [1u32, 2, 0xdead_beef, u32::MAX] {
            assert_eq!(pada_core::claim_table::tag_of(key, 32).wrapping_mul(inverse(TAG_MIX)), key);
        }
    }
}
