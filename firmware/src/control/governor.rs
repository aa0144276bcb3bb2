//! The wear governor on the controller: `SetMtbfBudget` starts or stops
//! it, and after every learning period it is fed the damage of the learned
//! joints and moves PADA's Δ or the low-pass filter's α
//! ([`pada_core::governor`]; its feed, [`pada_core::episodes::wear`]).
//!
//! What the board adds to the learning core's rule is its input: the
//! damage of the **reported joints** (the gearboxes the learned actions
//! drive: the pendulum's motor, LEO's hips and knees) as the board's own
//! torque estimate counts it, in periods that applied a **learning
//! action**, as `pada run` and the paper's MTBF count them. Test runs and
//! the waits between episodes are not learning and do not move the
//! governor.

use super::{CommandResult, Controller, PeriodOutput};
use crate::config::MAX_ROBOT_SERVOS;
use pada_core::robot::RobotRules;
use pada_core::episodes::wear;
use pada_core::error::ConfigError;
use pada_core::governor::{Governor, GovernorConfig, GOVERNED_JOINTS};
use pada_core::policy::PolicyKind;
use pada_core::weights::WeightStore;
use pada_core::wire::NackReason;

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    /// A fresh governor for the built `policy` holding `budget_s`,
    /// following the reported joints (at most [`GOVERNED_JOINTS`]).
    pub(super) fn governor_for(&self, policy: &PolicyKind, budget_s: f32) -> Result<Governor, ConfigError> {
        let config = GovernorConfig {
            budget_s,
            period_s: self.spec.period_s(),
            gearbox: self.spec.weakest_gearbox(),
            worst_torque_nm: self.spec.worst_commanded_torque(),
            joints: self.reported_joints().len().min(GOVERNED_JOINTS) as u8,
        };
        Governor::new(policy, &self.spec.motor()?, &config)
    }

    /// Starts the wear governor with `budget_s` (the smallest predicted
    /// MTBF over the last 1200 learning actions it accepts \[s\]), at its
    /// floor, or stops it (`None`: Δ or α stays where it is). Only with
    /// torque off and for a `pada` or `lowpass` learner; an invalid budget
    /// (`0 < budget <= 1e10 s`) changes nothing.
    pub fn set_mtbf_budget(&mut self, budget_s: Option<f32>) -> CommandResult {
        if self.torque_enabled() {
            return Err(NackReason::Busy);
        }
        let Some(budget) = budget_s else {
            self.governor = None;
            return Ok(());
        };
        let policy = self.agent().policy().built_kind();
        let governor = self.governor_for(&policy, budget).map_err(|_| NackReason::InvalidParameter)?;
        self.agent_mut().set_policy_parameter(governor.parameter()).map_err(|_| NackReason::InvalidParameter)?;
        self.policy = self.agent().policy().built_kind();
        self.governor = Some(governor);
        Ok(())
    }

    /// The wear governor, if one runs.
    pub fn governor(&self) -> Option<&Governor> {
        self.governor.as_ref()
    }

    /// Feeds the governor this period's damage of the learned joints; a
    /// move sets the policy's parameter for the next decision and is
    /// reported.
    pub(super) fn govern(&mut self, before: &[u64; MAX_ROBOT_SERVOS], out: &mut PeriodOutput) {
        let increments = wear::increments(before, &self.fatigue, self.reported_joints());
        let Some(moved) = self.governor.as_mut().and_then(|g| g.observe(&increments)) else { return };
        // The governor's ladder is the policy's own range, so this is
        // accepted; a refusal would leave the previous parameter in force.
        let _ = self.agent_mut().set_policy_parameter(moved);
        self.policy = self.agent().policy().built_kind();
        out.policy = Some(self.policy_report());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use crate::config::{TILINGS, TRACE};
    use pada_core::agent::{EpisodeEnd, Mode};
    use pada_core::safety::RunMode;
    use pada_core::wire::{self, StepKind};
    use rand_core::SeedableRng;

    #[test]
    fn the_wear_budget_command_starts_a_governor_for_pada_and_lowpass_only() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 1.0 }, table(), 3).unwrap();
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Ok(()));
        assert_eq!(c.governor().map(|g| g.budget_s()), Some(1.0e3));
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 }, "starts at the floor, one level");
        assert!(c.policy_report().governor.is_some(), "telemetry carries its status");
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 2.0e10] {
            assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(bad))).0, Err(NackReason::InvalidParameter), "{bad}");
            assert_eq!(c.governor().map(|g| g.budget_s()), Some(1.0e3), "a refused budget changes nothing");
        }
        start(&mut c, RunMode::Learning);
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(None)).0, Err(NackReason::Busy));
        stop(&mut c);
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(None)).0, Ok(()));
        assert!(c.governor().is_none());
        assert_eq!(c.policy(), PolicyKind::Pada { delta: 0.5 }, "stopping keeps the Δ in force");
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Ok(()));
        assert_eq!(c.command(&wire::ToChip::SetPolicy(PolicyKind::LowPass { alpha: 0.5 })).0, Ok(()));
        assert!(c.governor().is_none(), "a new learner starts without one");
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Ok(()));
        assert_eq!(c.policy(), PolicyKind::LowPass { alpha: 0.1 });
        for k in [PolicyKind::Sarsa, PolicyKind::Integrator { delta: 0.5 }, PolicyKind::OrnsteinUhlenbeck { theta: 0.15, sigma: 0.2 }] {
            assert_eq!(c.command(&wire::ToChip::SetPolicy(k)).0, Ok(()));
            assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(1.0e3))).0, Err(NackReason::InvalidParameter), "{k:?}");
            assert!(c.governor().is_none());
        }
    }

    #[test]
    fn a_governed_run_replays_bit_for_bit_from_its_telemetry() {
        // The board's Step records and the Policy reports of the
        // governor's moves, replayed through a host agent that takes each
        // reported Δ when it arrives, give the same actions and weights.
        let seed = 11;
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), seed).unwrap();
        assert_eq!(c.command(&wire::ToChip::SetMtbfBudget(Some(TEST_BUDGET_S))).0, Ok(()));
        start(&mut c, RunMode::Learning);
        let mut angle = 0.0;
        let sent = run_governed(&mut c, &mut angle, 3000);
        let moves = c.governor().unwrap().status().moves;
        assert!(moves >= 2, "the governor moved {moves} times: the test needs it to move");

            let mut rng = rand_pcg::Pcg32::seed_from_u64(seed);
        let mut agent = SPEC_33HZ.agent::<_, TILINGS, TRACE>(PolicyKind::Pada { delta: 0.5 }, profile(&SPEC_33HZ).layout, table()).unwrap();
        agent.reset_weights(&mut rng);
        let (mut compared, mut reports) = (0, 0);
        for r in &sent {
            let s = match r {
                Sent::Policy(p) => {
                    let g = p.governor.expect("a governed board reports its governor");
                    agent.set_policy_parameter(g.parameter).unwrap();
                    assert_eq!(p.built, PolicyKind::Pada { delta: g.parameter });
                    reports += 1;
                    continue;
                }
                Sent::Step(s) => s,
            };
            agent.set_mode(if s.mode == RunMode::Testing { Mode::Testing } else { Mode::Learning });
            match s.kind {
                StepKind::Start => assert_eq!(agent.start_episode(&s.state, &mut rng).unwrap().action, s.action),
                StepKind::Step => assert_eq!(agent.step(s.reward, &s.state, &mut rng).unwrap().action, s.action, "step {}", s.step),
                StepKind::Absorbing => agent.end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng).unwrap(),
                StepKind::Timeout => agent.end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng).unwrap(),
            }
            compared += 1;
        }
        assert!(compared > 1000 && reports >= moves, "{compared} steps, {reports} reports");
        assert_eq!(agent.weights_checksum(), c.agent().weights_checksum());
    }
}
