//! `pada leo compare`: pada's LEO driven open loop by the inputs of a
//! reference trajectory from another simulator (the authors' framework,
//! [`reference`]), step by step from the same start, and the difference
//! of every joint, the torso, the contacts and the touchdowns.
//!
//! Two ways to drive it ([`Drive`]):
//! - [`Drive::Applied`]: every servo gets the voltage the reference
//!   applied in that step, the held joints' P laws included. Only the
//!   physics can differ, so this is the model's A/B.
//! - [`Drive::Learned`]: only the three learned voltages come from the
//!   reference (read off its applied ones with its stance leg); pada's
//!   own task computes the held joints' voltages and the stance. This
//!   adds the task's rules to the comparison.

pub mod reference;

use serde::Serialize;

use crate::leo::model::{ModelOptions, NUM_JOINTS};
use crate::leo::task::Leg;
use crate::leo::{LeoConfig, LeoEnv, LeoError, Terminal};
pub use reference::{references_in, LeoState, Reference, ReferenceError, ReferenceStep};

/// How the reference drives pada's LEO (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Drive {
    /// Every servo's applied voltage from the reference.
    Applied,
    /// The three learned voltages from the reference, the rest pada's.
    Learned,
}

impl Drive {
    /// Both, for a command line's choices.
    pub const ALL: [Drive; 2] = [Drive::Applied, Drive::Learned];

    /// The name a command line gives it.
    pub fn name(self) -> &'static str {
        match self {
            Drive::Applied => "applied",
            Drive::Learned => "learned",
        }
    }
}

/// How far (control steps) a touchdown of pada's may lie from the
/// reference's to count as the same touchdown.
pub const TOUCHDOWN_MATCH_STEPS: i64 = 3;

/// The angles compared, in the order of [`StepComparison::angle_error`]:
/// the torso, then the joints in [`Joint`] order (their names in LEO's
/// hardware definition).
pub const ANGLE_NAMES: [&str; NUM_JOINTS + 1] = {
    let mut names = ["torso"; NUM_JOINTS + 1];
    let mut k = 0;
    while k < NUM_JOINTS {
        names[k + 1] = pada_core::robot::leo::JOINT_SPECS[k].name;
        k += 1;
    }
    names
};

/// One control step of both simulators.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct StepComparison {
    /// Control step, 1 for the first.
    pub step: usize,
    /// Time after the step (s since the first observation).
    pub time_s: f32,
    /// The torso angle φ and every joint angle after the step, pada's
    /// (rad; order of [`ANGLE_NAMES`]).
    pub pada_angles: [f32; NUM_JOINTS + 1],
    /// The reference's, same order.
    pub reference_angles: [f32; NUM_JOINTS + 1],
    /// pada − reference, same order.
    pub angle_error: [f32; NUM_JOINTS + 1],
    /// The filtered rates of the torso and every joint, pada − reference
    /// (rad/s, same order).
    pub rate_error: [f32; NUM_JOINTS + 1],
    /// pada's contact sensors (left toe, left heel, right toe, right heel).
    pub pada_contacts: [bool; 4],
    /// The reference's.
    pub reference_contacts: [bool; 4],
    /// Whether the left leg is the stance leg after the step, pada's.
    pub pada_stance_left: bool,
    /// The reference's.
    pub reference_stance_left: bool,
    /// The task's reward, pada's.
    pub pada_reward: f32,
    /// The reference's.
    pub reference_reward: f32,
    /// The voltages pada applied ([`Joint`] order, V).
    pub voltages: [f32; NUM_JOINTS],
}

/// A foot touching down: the step after which one of its two sensors
/// reads contact where neither did before.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Touchdown {
    /// "left" or "right".
    pub foot: &'static str,
    /// The reference's step.
    pub reference_step: usize,
    /// pada's nearest touchdown of the same foot, if any.
    pub pada_step: Option<usize>,
    /// pada − reference in control steps.
    pub difference: Option<i64>,
}

/// The whole comparison.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// How pada was driven.
    pub drive: Drive,
    /// The reference's provenance lines.
    pub provenance: Vec<String>,
    /// Physics steps and solver iterations of pada's model.
    pub substeps: u32,
    /// Solver iterations per physics step.
    pub solver_iterations: usize,
    /// The start: both simulators' state before the first step.
    pub start_error: [f32; NUM_JOINTS + 1],
    /// One entry per step both simulators made.
    pub steps: Vec<StepComparison>,
    /// The reference's first touchdown (its step), if any.
    pub first_touchdown: Option<usize>,
    /// The largest |angle error| up to and including the first touchdown
    /// (or over every step without one), [`ANGLE_NAMES`] order (rad).
    pub max_error_until_touchdown: [f32; NUM_JOINTS + 1],
    /// The largest |angle error| over every step compared.
    pub max_error: [f32; NUM_JOINTS + 1],
    /// Every touchdown of the reference and pada's match.
    pub touchdowns: Vec<Touchdown>,
    /// The touchdowns pada has that the reference does not (foot, step).
    pub extra_pada_touchdowns: Vec<(&'static str, usize)>,
    /// The step after which the reference fell, if it did.
    pub reference_fall: Option<usize>,
    /// The step after which pada fell, if it did.
    pub pada_fall: Option<usize>,
}

/// The angles of a state in [`ANGLE_NAMES`] order.
fn angles(s: &LeoState) -> [f32; NUM_JOINTS + 1] {
    let mut a = [s.torso; NUM_JOINTS + 1];
    a[1..].copy_from_slice(&s.angles);
    a
}

