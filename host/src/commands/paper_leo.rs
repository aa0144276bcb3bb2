//! `pada paper leo`: Section VIII on the LEO model — report.md next to the
//! paper's numbers, Fig. 7-style learning curves and Fig. 8-style end
//! performance against MTBF.

use crate::console::outln;
use crate::commands::options::{check_seconds, set_threads};
use crate::commands::paper_args::PaperArgs;
use crate::display::{fmt_estimate, fmt_mtbf};
use crate::error::CliError;
use crate::experiment::algo::label;
use crate::output::OutDir;
use crate::experiment::algo::Algo;
use crate::paper::figure_data::{curves, figure_label, point};
use crate::paper::leo::{self, LeoOptions, LeoResults};
use crate::paper::objective::Objective;
use crate::plan::mode::obtain_with_bar;
use crate::plot::figures::{LearningCurves, Measure, PerformanceVsMtbf, SweepPoint};
use crate::plot::save;
use std::fmt::Write as _;

/// Default trials per configuration of `pada paper leo` (paper: 15).
pub const DEFAULT_TRIALS: u32 = 3;

/// Runs `pada paper leo`.
pub fn run(args: PaperArgs) -> Result<(), CliError> {
    let o = LeoOptions {
        trials: args.trials.unwrap_or(DEFAULT_TRIALS),
        seconds: check_seconds("--seconds", args.seconds.unwrap_or(leo::PAPER_SECONDS))?,
        seed: args.trial.seed,
    };
    let out = OutDir::check(
        &args
            .out
            .clone()
            .unwrap_or_else(|| "pada-out/paper-leo".into()),
    )?;
    let mode = args.cluster.mode(out.path())?;
    set_threads(args.trial.threads)?;
    let command = format!(
        "pada paper leo --trials {} --seconds {} --seed {}",
        o.trials, o.seconds, o.seed
    );
    let experiment = leo::experiment(&o, command.clone());
    let mut kept = None;
    let steps = leo::expected_steps(&o);
    let Some((per_config, timing)) = obtain_with_bar(&mode, &experiment, steps, "Section VIII (LEO)", |p| {
        let (r, best) = leo::run_local(&experiment, p)?;
        kept = Some(best);
        Ok(r)
    })?
    else {
        return Ok(());
    };
    let best = match (kept, mode.plan_dir()) {
        (Some(best), _) => best,
        (None, Some(dir)) => leo::best_of_plan(dir, &experiment, &per_config)?,
        (None, None) => leo::rerun_best(&experiment, &per_config)?,
    };
    let r = leo::assemble(&o, &experiment, per_config)?;
    let report = render(&r, &command);
    out.write_all(&[
        ("report.md".to_string(), report.clone().into_bytes()),
        (
            "summary.json".to_string(),
            (serde_json::to_string_pretty(&r).map_err(anyhow::Error::from)? + "\n").into_bytes(),
        ),
        ("timing.json".to_string(), timing.to_json()),
    ])?;
    draw(&r, &out)?;
    // The gait of the best learner of the whole run: its weights and 10 s
    // of its greedy policy as a strip, an animation and CSV.
    if let Some(mut b) = best {
        let policy = r.configs[b.config].policy;
        let task = crate::leo::rl::LeoTask::default();
        crate::weights::save(
            &out.path().join("best.weights"),
            crate::experiment::task::Task::spec(&task),
            policy,
            b.switched,
            &b.agent,
        )?;
        let (frames, fell) = crate::gait::record_agent(&mut b.agent, 10.0)?;
        let source = format!(
            "{}, trial {} (best end performance)",
            name(&r, b.config),
            b.trial
        );
        let title = crate::gait::gait_title(&source, &frames, fell);
        out.write_all(&crate::gait::gait_files(&frames, 12, &title)?)?;
        outln!("{title}")?;
    }
    outln!("{report}")?;
    outln!(
        "{:.0} s wall, {}, {:.0} environment steps/s",
        timing.wall_s,
        timing.workers(),
        timing.env_steps_per_s
    )?;
    outln!(
        "wrote {}/report.md, the figures, best.weights and the gait (gait.svg/png, gait-animation.svg)",
        out.path().display()
    )?;
    Ok(())
}

