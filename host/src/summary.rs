//! The summary of a run (`summary.json`) and the per-trial CSV files.

use crate::experiment::algo::{algo_of, parameter_of, Algo};
use crate::experiment::{RunConfig, TrialResult, TILINGS, TRACE};
use crate::stats::Estimate;
use crate::experiment::task::TaskSpec;
use pada_core::agent::WeightInit;
use pada_core::fatigue::PAPER_WINDOW_STEPS;
use serde::Serialize;

/// Everything that defines a run besides the algorithm's name.
#[derive(Debug, Clone, Serialize)]
pub struct Parameters {
    /// Low-pass α (Eq. 8), for the low-pass algorithms.
    pub alpha: Option<f32>,
    /// Δ relative to the action range (Eq. 9), for the integrators, PADA
    /// and ε-PADA (with a wear governor: its floor, where it starts).
    pub delta: Option<f32>,
    /// OU's mean reversion θ per step.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub theta: Option<f32>,
    /// OU's or pink noise's σ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sigma: Option<f32>,
    /// The action-change penalty's weight.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weight: Option<f32>,
    /// The wear governor's MTBF budget \[s\], if one ran.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mtbf_budget_s: Option<f32>,
    /// Learning time of the switch back to SARSA(λ) \[s\], if any.
    pub switch_at_s: Option<f64>,
    /// Learning time per trial \[s\].
    pub seconds: f64,
    /// Master seed.
    pub seed: u64,
    /// Control period \[s\].
    pub control_period_s: f64,
    /// Episode length \[s\].
    pub episode_s: f64,
    /// Learning episodes between greedy test runs.
    pub test_interval_episodes: u32,
    /// SARSA learning rate α.
    pub learning_rate: f32,
    /// Discount γ per step.
    pub gamma: f32,
    /// Trace decay λ per step.
    pub lambda: f32,
    /// Exploration rate ε.
    pub epsilon: f32,
    /// Initial weights.
    pub weight_init: String,
    /// Tilings.
    pub tilings: usize,
    /// Trace capacity \[entries\].
    pub trace_capacity: usize,
    /// Learning actions counted for the MTBF.
    pub mtbf_window_actions: u32,
    /// How gearbox torques are obtained.
    pub gearbox_torque: String,
}

/// The summary of one run of one algorithm.
#[derive(Debug, Clone, Serialize)]
pub struct RunSummary {
    /// Task name.
    pub task: String,
    /// Algorithm name.
    pub algo: Algo,
    /// Parameters.
    pub parameters: Parameters,
    /// Number of trials.
    pub trials: u32,
    /// End performance over trials (Section VI).
    pub end_performance: Estimate,
    /// Rise time over trials \[s\] (Section VI).
    pub rise_time_s: Estimate,
    /// Predicted MTBF from the first 1200 actions \[s\] (Eqs. 3–7), the
    /// paper's definition: gearbox torques from the commanded action.
    pub mtbf_s: Estimate,
    /// Backlash re-engagements within those actions (the paper's).
    pub window_reengagements: Estimate,
    /// Predicted MTBF over all learning actions \[s\] (the paper's torques).
    pub run_mtbf_s: Estimate,
    /// Predicted MTBF from the first 1200 actions \[s\] from the simulated
    /// gear torques.
    pub physical_mtbf_s: Estimate,
    /// Re-engagements of the simulated gear torques within those actions.
    pub physical_window_reengagements: Estimate,
    /// Distance walked in the last 10% of the test runs \[m\] (walking
    /// tasks only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_walked_m: Option<Estimate>,
    /// Mean speed of the last 10% of the test runs \[m/s\] (walking tasks
    /// only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_speed_m_s: Option<Estimate>,
    /// What the wear governor did, over the trials (with `--mtbf-budget`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub governor: Option<GovernorSummary>,
    /// Each counted joint's gearbox and its MTBFs over the trials (a robot
    /// with more than one counted joint; the robot's MTBF is the weakest's).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gearboxes: Vec<GearboxWear>,
    /// Falls (absorbing ends) in learning episodes, per trial.
    pub learning_falls: Estimate,
    /// Falls in greedy test runs, per trial.
    pub test_falls: Estimate,
    /// Wall-clock time of the run \[s\]; absent where it is not measured
    /// (a configuration of `pada paper`, whose trials share one pool), so
    /// that such a summary depends only on the seed.
    #[serde(skip_serializing_if = "not_measured")]
    pub wall_s: f64,
    /// Environment steps (learning and test runs, all trials).
    pub env_steps: u64,
    /// Environment steps per wall-clock second, all threads together
    /// (absent with `wall_s`).
    #[serde(skip_serializing_if = "not_measured")]
    pub env_steps_per_s: f64,
    /// Worker threads (0 and absent where `wall_s` is not measured).
    #[serde(skip_serializing_if = "no_threads")]
    pub threads: usize,
    /// Per-trial results.
    pub per_trial: Vec<TrialResult>,
}

