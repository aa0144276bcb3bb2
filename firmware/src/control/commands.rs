//! The host commands the controller owns: start, stop, pause, clear
//! fault (through the safety machine), a new policy, ε, the switch to
//! SARSA(λ) and the wear budget; each answered for the `Ack`/`Nack`.

use super::Controller;
use crate::config::TILINGS;
use pada_core::robot::RobotRules;
use pada_core::policy::PolicyKind;
use pada_core::safety::{Command, Event, Transition};
use pada_core::weights::WeightStore;
use pada_core::wire::{self, NackReason};

/// A host command's result, for the `Ack`/`Nack`.
pub type CommandResult = Result<(), NackReason>;

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// Carries out a host command that the controller owns (start, stop,
    /// pause, clear fault, policy, ε, switch to SARSA); the others
    /// (checkpoints, weights, ping) are the caller's.
    pub fn command(&mut self, cmd: &wire::ToChip) -> (CommandResult, Option<Transition>) {
        let safety = |c| Some(Event::Command(c));
        let event = match *cmd {
            wire::ToChip::Start(mode) => safety(Command::Start(mode)),
            wire::ToChip::Stop => safety(Command::Stop),
            wire::ToChip::Pause => safety(Command::Pause),
            wire::ToChip::ClearFault => safety(Command::ClearFault),
            _ => None,
        };
        if let Some(event) = event {
            let t = self.safety.on(event);
            let result = match t.outcome {
                pada_core::safety::Outcome::Rejected(r) => Err(NackReason::State(r)),
                _ => Ok(()),
            };
            return (result, Some(t));
        }
        let result = match *cmd {
            wire::ToChip::SetPolicy(spec) => self.set_policy(spec),
            wire::ToChip::SetEpsilon(e) => self.agent_mut().set_epsilon(e).map_err(|_| NackReason::InvalidParameter),
            wire::ToChip::SwitchToSarsa => {
                self.agent_mut().switch_to_sarsa().map_err(|_| NackReason::InvalidParameter)
            }
            wire::ToChip::SetMtbfBudget(budget) => self.set_mtbf_budget(budget),
            _ => Err(NackReason::Unsupported),
        };
        (result, None)
    }

    /// A fresh learner with `policy` (generator reseeded, weights
    /// initialised, no wear governor: `SetMtbfBudget` starts one for the
    /// new learner); only while torque is off. An invalid parameter leaves
    /// the running learner as it was.
    pub fn set_policy(&mut self, policy: PolicyKind) -> CommandResult {
        if self.torque_enabled() {
            return Err(NackReason::Busy);
        }
        if self.spec.check::<TILINGS>(policy, self.profile.layout, self.weights().len()).is_err() {
            return Err(NackReason::InvalidParameter);
        }
        let Some(agent) = self.agent.take() else {
            return Err(NackReason::Busy);
        };
        let weights = agent.into_weights();
        self.governor = None;
        // Validated above, so this builds.
        self.build(policy, weights).map_err(|_| NackReason::InvalidParameter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use pada_core::fixed::Q16;
    use pada_core::safety::RunMode;

    #[test]
    fn policy_changes_only_with_torque_off_and_reseed() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 5).unwrap();
        let fresh = c.agent().weights_checksum();
        c.agent_mut().weights_mut()[0] = Q16(12345);
        assert_eq!(c.command(&wire::ToChip::SetPolicy(PolicyKind::Pada { delta: 0.5 })).0, Ok(()));
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 });
        assert_eq!(c.agent().weights_checksum(), fresh, "fresh learner, same seed, same weights");
        assert_eq!(
            c.command(&wire::ToChip::SetPolicy(PolicyKind::Pada { delta: -1.0 })).0,
            Err(NackReason::InvalidParameter)
        );
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 });
        start(&mut c, RunMode::Learning);
        assert_eq!(c.command(&wire::ToChip::SetPolicy(PolicyKind::Sarsa)).0, Err(NackReason::Busy));
        assert!(c.weights_mut().is_none());
        assert_eq!(c.command(&wire::ToChip::SetEpsilon(2.0)).0, Err(NackReason::InvalidParameter));
        assert_eq!(c.command(&wire::ToChip::SetEpsilon(0.0)).0, Ok(()));
        assert_eq!(c.command(&wire::ToChip::SwitchToSarsa).0, Ok(()));
    }
}
