//! The page's four plots, drawn by plotters as SVG on the server (the
//! same library and style as `pada paper`'s figures), so the page needs no
//! script library and works offline:
//!
//! - [`ReturnsPlot`]: test returns against learning time, the
//!   end-performance window (the last ⌈n/10⌉ test runs, Section VI) shaded
//!   and its mean dashed;
//! - [`FatiguePlot`]: damage J per gearbox against time (Eq. 7), or
//!   backlash re-engagements per gearbox;
//! - [`EpisodePlot`]: the last episode's applied output per joint, with the
//!   steps where a gearbox re-engaged marked.
//!
//! Each key is a strip under its plot ([`crate::plot::legend`]), so that
//! it never covers a point.

use super::state::WatchState;
use crate::plot::figures::lin_range;
use crate::plot::legend::{self, Entry, Mark};
use crate::plot::{plot_err, Figure, FONT};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use std::ops::Range;
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

/// The axes of every plot of the page: its caption, the ranges, the
/// tick labels of [`tick`] and the axis descriptions.
struct Axes<'t> {
    caption: &'t str,
    caption_px: u32,
    /// Width of the y labels' area \[px\] (wide enough for its ticks).
    y_label_px: u32,
    x_desc: &'t str,
    y_desc: &'t str,
}

impl Axes<'_> {
    fn draw<'a, DB: DrawingBackend>(
        &self,
        area: &'a DrawingArea<DB, Shift>,
        x: Range<f64>,
        y: Range<f64>,
    ) -> anyhow::Result<ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>>
    where
        DB::ErrorType: 'static,
    {
        let mut chart = ChartBuilder::on(area)
            .caption(self.caption, (FONT, self.caption_px))
            .margin(8)
            .x_label_area_size(40)
            .y_label_area_size(self.y_label_px)
            .build_cartesian_2d(x, y)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .x_desc(self.x_desc)
            .y_desc(self.y_desc)
            .label_style((FONT, 12))
            .axis_desc_style((FONT, 13))
            .draw()
            .map_err(plot_err)?;
        Ok(chart)
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
        let axes = Axes { caption: title, caption_px: 18, y_label_px: 64, x_desc: "learning time [s]", y_desc: "return" };
        let mut chart = axes.draw(&area, x.clone(), y.clone())?;
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

/// A fatigue counter's quantity per gearbox against time: damage J
/// ([`FatiguePlot::damage`], Eq. 7) or backlash re-engagements
/// ([`FatiguePlot::reengagements`]).
pub struct FatiguePlot<'a> {
    state: &'a WatchState,
    title: &'static str,
    y_desc: &'static str,
    value: fn(&super::state::FatiguePoint, usize) -> f64,
}

impl<'a> FatiguePlot<'a> {
    /// Damage J per gearbox (Eq. 7).
    pub fn damage(state: &'a WatchState) -> Self {
        FatiguePlot { state, title: "Damage J per gearbox (Eq. 7)", y_desc: "damage J", value: |p, i| p.damage[i] }
    }

    /// Backlash re-engagements per gearbox.
    pub fn reengagements(state: &'a WatchState) -> Self {
        FatiguePlot {
            state,
            title: "Backlash re-engagements per gearbox",
            y_desc: "re-engagements",
            value: |p, i| p.reengagements[i] as f64,
        }
    }
}

impl Figure for FatiguePlot<'_> {
    fn size(&self) -> (u32, u32) {
        SIZE
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        fatigue_plot(root, self.state, self.title, self.y_desc, self.value)
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
    let axes = Axes { caption: title, caption_px: 18, y_label_px: 72, x_desc: "time since boot [s]", y_desc };
    let mut chart = axes.draw(&area, x, y)?;
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
        let axes = Axes {
            caption: &caption,
            caption_px: 16,
            y_label_px: 64,
            x_desc: "time in the episode [s]",
            y_desc: "applied output (torque or voltage)",
        };
        let mut chart = axes.draw(&area, x, y)?;
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