/// What the wear governor did over a run's trials.
#[derive(Debug, Clone, Serialize)]
pub struct GovernorSummary {
    /// The budget \[s\].
    pub budget_s: f32,
    /// The share of trials whose MTBF over the first 1200 learning actions
    /// (the paper's, `mtbf_s`) is at least the budget.
    pub held_fraction: f64,
    /// The same for the physical MTBF, which the governor does not see.
    pub physical_held_fraction: f64,
    /// The mean Δ or α over the learning actions, per trial.
    pub mean_parameter: Estimate,
    /// The Δ or α at the end, per trial.
    pub final_parameter: Estimate,
    /// The share of learning actions at the floor, per trial.
    pub floor_fraction: Estimate,
    /// Moves per trial.
    pub moves: Estimate,
}

impl GovernorSummary {
    /// The summary of the trials' governor records (`None` if a trial had
    /// none).
    pub fn of(results: &[TrialResult]) -> Option<GovernorSummary> {
        let g: Vec<&crate::experiment::governed::GovernorTrial> =
            results.iter().map(|r| r.governor.as_ref()).collect::<Option<_>>()?;
        let first = g.first()?;
        let n = g.len() as f64;
        let col = |f: fn(&crate::experiment::governed::GovernorTrial) -> f64| g.iter().map(|t| f(t)).collect::<Vec<_>>();
        Some(GovernorSummary {
            budget_s: first.budget_s,
            held_fraction: g.iter().filter(|t| t.held).count() as f64 / n,
            physical_held_fraction: g.iter().filter(|t| t.physical_held).count() as f64 / n,
            mean_parameter: Estimate::of(&col(|t| t.mean_parameter)),
            final_parameter: Estimate::of(&col(|t| t.final_parameter as f64)),
            floor_fraction: Estimate::of(&col(|t| t.floor_fraction)),
            moves: Estimate::of(&col(|t| t.moves as f64)),
        })
    }
}

/// One counted joint's gearbox wear over the trials.
#[derive(Debug, Clone, Serialize)]
pub struct GearboxWear {
    /// The joint's name.
    pub joint: String,
    /// Its servo's gearbox (`pada_core::servo`).
    pub gearbox: String,
    /// Whether the gearbox's geometry is an estimate (not measured).
    pub estimate: bool,
    /// MTBF from the first 1200 actions, the paper's torques \[s\].
    pub mtbf_s: Estimate,
    /// The same from the simulated gear torques \[s\].
    pub physical_mtbf_s: Estimate,
}

impl GearboxWear {
    /// Per joint, when every trial measured every counted joint of a robot
    /// with more than one.
    fn of(spec: &TaskSpec, results: &[TrialResult]) -> Vec<GearboxWear> {
        let Some(robot) = spec.profile.map(|p| p.robot) else { return Vec::new() };
        let dims = spec.motor.dims();
        if dims < 2 || results.is_empty() || results.iter().any(|r| r.joint_mtbf_s.len() != dims || r.physical_joint_mtbf_s.len() != dims) {
            return Vec::new();
        }
        (0..dims)
            .map(|c| {
                let joint = robot.joints.get(robot.counted.start as usize + c);
                let gearbox = joint.and_then(|j| j.servo.gearbox().ok());
                GearboxWear {
                    joint: joint.map_or_else(|| format!("joint {c}"), |j| j.name.to_string()),
                    gearbox: gearbox.map_or("Table I (RX-28)", |g| g.name).to_string(),
                    estimate: gearbox.is_some_and(|g| g.estimate),
                    mtbf_s: Estimate::of(&results.iter().map(|r| r.joint_mtbf_s[c]).collect::<Vec<_>>()),
                    physical_mtbf_s: Estimate::of(&results.iter().map(|r| r.physical_joint_mtbf_s[c]).collect::<Vec<_>>()),
                }
            })
            .collect()
    }
}

