//! Paper results as the inputs of the figures: sweep points and labelled
//! learning curves, shared by the pendulum and LEO reports.

use super::pendulum::ConfigResult;
use crate::experiment::algo::{algo_of, label_with, parameter_of};
use crate::plot::figures::{Curve, SweepPoint};
use crate::plot::legend::parameter_text;
use pada_core::policy::PolicyKind;

/// A configuration's name in a figure's key: `pada Δ=1/6`, `lowpass α=0.2`.
pub fn figure_label(policy: &PolicyKind) -> String {
    label_with(policy, |v| parameter_text(f64::from(v)))
}

/// A configuration's summary as a point of the sweep figures (Figs. 3–5, 8).
pub fn point(c: &ConfigResult) -> SweepPoint {
    SweepPoint {
        algo: c.algo(),
        param: parameter_of(&c.policy).unwrap_or(1.0) as f64,
        mtbf_s: c.summary.mtbf_s,
        end: c.summary.end_performance,
        rise_s: c.summary.rise_time_s,
    }
}

/// The learning curves of the configurations `pick` keeps, labelled.
pub fn curves(cs: &[ConfigResult], pick: impl Fn(&ConfigResult) -> bool) -> Vec<Curve> {
    cs.iter()
        .filter(|c| pick(c))
        .map(|c| Curve {
            label: figure_label(&c.policy),
            algo: algo_of(&c.policy),
            points: c.curve.clone(),
        })
        .collect()
}
