//! The figure of `pada leo compare`: the torso angle and every joint angle
//! of pada's LEO and of the reference against time, one panel each, with
//! the reference's touchdowns marked.

use super::{plot_err, Figure, FONT};
use crate::leo::compare::{Comparison, StepComparison, ANGLE_NAMES};
use plotters::coord::Shift;
use plotters::prelude::*;

/// pada's trajectory.
const PADA: RGBColor = RGBColor(31, 119, 180);
/// The reference's trajectory.
const REFERENCE: RGBColor = RGBColor(0, 0, 0);
/// A touchdown of the reference.
const TOUCHDOWN: RGBColor = RGBColor(214, 39, 40);

/// Both trajectories of a comparison.
pub struct ComparisonFigure<'a> {
    /// The comparison.
    pub comparison: &'a Comparison,
    /// The title (the reference's name).
    pub title: String,
}

impl Figure for ComparisonFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (1100, 1100)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        // The key goes in the title, not over a panel's data.
        let root = root
            .titled(
                &format!(
                    "{} — pada (blue, solid) against the reference (black, dashed); \
                     red: the reference's touchdowns",
                    self.title
                ),
                (FONT, 18),
            )
            .map_err(plot_err)?;
        let panels = root.split_evenly((4, 2));
        let steps = &self.comparison.steps;
        let t_end = steps.last().map_or(1.0 / 30.0, |s| s.time_s as f64);
        let touchdowns: Vec<f64> = self
            .comparison
            .touchdowns
            .iter()
            .map(|t| t.reference_step as f64 / 30.0)
            .collect();
        for (k, panel) in panels.iter().enumerate() {
            let both = steps
                .iter()
                .flat_map(|s| [s.pada_angles[k] as f64, s.reference_angles[k] as f64]);
            let (lo, hi) = both.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            let pad = ((hi - lo) * 0.08).max(0.01);
            let y = (lo - pad)..(hi + pad);
            // Enough decimals that neighbouring ticks differ.
            let decimals = if y.end - y.start < 0.1 { 3 } else { 2 };
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("{} [rad]", ANGLE_NAMES[k]), (FONT, 15))
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(50)
                .build_cartesian_2d(0.0..t_end, y.clone())
                .map_err(plot_err)?;
            chart
                .configure_mesh()
                .x_desc("time [s]")
                .x_label_formatter(&|v| format!("{v:.2}"))
                .y_label_formatter(&|v| format!("{v:.decimals$}"))
                .label_style((FONT, 11))
                .axis_desc_style((FONT, 12))
                .draw()
                .map_err(plot_err)?;
            for &t in &touchdowns {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        vec![(t, y.start), (t, y.end)],
                        TOUCHDOWN.mix(0.5).stroke_width(1),
                    )))
                    .map_err(plot_err)?;
            }
            // Angle k of one simulator against time.
            let trajectory = |angles: fn(&StepComparison) -> &[f32]| {
                steps.iter().map(move |s| (s.time_s as f64, angles(s)[k] as f64))
            };
            chart
                .draw_series(DashedLineSeries::new(
                    trajectory(|s| &s.reference_angles),
                    6,
                    4,
                    REFERENCE.stroke_width(2),
                ))
                .map_err(plot_err)?;
            chart
                .draw_series(LineSeries::new(trajectory(|s| &s.pada_angles), PADA.stroke_width(2)))
                .map_err(plot_err)?;
        }
        Ok(())
    }
}
