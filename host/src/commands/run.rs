//! `pada run`: trials of one algorithm on one task, with a progress bar,
//! `summary.json`, `trials.csv` and per-trial learning curves.

use crate::console::outln;
use crate::algo::{label, policy_kind, Algo};
use crate::cli::{check_seconds, set_threads, RunArgs};
use crate::error::{usage, CliError};
use crate::experiment::{build_agent, run_trials, run_trials_observed, RunConfig};
use crate::output::OutDir;
use crate::progress::steps_bar;
use crate::summary::{run_files, RunSummary};
use crate::task::Task;
use crate::tasks::{visit_task, TaskVisitor};
use crate::telemetry::{parse_target, TelemetrySink};
use pada_core::wire::{self, ToHost};
use std::path::PathBuf;
use std::time::Instant;

/// Runs `pada run`.
pub fn run(args: RunArgs) -> Result<(), CliError> {
    visit_task(args.task, RunVisitor(args))
}

struct RunVisitor(RunArgs);

impl TaskVisitor for RunVisitor {
    type Output = Result<(), CliError>;

    fn visit<T: Task>(self, task: &T) -> Self::Output {
        let args = self.0;
        let spec = task.spec();
        let policy = policy_kind(args.algo, args.alpha, args.delta).map_err(|e| usage(e.0))?;
        let seconds = check_seconds("--seconds", args.seconds.unwrap_or(spec.default_seconds))?;
        if let Some(s) = args.switch_at {
            if !matches!(args.algo, Algo::LowPass | Algo::Pada) {
                return Err(usage(format!(
                    "--switch-at applies only to lowpass and pada (Section VIII), not to {}",
                    args.algo
                )));
            }
            if !(s.is_finite() && s >= 0.0 && s <= seconds) {
                return Err(usage(format!(
                    "--switch-at {s} is out of range: valid is 0 <= switch-at <= seconds ({seconds})"
                )));
            }
        }
        let cfg = RunConfig {
            policy,
            switch_at_s: args.switch_at,
            seconds,
            trials: args.trials.unwrap_or(spec.default_trials),
            seed: args.trial.seed,
        };
        let out_path = args
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("pada-out/run-{}-{}", spec.name, args.algo)));
        let out = OutDir::check(&out_path)?;
        let mut telemetry = match &args.telemetry {
            Some(t) => Some(TelemetrySink::open(&parse_target(t)?)?),
            None => None,
        };
        set_threads(args.trial.threads)?;

        let total = cfg.trials as u64
            * cfg.expected_steps(
                spec.control_period_s,
                spec.episode_steps,
                spec.test_interval,
            );
        let bar = steps_bar(total, &format!("{} {}", spec.name, label(&policy)));
        let start = Instant::now();
        let results = if telemetry.is_none() && args.save_weights.is_none() {
            run_trials(task, &cfg, &|n| bar.inc(n))?
        } else {
            let weight_count = build_agent(spec, policy)?.weights().len() as u32;
            let mut observer = telemetry.as_mut().map(|sink| {
                sink.send(&ToHost::Hello(wire::Hello {
                    protocol: wire::PROTOCOL_VERSION,
                    // 0: a host run, not a firmware configuration.
                    config_hash: 0,
                    weight_count,
                    period_us: (spec.control_period_s * 1e6).round() as u32,
                    state_dims: spec.state.len() as u8,
                    joints: spec.motor.dims() as u8,
                }));
                move |msg: ToHost| sink.send(&msg)
            });
            let (results, agent, switched) = run_trials_observed(
                task,
                &cfg,
                &|n| bar.inc(n),
                observer
                    .as_mut()
                    .map(|o| o as &mut (dyn FnMut(ToHost) + Send)),
            )?;
            if let Some(path) = &args.save_weights {
                crate::weights::save(path, spec, cfg.policy, switched, &agent)?;
            }
            results
        };
        let wall = start.elapsed().as_secs_f64();
        bar.finish_and_clear();

        let summary = RunSummary::new(spec, &cfg, &results, wall);
        out.write_all(&run_files(&summary)?)?;
        if let Some(sink) = telemetry {
            let totals = sink.finish()?;
            if !args.json {
                outln!(
                    "telemetry: trial 0, {} frames ({} bytes) to {}",
                    totals.frames, totals.bytes, totals.target
                )?;
            }
        }
        if args.json {
            outln!("{}", summary.to_json())?;
        } else {
            print_summary(&summary, &label(&policy))?;
            outln!("wrote {}", out.path().display())?;
        }
        Ok(())
    }
}

/// A short human-readable summary.
pub fn print_summary(s: &RunSummary, label: &str) -> Result<(), CliError> {
    outln!(
        "{}, {}: {} trials of {} s learning (seed {})",
        s.task, label, s.trials, s.parameters.seconds, s.parameters.seed
    )?;
    outln!(
        "  end performance      {}",
        fmt_estimate(s.end_performance.mean, s.end_performance.ci95, 1, "")
    )?;
    outln!(
        "  rise time            {}",
        fmt_estimate(s.rise_time_s.mean, s.rise_time_s.ci95, 0, " s")
    )?;
    outln!(
        "  MTBF (1200 actions)  {}",
        fmt_mtbf(s.mtbf_s.mean, s.mtbf_s.ci95)
    )?;
    if let (Some(w), Some(v)) = (&s.end_walked_m, &s.end_speed_m_s) {
        outln!(
            "  walked (last 10%)    {}",
            fmt_estimate(w.mean, w.ci95, 2, " m")
        )?;
        outln!(
            "  speed (last 10%)     {}",
            fmt_estimate(v.mean, v.ci95, 3, " m/s")
        )?;
    }
    outln!(
        "  falls                {:.1} learning, {:.1} test runs per trial",
        s.learning_falls.mean, s.test_falls.mean
    )?;
    outln!(
        "  wall {:.1} s, {:.0} env steps/s on {} threads",
        s.wall_s, s.env_steps_per_s, s.threads
    )?;
    Ok(())
}

/// `mean ± ci` with `digits` decimals, `n/a` for a missing interval.
pub fn fmt_estimate(mean: f64, ci: f64, digits: usize, unit: &str) -> String {
    if !mean.is_finite() {
        return format!("{mean}{unit}");
    }
    if ci.is_finite() {
        format!("{mean:.digits$} ± {ci:.digits$}{unit}")
    } else {
        format!("{mean:.digits$}{unit} (no interval)")
    }
}

/// An MTBF in seconds: plain below 10⁶ s, scientific above.
pub fn fmt_mtbf(mean: f64, ci: f64) -> String {
    if !mean.is_finite() {
        return "infinite (no re-engagement in the window)".to_string();
    }
    let ci_s = |c: f64| if c.is_finite() { c } else { f64::NAN };
    if mean.abs() >= 1e6 {
        format!("{:.3e} ± {:.2e} s", mean, ci_s(ci))
    } else {
        format!("{:.0} ± {:.0} s", mean, ci_s(ci))
    }
}
