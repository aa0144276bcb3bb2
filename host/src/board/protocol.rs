//! The run protocol of a board's trial (Section VI), written once for both
//! of its drivers: `pada run --board` ([`super::trial`], the firmware's
//! controller on the host) and `pada sil` (`crate::sil`, the firmware image
//! in QEMU). Both tell it every episode the board reports and send the
//! commands it returns, so the two runs take the same decisions at the same
//! episodes:
//!
//! 1. `SetPolicy` (a fresh learner from the seed), then `Start(Testing)`:
//!    a greedy test episode before learning;
//! 2. after it, `Start(Learning)`; the board runs its own greedy test
//!    episode after every tenth learning episode;
//! 3. once the learning episodes' steps reach the budget
//!    (`round(seconds / period)`), at the end of a learning episode,
//!    `Start(Testing)`: the final test episode;
//! 4. after it, done.
//!
//! # Seeds
//!
//! Both take `pada run`'s seed semantics: a master seed `K`
//! (`--seed`, default 1) gives trial `i` the learner seed
//! [`crate::seed::trial_seed`]`(K, i)` (SplitMix64); a SIL run is trial 0.
//! So `pada sil --seed K` and trial 0 of `pada run --board … --seed K` seed
//! the firmware's generator alike. (A real board, which no host
//! configures, seeds it with `pada_firmware::config::DEFAULT_SEED`.)

use crate::experiment::governed::GovernorTrial;
use crate::experiment::measured::TrialCounts;
use crate::experiment::TestPoint;
use pada_core::agent::AgentStats;
use pada_core::claim_table::Occupancy;
use pada_core::policy::PolicyKind;
use pada_core::wire::{Episode, RunMode, ToChip};

/// Where a run is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Waiting for the first test episode.
    FirstTest,
    /// Learning.
    Learning,
    /// Waiting for the final test episode.
    FinalTest,
    /// Finished.
    Done,
}

/// The protocol's state and the learning curve so far.
#[derive(Debug, Clone)]
pub struct RunProtocol {
    phase: Phase,
    period_s: f64,
    budget_steps: u64,
    learning_steps: u64,
    learning_episodes: u32,
    /// Learning episodes that ended in an absorbing state (falls).
    learning_falls: u64,
    /// Steps of the test episodes.
    test_steps: u64,
    curve: Vec<TestPoint>,
}

/// How a reported episode went, beyond the `Episode` message: what the
/// plant saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeOutcome {
    /// It ended in an absorbing state (a fall).
    pub fell: bool,
    /// Distance walked \[m\] (a walking robot).
    pub walked_m: Option<f64>,
    /// The claim table's claimed slots when the episode ended (a claim
    /// table whose occupancy the driver can see).
    pub claimed_slots: Option<u32>,
}

impl RunProtocol {
    /// A run of `seconds` learning time on a robot with a control period of
    /// `period_us`.
    pub fn new(seconds: f64, period_us: u32) -> Self {
        let period_s = period_us as f64 * 1e-6;
        RunProtocol {
            phase: Phase::FirstTest,
            period_s,
            budget_steps: (seconds / period_s).round() as u64,
            learning_steps: 0,
            learning_episodes: 0,
            learning_falls: 0,
            test_steps: 0,
            curve: Vec::new(),
        }
    }

    /// The commands that start a run, in order.
    pub fn start(policy: PolicyKind) -> [ToChip; 2] {
        [ToChip::SetPolicy(policy), ToChip::Start(RunMode::Testing)]
    }

    /// Takes the episode the board reported; returns the command to send
    /// now, if any.
    pub fn on_episode(&mut self, e: &Episode, outcome: EpisodeOutcome) -> Option<ToChip> {
        match e.mode {
            RunMode::Learning => {
                self.learning_steps += e.length as u64;
                self.learning_episodes += 1;
                self.learning_falls += outcome.fell as u64;
            }
            RunMode::Testing => {
                self.test_steps += e.length as u64;
                self.curve.push(TestPoint {
                    learning_time_s: self.learning_time_s(),
                    learning_episodes: self.learning_episodes,
                    test_return: e.total_reward as f64,
                    walked_m: outcome.walked_m,
                    fell: outcome.fell,
                    duration_s: e.length as f64 * self.period_s,
                    claimed_slots: outcome.claimed_slots,
                })
            }
        }
        let (next, command) = match (self.phase, e.mode) {
            (Phase::FirstTest, RunMode::Testing) => (Phase::Learning, Some(ToChip::Start(RunMode::Learning))),
            (Phase::Learning, RunMode::Learning) if self.learning_steps >= self.budget_steps => {
                (Phase::FinalTest, Some(ToChip::Start(RunMode::Testing)))
            }
            (Phase::FinalTest, RunMode::Testing) => (Phase::Done, None),
            (phase, _) => (phase, None),
        };
        self.phase = next;
        command
    }

