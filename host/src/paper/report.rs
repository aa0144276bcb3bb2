//! `report.md` of `pada paper pendulum`: pada's numbers next to the
//! paper's, with the differences spelled out.

use super::numbers::*;
use super::pendulum::{ConfigResult, PendulumResults};
use crate::experiment::algo::{label, parameter_of, Algo};
use crate::stats::Estimate;
use std::fmt::Write;

/// The figure files, `(stem, caption)`.
pub const FIGURES: [(&str, &str); 5] = [
    (
        "fig3-mtbf",
        "Fig. 3: predicted MTBF against α or Δ (simulated pendulum)",
    ),
    (
        "fig4-end-performance",
        "Fig. 4: end performance against MTBF (simulated pendulum)",
    ),
    (
        "fig5-rise-time",
        "Fig. 5: rise time against MTBF (simulated pendulum)",
    ),
    (
        "fig6-physical-curves",
        "Fig. 6: learning curves on the physical pendulum's model",
    ),
    (
        "fig6-simulated-curves",
        "Fig. 6 style: learning curves on the simulated pendulum",
    ),
];

fn pm(e: &Estimate, digits: usize) -> String {
    if !e.mean.is_finite() {
        return "∞".into();
    }
    if e.ci95.is_finite() {
        format!("{:.*} ± {:.*}", digits, e.mean, digits, e.ci95)
    } else {
        format!("{:.*}", digits, e.mean)
    }
}

fn pm_sci(e: &Estimate) -> String {
    if !e.mean.is_finite() {
        return "∞".into();
    }
    if e.ci95.is_finite() {
        format!("{:.3e} ± {:.1e}", e.mean, e.ci95)
    } else {
        format!("{:.3e}", e.mean)
    }
}

fn published(p: &Published, digits: usize) -> String {
    match p.ci95 {
        Some(c) => format!("{:.*} ± {:.*}", digits, p.mean, digits, c),
        None => format!("{:.*}", digits, p.mean),
    }
}

