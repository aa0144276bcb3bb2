//! A run that continues from saved weights (`pada run --weights FILE`):
//! each trial starts from the file's weights instead of the task's
//! initial ones, everything else as a run from nothing.
//!
//! The file must describe the same learner: the task, the table (layout,
//! size, entry width), the state and motor, and SARSA(λ)'s parameters, as
//! [`crate::weights::load`] checks them; and the run's algorithm must
//! learn in the same state and action space as the file's (SARSA(λ),
//! PADA and the low-pass filter share SARSA's learner; a Markov filter
//! adds a state dimension, an integrator learns other actions). The
//! algorithm's own parameter (Δ, α) may differ: it restricts decisions,
//! the weights mean the same.
//!
//! A trial still draws its initial weights from its seed before they are
//! replaced, so its random numbers afterwards are those of the same trial
//! from nothing: the two runs differ only in where the weights start.

use crate::experiment::task::TaskSpec;
use crate::experiment::{build_agent, HostAgent};
use crate::weights::{decode, WeightsHeader};
use pada_core::policy::{Policy, PolicyKind};
use pada_core::weights::WeightStore;
use std::path::{Path, PathBuf};

/// Weights a run starts from: a checked file's header and entries.
#[derive(Debug, Clone)]
pub struct StartWeights {
    /// The file they came from (for messages).
    pub path: PathBuf,
    /// Its header.
    pub header: WeightsHeader,
    /// Its entries' bytes, `header.entry_bytes` each.
    entries: Vec<u8>,
}

impl StartWeights {
    /// Reads `path` for a run of `spec` with `policy`; refuses, with one
    /// line naming the difference, a file for another task, table or
    /// learner.
    pub fn load(path: &Path, spec: &TaskSpec, policy: PolicyKind) -> anyhow::Result<StartWeights> {
        let bytes =
            std::fs::read(path).map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
        let (header, entries) = decode(&bytes).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let agent = build_agent(spec, policy)?;
        let expected = WeightsHeader::new(spec, policy, false, agent.weights().len());
        if let Some((name, file, want)) = header.mismatch(&expected) {
            anyhow::bail!(
                "{}: written for another configuration: {name} is {file} in the file but {want} here",
                path.display()
            );
        }
        same_learner(&header.policy, &policy, spec).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        Ok(StartWeights { path: path.to_path_buf(), header, entries: entries.to_vec() })
    }

    /// Puts the weights into `agent` (built for the spec and policy they
    /// were loaded for, its weights already reset from the trial's seed).
    pub fn apply(&self, agent: &mut HostAgent) -> anyhow::Result<()> {
        let eb = self.header.entry_bytes;
        for (i, src) in self.entries.chunks_exact(eb).enumerate() {
            agent.weights_mut().load_le(i, src);
        }
        agent.rehash();
        let mut state = agent.state();
        state.table_seed = self.header.table_seed;
        state.stats.claims_refused = self.header.claims_refused;
        agent.restore_state(&state).map_err(|e| anyhow::anyhow!("{}: {e}", self.path.display()))
    }

    /// Weights of `header` with `entries`, as if read from `path` (for
    /// tests of what reads them).
    pub fn from_parts(path: &Path, header: WeightsHeader, entries: Vec<u8>) -> StartWeights {
        StartWeights { path: path.to_path_buf(), header, entries }
    }

    /// The file's entries (`header.entry_bytes` each), for an export into
    /// a board's table.
    pub fn entries(&self) -> &[u8] {
        &self.entries
    }
}

/// Whether `run`'s learner has the state and actions of `file`'s, or one
/// line saying how they differ.
fn same_learner(file: &PolicyKind, run: &PolicyKind, spec: &TaskSpec) -> anyhow::Result<()> {
    let err = |e: pada_core::error::ConfigError| anyhow::anyhow!("{e}");
    let a = Policy::new(*file, spec.motor.clone()).map_err(err)?;
    let b = Policy::new(*run, spec.motor.clone()).map_err(err)?;
    let name = |k: &PolicyKind| crate::experiment::algo::label(k);
    anyhow::ensure!(
        a.extension_len() == b.extension_len() && a.learner_space() == b.learner_space(),
        "written for another learner: {} learned it, and {} learns in another state or action space \
         (sarsa, pada, lowpass and the gentle explorations share one; the integrators and Markov variants each their own)",
        name(file),
        name(run)
    );
    Ok(())
}
