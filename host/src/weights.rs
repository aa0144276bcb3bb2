//! Learned weights on disk: a versioned file with a CRC-32, which refuses
//! files written for another configuration and names the parameter that
//! differs.
//!
//! # Format (version 2)
//!
//! ```text
//! "PADAWTS2"                      8 bytes: magic with the format version
//! header length n                 u32 little endian
//! header                          n bytes of JSON (WeightsHeader)
//! entries                         count × entry_bytes: each the weight (i32
//!                                 little endian, raw Q16.16), then a claim
//!                                 table's 32-bit tag (pada_core::claim_table)
//! CRC-32/ISO-HDLC                 u32 little endian, of everything before
//! ```
//!
//! Version 1 (weights without claim tags, from before the claim table) is
//! refused with a line that says so.

use crate::experiment::task::{TaskSpec, WeightTable};
use crate::experiment::{HostAgent, TILINGS};
use pada_core::checkpoint::crc32;
use pada_core::policy::PolicyKind;
use pada_core::weights::WeightStore;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Magic and format version.
pub const MAGIC: &[u8; 8] = b"PADAWTS2";

/// Everything the weights depend on; loading compares it field by field.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WeightsHeader {
    /// Task name.
    pub task: String,
    /// The policy the agent learned with.
    pub policy: PolicyKind,
    /// Whether it had switched back to SARSA(λ) when saved.
    pub switched: bool,
    /// Tilings.
    pub tilings: usize,
    /// Weight table layout and size, e.g. `hashed 2^24` (with the action
    /// tile widths when actions are tile-coded).
    pub table: String,
    /// Number of weights.
    pub weights: usize,
    /// Bytes per stored entry: the weight's 4, plus a claim tag's 4.
    pub entry_bytes: usize,
    /// A claim table's seed of its unclaimed features' initial weights (0
    /// for other tables).
    #[serde(default)]
    pub table_seed: u64,
    /// Claims the claim table refused while it learned.
    #[serde(default)]
    pub claims_refused: u32,
    /// State dimensions as `min..max/width` (with `~` for wrapping).
    pub state: Vec<String>,
    /// Motor levels per dimension.
    pub motor: Vec<Vec<f32>>,
    /// SARSA α.
    pub alpha: f32,
    /// Discount γ.
    pub gamma: f32,
    /// Trace decay λ.
    pub lambda: f32,
    /// Exploration ε.
    pub epsilon: f32,
}

impl WeightsHeader {
    /// The header of an agent for `spec` with `policy` and `n` weights.
    pub fn new(spec: &TaskSpec, policy: PolicyKind, switched: bool, n: usize) -> Self {
        WeightsHeader {
            task: spec.name.to_string(),
            policy,
            switched,
            tilings: TILINGS,
            table: match (&spec.table, &spec.action_tiles) {
                (WeightTable::Exact, _) => "exact".into(),
                (WeightTable::ExactOf { weights }, _) => format!("exact in {weights}"),
                (WeightTable::Hashed { log2_size }, None) => format!("hashed 2^{log2_size}"),
                (WeightTable::Hashed { log2_size }, Some(w)) => {
                    format!("hashed 2^{log2_size}, action tiles {w:?}")
                }
                (WeightTable::Claimed { log2_size, .. }, None) => format!("claim 2^{log2_size}"),
                (WeightTable::Claimed { log2_size, .. }, Some(w)) => {
                    format!("claim 2^{log2_size}, action tiles {w:?}")
                }
            },
            weights: n,
            entry_bytes: match spec.table {
                WeightTable::Claimed { format, tag_bytes, .. } => format.bytes() + tag_bytes,
                _ => 4,
            },
            table_seed: 0,
            claims_refused: 0,
            state: spec.state.iter().map(|d| format!("{:?}", d)).collect(),
            motor: (0..spec.motor.dims())
                .map(|i| spec.motor.dim(i).values().to_vec())
                .collect(),
            alpha: spec.params.alpha,
            gamma: spec.params.gamma,
            lambda: spec.params.lambda,
            epsilon: spec.params.epsilon,
        }
    }

    /// The first parameter in which `self` (the file) differs from
    /// `expected`, as `(name, file value, expected value)`. The policy and
    /// the switch are not compared: they describe the file.
    pub fn mismatch(&self, expected: &WeightsHeader) -> Option<(&'static str, String, String)> {
        macro_rules! cmp {
            ($f:ident) => {
                if self.$f != expected.$f {
                    return Some((
                        stringify!($f),
                        format!("{:?}", self.$f),
                        format!("{:?}", expected.$f),
                    ));
                }
            };
        }
        cmp!(task);
        cmp!(tilings);
        cmp!(table);
        cmp!(weights);
        cmp!(entry_bytes);
        cmp!(state);
        cmp!(motor);
        cmp!(alpha);
        cmp!(gamma);
        cmp!(lambda);
        cmp!(epsilon);
        None
    }
}