impl RunSummary {
    /// Summarises `results` of `cfg` on a task with `spec`.
    pub fn new(
        spec: &TaskSpec,
        cfg: &RunConfig,
        results: &[TrialResult],
        wall_s: f64,
    ) -> RunSummary {
        let algo = algo_of(&cfg.policy);
        let p = parameter_of(&cfg.policy);
        let named = |name: &str| {
            let i = algo.parameter_names().iter().position(|n| *n == name)?;
            Some(cfg.policy.parameters()[i])
        };
        let col = |f: fn(&TrialResult) -> f64| results.iter().map(f).collect::<Vec<_>>();
        let env_steps: u64 = results
            .iter()
            .map(|r| r.learning_steps + r.test_steps)
            .sum();
        let walking = results.iter().all(|r| r.end_walked_m.is_some());
        RunSummary {
            task: spec.name.to_string(),
            algo,
            parameters: Parameters {
                alpha: if algo.takes_alpha() { p } else { None },
                delta: if algo.takes_delta() { p } else { None },
                theta: named("theta"),
                sigma: named("sigma"),
                weight: named("weight"),
                mtbf_budget_s: cfg.mtbf_budget_s,
                switch_at_s: cfg.switch_at_s,
                seconds: cfg.seconds,
                seed: cfg.seed,
                control_period_s: spec.control_period_s,
                episode_s: spec.episode_steps as f64 * spec.control_period_s,
                test_interval_episodes: spec.test_interval,
                learning_rate: spec.params.alpha,
                gamma: spec.params.gamma,
                lambda: spec.params.lambda,
                epsilon: spec.params.epsilon,
                weight_init: match spec.params.init {
                    WeightInit::Constant(c) => format!("constant {c}"),
                    WeightInit::Uniform { min, max } => format!("uniform [{min}, {max}]"),
                },
                tilings: TILINGS,
                trace_capacity: TRACE,
                mtbf_window_actions: PAPER_WINDOW_STEPS,
                gearbox_torque: spec.torque_note.to_string(),
            },
            trials: cfg.trials,
            end_performance: Estimate::of(&col(|r| r.end_performance)),
            rise_time_s: Estimate::of(&col(|r| r.rise_time_s)),
            mtbf_s: Estimate::of(&col(|r| r.mtbf_s)),
            window_reengagements: Estimate::of(&col(|r| r.window_reengagements as f64)),
            run_mtbf_s: Estimate::of(&col(|r| r.run_mtbf_s)),
            physical_mtbf_s: Estimate::of(&col(|r| r.physical_mtbf_s)),
            physical_window_reengagements: Estimate::of(&col(|r| r.physical_window_reengagements as f64)),
            end_walked_m: walking.then(|| Estimate::of(&col(|r| r.end_walked_m.unwrap_or(f64::NAN)))),
            end_speed_m_s: walking.then(|| Estimate::of(&col(|r| r.end_speed_m_s.unwrap_or(f64::NAN)))),
            governor: GovernorSummary::of(results),
            gearboxes: GearboxWear::of(spec, results),
            learning_falls: Estimate::of(&col(|r| r.learning_falls as f64)),
            test_falls: Estimate::of(&col(|r| r.test_falls as f64)),
            wall_s,
            env_steps,
            env_steps_per_s: if wall_s > 0.0 {
                env_steps as f64 / wall_s
            } else {
                f64::NAN
            },
            threads: if wall_s.is_nan() {
                0
            } else {
                rayon::current_num_threads()
            },
            per_trial: results.to_vec(),
        }
    }

    /// The summary as pretty JSON (non-finite numbers become `null`).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

fn not_measured(x: &f64) -> bool {
    x.is_nan()
}

fn no_threads(n: &usize) -> bool {
    *n == 0
}

/// A trial's learning curve as CSV:
/// `test_run,learning_time_s,learning_episodes,return`, and for a walking
/// task (a plant that measures walked distance) also `walked_m,fell,duration_s`,
/// and for a claim table `claimed_slots` (the slots claimed before the test run).
pub fn curve_csv(result: &TrialResult) -> anyhow::Result<Vec<u8>> {
    let walking = result.curve.iter().all(|p| p.walked_m.is_some()) && !result.curve.is_empty();
    let claims = result.curve.iter().all(|p| p.claimed_slots.is_some()) && !result.curve.is_empty();
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header = vec!["test_run", "learning_time_s", "learning_episodes", "return"];
    if walking {
        header.extend(["walked_m", "fell", "duration_s"]);
    }
    if claims {
        header.push("claimed_slots");
    }
    w.write_record(&header)?;
    for (i, p) in result.curve.iter().enumerate() {
        let mut row = vec![
            i.to_string(),
            format!("{}", p.learning_time_s),
            p.learning_episodes.to_string(),
            format!("{}", p.test_return),
        ];
        if walking {
            row.extend([format!("{}", p.walked_m.unwrap_or(f64::NAN)), (p.fell as u8).to_string(), format!("{}", p.duration_s)]);
        }
        if claims {
            row.push(p.claimed_slots.unwrap_or(0).to_string());
        }
        w.write_record(&row)?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

/// One row per trial: `trial,seed,end_performance,rise_time_s,mtbf_s,window_reengagements,learning_steps,test_steps`.
pub fn trials_csv(results: &[TrialResult]) -> anyhow::Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "trial",
        "seed",
        "end_performance",
        "rise_time_s",
        "mtbf_s",
        "window_reengagements",
        "learning_steps",
        "test_steps",
    ])?;
    for r in results {
        w.write_record([
            r.trial.to_string(),
            r.seed.to_string(),
            format!("{}", r.end_performance),
            format!("{}", r.rise_time_s),
            format!("{}", r.mtbf_s),
            r.window_reengagements.to_string(),
            r.learning_steps.to_string(),
            r.test_steps.to_string(),
        ])?;
    }
    w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))
}

