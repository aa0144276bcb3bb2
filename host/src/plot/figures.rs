//! The four figures of Section VII:
//!
//! - [`MtbfSweep`] (Fig. 3): MTBF against α or Δ, SARSA(λ)'s interval as
//!   dashed lines;
//! - [`PerformanceVsMtbf`] (Figs. 4 and 5): end performance or rise time
//!   against MTBF, the objective's threshold as a horizontal dashed line
//!   and SARSA(λ)'s MTBF as a vertical one;
//! - [`LearningCurves`] (Fig. 6): mean learning curves with their 95%
//!   bands, SARSA(λ)'s end performance and rise time as lines.

use super::{plot_err, Figure, FONT};
use crate::experiment::algo::Algo;
use crate::paper::pendulum::CurvePoint;
use crate::stats::Estimate;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A colour per algorithm.
pub fn color(algo: Algo) -> RGBColor {
    match algo {
        Algo::Sarsa => RGBColor(0, 0, 0),
        Algo::LowPass => RGBColor(31, 119, 180),
        Algo::MarkovLowPass => RGBColor(23, 190, 207),
        Algo::Integrator => RGBColor(214, 39, 40),
        Algo::MarkovIntegrator => RGBColor(255, 127, 14),
        Algo::Pada => RGBColor(44, 160, 44),
        Algo::EpsilonPada => RGBColor(188, 189, 34),
        Algo::OrnsteinUhlenbeck => RGBColor(148, 103, 189),
        Algo::PinkNoise => RGBColor(227, 119, 194),
        Algo::ActionPenalty => RGBColor(140, 86, 75),
    }
}

/// One configuration's results.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepPoint {
    /// The algorithm.
    pub algo: Algo,
    /// Its α or Δ (1 for SARSA(λ)).
    pub param: f64,
    /// Predicted MTBF \[s\].
    pub mtbf_s: Estimate,
    /// End performance.
    pub end: Estimate,
    /// Rise time \[s\].
    pub rise_s: Estimate,
}

/// The algorithms drawn as swept lines, in the paper's order.
const SWEPT: [Algo; 5] = [
    Algo::LowPass,
    Algo::MarkovLowPass,
    Algo::Integrator,
    Algo::MarkovIntegrator,
    Algo::Pada,
];

pub(crate) fn finite_ci(e: &Estimate) -> f64 {
    if e.ci95.is_finite() {
        e.ci95
    } else {
        0.0
    }
}

/// A log range covering `values` with some room.
pub(crate) fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 1.0..10.0;
    }
    lo / 1.6..hi * 1.6
}

/// A linear range covering `values` with 6% room (0..1 when empty; a
/// flat series gets ±0.1 % of its value, so its axis still has ticks).
pub(crate) fn lin_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.06).max(1e-12_f64.max(hi.abs() * 1e-3));
    lo - pad..hi + pad
}

/// Fig. 3: MTBF against α or Δ.
#[derive(Debug, Clone)]
pub struct MtbfSweep {
    /// Title.
    pub title: String,
    /// Every configuration but SARSA(λ).
    pub points: Vec<SweepPoint>,
    /// SARSA(λ)'s MTBF.
    pub sarsa_mtbf_s: Estimate,
}

