//! The page's four plots, drawn by plotters as SVG on the server (the
//! same library and style as `pada paper`'s figures), so the page needs no
//! script library and works offline:
//!
//! - [`ReturnsPlot`]: test returns against learning time, the
//!   end-performance window (the last ⌈n/10⌉ test runs, Section VI) shaded
//!   and its mean dashed;
//! - [`DamagePlot`]: damage J per gearbox against time (Eq. 7);
//! - [`ReengagementsPlot`]: backlash re-engagements per gearbox;
//! - [`EpisodePlot`]: the last episode's applied output per joint, with the
//!   steps where a gearbox re-engaged marked.
//!
//! Each key is a strip under its plot ([`crate::plot::legend`]), so that
//! it never covers a point.

use super::state::WatchState;
use crate::plot::figures::lin_range;
use crate::plot::legend::{self, Entry, Mark};
use crate::plot::{plot_err, Figure, FONT};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Pixel size of each plot.
pub const SIZE: (u32, u32) = (620, 340);

/// A colour per joint.
pub fn joint_color(i: usize) -> RGBColor {
    const C: [RGBColor; 4] = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
    ];
    C[i % C.len()]
}

/// The key of per-joint curves: one solid line per joint, in its colour.
fn joint_key(joints: usize) -> Vec<Entry> {
    (0..joints).map(|i| Entry { label: format!("joint {i}"), color: joint_color(i), mark: Mark::Line }).collect()
}

/// A tick label: scientific outside 0.01..10⁴, else at most three
/// decimals without trailing zeros.
fn tick(v: f64) -> String {
    if v != 0.0 && (v.abs() >= 1e4 || v.abs() < 1e-2) {
        return format!("{v:.1e}");
    }
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.to_string()
    }
}

/// Draws "waiting for …" where a plot has nothing yet.
fn empty<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    note: &str,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_err)?;
    root.titled(title, (FONT, 18)).map_err(plot_err)?;
    let (w, h) = root.dim_in_pixel();
    root.draw(&Text::new(
        note.to_string(),
        (w as i32 / 2 - 120, h as i32 / 2),
        (FONT, 15).into_font().color(&RGBColor(110, 110, 110)),
    ))
    .map_err(plot_err)?;
    Ok(())
}

/// Test returns against learning time.
pub struct ReturnsPlot<'a>(pub &'a WatchState);

impl Figure for ReturnsPlot<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let l = &self.0.learning;
        let title = "Test returns";
        if l.curve.is_empty() {
            return empty(root, title, "waiting for the first test run");
        }
        root.fill(&WHITE).map_err(plot_err)?;
        let k = l.end_window_runs.min(l.curve.len());
        let window = l.end_performance.filter(|_| k > 0);
        let (shade, dash) = (RGBColor(255, 200, 80), RGBColor(200, 120, 0));
        let key: Vec<Entry> = window
            .map(|end| {
                vec![
                    Entry { label: format!("end-performance window ({k} runs)"), color: shade, mark: Mark::Band },
                    Entry { label: format!("end performance {end:.1}"), color: dash, mark: Mark::Dashed },
                ]
            })
            .unwrap_or_default();
        let (area, key_area) = legend::split(root, key.len());
        let x = lin_range(l.curve.iter().map(|p| p.learning_time_s).chain([0.0]));
        let y = lin_range(l.curve.iter().map(|p| p.test_return));
        let mut chart = ChartBuilder::on(&area)
            .caption(title, (FONT, 18))
            .margin(8)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .x_desc("learning time [s]")
            .y_desc("return")
            .label_style((FONT, 12))
            .axis_desc_style((FONT, 13))
            .draw()
            .map_err(plot_err)?;
        if let Some(end) = window {
            let from = l.curve[l.curve.len() - k].learning_time_s;
            let to = l.curve[l.curve.len() - 1].learning_time_s;
            // At least a few pixels wide, so one test run's window shows.
            let w = ((x.end - x.start) * 0.004).max(to - from);
            chart
                .draw_series([Rectangle::new(
                    [(to - w, y.start), (to, y.end)],
                    shade.mix(legend::BAND_ALPHA).filled(),
                )])
                .map_err(plot_err)?;
            let (dash_px, gap_px) = Mark::Dashed.dashes().unwrap_or((6, 4));
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(x.start, end), (x.end, end)],
                    dash_px,
                    gap_px,
                    dash.stroke_width(2),
                ))
                .map_err(plot_err)?;
        }
        let black = RGBColor(0, 0, 0);
        chart
            .draw_series(LineSeries::new(
                l.curve.iter().map(|p| (p.learning_time_s, p.test_return)),
                black.stroke_width(2),
            ))
            .map_err(plot_err)?;
        chart
            .draw_series(
                l.curve
                    .iter()
                    .map(|p| Circle::new((p.learning_time_s, p.test_return), 2, black.filled())),
            )
            .map_err(plot_err)?;
        legend::draw(&key_area, &key)
    }
}