    /// Where the run is.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The run is over.
    pub fn done(&self) -> bool {
        self.phase == Phase::Done
    }

    /// Learning steps so far.
    pub fn learning_steps(&self) -> u64 {
        self.learning_steps
    }

    /// Learning episodes so far.
    pub fn learning_episodes(&self) -> u32 {
        self.learning_episodes
    }

    /// Learning time so far: learning episodes' steps × period \[s\].
    pub fn learning_time_s(&self) -> f64 {
        self.learning_steps as f64 * self.period_s
    }

    /// The learning time asked for, in steps.
    pub fn budget_steps(&self) -> u64 {
        self.budget_steps
    }

    /// The learning curve: every test episode so far.
    pub fn curve(&self) -> &[TestPoint] {
        &self.curve
    }

    /// The learning curve, taken.
    pub fn into_curve(self) -> Vec<TestPoint> {
        self.curve
    }

    /// What the run counted, with the driver's `trial`, `seed`, learner's
    /// `stats`, claim `table` and wear `governor`; and the learning curve.
    pub fn into_counts(
        self,
        trial: u32,
        seed: u64,
        stats: AgentStats,
        table: Option<Occupancy>,
        governor: Option<GovernorTrial>,
    ) -> (TrialCounts, Vec<TestPoint>) {
        let counts = TrialCounts {
            trial,
            seed,
            learning_steps: self.learning_steps,
            test_steps: self.test_steps,
            learning_falls: self.learning_falls,
            learning_episodes: self.learning_episodes,
            stats,
            table,
            governor,
        };
        (counts, self.curve)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn episode(mode: RunMode, length: u32) -> Episode {
        Episode { index: 0, mode, total_reward: -1.0, length, weights_checksum: 0 }
    }

    #[test]
    fn first_test_learning_until_the_budget_then_a_final_test() {
        let none = EpisodeOutcome { fell: false, walked_m: None, claimed_slots: None };
        // 1 s at 30 ms: a budget of 33 steps.
        let mut p = RunProtocol::new(1.0, 30_000);
        assert_eq!(p.budget_steps(), 33);
        assert_eq!(p.on_episode(&episode(RunMode::Testing, 10), none), Some(ToChip::Start(RunMode::Learning)));
        assert_eq!(p.on_episode(&episode(RunMode::Learning, 20), none), None);
        // The board's own test episode changes nothing.
        assert_eq!(p.on_episode(&episode(RunMode::Testing, 10), none), None);
        assert_eq!(p.phase(), Phase::Learning);
        assert_eq!(p.on_episode(&episode(RunMode::Learning, 13), none), Some(ToChip::Start(RunMode::Testing)));
        assert!((p.learning_time_s() - 0.99).abs() < 1e-12);
        let fell = EpisodeOutcome { fell: true, walked_m: Some(0.5), claimed_slots: None };
        assert_eq!(p.on_episode(&episode(RunMode::Testing, 5), fell), None);
        assert!(p.done());
        let curve = p.into_curve();
        assert_eq!(curve.len(), 3);
        assert_eq!((curve[1].learning_time_s, curve[1].learning_episodes), (20.0 * (30_000.0 * 1e-6), 1));
        assert_eq!((curve[2].fell, curve[2].walked_m, curve[2].duration_s), (true, Some(0.5), 5.0 * (30_000.0 * 1e-6)));
    }

    #[test]
    fn the_counts_are_the_test_episodes_steps_and_the_learning_falls() {
        let (none, fell) = (
            EpisodeOutcome { fell: false, walked_m: None, claimed_slots: None },
            EpisodeOutcome { fell: true, walked_m: None, claimed_slots: None },
        );
        let mut p = RunProtocol::new(1.0, 30_000);
        for (mode, length, outcome) in [
            (RunMode::Testing, 10, fell),
            (RunMode::Learning, 20, fell),
            (RunMode::Learning, 5, none),
            (RunMode::Learning, 9, fell),
            (RunMode::Testing, 4, none),
        ] {
            p.on_episode(&episode(mode, length), outcome);
        }
        assert!(p.done());
        let (counts, curve) = p.into_counts(3, 77, AgentStats::default(), None, None);
        assert_eq!((counts.trial, counts.seed), (3, 77));
        assert_eq!((counts.learning_steps, counts.learning_episodes, counts.learning_falls), (34, 3, 2));
        assert_eq!(counts.test_steps, 14);
        assert_eq!(curve.len(), 2);
    }
}
