//! How long a run took and on how many workers: `timing.json`.
//!
//! Wall time and thread counts change from run to run and from machine to
//! machine, so they are kept out of `pada paper`'s report.md and
//! summary.json: those depend only on the command and its seed, and a run
//! merged from a cluster's results gives the same bytes as a local run.
//! The timing goes here instead (and to the terminal).

use crate::plan::result::TrialTiming;
use serde::Serialize;

/// The timing of a whole run.
#[derive(Debug, Clone, Serialize)]
pub struct RunTiming {
    /// Where the trials ran: `local` (this process), `merge` (results of a
    /// plan run elsewhere) or `slurm` (a job array this process submitted).
    pub how: &'static str,
    /// Wall-clock time \[s\]: local, of the trials; slurm, from the first
    /// submission to the last result; merge, from the first trial's start
    /// to the last trial's end.
    pub wall_s: f64,
    /// Local: worker threads. From a plan: the most trials that ran at once
    /// (from their start and end times).
    pub threads: usize,
    /// Environment steps of all trials.
    pub env_steps: u64,
    /// Environment steps per wall-clock second.
    pub env_steps_per_s: f64,
    /// Wall time per trial, when the trials were timed one by one (plans).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trials: Option<TrialTimes>,
    /// The Slurm jobs of a `--slurm` run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slurm: Option<SlurmReport>,
}

/// Wall time per trial.
#[derive(Debug, Clone, Serialize)]
pub struct TrialTimes {
    /// Trials timed.
    pub count: usize,
    /// Mean wall time of a trial \[s\].
    pub mean_s: f64,
    /// Shortest \[s\].
    pub min_s: f64,
    /// Longest \[s\].
    pub max_s: f64,
    /// Sum over trials \[s\] (the CPU time a cluster spends on the run).
    pub total_s: f64,
    /// Per configuration: label, trials, mean and longest wall time.
    pub per_configuration: Vec<ConfigurationTimes>,
}

/// Wall time per trial of one configuration.
#[derive(Debug, Clone, Serialize)]
pub struct ConfigurationTimes {
    /// The configuration's label.
    pub label: String,
    /// Trials timed.
    pub trials: usize,
    /// Mean wall time of a trial \[s\].
    pub mean_s: f64,
    /// Longest \[s\].
    pub max_s: f64,
}

/// What a `--slurm` run submitted.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SlurmReport {
    /// Job ids, in submission order.
    pub jobs: Vec<String>,
    /// Trials whose results already verified before submitting.
    pub already_done: usize,
    /// Trials submitted again after their array task left no verified
    /// result (cancelled, failed, timed out).
    pub resubmitted: Vec<u32>,
}

impl RunTiming {
    /// A run of this process's thread pool.
    pub fn local(wall_s: f64, env_steps: u64) -> RunTiming {
        RunTiming {
            how: "local",
            wall_s,
            threads: rayon::current_num_threads(),
            env_steps,
            env_steps_per_s: rate(env_steps, wall_s),
            trials: None,
            slurm: None,
        }
    }

    /// A run of a plan's trials, from their timings (`(configuration,
    /// timing)` pairs) and the configurations' labels. `wall_s` is the
    /// measured wall time, or `None` for the span of the trials.
    pub fn of_trials(
        how: &'static str,
        wall_s: Option<f64>,
        env_steps: u64,
        timings: &[(usize, TrialTiming)],
        labels: &[String],
    ) -> RunTiming {
        let wall_s = wall_s.unwrap_or_else(|| span_s(timings.iter().map(|(_, t)| t)));
        RunTiming {
            how,
            wall_s,
            threads: peak_concurrency(timings.iter().map(|(_, t)| t)),
            env_steps,
            env_steps_per_s: rate(env_steps, wall_s),
            trials: Some(trial_times(timings, labels)),
            slurm: None,
        }
    }

    /// `2 threads` (local) or `at most 2 trials at once (slurm)`.
    pub fn workers(&self) -> String {
        if self.how == "local" {
            format!("{} threads", self.threads)
        } else {
            format!("at most {} trials at once ({})", self.threads, self.how)
        }
    }

