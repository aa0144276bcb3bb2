//! Figures in the style of the paper's Figs. 3–6, drawn with plotters as
//! SVG and PNG. Text uses DejaVu Sans embedded in the binary, so no system
//! font is needed.

pub mod figures;

use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// The font family the figures use.
pub const FONT: &str = "sans-serif";

/// Registers the embedded DejaVu Sans as [`FONT`] (once per process).
pub fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is a valid TrueType file; a failure would only
        // leave text undrawn in the PNGs, which the tests would notice.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

/// A figure that can draw itself on any plotters backend.
pub trait Figure {
    /// Pixel size.
    fn size(&self) -> (u32, u32) {
        (960, 640)
    }

    /// Draws the figure on `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static;
}

/// Writes `<stem>.svg` and `<stem>.png` into `dir`, each through a
/// temporary file and a rename.
pub fn save<F: Figure>(figure: &F, dir: &Path, stem: &str) -> anyhow::Result<()> {
    register_fonts();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
        figure.draw(&root)?;
        root.present()
            .map_err(|e| anyhow::anyhow!("drawing {stem}.svg: {e}"))?;
    }
    crate::output::write_atomic(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;

    let tmp = tempfile::Builder::new()
        .prefix(".pada-")
        .suffix(".png")
        .tempfile_in(dir)
        .map_err(|e| anyhow::anyhow!("cannot write in {}: {e}", dir.display()))?;
    {
        let root = BitMapBackend::new(tmp.path(), figure.size()).into_drawing_area();
        figure.draw(&root)?;
        root.present()
            .map_err(|e| anyhow::anyhow!("drawing {stem}.png: {e}"))?;
    }
    let path = dir.join(format!("{stem}.png"));
    tmp.persist(&path)
        .map_err(|e| anyhow::anyhow!("cannot write {}: {}", path.display(), e.error))?;
    Ok(())
}

/// Maps a plotters error into anyhow.
pub fn plot_err<E: std::error::Error + Send + Sync + 'static>(
    e: DrawingAreaErrorKind<E>,
) -> anyhow::Error {
    anyhow::anyhow!("plotting: {e}")
}
