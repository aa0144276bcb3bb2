//! `pada sil`: the firmware image learns inside QEMU against the simulated
//! plant (docs/sil.md).

use crate::console::{errln, outln};
use crate::commands::options::check_seconds;
use crate::error::{usage, CliError};
use crate::commands::policy_args::PolicyArgs;
use crate::experiment::algo::{label, Algo};
use crate::output::OutDir;
use crate::sil::{self, fault, SilConfig, SilSummary, SilTask};
use anyhow::{anyhow, Context};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// `pada sil`.
#[derive(Debug, Clone, Args)]
pub struct SilArgs {
    /// The robot: the physical pendulum (`pendulum`, the robot
    /// `physical-pendulum` of `pada run --task`; not `pada run --task
    /// pendulum`, the simulated one) against its model, or LEO (against the
    /// rapier3d LEO, with an operator who sets it up between episodes).
    #[arg(long, value_enum, default_value_t = SilTask::Pendulum)]
    pub task: SilTask,
    /// A robot of your own instead of --task: the path of its robot.toml
    /// (relative to the current directory; the URDF it names is read from
    /// beside it). The image is built for it (`cargo xtask qemu --robot
    /// FILE`, unless --elf), and the emulated bus answers with the physics
    /// of its URDF in rapier3d, as `pada run --board B --robot FILE`
    /// simulates it (default board f405).
    #[arg(long, value_name = "robot.toml", conflicts_with = "task")]
    pub robot: Option<PathBuf>,
    /// The board learner profile the image is built for, and so the
    /// emulated board: f405 (QEMU's netduinoplus2, an STM32F405) or
    /// f429-sdram (QEMU's mps2-an386, whose PSRAM holds LEO's 8 MiB table
    /// as the F429I-DISC1's SDRAM would). Default: f405 for the pendulum,
    /// f429-sdram for LEO.
    #[arg(long, value_parser = crate::robots::board_parser())]
    pub board: Option<pada_core::profile::Board>,
    /// Master seed, as `pada run`'s: the board learns with trial 0's seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Do not forecast the bus's answers: every answer costs a lock-step
    /// exchange (the same run, slower; to measure the forecasts).
    #[arg(long)]
    pub no_forecast: bool,
    /// Skip the comparison with the same controller on the host (`pada run
    /// --board`'s runner).
    #[arg(long)]
    pub no_compare: bool,
    /// Learning time to reach [s of emulated learning episodes] (default:
    /// 600 for the pendulum, 60 for LEO and a robot of files).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// The algorithm the firmware learns with (Section V).
    #[arg(long, value_parser = crate::experiment::algo::algo_parser(), default_value_t = Algo::Sarsa)]
    pub algo: Algo,
    /// α, Δ or a wear budget (the firmware's wear governor: `SetMtbfBudget`,
    /// sent after the policy and before the first run).
    #[command(flatten)]
    pub learner: PolicyArgs,
    /// Inject a fault on the servo bus (repeatable):
    /// KIND[:at=S][:for=S][:servo=ID][:ms=MS][:bits=NAME] with KIND drop,
    /// corrupt, delay, error-bits or past-limit; or `hang[:at=S]` (the
    /// control loop stops; the watchdog must reset the chip; mps2 boards
    /// only, board f429-sdram) (docs/sil.md).
    #[arg(long, value_name = "SPEC")]
    pub fault: Vec<String>,
    /// A power cut, repeatable: `at=SECONDS` (emulated time),
    /// `random:N[:in-save=M][:seed=K]` (N cuts at seeded random instants, M of them (default a third)
    /// inside a checkpoint save) or `during-save:K` (inside the K-th save).
    /// QEMU is killed (SIGKILL), the checkpoint file kept as it is, and the
    /// same image boots on it; the run goes on from the last completed save.
    #[arg(long, value_name = "SPEC")]
    pub power_cut: Vec<String>,
    /// Save a checkpoint every S seconds of learning (`Pause`,
    /// `SaveCheckpoint`, `Start` between learning episodes). Default with
    /// `--power-cut` or `--fault hang`, else none: 20 s for a checkpoint in
    /// flash; for one streamed to the host (LEO on f429-sdram, whose 8 MiB
    /// table fits no flash), three times the link time of a full table's
    /// save (the learner stands still while it streams over the 921 600-baud
    /// telemetry link: about 2 min) plus two of the robot's longest
    /// episodes, so that saves hold learning for at most a quarter of the
    /// time (LEO on f429-sdram: 403 s).
    #[arg(long, value_name = "S")]
    pub checkpoint_every: Option<f64>,
    /// The firmware ELF built for the emulated board (default: build it
    /// with `cargo xtask qemu --board B --robot R` in this repository).
    #[arg(long, value_name = "FILE")]
    pub elf: Option<PathBuf>,
    /// The QEMU to run (10 or later).
    #[arg(long, value_name = "PROGRAM", default_value = "qemu-system-arm")]
    pub qemu: PathBuf,
    /// Output directory: telemetry.bin (the raw stream), telemetry.csv,
    /// telemetry.mcap (the channels of `pada capture --mcap`, for
    /// Foxglove), episodes.csv, summary.json, the firmware's log (default:
    /// pada-out/sil-<task>-<algo>-<board>).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Wall-clock seconds without a word from the board before the run is
    /// called hung.
    #[arg(long, value_name = "S", default_value_t = 60)]
    pub hang_timeout: u64,
    /// Also stream the firmware's telemetry frames, as they come, to FILE
    /// or to tcp:HOST:PORT (loopback only).
    #[arg(long, value_name = "FILE|tcp:HOST:PORT")]
    pub telemetry: Option<String>,
    /// Start from weights learned on the host (`pada run --save-weights`):
    /// exported into the board's table as `pada run --board B --weights`
    /// does (the same summary), saved as the learner's checkpoint, which
    /// the host keeps and the board restores at its first boot. Only a
    /// board whose checkpoint the host keeps (f429-sdram with LEO) yet.
    #[arg(long, value_name = "FILE")]
    pub weights: Option<PathBuf>,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs `pada sil`.
pub fn run(args: SilArgs) -> Result<(), CliError> {
    let policy = args.learner.policy(args.algo)?;
    // A bad robot file is the user's mistake: one line, exit code 2.
    let task = match &args.robot {
        Some(path) => SilTask::of_file(path).map_err(|e| usage(format!("--robot: {e:#}")))?,
        None => args.task,
    };
    let default_seconds = match task {
        SilTask::Pendulum => 600.0,
        SilTask::Leo | SilTask::File(_) => 60.0,
    };
    let seconds = check_seconds("--seconds", args.seconds.unwrap_or(default_seconds))?;
    let board = args.board.unwrap_or(task.default_board());
    if sil::machine(board).is_none() {
        return Err(usage(format!(
            "--board {}: no emulated board; valid are f405 (netduinoplus2) and f429-sdram (mps2-an386)",
            board.name()
        )));
    }
    let mut hangs_s = Vec::new();
    let mut bus_faults = Vec::new();
    for f in &args.fault {
        match sil::power_cut::parse_hang(f) {
            Some(t) => hangs_s.push(t.map_err(usage)?),
            None => bus_faults.push(fault::parse(f).map_err(usage)?),
        }
    }
    let faults = bus_faults;
    if !hangs_s.is_empty() && board == pada_core::profile::Board::F405 {
        return Err(usage(
            "--fault hang: QEMU's netduinoplus2 (the f405 board's emulation) models no watchdog; \
             test the hang on mps2-an386 (--board f429-sdram), whose CMSDK watchdog the firmware arms"
                .to_string(),
        ));
    }
    let power_cuts = args
        .power_cut
        .iter()
        .map(|c| sil::power_cut::parse(c))
        .collect::<Result<Vec<_>, _>>()
        .map_err(usage)?;
    if let Some(s) = args.checkpoint_every {
        if !(s.is_finite() && s >= 1.0) {
            return Err(usage(format!("--checkpoint-every {s}: at least 1 s of learning")));
        }
    }
    let spec = task.robot();
    let profile = board.profile(spec).map_err(|e| match &args.robot {
        Some(path) => usage(format!("--robot {}: {e} on board {}", path.display(), board.name())),
        None => usage(e.to_string()),
    })?;
    if let Some(path) = &args.robot {
        crate::board::readable::check_readable(spec).map_err(|e| usage(format!("--robot {}: {e}", path.display())))?;
    }
    let save_every_s = args.checkpoint_every.or((!power_cuts.is_empty() || !hangs_s.is_empty()).then(|| {
        // The interval follows the time a save of this image takes on the
        // link: 20 s between LEO's 2-minute streams stopped learning most of
        // the time.
        sil::power_cut::default_save_every_s(
            sil::power_cut::checkpoint_bytes(profile.weights().unwrap_or(0), profile.entry_bytes()),
            pada_firmware::sil::CHECKPOINT_SLOT_LEN,
            spec.episode_steps as f64 * spec.period_us as f64 * 1e-6,
        )
    }));
    sil::bus::carried::check_servos(task.robot()).map_err(|e| usage(format!("{}: {e}", task.robot().name)))?;
    sil::bus::check_faults(task.robot(), &faults).map_err(usage)?;
    if !(1..=3600).contains(&args.hang_timeout) {
        return Err(usage(format!(
            "--hang-timeout {} is out of range: valid is 1..=3600 s",
            args.hang_timeout
        )));
    }
    let telemetry = args
        .telemetry
        .as_deref()
        .map(crate::telemetry::parse_target)
        .transpose()?;
    let out_path = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("pada-out/sil-{}-{}-{}", task.name(), args.algo, board.name())));
    OutDir::check(&out_path)?;
    let elf = match &args.elf {
        Some(p) if p.is_file() => p.clone(),
        Some(p) => return Err(usage(format!("--elf {}: no such file", p.display()))),
        None => build_image(task, board)?,
    };
    let weights = match &args.weights {
        Some(path) => {
            let sim = task.sim().map_err(|e| usage(format!("{e:#}")))?;
            let n = crate::board::trial::table_len(&profile, policy).map_err(|e| usage(e.to_string()))?;
            let ckpt = sil::power_cut::checkpoint_bytes(n, profile.entry_bytes());
            if ckpt <= pada_firmware::sil::CHECKPOINT_SLOT_LEN {
                return Err(usage(format!(
                    "--weights on board {}: its checkpoint lives in flash, which the emulation starts erased; \
                     only a board whose checkpoint the host keeps (f429-sdram with LEO) starts from exported weights in pada sil",
                    board.name()
                )));
            }
            let (entries, report) = crate::commands::run::exported_weights(path, &sim, &profile, policy, n)?;
            for line in report.lines(board.name()) {
                eprintln!("{line}");
            }
            let seed = crate::seed::trial_seed(args.seed, 0);
            let image = crate::board::exported::image_of(profile, &sim, policy, args.learner.mtbf_budget, seed, n, &entries)
                .map_err(|e| usage(format!("--weights {}: {e:#}", path.display())))?;
            Some(sil::config::SilWeights { entries, image })
        }
        None => None,
    };
    let cfg = SilConfig {
        qemu: args.qemu.clone(),
        elf,
        task,
        board,
        policy,
        mtbf_budget_s: args.learner.mtbf_budget,
        seconds,
        seed: args.seed,
        faults,
        power_cuts,
        hangs_s,
        save_every_s,
        forecast: !args.no_forecast,
        compare: !args.no_compare,
        out_dir: out_path.clone(),
        hang_timeout: Duration::from_secs(args.hang_timeout),
        progress: !args.json,
        telemetry,
        weights,
    };
    let summary = sil::run(&cfg)?;
    if args.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&summary).map_err(|e| CliError::Runtime(e.into()))?
        )?;
    } else {
        print_summary(&summary, &label(&policy))?;
        outln!("wrote {}", out_path.display())?;
    }
    if summary.passed {
        Ok(())
    } else {
        let failed: Vec<&str> = summary
            .checks
            .iter()
            .filter(|c| !c.ok)
            .map(|c| c.name)
            .collect();
        Err(CliError::Runtime(anyhow!(
            "SIL checks failed: {}",
            failed.join("; ")
        )))
    }
}

