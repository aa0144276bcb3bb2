//! The telemetry `Step` of one agent call: everything a host replay needs
//! (kind, observation, reward, action, TD error) and the fatigue of the
//! counted gearboxes, as the chip and the host both report it
//! ([`crate::wire::Step`]).

use super::{Episodes, Transition};
use crate::agent::Agent;
use crate::fatigue::JointFatigue;
use crate::weights::WeightStore;
use crate::wire::{self, RunMode, StepKind};
use heapless::Vec;

/// Where and when a call happened: the driver's counters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stamp {
    /// The driver's step counter (control periods on the chip, agent calls
    /// on the host).
    pub step: u32,
    /// Time since the run began \[ms\].
    pub time_ms: u32,
    /// Cycles the agent call took (0 where nothing counts them).
    pub agent_cycles: u32,
}

impl Episodes {
    /// The `Step` record of `t`, the call just made on `agent` in
    /// observation `obs`; `gearboxes` are the counted gearboxes' fatigue
    /// (the first [`wire::MAX_GEARBOXES`] are reported).
    ///
    /// At an end there is no new decision: the record carries no output,
    /// and the action of the decision whose outcome it reports. The
    /// TD error is the learning update's, so 0 at a `Start` and in a test
    /// episode. An observation longer than a record holds is cut to
    /// [`wire::MAX_STATE_DIMS`].
    pub fn record<W: WeightStore, const T: usize, const TR: usize>(
        &self,
        t: &Transition,
        agent: &Agent<W, T, TR>,
        obs: &[f32],
        gearboxes: &[JointFatigue],
        stamp: Stamp,
    ) -> wire::Step {
        let dims = agent.policy().motor_space().dims().min(wire::MAX_ACTION_DIMS);
        let output = match &t.decision {
            Some(d) => &d.output[..dims],
            None => &[],
        };
        let td_error = match (t.kind, t.mode) {
            (StepKind::Start, _) | (_, RunMode::Testing) => 0,
            _ => agent.stats().last_td_error.0,
        };
        let joints = gearboxes
            .iter()
            .take(wire::MAX_GEARBOXES)
            .map(|j| wire::JointFatigue { damage: j.damage(), reengagements: j.reengagements().min(u32::MAX as u64) as u32 })
            .collect();
        wire::Step {
            step: stamp.step,
            time_ms: stamp.time_ms,
            episode: self.started.wrapping_sub(1),
            mode: t.mode,
            kind: t.kind,
            state: obs.iter().take(wire::MAX_STATE_DIMS).copied().collect::<Vec<_, { wire::MAX_STATE_DIMS }>>(),
            action: t.decision.map_or(self.last_action, |d| d.action),
            output: output.iter().copied().collect(),
            reward: t.reward,
            td_error,
            explored: t.decision.is_some_and(|d| d.explored),
            footstep: t.footstep,
            joints,
            loop_us: 0,
            agent_cycles: stamp.agent_cycles,
        }
    }
}
