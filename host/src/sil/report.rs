//! What a SIL run shows: the summary (`summary.json`) and its checks — the
//! link, the bit-for-bit replay, the learning time, every injected fault,
//! and the comparison with the same controller on the host.
//!
//! # The comparison with the host
//!
//! - **LEO**: trial 0 of `pada run --board <board> --task leo` with the
//!   run's seed and policy (`crate::board`): the firmware's controller built
//!   for the host, against the same rapier3d LEO stepped on the same period
//!   boundaries. Without injected faults the two are the same run: every
//!   episode's index, mode, return (bit for bit), length and weight
//!   checksum must be equal, and so the learning curve and the final
//!   checksum.
//! - **Pendulum**: eight trials of that board runner against the same
//!   pendulum model (swinging freely between episodes), read at the period
//!   boundaries rather than when the bus gets there: the spread of the
//!   configuration, which the SIL run should lie in.

use super::bus::{BusEmulator, BusStats};
use super::forecast::ForecastStats;
use super::replay::{replay_from, Record, ReplayReport};
use super::config::{machine, SilConfig, SilTask};
use super::wall::WallTime;
use crate::board::{run_board_trial_from, run_board_trial_on, BoardStart, RunProtocol};
use crate::capture::{Latest, MessageCounts};
use crate::experiment::runner::RunConfig;
use crate::experiment::{end_performance, rise_time, TestPoint};
use crate::pendulum::PhysicalPendulumParams;
use crate::rig::PendulumRig;
use pada_core::wire::{Episode, LinkStats};
use rayon::prelude::*;
use serde::Serialize;

/// Learning time from which a run is expected to have learned \[s\].
pub const LEARNING_CHECK_S: f64 = 300.0;
/// Learning time from which LEO is expected to walk \[s\]: the
/// 3600 s run.
pub const WALKING_CHECK_S: f64 = 3600.0;
/// How far LEO must walk per test run over the last 10 % of them \[m\].
pub const WALKING_TARGET_M: f64 = 2.0;
/// Trials of the pendulum's host comparison.
const PENDULUM_TWIN_TRIALS: u32 = 8;

/// Distribution of the agent step's instruction count.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Instructions {
    /// Agent calls measured.
    pub calls: u64,
    /// Mean.
    pub mean: f64,
    /// Smallest.
    pub min: u32,
    /// Median.
    pub median: u32,
    /// 99th percentile.
    pub p99: u32,
    /// Largest.
    pub max: u32,
}

impl Instructions {
    fn of(mut v: Vec<u32>) -> Instructions {
        if v.is_empty() {
            return Instructions::default();
        }
        v.sort_unstable();
        let n = v.len();
        Instructions {
            calls: n as u64,
            mean: v.iter().map(|&x| x as f64).sum::<f64>() / n as f64,
            min: v[0],
            median: v[n / 2],
            p99: v[((n as f64 * 0.99) as usize).min(n - 1)],
            max: v[n - 1],
        }
    }
}

/// The agent step's instructions on the Cortex-M4 build, by call.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AgentInstructions {
    /// Learning steps (`step`: choose and update).
    pub learning_step: Instructions,
    /// Greedy test steps.
    pub test_step: Instructions,
    /// Episode starts.
    pub start: Instructions,
    /// Episode ends (time limit or absorbing).
    pub end: Instructions,
    /// Instructions stand in for cycles: QEMU counts instructions
    /// (`-icount shift=0`), not the M4's pipeline and flash wait states.
    pub note: &'static str,
}

/// What a fault did, as the plant side and the telemetry saw it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FaultResult {
    /// The `--fault` specification.
    pub spec: String,
    /// The first affected answer \[s, emulated time\].
    pub onset_s: Option<f64>,
    /// Every servo had torque at the onset (the fault hit a running robot).
    pub torque_at_onset: bool,
    /// When every servo's torque was off after the onset \[s\].
    pub torque_off_s: Option<f64>,
    /// Onset to torque off on every servo \[ms\].
    pub latency_ms: Option<f64>,
    /// The control period \[ms\].
    pub period_ms: f64,
    /// The latency is at most one control period.
    pub within_one_period: bool,
    /// The cause the firmware reported (telemetry `Fault`).
    pub cause: Option<String>,
    /// Its details.
    pub cause_detail: Option<String>,
    /// When the `Fault` frame was sent \[s\].
    pub reported_s: Option<f64>,
    /// Torque came back on, on every servo, after `ClearFault` and `Start`.
    pub resumed: bool,
}