/// Builds the emulated board's image with `cargo xtask qemu` in the
/// repository this binary was built from.
fn build_image(task: SilTask, board: pada_core::profile::Board) -> Result<PathBuf, CliError> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    if !root.join("xtask").is_dir() || !root.join("firmware").is_dir() {
        return Err(usage(format!(
            "no firmware image given and no pada repository at {} to build one: pass --elf FILE \
             (built with `cargo xtask qemu`)",
            root.display()
        )));
    }
    let (robot, board) = (task.xtask_robot(), board.name());
    errln!("pada sil: building the firmware for the emulated board (cargo xtask qemu --board {board} --robot {robot})");
    let output =
        std::process::Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
            .current_dir(&root)
            .args(["xtask", "qemu", "--board", board, "--robot", &robot])
            .stderr(std::process::Stdio::inherit())
            .output()
            .context("cannot start cargo to build the firmware (pass --elf FILE instead)")?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        return Err(CliError::Runtime(anyhow!(
            "cargo xtask qemu failed ({}):\n{stdout}",
            output.status
        )));
    }
    stdout
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("xtask: firmware ELF: "))
        .map(PathBuf::from)
        .ok_or_else(|| {
            CliError::Runtime(anyhow!("cargo xtask qemu did not name the ELF:\n{stdout}"))
        })
}

