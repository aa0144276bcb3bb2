//! A key drawn in its own strip under the plot, so that it can never cover
//! a data point (plotters' series labels are drawn inside the plotting
//! area, where they covered SARSA(λ)'s point in Fig. 8).

use super::{plot_err, FONT};
use plotters::coord::Shift;
use plotters::prelude::*;

/// How an entry of the key is marked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// A solid line.
    Line,
    /// A dashed line.
    Dashed,
    /// A dotted line.
    Dotted,
    /// A filled dot.
    Dot,
    /// A filled triangle.
    Triangle,
    /// A shaded square, for a shaded band of the plot.
    Band,
}

impl Mark {
    /// The line styles that tell apart curves of one colour, in order.
    pub const LINES: [Mark; 3] = [Mark::Line, Mark::Dashed, Mark::Dotted];

    /// Dash and gap lengths in pixels of a line mark (`None`: solid).
    pub fn dashes(self) -> Option<(u32, u32)> {
        match self {
            Mark::Dashed => Some((10, 6)),
            Mark::Dotted => Some((2, 4)),
            Mark::Line | Mark::Dot | Mark::Triangle | Mark::Band => None,
        }
    }
}

/// One entry of the key.
#[derive(Debug, Clone)]
pub struct Entry {
    /// Its text.
    pub label: String,
    /// Its colour.
    pub color: RGBColor,
    /// Its mark.
    pub mark: Mark,
}

/// The opacity of a shaded band, in the plot and in its key.
pub const BAND_ALPHA: f64 = 0.35;

/// Entries per row of the key.
const COLUMNS: usize = 2;
/// Height of one row of the key in pixels.
const ROW_PX: u32 = 22;

/// Splits `root` into the plotting area and a strip under it for a key of
/// `entries` entries.
pub fn split<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    entries: usize,
) -> (DrawingArea<DB, Shift>, DrawingArea<DB, Shift>) {
    let rows = entries.div_ceil(COLUMNS) as u32;
    let (_, h) = root.dim_in_pixel();
    root.split_vertically(h.saturating_sub(rows * ROW_PX + 12))
}

/// Draws the key into `area` (from [`split`]), two entries per row.
pub fn draw<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, entries: &[Entry]) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let (w, _) = area.dim_in_pixel();
    let column_px = (w.saturating_sub(80) / COLUMNS as u32) as i32;
    for (i, e) in entries.iter().enumerate() {
        let x = 80 + (i % COLUMNS) as i32 * column_px;
        let y = 6 + (i / COLUMNS) as i32 * ROW_PX as i32 + ROW_PX as i32 / 2;
        let style = e.color.stroke_width(2);
        match e.mark {
            Mark::Dot => area
                .draw(&Circle::new((x + 12, y), 4, e.color.filled()))
                .map_err(plot_err)?,
            Mark::Triangle => area
                .draw(&TriangleMarker::new((x + 12, y), 6, e.color.filled()))
                .map_err(plot_err)?,
            Mark::Band => area
                .draw(&Rectangle::new([(x + 4, y - 6), (x + 24, y + 6)], e.color.mix(BAND_ALPHA).filled()))
                .map_err(plot_err)?,
            mark => {
                let segments = match mark.dashes() {
                    None => vec![(x, x + 28)],
                    Some((dash, gap)) => (0..)
                        .map(|k| x + k * (dash + gap) as i32)
                        .take_while(|&s| s < x + 28)
                        .map(|s| (s, (s + dash as i32).min(x + 28)))
                        .collect(),
                };
                for (a, b) in segments {
                    area.draw(&PathElement::new(vec![(a, y), (b, y)], style))
                        .map_err(plot_err)?;
                }
            }
        }
        area.draw(&Text::new(
            e.label.clone(),
            (x + 36, y - 8),
            (FONT, 14).into_font().color(&BLACK),
        ))
        .map_err(plot_err)?;
    }
    Ok(())
}

/// A parameter as the paper writes it: a value with at most two decimals
/// as a decimal (α = 0.2, Δ = 0.5), a unit fraction that has no short
/// decimal as `1/k` (PADA's Δ = 1/6 and 1/3 on LEO: one and two of the
/// seven levels' steps over the range), anything else in at most three
/// decimals.
pub fn parameter_text(value: f64) -> String {
    let short_decimal = ((value * 100.0) - (value * 100.0).round()).abs() < 1e-4;
    if !short_decimal && value > 0.0 && value < 1.0 {
        let k = (1.0 / value).round();
        if k >= 2.0 && (1.0 / value - k).abs() < 1e-4 * k {
            return format!("1/{k:.0}");
        }
    }
    let s = format!("{value:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_fractions_read_as_the_paper_writes_them() {
        assert_eq!(parameter_text(0.166_666_67_f32 as f64), "1/6");
        assert_eq!(parameter_text(0.333_333_34_f32 as f64), "1/3");
        assert_eq!(parameter_text(1.0 / 7.0), "1/7");
        assert_eq!(parameter_text(0.5), "0.5");
        assert_eq!(parameter_text(0.2_f32 as f64), "0.2");
        assert_eq!(parameter_text(0.05_f32 as f64), "0.05");
        assert_eq!(parameter_text(0.834_f32 as f64), "0.834");
        assert_eq!(parameter_text(0.25), "0.25");
        assert_eq!(parameter_text(0.7), "0.7");
        assert_eq!(parameter_text(1.0), "1");
    }
}