impl Figure for MtbfSweep {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let s = &self.sarsa_mtbf_s;
        let y = log_range(
            self.points
                .iter()
                .flat_map(|p| {
                    [
                        p.mtbf_s.mean - finite_ci(&p.mtbf_s),
                        p.mtbf_s.mean + finite_ci(&p.mtbf_s),
                    ]
                })
                .chain([s.mean - finite_ci(s), s.mean + finite_ci(s)]),
        );
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(90)
            .build_cartesian_2d(0.0f64..1.05, y.clone().log_scale())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("α (low-pass) or Δ (integrators, PADA)")
            .y_desc("predicted MTBF [s]")
            .y_label_formatter(&|v| format!("{v:.0}"))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_err)?;
        for bound in [s.lower(), s.upper()] {
            if bound.is_finite() && bound > 0.0 {
                chart
                    .draw_series(DashedLineSeries::new(
                        vec![(0.0, bound), (1.05, bound)],
                        8,
                        6,
                        BLACK.stroke_width(1),
                    ))
                    .map_err(plot_err)?;
            }
        }
        for algo in SWEPT {
            let mut pts: Vec<&SweepPoint> = self
                .points
                .iter()
                .filter(|p| p.algo == algo && p.mtbf_s.mean.is_finite())
                .collect();
            pts.sort_by(|a, b| a.param.total_cmp(&b.param));
            if pts.is_empty() {
                continue;
            }
            let c = color(algo);
            chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.param, p.mtbf_s.mean)),
                    c.stroke_width(2),
                ))
                .map_err(plot_err)?
                .label(algo.title())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
            chart
                .draw_series(pts.iter().map(|p| {
                    let e = finite_ci(&p.mtbf_s);
                    ErrorBar::new_vertical(
                        p.param,
                        (p.mtbf_s.mean - e).max(y.start),
                        p.mtbf_s.mean,
                        p.mtbf_s.mean + e,
                        c.filled(),
                        8,
                    )
                }))
                .map_err(plot_err)?;
            chart
                .draw_series(
                    pts.iter()
                        .map(|p| Circle::new((p.param, p.mtbf_s.mean), 4, c.filled())),
                )
                .map_err(plot_err)?;
        }
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(0.0, s.mean), (0.0, s.mean)],
                BLACK,
            )))
            .map_err(plot_err)?
            .label("SARSA(λ) 95% interval (dashed)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(plot_err)?;
        Ok(())
    }
}

/// Which measure [`PerformanceVsMtbf`] plots.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// End performance (Fig. 4).
    EndPerformance,
    /// Rise time (Fig. 5).
    RiseTime,
}

/// Figs. 4 and 5: a learning measure against MTBF.
#[derive(Debug, Clone)]
pub struct PerformanceVsMtbf {
    /// Title.
    pub title: String,
    /// The measure.
    pub measure: Measure,
    /// Every configuration, SARSA(λ) included.
    pub points: Vec<SweepPoint>,
    /// The objective's threshold for the measure.
    pub threshold: f64,
    /// SARSA(λ)'s mean MTBF \[s\].
    pub sarsa_mtbf_s: f64,
}

impl PerformanceVsMtbf {
    fn value(&self, p: &SweepPoint) -> Estimate {
        match self.measure {
            Measure::EndPerformance => p.end,
            Measure::RiseTime => p.rise_s,
        }
    }
}

impl Figure for PerformanceVsMtbf {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let x = log_range(
            self.points
                .iter()
                .map(|p| p.mtbf_s.mean)
                .chain([self.sarsa_mtbf_s]),
        );
        let y = lin_range(
            self.points
                .iter()
                .flat_map(|p| {
                    let v = self.value(p);
                    [v.mean - finite_ci(&v), v.mean + finite_ci(&v)]
                })
                .chain([self.threshold]),
        );
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x.clone().log_scale(), y.clone())
            .map_err(plot_err)?;
        let y_desc = match self.measure {
            Measure::EndPerformance => "end performance (return of a greedy test run)",
            Measure::RiseTime => "rise time [s]",
        };
        chart
            .configure_mesh()
            .x_desc("predicted MTBF [s]")
            .y_desc(y_desc)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_err)?;
        chart
            .draw_series(DashedLineSeries::new(
                vec![(x.start, self.threshold), (x.end, self.threshold)],
                8,
                6,
                BLACK.stroke_width(1),
            ))
            .map_err(plot_err)?
            .label(match self.measure {
                Measure::EndPerformance => format!("objective: above {:.0}", self.threshold),
                Measure::RiseTime => format!("objective: below {:.0} s", self.threshold),
            })
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
        chart
            .draw_series(DashedLineSeries::new(
                vec![(self.sarsa_mtbf_s, y.start), (self.sarsa_mtbf_s, y.end)],
                8,
                6,
                RGBColor(120, 120, 120).stroke_width(1),
            ))
            .map_err(plot_err)?;
        for algo in std::iter::once(Algo::Sarsa).chain(SWEPT) {
            let mut pts: Vec<&SweepPoint> = self
                .points
                .iter()
                .filter(|p| p.algo == algo && p.mtbf_s.mean.is_finite())
                .collect();
            pts.sort_by(|a, b| a.mtbf_s.mean.total_cmp(&b.mtbf_s.mean));
            if pts.is_empty() {
                continue;
            }
            let c = color(algo);
            let series = chart
                .draw_series(pts.iter().map(|p| {
                    let v = self.value(p);
                    let e = finite_ci(&v);
                    ErrorBar::new_vertical(
                        p.mtbf_s.mean,
                        v.mean - e,
                        v.mean,
                        v.mean + e,
                        c.stroke_width(2),
                        8,
                    )
                }))
                .map_err(plot_err)?;
            series
                .label(algo.title())
                .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
            chart
                .draw_series(
                    pts.iter()
                        .map(|p| Circle::new((p.mtbf_s.mean, self.value(p).mean), 4, c.filled())),
                )
                .map_err(plot_err)?;
            if algo != Algo::Sarsa {
                chart
                    .draw_series(LineSeries::new(
                        pts.iter().map(|p| (p.mtbf_s.mean, self.value(p).mean)),
                        c.mix(0.5),
                    ))
                    .map_err(plot_err)?;
                let prefix = if algo.takes_alpha() { "α" } else { "Δ" };
                chart
                    .draw_series(pts.iter().map(|p| {
                        Text::new(
                            format!("{prefix}={}", p.param as f32),
                            (p.mtbf_s.mean * 1.04, self.value(p).mean),
                            (FONT, 11).into_font().color(&c),
                        )
                    }))
                    .map_err(plot_err)?;
            }
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(match self.measure {
                Measure::EndPerformance => SeriesLabelPosition::LowerLeft,
                Measure::RiseTime => SeriesLabelPosition::LowerLeft,
            })
            .draw()
            .map_err(plot_err)?;
        Ok(())
    }
}

