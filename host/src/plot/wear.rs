//! The wear figure of `pada paper wear`: end performance against MTBF —
//! the paper's (commanded torque) and the physical one side by side —
//! every configuration with its 95 % interval, the governed ones as
//! triangles, and the Pareto front as a line.

use super::figures::{color, finite_ci, lin_range, log_range};
use super::{plot_err, Figure, FONT};
use crate::experiment::algo::Algo;
use crate::stats::Estimate;
use plotters::coord::Shift;
use plotters::prelude::*;

/// One configuration of the figure.
#[derive(Debug, Clone)]
pub struct WearPoint {
    /// The strategy (colour).
    pub algo: Algo,
    /// Governed (a triangle) or fixed (a circle).
    pub governed: bool,
    /// The paper's MTBF \[s\].
    pub mtbf_s: Estimate,
    /// The physical MTBF \[s\].
    pub physical_mtbf_s: Estimate,
    /// End performance.
    pub end: Estimate,
    /// On the front against the paper's MTBF.
    pub pareto: bool,
    /// On the front against the physical MTBF.
    pub pareto_physical: bool,
}

/// The figure.
#[derive(Debug, Clone)]
pub struct WearPareto {
    /// Title.
    pub title: String,
    /// Every configuration.
    pub points: Vec<WearPoint>,
    /// SARSA(λ)'s MTBFs (paper's, physical) \[s\], as dashed vertical lines.
    pub sarsa_mtbf_s: [f64; 2],
}

impl WearPareto {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        physical: bool,
    ) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let x_of = |p: &WearPoint| {
            if physical {
                p.physical_mtbf_s.mean
            } else {
                p.mtbf_s.mean
            }
        };
        let sarsa = self.sarsa_mtbf_s[physical as usize];
        let x = log_range(self.points.iter().map(x_of).chain([sarsa]));
        let y = lin_range(self.points.iter().flat_map(|p| {
            [
                p.end.mean - finite_ci(&p.end),
                p.end.mean + finite_ci(&p.end),
            ]
        }));
        let caption = if physical {
            "physical MTBF (simulated gear torque)"
        } else {
            "the paper's MTBF (commanded torque)"
        };
        let mut chart = ChartBuilder::on(area)
            .caption(caption, (FONT, 18))
            .margin(10)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d(x.clone().log_scale(), y.clone())
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .x_labels(6)
            .x_desc("predicted MTBF over the first 1200 actions [s]")
            .y_desc("end performance")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .label_style((FONT, 13))
            .axis_desc_style((FONT, 14))
            .draw()
            .map_err(plot_err)?;
        chart
            .draw_series(DashedLineSeries::new(
                vec![(sarsa, y.start), (sarsa, y.end)],
                8,
                6,
                RGBColor(120, 120, 120).stroke_width(1),
            ))
            .map_err(plot_err)?;
        let mut front: Vec<&WearPoint> = self
            .points
            .iter()
            .filter(|p| {
                if physical {
                    p.pareto_physical
                } else {
                    p.pareto
                }
            })
            .collect();
        front.sort_by(|a, b| x_of(a).total_cmp(&x_of(b)));
        chart
            .draw_series(LineSeries::new(
                front
                    .iter()
                    .filter(|p| x_of(p).is_finite())
                    .map(|p| (x_of(p), p.end.mean)),
                BLACK.stroke_width(2),
            ))
            .map_err(plot_err)?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        let mut labelled = Vec::new();
        for p in self.points.iter().filter(|p| x_of(p).is_finite()) {
            let c = color(p.algo);
            let e = finite_ci(&p.end);
            chart
                .draw_series(std::iter::once(ErrorBar::new_vertical(
                    x_of(p),
                    p.end.mean - e,
                    p.end.mean,
                    p.end.mean + e,
                    c.stroke_width(1),
                    6,
                )))
                .map_err(plot_err)?;
            let key = (p.algo.name(), p.governed);
            let first = !labelled.contains(&key);
            labelled.push(key);
            let at = (x_of(p), p.end.mean);
            if p.governed {
                let s = chart
                    .draw_series(std::iter::once(TriangleMarker::new(at, 7, c.filled())))
                    .map_err(plot_err)?;
                if first {
                    s.label(format!("{} + governor", p.algo.name()))
                        .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, c.filled()));
                }
            } else {
                let s = chart
                    .draw_series(std::iter::once(Circle::new(at, 4, c.filled())))
                    .map_err(plot_err)?;
                if first {
                    s.label(p.algo.name())
                        .legend(move |(x, y)| Circle::new((x + 10, y), 4, c.filled()));
                }
            }
        }
        if !physical {
            chart
                .configure_series_labels()
                .label_font((FONT, 12))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::LowerRight)
                .draw()
                .map_err(plot_err)?;
        }
        Ok(())
    }
}

impl Figure for WearPareto {
    fn size(&self) -> (u32, u32) {
        (1500, 640)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let root = root.titled(&self.title, (FONT, 22)).map_err(plot_err)?;
        let (left, right) = root.split_horizontally(750);
        self.panel(&left, false)?;
        self.panel(&right, true)?;
        Ok(())
    }
}