fn name(r: &LeoResults, i: usize) -> String {
    let c = &r.configs[i];
    if r.switched[i] {
        format!(
            "{}, switch at {:.0} s",
            label(&c.policy),
            r.options.seconds / 2.0
        )
    } else {
        label(&c.policy)
    }
}

/// The report: the table next to the paper's numbers.
pub fn render(r: &LeoResults, command: &str) -> String {
    let sarsa = &r.configs[0].summary;
    let obj = Objective::from_sarsa(&sarsa.end_performance, &sarsa.rise_time_s, &sarsa.mtbf_s);
    let mut s = String::new();
    let _ = writeln!(s, "# Section VIII on the LEO model\n");
    let _ = writeln!(s, "Command: `{command}`\n");
    let _ = writeln!(
        s,
        "Scale: {} trials × {} s of learning per configuration (paper: {} trials × {} s), {} configurations, {} environment steps. (Wall time and threads: timing.json; this report depends only on the command, so a run merged from a cluster's results gives the same bytes.)\n",
        r.options.trials,
        r.options.seconds,
        leo::PAPER_TRIALS,
        leo::PAPER_SECONDS,
        r.configs.len(),
        r.env_steps,
    );
    let _ = writeln!(
        s,
        "Paper: SARSA(λ) end performance {} ± {}, MTBF {} s; PADA and low-pass with the switch back to SARSA(λ) at 7,333 s reach ≈ {} s (×108) with end performance near SARSA(λ)'s (objective: above 1441). pada's reward scale and model differ (rapier3d, not ODE): compare ratios and shapes.\n",
        leo::PAPER_SARSA_END.0, leo::PAPER_SARSA_END.1, leo::PAPER_SARSA_MTBF_S, leo::PAPER_FILTERED_MTBF_S
    );
    let _ = writeln!(
        s,
        "Objective from this run's SARSA(λ) (Section VI rule): end performance above {:.1}.\n",
        obj.end_threshold
    );
    let _ = writeln!(s, "| configuration | end performance | MTBF, the paper's (1200 actions) | × SARSA | physical MTBF | × SARSA | walked, last 10% of tests | walking trials (≥ 1 m) | speed | learning falls / trial |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|---|");
    for (i, c) in r.configs.iter().enumerate() {
        let m = &c.summary;
        let w = m
            .end_walked_m
            .unwrap_or_else(|| crate::stats::Estimate::of(&[]));
        let v = m
            .end_speed_m_s
            .unwrap_or_else(|| crate::stats::Estimate::of(&[]));
        let walking = m.per_trial.iter().filter(|t| t.end_walked_m.is_some_and(|w| w >= 1.0)).count();
        let _ = writeln!(
            s,
            "| {} | {} | {} | ×{:.2} | {} | ×{:.2} | {} | {} of {} | {} | {:.0} |",
            name(r, i),
            fmt_estimate(m.end_performance.mean, m.end_performance.ci95, 1, ""),
            fmt_mtbf(m.mtbf_s.mean, m.mtbf_s.ci95),
            m.mtbf_s.mean / sarsa.mtbf_s.mean,
            fmt_mtbf(m.physical_mtbf_s.mean, m.physical_mtbf_s.ci95),
            m.physical_mtbf_s.mean / sarsa.physical_mtbf_s.mean,
            fmt_estimate(w.mean, w.ci95, 2, " m"),
            walking,
            m.per_trial.len(),
            fmt_estimate(v.mean, v.ci95, 3, " m/s"),
            m.learning_falls.mean
        );
    }
    let _ = writeln!(
        s,
        "\nBoth MTBFs are predicted from the first 1200 learning actions (40 s), before any switch (the switch only changes the end performance), per physical gearbox (both hips, both knees; the robot's is the weakest gearbox's). **The paper's** (Section IV) takes T_m from the commanded action, linear in the voltage: the RX-28's stall torque of the commanded voltage (0.167 N·m/V). **The physical** one takes the rapier3d model's mean gear torque over each control step, back-EMF included. The figures use the paper's. Figures: `fig7-learning-curves.svg/png`, `fig8-end-vs-mtbf.svg/png` (without switch), `fig8-end-vs-mtbf-switch.svg/png` (with)."
    );
    s
}