pub use super::check::Check;

/// The firmware's controller on the host, against the same plant.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HostComparison {
    /// What ran.
    pub what: String,
    /// Trials run.
    pub trials: u32,
    /// End performance of each trial.
    pub end_performance: Vec<f64>,
    /// Mean distance walked per test run over the last 10 % of each
    /// trial's test runs \[m\] (LEO).
    pub end_walked_m: Vec<Option<f64>>,
    /// Trial 0's final weight checksum.
    pub weights_checksum: u32,
    /// LEO: episodes compared with the SIL run's.
    pub episodes_compared: usize,
    /// LEO: the first episode that differs, if any.
    pub first_difference: Option<String>,
    /// LEO: every episode and the final checksum equal.
    pub identical: Option<bool>,
    /// Wall-clock time of the host runs \[s\].
    pub wall_s: f64,
}

/// The summary of a SIL run (`summary.json`).
#[derive(Debug, Clone, Serialize)]
pub struct SilSummary {
    /// The task.
    pub task: SilTask,
    /// The firmware's robot.
    pub robot: &'static str,
    /// The board learner profile.
    pub board: &'static str,
    /// The QEMU machine that emulates it.
    pub machine: &'static str,
    /// Weights in the board's table.
    pub weights: usize,
    /// The policy.
    pub policy: String,
    /// The master seed (`pada run --seed`'s).
    pub seed: u64,
    /// The seed of the board's learner: trial 0's of the master seed.
    pub learner_seed: u64,
    /// The firmware image.
    pub elf: String,
    /// What stands behind the bus.
    pub plant: String,
    /// Learning time asked for \[s\].
    pub seconds: f64,
    /// Learning time reached \[s\].
    pub learning_s: f64,
    /// Emulated time of the whole run \[s\].
    pub emulated_s: f64,
    /// Wall-clock time of the run, QEMU's start to its end \[s\].
    pub wall_s: f64,
    /// Emulated seconds per wall-clock second.
    pub speedup: f64,
    /// Lock-step exchanges.
    pub exchanges: u64,
    /// Exchanges per control period of emulated time.
    pub exchanges_per_period: f64,
    /// The forecasts of the bus's answers.
    pub forecasts: ForecastStats,
    /// Where the wall-clock time of the lock-step loop went.
    pub wall_time: WallTime,
    /// Instructions the firmware executed (outside the board's transport).
    pub instructions: u64,
    /// Instructions per control period of emulated time.
    pub instructions_per_period: f64,
    /// Learning episodes finished.
    pub learning_episodes: u32,
    /// The learning curve: every test episode.
    pub curve: Vec<TestPoint>,
    /// Return of the first test episode (before learning).
    pub first_test_return: Option<f64>,
    /// Mean of the last 10 % of test returns (Section VI).
    pub end_performance: Option<f64>,
    /// Rise time (Section VI) \[s of learning\].
    pub rise_time_s: Option<f64>,
    /// Distance walked per test run over the last 10 % of test runs, as
    /// the plant measured it \[m\] (LEO).
    pub end_walked_m: Option<f64>,
    /// Damage J of the learned joint(s) at the end (firmware's counter).
    pub damage: Vec<f64>,
    /// Backlash re-engagements of the learned joint(s) at the end.
    pub reengagements: Vec<u32>,
    /// The agent step's instruction counts.
    pub agent_instructions: AgentInstructions,
    /// The telemetry link: frames, bytes, every kind of loss.
    pub telemetry: LinkStats,
    /// Frames by message.
    pub messages: MessageCounts,
    /// The emulated servo bus.
    pub bus: BusStats,
    /// The bit-for-bit replay.
    pub replay: ReplayReport,
    /// The same controller on the host against the same plant.
    pub host: Option<HostComparison>,
    /// The injected faults.
    pub faults: Vec<FaultResult>,
    /// Faults the firmware reported that no injection explains.
    pub unexpected_faults: Vec<String>,
    /// Power cuts, checkpoint saves and hangs (`--power-cut`, `--fault
    /// hang`).
    pub power: super::power_cut::PowerReport,
    /// The checks; the run passes when all hold.
    pub checks: Vec<Check>,
    /// All checks hold.
    pub passed: bool,
}

