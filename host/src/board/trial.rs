//! One trial of a board's learner on the host: the firmware's controller
//! and a [`Rig`] in lock step, one control period at a time, with the run
//! protocol of `pada sil` ([`super::protocol`]: a greedy test run before
//! learning, the controller's own test run after every tenth learning
//! episode, a final test run once the learning time is spent).
//!
//! Per period `k` (at `t = k·T`, where the firmware's control ticks lie,
//! `pada_firmware`'s control task):
//!
//! 1. every servo's Present Position … Temperature and the sensors are read
//!    from the rig at `t` (the state at the period boundary, see
//!    [`crate::rig::leo`]);
//! 2. the controller runs its period, as on the chip;
//! 3. its commands (Moving Speeds: ratios of the rig's supply) drive the rig from
//!    `t`; an episode's end or start tells the rig's operator at `t`;
//! 4. the rig advances to `t + T`; if the period applied a learning action,
//!    the gearbox torques of the learned joints over it go to the MTBF
//!    count, as `pada run` counts them.
//!
//! This is what the SIL run does on the emulated bus: its reads and writes
//! of period `k` fall within `[k·T, (k+1)·T)`, the operator hears of an
//! episode's end in the same period, and LEO's rig advances in whole
//! periods on the same boundaries; so for LEO, `pada sil` and this trial
//! with the same seed give the same episodes, bit for bit (`pada sil`
//! checks it). The walked distance is the rig's measure.
//!
//! Differences to `pada run` that are the board's: the table (the board's
//! profile), the sensors (counts, differenced rates), the seeds (the
//! controller's PCG32 from the trial's seed, not the runner's PCG64), the
//! held joints and resets, and the switch back to SARSA(λ) at the first
//! period at or after `--switch-at` rather than at the exact step.

use super::fault_line::{fault_explained, Faulted};
use super::protocol::{EpisodeOutcome, RunProtocol};
use crate::experiment::governed::GovernorStats;
use crate::experiment::measured::robot_mtbf_s;
use crate::experiment::RunConfig;
use crate::experiment::TrialResult;
use crate::rig::Rig;
use crate::seed::trial_seed;
use anyhow::{anyhow, bail};
use pada_core::fatigue::{FatigueCounter, PAPER_WINDOW_STEPS};
use pada_core::fixed::Q16;
use pada_core::policy::PolicyKind;
use pada_core::episodes::is_learning_action;
use crate::robots::{DynRules, SimRobot};
use pada_core::claim_table::{ClaimTable, Tags16, Tags32};
use pada_core::profile::{LearnerProfile, TILINGS};
use pada_core::robot::RobotRules;
use pada_core::servo::ServoProtocol;
use pada_core::tile_coding::Layout;
use pada_core::weights::{Half, WeightFormat, WeightStore};
use pada_core::wire::{Episode, StepKind, ToChip};
use pada_firmware::control::{Controller, PeriodOutput, Readings};
use pada_firmware::io::CycleCounter;
use serde::Serialize;

/// The most joints whose fatigue a trial counts (LEO's hips and knees).
const COUNTED: usize = 4;

/// One board trial.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoardTrial {
    /// What `pada run` reports per trial.
    pub result: TrialResult,
    /// The learner's configuration hash (as the board's `Hello` says).
    pub config_hash: u32,
    /// Weights in the table.
    pub weights: usize,
    /// The final weights' checksum (FNV-1a of the stored bytes).
    pub weights_checksum: u32,
    /// The predicted MTBF from the board's own torque estimate (the RX-28
    /// model at the measured rate for LEO, the linear voltage law for the
    /// pendulum) over the same first learning actions \[s\]. (The result's
    /// `mtbf_s` is the paper's, from the commanded voltages;
    /// `physical_mtbf_s` is from the simulation's gear torques.)
    pub board_estimated_mtbf_s: f64,
    /// Control periods run, with the waits between episodes.
    pub periods: u64,
    /// Every episode as the board reports it (for `pada sil`'s
    /// comparison; not in `summary.json`).
    #[serde(skip)]
    pub episodes: Vec<Episode>,
}

/// The cycle counter of a controller off the chip: none.
struct NoCycles;

impl CycleCounter for NoCycles {
    fn cycles(&self) -> u32 {
        0
    }
}

/// Weights a table of `profile` needs with `policy`: the profile's fixed
/// size, or the exact layout's size for the policy (the host's pendulum).
pub fn table_len(profile: &LearnerProfile, policy: PolicyKind) -> anyhow::Result<usize> {
    if let Some(n) = profile.weights() {
        return Ok(n);
    }
    profile.robot.exact_table_len::<TILINGS>(policy).map_err(|e| anyhow!("{e}"))
}