    /// `timing.json`'s bytes.
    pub fn to_json(&self) -> Vec<u8> {
        (serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
            + "\n")
            .into_bytes()
    }
}

fn rate(steps: u64, wall_s: f64) -> f64 {
    if wall_s > 0.0 {
        steps as f64 / wall_s
    } else {
        f64::NAN
    }
}

/// From the first start to the last end \[s\] (0 without trials).
pub fn span_s<'a>(timings: impl Iterator<Item = &'a TrialTiming> + Clone) -> f64 {
    let start = timings
        .clone()
        .map(|t| t.started_unix_s)
        .fold(f64::INFINITY, f64::min);
    let end = timings
        .map(TrialTiming::finished_unix_s)
        .fold(f64::NEG_INFINITY, f64::max);
    if end >= start {
        end - start
    } else {
        0.0
    }
}

/// The most trials running at the same instant.
pub fn peak_concurrency<'a>(timings: impl Iterator<Item = &'a TrialTiming>) -> usize {
    // +1 at each start, −1 at each end; an end sorts before a start at the
    // same instant (a trial that ends as another begins does not overlap it).
    let mut events: Vec<(f64, i32)> = timings
        .flat_map(|t| [(t.started_unix_s, 1), (t.finished_unix_s(), -1)])
        .collect();
    events.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let (mut now, mut peak) = (0i32, 0i32);
    for (_, d) in events {
        now += d;
        peak = peak.max(now);
    }
    peak as usize
}

fn trial_times(timings: &[(usize, TrialTiming)], labels: &[String]) -> TrialTimes {
    let walls: Vec<f64> = timings.iter().map(|(_, t)| t.wall_s).collect();
    let total: f64 = walls.iter().sum();
    let per_configuration = labels
        .iter()
        .enumerate()
        .filter_map(|(c, label)| {
            let w: Vec<f64> = timings
                .iter()
                .filter(|(k, _)| *k == c)
                .map(|(_, t)| t.wall_s)
                .collect();
            (!w.is_empty()).then(|| ConfigurationTimes {
                label: label.clone(),
                trials: w.len(),
                mean_s: w.iter().sum::<f64>() / w.len() as f64,
                max_s: w.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            })
        })
        .collect();
    TrialTimes {
        count: walls.len(),
        mean_s: if walls.is_empty() {
            f64::NAN
        } else {
            total / walls.len() as f64
        },
        min_s: walls.iter().copied().fold(f64::INFINITY, f64::min),
        max_s: walls.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        total_s: total,
        per_configuration,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(start: f64, wall: f64) -> TrialTiming {
        TrialTiming {
            started_unix_s: start,
            wall_s: wall,
            host: "h".into(),
            slurm_task: None,
        }
    }

    #[test]
    fn concurrency_and_span_of_trials() {
        // Two workers: [0,2) [0,1) [1,3) [2,3): never more than two at once.
        let ts = [t(0.0, 2.0), t(0.0, 1.0), t(1.0, 2.0), t(2.0, 1.0)];
        assert_eq!(peak_concurrency(ts.iter()), 2);
        assert_eq!(span_s(ts.iter()), 3.0);
        assert_eq!(
            peak_concurrency([t(0.0, 5.0), t(1.0, 1.0), t(1.5, 1.0)].iter()),
            3
        );
        assert_eq!(peak_concurrency([].iter()), 0);
        assert_eq!(span_s([].iter()), 0.0);
    }

    #[test]
    fn times_per_configuration() {
        let ts = vec![(0, t(0.0, 1.0)), (0, t(0.0, 3.0)), (1, t(1.0, 4.0))];
        let r = RunTiming::of_trials(
            "merge",
            None,
            100,
            &ts,
            &["a".into(), "b".into(), "c".into()],
        );
        assert_eq!(r.wall_s, 5.0);
        assert_eq!(r.env_steps_per_s, 20.0);
        let times = r.trials.unwrap();
        assert_eq!(times.count, 3);
        assert_eq!(times.total_s, 8.0);
        assert_eq!(times.per_configuration.len(), 2, "c has no trials");
        assert_eq!(times.per_configuration[0].mean_s, 2.0);
        assert_eq!(times.per_configuration[1].max_s, 4.0);
    }
}
