//! Building the host's SARSA(λ) agent for a task and a policy.
//!
//! The tilings and trace capacity of every board ([`pada_core::profile`]:
//! 16 tilings, the paper's reference configuration; a trace of at most 64
//! entries, which the paper's γλ = 0.99·0.92 never fills), and a weight
//! table laid out as the task asks ([`WeightTable`]).

use crate::experiment::task::{TaskSpec, WeightTable};
use pada_core::agent::Agent;
use pada_core::fixed::Q16;
use pada_core::policy::{Policy, PolicyKind};
use pada_core::tile_coding::{Layout, TileCoder};

pub use pada_core::profile::{TILINGS, TRACE};

/// The agent the host runs: weights in a boxed slice.
pub type HostAgent = Agent<Box<[Q16]>, TILINGS, TRACE>;

/// An agent for `spec` driving its motor through `policy`, with the task's
/// learning parameters; the weights still need
/// [`Agent::reset_weights`].
pub fn build_agent(spec: &TaskSpec, policy: PolicyKind) -> anyhow::Result<HostAgent> {
    let err = |e: pada_core::error::ConfigError| anyhow::anyhow!("{e}");
    let (layout, size) = match spec.table {
        WeightTable::Hashed { log2_size } => (Layout::Hashed, 1usize << log2_size),
        WeightTable::ExactOf { weights } => (Layout::Exact, weights),
        WeightTable::Exact => {
            // The exact size depends on the policy's state extension and
            // its learner actions: ask a coder built like the agent's.
            let p = Policy::new(policy, spec.motor.clone()).map_err(err)?;
            let mut dims = spec.state.clone();
            for i in 0..p.extension_len() {
                dims.push(p.extension_dim(i).map_err(err)?);
            }
            let coder = TileCoder::<TILINGS>::new(
                &dims,
                p.learner_space().joint_count(),
                Layout::Exact,
                u32::MAX as usize,
            )
            .map_err(err)?;
            (Layout::Exact, coder.exact_size().unwrap_or(0))
        }
    };
    let weights = vec![Q16::ZERO; size].into_boxed_slice();
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