/// What the session hands over for the summary.
pub struct Facts<'a> {
    /// Emulated time \[s\].
    pub emulated_s: f64,
    /// Wall time of the run \[s\].
    pub wall_s: f64,
    /// Wall time of the lock-step loop \[s\].
    pub loop_s: f64,
    /// Its breakdown.
    pub wall_time: WallTime,
    /// Exchanges.
    pub exchanges: u64,
    /// Instructions executed by the firmware.
    pub instructions: u64,
    /// The forecasts.
    pub forecasts: ForecastStats,
    /// Every Step and Episode, in order.
    pub records: Vec<Record>,
    /// Agent-call instructions: learning, test, start, end.
    pub cycles: [Vec<u32>; 4],
    /// Faults the firmware reported: time \[s\], cause, details.
    pub fault_reports: Vec<(f64, String, String)>,
    /// The run protocol at the end (learning time, curve).
    pub protocol: RunProtocol,
    /// The plant's description.
    pub plant: String,
    /// The bus emulator (counters, fault traces).
    pub bus: &'a BusEmulator,
    /// The telemetry link.
    pub link: LinkStats,
    /// Frames by message.
    pub messages: MessageCounts,
    /// The last values the telemetry carried.
    pub latest: Latest,
    /// The `--telemetry` forwarder.
    pub sink: Option<crate::telemetry::TelemetrySink>,
    /// Power cuts, saves and hangs.
    pub power: super::power_cut::PowerReport,
}

/// Mean distance walked per test run over the last 10 % (at least one) of
/// `curve`'s test runs.
pub fn tail_walked_m(curve: &[TestPoint]) -> Option<f64> {
    let n = curve.len().div_ceil(10).max(1).min(curve.len());
    let tail = &curve[curve.len() - n..];
    let walked: Option<f64> = tail.iter().map(|p| p.walked_m).sum();
    walked.filter(|_| n > 0).map(|w| w / n as f64)
}

/// The first difference between two runs' episodes, if any.
fn first_difference(sil: &[Episode], host: &[Episode]) -> Option<String> {
    for (k, (a, b)) in sil.iter().zip(host).enumerate() {
        let same = a.index == b.index
            && a.mode == b.mode
            && a.total_reward.to_bits() == b.total_reward.to_bits()
            && a.length == b.length
            && a.weights_checksum == b.weights_checksum;
        if !same {
            return Some(format!("episode {k}: SIL {a:?}, host {b:?}"));
        }
    }
    (sil.len() != host.len()).then(|| format!("SIL has {} episodes, host {}", sil.len(), host.len()))
}

/// The host comparison of `cfg`, against the SIL run's `episodes`.
fn compare(cfg: &SilConfig, episodes: &[Episode]) -> anyhow::Result<HostComparison> {
    let started = std::time::Instant::now();
    let profile = cfg.profile();
    let run = |trials| RunConfig { policy: cfg.policy, switch_at_s: None, mtbf_budget_s: cfg.mtbf_budget_s, seconds: cfg.seconds, trials, seed: cfg.seed };
    let none = |_| {};
    match cfg.task {
        // The same rig behind the bus as behind `pada run --board`'s
        // controller: the same trial, bit for bit.
        SilTask::Leo | SilTask::File(_) => {
            let start = cfg.weights.as_ref().map_or(BoardStart::Fresh, |w| BoardStart::Entries(&w.entries));
            let t = run_board_trial_from(profile, &cfg.task.sim()?, &run(1), 0, start, &none)?;
            let first = first_difference(episodes, &t.episodes);
            let (what, body) = match cfg.task {
                SilTask::File(f) => (format!("--robot {}", f.path.display()), "the same URDF in rapier3d"),
                _ => ("--task leo".to_string(), "the same rapier3d LEO"),
            };
            Ok(HostComparison {
                what: format!(
                    "trial 0 of `pada run --board {} {what}` with the same seed and policy (the firmware's controller on the host, {body})",
                    cfg.board.name()
                ),
                trials: 1,
                end_performance: vec![t.result.end_performance],
                end_walked_m: vec![t.result.end_walked_m],
                weights_checksum: t.weights_checksum,
                episodes_compared: episodes.len().min(t.episodes.len()),
                identical: Some(first.is_none() && episodes.last().map(|e| e.weights_checksum) == Some(t.weights_checksum)),
                first_difference: first,
                wall_s: started.elapsed().as_secs_f64(),
            })
        }
        SilTask::Pendulum => {
            let cfg8 = run(PENDULUM_TWIN_TRIALS);
            let trials = (0..PENDULUM_TWIN_TRIALS)
                .into_par_iter()
                .map(|i| {
                    let mut rig = PendulumRig::new(PhysicalPendulumParams::default());
                    run_board_trial_on(profile, &crate::robots::sim_robot(profile.robot)?, &cfg8, i, &mut rig, &none)
                })
                .collect::<anyhow::Result<Vec<_>>>()?;
            Ok(HostComparison {
                what: format!(
                    "{PENDULUM_TWIN_TRIALS} trials of the firmware's controller on the host (`pada run --board {}`'s runner) against the same pendulum model, swinging freely between episodes, read at the period boundaries",
                    cfg.board.name()
                ),
                trials: PENDULUM_TWIN_TRIALS,
                end_performance: trials.iter().map(|t| t.result.end_performance).collect(),
                end_walked_m: trials.iter().map(|t| t.result.end_walked_m).collect(),
                weights_checksum: trials[0].weights_checksum,
                episodes_compared: 0,
                first_difference: None,
                identical: None,
                wall_s: started.elapsed().as_secs_f64(),
            })
        }
    }
}

