//! `pada run`: trials of one algorithm on one task, with a progress bar,
//! `summary.json`, `trials.csv` and per-trial learning curves.

use crate::console::outln;
use crate::commands::options::{check_seconds, set_threads};
use crate::display::{fmt_estimate, fmt_mtbf};
use crate::error::{usage, CliError};
use crate::experiment::algo::{label, parameter_of, Algo, PolicyFlags};
use crate::board::trial::table_len;
use crate::board::export::{export, ExportReport};
use crate::board::{robot_of_task, run_board_from, BoardStart};
use crate::experiment::task::{Task, TaskSpec};
use crate::experiment::tasks::{visit_task, TaskVisitor};
use crate::summary::{board_files, BoardSummary};
use pada_core::claim_table::WhenFull;
use pada_core::profile::{Board, LearnerProfile, TILINGS};
use pada_core::tile_coding::Layout;
use pada_core::weights::WeightFormat;
use crate::experiment::{build_agent, run_trials, run_trials_observed, RunConfig, StartWith, TrialResult};
use crate::output::OutDir;
use crate::plan::mode::{obtain, Mode, Trials};
use crate::plan::{Experiment, ExperimentKind};
use crate::progress::steps_bar;
use crate::summary::{run_files, RunSummary};
use crate::telemetry::{parse_target, TelemetrySink};
use pada_core::wire::{self, ToHost};
use std::path::PathBuf;
use std::time::Instant;
use crate::commands::options::TrialOptions;
use crate::experiment::tasks::TaskName;
use crate::start_weights::StartWeights;
use clap::Args;