/// The file's bytes for `header` and the entries of `table` (as many as
/// `header.weights`, `header.entry_bytes` each).
pub fn encode<W: WeightStore + ?Sized>(header: &WeightsHeader, table: &W) -> anyhow::Result<Vec<u8>> {
    anyhow::ensure!(
        header.weights == table.len() && header.entry_bytes == table.entry_bytes(),
        "weights header says {} entries of {} bytes, the table has {} of {}",
        header.weights,
        header.entry_bytes,
        table.len(),
        table.entry_bytes()
    );
    let json = serde_json::to_vec(header)?;
    let eb = header.entry_bytes;
    let mut b = Vec::with_capacity(16 + json.len() + eb * table.len());
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&(json.len() as u32).to_le_bytes());
    b.extend_from_slice(&json);
    let start = b.len();
    b.resize(start + eb * table.len(), 0);
    for (i, dst) in b[start..].chunks_exact_mut(eb).enumerate() {
        table.stored_le(i, dst);
    }
    let crc = crc32(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    Ok(b)
}

/// Parses a file's bytes: magic, checksum, header, and the entries'
/// bytes (`header.entry_bytes` each).
pub fn decode(b: &[u8]) -> anyhow::Result<(WeightsHeader, &[u8])> {
    anyhow::ensure!(
        b.len() >= 16 && &b[..6] == b"PADAWT",
        "not a pada weights file (bad magic)"
    );
    anyhow::ensure!(
        &b[..8] != b"PADAWTS1",
        "weights file version 1: a table without claim tags, from before the claim table \
         (this pada reads version 2; save the weights again with --save-weights)"
    );
    anyhow::ensure!(
        &b[..8] == MAGIC,
        "unsupported weights file version {:?} (this pada reads {:?})",
        String::from_utf8_lossy(&b[6..8]),
        String::from_utf8_lossy(&MAGIC[6..8])
    );
    let (body, tail) = b.split_at(b.len() - 4);
    let stored = u32::from_le_bytes(tail.try_into().expect("4 bytes"));
    let actual = crc32(body);
    anyhow::ensure!(
        stored == actual,
        "weights file is corrupted: checksum {actual:#010x} does not match the stored {stored:#010x}"
    );
    let n = u32::from_le_bytes(body[8..12].try_into().expect("4 bytes")) as usize;
    anyhow::ensure!(12 + n <= body.len(), "weights file is truncated (header)");
    let header: WeightsHeader = serde_json::from_slice(&body[12..12 + n])?;
    let payload = &body[12 + n..];
    anyhow::ensure!(
        matches!(header.entry_bytes, 4 | 8) && Some(payload.len()) == header.weights.checked_mul(header.entry_bytes),
        "weights file holds {} bytes of entries, its header says {} entries of {} bytes (4 or 8)",
        payload.len(),
        header.weights,
        header.entry_bytes
    );
    Ok((header, payload))
}

/// Saves `agent`'s weights for `spec`.
pub fn save(
    path: &Path,
    spec: &TaskSpec,
    policy: PolicyKind,
    switched: bool,
    agent: &HostAgent,
) -> anyhow::Result<()> {
    let w = agent.weights();
    let state = agent.state();
    let header = WeightsHeader {
        table_seed: state.table_seed,
        claims_refused: state.stats.claims_refused,
        ..WeightsHeader::new(spec, policy, switched, w.len())
    };
    crate::output::write_atomic(path, &encode(&header, w)?)
}

/// Loads a weights file for `spec`: an agent with its policy (switched
/// back to SARSA(λ) if it was) and its weights. Refuses a file for another
/// configuration, naming the first differing parameter.
pub fn load(path: &Path, spec: &TaskSpec) -> anyhow::Result<(WeightsHeader, HostAgent)> {
    let bytes =
        std::fs::read(path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    let (header, entries) =
        decode(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut agent = crate::experiment::build_agent(spec, header.policy)?;
    let expected = WeightsHeader::new(spec, header.policy, header.switched, agent.weights().len());
    if let Some((name, file, want)) = header.mismatch(&expected) {
        anyhow::bail!(
            "{}: written for another configuration: {name} is {file} in the file but {want} here",
            path.display()
        );
    }
    let eb = header.entry_bytes;
    for (i, src) in entries.chunks_exact(eb).enumerate() {
        agent.weights_mut().load_le(i, src);
    }
    agent.rehash();
    // A claim table counts its claimed slots and takes its initial
    // weights' seed back.
    let mut state = agent.state();
    state.table_seed = header.table_seed;
    state.stats.claims_refused = header.claims_refused;
    agent.restore_state(&state).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    if header.switched {
        agent
            .switch_to_sarsa()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    Ok((header, agent))
}
