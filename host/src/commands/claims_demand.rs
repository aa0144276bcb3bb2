//! `pada claims --robot FILE --board B` (or `--task leo`): will the robot's
//! learning fit the board's table? One host trial (cached) measures the
//! features a trial writes over its learning time
//! ([`crate::board::demand`]); the answer is the board's capacity, when it
//! would be nine tenths full, and a warning with the fixes where it fills.
//! `cargo xtask firmware --robot R --board B` runs this before it builds.

use super::claims::ClaimsArgs;
use crate::board::demand::{demand, has_claim_table, Forecast};
use crate::console::outln;
use crate::error::{usage, CliError};
use crate::experiment::algo::{policy_kind, Algo};
use crate::progress::steps_bar;
use pada_core::profile::Board;
use serde::Serialize;

/// What `--json` prints.
#[derive(Serialize)]
struct Answer {
    robot: String,
    board: String,
    /// `None`: the board's table is exact (its size is the robot's, and a
    /// robot that does not fit fails the build).
    forecast: Option<Forecast>,
    /// (learning time [s], features written) of the host trial.
    curve: Vec<(f64, u32)>,
    lines: Vec<String>,
}

/// Runs the check.
pub fn run(args: ClaimsArgs) -> Result<(), CliError> {
    let board = args.board.ok_or_else(|| usage("--robot and --task need --board: the board whose table to check"))?;
    let sim = match (&args.robot, args.task) {
        (Some(path), _) => {
            let file = pada_robot_file::load(path).map_err(|e| usage(e.to_string()))?;
            crate::robots::from_file(&file).map_err(|e| usage(e.to_string()))?
        }
        (None, Some(task)) => {
            let robot = crate::board::robot_of_task(task).map_err(usage)?;
            crate::robots::sim_robot(robot).map_err(|e| usage(e.to_string()))?
        }
        (None, None) => unreachable!("claims::run dispatches here only with --robot or --task"),
    };
    let profile = board.profile(sim.robot).map_err(|e| usage(e.to_string()))?;
    let name = sim.robot.name.to_string();
    if profile.layout == pada_core::tile_coding::Layout::Exact || !has_claim_table(&sim) {
        let line = format!(
            "{name} on {}: an exact table of {} weights ({} bytes), fixed by its tiles: it fits, or the build fails",
            board.name(),
            profile.weights().unwrap_or(0),
            profile.table_bytes().unwrap_or(0)
        );
        return print(&args, Answer { robot: name, board: board.name().into(), forecast: None, curve: vec![], lines: vec![line] });
    }
    let algo = args.algo.unwrap_or(Algo::Pada);
    let policy = policy_kind(algo, None, args.delta)
        .map_err(|e| usage(e.to_string()))?;
    let spec = sim.task_spec(Board::Host.profile(sim.robot).map_err(|e| usage(e.to_string()))?).map_err(|e| usage(e.to_string()))?;
    let seconds = args.seconds.unwrap_or(spec.default_seconds);
    if !(seconds.is_finite() && seconds > 0.0) {
        return Err(usage(format!("--seconds {seconds} is out of range: valid is a learning time > 0 s")));
    }
    let cfg = crate::experiment::RunConfig { policy, switch_at_s: None, mtbf_budget_s: None, seconds, trials: 1, seed: args.seed };
    let bar = steps_bar(
        cfg.expected_steps(spec.control_period_s, spec.episode_steps, spec.test_interval),
        &format!("{name}: the table's demand (a host trial)"),
    );
    let d = demand(&sim, policy, seconds, args.seed, &|n| bar.inc(n)).map_err(|e| usage(format!("{e:#}")))?;
    bar.finish_and_clear();
    let forecast = Forecast::of(&d, &profile);
    let lines = forecast.as_ref().map(|f| f.lines(&d)).unwrap_or_default();
    print(&args, Answer { robot: name, board: board.name().into(), forecast, curve: d.curve, lines })
}

fn print(args: &ClaimsArgs, answer: Answer) -> Result<(), CliError> {
    if args.json {
        let json = serde_json::to_string_pretty(&answer).map_err(|e| usage(e.to_string()))?;
        outln!("{json}")?;
    } else {
        for line in &answer.lines {
            outln!("{line}")?;
        }
    }
    Ok(())
}
