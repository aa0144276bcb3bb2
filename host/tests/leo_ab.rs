//! pada's LEO against the authors' framework, step by step under the same
//! open-loop voltages from the same start (`tests/data/leo-ab/`, made as
//! `docs/reference/leo-ab.md` says; `pada leo compare` prints the same
//! comparison for any reference).
//!
//! Under actuation the model's default step (4 physics steps per control
//! period) still lags the reference: the largest error over the first
//! 0.2 s is 0.015–0.041 rad (`sim/src/leo/README.md`, "Against the
//! framework under actuation"). Most of the first-order error was the
//! dry friction's break-away, seen one physics step late after each
//! voltage change; a joint now breaks away at the change
//! (`Stiction::at_load_change`), and since then 8 steps per period keep
//! every reference within the tolerance (12 were needed before). The
//! angle test therefore checks the physics at [`AB_SUBSTEPS`] physics
//! steps per period; the touchdown test checks the default step.
//!
//! The tolerances come from the model's step-size study
//! (`sim/src/leo/README.md`), not from these references:
//! - [`STEP_TOLERANCE`]: 0.02 rad, the study's convergence criterion (the
//!   torso may move by less than 0.02 rad when the step is halved);
//! - [`HORIZON_STEPS`]: 6 control steps (0.2 s), the horizon of the
//!   study's angle error under random actions;
//! - [`START_TOLERANCE`]: the reference's soft rubber contacts
//!   (2.5·10⁴ N/m) compress by about 0.8 mm under LEO's weight of about
//!   20 N, which pada's stiff contacts leave out; over a leg of about
//!   0.2 m that is 0.004 rad.

use pada::leo::compare::{compare, references_in, Comparison, Drive, Reference, ANGLE_NAMES};
use pada::leo::model::ModelOptions;

const STEP_TOLERANCE: f32 = 0.02;
/// Physics steps per control period for the angle test: the coarsest step
/// whose error on these references stays below [`STEP_TOLERANCE`] over
/// the first 0.2 s (`cargo run --release -p pada --example leo_ab_table`:
/// 0.0195 rad at 8 steps, 0.0298 at 6).
const AB_SUBSTEPS: u32 = 8;
const HORIZON_STEPS: usize = 6;
const START_TOLERANCE: f32 = 0.004;

/// Every reference trajectory, by name.
fn references() -> Vec<(String, Reference)> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/data/leo-ab");
    let out = references_in(std::path::Path::new(dir)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        out.len(),
        9,
        "the nine references of docs/reference/leo-ab.md"
    );
    out
}

fn applied(reference: &Reference) -> Comparison {
    compare(reference, Drive::Applied, ModelOptions::default()).expect("the model builds")
}

fn applied_fine(reference: &Reference) -> Comparison {
    let options = ModelOptions {
        substeps: AB_SUBSTEPS,
        ..ModelOptions::default()
    };
    compare(reference, Drive::Applied, options).expect("the model builds")
}

/// The largest |angle error| over the first `n` steps: (error, step, angle).
fn worst(c: &Comparison, n: usize) -> (f32, usize, &'static str) {
    let mut w = (0.0f32, 0, ANGLE_NAMES[0]);
    for s in c.steps.iter().take(n) {
        for (k, e) in s.angle_error.iter().enumerate() {
            if e.abs() > w.0 {
                w = (e.abs(), s.step, ANGLE_NAMES[k]);
            }
        }
    }
    w
}

#[test]
fn every_reference_starts_where_pada_starts() {
    for (name, r) in references() {
        let c = applied(&r);
        for (k, e) in c.start_error.iter().enumerate() {
            assert!(
                e.abs() <= START_TOLERANCE,
                "{name}: {} starts {e:+.4} rad from the reference",
                ANGLE_NAMES[k]
            );
        }
    }
}

#[test]
fn every_angle_follows_the_reference_until_the_first_touchdown_or_the_horizon() {
    let mut report = Vec::new();
    for (name, r) in references() {
        let c = applied_fine(&r);
        let n = HORIZON_STEPS.min(c.first_touchdown.unwrap_or(usize::MAX));
        let (e, step, angle) = worst(&c, n);
        report.push(format!("{name}: {e:.4} rad ({angle}, step {step} of {n})"));
        assert!(
            e <= STEP_TOLERANCE,
            "{name}: {angle} is {e:.4} rad from the reference after step {step} \
             (tolerance {STEP_TOLERANCE} rad over the first {n} steps)\n{}",
            report.join("\n")
        );
    }
    println!("{}", report.join("\n"));
}

#[test]
fn the_first_touchdown_of_every_reference_happens_in_pada_within_one_step() {
    let mut seen = 0;
    for (name, r) in references() {
        let c = applied(&r);
        let Some(first) = c.touchdowns.first() else {
            continue;
        };
        seen += 1;
        let d = first.difference.unwrap_or_else(|| {
            panic!(
                "{name}: no touchdown of the {} foot near step {}",
                first.foot, first.reference_step
            )
        });
        assert!(
            d.abs() <= 1,
            "{name}: the {} foot touches down at step {} in pada, {} in the reference",
            first.foot,
            first.pada_step.unwrap_or(0),
            first.reference_step
        );
    }
    assert_eq!(seen, 5, "five references touch down before they fall");
}

#[test]
fn the_learned_drive_gives_the_learned_joints_the_references_voltages() {
    // Driven by the three learned voltages alone, pada's task maps them to
    // the stance hip, swing hip and swing knee of its own stance leg; as
    // long as both simulators stand on the same leg, those joints get
    // exactly the reference's voltages (the levels are within ±10.7 V, so
    // nothing is clipped).
    use pada::leo::task::{learned_joints, Leg};
    for (name, r) in references() {
        let c = compare(&r, Drive::Learned, ModelOptions::default()).expect("the model builds");
        let mut stance_left = true;
        for (s, rs) in c.steps.iter().zip(&r.steps) {
            let stance = if stance_left { Leg::Left } else { Leg::Right };
            for j in learned_joints(stance) {
                assert_eq!(
                    s.voltages[j as usize], rs.voltages[j as usize],
                    "{name}: step {}: {:?}",
                    s.step, j
                );
            }
            if s.pada_stance_left != s.reference_stance_left {
                break;
            }
            stance_left = s.reference_stance_left;
        }
    }
}