/// `pada run`.
#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// The task.
    #[arg(long, value_enum, default_value_t = TaskName::Pendulum)]
    pub task: TaskName,
    /// A robot of your own instead of a task: its robot.toml (and the URDF
    /// it names), simulated in rapier3d, driven through its servos' models
    /// and its rules (docs/your-robot.md; `pada new-robot` writes one).
    #[arg(long, value_name = "robot.toml", conflicts_with = "task")]
    pub robot: Option<PathBuf>,
    /// The algorithm (Section V, and the gentle explorations epsilon-pada,
    /// ou, pink, action-penalty).
    #[arg(long, value_parser = crate::experiment::algo::algo_parser())]
    pub algo: Algo,
    /// Low-pass α of Eq. 8, 0 < α ≤ 1 (lowpass, markov-lowpass; default 0.834).
    #[arg(long)]
    pub alpha: Option<f32>,
    /// Δ relative to the action range, 0 < Δ ≤ 1 (integrator,
    /// markov-integrator, pada, epsilon-pada; default 0.5).
    #[arg(long)]
    pub delta: Option<f32>,
    /// OU's mean reversion per step, 0 < θ ≤ 1 (ou; default 0.15).
    #[arg(long)]
    pub theta: Option<f32>,
    /// Noise scale, 0 < σ ≤ 4, in units of the largest distance from 0 to a
    /// bound of the action range (ou, default 0.2; pink, default 0.38).
    #[arg(long)]
    pub sigma: Option<f32>,
    /// The action-change penalty per squared full-range change,
    /// 0 < w ≤ 10000 (action-penalty; default 1).
    #[arg(long)]
    pub weight: Option<f32>,
    /// Learn on a wear budget: a governor moves PADA's Δ or the low-pass
    /// filter's α while learning so that the predicted MTBF over the last
    /// 1200 learning actions stays at or above this [s] (pada, lowpass;
    /// 0 < budget <= 1e10; instead of --delta or --alpha).
    #[arg(long, value_name = "SECONDS")]
    pub mtbf_budget: Option<f32>,
    /// Switch back to SARSA(λ) after this much learning time [s]
    /// (lowpass, pada and the gentle explorations; Section VIII).
    #[arg(long, value_name = "SECONDS")]
    pub switch_at: Option<f64>,
    /// Trials (default: the task's: 29 for the pendulum and 28 for the physical one, as the paper; 2 for LEO; 10 for a robot of files).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub trials: Option<u32>,
    /// Learning time per trial [s of simulated time] (default: the task's).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Output directory for summary.json, trials.csv and the learning
    /// curves (default: pada-out/run-<task>-<algo>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Stream trial 0 as the firmware's telemetry frames to FILE or to
    /// tcp:HOST:PORT (loopback only); `pada capture --file` reads them.
    #[arg(long, value_name = "FILE|tcp:HOST:PORT")]
    pub telemetry: Option<String>,
    /// Record trial 0's telemetry as an MCAP file: the channels of `pada
    /// capture --mcap` (every record kind, the robot on /scene), to open
    /// in Foxglove; with or without --telemetry.
    #[arg(long, value_name = "FILE.mcap")]
    pub mcap: Option<PathBuf>,
    /// Save the first trial's learned weights to this file (versioned, with
    /// a checksum; read by `pada render`).
    #[arg(long, value_name = "FILE")]
    pub save_weights: Option<PathBuf>,
    /// Continue from weights saved by `pada run --save-weights`: every
    /// trial starts from them instead of the task's initial weights, and
    /// learns on as a run from nothing would (the same seeds). The file
    /// must be for the same task, table and learner (sarsa, pada, lowpass
    /// and the gentle explorations share one); one that is not is refused
    /// with the first difference. With --board: the weights are exported
    /// into the board's table first (docs/board.md, "Weights from the
    /// host"), and what that changed is printed.
    #[arg(long, value_name = "FILE")]
    pub weights: Option<PathBuf>,
    /// Run a board's own learner instead of the host's: the firmware's
    /// controller built for the host, with the board's learner profile
    /// (table layout, size, weight format), its sensors (servo counts,
    /// differenced rates, the encoder) and its episode logic, against the
    /// simulated robot: the task's plant (physical-pendulum or leo) or a
    /// robot of files (--robot robot.toml, its URDF's body in rapier3d).
    /// What it learns is what the board will learn; a soft limit faults it
    /// and ends the trial, as it does without --board.
    #[arg(long, value_name = "NAME", value_parser = crate::robots::board_parser())]
    pub board: Option<pada_core::profile::Board>,
    /// With --board: a table of 2^N entries instead of the board's, in the
    /// board's layout (a claim table for LEO; placed in CCM, then SRAM on
    /// an F405), to see what a board would learn with more or less memory.
    /// The firmware builds only the boards' own profiles.
    #[arg(long, value_name = "N", requires = "board", value_parser = clap::value_parser!(u32).range(8..=26))]
    pub table_log2: Option<u32>,
    /// With --board: store weights in 16 or 32 bits (16: stochastic
    /// rounding, the robot's range; see pada_core::weights).
    #[arg(long, value_name = "BITS", requires = "board", value_parser = ["16", "32"])]
    pub weight_bits: Option<String>,
    /// With --board: a claim table's tags in 16 or 32 bits (16: features
    /// whose homes lie within one probe run share a slot with probability
    /// 2^-16, and below 2^17 slots a table keeps only log2 + 15 bits of a
    /// key; 32: only features with equal 32-bit hashes share one; see
    /// pada_core::claim_table).
    #[arg(long, value_name = "BITS", requires = "board", value_parser = ["16", "32"])]
    pub tag_bits: Option<String>,
    /// With --board: what the board's table memory does when it is full
    /// (docs/board.md, "A full table"): a claim table of 16-bit weights and
    /// tags that refuses a new feature (it never learns) or replaces the
    /// least-learned feature of its probe, or collide: a hashed table of
    /// 16-bit weights in the same bytes, twice the entries, where features
    /// share them (the F405's own for robots with many features).
    #[arg(long, value_name = "BEHAVIOUR", requires = "board")]
    pub table_full: Option<TableFull>,
    /// Learn on a plant that is not the model: drawn once per trial within
    /// the ranges (robot.toml's [plant], the pendulums' stated ones, or
    /// --plant-ranges), or randomised anew every episode (domain
    /// randomisation); seeded by --seed (docs/your-robot.md, "A robot that
    /// is not its model").
    #[arg(long, value_enum, value_name = "HOW")]
    pub plant: Option<crate::commands::plant_args::PlantMode>,
    /// With --plant: ranges over the robot's, as NAME=VALUE or
    /// NAME=LOW..HIGH separated by commas (mass, motor_constant,
    /// friction_nm, backlash_rad, delay_periods, noise_rad).
    #[arg(long, value_name = "RANGES", requires = "plant")]
    pub plant_ranges: Option<String>,
    /// Seed and threads.
    #[command(flatten)]
    pub trial: TrialOptions,
    /// Plans, merges and Slurm.
    #[command(flatten)]
    pub cluster: crate::plan::mode::ClusterOptions,
}

