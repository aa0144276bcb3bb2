//! `pada drive --port /dev/ttyUSB0 --robot R`: learning on a real robot
//! from a PC ([`crate::drive`]).
//!
//! Writes into `--out` (default `pada-out/drive-<robot>-<algo>`):
//! `summary.json`, `trials.csv` and `trial-000.csv` as `pada run --board`
//! does (the learning curve), `drive.json` (why it ended, the period's
//! jitter and overruns, the bus's counters, each servo's set-up, the
//! checkpoint), `telemetry.csv` (every frame the run sent, as `pada
//! capture --out` writes them) and, unless `--checkpoint` puts it
//! elsewhere, `checkpoint.bin` (loaded at the start when it matches).

use crate::board::trial::table_len;
use crate::commands::options::check_seconds;
use crate::commands::stream_args::StreamRecord;
use crate::console::{errln, outln};
use crate::drive::latency::latency;
use crate::drive::session::{drive, BadBus, DriveSetup, Ended};
use crate::drive::telemetry::TelemetryPipe;
use crate::error::{usage, CliError};
use crate::commands::policy_args::PolicyArgs;
use crate::experiment::algo::{label, Algo};
use crate::experiment::RunConfig;
use crate::output::OutDir;
use crate::robot_arg::RobotArg;
use crate::summary::{board_files, BoardSummary};
use crate::telemetry::{parse_target, TelemetrySink};
use clap::Args;
use pada_core::profile::{Board, TILINGS};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// `pada drive`.
#[derive(Debug, Clone, Args)]
pub struct DriveArgs {
    /// The serial port of the robot's servos: a USB adapter
    /// (/dev/ttyUSB0, /dev/serial/by-id/…) or `pada servos`' port.
    #[arg(long, value_name = "DEVICE")]
    pub port: PathBuf,
    /// The robot: a built-in robot (pendulum, pendulum-20hz, leo) or the
    /// path of a robot's robot.toml.
    #[arg(long, value_name = "R", value_parser = RobotArg::parser())]
    pub robot: RobotArg,
    /// Every joint's servo of this model instead of the definition's (the
    /// pendulum on an X-series servo): RX-28, MX-28, XM430-W350, XL430-W250,
    /// XL330-M288.
    #[arg(long, value_name = "MODEL")]
    pub servo: Option<String>,
    /// The servos' baud rate.
    #[arg(long, value_name = "BPS", default_value_t = 1_000_000)]
    pub baud: u32,
    /// The learner's profile: the PC's (host: as large a table as the robot
    /// needs), or a board's, to learn as that board would.
    #[arg(long, value_name = "NAME", value_parser = crate::robots::board_parser(), default_value = "host")]
    pub board: Board,
    /// The algorithm (Section V).
    #[arg(long, value_parser = crate::experiment::algo::algo_parser(), default_value = "pada")]
    pub algo: Algo,
    /// α, Δ or a wear budget.
    #[command(flatten)]
    pub learner: PolicyArgs,
    /// Switch back to SARSA(λ) after this much learning time [s].
    #[arg(long, value_name = "SECONDS")]
    pub switch_at: Option<f64>,
    /// Learning time [s] before the final test episode (default 1500).
    #[arg(long, value_name = "S")]
    pub seconds: Option<f64>,
    /// Seed of the learner (as trial 0 of `pada run --board --seed K`).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Against `pada servos --lockstep`: run each period as soon as the last
    /// ends, on the virtual servos' clock, reproducibly.
    #[arg(long)]
    pub lockstep: bool,
    /// The output directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// The checkpoint file (default: checkpoint.bin in the output
    /// directory): loaded at the start when its configuration matches,
    /// saved at the end.
    #[arg(long, value_name = "FILE")]
    pub checkpoint: Option<PathBuf>,
    /// Start from weights learned on the host (`pada run --save-weights`
    /// for this robot): exported into the learner's table (--board's) as
    /// `pada run --board B --weights` does, with the same summary of what
    /// the export changed; the learner then continues from them. A robot,
    /// table or learner the file was not saved for is refused with one
    /// line.
    #[arg(long, value_name = "FILE")]
    pub weights: Option<PathBuf>,
    /// Also stream the telemetry to FILE or tcp:HOST:PORT (`pada watch
    /// --listen tcp:127.0.0.1:9000` shows it live).
    #[arg(long, value_name = "FILE|tcp:HOST:PORT")]
    pub telemetry: Option<String>,
    /// Record the telemetry as MCAP (Foxglove).
    #[arg(long, value_name = "FILE.mcap")]
    pub mcap: Option<PathBuf>,
    /// Serve the telemetry live in Foxglove's WebSocket protocol.
    #[arg(long, value_name = "tcp:HOST:PORT")]
    pub foxglove: Option<String>,
    /// Print drive.json on stdout.
    #[arg(long)]
    pub json: bool,
    /// Run the periods at the ordinary priority: no SCHED_FIFO, no locked
    /// memory (by default, in real time, both are asked for, and what was
    /// granted is in the summary).
    #[arg(long)]
    pub no_realtime: bool,
}

