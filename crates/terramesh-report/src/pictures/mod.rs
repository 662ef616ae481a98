//! Pictures of the pipeline, drawn with plotters as PNG and SVG: sample points over the
//! region, planar meshes, coloured and hill-shaded maps with contours, and a shaded 3D view.
//!
//! Every drawing is deterministic (no dates, a bundled font), so two builds give identical
//! files.

mod chart;
mod colour;
mod detail;
mod fill;
mod maps;
mod section;
mod view3d;

use std::path::{Path, PathBuf};

use plotters::prelude::*;

pub use chart::draw_variogram;
pub use colour::{hillshade, shade, ColourMap};
pub use detail::{central_detail, DETAIL_TRIANGLES};
pub use maps::{draw_mesh, draw_samples, draw_surface, SurfaceMap};
/// The colour type of [`draw_bodies_view3d`]'s facets and [`unit_colour`] (plotters').
pub use plotters::style::RGBColor;
pub use section::{draw_section, unit_colour, Section, SectionFault, SectionHole};
pub use view3d::{draw_bodies_view3d, draw_view3d};

/// Above this many triangles, the build draws mesh pictures as [`SvgMode::Raster`].
pub const VECTOR_TRIANGLE_LIMIT: usize = 100_000;

/// A picture failed to render or write.
#[derive(Debug, thiserror::Error)]
#[error("drawing {file}: {message}")]
pub struct PictureError {
    /// The output file.
    pub file: String,
    /// What went wrong.
    pub message: String,
}

/// Registers the bundled DejaVu Sans font once (no system fonts are needed).
fn ensure_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // Registration only fails on a malformed font, and the bundled one is fixed.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Renders one drawing as `stem.png` and `stem.svg` at `size` pixels; returns both paths.
///
/// The PNG and SVG are written to temporary files and renamed, as every output.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use plotters::prelude::*;
/// let dir = tempfile::tempdir()?;
/// let files = terramesh_report::pictures::render_both(&dir.path().join("dot"), (100, 80), |root| {
///     root.fill(&WHITE)?;
///     root.draw(&Circle::new((50, 40), 10, RED.filled()))?;
///     Ok(())
/// })?;
/// assert!(files[0].ends_with("dot.png") && files[1].ends_with("dot.svg"));
/// assert!(std::fs::read_to_string(&files[1])?.contains("<svg"));
/// # Ok(()) }
/// ```
pub fn render_both<F>(stem: &Path, size: (u32, u32), draw: F) -> Result<[PathBuf; 2], PictureError>
where
    F: Fn(
        &DrawingArea<DynBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
{
    render_both_as(stem, size, SvgMode::Vector, draw)
}

/// How [`render_both_as`] writes the SVG.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SvgMode {
    /// Every shape as an SVG element (the default).
    Vector,
    /// The PNG rendering inside the SVG as one embedded image: for drawings of millions of
    /// triangles, whose vector SVG would run to hundreds of megabytes.
    Raster,
}

