//! The tile coder of an agent: the observation's dimensions and the
//! policy's own over the policy's learner actions, built in one place.

use crate::action_space::ActionSpace;
use crate::error::ConfigError;
use crate::policy::{Policy, PolicyKind};
use crate::tile_coding::{Layout, StateDim, TileCoder, MAX_STATE_DIMS};
use heapless::Vec;

/// The tile coder of an agent for `obs` driving `policy`, on a table of
/// `table_len` weights laid out as `layout`: the observation's dimensions,
/// then the policy's own (the Markov filters' previous action), over the
/// policy's learner actions. The one place it is built, for the agent
/// ([`super::Agent::new`]), the robot's check before a new policy
/// ([`crate::robot::RobotSpec::check`]) and the size of an exact table
/// ([`exact_table_len`]).
pub fn coder_for<const TILINGS: usize>(
    obs: &[StateDim],
    policy: &Policy,
    layout: Layout,
    table_len: usize,
) -> Result<TileCoder<TILINGS>, ConfigError> {
    let too_many = || {
        ConfigError::new("state dimensions", (obs.len() + policy.extension_len()) as f32, "at most 16 including the policy's")
    };
    let mut dims: Vec<StateDim, MAX_STATE_DIMS> = Vec::new();
    for d in obs {
        dims.push(*d).map_err(|_| too_many())?;
    }
    for i in 0..policy.extension_len() {
        dims.push(policy.extension_dim(i)?).map_err(|_| too_many())?;
    }
    TileCoder::new(&dims, policy.learner_space().joint_count(), layout, table_len)
}

/// Weights of the exact table (tilings × tiles × learner actions) an agent
/// for `obs` driving `motor` through `policy` needs: a Markov filter's extra
/// state dimension and PADA's fewer learner actions change it.
pub fn exact_table_len<const TILINGS: usize>(
    obs: &[StateDim],
    motor: ActionSpace,
    policy: PolicyKind,
) -> Result<usize, ConfigError> {
    let policy = Policy::new(policy, motor)?;
    let coder = coder_for::<TILINGS>(obs, &policy, Layout::Exact, u32::MAX as usize)?;
    coder.exact_size().ok_or_else(|| ConfigError::new("exact table size", f32::INFINITY, "fewer than 2^32 weights"))
}
