//! What a trial writes: the claim table's claimed slots against learning
//! time, one line per trial, one colour and line style per configuration,
//! with the boards' table sizes drawn across.

use super::figures::color;
use super::legend::{self, Entry, Mark};
use super::{plot_err, Figure, FONT};
use crate::experiment::algo::Algo;
use plotters::coord::Shift;
use plotters::prelude::*;

/// One configuration's trials.
#[derive(Debug, Clone)]
pub struct ClaimSeries {
    /// Legend label.
    pub label: String,
    /// The algorithm (colour).
    pub algo: Algo,
    /// Per trial: (learning time \[s\], claimed slots) at each test run.
    pub trials: Vec<Vec<(f64, f64)>>,
}

/// A table size drawn across the plot.
#[derive(Debug, Clone)]
pub struct Capacity {
    /// Legend label.
    pub label: String,
    /// Slots.
    pub slots: f64,
}

/// The figure.
#[derive(Debug, Clone)]
pub struct ClaimsFigure {
    /// Title.
    pub title: String,
    /// The configurations.
    pub series: Vec<ClaimSeries>,
    /// Table sizes to draw across.
    pub capacities: Vec<Capacity>,
}

const CAPACITY: RGBColor = RGBColor(120, 120, 120);

impl Figure for ClaimsFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let marks = super::figures::line_marks(self.series.iter().map(|s| s.algo));
        let mut key: Vec<Entry> = self
            .series
            .iter()
            .zip(&marks)
            .map(|(s, m)| Entry { label: s.label.clone(), color: color(s.algo), mark: *m })
            .collect();
        let cap_marks = [Mark::Dotted, Mark::Dashed, Mark::Line];
        for (c, m) in self.capacities.iter().zip(cap_marks.iter().cycle()) {
            key.push(Entry { label: c.label.clone(), color: CAPACITY, mark: *m });
        }
        let (plot_area, key_area) = legend::split(root, key.len());
        legend::draw(&key_area, &key)?;
        let points = || self.series.iter().flat_map(|s| s.trials.iter().flatten());
        let x_max = points().map(|p| p.0).fold(1.0f64, f64::max);
        let y_max = points()
            .map(|p| p.1)
            .chain(self.capacities.iter().map(|c| c.slots))
            .fold(1.0f64, f64::max)
            * 1.05;
        let mut chart = ChartBuilder::on(&plot_area)
            .caption(&self.title, (FONT, 22))
            .margin(12)
            .x_label_area_size(50)
            .y_label_area_size(80)
            .build_cartesian_2d(0.0..x_max, 0.0..y_max)
            .map_err(plot_err)?;
        chart
            .configure_mesh()
            .x_desc("learning time [s]")
            .y_desc("claimed slots [millions]")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{:.1}", v / 1e6))
            .label_style((FONT, 14))
            .axis_desc_style((FONT, 16))
            .draw()
            .map_err(plot_err)?;
        for (c, m) in self.capacities.iter().zip(cap_marks.iter().cycle()) {
            line(&mut chart, vec![(0.0, c.slots), (x_max, c.slots)], CAPACITY, *m)?;
        }
        for (s, m) in self.series.iter().zip(&marks) {
            for trial in &s.trials {
                line(&mut chart, trial.clone(), color(s.algo), *m)?;
            }
        }
        Ok(())
    }
}

type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>>;

fn line<DB: DrawingBackend>(chart: &mut Chart<'_, DB>, points: Vec<(f64, f64)>, c: RGBColor, mark: Mark) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    match mark.dashes() {
        None => chart.draw_series(LineSeries::new(points, c.stroke_width(2))),
        Some((dash, gap)) => chart.draw_series(DashedLineSeries::new(points, dash, gap, c.stroke_width(2))),
    }
    .map_err(plot_err)?;
    Ok(())
}