/// Renders `draw` into PNG bytes (no time chunk).
fn png_bytes<F>(size: (u32, u32), draw: &F) -> Result<Vec<u8>, String>
where
    F: Fn(
        &DrawingArea<DynBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
{
    ensure_font();
    let mut pixels = vec![255u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = DynBackend::Pixels(&mut pixels, size).into_drawing_area();
        draw(&root).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    encode_png(&pixels, size)
}

/// Renders `draw` as SVG text.
fn svg_text<F>(size: (u32, u32), draw: &F) -> Result<String, String>
where
    F: Fn(
        &DrawingArea<DynBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
{
    ensure_font();
    let mut text = String::new();
    {
        let backend = SVGBackend::with_string(&mut text, size);
        let root = DynBackend::Svg(backend).into_drawing_area();
        draw(&root).map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(text)
}

/// Renders one drawing into `path`, as PNG or SVG by its extension.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use plotters::prelude::*;
/// let dir = tempfile::tempdir()?;
/// let dot = |root: &DrawingArea<terramesh_report::pictures::DynBackend<'_>, plotters::coord::Shift>|
///     -> Result<(), Box<dyn std::error::Error>> {
///     root.fill(&WHITE)?;
///     root.draw(&Circle::new((50, 40), 10, RED.filled()))?;
///     Ok(())
/// };
/// terramesh_report::pictures::render_file(&dir.path().join("dot.svg"), (100, 80), dot)?;
/// assert!(std::fs::read_to_string(dir.path().join("dot.svg"))?.contains("<circle"));
/// terramesh_report::pictures::render_file(&dir.path().join("dot.png"), (100, 80), dot)?;
/// assert!(std::fs::read(dir.path().join("dot.png"))?.starts_with(b"\x89PNG"));
/// assert!(terramesh_report::pictures::render_file(&dir.path().join("dot.gif"), (100, 80), dot).is_err());
/// # Ok(()) }
/// ```
pub fn render_file<F>(path: &Path, size: (u32, u32), draw: F) -> Result<(), PictureError>
where
    F: Fn(
        &DrawingArea<DynBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
{
    let err = |message: String| PictureError {
        file: path.display().to_string(),
        message,
    };
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes = match ext.as_str() {
        "png" => png_bytes(size, &draw).map_err(err)?,
        "svg" => svg_text(size, &draw).map_err(err)?.into_bytes(),
        _ => return Err(err("the file name must end in .png or .svg".into())),
    };
    terramesh_io::output::write_atomic(path, &bytes).map_err(|e| err(e.to_string()))
}

/// [`render_both`] with a choice of SVG content.
///
/// ```
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// use plotters::prelude::*;
/// use terramesh_report::pictures::{render_both_as, SvgMode};
/// let dir = tempfile::tempdir()?;
/// let files = render_both_as(&dir.path().join("dot"), (100, 80), SvgMode::Raster, |root| {
///     root.fill(&WHITE)?;
///     root.draw(&Circle::new((50, 40), 10, RED.filled()))?;
///     Ok(())
/// })?;
/// let svg = std::fs::read_to_string(&files[1])?;
/// assert!(svg.contains("<image") && svg.contains("data:image/png;base64,") && !svg.contains("<circle"));
/// # Ok(()) }
/// ```
pub fn render_both_as<F>(
    stem: &Path,
    size: (u32, u32),
    mode: SvgMode,
    draw: F,
) -> Result<[PathBuf; 2], PictureError>
where
    F: Fn(
        &DrawingArea<DynBackend<'_>, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>,
{
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    let err = |file: &Path, message: String| PictureError {
        file: file.display().to_string(),
        message,
    };
    let encoded = png_bytes(size, &draw).map_err(|e| err(&png, e))?;
    terramesh_io::output::write_atomic(&png, &encoded).map_err(|e| err(&png, e.to_string()))?;
    let text = match mode {
        SvgMode::Raster => {
            let (w, h) = size;
            let data = crate::report::base64(&encoded);
            format!(
                "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" \
                 width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n<image x=\"0\" y=\"0\" \
                 width=\"{w}\" height=\"{h}\" xlink:href=\"data:image/png;base64,{data}\"/>\n</svg>\n"
            )
        }
        SvgMode::Vector => svg_text(size, &draw).map_err(|e| err(&svg, e))?,
    };
    terramesh_io::output::write_atomic(&svg, text.as_bytes())
        .map_err(|e| err(&svg, e.to_string()))?;
    Ok([png, svg])
}

/// Encodes RGB pixels as PNG (no time chunk: identical input gives identical bytes).
fn encode_png(pixels: &[u8], size: (u32, u32)) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, size.0, size.1);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(pixels).map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// A drawing backend that is either a bitmap or an SVG, so one drawing function serves both.
pub enum DynBackend<'a> {
    /// Pixels.
    Bitmap(BitMapBackend<'a>),
    /// Vector.
    Svg(SVGBackend<'a>),
    /// An RGB buffer (3 bytes a pixel, row by row) of the given size: drawn as `Bitmap`
    /// draws, and open to [`RasterAccess`], through which the maps and the 3D view fill
    /// their triangles straight into it (the same pixels, without plotters' per-triangle
    /// costs).
    Pixels(&'a mut [u8], (u32, u32)),
}

/// A drawing backend that may hand out its RGB pixels: [`draw_surface`], [`draw_view3d`] and
/// [`draw_bodies_view3d`] then fill their triangles into them directly, pixel for pixel as
/// plotters' bitmap backend fills them; other backends draw plotters' polygons.
pub trait RasterAccess: plotters_backend::DrawingBackend {
    /// The RGB pixels (3 bytes a pixel, row by row) and their width and height, if the
    /// backend is such a buffer.
    fn rgb_pixels(&mut self) -> Option<(&mut [u8], (u32, u32))> {
        None
    }
}

impl RasterAccess for DynBackend<'_> {
    fn rgb_pixels(&mut self) -> Option<(&mut [u8], (u32, u32))> {
        match self {
            DynBackend::Pixels(buf, size) => Some((&mut **buf, *size)),
            _ => None,
        }
    }
}

impl RasterAccess for BitMapBackend<'_> {}

impl RasterAccess for SVGBackend<'_> {}

/// An element that draws nothing through plotters: drawn on an area, it runs its function
/// on the backend's pixels where the backend has them ([`on_canvas`]).
struct OnCanvas<F> {
    draw: F,
    done: std::cell::Cell<bool>,
}

impl<'a, C: 'a, F> plotters::element::PointCollection<'a, C> for &'a OnCanvas<F> {
    type Point = &'a C;
    type IntoIter = std::iter::Empty<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::empty()
    }
}

impl<DB: RasterAccess, F: Fn(&mut fill::Canvas)> plotters::element::Drawable<DB> for OnCanvas<F> {
    fn draw<I: Iterator<Item = plotters_backend::BackendCoord>>(
        &self,
        _: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), plotters_backend::DrawingErrorKind<DB::ErrorType>> {
        if let Some(mut canvas) = backend
            .rgb_pixels()
            .and_then(|(buf, size)| fill::Canvas::new(buf, size))
        {
            (self.draw)(&mut canvas);
            self.done.set(true);
        }
        Ok(())
    }
}

/// Runs `draw` on the pixels of `area`'s backend if it has them (see [`RasterAccess`]);
/// whether it ran.
fn on_canvas<DB, CT>(
    area: &DrawingArea<DB, CT>,
    draw: impl Fn(&mut fill::Canvas),
) -> Result<bool, Box<dyn std::error::Error>>
where
    DB: RasterAccess,
    DB::ErrorType: 'static,
    CT: plotters::coord::CoordTranslate,
{
    let element = OnCanvas {
        draw,
        done: std::cell::Cell::new(false),
    };
    area.draw(&element)?;
    Ok(element.done.get())
}

/// The pixel where `area` draws the point `p` of an element: its coordinates' translation,
/// clamped to the area (as `DrawingArea::draw` gives them to the backend).
fn pixel_of<DB, CT>(area: &DrawingArea<DB, CT>, p: &CT::From) -> (i32, i32)
where
    DB: plotters_backend::DrawingBackend,
    CT: plotters::coord::CoordTranslate,
{
    let (xs, ys) = area.get_pixel_range();
    let (x, y) = area.map_coordinate(p);
    (x.min(xs.end).max(xs.start), y.min(ys.end).max(ys.start))
}

/// Errors of either backend, as text.
#[derive(Debug)]
pub struct DynError(String);

impl std::fmt::Display for DynError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DynError {}

fn conv<E: std::error::Error + Send + Sync>(
    e: plotters_backend::DrawingErrorKind<E>,
) -> plotters_backend::DrawingErrorKind<DynError> {
    match e {
        plotters_backend::DrawingErrorKind::DrawingError(e) => {
            plotters_backend::DrawingErrorKind::DrawingError(DynError(e.to_string()))
        }
        plotters_backend::DrawingErrorKind::FontError(f) => {
            plotters_backend::DrawingErrorKind::FontError(f)
        }
    }
}

macro_rules! both {
    ($self:ident, $b:ident => $e:expr) => {
        match $self {
            DynBackend::Bitmap($b) => $e.map_err(conv),
            DynBackend::Svg($b) => $e.map_err(conv),
            DynBackend::Pixels(buf, size) => {
                // A bitmap backend over the buffer for this call (it keeps no state between
                // calls, and presenting a buffer does nothing).
                let mut bitmap = BitMapBackend::with_buffer(buf, *size);
                let $b = &mut bitmap;
                $e.map_err(conv)
            }
        }
    };
}

impl plotters_backend::DrawingBackend for DynBackend<'_> {
    type ErrorType = DynError;

    fn get_size(&self) -> (u32, u32) {
        match self {
            DynBackend::Bitmap(b) => b.get_size(),
            DynBackend::Svg(b) => b.get_size(),
            DynBackend::Pixels(_, size) => *size,
        }
    }
    fn ensure_prepared(&mut self) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.ensure_prepared())
    }
    fn present(&mut self) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.present())
    }
    fn draw_pixel(
        &mut self,
        point: plotters_backend::BackendCoord,
        color: plotters_backend::BackendColor,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.draw_pixel(point, color))
    }
    fn draw_line<S: plotters_backend::BackendStyle>(
        &mut self,
        from: plotters_backend::BackendCoord,
        to: plotters_backend::BackendCoord,
        style: &S,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.draw_line(from, to, style))
    }
    fn draw_rect<S: plotters_backend::BackendStyle>(
        &mut self,
        upper_left: plotters_backend::BackendCoord,
        bottom_right: plotters_backend::BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.draw_rect(upper_left, bottom_right, style, fill))
    }
    fn draw_path<
        S: plotters_backend::BackendStyle,
        I: IntoIterator<Item = plotters_backend::BackendCoord>,
    >(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.draw_path(path, style))
    }
    fn draw_circle<S: plotters_backend::BackendStyle>(
        &mut self,
        center: plotters_backend::BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.draw_circle(center, radius, style, fill))
    }
    fn fill_polygon<
        S: plotters_backend::BackendStyle,
        I: IntoIterator<Item = plotters_backend::BackendCoord>,
    >(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.fill_polygon(vert, style))
    }
    fn draw_text<TStyle: plotters_backend::BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: plotters_backend::BackendCoord,
    ) -> Result<(), plotters_backend::DrawingErrorKind<DynError>> {
        both!(self, b => b.draw_text(text, style, pos))
    }
}
