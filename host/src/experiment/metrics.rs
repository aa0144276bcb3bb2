//! The two learning-performance measures of Section VI, on one trial's
//! learning curve (test-run returns in order).

/// End performance (Section VI): the mean return of the last 10% of the
/// test runs, at least one run (`⌈n/10⌉` runs). `None` for no test run.
pub fn end_performance(returns: &[f64]) -> Option<f64> {
    if returns.is_empty() {
        return None;
    }
    let k = returns.len().div_ceil(10);
    let tail = &returns[returns.len() - k..];
    Some(tail.iter().sum::<f64>() / k as f64)
}

/// Rise time (Section VI): the learning time of the first test run whose
/// return has covered 95% of the way from the first test run to the end
/// performance, `(R_k − R_0) ≥ 0.95·(end − R_0)` (with the inequality
/// reversed when performance fell). `times[k]` is the learning time of test
/// run `k`. Always defined when the curve is: the end performance is a mean
/// of the last runs, so one of them reaches it.
pub fn rise_time(times: &[f64], returns: &[f64]) -> Option<f64> {
    let end = end_performance(returns)?;
    let first = returns[0];
    let target = first + 0.95 * (end - first);
    let reached = |r: f64| {
        if end >= first {
            r >= target
        } else {
            r <= target
        }
    };
    returns.iter().position(|&r| reached(r)).map(|k| times[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn end_performance_is_the_mean_of_the_last_tenth() {
        let r: Vec<f64> = (0..100).map(|i| i as f64).collect();
        // Last 10: 90..99, mean 94.5.
        assert_eq!(end_performance(&r), Some(94.5));
        // 101 runs: the last 11 (⌈10.1⌉), 90..100, mean 95.
        let r: Vec<f64> = (0..101).map(|i| i as f64).collect();
        assert_eq!(end_performance(&r), Some(95.0));
        assert_eq!(end_performance(&[3.0]), Some(3.0));
        assert_eq!(end_performance(&[]), None);
    }

    #[test]
    fn rise_time_on_a_synthetic_exponential_curve() {
        // R(t) = −3000 + 2200·(1 − e^(−t/τ)), τ = 200 s, sampled every 30 s
        // to t = 6000 s. The end is ≈ −800 and 95% of the rise is reached at
        // t = τ·ln 20 ≈ 599 s, so the first test at or after it is 600 s.
        let tau = 200.0;
        let times: Vec<f64> = (0..=200).map(|k| k as f64 * 30.0).collect();
        let returns: Vec<f64> = times
            .iter()
            .map(|t| -3000.0 + 2200.0 * (1.0 - (-t / tau).exp()))
            .collect();
        let end = end_performance(&returns).unwrap();
        assert!((end + 800.0).abs() < 1e-6, "{end}");
        assert_eq!(rise_time(&times, &returns), Some(600.0));
    }

    #[test]
    fn rise_time_takes_the_first_crossing_and_handles_decline() {
        let times = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0];
        // A spike at 20 s crosses before the plateau: the first crossing counts.
        let r = [
            -100.0, -90.0, -5.0, -50.0, -20.0, -10.0, -10.0, -10.0, -10.0, -10.0,
        ];
        assert_eq!(rise_time(&times, &r), Some(20.0));
        // A falling curve: 95% of the fall from 0 to −100 is −95.
        let r = [
            0.0, -50.0, -94.0, -96.0, -100.0, -100.0, -100.0, -100.0, -100.0, -100.0,
        ];
        assert_eq!(rise_time(&times, &r), Some(30.0));
        // Flat: reached at once.
        assert_eq!(rise_time(&times, &[-5.0; 10]), Some(0.0));
        assert_eq!(rise_time(&[], &[]), None);
    }
}
