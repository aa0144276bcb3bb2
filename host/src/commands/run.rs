//! `pada run`: trials of one algorithm on one task, with a progress bar,
//! `summary.json`, `trials.csv` and per-trial learning curves.

use crate::cli::{check_seconds, set_threads, RunArgs};
use crate::display::{fmt_estimate, fmt_mtbf};
use crate::error::{usage, CliError};
use crate::experiment::algo::{label, parameter_of, policy_kind, Algo};
use crate::experiment::task::Task;
use crate::experiment::tasks::{visit_task, TaskVisitor};
use crate::experiment::{build_agent, run_trials, run_trials_observed, RunConfig, TrialResult};
use crate::output::OutDir;
use crate::plan::mode::{obtain, Mode, Trials};
use crate::plan::{Experiment, ExperimentKind};
use crate::progress::steps_bar;
use crate::summary::{run_files, RunSummary};
use crate::telemetry::{parse_target, TelemetrySink};
use pada_core::wire::{self, ToHost};
use std::path::PathBuf;

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
            if !matches!(args.algo, Algo::Lowpass | Algo::Pada) {
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
        let mode = args.cluster.mode(out.path())?;
        if mode != Mode::Local && (args.telemetry.is_some() || args.save_weights.is_some()) {
            return Err(usage(
                "--telemetry and --save-weights need the trials in this process: they do not combine with --plan, --merge or --slurm",
            ));
        }
        let mut telemetry = match &args.telemetry {
            Some(t) => Some(TelemetrySink::open(&parse_target(t)?)?),
            None => None,
        };
        set_threads(args.trial.threads)?;

        let experiment = Experiment::new(
            ExperimentKind::Run,
            command_line(&args, &cfg),
            &[(args.task, cfg)],
        );
        let local = || -> anyhow::Result<Vec<Vec<TrialResult>>> {
            let total = cfg.trials as u64
                * cfg.expected_steps(
                    spec.control_period_s,
                    spec.episode_steps,
                    spec.test_interval,
                );
            let bar = steps_bar(total, &format!("{} {}", spec.name, label(&policy)));
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
            bar.finish_and_clear();
            Ok(vec![results])
        };
        let (mut per_config, timing) = match obtain(&mode, &experiment, args.json, local)? {
            Trials::PlanWritten => return Ok(()),
            Trials::Results(r, t) => (r, t),
        };
        let results = per_config.pop().unwrap_or_default();

        let mut summary = RunSummary::new(spec, &cfg, &results, timing.wall_s);
        // From a plan: the most trials that ran at once, not this process's
        // thread pool.
        summary.threads = timing.threads;
        let mut files = run_files(&summary)?;
        if mode != Mode::Local {
            files.push(("timing.json".to_string(), timing.to_json()));
        }
        out.write_all(&files)?;
        if let Some(sink) = telemetry {
            let totals = sink.finish()?;
            if !args.json {
                println!(
                    "telemetry: trial 0, {} frames ({} bytes) to {}",
                    totals.frames, totals.bytes, totals.target
                );
            }
        }
        if args.json {
            println!("{}", summary.to_json());
        } else {
            print_summary(&summary, &label(&policy));
            println!("wrote {}", out.path().display());
        }
        Ok(())
    }
}

/// The command line that describes a run, with every value explicit (a
/// plan's identity, and the merge command it prints).
fn command_line(args: &RunArgs, cfg: &RunConfig) -> String {
    let mut c = format!("pada run --task {} --algo {}", args.task, args.algo);
    match parameter_of(&cfg.policy) {
        Some(a) if args.algo.takes_alpha() => c += &format!(" --alpha {a}"),
        Some(d) => c += &format!(" --delta {d}"),
        None => {}
    }
    if let Some(s) = cfg.switch_at_s {
        c += &format!(" --switch-at {s}");
    }
    c + &format!(
        " --trials {} --seconds {} --seed {}",
        cfg.trials, cfg.seconds, cfg.seed
    )
}

/// A short human-readable summary.
pub fn print_summary(s: &RunSummary, label: &str) {
    println!(
        "{}, {}: {} trials of {} s learning (seed {})",
        s.task, label, s.trials, s.parameters.seconds, s.parameters.seed
    );
    println!(
        "  end performance      {}",
        fmt_estimate(s.end_performance.mean, s.end_performance.ci95, 1, "")
    );
    println!(
        "  rise time            {}",
        fmt_estimate(s.rise_time_s.mean, s.rise_time_s.ci95, 0, " s")
    );
    println!(
        "  MTBF (1200 actions)  {}",
        fmt_mtbf(s.mtbf_s.mean, s.mtbf_s.ci95)
    );
    if let (Some(w), Some(v)) = (&s.end_walked_m, &s.end_speed_m_s) {
        println!(
            "  walked (last 10%)    {}",
            fmt_estimate(w.mean, w.ci95, 2, " m")
        );
        println!(
            "  speed (last 10%)     {}",
            fmt_estimate(v.mean, v.ci95, 3, " m/s")
        );
    }
    println!(
        "  falls                {:.1} learning, {:.1} test runs per trial",
        s.learning_falls.mean, s.test_falls.mean
    );
    println!(
        "  wall {:.1} s, {:.0} env steps/s on {} threads",
        s.wall_s, s.env_steps_per_s, s.threads
    );
}