/// The filtered configurations that Fig. 7 shows beside SARSA(λ): the
/// paper's shows a PADA and a low-pass filter, both switching back to
/// SARSA(λ) at half the run, "which both have the same MTBF". Of the
/// switching PADA and low-pass configurations this picks the pair whose
/// MTBFs are closest in ratio.
fn equal_mtbf_pair(r: &LeoResults) -> Option<(usize, usize)> {
    let of = |algo: Algo| {
        (0..r.configs.len())
            .filter(move |&i| r.switched[i] && r.configs[i].algo() == algo)
            .filter(|&i| r.configs[i].summary.mtbf_s.mean.is_finite())
    };
    of(Algo::Pada)
        .flat_map(|p| of(Algo::LowPass).map(move |l| (p, l)))
        .min_by(|a, b| {
            let gap = |(p, l): (usize, usize)| {
                (r.configs[p].summary.mtbf_s.mean / r.configs[l].summary.mtbf_s.mean)
                    .ln()
                    .abs()
            };
            gap(*a).total_cmp(&gap(*b))
        })
}

fn draw(r: &LeoResults, out: &OutDir) -> anyhow::Result<()> {
    let dir = out.path();
    let sarsa = &r.configs[0].summary;
    let obj = Objective::from_sarsa(&sarsa.end_performance, &sarsa.rise_time_s, &sarsa.mtbf_s);
    let mut shown = vec![0];
    let mut title = "Fig. 7 — LEO learning curves".to_string();
    if let Some((p, l)) = equal_mtbf_pair(r) {
        shown.extend([p, l]);
        let _ = write!(
            title,
            ", PADA and low-pass at about equal MTBF ({:.0} s, {:.0} s)",
            r.configs[p].summary.mtbf_s.mean,
            r.configs[l].summary.mtbf_s.mean
        );
    }
    let all = curves(&r.configs, |_| true);
    let curve_set: Vec<_> = shown
        .iter()
        .map(|&i| {
            let mut c = all[i].clone();
            c.label = format!(
                "{}{}, MTBF {:.0} s",
                figure_label(&r.configs[i].policy),
                if r.switched[i] { ", switching back" } else { "" },
                r.configs[i].summary.mtbf_s.mean
            );
            c
        })
        .collect();
    save(
        &LearningCurves {
            title,
            curves: curve_set,
            sarsa_end: sarsa.end_performance.mean,
            sarsa_rise_s: sarsa.rise_time_s.mean,
            switch_at_s: (shown.len() > 1).then_some(r.options.seconds / 2.0),
        },
        dir,
        "fig7-learning-curves",
    )?;
    for (switch, stem, title) in [
        (
            false,
            "fig8-end-vs-mtbf",
            "Fig. 8 — LEO end performance against MTBF (no switch)",
        ),
        (
            true,
            "fig8-end-vs-mtbf-switch",
            "Fig. 8 — LEO end performance against MTBF (switch back at half)",
        ),
    ] {
        let points: Vec<SweepPoint> = r
            .configs
            .iter()
            .enumerate()
            .filter(|(i, _)| *i == 0 || r.switched[*i] == switch)
            .map(|(_, c)| point(c))
            .collect();
        save(
            &PerformanceVsMtbf {
                title: title.into(),
                measure: Measure::EndPerformance,
                points,
                threshold: obj.end_threshold,
                sarsa_mtbf_s: sarsa.mtbf_s.mean,
            },
            dir,
            stem,
        )?;
    }
    Ok(())
}