/// Runs `pada run`.
pub fn run(args: RunArgs) -> Result<(), CliError> {
    let file = match &args.robot {
        Some(path) => Some(pada_robot_file::load(path).map_err(|e| usage(e.to_string()))?),
        None => None,
    };
    if let Some(board) = args.board {
        let robot = match &file {
            Some(f) => crate::robots::from_file(f).map_err(|e| usage(e.to_string()))?,
            None => crate::robots::sim_robot(robot_of_task(args.task).map_err(usage)?).map_err(|e| usage(e.to_string()))?,
        };
        return run_on_board(args, board, robot);
    }
    if let Some(mode) = args.plant {
        return run_on_plant(args, file, mode);
    }
    match file {
        Some(f) => {
            if args.cluster.plan.is_some() || args.cluster.merge.is_some() || args.cluster.slurm {
                return Err(usage("--plan, --merge and --slurm run pada's own tasks: they do not take --robot yet"));
            }
            let task = pada_sim::urdf::UrdfTask::new(&f).map_err(|e| usage(e.to_string()))?;
            RunVisitor(args).visit(&task)
        }
        None => visit_task(args.task, RunVisitor(args)),
    }
}

/// `pada run --plant`: the trials on plants drawn within the ranges.
fn run_on_plant(
    args: RunArgs,
    file: Option<pada_robot_file::RobotFile>,
    mode: crate::commands::plant_args::PlantMode,
) -> Result<(), CliError> {
    use crate::commands::plant_args::{task_ranges, with_ranges_arg};
    use pada_sim::variation::Varied;
    if args.cluster.plan.is_some() || args.cluster.merge.is_some() || args.cluster.slurm {
        return Err(usage("--plant runs the trials in this process: it does not combine with --plan, --merge or --slurm"));
    }
    let base = match &file {
        Some(f) => f.plant,
        None => task_ranges(args.task)?,
    };
    let ranges = with_ranges_arg(base, args.plant_ranges.as_deref())?;
    if !args.json {
        outln!("plant: {} within {}", match mode {
            crate::commands::plant_args::PlantMode::Drawn => "drawn once per trial",
            crate::commands::plant_args::PlantMode::Randomised => "drawn anew every episode",
        }, ranges.to_arg())?;
    }
    let redraw = mode.redraw();
    match file {
        Some(f) => {
            let task = pada_sim::urdf::UrdfTask::new(&f).map_err(|e| usage(e.to_string()))?;
            RunVisitor(args).visit(&Varied::new(task, ranges, redraw))
        }
        None => match args.task {
            TaskName::Pendulum => RunVisitor(args).visit(&Varied::new(crate::pendulum::SimulatedPendulumTask::default(), ranges, redraw)),
            TaskName::PhysicalPendulum => RunVisitor(args).visit(&Varied::new(crate::pendulum::PhysicalPendulumTask::default(), ranges, redraw)),
            TaskName::Leo => Err(usage("--plant does not vary LEO")),
        },
    }
}

/// What a full board table does (`--table-full`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TableFull {
    /// Refuse the claim and count it.
    Refuse,
    /// Give the new feature the least-learned slot of its probe.
    Replace,
    /// No claims: a hashed table of 16-bit weights in the same bytes.
    Collide,
}

/// `profile`'s table memory holding `full`'s table, or why it cannot: a
/// claim table of 16-bit weights and 16-bit tags that refuses or
/// replaces when full, or a hashed table of 16-bit weights (twice the
/// entries) whose features collide.
fn with_table_full(profile: LearnerProfile, full: TableFull) -> Result<LearnerProfile, CliError> {
    if profile.layout == Layout::Exact {
        return Err(usage(format!(
            "--table-full needs a robot whose table is hashed or claimed; {} has an exact one for {}",
            profile.board.name(),
            profile.robot.name
        )));
    }
    let bytes = profile.table_bytes().unwrap_or(0);
    let format = WeightFormat::Half { shift: profile.robot.half_shift };
    let claim = |when_full| {
        let slots = (bytes / (format.bytes() + 2)).max(2);
        profile.with_hashed_table(Layout::Claimed, slots.ilog2(), format, 2).when_full(when_full)
    };
    Ok(match full {
        TableFull::Refuse => claim(WhenFull::Refuse),
        TableFull::Replace => claim(WhenFull::Replace),
        TableFull::Collide => {
            let entries = (bytes / format.bytes()).max(2);
            profile.with_hashed_table(Layout::Hashed, entries.ilog2(), format, 0).when_full(WhenFull::Refuse)
        }
    })
}