/// Damage J per gearbox against time.
pub struct DamagePlot<'a>(pub &'a WatchState);

impl Figure for DamagePlot<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        fatigue_plot(
            root,
            self.0,
            "Damage J per gearbox (Eq. 7)",
            "damage J",
            |p, i| p.damage[i],
        )
    }
}

/// Backlash re-engagements per gearbox against time.
pub struct ReengagementsPlot<'a>(pub &'a WatchState);

impl Figure for ReengagementsPlot<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        fatigue_plot(
            root,
            self.0,
            "Backlash re-engagements per gearbox",
            "re-engagements",
            |p, i| p.reengagements[i] as f64,
        )
    }
}

fn fatigue_plot<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    s: &WatchState,
    title: &str,
    y_desc: &str,
    value: fn(&super::state::FatiguePoint, usize) -> f64,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let h = &s.fatigue.history;
    let n = s.joint_count();
    if h.pushed == 0 || n == 0 {
        return empty(root, title, "waiting for the first step");
    }
    root.fill(&WHITE).map_err(plot_err)?;
    let (area, key_area) = legend::split(root, n);
    let x = lin_range(h.with_last().map(|p| p.time_s));
    // Counters only grow from 0: the axis starts at 0 exactly.
    let top = h
        .with_last()
        .flat_map(|p| (0..n).map(move |i| value(p, i)))
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let y = 0.0..if top > 0.0 { top * 1.06 } else { 1.0 };
    let mut chart = ChartBuilder::on(&area)
        .caption(title, (FONT, 18))
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(72)
        .build_cartesian_2d(x, y)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .x_desc("time since boot [s]")
        .y_desc(y_desc)
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .draw()
        .map_err(plot_err)?;
    for i in 0..n {
        let c = joint_color(i);
        chart
            .draw_series(LineSeries::new(
                h.with_last().map(|p| (p.time_s, value(p, i))),
                c.stroke_width(2),
            ))
            .map_err(plot_err)?;
    }
    legend::draw(&key_area, &joint_key(n))
}

/// The last episode's applied output per joint.
pub struct EpisodePlot<'a>(pub &'a WatchState);

impl Figure for EpisodePlot<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let title = "Last episode: applied action per joint";
        let Some(e) = &self.0.last_episode else {
            return empty(root, title, "waiting for the first episode's end");
        };
        let dims = e.steps.iter().map(|s| s.output.len()).max().unwrap_or(0);
        if dims == 0 {
            return empty(root, title, "the last episode had no actions");
        }
        root.fill(&WHITE).map_err(plot_err)?;
        let (area, key_area) = legend::split(root, dims);
        let caption = format!(
            "Last episode ({} {}{}): applied action per joint",
            e.mode,
            e.episode,
            e.total_return
                .map(|r| format!(", return {r:.1}"))
                .unwrap_or_default()
        );
        let x = lin_range(e.steps.iter().map(|s| s.t_s).chain([0.0]));
        let y = lin_range(
            e.steps
                .iter()
                .flat_map(|s| s.output.iter().map(|&v| v as f64)),
        );
        let mut chart = ChartBuilder::on(&area)
            .caption(caption, (FONT, 16))
            .margin(8)
            .x_label_area_size(40)
            .y_label_area_size(64)
            .build_cartesian_2d(x, y)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .x_desc("time in the episode [s]")
            .y_desc("applied output (torque or voltage)")
            .label_style((FONT, 12))
            .axis_desc_style((FONT, 13))
            .draw()
            .map_err(plot_err)?;
        for i in 0..dims {
            let c = joint_color(i);
            // Held for the whole control period: a staircase.
            let mut pts = Vec::with_capacity(e.steps.len() * 2);
            let mut prev: Option<f64> = None;
            for s in &e.steps {
                let Some(&v) = s.output.get(i) else { continue };
                if let Some(p) = prev {
                    pts.push((s.t_s, p));
                }
                pts.push((s.t_s, v as f64));
                prev = Some(v as f64);
            }
            chart
                .draw_series(LineSeries::new(pts, c.stroke_width(2)))
                .map_err(plot_err)?;
            let marks: Vec<(f64, f64)> = e
                .steps
                .windows(2)
                .filter(|w| w[1].reengaged.get(i).copied().unwrap_or(false))
                .filter_map(|w| w[0].output.get(i).map(|&v| (w[1].t_s, v as f64)))
                .collect();
            chart
                .draw_series(
                    marks
                        .into_iter()
                        .map(|p| Circle::new(p, 4, c.stroke_width(2))),
                )
                .map_err(plot_err)?;
        }
        legend::draw(&key_area, &joint_key(dims))
    }
}