fn print_summary(s: &SilSummary, policy: &str) -> Result<(), CliError> {
    outln!(
        "sil {} on board {} ({}), {policy}, seed {}: {:.0} s learning in {:.0} s emulated, {:.1} s wall ({:.1}x real time, {:.2} exchanges per period)",
        s.robot, s.board, s.machine, s.seed, s.learning_s, s.emulated_s, s.wall_s, s.speedup, s.exchanges_per_period
    )?;
    outln!("  plant: {}", s.plant)?;
    let fmt = |x: Option<f64>| x.map(|v| format!("{v:.1}")).unwrap_or_else(|| "-".into());
    outln!(
        "  test return: first {}, end performance {}, rise time {} s; {} learning episodes{}",
        fmt(s.first_test_return),
        fmt(s.end_performance),
        fmt(s.rise_time_s),
        s.learning_episodes,
        s.end_walked_m.map(|w| format!("; walked {w:.2} m per test run (last 10 %)")).unwrap_or_default()
    )?;
    let i = &s.agent_instructions;
    outln!(
        "  agent step on the Cortex-M4 build: {:.0} instructions mean (min {}, max {}) learning; {:.0} greedy",
        i.learning_step.mean, i.learning_step.min, i.learning_step.max, i.test_step.mean
    )?;
    for c in &s.checks {
        outln!(
            "  [{}] {}: {}",
            if c.ok { "ok" } else { "FAILED" },
            c.name,
            c.detail
        )?;
    }
    Ok(())
}

/// The help of `--checkpoint-every`, as `pada sil --help` prints it (a test
/// checks that the default it names is the one computed).
#[cfg(test)]
pub(crate) fn checkpoint_every_help() -> String {
    use clap::Args as _;
    let cmd = SilArgs::augment_args(clap::Command::new("sil"));
    let help = cmd
        .get_arguments()
        .find(|a| a.get_id() == "checkpoint_every")
        .and_then(|a| a.get_long_help().or(a.get_help()))
        .map(|h| h.to_string())
        .unwrap_or_default();
    help
}
