//! A trial's result, [`TrialResult`], and how it follows from what the
//! trial counted, the same for every way a trial runs (on the host, on a
//! board's learner, over real servos): the learning curve's measures
//! (Section VI) and the wear of its two fatigue counters.

use super::governed::GovernorTrial;
use super::metrics::{end_performance, rise_time};
use serde::Serialize;
use pada_core::agent::AgentStats;
use pada_core::claim_table::Occupancy;
use pada_core::fatigue::FatigueCounter;

/// One point of a learning curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TestPoint {
    /// Learning time before this test run \[s of simulated time\].
    pub learning_time_s: f64,
    /// Learning episodes before this test run.
    pub learning_episodes: u32,
    /// Sum of the rewards of the greedy test run.
    pub test_return: f64,
    /// Distance walked in the test run \[m\] (walking tasks only).
    pub walked_m: Option<f64>,
    /// Whether the test run ended in an absorbing state (a fall).
    pub fell: bool,
    /// Duration of the test run \[s\].
    pub duration_s: f64,
    /// Slots of the claim table claimed before this test run (claim
    /// tables only: what the learning so far has written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub claimed_slots: Option<u32>,
}

/// Everything measured in one trial.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrialResult {
    /// Trial index within the run.
    pub trial: u32,
    /// The trial's seed (derived from the master seed).
    pub seed: u64,
    /// End performance: mean return of the last 10% of test runs.
    pub end_performance: f64,
    /// Rise time \[s of learning time\].
    pub rise_time_s: f64,
    /// Predicted MTBF from the first 1200 learning actions \[s\], the
    /// paper's definition: torques from the commanded action (infinite when
    /// nothing re-engaged).
    pub mtbf_s: f64,
    /// Backlash re-engagements within those actions (all gearboxes), the
    /// paper's definition.
    pub window_reengagements: u64,
    /// Predicted MTBF over all learning actions of the trial \[s\], the
    /// paper's torques: how the learner wears the gearbox once it knows
    /// more (the window's MTBF is its first minute).
    pub run_mtbf_s: f64,
    /// Predicted MTBF from the first 1200 learning actions \[s\], from the
    /// simulated gear torques.
    pub physical_mtbf_s: f64,
    /// Re-engagements of the simulated gear torques within those actions.
    pub physical_window_reengagements: u64,
    /// Each counted gearbox's `mtbf_s`, in the robot's counted-joint order
    /// (the robot's is the smallest); empty where not measured (results
    /// stored by a plan).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub joint_mtbf_s: Vec<f64>,
    /// Each counted gearbox's `physical_mtbf_s`, as `joint_mtbf_s`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub physical_joint_mtbf_s: Vec<f64>,
    /// Learning steps taken.
    pub learning_steps: u64,
    /// Test-run steps taken.
    pub test_steps: u64,
    /// Learning episodes that ended in an absorbing state (falls).
    pub learning_falls: u64,
    /// Learning episodes.
    pub learning_episodes: u32,
    /// Test runs that ended in an absorbing state (falls).
    pub test_falls: u32,
    /// Mean distance walked in the last 10% of the test runs \[m\]
    /// (walking tasks only).
    pub end_walked_m: Option<f64>,
    /// Mean speed of the last 10% of the test runs, distance over duration
    /// \[m/s\] (walking tasks only).
    pub end_speed_m_s: Option<f64>,
    /// Weight writes that saturated the fixed-point range (should be 0).
    pub saturations: u32,
    /// Trace entries dropped for capacity (should be 0).
    pub trace_drops: u32,
    /// The claim table's occupancy at the end (claim tables only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub table: Option<pada_core::claim_table::Occupancy>,
    /// What the wear governor did, when one ran (`--mtbf-budget`).
    pub governor: Option<GovernorTrial>,
    /// The learning curve.
    #[serde(skip)]
    pub curve: Vec<TestPoint>,
}

/// What a trial counted besides its curve and its wear.
#[derive(Debug, Clone)]
pub struct TrialCounts {
    /// Trial index within the run.
    pub trial: u32,
    /// The trial's seed.
    pub seed: u64,
    /// Learning steps taken.
    pub learning_steps: u64,
    /// Test-run steps taken.
    pub test_steps: u64,
    /// Learning episodes that ended in an absorbing state.
    pub learning_falls: u64,
    /// Learning episodes.
    pub learning_episodes: u32,
    /// The learner's books (saturations, trace drops).
    pub stats: AgentStats,
    /// The claim table's occupancy at the end (claim tables only).
    pub table: Option<Occupancy>,
    /// What the wear governor did, when one ran.
    pub governor: Option<GovernorTrial>,
}

/// The windowed MTBF of each of the first `dims` gearboxes of `counter`
/// \[s\] (`+∞` where nothing re-engaged).
pub fn joint_mtbf_s<const N: usize>(counter: &FatigueCounter<N>, dims: usize) -> Vec<f64> {
    (0..dims.min(N)).map(|j| counter.windowed_mtbf_s(j).unwrap_or(f64::INFINITY)).collect()
}

