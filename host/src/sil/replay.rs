//! The bit-for-bit check: the observations and rewards the firmware
//! reported, replayed through the host build of the same agent (the
//! robot's definition and the board's learner profile from pada-core, the
//! same policy and seed), must give the same action at every step and the same
//! weight checksum at every episode's end.
//!
//! The firmware's agent draws from its generator only in the agent calls
//! (`pada_firmware::control`), and a `Step` frame says which call it was
//! (start, step, absorbing end, time-limit end), with the observation, the
//! reward and the mode, and whether the policy's memory was mirrored first
//! (LEO's footsteps), so the replay makes the same calls in the same order. A policy change (`SetPolicy`) starts a fresh learner from the
//! seed, as on the chip; the replay is given the policy the run used, and
//! takes the wear governor's Δ or α from each `Policy` report where the
//! firmware reported it.

use pada_core::agent::{EpisodeEnd, Mode};
use crate::experiment::table::HostTable;
use pada_core::policy::PolicyKind;
use pada_core::tile_coding::Layout;
use pada_core::wire::{Episode, RunMode, Step, StepKind};
use pada_core::profile::{LearnerProfile, TILINGS, TRACE};
use rand_core::SeedableRng;
use rand_pcg::Pcg32;
use serde::Serialize;

/// A record of the run, in the order the firmware sent it.
#[derive(Debug, Clone)]
pub enum Record {
    /// A step.
    Step(Step),
    /// An episode's end.
    Episode(Episode),
    /// The wear governor's Δ or α, from a `Policy` report: in force from
    /// the next decision on.
    Restriction(f32),
    /// A checkpoint save completed (`Checkpoint(Saved)`): what a later boot
    /// must load.
    Saved,
    /// The board booted again (after a power cut or a watchdog reset): its
    /// learner is the last completed save's, or a fresh one from the seed
    /// if there was none.
    Boot,
}

/// What the replay found.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ReplayReport {
    /// Agent calls replayed.
    pub steps: u64,
    /// Actions compared (calls that choose one).
    pub actions_compared: u64,
    /// Episode ends whose weight checksums were compared.
    pub checksums_compared: u64,
    /// The first step whose action differed: (control step, firmware's
    /// action, replay's action).
    pub first_action_mismatch: Option<(u32, u32, u32)>,
    /// The first episode whose checksum differed: (index, firmware, replay).
    pub first_checksum_mismatch: Option<(u32, u32, u32)>,
    /// An agent call the host build refused (a non-finite observation the
    /// firmware accepted, or a call out of order).
    pub error: Option<String>,
    /// The firmware's checksum at its last episode end.
    pub final_checksum_firmware: Option<u32>,
    /// The replay's checksum at the same point.
    pub final_checksum_replay: Option<u32>,
    /// Boots after the first, each replayed from the last completed save.
    pub boots: u64,
    /// Every action and every checksum identical.
    pub identical: bool,
}

/// Replays `records` through a fresh host agent of the board's learner
/// `profile` with `policy` and `seed`.
pub fn replay(profile: &LearnerProfile, policy: PolicyKind, seed: u64, records: &[Record]) -> ReplayReport {
    replay_from(profile, policy, seed, None, records)
}

