//! Learned weights on disk: a versioned file with a CRC-32, which refuses
//! files written for another configuration and names the parameter that
//! differs.
//!
//! # Format (version 1)
//!
//! ```text
//! "PADAWTS1"                      8 bytes: magic with the format version
//! header length n                 u32 little endian
//! header                          n bytes of JSON (WeightsHeader)
//! weights                         count × i32 little endian (raw Q16.16)
//! CRC-32/ISO-HDLC                 u32 little endian, of everything before
//! ```

use crate::experiment::task::{TaskSpec, WeightTable};
use crate::experiment::{HostAgent, TILINGS};
use pada_core::checkpoint::crc32;
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Magic and format version.
pub const MAGIC: &[u8; 8] = b"PADAWTS1";

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
            },
            weights: n,
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
        cmp!(state);
        cmp!(motor);
        cmp!(alpha);
        cmp!(gamma);
        cmp!(lambda);
        cmp!(epsilon);
        None
    }
}

/// The file's bytes for `header` and `weights`.
pub fn encode(header: &WeightsHeader, weights: &[Q16]) -> anyhow::Result<Vec<u8>> {
    let json = serde_json::to_vec(header)?;
    let mut b = Vec::with_capacity(16 + json.len() + 4 * weights.len());
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&(json.len() as u32).to_le_bytes());
    b.extend_from_slice(&json);
    for w in weights {
        b.extend_from_slice(&w.0.to_le_bytes());
    }
    let crc = crc32(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    Ok(b)
}

/// Parses a file's bytes: magic, checksum, header, weights.
pub fn decode(b: &[u8]) -> anyhow::Result<(WeightsHeader, Vec<Q16>)> {
    anyhow::ensure!(
        b.len() >= 16 && &b[..6] == b"PADAWT",
        "not a pada weights file (bad magic)"
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
        payload.len() == 4 * header.weights,
        "weights file holds {} bytes of weights, its header says {} weights",
        payload.len(),
        header.weights
    );
    let weights = payload
        .chunks_exact(4)
        .map(|c| Q16(i32::from_le_bytes(c.try_into().expect("4 bytes"))))
        .collect();
    Ok((header, weights))
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
    let header = WeightsHeader::new(spec, policy, switched, w.len());
    crate::output::write_atomic(path, &encode(&header, w)?)
}

/// Loads a weights file for `spec`: an agent with its policy (switched
/// back to SARSA(λ) if it was) and its weights. Refuses a file for another
/// configuration, naming the first differing parameter.
pub fn load(path: &Path, spec: &TaskSpec) -> anyhow::Result<(WeightsHeader, HostAgent)> {
    let bytes =
        std::fs::read(path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    let (header, weights) =
        decode(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut agent = crate::experiment::build_agent(spec, header.policy)?;
    let expected = WeightsHeader::new(spec, header.policy, header.switched, agent.weights().len());
    if let Some((name, file, want)) = header.mismatch(&expected) {
        anyhow::bail!(
            "{}: written for another configuration: {name} is {file} in the file but {want} here",
            path.display()
        );
    }
    agent.weights_mut().copy_from_slice(&weights);
    agent.rehash();
    if header.switched {
        agent
            .switch_to_sarsa()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
    }
    Ok((header, agent))
}
