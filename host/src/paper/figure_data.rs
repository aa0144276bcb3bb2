//! Paper results as the inputs of the figures: sweep points and labelled
//! learning curves, shared by the pendulum and LEO reports.

use super::pendulum::ConfigResult;
use crate::experiment::algo::{algo_of, label, parameter_of};
use crate::plot::figures::{Curve, SweepPoint};

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
            label: label(&c.policy),
            algo: algo_of(&c.policy),
            points: c.curve.clone(),
        })
        .collect()
}
