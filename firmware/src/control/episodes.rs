//! The episode cycle: bringing the robot back to its start between
//! episodes, the agent's `start_episode`, `step` and `end_episode` (at an
//! absorbing state or the time limit), one greedy test episode every
//! `test_interval` learning episodes (Section VI), LEO's footstep remap,
//! and the step record of each decision (steps 2 and 4 of
//! [`Controller::period`]).

use super::{Controller, PeriodOutput, Phase, Readings};
use crate::config::MAX_OBS;
use crate::io::CycleCounter;
use crate::robot::RobotAdapter;
use heapless::Vec;
use pada_core::agent::{Decision, EpisodeEnd, Mode};
use pada_core::safety::RunMode;
use pada_core::weights::WeightStore;
use pada_core::wire::{self, StepKind};

impl<W, R> Controller<W, R>
where
    W: WeightStore,
    R: RobotAdapter,
{
    pub(super) fn begin_reset(&mut self) {
        self.phase = Phase::Resetting;
        self.robot.begin_reset();
    }

    pub(super) fn start_episode(&mut self, mode: RunMode, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        // Every `test_interval` learning episodes, one greedy test episode.
        let test = mode == RunMode::Testing || self.since_test >= self.spec.test_interval;
        self.episode_mode = if test { RunMode::Testing } else { RunMode::Learning };
        if test {
            if mode == RunMode::Learning {
                self.since_test = 0;
            }
        } else {
            self.since_test += 1;
        }
        self.agent_mut().set_mode(if test { Mode::Testing } else { Mode::Learning });
        self.episode_return = 0.0;
        let mut obs = [0.0; MAX_OBS];
        let dims = self.robot.observe(&mut obs);
        let t0 = cycles.cycles();
        let result = {
            let (agent, rng) = (self.agent.as_mut(), &mut self.rng);
            agent.map(|a| a.start_episode(&obs[..dims], rng))
        };
        out.agent_cycles = Some(cycles.cycles().wrapping_sub(t0));
        match result {
            Some(Ok(decision)) => {
                self.phase = Phase::Running { steps: 0 };
                self.record(StepKind::Start, &obs[..dims], 0.0, Some(decision), false, readings.time_ms, out);
            }
            // A non-finite observation (a broken sensor): try again next
            // period.
            _ => self.begin_reset(),
        }
    }

    pub(super) fn continue_episode(&mut self, steps: u32, readings: &Readings, cycles: &impl CycleCounter, out: &mut PeriodOutput) {
        let mut obs = [0.0; MAX_OBS];
        let dims = self.robot.observe(&mut obs);
        let (reward, absorbing) = (self.robot.reward(&self.applied), self.robot.absorbing());
        let timeout = steps >= self.spec.episode_steps;
        // A footstep: the policy's memory moves with the joints before the
        // next decision.
        let footstep = self.robot.footstep() && self.spec.footstep_remap.is_some();
        if let (true, Some(map)) = (footstep, self.spec.footstep_remap) {
            self.agent_mut().remap_memory(&map);
        }
        let t0 = cycles.cycles();
        let (kind, result) = {
            let Some(agent) = self.agent.as_mut() else { return };
            let rng = &mut self.rng;
            if absorbing {
                (StepKind::Absorbing, agent.end_episode(reward, EpisodeEnd::Absorbing, rng).map(|_| None))
            } else if timeout {
                (StepKind::Timeout, agent.end_episode(reward, EpisodeEnd::Timeout(&obs[..dims]), rng).map(|_| None))
            } else {
                (StepKind::Step, agent.step(reward, &obs[..dims], rng).map(Some))
            }
        };
        out.agent_cycles = Some(cycles.cycles().wrapping_sub(t0));
        match result {
            Ok(decision) => {
                self.episode_return += reward;
                self.record(kind, &obs[..dims], reward, decision, footstep, readings.time_ms, out);
                if decision.is_some() {
                    self.phase = Phase::Running { steps };
                } else {
                    out.episode = Some(wire::Episode {
                        index: self.episodes.wrapping_sub(1),
                        mode: self.episode_mode,
                        total_reward: self.episode_return,
                        length: steps,
                        weights_checksum: self.agent().weights_checksum(),
                    });
                    self.begin_reset();
                }
            }
            // A non-finite observation or reward: the episode is given up
            // (nothing learned from it) and the robot reset.
            Err(_) => self.begin_reset(),
        }
    }

    /// Fills the step record.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &mut self,
        kind: StepKind,
        obs: &[f32],
        reward: f32,
        decision: Option<Decision>,
        footstep: bool,
        time_ms: u32,
        out: &mut PeriodOutput,
    ) {
        if kind == StepKind::Start {
            self.episodes = self.episodes.wrapping_add(1);
        }
        let outputs = self.agent().policy().motor_space().dims();
        match decision {
            Some(d) => {
                self.last_action = d.action;
                self.last_output = d.output;
            }
            None => self.last_output = [0.0; pada_core::action_space::MAX_ACTION_DIMS],
        }
        let td_error = match (kind, self.episode_mode) {
            (StepKind::Start, _) | (_, RunMode::Testing) => 0,
            _ => self.agent().stats().last_td_error.0,
        };
        let mut joints = Vec::new();
        for j in self.reported_joints() {
            if let Some(f) = self.fatigue.joint(j) {
                let _ = joints.push(wire::JointFatigue {
                    damage: f.damage(),
                    reengagements: f.reengagements().min(u32::MAX as u64) as u32,
                });
            }
        }
        out.step = Some(wire::Step {
            step: self.steps,
            time_ms,
            episode: self.episodes.wrapping_sub(1),
            mode: self.episode_mode,
            kind,
            state: Vec::from_slice(obs).unwrap_or_default(),
            action: self.last_action,
            output: Vec::from_slice(&self.last_output[..outputs]).unwrap_or_default(),
            reward,
            td_error,
            explored: decision.is_some_and(|d| d.explored),
            footstep,
            joints,
            loop_us: 0,
            agent_cycles: out.agent_cycles.unwrap_or(0),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::test_support::*;
    use crate::config::Robot;
    use crate::pendulum::Pendulum33;
    use core::cell::Cell;
    use pada_core::policy::PolicyKind;

    #[test]
    fn pendulum_episodes_start_after_hanging_still_and_end_by_time() {
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Pada { delta: 0.5 }, table(), 7).unwrap();
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
                assert_eq!(s.output.len(), 1);
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
        let mut c = Controller::<_, Pendulum33>::new(profile(Robot::Pendulum33), PolicyKind::Sarsa, table(), 3).unwrap();
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
