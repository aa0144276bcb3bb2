//! The wear figure of `pada paper wear`: end performance against MTBF —
//! the paper's (commanded torque) and the physical one side by side —
//! every configuration with its 95 % interval, the governed ones as
//! triangles, and the Pareto front as a line.

use super::figures::{color, finite_ci, lin_range, log_range};
use super::legend::{self, Entry, Mark};
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
            .map_err(plot_err)?;
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
            let at = (x_of(p), p.end.mean);
            if p.governed {
                chart
                    .draw_series(std::iter::once(TriangleMarker::new(at, 7, c.filled())))
                    .map_err(plot_err)?;
            } else {
                chart
                    .draw_series(std::iter::once(Circle::new(at, 4, c.filled())))
                    .map_err(plot_err)?;
            }
        }
        Ok(())
    }

    /// The key: the Pareto front, then every strategy once, in the order
    /// of the points (a governed one as a triangle). It is drawn in a strip
    /// under both panels, never over a point.
    fn key(&self) -> Vec<Entry> {
        let mut key = vec![Entry { label: "Pareto front".into(), color: BLACK, mark: Mark::Line }];
        let mut seen = Vec::new();
        for p in &self.points {
            if seen.contains(&(p.algo.name(), p.governed)) {
                continue;
            }
            seen.push((p.algo.name(), p.governed));
            let (label, mark) = if p.governed {
                (format!("{} + governor", p.algo.name()), Mark::Triangle)
            } else {
                (p.algo.name().to_string(), Mark::Dot)
            };
            key.push(Entry { label, color: color(p.algo), mark });
        }
        key
    }
}

impl Figure for WearPareto {
    fn size(&self) -> (u32, u32) {
        // The plots' 640 px and the key's strip (two entries a row).
        (1500, 640 + 22 * self.key().len().div_ceil(2) as u32 + 12)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let root = root.titled(&self.title, (FONT, 22)).map_err(plot_err)?;
        let key = self.key();
        let (plots, key_area) = legend::split(&root, key.len());
        legend::draw(&key_area, &key)?;
        let (left, right) = plots.split_horizontally(750);
        self.panel(&left, false)?;
        self.panel(&right, true)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(v: &serde_json::Value) -> Estimate {
        Estimate {
            // `null` means infinite (a trial without damage) or too few trials.
            mean: v["mean"].as_f64().unwrap_or(f64::INFINITY),
            ci95: v["ci95"].as_f64().unwrap_or(f64::NAN),
            n: v["n"].as_u64().unwrap_or(0) as usize,
        }
    }

    /// Draws the LEO sweep of `docs/wear/` again from its `leo-summary.json`
    /// (into the temporary folder `pada-wear-leo-figure/`): every strategy
    /// once in the key, which sits in its own strip under the plots.
    #[test]
    fn the_leo_sweep_draws_with_its_key_under_the_plots() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/wear/leo-summary.json");
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let configs = v["configs"].as_array().unwrap();
        let points: Vec<WearPoint> = configs
            .iter()
            .map(|c| WearPoint {
                algo: Algo::from_name(c["summary"]["algo"].as_str().unwrap()).unwrap(),
                governed: !c["budget_s"].is_null(),
                mtbf_s: estimate(&c["summary"]["mtbf_s"]),
                physical_mtbf_s: estimate(&c["summary"]["physical_mtbf_s"]),
                end: estimate(&c["summary"]["end_performance"]),
                pareto: c["pareto"].as_bool().unwrap(),
                pareto_physical: c["pareto_physical"].as_bool().unwrap(),
            })
            .collect();
        let sarsa = &points[0];
        let figure = WearPareto {
            title: "End performance against MTBF (leo): every strategy and the wear governor".into(),
            sarsa_mtbf_s: [sarsa.mtbf_s.mean, sarsa.physical_mtbf_s.mean],
            points: points.clone(),
        };
        let key = figure.key();
        // The front, the sweep's ten strategies and the two governed ones.
        assert_eq!(key.len(), 1 + 10 + 2, "{key:?}");
        assert_eq!(key.iter().filter(|e| e.mark == Mark::Triangle).count(), 2);
        assert_eq!(key[0].label, "Pareto front");
        // The figure grows by the key's strip instead of drawing it over a plot.
        assert_eq!(figure.size(), (1500, 640 + 22 * 7 + 12));
        let dir = std::env::temp_dir().join("pada-wear-leo-figure");
        std::fs::create_dir_all(&dir).unwrap();
        crate::plot::save(&figure, &dir, "leo-wear-pareto").unwrap();
        assert!(std::fs::metadata(dir.join("leo-wear-pareto.png")).unwrap().len() > 10_000);
    }
}