/// `pada run --board`: the board's own learner ([`crate::board`]).
fn run_on_board(args: RunArgs, board: Board, sim: crate::robots::SimRobot) -> Result<(), CliError> {
    let robot = sim.robot;
    if args.plant.is_some() {
        return Err(usage("--plant is not available with --board: the board's run drives the model's plant"));
    }
    for (flag, given) in [
        ("--telemetry", args.telemetry.is_some()),
        ("--mcap", args.mcap.is_some()),
        ("--save-weights", args.save_weights.is_some()),
    ] {
        if given {
            return Err(usage(format!(
                "{flag} is not available with --board (the board streams its own telemetry: `pada sil --telemetry`, \
                 whose output directory holds telemetry.mcap)"
            )));
        }
    }
    if args.cluster.plan.is_some() || args.cluster.merge.is_some() || args.cluster.slurm {
        // A plan's configurations leave room for a board (plan::Configuration::board),
        // but its trials run on the host's learner only, so far.
        return Err(usage(
            "--plan, --merge and --slurm run the host's learner: they do not combine with --board yet",
        ));
    }
    let mut profile = board.profile(robot).map_err(|e| match &args.robot {
        Some(p) => usage(format!("{}: {e}", p.display())),
        None => usage(e.to_string()),
    })?;
    if let Some(p) = &args.robot {
        crate::board::readable::check_readable(robot).map_err(|e| usage(format!("{}: {e}", p.display())))?;
    }
    let format = match args.weight_bits.as_deref() {
        Some("16") => WeightFormat::Half { shift: robot.half_shift },
        Some(_) => WeightFormat::Q16,
        None => profile.format,
    };
    let tag_bytes = match args.tag_bits.as_deref() {
        Some("16") => 2,
        Some(_) => 4,
        None => profile.tag_bytes,
    };
    if args.tag_bits.is_some() && profile.layout != Layout::Claimed {
        return Err(usage(format!(
            "--tag-bits needs a claim table; {} has a {} one for {}",
            board.name(),
            profile.layout.name(),
            robot.name
        )));
    }
    if args.table_log2.is_some() || format != profile.format || tag_bytes != profile.tag_bytes {
        let log2 = match (args.table_log2, profile.layout, profile.weights()) {
            (Some(n), _, _) => n,
            (None, Layout::Hashed | Layout::Claimed, Some(n)) => n.trailing_zeros(),
            _ => return Err(usage(format!(
                "--weight-bits without --table-log2 needs a hashed board table; {} has an exact one for {}",
                board.name(),
                robot.name
            ))),
        };
        let layout = if profile.layout == Layout::Exact { Layout::Hashed } else { profile.layout };
        profile = profile.with_hashed_table(layout, log2, format, tag_bytes);
    }
    if let Some(full) = args.table_full {
        profile = with_table_full(profile, full)?;
    }
    let policy = policy_of(&args)?;
    // The task as the runner describes it, with the board's table: the
    // summary's keys and parameters are `pada run`'s.
    let task_spec = sim.task_spec(profile).map_err(|e| usage(e.to_string()))?;
    let weights = table_len(&profile, policy).map_err(|e| usage(format!("{e}")))?;
    if let Err(e) = robot.check::<TILINGS>(policy, profile.layout, weights) {
        return Err(usage(format!(
            "--algo {} does not fit board {}'s learner for {} ({} {} weights): {e}",
            args.algo,
            board.name(),
            robot.name,
            weights,
            profile.layout.name()
        )));
    }
    let cfg = run_config(&args, &task_spec, policy)?;
    let out_path = args.out.clone().unwrap_or_else(|| {
        PathBuf::from(format!("pada-out/run-{}-{}-{}", task_spec.name, args.algo, board.name()))
    });
    let out = OutDir::check(&out_path)?;
    set_threads(args.trial.threads)?;
    // The host's weights in the board's table, checked before anything
    // runs.
    let entries = match &args.weights {
        Some(path) => {
            let (entries, report) = exported_weights(path, &sim, &profile, policy, weights)?;
            for line in report.lines(board.name()) {
                if args.json {
                    eprintln!("{line}");
                } else {
                    outln!("{line}")?;
                }
            }
            Some(entries)
        }
        None => None,
    };
    // Before the board's run: the slots this robot's learning writes
    // against the board's claim table, from a host trial (cached).
    if profile.layout != Layout::Exact && crate::board::demand::has_claim_table(&sim) {
        let bar = steps_bar(
            cfg.expected_steps(task_spec.control_period_s, task_spec.episode_steps, task_spec.test_interval),
            &format!("{}: the table's demand (a host trial)", task_spec.name),
        );
        let demand = crate::board::demand::demand(&sim, policy, cfg.seconds, cfg.seed, &|n| bar.inc(n))
            .map_err(|e| usage(format!("{e:#}")))?;
        bar.finish_and_clear();
        if let Some(f) = crate::board::demand::Forecast::of(&demand, &profile) {
            for line in f.lines(&demand) {
                if args.json {
                    eprintln!("{line}");
                } else {
                    outln!("{line}")?;
                }
            }
        }
    }
    let start_from = entries.as_deref().map_or(BoardStart::Fresh, BoardStart::Entries);
    let total = cfg.trials as u64
        * cfg.expected_steps(task_spec.control_period_s, task_spec.episode_steps, task_spec.test_interval);
    let bar = steps_bar(total, &format!("{} {} on {}", task_spec.name, label(&policy), board.name()));
    let start = Instant::now();
    let trials = run_board_from(profile, &sim, &cfg, start_from, &|n| bar.inc(n))?;
    let wall = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let summary = BoardSummary::new(&task_spec, &cfg, &profile, &trials, wall);
    out.write_all(&board_files(&summary)?)?;
    if args.json {
        outln!("{}", summary.to_json())?;
    } else {
        print_summary(&summary.run, &run_label(&policy, cfg.mtbf_budget_s))?;
        let p = &summary.profile;
        outln!(
            "  board                {}: {} table of {} entries ({} KiB: {}-bit weights{}) in {}",
            board.name(),
            p.layout,
            p.weights,
            p.table_bytes / 1024,
            p.weight_bits,
            if p.tag_bits > 0 { format!(", {}-bit tags", p.tag_bits) } else { String::new() },
            p.memory
        )?;
        outln!("wrote {}", out.path().display())?;
    }
    Ok(())
}

