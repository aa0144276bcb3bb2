//! Figures in the style of the paper's Figs. 3–6, drawn with plotters as
//! SVG and rasterised to PNG with resvg. Text in the PNGs uses DejaVu Sans
//! embedded in the binary, so no system font is needed.

pub mod claims;
pub mod compare;
pub mod figures;
pub mod legend;
pub mod transfer;
pub mod wear;

use plotters::coord::Shift;
use plotters::prelude::*;
use resvg::{tiny_skia, usvg};
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// The font family the figures name (resolved to DejaVu Sans in the PNGs).
pub const FONT: &str = "sans-serif";

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

/// The figure as an SVG document.
pub fn to_svg<F: Figure>(figure: &F) -> anyhow::Result<String> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
        figure.draw(&root)?;
        root.present()
            .map_err(|e| anyhow::anyhow!("drawing SVG: {e}"))?;
    }
    Ok(svg)
}

/// The embedded fonts, with DejaVu Sans as every generic family.
fn fonts() -> Arc<usvg::fontdb::Database> {
    static DB: OnceLock<Arc<usvg::fontdb::Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let mut db = usvg::fontdb::Database::new();
        db.load_font_data(dejavu::sans::regular().to_vec());
        db.load_font_data(dejavu::sans::bold().to_vec());
        db.set_sans_serif_family("DejaVu Sans");
        db.set_serif_family("DejaVu Sans");
        db.set_monospace_family("DejaVu Sans");
        Arc::new(db)
    })
    .clone()
}

/// Rasterises an SVG document to PNG bytes.
pub fn svg_to_png(svg: &str) -> anyhow::Result<Vec<u8>> {
    let options = usvg::Options {
        fontdb: fonts(),
        font_family: "DejaVu Sans".into(),
        ..Default::default()
    };
    let tree =
        usvg::Tree::from_str(svg, &options).map_err(|e| anyhow::anyhow!("rendering SVG: {e}"))?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| anyhow::anyhow!("empty figure"))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    pixmap
        .encode_png()
        .map_err(|e| anyhow::anyhow!("encoding PNG: {e}"))
}

/// Writes `<stem>.svg` and `<stem>.png` into `dir`, each through a
/// temporary file and a rename.
pub fn save<F: Figure>(figure: &F, dir: &Path, stem: &str) -> anyhow::Result<()> {
    let svg = to_svg(figure)?;
    let png = svg_to_png(&svg)?;
    crate::output::write_atomic(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;
    crate::output::write_atomic(&dir.join(format!("{stem}.png")), &png)?;
    Ok(())
}

/// Maps a plotters error into anyhow.
pub fn plot_err<E: std::error::Error + Send + Sync + 'static>(
    e: DrawingAreaErrorKind<E>,
) -> anyhow::Error {
    anyhow::anyhow!("plotting: {e}")
}