/// Where a board trial's learner starts.
#[derive(Debug, Clone, Copy, Default)]
pub enum BoardStart<'a> {
    /// A fresh learner from the trial's seed (`SetPolicy`).
    #[default]
    Fresh,
    /// The fresh learner with these table entries written over its table
    /// before the first Start (`Controller::import_entries`: weights
    /// exported from the host, [`super::export`]).
    Entries(&'a [u8]),
    /// The learner of this checkpoint image (a slot's, as the host keeps
    /// it for a board), loaded as the firmware loads one at boot; no
    /// `SetPolicy` then, only the Start.
    Checkpoint(&'a [u8]),
}

/// Trial `trial` of `cfg` with `profile`'s learner against its robot's
/// rig ([`SimRobot::board_rig`]).
pub fn run_board_trial(
    profile: LearnerProfile,
    robot: &SimRobot,
    cfg: &RunConfig,
    trial: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<BoardTrial> {
    run_board_trial_from(profile, robot, cfg, trial, BoardStart::Fresh, progress)
}

/// [`run_board_trial`] with the learner starting as `start` says.
pub fn run_board_trial_from(
    profile: LearnerProfile,
    robot: &SimRobot,
    cfg: &RunConfig,
    trial: u32,
    start: BoardStart<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<BoardTrial> {
    let mut rig = robot.board_rig()?;
    run_board_trial_on_from(profile, robot, cfg, trial, rig.as_mut(), start, progress)
}

/// `$body` applied to `n` 16-bit weights shifted by `$shift`: the shift
/// is part of the weights' type, so each shift a robot may choose is one
/// instance (`RobotSpec::half_shift`, 8 to 15: Q-values within ±128 to
/// ±16384).
macro_rules! with_half_weights {
    ($shift:expr, $n:expr, |$w:ident| $body:expr) => {{
        let n = $n;
        macro_rules! one {
            ($s:literal) => {{
                let $w = Half::<_, $s>::new(vec![0i16; n].into_boxed_slice());
                $body
            }};
        }
        match $shift {
            8 => one!(8),
            9 => one!(9),
            10 => one!(10),
            11 => one!(11),
            12 => one!(12),
            13 => one!(13),
            14 => one!(14),
            15 => one!(15),
            s => bail!("16-bit weights shifted by {s}: the board runner takes shifts 8 to 15"),
        }
    }};
}

/// What runs on a board's table once its type is known: the profile
/// chooses the table's layout, weight format and tags at run time, and
/// each combination is a type of its own ([`with_table`]).
pub trait TableVisitor {
    /// What the visit gives.
    type Output;
    /// Runs with `table`.
    fn visit<W: WeightStore>(self, table: W) -> anyhow::Result<Self::Output>;
}

/// Builds `profile`'s table of `n` weights (on the host a table split over
/// CCM and SRAM is one slice: `Split` addresses the same weights in the
/// same order) and hands it to `v`.
pub fn with_table<V: TableVisitor>(profile: &LearnerProfile, n: usize, v: V) -> anyhow::Result<V::Output> {
    match (profile.layout, profile.format) {
        (Layout::Claimed, WeightFormat::Q16) => claim_on(profile, vec![Q16::ZERO; n].into_boxed_slice(), n, v),
        (Layout::Claimed, WeightFormat::Half { shift }) => with_half_weights!(shift, n, |w| claim_on(profile, w, n, v)),
        (_, WeightFormat::Q16) => v.visit(vec![Q16::ZERO; n].into_boxed_slice()),
        (_, WeightFormat::Half { shift }) => with_half_weights!(shift, n, |w| v.visit(w)),
    }
}

/// A claim table over `weights` with the profile's tags (16 or 32 bits) of
/// `n` slots, handed to `v`.
fn claim_on<W: WeightStore, V: TableVisitor>(profile: &LearnerProfile, weights: W, n: usize, v: V) -> anyhow::Result<V::Output> {
    let err = |e: pada_core::claim_table::ClaimTableError| anyhow!("{e}");
    match profile.tag_bytes {
        2 => v.visit(ClaimTable::new(weights, Tags16(vec![0u16; n].into_boxed_slice())).map_err(err)?.on_full(profile.when_full)),
        _ => v.visit(ClaimTable::new(weights, Tags32(vec![0u32; n].into_boxed_slice())).map_err(err)?.on_full(profile.when_full)),
    }
}

/// Trial `trial` of `cfg` with `profile`'s learner against `rig`.
pub fn run_board_trial_on(
    profile: LearnerProfile,
    robot: &SimRobot,
    cfg: &RunConfig,
    trial: u32,
    rig: &mut dyn Rig,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<BoardTrial> {
    run_board_trial_on_from(profile, robot, cfg, trial, rig, BoardStart::Fresh, progress)
}

/// [`run_board_trial_on`] with the learner starting as `start` says.
pub fn run_board_trial_on_from(
    profile: LearnerProfile,
    robot: &SimRobot,
    cfg: &RunConfig,
    trial: u32,
    rig: &mut dyn Rig,
    start: BoardStart<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<BoardTrial> {
    let n = table_len(&profile, cfg.policy)?;
    let seed = trial_seed(cfg.seed, trial);
    anyhow::ensure!(robot.robot == profile.robot, "the profile is {}'s, the robot {}", profile.robot.name, robot.robot.name);
    let rules = robot.rules();
    struct Visit<'a> {
        profile: LearnerProfile,
        rules: DynRules,
        rig: &'a mut dyn Rig,
        cfg: &'a RunConfig,
        trial: u32,
        seed: u64,
        start: BoardStart<'a>,
        progress: &'a (dyn Fn(u64) + Sync),
    }
    impl TableVisitor for Visit<'_> {
        type Output = BoardTrial;
        fn visit<W: WeightStore>(self, table: W) -> anyhow::Result<BoardTrial> {
            run(self.profile, table, self.rules, self.rig, self.cfg, self.trial, self.seed, self.start, self.progress)
        }
    }
    with_table(&profile, n, Visit { profile, rules, rig, cfg, trial, seed, start, progress })
}

/// Carries out a host command, as the board would; a refusal is an error.
pub fn command<W: WeightStore, R: RobotRules>(ctl: &mut Controller<W, R>, cmd: ToChip) -> anyhow::Result<()> {
    ctl.command(&cmd).0.map_err(|e| anyhow!("{cmd:?} refused: {e:?}"))
}

#[allow(clippy::too_many_arguments)]
fn run<R: RobotRules, W: WeightStore>(
    profile: LearnerProfile,
    table: W,
    rules: R,
    rig: &mut dyn Rig,
    cfg: &RunConfig,
    trial: u32,
    seed: u64,
    start: BoardStart<'_>,
    progress: &(dyn Fn(u64) + Sync),
) -> anyhow::Result<BoardTrial> {
    let spec = rules.spec();
    let period_us = spec.period_us as u64;
    let period_s = spec.period_s();
    let weights = table.len();
    // As the SIL run: the board boots with SARSA, the host sets the policy
    // (a fresh learner from the seed) and starts the first test run.
    let mut ctl = Controller::new(rules, profile, PolicyKind::Sarsa, table, seed).map_err(|e| anyhow!("{e}"))?;
    if let BoardStart::Checkpoint(image) = start {
        // As the firmware's boot with a kept checkpoint: its learner, then
        // the run's Start.
        super::image_store::load_image(&mut ctl, image)?;
        command(&mut ctl, ToChip::Start(pada_core::wire::RunMode::Testing))?;
    }
    let protocol_start = if matches!(start, BoardStart::Checkpoint(_)) { None } else { Some(RunProtocol::start(cfg.policy)) };
    for cmd in protocol_start.into_iter().flatten() {
        let starts = matches!(cmd, ToChip::Start(_));
        if let (true, Some(budget)) = (starts, cfg.mtbf_budget_s) {
            // As the host would: the wire command, after the policy and
            // before the first run (torque off).
            command(&mut ctl, ToChip::SetMtbfBudget(Some(budget)))?;
        }
        if let (true, BoardStart::Entries(entries)) = (starts, start) {
            // The exported weights over the fresh learner's table, last
            // before the first run.
            ctl.import_entries(entries).map_err(|e| anyhow!("the exported weights: {e}"))?;
        }
        command(&mut ctl, cmd).map_err(|e| anyhow!("--algo {:?} on board {}: {e}", cfg.policy, profile.board.name()))?;
    }
    let mut governed = GovernorStats::default();
    let mut protocol = RunProtocol::new(cfg.seconds, spec.period_us);
    let mut episodes = Vec::new();

    let joints = spec.joints;
    let counted = spec.counted.range();
    let ids: Vec<u8> = counted.clone().map(|j| joints[j].id).collect();
    anyhow::ensure!(ids.len() <= COUNTED, "at most {COUNTED} counted joints");
    let window = Some(PAPER_WINDOW_STEPS);
    let fatigue = |_: ()| FatigueCounter::<COUNTED>::with_gearboxes(|c| spec.gearbox(c), period_s, window);
    let mut paper = fatigue(()).map_err(|e| anyhow!("{e}"))?;
    let mut simulated = fatigue(()).map_err(|e| anyhow!("{e}"))?;
    let mut estimated = fatigue(()).map_err(|e| anyhow!("{e}"))?;
    let mut volts_of = [0.0f32; 256];

    let switch_step = cfg.switch_at_s.map(|s| (s / period_s).round() as u64);
    let mut switched = false;
    let mut out = PeriodOutput::default();
    let mut learning_actions = 0u64;
    let mut last_kind = StepKind::Start;
    // Generous: every episode may be followed by a wait of up to 15 s.
    let limit = (protocol.budget_steps() + 1) * 20 + 100_000;
    let mut k: u64 = 0;
    loop {
        let t = k * period_us;
        if k > limit {
            bail!("trial {trial}: no end after {k} control periods (the robot never got back to its start?)");
        }
        // 1. Read.
        let mut readings = Readings { time_ms: (t / 1000) as u32, ..Readings::default() };
        for (i, joint) in joints.iter().enumerate() {
            // Each servo in its own model's units: an RX-28's Present
            // Position … Temperature, an X-series servo's present block; an
            // STS3215's present block holds the same signed values in its
            // own units (4096 steps a turn, steps/s, load in 0.1 %).
            readings.servos[i].state = Some(match joint.servo.protocol {
                ServoProtocol::V1 => rig.present(t, joint.id).into(),
                ServoProtocol::V2 | ServoProtocol::Feetech => {
                    crate::rig::x_reading(joint, rig.joint_state(t, joint.id), 0, rig.supply_v()).into()
                }
            });
        }
        let (count, contacts) = rig.sensors(t);
        readings.encoder = Some(count);
        readings.contacts = contacts;
        // 2. The controller's period.
        ctl.period(&readings, &NoCycles, &mut out);
        // A fault switches torque off until an operator clears it, and
        // nobody does here: the trial ends with the cause.
        if let Some(cause) = out.transitions.iter().find_map(|tr| tr.entered_fault()) {
            bail!("trial {trial}: {}", fault_explained(spec, cause, t, ctl.episode(), Faulted::Board));
        }
        // 3. Drive, and tell the operator.
        let supply = rig.supply_v();
        for &(id, drive) in &out.commands {
            let volts = drive.ratio() as f64 * supply;
            rig.drive(t, id, out.torque, volts);
            volts_of[id as usize] = if out.torque { volts as f32 } else { 0.0 };
        }
        let mut learning_action = false;
        if let Some(s) = &out.step {
            last_kind = s.kind;
            if s.kind == StepKind::Start {
                rig.episode_started(t);
            }
            learning_action = is_learning_action(s.mode, s.kind);
        }
        // The operator hears of an episode's end in its period, before the
        // next boundary, as in the SIL run; the distance is the plant's.
        let ended = out.episode.map(|e| {
            let outcome = EpisodeOutcome {
                fell: last_kind == StepKind::Absorbing,
                walked_m: rig.walked_m(),
                claimed_slots: ctl.weights().occupancy().map(|o| o.claimed),
            };
            rig.episode_ended(t);
            (e, outcome)
        });
        // 4. Advance; count the learning action's torques.
        k += 1;
        rig.advance_to(k * period_us);
        if learning_action {
            // The parameter this action was chosen with (the period's own
            // move, if any, applies to the next decision).
            if let Some(g) = ctl.governor() {
                governed.record(g);
            }
            let mut com = [0.0f32; COUNTED];
            let mut sim = [0.0f32; COUNTED];
            let mut est = [0.0f32; COUNTED];
            for (c, (j, id)) in counted.clone().zip(&ids).enumerate() {
                com[c] = spec.paper_gear_torque(c, volts_of[*id as usize]);
                sim[c] = rig.gear_torque(*id);
                est[c] = out.torques[j];
            }
            paper.update(&com).map_err(|e| anyhow!("{e}"))?;
            simulated.update(&sim).map_err(|e| anyhow!("{e}"))?;
            estimated.update(&est).map_err(|e| anyhow!("{e}"))?;
            learning_actions += 1;
            if !switched && switch_step.is_some_and(|s| learning_actions >= s) {
                command(&mut ctl, ToChip::SwitchToSarsa)?;
                switched = true;
            }
        }
        let Some((e, outcome)) = ended else { continue };
        progress(e.length as u64);
        episodes.push(e);
        if let Some(cmd) = protocol.on_episode(&e, outcome) {
            command(&mut ctl, cmd)?;
        }
        if protocol.done() {
            break;
        }
    }
    let governor = ctl.governor().map(|g| governed.finish(g, robot_mtbf_s(&paper), robot_mtbf_s(&simulated)));
    let (counts, curve) = protocol.into_counts(trial, seed, ctl.agent_stats(), ctl.weights().occupancy(), governor);
    let result = TrialResult::measured(counts, curve, &paper, &simulated, ids.len());
    Ok(BoardTrial {
        result,
        config_hash: ctl.config_hash(),
        weights,
        weights_checksum: ctl.weights().checksum(),
        board_estimated_mtbf_s: robot_mtbf_s(&estimated),
        periods: k,
        episodes,
    })
}