/// `summary.json` of a drive: `pada run --board`'s, and what the operating
/// system granted the control thread.
#[derive(serde::Serialize)]
struct DriveSummary<'a> {
    #[serde(flatten)]
    board: &'a BoardSummary,
    realtime: &'a crate::drive::realtime::RealtimeReport,
}

/// Runs `pada drive`.
pub fn run(args: DriveArgs) -> Result<(), CliError> {
    let mut robot = args.robot;
    if let Some(name) = &args.servo {
        let model = pada_core::servo::servo(name).map_err(|e| usage(format!("--servo: {e}")))?;
        robot = robot.with_servo(model).map_err(usage)?;
    }
    if !(9_600..=4_500_000).contains(&args.baud) {
        return Err(usage(format!("--baud {} is out of range: valid is 9600 to 4500000 (57600 and 1000000 are usual)", args.baud)));
    }
    let policy = args.learner.policy(args.algo)?;
    let profile = args.board.profile(robot.spec).map_err(|e| usage(e.to_string()))?;
    let weights = table_len(&profile, policy).map_err(|e| usage(e.to_string()))?;
    robot
        .spec
        .check::<TILINGS>(policy, profile.layout, weights)
        .map_err(|e| usage(format!("--algo {} does not fit the {} learner for {}: {e}", args.algo, args.board.name(), robot.spec.name)))?;
    let seconds = check_seconds("--seconds", args.seconds.unwrap_or(1500.0))?;
    if let Some(s) = args.switch_at {
        if !(s.is_finite() && s >= 0.0 && s <= seconds) || args.algo == Algo::Sarsa {
            return Err(usage(format!("--switch-at {s}: valid is 0 <= switch-at <= seconds ({seconds}), with an algorithm other than sarsa")));
        }
    }
    let cfg = RunConfig { policy, switch_at_s: args.switch_at, mtbf_budget_s: args.learner.mtbf_budget, seconds, trials: 1, seed: args.seed };
    let exported = match &args.weights {
        Some(path) => {
            let (entries, report) = crate::commands::run::exported_weights(path, robot.sim(), &profile, policy, weights)?;
            for line in report.lines(args.board.name()) {
                errln!("drive: {line}");
            }
            Some(entries)
        }
        None => None,
    };
    let out_path = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("pada-out/drive-{}-{}", robot.spec.name, args.algo)));
    let out = OutDir::check(&out_path)?;
    std::fs::create_dir_all(out.path()).map_err(|e| usage(format!("--out {}: {e}", out.path().display())))?;
    let checkpoint = args.checkpoint.clone().unwrap_or_else(|| out.path().join("checkpoint.bin"));

    // The port's latency timer, before anything runs.
    let lat = latency(&args.port);
    errln!("drive: {}", lat.advice(robot.spec.period_us));

    // Telemetry: the CSV of every frame, MCAP, Foxglove, a stream.
    let csv = std::fs::File::create(out.path().join("telemetry.csv")).map_err(|e| usage(format!("--out: cannot create telemetry.csv: {e}")))?;
    let record = StreamRecord {
        out: None,
        seconds: None,
        json: false,
        mcap: args.mcap.clone(),
        foxglove: args.foxglove.clone(),
        checkpoint: None,
    };
    let mut taps = record.taps("drive")?;
    let sink = match &args.telemetry {
        Some(t) => Some(TelemetrySink::open(&parse_target(t)?)?),
        None => None,
    };
    let pipe = TelemetryPipe::start(Some(Box::new(std::io::BufWriter::new(csv))), taps.tap.take(), sink).map_err(CliError::Runtime)?;

    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let spec = robot.spec;
    let setup = DriveSetup {
        robot,
        profile,
        cfg,
        port: args.port.clone(),
        baud: args.baud,
        lock_step: args.lockstep,
        checkpoint: Some(checkpoint),
        weights: exported,
        stop,
        latency: lat,
        realtime: !args.no_realtime,
    };
    errln!(
        "drive: {} on {} at {} bps, {} on the {} learner, {} s of learning{}",
        spec.name,
        args.port.display(),
        args.baud,
        label(&policy),
        args.board.name(),
        seconds,
        if args.lockstep { " (lock step)" } else { "" }
    );
    let started = Instant::now();
    let outcome = match drive(&setup, pipe) {
        Ok(o) => o,
        Err(e) => {
            taps.close("drive");
            return Err(match e.downcast::<BadBus>() {
                Ok(bad) => usage(bad.0),
                Err(e) => CliError::Runtime(e),
            });
        }
    };
    let wall = started.elapsed().as_secs_f64();
    taps.close("drive");
    for line in &outcome.servos {
        errln!("drive: {line}");
    }
    for line in &outcome.checkpoint {
        errln!("drive: checkpoint {line}");
    }
    for line in outcome.realtime.lines() {
        errln!("drive: real time: {line}");
    }

    // The files: the learning curve as `pada run --board` writes it, and
    // the run's own report.
    let task = pada_sim::task::TaskSpec::of_robot(profile, "the robot on the serial port", "the robot definition's torque law");
    let summary = BoardSummary::new(&task, &cfg, &profile, std::slice::from_ref(&outcome.trial), wall);
    let mut files = board_files(&summary).map_err(CliError::Runtime)?;
    let drive_summary = DriveSummary { board: &summary, realtime: &outcome.realtime };
    files[0].1 = (serde_json::to_string_pretty(&drive_summary).map_err(|e| CliError::Runtime(e.into()))? + "\n").into_bytes();
    let report = serde_json::to_string_pretty(&outcome).map_err(|e| CliError::Runtime(e.into()))?;
    files.push(("drive.json".to_string(), (report.clone() + "\n").into_bytes()));
    out.write_all(&files).map_err(CliError::Runtime)?;

    let c = &outcome.clock;
    let t = &outcome.telemetry;
    if args.json {
        outln!("{report}")?;
    } else {
        outln!(
            "{}: {} episodes ({} learning), {:.0} s of learning; end performance {:.1}",
            spec.name,
            outcome.trial.episodes.len(),
            outcome.trial.result.learning_episodes,
            outcome.trial.result.learning_steps as f64 * spec.period_s(),
            outcome.trial.result.end_performance
        )?;
        outln!(
            "  period {} ms: {} periods, jitter p50 {} µs, p99 {} µs, max {} µs; work p99 {} µs; {} overruns, {} ticks skipped",
            spec.period_us as f64 / 1000.0,
            c.periods,
            c.jitter_us.p50,
            c.jitter_us.p99,
            c.jitter_us.max,
            c.work_us.p99,
            c.overruns,
            c.skipped_ticks
        )?;
        outln!("  real time: {} (drive.json says why)", outcome.realtime.summary())?;
        outln!(
            "  bus: {:.0} bytes a period ({} from the packets: {:.2} ms on the wire, {:.1} % of the period), {} timeouts, {} damaged answers; telemetry: {} frames, {} lost, {} dropped",
            outcome.bus.bytes_per_period,
            outcome.bus.predicted_bytes_per_period,
            outcome.bus.wire_ms_per_period,
            outcome.bus.wire_ms_per_period * 100.0 / (spec.period_us as f64 / 1000.0),
            outcome.bus.timeouts,
            outcome.bus.checksum_errors,
            t.link.frames,
            t.link.bad_frames() as u64 + t.link.frames_missed,
            t.dropped
        )?;
        outln!("wrote {}", out.path().display())?;
    }
    match outcome.ended {
        Ended::Done => Ok(()),
        Ended::Interrupted => {
            errln!("drive: interrupted: torque off, checkpoint saved, telemetry written");
            Ok(())
        }
        Ended::Fault(why) => Err(usage(format!("fault: {why}; torque is off on every servo, the checkpoint and the log are saved"))),
        Ended::PortGone(why) => Err(usage(format!(
            "the port {} went away ({why}): nothing reaches the servos now; {}; the checkpoint and the log are saved",
            args.port.display(),
            stop_line(&setup)
        ))),
    }
}

/// What stops the servos when the PC cannot reach them: only the X
/// series has a bus watchdog; Protocol 1.0 and Feetech servos keep their
/// last command.
fn stop_line(setup: &DriveSetup) -> String {
    use pada_core::servo::ServoProtocol;
    let has = |p: ServoProtocol| setup.robot.spec.joints.iter().any(|j| j.servo.protocol == p);
    let watchdog = pada_firmware::bus::v2::watchdog_units(setup.robot.spec.period_us) as u32 * 20;
    let blind: Vec<&str> = [(ServoProtocol::V1, "Protocol 1.0 servos"), (ServoProtocol::Feetech, "Feetech servos")]
        .into_iter()
        .filter(|(p, _)| has(*p))
        .map(|(_, name)| name)
        .collect();
    let blind = blind.join(" and the ");
    match (has(ServoProtocol::V2), blind.is_empty()) {
        (true, true) => format!("the X-series servos stop by their Bus Watchdog within {watchdog} ms of the last instruction"),
        (false, _) => format!("{blind} have no bus watchdog: they keep their last command until their power is cut — cut it now"),
        (true, false) => format!("the X-series servos stop by their Bus Watchdog within {watchdog} ms; the {blind} keep their last command until their power is cut"),
    }
}
