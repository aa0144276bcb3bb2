//! `pada paper transfer`'s figure: per robot (a column), the gear damage
//! and the learning time each way of starting spent on the differing
//! plant until the objective (means with 95 % intervals, one colour per
//! way), the key in its own strip.

use super::legend::{self, Entry, Mark};
use super::{plot_err, Figure, FONT};
use crate::paper::transfer::{RobotTransfer, Start};
use plotters::coord::Shift;
use plotters::prelude::*;

/// The figure.
pub struct TransferFigure<'a> {
    /// One column per robot.
    pub robots: &'a [RobotTransfer],
}

/// The colour of each way (distinct, and distinct in greyscale).
pub fn color(start: Start) -> RGBColor {
    match start {
        Start::Nothing => RGBColor(0, 0, 0),
        Start::Model => RGBColor(31, 119, 180),
        Start::Randomised => RGBColor(230, 120, 0),
    }
}

impl Figure for TransferFigure<'_> {
    fn size(&self) -> (u32, u32) {
        (360 * self.robots.len().max(1) as u32 + 40, 700)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE).map_err(plot_err)?;
        let key: Vec<Entry> = Start::ALL.iter().map(|s| Entry { label: s.label().into(), color: color(*s), mark: Mark::Dot }).collect();
        let (plot_area, key_area) = legend::split(root, key.len());
        legend::draw(&key_area, &key)?;
        let rows = plot_area.split_evenly((2, self.robots.len().max(1)));
        for (c, robot) in self.robots.iter().enumerate() {
            panel(&rows[c], robot, "damage until the objective", &|w| (w.damage.mean, w.damage.ci95))?;
            panel(&rows[self.robots.len() + c], robot, "learning time until it [s]", &|w| (w.time_s.mean, w.time_s.ci95))?;
        }
        Ok(())
    }
}

/// One panel: each way's mean and 95 % interval of `value`.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    robot: &RobotTransfer,
    what: &str,
    value: &dyn Fn(&crate::paper::transfer::Way) -> (f64, f64),
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let ci = |x: f64| if x.is_finite() { x } else { 0.0 };
    let top = robot.ways.iter().map(|w| { let (m, c) = value(w); m + ci(c) }).filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    let top = if top > 0.0 { top * 1.15 } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .caption(format!("{}: {what}", robot.robot), (FONT, 15))
        .margin(10)
        .x_label_area_size(10)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5f64..2.5f64, 0.0..top)
        .map_err(plot_err)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 12))
        .draw()
        .map_err(plot_err)?;
    for (i, w) in robot.ways.iter().enumerate() {
        let (m, c) = value(w);
        let x = i as f64;
        let col = color(w.start);
        chart.draw_series(std::iter::once(Circle::new((x, m), 6, col.filled()))).map_err(plot_err)?;
        let c = ci(c);
        chart
            .draw_series(std::iter::once(PathElement::new(vec![(x, (m - c).max(0.0)), (x, m + c)], col.stroke_width(2))))
            .map_err(plot_err)?;
        for y in [(m - c).max(0.0), m + c] {
            chart
                .draw_series(std::iter::once(PathElement::new(vec![(x - 0.12, y), (x + 0.12, y)], col.stroke_width(2))))
                .map_err(plot_err)?;
        }
    }
    Ok(())
}

/// A tick's label: no more digits than its size needs.
fn tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(0.01..1e5).contains(&a) {
        format!("{v:.1e}")
    } else if a >= 10.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}