/// The rates of a state in [`ANGLE_NAMES`] order.
fn rates(s: &LeoState) -> [f32; NUM_JOINTS + 1] {
    let mut a = [s.torso_rate; NUM_JOINTS + 1];
    a[1..].copy_from_slice(&s.rates);
    a
}

fn difference(a: &[f32; NUM_JOINTS + 1], b: &[f32; NUM_JOINTS + 1]) -> [f32; NUM_JOINTS + 1] {
    core::array::from_fn(|i| a[i] - b[i])
}

/// pada's state as the reference reports its own (§3.1–3.2).
fn pada_state(env: &LeoEnv) -> LeoState {
    let s = env.model().state();
    LeoState {
        torso: -s.torso_pitch,
        torso_rate: env.observation().0[1],
        angles: s.angles,
        rates: env.filtered_rates(),
    }
}

/// The touchdowns of a run of contact words: (foot, step) where a foot's
/// sensors go from none to some; `start` is the contacts before step 1.
fn touchdowns(start: [bool; 4], after: &[[bool; 4]]) -> Vec<(&'static str, usize)> {
    let mut out = Vec::new();
    let mut prev = start;
    for (i, c) in after.iter().enumerate() {
        for (foot, a, b) in [("left", 0, 1), ("right", 2, 3)] {
            if !(prev[a] || prev[b]) && (c[a] || c[b]) {
                out.push((foot, i + 1));
            }
        }
        prev = *c;
    }
    out
}

/// Drives pada's LEO with the reference's inputs and compares (see the
/// module's documentation). Stops at the first step after which either
/// simulator's episode ended, or at the reference's end.
pub fn compare(
    reference: &Reference,
    drive: Drive,
    options: ModelOptions,
) -> Result<Comparison, LeoError> {
    let mut env = LeoEnv::new(LeoConfig {
        model: options,
        // No timeout: the reference's own end decides.
        timeout: None,
        ..LeoConfig::default()
    })?;
    let first = &reference.steps[0];
    let start = pada_state(&env);
    let start_error = difference(&angles(&start), &angles(&first.before));
    let start_contacts = env.model().state().contacts;
    // The reference's contacts before its first step are not exported;
    // both start in the same pose with the left foot down.
    let mut steps = Vec::with_capacity(reference.steps.len());
    let mut stance_left = true;
    let mut pada_fall = None;
    let mut reference_fall = None;
    for (i, r) in reference.steps.iter().enumerate() {
        let result = match drive {
            Drive::Applied => env.step_joint_voltages(r.voltages),
            Drive::Learned => env.step(r.learned_voltages(stance_left)),
        };
        stance_left = r.stance_left;
        let p = pada_state(&env);
        let (pa, ra) = (angles(&p), angles(&r.after));
        steps.push(StepComparison {
            step: i + 1,
            time_s: (i + 1) as f32 / 30.0,
            pada_angles: pa,
            reference_angles: ra,
            angle_error: difference(&pa, &ra),
            rate_error: difference(&rates(&p), &rates(&r.after)),
            pada_contacts: env.model().state().contacts,
            reference_contacts: r.contacts,
            pada_stance_left: env.stance() == Leg::Left,
            reference_stance_left: r.stance_left,
            pada_reward: result.reward,
            reference_reward: r.reward,
            voltages: result.info.voltages,
        });
        if result.terminal == Terminal::Fall {
            pada_fall = Some(i + 1);
        }
        if r.terminal == 2 {
            reference_fall = Some(i + 1);
        }
        if pada_fall.is_some() || reference_fall.is_some() {
            break;
        }
    }
    let reference_contacts: Vec<[bool; 4]> = steps.iter().map(|s| s.reference_contacts).collect();
    let pada_contacts: Vec<[bool; 4]> = steps.iter().map(|s| s.pada_contacts).collect();
    let reference_touchdowns = touchdowns(start_contacts, &reference_contacts);
    let mut pada_touchdowns = touchdowns(start_contacts, &pada_contacts);
    let first_touchdown = reference_touchdowns.first().map(|&(_, s)| s);
    let mut matched = Vec::new();
    for &(foot, step) in &reference_touchdowns {
        let nearest = pada_touchdowns
            .iter()
            .enumerate()
            .filter(|(_, (f, _))| *f == foot)
            .min_by_key(|(_, (_, s))| (*s as i64 - step as i64).abs());
        let (pada_step, diff) = match nearest {
            Some((k, &(_, s))) if (s as i64 - step as i64).abs() <= TOUCHDOWN_MATCH_STEPS => {
                pada_touchdowns.remove(k);
                (Some(s), Some(s as i64 - step as i64))
            }
            _ => (None, None),
        };
        matched.push(Touchdown {
            foot,
            reference_step: step,
            pada_step,
            difference: diff,
        });
    }
    let until = first_touchdown.unwrap_or(steps.len());
    let max_abs = |rows: &[StepComparison]| -> [f32; NUM_JOINTS + 1] {
        let mut m = [0.0f32; NUM_JOINTS + 1];
        for s in rows {
            for (k, e) in s.angle_error.iter().enumerate() {
                m[k] = m[k].max(e.abs());
            }
        }
        m
    };
    Ok(Comparison {
        drive,
        provenance: reference.provenance.clone(),
        substeps: options.substeps,
        solver_iterations: options.solver_iterations,
        start_error,
        max_error_until_touchdown: max_abs(&steps[..until.min(steps.len())]),
        max_error: max_abs(&steps),
        first_touchdown,
        touchdowns: matched,
        extra_pada_touchdowns: pada_touchdowns,
        reference_fall,
        pada_fall,
        steps,
    })
}
