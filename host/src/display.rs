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
    // One trial has no interval: say so, as fmt_estimate does, rather
    // than print "± NaN".
    match (mean.abs() >= 1e6, ci.is_finite()) {
        (true, true) => format!("{:.3e} ± {:.2e} s", mean, ci),
        (true, false) => format!("{:.3e} s (no interval)", mean),
        (false, true) => format!("{:.0} ± {:.0} s", mean, ci),
        (false, false) => format!("{:.0} s (no interval)", mean),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_mtbf_without_an_interval_says_so() {
        assert_eq!(fmt_mtbf(352.4, f64::NAN), "352 s (no interval)");
        assert_eq!(fmt_mtbf(352.4, 11.2), "352 ± 11 s");
        assert_eq!(fmt_mtbf(2.5e7, f64::NAN), "2.500e7 s (no interval)");
    }
}