/// The host's weights in `path` (saved by `pada run` for `sim`'s robot,
/// with the host's table), exported into `profile`'s table of `n`
/// entries for a board run with `policy`: the entries' bytes and what the
/// export changed. A file for another robot, table or learner is refused
/// with one line.
pub fn exported_weights(
    path: &std::path::Path,
    sim: &crate::robots::SimRobot,
    profile: &LearnerProfile,
    policy: pada_core::policy::PolicyKind,
    n: usize,
) -> Result<(Vec<u8>, ExportReport), CliError> {
    let board_spec = &sim.task_spec(*profile).map_err(|e| usage(e.to_string()))?;
    let host_profile = Board::Host.profile(sim.robot).map_err(|e| usage(e.to_string()))?;
    let host_spec = sim.task_spec(host_profile).map_err(|e| usage(e.to_string()))?;
    let w = StartWeights::load(path, &host_spec, policy).map_err(|e| usage(format!("--weights {e}")))?;
    // The board's learner is the host's but for its table.
    let mut host = crate::weights::WeightsHeader::new(&host_spec, policy, false, 0);
    let on_board = crate::weights::WeightsHeader::new(board_spec, policy, false, 0);
    (host.table, host.entry_bytes) = (on_board.table.clone(), on_board.entry_bytes);
    if let Some((name, h, b)) = host.mismatch(&on_board) {
        return Err(usage(format!(
            "--weights {}: board {}'s learner differs from the host's in more than its table: {name} is {b} on the board but {h} on the host",
            path.display(),
            profile.board.name()
        )));
    }
    export(&w, &host_spec, profile, n).map_err(|e| usage(format!("--weights {e}")))
}

