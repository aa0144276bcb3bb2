//! Mean learning curves over a configuration's trials, for the figures
//! and the curves' CSV.
//!
//! - [`mean_curve`] pairs the trials' test runs by their index. On the
//!   pendulum every learning episode has the same length, so the k-th test
//!   run of every trial comes at the same learning time.
//! - [`binned_curve`] pairs them by learning time. On LEO an episode ends
//!   at a fall, so a trial that walks has longer episodes and fewer test
//!   runs than one that falls; pairing by index would stop the mean at the
//!   shortest trial's last test run (half the trial length for a walking
//!   configuration) and mix early and late test runs.

use crate::experiment::trial::TestPoint;
use crate::experiment::TrialResult;
use crate::stats::Estimate;
use serde::Serialize;

/// One point of a mean learning curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Mean learning time of the test run \[s\].
    pub learning_time_s: f64,
    /// Mean test return over trials.
    pub mean: f64,
    /// 95% half-width over trials.
    pub ci95: f64,
}

/// The mean learning curve over trials, test run by test run (up to the
/// shortest trial's curve).
pub fn mean_curve(results: &[TrialResult]) -> Vec<CurvePoint> {
    let len = results.iter().map(|r| r.curve.len()).min().unwrap_or(0);
    (0..len)
        .map(|k| {
            let returns: Vec<f64> = results.iter().map(|r| r.curve[k].test_return).collect();
            let e = Estimate::of(&returns);
            let t = results
                .iter()
                .map(|r| r.curve[k].learning_time_s)
                .sum::<f64>()
                / results.len() as f64;
            CurvePoint {
                learning_time_s: t,
                mean: e.mean,
                ci95: e.ci95,
            }
        })
        .collect()
}

/// The mean learning curve over trials in bins of `bin_s` seconds of
/// learning time, from 0 to `seconds`, drawn at each bin's centre.
///
/// A trial's value in a bin is the mean return of its test runs in that
/// bin; in a bin without a test run of its own it keeps its last test
/// run's return (a greedy policy is the same until the next test shows
/// otherwise), and before its first test run it has no value. `bin_s`
/// should be at least the longest gap between two test runs (for LEO, 10
/// learning episodes of at most 25 s), so that a held value spans at most
/// one bin. Bins in which no trial has a value are left out.
pub fn binned_curve(results: &[TrialResult], seconds: f64, bin_s: f64) -> Vec<CurvePoint> {
    let curves: Vec<&[TestPoint]> = results.iter().map(|r| r.curve.as_slice()).collect();
    binned(&curves, seconds, bin_s)
}

fn binned(results: &[&[TestPoint]], seconds: f64, bin_s: f64) -> Vec<CurvePoint> {
    if !(bin_s > 0.0 && seconds > 0.0) {
        return Vec::new();
    }
    let bins = (seconds / bin_s).ceil() as usize;
    let mut held: Vec<Option<f64>> = vec![None; results.len()];
    let mut next: Vec<usize> = vec![0; results.len()];
    let mut out = Vec::with_capacity(bins);
    for b in 0..bins {
        let end = ((b + 1) as f64 * bin_s).min(seconds);
        let mut values = Vec::with_capacity(results.len());
        for (i, r) in results.iter().enumerate() {
            let (mut sum, mut n) = (0.0, 0usize);
            while let Some(p) = r.get(next[i]) {
                // The last bin also takes a test run at exactly `seconds`.
                if p.learning_time_s >= end && !(b + 1 == bins && p.learning_time_s <= seconds) {
                    break;
                }
                sum += p.test_return;
                n += 1;
                next[i] += 1;
            }
            if n > 0 {
                held[i] = Some(sum / n as f64);
            }
            if let Some(v) = held[i] {
                values.push(v);
            }
        }
        if values.is_empty() {
            continue;
        }
        let e = Estimate::of(&values);
        out.push(CurvePoint {
            learning_time_s: (b as f64 * bin_s + end) / 2.0,
            mean: e.mean,
            ci95: e.ci95,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trial(points: &[(f64, f64)]) -> Vec<TestPoint> {
        points
            .iter()
            .map(|&(t, ret)| TestPoint {
                learning_time_s: t,
                learning_episodes: 0,
                test_return: ret,
                walked_m: None,
                fell: false,
                duration_s: 0.0,
                claimed_slots: None,
            })
            .collect()
    }

    fn binned_curve(trials: &[Vec<TestPoint>], seconds: f64, bin_s: f64) -> Vec<CurvePoint> {
        let curves: Vec<&[TestPoint]> = trials.iter().map(Vec::as_slice).collect();
        binned(&curves, seconds, bin_s)
    }

    #[test]
    fn a_binned_curve_spans_the_whole_trial_when_trials_have_unequal_test_counts() {
        // Trial a tests often, trial b (long episodes) rarely.
        let a = trial(&[(10.0, 1.0), (60.0, 2.0), (110.0, 3.0), (160.0, 4.0), (210.0, 5.0)]);
        let b = trial(&[(40.0, 10.0), (240.0, 30.0)]);
        let binned = binned_curve(&[a, b], 250.0, 100.0);
        assert_eq!(binned.len(), 3, "bins 0-100, 100-200, 200-250");
        assert_eq!(binned[0].learning_time_s, 50.0);
        assert_eq!(binned[2].learning_time_s, 225.0);
        // Bin 0: a's mean of 1 and 2, b's 10.
        assert!((binned[0].mean - (1.5 + 10.0) / 2.0).abs() < 1e-12);
        // Bin 1: a's 3.5, b holds its 10.
        assert!((binned[1].mean - (3.5 + 10.0) / 2.0).abs() < 1e-12);
        // Bin 2: a's 5, b's 30.
        assert!((binned[2].mean - (5.0 + 30.0) / 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_trial_counts_only_from_its_first_test_run() {
        let a = trial(&[(10.0, 1.0)]);
        let b = trial(&[(150.0, 7.0)]);
        let binned = binned_curve(&[a, b], 200.0, 100.0);
        assert_eq!(binned.len(), 2);
        assert_eq!(binned[0].mean, 1.0);
        assert!(binned[0].ci95.is_nan(), "one trial has no interval");
        assert!((binned[1].mean - 4.0).abs() < 1e-12);
    }

    #[test]
    fn a_test_run_at_the_very_end_lands_in_the_last_bin() {
        let a = trial(&[(50.0, 1.0), (200.0, 9.0)]);
        let binned = binned_curve(&[a], 200.0, 100.0);
        assert_eq!(binned.len(), 2);
        assert_eq!(binned[1].mean, 9.0);
    }

    #[test]
    fn no_bins_for_a_zero_width() {
        assert!(binned_curve(&[trial(&[(1.0, 1.0)])], 10.0, 0.0).is_empty());
    }
}