/// The summary and checks of a finished run.
pub fn summarize(cfg: &SilConfig, facts: Facts<'_>) -> SilSummary {
    let profile = cfg.profile();
    let period_us = cfg.task.robot().period_us;
    let period_ms = period_us as f64 * 1e-3;
    let periods = facts.emulated_s / (period_us as f64 * 1e-6);
    let curve = facts.protocol.curve().to_vec();
    let returns: Vec<f64> = curve.iter().map(|p| p.test_return).collect();
    let times: Vec<f64> = curve.iter().map(|p| p.learning_time_s).collect();
    let replay = replay_from(&profile, cfg.policy, cfg.learner_seed(), cfg.weights.as_ref().map(|w| &w.entries[..]), &facts.records);
    let episodes: Vec<Episode> = facts
        .records
        .iter()
        .filter_map(|r| match r {
            Record::Episode(e) => Some(*e),
            _ => None,
        })
        .collect();

    let mut faults = Vec::new();
    let mut explained = vec![false; facts.fault_reports.len()];
    for (spec, trace) in facts.bus.faults() {
        let latency_ms = match (trace.onset_us, trace.torque_off_us) {
            (Some(a), Some(b)) => Some((b - a) as f64 * 1e-3),
            _ => None,
        };
        // The firmware's report: the first Fault sent after the onset.
        let report = trace
            .onset_us
            .and_then(|on| facts.fault_reports.iter().enumerate().find(|(_, r)| r.0 * 1e6 >= on as f64 - 1.0));
        if let Some((i, _)) = report {
            explained[i] = true;
        }
        faults.push(FaultResult {
            spec: spec.to_string(),
            onset_s: trace.onset_us.map(|t| t as f64 * 1e-6),
            torque_at_onset: trace.torque_at_onset,
            torque_off_s: trace.torque_off_us.map(|t| t as f64 * 1e-6),
            latency_ms,
            period_ms,
            within_one_period: latency_ms.is_some_and(|l| l <= period_ms),
            cause: report.map(|(_, r)| r.1.clone()),
            cause_detail: report.map(|(_, r)| r.2.clone()),
            reported_s: report.map(|(_, r)| r.0),
            resumed: trace.torque_on_again_us.is_some(),
        });
    }
    let unexpected_faults: Vec<String> = facts
        .fault_reports
        .iter()
        .zip(&explained)
        .filter(|(_, e)| !**e)
        .map(|(r, _)| format!("{:.3} s: {}", r.0, r.2))
        .collect();

    let link = facts.link;
    let mut checks = vec![
        Check {
            name: "telemetry: every frame decoded, no sequence gap",
            ok: link.is_clean() && link.frames > 0,
            detail: format!(
                "{} frames, {} bytes; crc {} cobs {} oversize {} short {} undecodable {} non-canonical {}; gaps {} ({} frames missed, {} resyncs)",
                link.frames,
                link.bytes,
                link.crc_errors,
                link.cobs_errors,
                link.oversize,
                link.too_short,
                link.decode_errors,
                link.noncanonical,
                link.seq_gaps,
                link.frames_missed,
                link.seq_resyncs
            ),
        },
        Check {
            name: "replay: same action at every step and same weight checksums, bit for bit",
            ok: replay.identical,
            detail: format!(
                "{} agent calls, {} actions and {} checksums compared; final checksum firmware {} replay {}{}{}",
                replay.steps,
                replay.actions_compared,
                replay.checksums_compared,
                replay.final_checksum_firmware.map(|c| format!("{c:08x}")).unwrap_or("-".into()),
                replay.final_checksum_replay.map(|c| format!("{c:08x}")).unwrap_or("-".into()),
                replay
                    .first_action_mismatch
                    .map(|m| format!("; first action mismatch at step {}: {} vs {}", m.0, m.1, m.2))
                    .unwrap_or_default(),
                replay.error.as_ref().map(|e| format!("; {e}")).unwrap_or_default()
            ),
        },
        Check {
            name: "learning time reached and a final test episode run",
            ok: facts.protocol.done(),
            detail: format!("{:.1} s of {} s", facts.protocol.learning_time_s(), cfg.seconds),
        },
        Check {
            name: "no fault without an injected cause",
            ok: unexpected_faults.is_empty(),
            detail: if unexpected_faults.is_empty() { "none".into() } else { unexpected_faults.join("; ") },
        },
    ];
    for f in &faults {
        checks.push(Check {
            name: "fault: hit with torque on, torque off on every servo within one control period, cause reported, resumed",
            ok: f.torque_at_onset && f.within_one_period && f.cause.is_some() && f.resumed,
            detail: format!(
                "{}: onset {} (torque {}) torque off {} latency {} (period {} ms), cause {}, resumed {}",
                f.spec,
                f.onset_s.map(|t| format!("{t:.4} s")).unwrap_or("never".into()),
                if f.torque_at_onset { "on" } else { "off" },
                f.torque_off_s.map(|t| format!("{t:.4} s")).unwrap_or("never".into()),
                f.latency_ms.map(|t| format!("{t:.2} ms")).unwrap_or("-".into()),
                f.period_ms,
                f.cause.as_deref().unwrap_or("none"),
                f.resumed
            ),
        });
    }
    let end = end_performance(&returns);
    let end_walked_m = tail_walked_m(&curve);
    let host = if cfg.compare {
        match compare(cfg, &episodes) {
            Ok(h) => Some(h),
            Err(e) => {
                checks.push(Check { name: "the same controller on the host", ok: false, detail: format!("{e:#}") });
                None
            }
        }
    } else {
        None
    };
    if let (SilTask::Leo | SilTask::File(_), Some(h), true) = (cfg.task, &host, cfg.faults.is_empty()) {
        checks.push(Check {
            name: "equals `pada run --board`: every episode and the final weight checksum",
            ok: h.identical == Some(true),
            detail: format!(
                "{} episodes compared; final checksum SIL {} host {:08x}; end performance host {:.1}, walked host {}{}",
                h.episodes_compared,
                episodes.last().map(|e| format!("{:08x}", e.weights_checksum)).unwrap_or("-".into()),
                h.weights_checksum,
                h.end_performance[0],
                h.end_walked_m[0].map(|w| format!("{w:.2} m")).unwrap_or("-".into()),
                h.first_difference.as_ref().map(|d| format!("; first difference: {d}")).unwrap_or_default()
            ),
        });
    }
    if cfg.task == SilTask::Pendulum && cfg.seconds >= LEARNING_CHECK_S {
        let first = returns.first().copied();
        let host_text = host
            .as_ref()
            .map(|h| {
                let v = &h.end_performance;
                let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                format!("; host {:.0} (trials: {lo:.0} .. {hi:.0})", v.iter().sum::<f64>() / v.len() as f64)
            })
            .unwrap_or_default();
        checks.push(Check {
            name: "learned: end performance above the first test return",
            ok: matches!((first, end), (Some(f), Some(e)) if e > f),
            detail: format!(
                "first {} end {}{host_text}",
                first.map(|v| format!("{v:.0}")).unwrap_or("-".into()),
                end.map(|v| format!("{v:.0}")).unwrap_or("-".into())
            ),
        });
    }
    if cfg.task == SilTask::Leo && cfg.seconds >= WALKING_CHECK_S {
        checks.push(Check {
            name: "walks: at least 2 m per test run over the last 10 % of test runs",
            ok: end_walked_m.is_some_and(|w| w >= WALKING_TARGET_M),
            detail: format!(
                "{} per test run over the last {} of {} test runs",
                end_walked_m.map(|w| format!("{w:.2} m")).unwrap_or("-".into()),
                curve.len().div_ceil(10).max(1),
                curve.len()
            ),
        });
    }
    let mut power = facts.power;
    let fits = super::power_cut::checkpoint_bytes(profile.weights().unwrap_or(0), profile.entry_bytes())
        <= pada_firmware::sil::CHECKPOINT_SLOT_LEN;
    checks.extend(super::power_cut::checks(&mut power, period_ms, facts.emulated_s, fits));
    if let Some(sink) = facts.sink {
        let (ok, detail) = match sink.finish() {
            Ok(t) => (true, format!("{} bytes to {}", t.bytes, t.target)),
            Err(e) => (false, format!("{e:#}")),
        };
        checks.push(Check { name: "telemetry forwarded (--telemetry)", ok, detail });
    }
    let passed = checks.iter().all(|c| c.ok);
    let [learning, test, start, end_calls] = facts.cycles;
    SilSummary {
        task: cfg.task,
        robot: cfg.task.robot().name,
        board: cfg.board.name(),
        machine: machine(cfg.board).unwrap_or("none"),
        weights: profile.weights().unwrap_or(0),
        policy: crate::experiment::algo::label(&cfg.policy),
        seed: cfg.seed,
        learner_seed: cfg.learner_seed(),
        elf: cfg.elf.display().to_string(),
        plant: facts.plant,
        seconds: cfg.seconds,
        learning_s: facts.protocol.learning_time_s(),
        emulated_s: facts.emulated_s,
        wall_s: facts.wall_s,
        speedup: if facts.wall_s > 0.0 { facts.emulated_s / facts.wall_s } else { 0.0 },
        exchanges: facts.exchanges,
        exchanges_per_period: if periods > 0.0 { facts.exchanges as f64 / periods } else { 0.0 },
        forecasts: facts.forecasts,
        wall_time: facts.wall_time,
        instructions: facts.instructions,
        instructions_per_period: if periods > 0.0 { facts.instructions as f64 / periods } else { 0.0 },
        learning_episodes: facts.protocol.learning_episodes(),
        first_test_return: returns.first().copied(),
        end_performance: end,
        rise_time_s: rise_time(&times, &returns),
        end_walked_m,
        curve,
        damage: facts.latest.damage,
        reengagements: facts.latest.reengagements,
        agent_instructions: AgentInstructions {
            learning_step: Instructions::of(learning),
            test_step: Instructions::of(test),
            start: Instructions::of(start),
            end: Instructions::of(end_calls),
            note: "instructions executed (QEMU -icount shift=0), counted around the agent call by the board's counter",
        },
        telemetry: link,
        messages: facts.messages,
        bus: facts.bus.stats(),
        replay,
        host,
        faults,
        unexpected_faults,
        power,
        checks,
        passed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pada_core::wire::RunMode;

    fn point(walked: Option<f64>) -> TestPoint {
        TestPoint {
            learning_time_s: 0.0,
            learning_episodes: 0,
            test_return: 0.0,
            walked_m: walked,
            fell: false,
            duration_s: 1.0,
            claimed_slots: None,
        }
    }

    #[test]
    fn the_walking_tail_is_the_last_tenth_of_test_runs() {
        let mut curve: Vec<TestPoint> = (0..19).map(|_| point(Some(0.0))).collect();
        curve.push(point(Some(3.0)));
        curve.push(point(Some(1.0)));
        // 21 test runs: the last 3.
        assert_eq!(tail_walked_m(&curve), Some(4.0 / 3.0));
        assert_eq!(tail_walked_m(&[point(None)]), None);
        assert_eq!(tail_walked_m(&[]), None);
    }

    #[test]
    fn episodes_differ_at_the_first_bit() {
        let e = Episode { index: 3, mode: RunMode::Learning, total_reward: -1.0, length: 9, weights_checksum: 7 };
        assert_eq!(first_difference(&[e, e], &[e, e]), None);
        let other = Episode { total_reward: f32::from_bits((-1.0f32).to_bits() + 1), ..e };
        assert!(first_difference(&[e, e], &[e, other]).unwrap().starts_with("episode 1"));
        assert!(first_difference(&[e], &[e, e]).unwrap().contains("1 episodes, host 2"));
    }
}