/// One learning curve of [`LearningCurves`].
#[derive(Debug, Clone)]
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// The algorithm (colour).
    pub algo: Algo,
    /// Mean and interval per test run.
    pub points: Vec<CurvePoint>,
}

/// Fig. 6: mean learning curves with 95% bands.
#[derive(Debug, Clone)]
pub struct LearningCurves {
    /// Title.
    pub title: String,
    /// The curves.
    pub curves: Vec<Curve>,
    /// SARSA(λ)'s end performance (horizontal line).
    pub sarsa_end: f64,
    /// SARSA(λ)'s rise time \[s\] (vertical line).
    pub sarsa_rise_s: f64,
}

impl Figure for LearningCurves {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let all = || self.curves.iter().flat_map(|c| c.points.iter());
        let x = lin_range(all().map(|p| p.learning_time_s));
        let x = 0.0f64.min(x.start)..x.end;
        let y = lin_range(all().flat_map(|p| {
            let e = if p.ci95.is_finite() { p.ci95 } else { 0.0 };
            [p.mean - e, p.mean + e]
        }));
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(x.clone(), y.clone())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("learning time [s]")
            .y_desc("return of a greedy test run")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_err)?;
        for curve in &self.curves {
            let c = color(curve.algo);
            let ci = |p: &CurvePoint| if p.ci95.is_finite() { p.ci95 } else { 0.0 };
            let band: Vec<(f64, f64)> = curve
                .points
                .iter()
                .map(|p| (p.learning_time_s, p.mean + ci(p)))
                .chain(
                    curve
                        .points
                        .iter()
                        .rev()
                        .map(|p| (p.learning_time_s, p.mean - ci(p))),
                )
                .collect();
            chart
                .draw_series(std::iter::once(Polygon::new(band, c.mix(0.18))))
                .map_err(plot_err)?;
            chart
                .draw_series(LineSeries::new(
                    curve.points.iter().map(|p| (p.learning_time_s, p.mean)),
                    c.stroke_width(2),
                ))
                .map_err(plot_err)?
                .label(curve.label.as_str())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
        }
        chart
            .draw_series(LineSeries::new(
                vec![(x.start, self.sarsa_end), (x.end, self.sarsa_end)],
                BLACK.stroke_width(1),
            ))
            .map_err(plot_err)?
            .label(format!("SARSA(λ) end performance {:.0}", self.sarsa_end))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(1)));
        chart
            .draw_series(DashedLineSeries::new(
                vec![(self.sarsa_rise_s, y.start), (self.sarsa_rise_s, y.end)],
                8,
                6,
                BLACK.stroke_width(1),
            ))
            .map_err(plot_err)?
            .label(format!("SARSA(λ) rise time {:.0} s", self.sarsa_rise_s))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], BLACK.stroke_width(1)));
        chart
            .configure_series_labels()
            .label_font((FONT, 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(plot_err)?;
        Ok(())
    }
}
