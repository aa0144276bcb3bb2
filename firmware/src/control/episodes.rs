//! The chip's side of the episode cycle ([`pada_core::episodes`], written
//! once for the chip and the host): bringing the robot back to its start
//! between episodes, and handing each period's observation, reward and
//! absorbing state to the shared cycle (steps 2 and 4 of
//! [`Controller::period`]). What stays here is I/O: the robot's adapter,
//! the cycle counter and the period's output.

use super::{Controller, PeriodOutput, Phase, Readings};
use crate::config::MAX_OBS;
use crate::io::CycleCounter;
use pada_core::robot::RobotRules;
use pada_core::episodes::record::Stamp;
use pada_core::episodes::Transition;
use pada_core::safety::RunMode;
use pada_core::weights::WeightStore;

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotRules,
{
    pub(super) fn begin_reset(&mut self) {
        self.phase = Phase::Resetting;
        self.episodes.abandon();
        self.robot.begin_reset();
    }

    pub(super) fn start_episode(&mut self, mode: RunMode, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        let mut obs = [0.0; MAX_OBS];
        let dims = self.robot.observe(&mut obs);
        let t0 = cycles.cycles();
        let result = {
            let (Some(agent), rng) = (self.agent.as_mut(), &mut self.rng) else { return };
            self.episodes.begin(agent, mode, &obs[..dims], rng)
        };
        out.agent_cycles = Some(cycles.cycles().wrapping_sub(t0));
        match result {
            Ok(t) => {
                self.phase = Phase::Running;
                self.record(&t, &obs[..dims], readings.time_ms, out);
            }
            // A non-finite observation (a broken sensor): try again next
            // period.
            Err(_) => self.begin_reset(),
        }
    }

    pub(super) fn continue_episode(&mut self, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        let mut obs = [0.0; MAX_OBS];
        let dims = self.robot.observe(&mut obs);
        let (reward, absorbing, footstep) = (self.robot.reward(&self.applied), self.robot.absorbing(), self.robot.footstep());
        let t0 = cycles.cycles();
        let result = {
            let (Some(agent), rng) = (self.agent.as_mut(), &mut self.rng) else { return };
            self.episodes.advance(agent, &obs[..dims], reward, absorbing, footstep, rng)
        };
        out.agent_cycles = Some(cycles.cycles().wrapping_sub(t0));
        match result {
            Ok(t) => {
                self.record(&t, &obs[..dims], readings.time_ms, out);
                if t.ended.is_some() {
                    out.episode = t.ended;
                    self.begin_reset();
                }
            }
            // A non-finite observation or reward: the episode is given up
            // (nothing learned from it) and the robot reset.
            Err(_) => self.begin_reset(),
        }
    }

    /// Keeps the decision's output for the servos and fills the step record.
    fn record(&mut self, t: &Transition, obs: &[f32], time_ms: u32, out: &mut PeriodOutput) {
        self.last_output = t.decision.map_or([0.0; pada_core::action_space::MAX_ACTION_DIMS], |d| d.output);
        let stamp = Stamp { step: self.steps, time_ms, agent_cycles: out.agent_cycles.unwrap_or(0) };
        let gearboxes = self.fatigue.joints().get(self.reported_joints()).unwrap_or(&[]);
        out.step = Some(self.episodes.record(t, self.agent(), obs, gearboxes, stamp));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use core::cell::Cell;
    use pada_core::policy::PolicyKind;
    use pada_core::wire::StepKind;

    #[test]
    fn pendulum_episodes_start_after_hanging_still_and_end_by_time() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Pada { delta: 0.5 }, table(), 7).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut kinds = std::vec::Vec::new();
        let mut episodes = std::vec::Vec::new();
        for k in 0..400u32 {
            c.period(&pendulum_readings(0, k * 30), &clock, &mut out);
            assert!(out.torque);
            if let Some(s) = &out.step {
                kinds.push(s.kind);
                assert_eq!(s.state.len(), 2);
                // An end reports no output (no decision).
                let ends = matches!(s.kind, StepKind::Absorbing | StepKind::Timeout);
                assert_eq!(s.output.len(), if ends { 0 } else { 1 });
                assert_eq!(s.joints.len(), 1);
                assert!(out.agent_cycles.is_some());
            }
            if let Some(e) = out.episode {
                episodes.push(e);
            }
        }
        // 34 periods of waiting (1 s still), then Start, 99 Steps, Timeout.
        assert_eq!(kinds[0], StepKind::Start);
        assert!(kinds.iter().filter(|k| **k == StepKind::Step).count() >= 99);
        assert_eq!(kinds[100], StepKind::Timeout);
        assert_eq!(episodes[0].length, 100);
        assert_eq!(episodes[0].index, 0);
        assert_eq!(episodes[0].mode, RunMode::Learning);
        // Reward at the bottom, at rest, with the actions taken.
        assert!(episodes[0].total_reward < 0.0);
    }

    #[test]
    fn every_tenth_episode_is_a_test() {
        let mut c = Controller::new(Pendulum::at_33hz(), profile(&SPEC_33HZ), PolicyKind::Sarsa, table(), 3).unwrap();
        start(&mut c, RunMode::Learning);
        let clock = Clock(Cell::new(0));
        let mut out = PeriodOutput::default();
        let mut modes = std::vec::Vec::new();
        for k in 0..(11 * 140) {
            c.period(&pendulum_readings(0, k * 30), &clock, &mut out);
            if let Some(e) = out.episode {
                modes.push(e.mode);
            }
        }
        assert!(modes.len() >= 11, "{}", modes.len());
        assert!(modes[..10].iter().all(|m| *m == RunMode::Learning));
        assert_eq!(modes[10], RunMode::Testing);
    }
}
