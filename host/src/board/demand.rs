//! The table's demand, known before flashing: how many slots a trial of a
//! robot writes over its learning time, against what a board's claim
//! table holds, and when it would be nine tenths full.
//!
//! The demand is measured by one host trial on the host's claim table
//! (2^22 slots with 32-bit tags: nothing is refused or replaced there, so
//! the curve is what learning writes, not what a board kept), with the
//! policy, learning time and seed that the board will run. It is kept in a
//! cache file named by everything it depends on (the robot's name and
//! definition hash, the policy, the learning time, the seed), so that
//! `pada run --board`, `pada claims --robot` and `cargo xtask firmware`
//! measure it once between them.

use crate::experiment::algo::label;
use crate::experiment::{run_trials, RunConfig};
use crate::robots::{Body, SimRobot};
use anyhow::Context;
use pada_core::policy::PolicyKind;
use pada_core::profile::{Board, LearnerProfile};
use pada_core::tile_coding::Layout;
use pada_sim::leo::rl::LeoTask;
use pada_sim::urdf::UrdfTask;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// What a trial of a robot writes into its claim table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Demand {
    /// The robot.
    pub robot: String,
    /// Its definition hash.
    pub definition: u32,
    /// The policy, as `pada run` labels it.
    pub policy: String,
    /// The trial's learning time [s].
    pub learning_s: f64,
    /// The run's master seed (the trial is trial 0 of it).
    pub seed: u64,
    /// (learning time [s], distinct features written) at each test run.
    pub curve: Vec<(f64, u32)>,
}

impl Demand {
    /// Features written by the end of the learning time.
    pub fn at_end(&self) -> u32 {
        self.curve.last().map_or(0, |p| p.1)
    }

    /// The learning time at which `slots` features had been written,
    /// interpolated between test runs; `None` if the trial never wrote
    /// that many.
    pub fn time_of(&self, slots: f64) -> Option<f64> {
        let mut before = (0.0, 0.0);
        for &(t, n) in &self.curve {
            let n = n as f64;
            if n >= slots {
                let (t0, n0) = before;
                return Some(if n > n0 { t0 + (t - t0) * (slots - n0) / (n - n0) } else { t });
            }
            before = (t, n);
        }
        None
    }
}

/// Where the demand of a trial is cached: `$PADA_CACHE`, else
/// `$XDG_CACHE_HOME/pada`, else `~/.cache/pada`, then `demand/`.
fn cache_dir() -> Option<PathBuf> {
    let base = std::env::var_os("PADA_CACHE")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("pada")))
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache").join("pada")))?;
    Some(base.join("demand"))
}

/// The cache file of one measurement.
fn cache_file(sim: &SimRobot, policy: &PolicyKind, seconds: f64, seed: u64) -> Option<PathBuf> {
    let policy: String = label(policy).chars().map(|c| if c.is_ascii_alphanumeric() || c == '.' { c } else { '_' }).collect();
    let name = format!("{}-{:08x}-{policy}-{seconds}s-seed{seed}.json", sim.robot.name, sim.robot.definition_hash());
    Some(cache_dir()?.join(name))
}

/// Whether a robot's boards keep a claim table (the demand means nothing
/// for an exact table: its size is fixed by the tiles, and a table that
/// fits no board fails the build).
pub fn has_claim_table(sim: &SimRobot) -> bool {
    Board::Host.profile(sim.robot).is_ok_and(|p| p.layout == Layout::Claimed)
}

/// The demand of trial 0 of a run of `sim` with `policy`, `seconds` and
/// master `seed`: read from the cache, or measured by a host trial and
/// cached (a cache that cannot be written is no error: the next command
/// measures again). `progress` is told the environment steps.
pub fn demand(
    sim: &SimRobot,
    policy: PolicyKind,
    seconds: f64,
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<Demand> {
    let file = cache_file(sim, &policy, seconds, seed);
    if let Some(d) = file.as_ref().and_then(|f| std::fs::read(f).ok()).and_then(|b| serde_json::from_slice::<Demand>(&b).ok()) {
        if d.robot == sim.robot.name && d.definition == sim.robot.definition_hash() {
            return Ok(d);
        }
    }
    let d = measure(sim, policy, seconds, seed, progress)?;
    if let Some(f) = file {
        let _ = f.parent().map(std::fs::create_dir_all);
        let _ = serde_json::to_vec_pretty(&d).map(|b| std::fs::write(&f, b));
    }
    Ok(d)
}

/// One host trial of `sim` on the host's claim table, its claimed slots
/// at every test run.
fn measure(sim: &SimRobot, policy: PolicyKind, seconds: f64, seed: u64, progress: &(dyn Fn(u64) + Sync)) -> anyhow::Result<Demand> {
    let cfg = RunConfig { policy, switch_at_s: None, mtbf_budget_s: None, seconds, trials: 1, seed };
    let host = Board::Host.profile(sim.robot).map_err(|e| anyhow::anyhow!("{e}"))?;
    let trials = match &sim.body {
        Body::Leo => run_trials(&LeoTask::default(), &cfg, progress),
        Body::Urdf(model) => run_trials(&UrdfTask::of_model(model, host), &cfg, progress),
        Body::Pendulum => anyhow::bail!("the pendulum's table is exact: it has no claim table to fill"),
    }
    .context("measuring the table's demand with a host trial")?;
    let curve = trials
        .first()
        .map(|t| t.curve.iter().filter_map(|p| Some((p.learning_time_s, p.claimed_slots?))).collect())
        .unwrap_or_default();
    Ok(Demand {
        robot: sim.robot.name.to_string(),
        definition: sim.robot.definition_hash(),
        policy: label(&policy),
        learning_s: seconds,
        seed,
        curve,
    })
}

/// A board's claim table against a demand.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Forecast {
    /// The board.
    pub board: String,
    /// Its claim table's slots.
    pub slots: u32,
    /// What it does when full (`refuse`, `replace`, `collide`).
    pub when_full: String,
    /// Features the trial wrote by the end of its learning time.
    pub demand_at_end: u32,
    /// The learning time [s].
    pub learning_s: f64,
    /// When the table would be nine tenths full [s]; `None`: never.
    pub nine_tenths_at_s: Option<f64>,
}