/// `pada − paper` and its share of the paper's magnitude.
fn diff(pada: f64, paper: f64, digits: usize) -> String {
    let d = pada - paper;
    format!("{:+.*} ({:+.1}%)", digits, d, 100.0 * d / paper.abs())
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn find(cs: &[ConfigResult], algo: Algo, param: Option<f32>) -> Option<&ConfigResult> {
    cs.iter()
        .find(|c| c.algo() == algo && parameter_of(&c.policy) == param)
}

/// The report as Markdown. `command` is the command line that produced it.
pub fn render(r: &PendulumResults, command: &str) -> String {
    let mut s = String::new();
    let o = &r.options;
    let sarsa = &r.simulated[0].summary;
    let _ = writeln!(
        s,
        "# The pendulum experiments of Section VII, reproduced by pada\n"
    );
    let _ = writeln!(
        s,
        "Produced by `{command}`: {} configurations × {} trials × {} s of learning on the simulated pendulum, \
         {} configurations × {} trials × {} s on the physical pendulum's model (master seed {}); \
         {:.2e} environment steps. (The run's wall time and threads are in timing.json: this report depends \
         only on the command, so a run merged from a cluster's results gives the same bytes as a local run.)\n",
        r.simulated.len(),
        o.sim_trials,
        o.sim_seconds,
        r.physical.len(),
        o.phys_trials,
        o.phys_seconds,
        o.seed,
        r.env_steps as f64,
    );
    let _ = writeln!(
        s,
        "Every mean is over trials with its Student-t 95% confidence half-width. End performance: mean return of \
         the last 10% of greedy test runs; rise time: learning time of the first test run that covers 95% of the \
         way from the first test run to the end performance (Section VI); MTBF: predicted from the first 1200 \
         learning actions with Eqs. 3–7 and Table I.\n"
    );

    // --- SARSA baseline -------------------------------------------------------
    let _ = writeln!(s, "## SARSA(λ) on the simulated pendulum\n");
    let _ = writeln!(
        s,
        "| measure | paper | pada | pada − paper |\n|---|---|---|---|"
    );
    for (measure, paper, ours) in [
        ("end performance", &SIM_SARSA_END, &sarsa.end_performance),
        ("rise time [s]", &SIM_SARSA_RISE_S, &sarsa.rise_time_s),
        ("MTBF [s]", &SIM_SARSA_MTBF_S, &sarsa.mtbf_s),
    ] {
        let (theirs, mine, gap) = (published(paper, 0), pm(ours, 0), diff(ours.mean, paper.mean, 0));
        let _ = writeln!(s, "| {measure} | {theirs} | {mine} | {gap} |");
    }
    let _ = writeln!(
        s,
        "| backlash re-engagements in the first 1200 actions | – | {} | |\n",
        pm(&sarsa.window_reengagements, 1)
    );

    // --- objective ------------------------------------------------------------
    let obj = &r.objective;
    let _ = writeln!(s, "## The objective\n");
    let _ = writeln!(
        s,
        "Derived from SARSA(λ) with the paper's arithmetic (end: mean − 33%·|mean| + CI; rise: 1.33·mean − CI, \
         which is how the paper gets −1093 and 839 s from −851 ± 39 and 681 ± 67 s). An algorithm meets the \
         objective when its whole 95% interval lies above the end-performance threshold and below the rise-time \
         threshold, and its MTBF interval lies above SARSA(λ)'s.\n"
    );
    let _ = writeln!(s, "| threshold | paper | pada |\n|---|---|---|");
    let _ = writeln!(
        s,
        "| end performance above | {SIM_END_THRESHOLD:.0} | {:.0} |",
        obj.end_threshold
    );
    let _ = writeln!(
        s,
        "| rise time below [s] | {SIM_RISE_THRESHOLD_S:.0} | {:.0} |\n",
        obj.rise_threshold_s
    );

    // --- all configurations ---------------------------------------------------
    let _ = writeln!(
        s,
        "## All algorithms on the simulated pendulum (Figs. 3–5)\n"
    );
    let _ = writeln!(
        s,
        "| algorithm | MTBF [s] | × SARSA(λ) | re-engagements | end performance | rise time [s] | end ok | rise ok | MTBF up | meets objective |\n\
         |---|---|---|---|---|---|---|---|---|---|"
    );
    for (i, (c, v)) in r.simulated.iter().zip(&r.verdicts).enumerate() {
        let m = &c.summary;
        let verdicts = if i == 0 {
            "baseline | baseline | baseline | baseline".to_string()
        } else {
            format!(
                "{} | {} | {} | **{}**",
                yes(v.end_ok),
                yes(v.rise_ok),
                yes(v.mtbf_up),
                yes(v.meets())
            )
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {} | {} | {} | {} |",
            label(&c.policy),
            pm(&m.mtbf_s, 0),
            m.mtbf_s.mean / sarsa.mtbf_s.mean,
            pm(&m.window_reengagements, 0),
            pm(&m.end_performance, 0),
            pm(&m.rise_time_s, 0),
            verdicts
        );
    }
    let _ = writeln!(s);
    for (stem, caption) in &FIGURES[..3] {
        let _ = writeln!(s, "![{caption}]({stem}.png)\n");
    }

    // --- the paper's claim ----------------------------------------------------
    let _ = writeln!(s, "### The paper's conclusion, checked\n");
    let _ = writeln!(
        s,
        "The paper: the low-pass filter with α ≥ {SIM_LOWPASS_ALPHA} and PADA with Δ = {SIM_PADA_DELTA} meet the \
         objective, both with about {SIM_MTBF_FACTOR:.0}× SARSA(λ)'s MTBF; the plain integrating controller misses \
         the end performance and both Markov variants miss the rise time.\n"
    );
    for (algo, p) in [
        (Algo::LowPass, SIM_LOWPASS_ALPHA),
        (Algo::Pada, SIM_PADA_DELTA),
    ] {
        if let Some(i) = r
            .simulated
            .iter()
            .position(|c| c.algo() == algo && parameter_of(&c.policy) == Some(p))
        {
            let c = &r.simulated[i];
            let v = r.verdicts[i];
            let _ = writeln!(
                s,
                "- pada, {}: MTBF {:.2}× SARSA(λ)'s (paper: about 2×); end performance {} (threshold {:.0}), \
                 rise time {} s (threshold {:.0} s): {}.",
                label(&c.policy),
                c.summary.mtbf_s.mean / sarsa.mtbf_s.mean,
                pm(&c.summary.end_performance, 0),
                obj.end_threshold,
                pm(&c.summary.rise_time_s, 0),
                obj.rise_threshold_s,
                if v.meets() { "meets the objective" } else { "does **not** meet the objective" }
            );
        }
    }
    let meeting: Vec<String> = r
        .simulated
        .iter()
        .zip(&r.verdicts)
        .skip(1)
        .filter(|(_, v)| v.meets())
        .map(|(c, _)| label(&c.policy))
        .collect();
    let _ = writeln!(
        s,
        "- Configurations that meet the objective in this run: {}.\n",
        if meeting.is_empty() {
            "none".to_string()
        } else {
            meeting.join(", ")
        }
    );

    // --- physical pendulum ----------------------------------------------------
    let _ = writeln!(s, "## The physical pendulum (Fig. 6)\n");
    let _ = writeln!(
        s,
        "The model of docs/reference/grl.md §4 stands in for the real pendulum. Gearbox torque = voltage × K/R = 5.642·10⁻³ N·m/V \
         (the motor's stall torque per volt; the paper assumes a linear voltage-to-torque relation and LEO's \
         gearbox of Table I).\n"
    );
    let _ = writeln!(
        s,
        "| algorithm | MTBF paper [s] | MTBF pada [s] | pada / paper | × SARSA(λ) paper | × SARSA(λ) pada | end performance | rise time [s] |\n\
         |---|---|---|---|---|---|---|---|"
    );
    let phys_sarsa = &r.physical[0].summary;
    for c in &r.physical {
        let paper = match c.algo() {
            Algo::Sarsa => PHYS_SARSA_MTBF_S,
            Algo::LowPass => PHYS_LOWPASS_MTBF_S,
            _ => PHYS_PADA_MTBF_S,
        };
        let m = &c.summary;
        let _ = writeln!(
            s,
            "| {} | {:.3e} | {} | {:.2} | {:.2} | {:.2} | {} | {} |",
            label(&c.policy),
            paper,
            pm_sci(&m.mtbf_s),
            m.mtbf_s.mean / paper,
            paper / PHYS_SARSA_MTBF_S,
            m.mtbf_s.mean / phys_sarsa.mtbf_s.mean,
            pm(&m.end_performance, 0),
            pm(&m.rise_time_s, 0)
        );
    }
    let _ = writeln!(s);
    for (stem, caption) in &FIGURES[3..] {
        let _ = writeln!(s, "![{caption}]({stem}.png)\n");
    }

    // --- differences ----------------------------------------------------------
    let _ = writeln!(
        s,
        "## Where pada differs from the paper, and why it might\n"
    );
    let rel = |a: f64, b: f64| 100.0 * (a - b) / b.abs();
    let _ = writeln!(
        s,
        "- SARSA(λ) end performance {:.0} against the paper's {:.0} ({:+.1}%), rise time {:.0} s against {:.0} s \
         ({:+.1}%), MTBF {:.0} s against {:.0} s ({:+.1}%).",
        sarsa.end_performance.mean,
        SIM_SARSA_END.mean,
        rel(sarsa.end_performance.mean, SIM_SARSA_END.mean),
        sarsa.rise_time_s.mean,
        SIM_SARSA_RISE_S.mean,
        rel(sarsa.rise_time_s.mean, SIM_SARSA_RISE_S.mean),
        sarsa.mtbf_s.mean,
        SIM_SARSA_MTBF_S.mean,
        rel(sarsa.mtbf_s.mean, SIM_SARSA_MTBF_S.mean)
    );
    if let (Some(lp), Some(pd)) = (
        find(&r.physical, Algo::LowPass, Some(0.834)),
        find(&r.physical, Algo::Pada, Some(0.5)),
    ) {
        let _ = writeln!(
            s,
            "- Physical pendulum MTBF: pada/paper = {:.2} (SARSA(λ)), {:.2} (low-pass), {:.2} (PADA); the ratios to \
             SARSA(λ) are {:.2} and {:.2} against the paper's {:.2} and {:.2}.",
            phys_sarsa.mtbf_s.mean / PHYS_SARSA_MTBF_S,
            lp.summary.mtbf_s.mean / PHYS_LOWPASS_MTBF_S,
            pd.summary.mtbf_s.mean / PHYS_PADA_MTBF_S,
            lp.summary.mtbf_s.mean / phys_sarsa.mtbf_s.mean,
            pd.summary.mtbf_s.mean / phys_sarsa.mtbf_s.mean,
            PHYS_LOWPASS_MTBF_S / PHYS_SARSA_MTBF_S,
            PHYS_PADA_MTBF_S / PHYS_SARSA_MTBF_S
        );
    }
    let _ = writeln!(
        s,
        "- The paper does not state the episode length, tile widths, number of tilings, initial weights, test-run \
         interval or learning time per trial. pada uses 3 s episodes, 16 tilings of 20 angle tiles × π rad/s, \
         weights U[0, 1], a test run every 10 learning episodes and {} s (physical: {} s) of learning; the end \
         performance scales with the episode length and the rise time with the learning time, so both depend on \
         these choices. A hand-written energy-pumping swing-up controller scores −864 on a 3 s episode \
         (a unit test of `sim/src/pendulum/simulated.rs`), close to the paper's −851, which supports the 3 s \
         choice.",
        o.sim_seconds,
        o.phys_seconds
    );
    let _ = writeln!(
        s,
        "- The MTBF is set by the exploration of the first 1200 actions (60 s): the number of sign changes of the \
         torque depends on how optimistic the initial weights are relative to the returns and on how the greedy \
         choice flips between actions. The paper's 1596 s corresponds to about 283 re-engagements at 1.5 N·m in \
         1200 actions; pada sees {:.0}.",
        sarsa.window_reengagements.mean
    );
    let _ = writeln!(
        s,
        "- The rise time is read off single greedy test runs, whose returns jump when a learned swing-up starts or \
         stops working; its first-crossing definition makes it sensitive to one lucky early run, which widens its \
         interval."
    );
    let _ = writeln!(
        s,
        "- The simulated pendulum uses the paper's 0.048 kg·m² as given; a point mass of 2 kg at 0.2 m would have \
         0.08 kg·m². The physical pendulum is a model (GRL's constants), not the real setup, and is integrated \
         with RK4 at 10 sub-steps per 0.03 s."
    );
    s
}