/// [`replay`] of a run whose learner started from exported table
/// `entries` (`pada sil --weights`), written over the fresh learner's
/// table as the board's import does.
pub fn replay_from(profile: &LearnerProfile, policy: PolicyKind, seed: u64, entries: Option<&[u8]>, records: &[Record]) -> ReplayReport {
    let mut report = ReplayReport::default();
    let Some(weights) = profile.weights() else {
        report.error = Some(format!("board profile {} has no fixed table size", profile.board.name()));
        return report;
    };
    let table = match profile.layout {
        Layout::Claimed => match HostTable::claimed(weights, profile.format, profile.tag_bytes) {
            Ok(t) => t.on_full(profile.when_full),
            Err(e) => {
                report.error = Some(format!("cannot build the table: {e}"));
                return report;
            }
        },
        Layout::Exact | Layout::Hashed => match HostTable::plain_of(weights, profile.format) {
            Ok(t) => t,
            Err(e) => {
                report.error = Some(format!("cannot build the table: {e}"));
                return report;
            }
        },
    };
    let agent = profile.robot.agent::<_, TILINGS, TRACE>(policy, profile.layout, table);
    let mut agent = match agent {
        Ok(a) => a,
        Err(e) => {
            report.error = Some(format!("cannot build the agent: {e}"));
            return report;
        }
    };
    let mut rng = Pcg32::seed_from_u64(seed);
    agent.reset_weights(&mut rng);
    if let Some(entries) = entries {
        let eb = pada_core::weights::WeightStore::entry_bytes(agent.weights());
        for (i, src) in entries.chunks_exact(eb).enumerate() {
            pada_core::weights::WeightStore::load_le(agent.weights_mut(), i, src);
        }
        let state = agent.state();
        if let Err(e) = agent.restore_state(&state) {
            report.error = Some(format!("the exported weights do not restore: {e}"));
            return report;
        }
        agent.rehash();
    }
    // What a boot without a checkpoint starts from (the run sends
    // `SetPolicy` again: a fresh learner from the seed), and the last save.
    let mut saved = (agent.state(), agent.weights().clone(), rng.clone());
    for record in records {
        match record {
            Record::Saved => saved = (agent.state(), agent.weights().clone(), rng.clone()),
            Record::Boot => {
                report.boots += 1;
                let (state, weights, generator) = &saved;
                // The table first: a claim table's restore counts its slots.
                agent.weights_mut().clone_from(weights);
                agent.rehash();
                if let Err(e) = agent.restore_state(state) {
                    report.error = Some(format!("boot {}: the saved state does not restore: {e}", report.boots));
                    break;
                }
                rng = generator.clone();
            }
            Record::Step(s) => {
                report.steps += 1;
                if s.footstep {
                    match profile.robot.footstep_remap {
                        Some(map) => agent.remap_memory(&map),
                        None => {
                            report.error = Some(format!("step {}: a footstep on a robot without one", s.step));
                            break;
                        }
                    }
                }
                agent.set_mode(if s.mode == RunMode::Testing {
                    Mode::Testing
                } else {
                    Mode::Learning
                });
                let decision = match s.kind {
                    StepKind::Start => agent.start_episode(&s.state, &mut rng).map(Some),
                    StepKind::Step => agent.step(s.reward, &s.state, &mut rng).map(Some),
                    StepKind::Absorbing => agent
                        .end_episode(s.reward, EpisodeEnd::Absorbing, &mut rng)
                        .map(|_| None),
                    StepKind::Timeout => agent
                        .end_episode(s.reward, EpisodeEnd::Timeout(&s.state), &mut rng)
                        .map(|_| None),
                };
                match decision {
                    Ok(Some(d)) => {
                        report.actions_compared += 1;
                        if d.action != s.action && report.first_action_mismatch.is_none() {
                            report.first_action_mismatch = Some((s.step, s.action, d.action));
                        }
                    }
                    Ok(None) => {}
                    Err(e) => {
                        report.error = Some(format!("step {}: {e}", s.step));
                        break;
                    }
                }
            }
            Record::Restriction(v) => {
                if let Err(e) = agent.set_policy_parameter(*v) {
                    report.error = Some(format!("the governor's parameter {v}: {e}"));
                    break;
                }
            }
            Record::Episode(e) => {
                report.checksums_compared += 1;
                let mine = agent.weights_checksum();
                if mine != e.weights_checksum && report.first_checksum_mismatch.is_none() {
                    report.first_checksum_mismatch = Some((e.index, e.weights_checksum, mine));
                }
                report.final_checksum_firmware = Some(e.weights_checksum);
                report.final_checksum_replay = Some(mine);
            }
        }
    }
    report.identical = report.error.is_none()
        && report.first_action_mismatch.is_none()
        && report.first_checksum_mismatch.is_none()
        && report.actions_compared > 0
        && report.checksums_compared > 0;
    report
}