/// The robot's windowed MTBF of `counter` \[s\] (`+∞` where nothing
/// re-engaged).
pub fn robot_mtbf_s<const N: usize>(counter: &FatigueCounter<N>) -> f64 {
    counter.robot_windowed_mtbf_s().unwrap_or(f64::INFINITY)
}

/// Backlash re-engagements of `counter`'s window, all gearboxes.
fn window_reengagements<const N: usize>(counter: &FatigueCounter<N>) -> u64 {
    counter.joints().iter().filter_map(|j| j.window_reengagements()).sum()
}

impl TrialResult {
    /// The result of a trial that counted `counts` and learned `curve`,
    /// with `paper` counting the paper's torques and `physical` the gear
    /// torques (simulated, or the board's estimate where there is no
    /// simulation) over its first `joints` gearboxes.
    ///
    /// The end's walked distance and speed are the means of the last
    /// tenth of the test runs (at least one) when every one of them
    /// measured a distance; a curve with no test run (a drive stopped
    /// before its first) measures 0 m.
    pub fn measured<const N: usize>(
        counts: TrialCounts,
        curve: Vec<TestPoint>,
        paper: &FatigueCounter<N>,
        physical: &FatigueCounter<N>,
        joints: usize,
    ) -> TrialResult {
        let times: Vec<f64> = curve.iter().map(|p| p.learning_time_s).collect();
        let returns: Vec<f64> = curve.iter().map(|p| p.test_return).collect();
        let tail_n = curve.len().div_ceil(10).max(1);
        let tail = &curve[curve.len().saturating_sub(tail_n)..];
        let walked: Option<f64> = tail.iter().map(|p| p.walked_m).sum();
        TrialResult {
            trial: counts.trial,
            seed: counts.seed,
            end_performance: end_performance(&returns).unwrap_or(f64::NAN),
            rise_time_s: rise_time(&times, &returns).unwrap_or(f64::NAN),
            mtbf_s: robot_mtbf_s(paper),
            window_reengagements: window_reengagements(paper),
            run_mtbf_s: paper.robot_mtbf_s(),
            physical_mtbf_s: robot_mtbf_s(physical),
            physical_window_reengagements: window_reengagements(physical),
            joint_mtbf_s: joint_mtbf_s(paper, joints),
            physical_joint_mtbf_s: joint_mtbf_s(physical, joints),
            learning_steps: counts.learning_steps,
            test_steps: counts.test_steps,
            learning_falls: counts.learning_falls,
            learning_episodes: counts.learning_episodes,
            test_falls: curve.iter().filter(|p| p.fell).count() as u32,
            end_walked_m: walked.map(|w| w / tail_n as f64),
            end_speed_m_s: walked.map(|w| w / tail.iter().map(|p| p.duration_s).sum::<f64>().max(1e-9)),
            saturations: counts.stats.saturations,
            trace_drops: counts.stats.trace_drops,
            table: counts.table,
            governor: counts.governor,
            curve,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::fatigue::GearboxParams;

    fn counts() -> TrialCounts {
        TrialCounts {
            trial: 2,
            seed: 5,
            learning_steps: 100,
            test_steps: 30,
            learning_falls: 1,
            learning_episodes: 4,
            stats: AgentStats { saturations: 3, trace_drops: 4, ..AgentStats::default() },
            table: None,
            governor: None,
        }
    }

    fn point(k: u32, walked_m: Option<f64>) -> TestPoint {
        TestPoint {
            learning_time_s: k as f64,
            learning_episodes: k,
            test_return: k as f64,
            walked_m,
            fell: k % 2 == 1,
            duration_s: 2.0,
            claimed_slots: None,
        }
    }

    #[test]
    fn the_end_is_the_last_tenth_of_the_test_runs_and_an_empty_curve_walked_nothing() {
        let counter = FatigueCounter::<2>::new(GearboxParams::default(), 0.05, Some(1200)).unwrap();
        // 11 test runs: the last tenth is the last two.
        let curve: Vec<TestPoint> = (0..11).map(|k| point(k, Some(k as f64))).collect();
        let r = TrialResult::measured(counts(), curve, &counter, &counter, 2);
        assert_eq!((r.trial, r.seed, r.saturations, r.trace_drops), (2, 5, 3, 4));
        assert_eq!(r.end_performance, 9.5);
        assert_eq!((r.end_walked_m, r.end_speed_m_s), (Some(9.5), Some(19.0 / 4.0)));
        assert_eq!(r.test_falls, 5);
        assert_eq!((r.mtbf_s, r.joint_mtbf_s.len()), (f64::INFINITY, 2));
        // One test run without a distance: no walking measures.
        let mut curve: Vec<TestPoint> = (0..11).map(|k| point(k, Some(1.0))).collect();
        curve[10].walked_m = None;
        let r = TrialResult::measured(counts(), curve, &counter, &counter, 2);
        assert_eq!((r.end_walked_m, r.end_speed_m_s), (None, None));
        // No test run (a drive stopped before its first).
        let r = TrialResult::measured(counts(), Vec::new(), &counter, &counter, 2);
        assert!(r.end_performance.is_nan() && r.rise_time_s.is_nan());
        assert_eq!((r.end_walked_m, r.end_speed_m_s), (Some(0.0), Some(0.0)));
    }
}