impl Forecast {
    /// The forecast of `profile`'s table against `demand`; `None` for an
    /// exact table (its size is the robot's).
    pub fn of(demand: &Demand, profile: &LearnerProfile) -> Option<Forecast> {
        let when_full = match profile.layout {
            Layout::Exact => return None,
            // Past its entries, a hashed table's features share them.
            Layout::Hashed => "collide".to_string(),
            Layout::Claimed => profile.when_full.name().to_string(),
        };
        let slots = profile.weights()? as u32;
        Some(Forecast {
            board: profile.board.name().to_string(),
            slots,
            when_full,
            demand_at_end: demand.at_end(),
            learning_s: demand.learning_s,
            nine_tenths_at_s: demand.time_of(0.9 * slots as f64),
        })
    }

    /// Whether the table passes nine tenths full before learning ends.
    pub fn fills(&self) -> bool {
        self.nine_tenths_at_s.is_some()
    }

    /// The lines a person reads before flashing: the demand, the
    /// capacity, when it is nine tenths full; and, where it fills, one
    /// warning line naming the fixes.
    pub fn lines(&self, demand: &Demand) -> Vec<String> {
        let pct = 100.0 * self.demand_at_end as f64 / self.slots as f64;
        let mut lines = vec![format!(
            "table demand: a host trial of {} ({}, seed {}) writes {} features in {:.0} s of learning; {}'s table has {} {} ({pct:.0} % of them)",
            demand.robot,
            demand.policy,
            demand.seed,
            self.demand_at_end,
            self.learning_s,
            self.board,
            self.slots,
            if self.when_full == "collide" { "hashed entries" } else { "claim slots" }
        )];
        match self.nine_tenths_at_s {
            Some(t) => {
                lines.push(format!("  nine tenths full at {t:.0} s of learning"));
                lines.push(format!(
                    "warning: {}'s table fills at {t:.0} s, before learning ends at {:.0} s; then {} (docs/board.md, \"A full table\"). \
                     To fit: coarser tiles, fewer observed signals, fewer levels, or the f429-sdram",
                    self.board,
                    self.learning_s,
                    match self.when_full.as_str() {
                        "collide" => "new features share weights with others",
                        "replace" => "new features replace the least-learned",
                        _ => "new features are refused and do not learn",
                    }
                ));
            }
            None => lines.push(format!("  never nine tenths full: at most {pct:.0} % by the end")),
        }
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demand(curve: Vec<(f64, u32)>) -> Demand {
        Demand { robot: "arm3".into(), definition: 1, policy: "pada".into(), learning_s: 1200.0, seed: 1, curve }
    }

    #[test]
    fn nine_tenths_is_interpolated_between_test_runs_and_never_past_the_curve() {
        let d = demand(vec![(60.0, 10_000), (120.0, 30_000), (180.0, 40_000)]);
        // 0.9 * 32768 = 29491.2: between 60 s and 120 s.
        let t = d.time_of(29_491.2).unwrap();
        assert!((t - (60.0 + 60.0 * 19_491.2 / 20_000.0)).abs() < 1e-9, "{t}");
        assert_eq!(d.time_of(40_001.0), None);
        assert_eq!(d.time_of(5_000.0), Some(30.0), "from 0 at 0 s");
        assert_eq!(d.at_end(), 40_000);
    }

    #[test]
    fn a_table_that_fills_warns_in_one_line_with_the_fixes_and_one_that_does_not_says_so() {
        let hashed = Board::F405.profile(&pada_core::robot::leo::SPEC).unwrap();
        let f = Forecast::of(&demand(vec![(600.0, 40_000), (1200.0, 80_000)]), &hashed).unwrap();
        assert_eq!((f.slots, f.when_full.as_str()), (1 << 15, "collide"));
        assert!(f.lines(&demand(vec![]))[0].contains("32768 hashed entries"));
        let profile = hashed.with_hashed_table(Layout::Claimed, 15, hashed.format, 2);
        assert_eq!(profile.weights(), Some(1 << 15));
        let fills = Forecast::of(&demand(vec![(600.0, 20_000), (1200.0, 40_000)]), &profile).unwrap();
        assert!(fills.fills());
        let lines = fills.lines(&demand(vec![]));
        let warnings: Vec<&String> = lines.iter().filter(|l| l.starts_with("warning:")).collect();
        assert_eq!(warnings.len(), 1, "{lines:?}");
        for fix in ["coarser tiles", "fewer observed signals", "fewer levels", "f429-sdram"] {
            assert!(warnings[0].contains(fix), "{fix}: {}", warnings[0]);
        }
        assert!(lines[0].contains("32768 claim slots"), "{}", lines[0]);
        let fits = Forecast::of(&demand(vec![(600.0, 2_000), (1200.0, 4_000)]), &profile).unwrap();
        assert!(!fits.fills());
        assert!(fits.lines(&demand(vec![])).iter().all(|l| !l.starts_with("warning")));
        // An exact table has no forecast.
        let exact = Board::F405.profile(&pada_core::robot::pendulum::SPEC_33HZ).unwrap();
        assert!(Forecast::of(&demand(vec![]), &exact).is_none());
    }
}