/// The files of a run: `summary.json`, `trials.csv` and
/// `trial-NNN.csv` learning curves.
pub fn run_files(summary: &RunSummary) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let mut files = vec![
        (
            "summary.json".to_string(),
            (summary.to_json() + "\n").into_bytes(),
        ),
        ("trials.csv".to_string(), trials_csv(&summary.per_trial)?),
    ];
    for r in &summary.per_trial {
        files.push((format!("trial-{:03}.csv", r.trial), curve_csv(r)?));
    }
    Ok(files)
}

/// The summary of `pada run --board`: everything of [`RunSummary`] (the
/// same keys, flattened), plus the board's learner and what the board
/// itself would report per trial.
#[derive(Debug, Clone, Serialize)]
pub struct BoardSummary {
    /// What `pada run` reports.
    #[serde(flatten)]
    pub run: RunSummary,
    /// The board's learner profile and its memory.
    pub profile: crate::board::ProfileReport,
    /// The predicted MTBF from the board's own torque estimate over the
    /// first learning actions \[s\] (`mtbf_s` is from the simulation's gear
    /// torques, as `pada run` counts them).
    pub board_estimated_mtbf_s: Estimate,
    /// Per trial: the configuration hash, the final weights' checksum, the
    /// board's estimated MTBF and the control periods run.
    pub board_per_trial: Vec<BoardTrialSummary>,
}

/// What one board trial adds to its [`TrialResult`].
#[derive(Debug, Clone, Serialize)]
pub struct BoardTrialSummary {
    /// Trial index.
    pub trial: u32,
    /// The learner's configuration hash.
    pub config_hash: u32,
    /// FNV-1a of the final table's stored bytes.
    pub weights_checksum: u32,
    /// MTBF from the board's torque estimate \[s\].
    pub board_estimated_mtbf_s: f64,
    /// Control periods, with the waits between episodes.
    pub periods: u64,
}

impl BoardSummary {
    /// Summarises board `trials` of `cfg` with `profile` on a task with `spec`.
    pub fn new(
        spec: &TaskSpec,
        cfg: &RunConfig,
        profile: &pada_core::profile::LearnerProfile,
        trials: &[crate::board::BoardTrial],
        wall_s: f64,
    ) -> BoardSummary {
        let results = crate::board::results(trials);
        let weights = trials.first().map_or(profile.weights().unwrap_or(0), |t| t.weights);
        BoardSummary {
            run: RunSummary::new(spec, cfg, &results, wall_s),
            profile: crate::board::ProfileReport::new(profile, weights),
            board_estimated_mtbf_s: Estimate::of(&trials.iter().map(|t| t.board_estimated_mtbf_s).collect::<Vec<_>>()),
            board_per_trial: trials
                .iter()
                .map(|t| BoardTrialSummary {
                    trial: t.result.trial,
                    config_hash: t.config_hash,
                    weights_checksum: t.weights_checksum,
                    board_estimated_mtbf_s: t.board_estimated_mtbf_s,
                    periods: t.periods,
                })
                .collect(),
        }
    }

    /// The summary as pretty JSON (non-finite numbers become `null`).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

/// The files of a board run: `run_files`' with the board's summary.
pub fn board_files(summary: &BoardSummary) -> anyhow::Result<Vec<(String, Vec<u8>)>> {
    let mut files = run_files(&summary.run)?;
    files[0].1 = (summary.to_json() + "\n").into_bytes();
    Ok(files)
}