/// The run's label: the policy, or the governed policy and its budget.
fn run_label(policy: &pada_core::policy::PolicyKind, budget_s: Option<f32>) -> String {
    crate::paper::wear::WearResult::label_of(policy, budget_s)
}

/// The policy of the flags, checked.
fn policy_of(args: &RunArgs) -> Result<pada_core::policy::PolicyKind, CliError> {
    let flags = PolicyFlags { alpha: args.alpha, delta: args.delta, theta: args.theta, sigma: args.sigma, weight: args.weight };
    crate::commands::policy_args::checked_policy(args.algo, &flags, args.mtbf_budget)
}

/// The run's configuration from the flags, checked.
fn run_config(args: &RunArgs, spec: &TaskSpec, policy: pada_core::policy::PolicyKind) -> Result<RunConfig, CliError> {
    let seconds = check_seconds("--seconds", args.seconds.unwrap_or(spec.default_seconds))?;
    if args.mtbf_budget.is_some() {
        if args.switch_at.is_some() {
            return Err(usage(
                "--switch-at and --mtbf-budget exclude each other: the governor keeps the restriction for the whole run",
            ));
        }
    }
    if let Some(s) = args.switch_at {
        if args.algo == Algo::Sarsa || !args.algo.can_switch() {
            return Err(usage(format!(
                "--switch-at applies only to lowpass, pada, epsilon-pada, ou, pink and action-penalty (Section VIII), not to {}",
                args.algo
            )));
        }
        if !(s.is_finite() && s >= 0.0 && s <= seconds) {
            return Err(usage(format!(
                "--switch-at {s} is out of range: valid is 0 <= switch-at <= seconds ({seconds})"
            )));
        }
    }
    Ok(RunConfig {
        policy,
        switch_at_s: args.switch_at,
        mtbf_budget_s: args.mtbf_budget,
        seconds,
        trials: args.trials.unwrap_or(spec.default_trials),
        seed: args.trial.seed,
    })
}

struct RunVisitor(RunArgs);

impl TaskVisitor for RunVisitor {
    type Output = Result<(), CliError>;

