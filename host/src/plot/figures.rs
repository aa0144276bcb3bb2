//! The four figures of Section VII:
//!
//! - [`MtbfSweep`] (Fig. 3): MTBF against α or Δ, SARSA(λ)'s interval as
//!   dashed lines;
//! - [`PerformanceVsMtbf`] (Figs. 4 and 5): end performance or rise time
//!   against MTBF, the objective's threshold as a horizontal dashed line
//!   and SARSA(λ)'s MTBF as a vertical one;
//! - [`LearningCurves`] (Fig. 6): mean learning curves with their 95%
//!   bands, SARSA(λ)'s end performance and rise time as lines.

use super::legend::{self, parameter_text, Entry, Mark};
use super::{plot_err, Figure, FONT};
use crate::experiment::algo::Algo;
use crate::paper::curves::CurvePoint;
use crate::stats::Estimate;
use plotters::coord::Shift;
use plotters::prelude::*;

/// The colour of reference lines that are not a learner's curve.
const GREY_LINE: RGBColor = RGBColor(120, 120, 120);

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

/// A log axis's tick label: only the ticks at 1, 2 and 5 times a power of
/// ten are written, so that the ticks plotters puts at every integer
/// multiple do not run into each other near the top of a decade.
pub(crate) fn log_tick(v: &f64) -> String {
    if !(*v > 0.0 && v.is_finite()) {
        return String::new();
    }
    let mantissa = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6 * m) {
        format!("{v:.0}")
    } else {
        String::new()
    }
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
        let algos: Vec<Algo> = std::iter::once(Algo::Sarsa)
            .chain(SWEPT)
            .filter(|a| self.points.iter().any(|p| p.algo == *a && p.mtbf_s.mean.is_finite()))
            .collect();
        let mut key = vec![Entry {
            label: match self.measure {
                Measure::EndPerformance => format!("objective: above {:.0}", self.threshold),
                Measure::RiseTime => format!("objective: below {:.0} s", self.threshold),
            },
            color: BLACK,
            mark: Mark::Dashed,
        }];
        key.push(Entry {
            label: format!("SARSA(λ)'s MTBF {:.0} s", self.sarsa_mtbf_s),
            color: GREY_LINE,
            mark: Mark::Dashed,
        });
        key.extend(algos.iter().map(|a| Entry {
            label: a.title().to_string(),
            color: color(*a),
            mark: Mark::Dot,
        }));
        let (plot_area, key_area) = legend::split(root, key.len());
        legend::draw(&key_area, &key)?;
        let root = &plot_area;
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
            .x_max_light_lines(2)
            .x_label_formatter(&log_tick)
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
            .map_err(plot_err)?;
        chart
            .draw_series(DashedLineSeries::new(
                vec![(self.sarsa_mtbf_s, y.start), (self.sarsa_mtbf_s, y.end)],
                8,
                6,
                GREY_LINE.stroke_width(1),
            ))
            .map_err(plot_err)?;
        let mut labels: Vec<((f64, f64), String, RGBColor)> = Vec::new();
        for algo in algos {
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
            chart
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
                labels.extend(pts.iter().map(|p| {
                    let at = (p.mtbf_s.mean, self.value(p).mean);
                    (at, format!("{prefix}={}", parameter_text(p.param)), c)
                }));
            }
        }
        // Each point's α or Δ beside it, moved down a line at a time
        // while it would overlap a label already placed (two nearby
        // points of two filters ran their labels together).
        let mut placed: Vec<(i32, i32, i32)> = Vec::new();
        for (at, text, c) in labels {
            let (px, py) = chart.backend_coord(&at);
            let width = LABEL_CHAR_PX * text.chars().count() as i32;
            let (x0, mut y0) = (px + 6, py - LABEL_LINE_PX / 2);
            while placed.iter().any(|&(x, y, w)| {
                x0 < x + w && x < x0 + width && (y0 - y).abs() < LABEL_LINE_PX
            }) {
                y0 += LABEL_LINE_PX;
            }
            placed.push((x0, y0, width));
            chart
                .plotting_area()
                .draw(
                    &(EmptyElement::at(at)
                        + Text::new(text, (x0 - px, y0 - py), (FONT, 11).into_font().color(&c))),
                )
                .map_err(plot_err)?;
        }
        Ok(())
    }
}

/// Width of one character of a point's label at 11 px, rounded up \[px\].
const LABEL_CHAR_PX: i32 = 7;
/// Height of a point's label line \[px\].
const LABEL_LINE_PX: i32 = 13;

/// The line style of each of a figure's series, in order: the first of
/// an algorithm solid, the next dashed, then dotted, so two series of one
/// colour never look alike.
pub fn line_marks(algos: impl Iterator<Item = Algo>) -> Vec<Mark> {
    let algos: Vec<Algo> = algos.collect();
    (0..algos.len())
        .map(|i| {
            let before = algos[..i].iter().filter(|&&a| a == algos[i]).count();
            Mark::LINES[before % Mark::LINES.len()]
        })
        .collect()
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
    /// When the filtered learners switch back to SARSA(λ) \[s\] (a
    /// vertical line), if they do.
    pub switch_at_s: Option<f64>,
}

impl LearningCurves {
    /// Each curve's mark: the first curve of an algorithm solid, the next
    /// dashed, then dotted, so two curves of one colour never look alike.
    fn marks(&self) -> Vec<Mark> {
        line_marks(self.curves.iter().map(|c| c.algo))
    }
}

