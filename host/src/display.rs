//! Numbers for the terminal and reports: an estimate with its confidence
//! interval, an MTBF in a readable scale. Shared by every command that
//! prints results.

/// `mean ± ci` with `digits` decimals, `n/a` for a missing interval.
pub fn fmt_estimate(mean: f64, ci: f64, digits: usize, unit: &str) -> String {
    if !mean.is_finite() {
        return format!("{mean}{unit}");
    }
    if ci.is_finite() {
        format!("{mean:.digits$} ± {ci:.digits$}{unit}")
    } else {
        format!("{mean:.digits$}{unit} (no interval)")
    }
}

/// An MTBF in seconds: plain below 10⁶ s, scientific above.
pub fn fmt_mtbf(mean: f64, ci: f64) -> String {
    if !mean.is_finite() {
        return "infinite (no re-engagement in the window)".to_string();
    }
    let ci_s = |c: f64| if c.is_finite() { c } else { f64::NAN };
    if mean.abs() >= 1e6 {
        format!("{:.3e} ± {:.2e} s", mean, ci_s(ci))
    } else {
        format!("{:.0} ± {:.0} s", mean, ci_s(ci))
    }
}
