//! Building the host's SARSA(λ) agent for a task and a policy.
//!
//! The tilings and trace capacity of every board ([`pada_core::profile`]:
//! 16 tilings, the paper's reference configuration; a trace of at most 64
//! entries, which the paper's γλ = 0.99·0.92 never fills), and a weight
//! table laid out as the task asks ([`WeightTable`]).

use crate::experiment::table::HostTable;
use crate::experiment::task::{TaskSpec, WeightTable};
use pada_core::agent::Agent;
use pada_core::policy::PolicyKind;
use pada_core::tile_coding::Layout;
use pada_core::weights::WeightFormat;

pub use pada_core::profile::{TILINGS, TRACE};

/// The agent the host runs: weights on the heap, in a plain slice or a
/// claim table ([`HostTable`]).
pub type HostAgent = Agent<HostTable, TILINGS, TRACE>;

/// An agent for `spec` driving its motor through `policy`, with the task's
/// learning parameters; the weights still need
/// [`Agent::reset_weights`].
pub fn build_agent(spec: &TaskSpec, policy: PolicyKind) -> anyhow::Result<HostAgent> {
    let err = |e: pada_core::error::ConfigError| anyhow::anyhow!("{e}");
    let (layout, size) = match spec.table {
        WeightTable::Hashed { log2_size } => (Layout::Hashed, 1usize << log2_size),
        WeightTable::Claimed { log2_size, .. } => (Layout::Claimed, 1usize << log2_size),
        WeightTable::ExactOf { weights } => (Layout::Exact, weights),
        // The exact size depends on the policy's state extension and its
        // learner actions.
        WeightTable::Exact => {
            (Layout::Exact, pada_core::agent::exact_table_len::<TILINGS>(&spec.state, spec.motor.clone(), policy).map_err(err)?)
        }
    };
    let weights = match spec.table {
        WeightTable::Claimed { format, tag_bytes, when_full, .. } => HostTable::claimed(size, format, tag_bytes)?.on_full(when_full),
        // A board's hashed table keeps its weights in the board's format
        // (the F405's: 16 bits); the host's own tables are Q16.
        _ => HostTable::plain_of(size, spec.profile.map_or(WeightFormat::Q16, |p| p.format))?,
    };
    let mut agent = Agent::new(
        &spec.state,
        spec.motor.clone(),
        policy,
        spec.params,
        layout,
        weights,
    )
    .map_err(err)?;
    if let Some(widths) = &spec.action_tiles {
        agent.generalise_actions(widths).map_err(err)?;
    }
    Ok(agent)
}