    fn visit<T: Task>(self, task: &T) -> Self::Output {
        let args = self.0;
        let spec = task.spec();
        let policy = policy_of(&args)?;
        let cfg = run_config(&args, spec, policy)?;
        let out_path = args
            .out
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("pada-out/run-{}-{}", spec.name, args.algo)));
        let out = OutDir::check(&out_path)?;
        let mode = args.cluster.mode(out.path())?;
        if mode != Mode::Local
            && (args.telemetry.is_some() || args.mcap.is_some() || args.save_weights.is_some() || args.weights.is_some())
        {
            return Err(usage(
                "--telemetry, --mcap, --save-weights and --weights need the trials in this process: they do not combine with --plan, --merge or --slurm",
            ));
        }
        let start = match &args.weights {
            Some(p) => Some(StartWeights::load(p, spec, policy).map_err(|e| usage(format!("--weights {e}")))?),
            None => None,
        };
        let apply = start.as_ref().map(|s| move |a: &mut crate::experiment::HostAgent| s.apply(a));
        let mut telemetry = match &args.telemetry {
            Some(t) => Some(TelemetrySink::open(&parse_target(t)?)?),
            None => None,
        };
        let mut mcap = match &args.mcap {
            Some(p) => Some(crate::mcap::tee::McapTee::create(p, "--mcap")?),
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
            let results = if telemetry.is_none() && mcap.is_none() && args.save_weights.is_none() && start.is_none() {
                run_trials(task, &cfg, &|n| bar.inc(n))?
            } else {
                let weight_count = pada_core::weights::WeightStore::len(build_agent(spec, policy)?.weights()) as u32;
                let (mut sink, mut tee) = (telemetry.as_mut(), mcap.as_mut());
                let streaming = sink.is_some() || tee.is_some();
                let mut observer = streaming.then(|| {
                    let hello = ToHost::Hello(wire::Hello {
                        protocol: wire::PROTOCOL_VERSION,
                        // The task's robot; the simulated pendulum, which is
                        // none, by the task's name with hash 0.
                        robot: heapless::String::try_from(spec.name).unwrap_or_default(),
                        robot_hash: spec.profile.map_or(0, |p| p.robot.definition_hash()),
                        // 0: a host run, not a firmware configuration.
                        config_hash: 0,
                        weight_count,
                        period_us: (spec.control_period_s * 1e6).round() as u32,
                        state_dims: spec.state.len() as u8,
                        joints: spec.motor.dims() as u8,
                    });
                    let mut send = move |msg: ToHost| {
                        if let Some(s) = sink.as_mut() {
                            s.send(&msg);
                        }
                        if let Some(t) = tee.as_mut() {
                            t.send(&msg);
                        }
                    };
                    send(hello);
                    send
                });
                let (results, agent, switched) = run_trials_observed(
                    task,
                    &cfg,
                    &|n| bar.inc(n),
                    observer
                        .as_mut()
                        .map(|o| o as &mut (dyn FnMut(ToHost) + Send)),
                    apply.as_ref().map(|f| f as StartWith<'_>),
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
        if let Some(tee) = mcap {
            let (frames, path) = tee.finish()?;
            if !args.json {
                outln!("mcap: trial 0, {frames} frames recorded in {}", path.display())?;
            }
        }
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
            print_summary(&summary, &run_label(&policy, cfg.mtbf_budget_s))?;
            if let Some(s) = &start {
                outln!(
                    "  started from         {} ({} weights learned by {})",
                    s.path.display(),
                    s.header.weights,
                    crate::experiment::algo::label(&s.header.policy)
                )?;
            }
            outln!("wrote {}", out.path().display())?;
        }
        Ok(())
    }
}

/// The command line that describes a run, with every value explicit (a
/// plan's identity, and the merge command it prints).
fn command_line(args: &RunArgs, cfg: &RunConfig) -> String {
    let mut c = match &args.robot {
        Some(p) => format!("pada run --robot {} --algo {}", p.display(), args.algo),
        None => format!("pada run --task {} --algo {}", args.task, args.algo),
    };
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
        "  MTBF (1200 actions)  {} (the paper's: torque from the commanded action)",
        fmt_mtbf(s.mtbf_s.mean, s.mtbf_s.ci95)
    )?;
    outln!(
        "  MTBF (whole run)     {} (the paper's, over all learning actions)",
        fmt_mtbf(s.run_mtbf_s.mean, s.run_mtbf_s.ci95)
    )?;
    outln!(
        "  physical MTBF        {} (from the simulated gear torques)",
        fmt_mtbf(s.physical_mtbf_s.mean, s.physical_mtbf_s.ci95)
    )?;
    for g in &s.gearboxes {
        outln!(
            "    {:<18} {} (physical {}), gearbox {}{}",
            g.joint,
            fmt_mtbf(g.mtbf_s.mean, g.mtbf_s.ci95),
            fmt_mtbf(g.physical_mtbf_s.mean, g.physical_mtbf_s.ci95),
            g.gearbox,
            if g.estimate { " (geometry estimated)" } else { "" }
        )?;
    }
    if let Some(g) = &s.governor {
        outln!(
            "  wear governor        budget {} s: held in {:.0} % of trials (physical MTBF: {:.0} %); mean {} {}, at the floor {:.0} % of the time, {:.0} moves per trial",
            g.budget_s,
            100.0 * g.held_fraction,
            100.0 * g.physical_held_fraction,
            if s.algo.takes_alpha() { "α" } else { "Δ" },
            fmt_estimate(g.mean_parameter.mean, g.mean_parameter.ci95, 3, ""),
            100.0 * g.floor_fraction.mean,
            g.moves.mean
        )?;
    }
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
    let tables: Vec<_> = s.per_trial.iter().filter_map(|t| t.table).collect();
    if let Some(most) = tables.iter().max_by_key(|o| o.claimed) {
        outln!(
            "  claim table          {} of {} slots claimed ({:.1} %, the fullest trial), {} claims refused and {} replaced in all, longest probe {}",
            most.claimed,
            most.slots,
            100.0 * most.fraction(),
            tables.iter().map(|o| o.refused as u64).sum::<u64>(),
            tables.iter().map(|o| o.replaced as u64).sum::<u64>(),
            tables.iter().map(|o| o.longest_probe).max().unwrap_or(0)
        )?;
    }
    outln!(
        "  wall {:.1} s, {:.0} env steps/s on {} threads",
        s.wall_s, s.env_steps_per_s, s.threads
    )?;
    Ok(())
}