impl Figure for LearningCurves {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let marks = self.marks();
        let mut key: Vec<Entry> = self
            .curves
            .iter()
            .zip(&marks)
            .map(|(c, m)| Entry { label: c.label.clone(), color: color(c.algo), mark: *m })
            .collect();
        key.push(Entry {
            label: format!("SARSA(λ) end performance {:.0}", self.sarsa_end),
            color: GREY_LINE,
            mark: Mark::Line,
        });
        key.push(Entry {
            label: format!("SARSA(λ) rise time {:.0} s", self.sarsa_rise_s),
            color: BLACK,
            mark: Mark::Dashed,
        });
        if let Some(t) = self.switch_at_s {
            key.push(Entry {
                label: format!("switch back to SARSA(λ) at {t:.0} s"),
                color: GREY_LINE,
                mark: Mark::Dotted,
            });
        }
        let (plot_area, key_area) = legend::split(root, key.len());
        legend::draw(&key_area, &key)?;
        let root = &plot_area;
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
        for (curve, mark) in self.curves.iter().zip(&marks) {
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
            let line = curve.points.iter().map(|p| (p.learning_time_s, p.mean));
            match mark.dashes() {
                None => chart.draw_series(LineSeries::new(line, c.stroke_width(2))),
                Some((dash, gap)) => chart.draw_series(DashedLineSeries::new(
                    line,
                    dash,
                    gap,
                    c.stroke_width(2),
                )),
            }
            .map_err(plot_err)?;
        }
        chart
            .draw_series(LineSeries::new(
                vec![(x.start, self.sarsa_end), (x.end, self.sarsa_end)],
                GREY_LINE.stroke_width(2),
            ))
            .map_err(plot_err)?;
        chart
            .draw_series(DashedLineSeries::new(
                vec![(self.sarsa_rise_s, y.start), (self.sarsa_rise_s, y.end)],
                8,
                6,
                BLACK.stroke_width(1),
            ))
            .map_err(plot_err)?;
        if let Some(t) = self.switch_at_s {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(t, y.start), (t, y.end)],
                    2,
                    4,
                    GREY_LINE.stroke_width(2),
                ))
                .map_err(plot_err)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(mean: f64, ci95: f64) -> Estimate {
        Estimate { mean, ci95, n: 15 }
    }

    /// The x and y of every `<text>` in an SVG whose content is `label`.
    fn text_positions(svg: &str, label: &str) -> Vec<(f64, f64)> {
        svg.split("<text")
            .skip(1)
            .filter(|t| t.split('>').nth(1).is_some_and(|c| c.trim_start().starts_with(label)))
            .map(|t| {
                let attr = |name: &str| -> f64 {
                    let key = format!(" {name}=\"");
                    let from = t.find(&key).expect("attribute") + key.len();
                    t[from..].split('"').next().unwrap().parse().unwrap()
                };
                (attr("x"), attr("y"))
            })
            .collect()
    }

    #[test]
    fn point_labels_of_two_nearby_points_do_not_overlap_and_read_as_fractions() {
        let point = |algo, param: f64, mtbf, end| SweepPoint {
            algo,
            param,
            mtbf_s: estimate(mtbf, 1000.0),
            end: estimate(end, 100.0),
            rise_s: estimate(f64::NAN, f64::NAN),
        };
        let figure = PerformanceVsMtbf {
            title: "labels".into(),
            measure: Measure::EndPerformance,
            points: vec![
                point(Algo::Sarsa, 1.0, 1108.0, -222.0),
                point(Algo::Pada, f64::from(1.0f32 / 6.0), 32348.0, -178.0),
                point(Algo::Pada, f64::from(1.0f32 / 3.0), 9809.0, -354.0),
                point(Algo::LowPass, 0.2, 37419.0, -174.0),
            ],
            threshold: 1084.0,
            sarsa_mtbf_s: 1108.0,
        };
        let svg = crate::plot::to_svg(&figure).unwrap();
        let sixth = text_positions(&svg, "Δ=1/6");
        let alpha = text_positions(&svg, "α=0.2");
        assert_eq!((sixth.len(), alpha.len()), (1, 1), "one label each");
        assert_eq!(text_positions(&svg, "Δ=1/3").len(), 1);
        let (a, b) = (sixth[0], alpha[0]);
        let width = |s: &str| f64::from(LABEL_CHAR_PX) * s.chars().count() as f64;
        let apart_x = a.0 + width("Δ=1/6") <= b.0 || b.0 + width("α=0.2") <= a.0;
        let apart_y = (a.1 - b.1).abs() >= f64::from(LABEL_LINE_PX);
        assert!(apart_x || apart_y, "labels at {a:?} and {b:?} overlap");
    }

    #[test]
    fn the_key_is_drawn_below_every_data_point() {
        let figure = LearningCurves {
            title: "key".into(),
            curves: vec![Curve {
                label: "sarsa".into(),
                algo: Algo::Sarsa,
                points: (0..20)
                    .map(|i| CurvePoint { learning_time_s: i as f64, mean: -(i as f64), ci95: 1.0 })
                    .collect(),
            }],
            sarsa_end: -19.0,
            sarsa_rise_s: 3.0,
            switch_at_s: Some(10.0),
        };
        let svg = crate::plot::to_svg(&figure).unwrap();
        let key_y = text_positions(&svg, "sarsa")[0].1;
        let axis_label_y = text_positions(&svg, "learning time [s]")[0].1;
        assert!(key_y > axis_label_y, "key at y {key_y}, x axis title at {axis_label_y}");
        assert_eq!(text_positions(&svg, "switch back to SARSA(λ) at 10 s").len(), 1);
    }

    #[test]
    fn log_ticks_are_written_at_one_two_and_five_only() {
        assert_eq!(log_tick(&1000.0), "1000");
        assert_eq!(log_tick(&2000.0), "2000");
        assert_eq!(log_tick(&5000.0), "5000");
        assert_eq!(log_tick(&7000.0), "");
        assert_eq!(log_tick(&9000.0), "");
        assert_eq!(log_tick(&10000.0), "10000");
    }
}
