//! Plots for benchmark reports, one PNG per plot: scatter ("error against run time"), curves
//! on log-log axes (scaling: time against triangles, resolution, lights) and paired horizontal
//! bars (each pass beside its speed-of-light copy).
//!
//! [`write_curves_png`] joins each series' points in x order on log-log axes;
//! [`write_bars_png`] draws one pair of bars per row (value and its floor).
//!
//! [`write_scatter_png`] draws labelled points (e.g. each variant of a technique's knobs: x = its
//! lighting pass time, y = its max abs error against the reference) in one colour per
//! [`PlotSeries`], with a legend, axis titles and an optional log-scale y axis, into a 960x640
//! PNG. It is drawn with `plotters` into memory and written with
//! [`write_file_atomic`](crate::files::write_file_atomic), so a reader never sees half a file.
//!
//! Text is drawn with a system TrueType font, loaded once at run time (no font is compiled in):
//! DejaVu Sans (Debian/Ubuntu: `apt-get install fonts-dejavu-core`, listed in `tools/setup.sh`),
//! or any `.ttf` named by the `LUCENT_PLOT_FONT` environment variable. Without a font the writer
//! returns an error saying what to install; it never panics, whatever the data.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use image::{ExtendedColorType, ImageEncoder};
use plotters::backend::RGBPixel;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font::{FONT_CANDIDATES, FONT_ENV};
use crate::error::{LucentError, Result};

/// One labelled point of a plot.
#[derive(Debug, Clone, PartialEq)]
pub struct PlotPoint {
    /// Text drawn next to the point (e.g. the variant's knob setting).
    pub label: String,
    /// Horizontal position (e.g. lighting pass ms).
    pub x: f64,
    /// Vertical position (e.g. max abs error).
    pub y: f64,
}

/// A named group of points drawn in one colour (e.g. one knob's variants).
#[derive(Debug, Clone, PartialEq)]
pub struct PlotSeries {
    /// Shown in the legend; a series with an empty name gets no legend entry.
    pub name: String,
    /// The points, in any order.
    pub points: Vec<PlotPoint>,
}

/// Width of every plot, pixels.
const WIDTH: u32 = 960;
/// Height of every plot, pixels.
const HEIGHT: u32 = 640;

/// Smallest value drawn on a log axis when no value is positive.
const LOG_FLOOR: f64 = 1e-6;

/// Series colours (the "tab10" palette, then six darker hues so the SSS report's dozen series
/// each get their own), reused in order when there are more series.
const COLOURS: &[RGBColor] = &[
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 0),
    RGBColor(0, 70, 140),
    RGBColor(120, 0, 0),
    RGBColor(0, 110, 80),
    RGBColor(110, 90, 0),
    RGBColor(90, 0, 110),
];

/// Writes a scatter plot: x axis `x_label` (e.g. "lighting pass ms"), y axis `y_label` (e.g.
/// "max abs error"), log-scale y when `log_y`, each point annotated with its label, a legend of
/// series names, and `title` at the top. 960x640 pixels.
///
/// On a log axis, values <= 0 are clamped to the smallest positive value present (or 1e-6 when
/// none is), and the title says how many were.
///
/// Degenerate input still gives a plot: no points at all (or none finite) draws axes and
/// "no data"; a single point or all-equal x or y values get a padded axis range; points with a
/// NaN or infinite coordinate are left out and counted in the title, as are values clamped on a
/// log axis. Missing parent directories of `path` are created; the file is replaced atomically.
///
/// Errors: no usable font (see the module docs), coordinates too far apart to lay out an axis
/// (a range wider than `f64::MAX`, or on a log axis more than about 308 decades), or the file
/// cannot be written. Never panics.
pub fn write_scatter_png(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[PlotSeries],
    log_y: bool,
) -> Result<()> {
    ensure_font()?;
    let data = Prepared::new(series, log_y);
    let caption = data.caption(title);

    let mut rgb = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut rgb, (WIDTH, HEIGHT))
            .map_err(|e| LucentError::file(path, format!("cannot set up plot: {e}")))?;
        let root = backend.into_drawing_area();
        let drawn = draw(&root, &data, &caption, x_label, y_label, log_y)
            .and_then(|()| root.present().map_err(|e| e.to_string()));
        drawn.map_err(|e| LucentError::file(path, format!("cannot draw plot: {e}")))?;
    }

    let mut encoded = Vec::new();
    image::codecs::png::PngEncoder::new(&mut encoded)
        .write_image(&rgb, WIDTH, HEIGHT, ExtendedColorType::Rgb8)
        .map_err(|e| LucentError::file(path, format!("PNG encoding failed: {e}")))?;
    crate::files::write_file_atomic(path, &encoded)
}

/// Loads and registers the plot font as plotters' "sans-serif", once per process. The outcome
/// (also a failure) is cached: plotters needs `&'static` font bytes, so they are leaked, once.
fn ensure_font() -> Result<()> {
    static FONT: OnceLock<std::result::Result<(), (PathBuf, String)>> = OnceLock::new();
    match FONT.get_or_init(load_font) {
        Ok(()) => Ok(()),
        Err((path, message)) => Err(LucentError::file(path.clone(), message)),
    }
}

fn load_font() -> std::result::Result<(), (PathBuf, String)> {
    if let Some(wanted) = std::env::var_os(FONT_ENV).filter(|v| !v.is_empty()) {
        // An explicit choice that fails is an error, not a reason to pick another font.
        return register(Path::new(&wanted)).map_err(|message| {
            (
                PathBuf::from(&wanted),
                format!("{message} (named by {FONT_ENV})"),
            )
        });
    }
    let mut problems = Vec::new();
    for candidate in FONT_CANDIDATES {
        let candidate = Path::new(candidate);
        if !candidate.is_file() {
            continue;
        }
        match register(candidate) {
            Ok(()) => return Ok(()),
            Err(message) => problems.push(format!("{}: {message}", candidate.display())),
        }
    }
    let found = if problems.is_empty() {
        String::from("none of them exists")
    } else {
        problems.join("; ")
    };
    Err((
        PathBuf::from(FONT_CANDIDATES[0]),
        format!(
            "no usable font to draw plot text ({found}; looked for {}); install one: \
             apt-get install fonts-dejavu-core, or set {FONT_ENV} to a .ttf file",
            FONT_CANDIDATES.join(", ")
        ),
    ))
}

/// Reads `path` and registers it as "sans-serif". The bytes are leaked only after they were read.
fn register(path: &Path) -> std::result::Result<(), String> {
    let bytes = crate::files::read_capped(path, 64 << 20, "font")
        .map_err(|e| format!("cannot read font: {e}"))?;
    let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
    plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
        .map_err(|_| String::from("not a TrueType/OpenType font plotters can parse"))
}

/// A point as drawn: `(label, x, y)`.
type Drawn<'a> = (&'a str, f64, f64);

/// The input reduced to what is drawn: finite points only, log-axis values clamped.
struct Prepared<'a> {
    /// Per input series: its name and its drawable points `(label, x, y)`.
    series: Vec<(&'a str, Vec<Drawn<'a>>)>,
    /// Points left out because x or y is NaN or infinite.
    non_finite: usize,
    /// Values <= 0 moved up to `floor` on a log axis.
    clamped: usize,
    /// Where clamped values are drawn (log axis only).
    floor: f64,
}

impl<'a> Prepared<'a> {
    fn new(series: &'a [PlotSeries], log_y: bool) -> Self {
        let finite = |p: &&PlotPoint| p.x.is_finite() && p.y.is_finite();
        let total: usize = series.iter().map(|s| s.points.len()).sum();
        let kept: usize = series
            .iter()
            .map(|s| s.points.iter().filter(finite).count())
            .sum();
        // A log axis cannot show values <= 0: they are clamped to the smallest positive value
        // present (or LOG_FLOOR when none is), so they sit on the bottom edge of the data, and
        // the title says how many were moved.
        let floor = series
            .iter()
            .flat_map(|s| s.points.iter().filter(finite))
            .map(|p| p.y)
            .filter(|&y| y > 0.0)
            .fold(f64::INFINITY, f64::min);
        let floor = if floor.is_finite() { floor } else { LOG_FLOOR };
        let mut clamped = 0;
        let series = series
            .iter()
            .map(|s| {
                let points = s
                    .points
                    .iter()
                    .filter(finite)
                    .map(|p| {
                        let y = if log_y && p.y <= 0.0 {
                            clamped += 1;
                            floor
                        } else {
                            p.y
                        };
                        (p.label.as_str(), p.x, y)
                    })
                    .collect();
                (s.name.as_str(), points)
            })
            .collect();
        Prepared {
            series,
            non_finite: total - kept,
            clamped,
            floor,
        }
    }

    fn points(&self) -> impl Iterator<Item = &Drawn<'a>> + '_ {
        self.series.iter().flat_map(|(_, points)| points.iter())
    }

    fn is_empty(&self) -> bool {
        self.points().next().is_none()
    }

    /// `title` plus a note for every point not drawn where its value says.
    fn caption(&self, title: &str) -> String {
        let mut caption = title.to_string();
        if self.non_finite > 0 {
            let s = if self.non_finite == 1 { "" } else { "s" };
            caption += &format!(" ({} non-finite point{s} left out)", self.non_finite);
        }
        if self.clamped > 0 {
            let s = if self.clamped == 1 { "" } else { "s" };
            caption += &format!(
                " ({} value{s} <= 0 drawn at {})",
                self.clamped,
                format_tick(self.floor)
            );
        }
        caption
    }
}

/// The range of `values` with a 5% margin; a zero-width range is widened around its value. The
/// margin stops at `±f64::MAX`.
fn linear_range(values: impl Iterator<Item = f64>) -> std::result::Result<Range<f64>, String> {
    let (min, max) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let (min, max) = if min <= max { (min, max) } else { (0.0, 1.0) };
    let span = max - min;
    let pad = if span > 0.0 {
        0.05 * span
    } else {
        0.1 * min.abs()
    };
    let (mut lo, mut hi) = (min - pad, max + pad);
    if hi <= lo {
        // Zero, or too small for the padding to move it (subnormal values).
        (lo, hi) = (min - 1.0, max + 1.0);
    }
    let (mut lo, mut hi) = (lo.max(-f64::MAX), hi.min(f64::MAX));
    if !(hi - lo).is_finite() {
        // The margin made the span overflow: draw the data edge to edge.
        (lo, hi) = (min, max);
    }
    if !(hi > lo && (hi - lo).is_finite()) {
        return Err(format!(
            "values from {min:e} to {max:e} are too far apart to draw on one axis"
        ));
    }
    Ok(lo..hi)
}

/// Like [`linear_range`] on a log scale, for positive `values`: the margin is 5% of the decades
/// spanned, and a single value gets half a decade either side. Where the margin would leave the
/// range of `f64`, the axis ends at the data (or at `f64::MAX`).
fn log_range(values: impl Iterator<Item = f64>) -> std::result::Result<Range<f64>, String> {
    let (min, max) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let (min, max) = if min <= max && min > 0.0 {
        (min, max)
    } else {
        (LOG_FLOOR, 1.0)
    };
    let (lo, hi) = (min.log10(), max.log10());
    let span = hi - lo;
    let (lo, hi) = if span > 1e-9 {
        (lo - 0.05 * span, hi + 0.05 * span)
    } else {
        (lo - 0.5, hi + 0.5)
    };
    let lo = Some(10f64.powf(lo))
        .filter(|&v| v > 0.0 && v <= min)
        .unwrap_or(min);
    let hi = Some(10f64.powf(hi))
        .filter(|&v| v >= max)
        .unwrap_or(max)
        .min(f64::MAX);
    // plotters' log axis needs hi / lo finite (its tick search loops about hi / lo decades
    // times, without end when the ratio is infinite): drop the margin, or give up.
    let (lo, hi) = if (hi / lo).is_finite() {
        (lo, hi)
    } else {
        (min, max)
    };
    if !(hi > lo && (hi / lo).is_finite()) {
        return Err(format!(
            "values from {min:e} to {max:e} span too many decades to draw on a log axis"
        ));
    }
    Ok(lo..hi)
}

/// Tick and note text: up to 4 significant digits, scientific outside 0.01..100000.
fn format_tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return String::from("0");
    }
    if (1e-2..1e5).contains(&a) {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        let text = format!("{v:.decimals$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        let text = format!("{v:.2e}");
        match text.split_once('e') {
            Some((mantissa, exponent)) if mantissa.contains('.') => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                format!("{mantissa}e{exponent}")
            }
            _ => text,
        }
    }
}

type Area<'b> = DrawingArea<BitMapBackend<'b, RGBPixel>, Shift>;

fn draw(
    root: &Area<'_>,
    data: &Prepared<'_>,
    caption: &str,
    x_label: &str,
    y_label: &str,
    log_y: bool,
) -> std::result::Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let x_range = linear_range(data.points().map(|p| p.1))?;
    if data.is_empty() {
        // Axes with their titles but no ticks, and a note in the middle.
        return draw_chart(root, data, caption, x_label, y_label, 0.0..1.0, 0.0..1.0);
    }
    if log_y {
        let y_range = log_range(data.points().map(|p| p.2))?;
        draw_chart(
            root,
            data,
            caption,
            x_label,
            y_label,
            x_range,
            y_range.log_scale(),
        )
    } else {
        let y_range = linear_range(data.points().map(|p| p.2))?;
        draw_chart(root, data, caption, x_label, y_label, x_range, y_range)
    }
}

/// Draws the chart with y axis `y_spec` (a linear or a log range); with no points, draws the axes
/// and "no data".
fn draw_chart<Y>(
    root: &Area<'_>,
    data: &Prepared<'_>,
    caption: &str,
    x_label: &str,
    y_label: &str,
    x_range: Range<f64>,
    y_spec: Y,
) -> std::result::Result<(), String>
where
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    let (x_lo, x_span) = (x_range.start, x_range.end - x_range.start);
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range, y_spec)
        .map_err(err)?;

    let empty = data.is_empty();
    let ticks = if empty { 0 } else { 10 };
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_labels(ticks)
        .y_labels(ticks)
        .x_label_formatter(&|v| format_tick(*v))
        .y_label_formatter(&|v| format_tick(*v))
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 14))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;

    if empty {
        let (w, h) = chart.plotting_area().dim_in_pixel();
        let style = ("sans-serif", 28)
            .into_font()
            .color(&RGBColor(110, 110, 110))
            .pos(Pos::new(HPos::Center, VPos::Center));
        chart
            .plotting_area()
            .strip_coord_spec()
            .draw(&Text::new("no data", (w as i32 / 2, h as i32 / 2), style))
            .map_err(err)?;
        return Ok(());
    }

    let mut any_named = false;
    for (i, (name, points)) in data.series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let elements = points.iter().map(|&(label, x, y)| {
            // Labels of points in the right quarter go to the left of the marker, so they stay
            // inside the picture.
            let (dx, anchor) = if (x - x_lo) / x_span > 0.75 {
                (-8, HPos::Right)
            } else {
                (8, HPos::Left)
            };
            let style = ("sans-serif", 13)
                .into_font()
                .color(&RGBColor(40, 40, 40))
                .pos(Pos::new(anchor, VPos::Center));
            EmptyElement::at((x, y))
                + Circle::new((0, 0), 5, colour.filled())
                + Circle::new((0, 0), 5, BLACK.stroke_width(1))
                + Text::new(label.to_string(), (dx, 0), style)
        });
        let annotation = chart.draw_series(elements).map_err(err)?;
        if !name.is_empty() {
            any_named = true;
            annotation
                .label(name.to_string())
                .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
        }
    }
    if any_named {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(160, 160, 160))
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// Writes curves on log-log axes: each series' finite, positive points joined in x order, with
/// a marker per point, a legend and axis titles. 960x640 pixels. Points with a coordinate <= 0
/// or not finite cannot sit on a log axis: they are left out and counted in the title.
///
/// Errors as [`write_scatter_png`]. Never panics.
pub fn write_curves_png(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[PlotSeries],
) -> Result<()> {
    ensure_font()?;
    let usable = |p: &&PlotPoint| p.x.is_finite() && p.y.is_finite() && p.x > 0.0 && p.y > 0.0;
    let total: usize = series.iter().map(|s| s.points.len()).sum();
    let mut kept: Vec<(&str, Vec<(f64, f64)>)> = series
        .iter()
        .map(|s| {
            let mut pts: Vec<(f64, f64)> =
                s.points.iter().filter(usable).map(|p| (p.x, p.y)).collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            (s.name.as_str(), pts)
        })
        .collect();
    kept.retain(|(_, pts)| !pts.is_empty());
    let drawn: usize = kept.iter().map(|(_, p)| p.len()).sum();
    let mut caption = title.to_string();
    if drawn < total {
        caption += &format!(" ({} point(s) <= 0 or non-finite left out)", total - drawn);
    }
    let mut rgb = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut rgb, (WIDTH, HEIGHT))
            .map_err(|e| LucentError::file(path, format!("cannot set up plot: {e}")))?;
        let root = backend.into_drawing_area();
        let drawn = draw_curves(&root, &kept, &caption, x_label, y_label)
            .and_then(|()| root.present().map_err(|e| e.to_string()));
        drawn.map_err(|e| LucentError::file(path, format!("cannot draw plot: {e}")))?;
    }
    encode_png(path, &rgb)
}

fn encode_png(path: &Path, rgb: &[u8]) -> Result<()> {
    let mut encoded = Vec::new();
    image::codecs::png::PngEncoder::new(&mut encoded)
        .write_image(rgb, WIDTH, HEIGHT, ExtendedColorType::Rgb8)
        .map_err(|e| LucentError::file(path, format!("PNG encoding failed: {e}")))?;
    crate::files::write_file_atomic(path, &encoded)
}

fn draw_curves(
    root: &Area<'_>,
    series: &[(&str, Vec<(f64, f64)>)],
    caption: &str,
    x_label: &str,
    y_label: &str,
) -> std::result::Result<(), String> {
    let err = |e: DrawingAreaErrorKind<_>| e.to_string();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let xs = series.iter().flat_map(|(_, p)| p.iter().map(|q| q.0));
    let ys = series.iter().flat_map(|(_, p)| p.iter().map(|q| q.1));
    let x_range = log_range(xs)?;
    let y_range = log_range(ys)?;
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(x_label)
        .y_desc(y_label)
        .x_label_formatter(&|v| format_tick(*v))
        .y_label_formatter(&|v| format_tick(*v))
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 14))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    if series.is_empty() {
        let (w, h) = chart.plotting_area().dim_in_pixel();
        let style = ("sans-serif", 28)
            .into_font()
            .color(&RGBColor(110, 110, 110))
            .pos(Pos::new(HPos::Center, VPos::Center));
        chart
            .plotting_area()
            .strip_coord_spec()
            .draw(&Text::new("no data", (w as i32 / 2, h as i32 / 2), style))
            .map_err(err)?;
        return Ok(());
    }
    for (i, (name, points)) in series.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()];
        let line = chart
            .draw_series(std::iter::once(PathElement::new(
                points.clone(),
                colour.stroke_width(2),
            )))
            .map_err(err)?;
        if !name.is_empty() {
            line.label(name.to_string()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
            });
        }
        chart
            .draw_series(
                points
                    .iter()
                    .map(|&(x, y)| Circle::new((x, y), 4, colour.filled())),
            )
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.6))
        .border_style(RGBColor(160, 160, 160))
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// One row of a bar plot: a value and the floor it is measured against.
#[derive(Debug, Clone, PartialEq)]
pub struct BarRow {
    /// Row label (a pass name).
    pub label: String,
    /// The measured value (pass ms).
    pub value: f64,
    /// Its floor (copy ms), if any.
    pub floor: Option<f64>,
}

/// Writes horizontal bars, one pair per row: `value_name` (e.g. "pass") in the first colour and
/// `floor_name` (e.g. "copy") in grey below it, x axis `x_label` from 0. 960x640 pixels; more
/// than about 30 rows get thin bars. Non-finite or negative values are drawn as 0 and counted
/// in the title.
///
/// Errors as [`write_scatter_png`]. Never panics.
pub fn write_bars_png(
    path: &Path,
    title: &str,
    x_label: &str,
    value_name: &str,
    floor_name: &str,
    rows: &[BarRow],
) -> Result<()> {
    ensure_font()?;
    let clean = |v: f64| if v.is_finite() && v >= 0.0 { v } else { 0.0 };
    let bad = rows
        .iter()
        .flat_map(|r| std::iter::once(r.value).chain(r.floor))
        .filter(|v| !(v.is_finite() && *v >= 0.0))
        .count();
    let mut caption = title.to_string();
    if bad > 0 {
        caption += &format!(" ({bad} value(s) not finite or < 0 drawn as 0)");
    }
    let max = rows
        .iter()
        .flat_map(|r| std::iter::once(clean(r.value)).chain(r.floor.map(clean)))
        .fold(0.0f64, f64::max);
    let x_max = if max > 0.0 { max * 1.08 } else { 1.0 };
    let mut rgb = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut rgb, (WIDTH, HEIGHT))
            .map_err(|e| LucentError::file(path, format!("cannot set up plot: {e}")))?;
        let root = backend.into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| e.to_string();
        let drawn = (|| -> std::result::Result<(), String> {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let n = rows.len().max(1) as f64;
            let labels: Vec<String> = rows.iter().map(|r| r.label.clone()).collect();
            let label_width = labels
                .iter()
                .map(|l| l.len())
                .max()
                .unwrap_or(4)
                .clamp(4, 40);
            let mut chart = ChartBuilder::on(&root)
                .caption(&caption, ("sans-serif", 22))
                .margin(16)
                .x_label_area_size(48)
                .y_label_area_size((label_width * 7 + 16) as u32)
                .build_cartesian_2d(0.0..x_max, 0.0..n)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_labels(0)
                .x_label_formatter(&|v| format_tick(*v))
                .axis_desc_style(("sans-serif", 17))
                .label_style(("sans-serif", 13))
                .disable_y_mesh()
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(err)?;
            // Row labels by hand, centred on each row's pair of bars, right-aligned left of
            // the axis (the mesh's own ticks would not sit on the rows).
            let label_style = ("sans-serif", 13)
                .into_font()
                .color(&RGBColor(40, 40, 40))
                .pos(Pos::new(HPos::Right, VPos::Center));
            for (i, label) in labels.iter().enumerate() {
                let (px, py) = chart.backend_coord(&(0.0, n - i as f64 - 0.5));
                root.draw(&Text::new(label.clone(), (px - 8, py), label_style.clone()))
                    .map_err(err)?;
            }
            let colour = COLOURS[0];
            let grey = RGBColor(150, 150, 150);
            for (i, r) in rows.iter().enumerate() {
                let top = n - i as f64;
                let value = clean(r.value);
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(0.0, top - 0.1), (value, top - 0.5)],
                        colour.filled(),
                    )))
                    .map_err(err)?;
                if let Some(f) = r.floor {
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(0.0, top - 0.5), (clean(f), top - 0.9)],
                            grey.filled(),
                        )))
                        .map_err(err)?;
                }
            }
            // Legend by hand, below the x axis at the right, clear of the bars.
            for (k, (name, c)) in [(value_name, colour), (floor_name, grey)]
                .iter()
                .enumerate()
            {
                let y = HEIGHT as i32 - 22;
                let x = WIDTH as i32 - 330 + 150 * k as i32;
                root.draw(&Rectangle::new([(x, y), (x + 16, y + 12)], c.filled()))
                    .map_err(err)?;
                root.draw(&Text::new(
                    name.to_string(),
                    (x + 22, y),
                    ("sans-serif", 14).into_font(),
                ))
                .map_err(err)?;
            }
            Ok(())
        })()
        .and_then(|()| root.present().map_err(|e| e.to_string()));
        drawn.map_err(|e| LucentError::file(path, format!("cannot draw plot: {e}")))?;
    }
    encode_png(path, &rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_and_bars_decode_and_are_not_blank() {
        let dir = temp_dir("curves");
        let curves = dir.join("curves.png");
        let data = [
            series(
                "gbuffer",
                &[("", 3e3, 0.5), ("", 1e5, 4.0), ("", 1e6, 30.0)],
            ),
            series(
                "tonemap",
                &[("", 3e3, 1.0), ("", 1e5, 1.0), ("", 1e6, -1.0)],
            ),
        ];
        write_curves_png(&curves, "time against triangles", "triangles", "ms", &data).unwrap();
        check_png(&curves);
        let empty = dir.join("curves-empty.png");
        write_curves_png(&empty, "empty", "x", "y", &[]).unwrap();
        check_png(&empty);
        let bars = dir.join("bars.png");
        let rows = [
            BarRow {
                label: "gbuffer + lighting".into(),
                value: 12.0,
                floor: Some(3.0),
            },
            BarRow {
                label: "tonemap".into(),
                value: f64::NAN,
                floor: None,
            },
        ];
        write_bars_png(&bars, "passes", "ms", "pass", "copy", &rows).unwrap();
        check_png(&bars);
        let empty = dir.join("bars-empty.png");
        write_bars_png(&empty, "no rows", "ms", "pass", "copy", &[]).unwrap();
        check_png(&empty);
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lucent-plot-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn point(label: &str, x: f64, y: f64) -> PlotPoint {
        PlotPoint {
            label: label.to_string(),
            x,
            y,
        }
    }

    fn series(name: &str, points: &[(&str, f64, f64)]) -> PlotSeries {
        PlotSeries {
            name: name.to_string(),
            points: points.iter().map(|&(l, x, y)| point(l, x, y)).collect(),
        }
    }

    /// Decodes `path` and checks its size and that it is more than one colour.
    fn check_png(path: &Path) {
        let image = image::open(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .into_rgb8();
        assert_eq!((image.width(), image.height()), (WIDTH, HEIGHT));
        let first = image.get_pixel(0, 0);
        assert!(
            image.pixels().any(|p| p != first),
            "{} is a single colour",
            path.display()
        );
    }

    #[test]
    fn two_series_plot_decodes_and_is_not_blank() {
        let dir = temp_dir("two");
        let path = dir.join("error_vs_time.png");
        let data = [
            series(
                "samples",
                &[
                    ("4 spp", 1.2, 0.08),
                    ("8 spp", 2.1, 0.03),
                    ("16 spp", 3.9, 0.011),
                ],
            ),
            series(
                "radius",
                &[
                    ("r=0.5", 1.5, 0.05),
                    ("r=1", 1.9, 0.02),
                    ("r=2", 2.6, 0.004),
                ],
            ),
        ];
        for (name, log_y) in [("linear.png", false), ("log.png", true)] {
            let path = dir.join(name);
            write_scatter_png(
                &path,
                "skin: error against run time",
                "lighting pass ms",
                "max abs error",
                &data,
                log_y,
            )
            .unwrap();
            check_png(&path);
        }
        write_scatter_png(&path, "t", "x", "y", &data, true).unwrap();
        check_png(&path);
        let leftovers = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 3, "temporary file left behind");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn degenerate_input_still_gives_a_plot() {
        let dir = temp_dir("degenerate");
        let nan = f64::NAN;
        let inf = f64::INFINITY;
        let cases: Vec<(&str, Vec<PlotSeries>)> = vec![
            ("no_series", vec![]),
            ("empty_series", vec![series("a", &[]), series("", &[])]),
            ("single", vec![series("a", &[("only", 2.0, 0.5)])]),
            (
                "equal_x",
                vec![series("a", &[("p", 3.0, 0.1), ("q", 3.0, 0.2)])],
            ),
            (
                "equal_y",
                vec![series("a", &[("p", 1.0, 0.25), ("q", 2.0, 0.25)])],
            ),
            ("zero", vec![series("a", &[("z", 0.0, 0.0)])]),
            (
                "non_finite",
                vec![
                    series("a", &[("nan", nan, 1.0), ("ok", 1.0, 0.1)]),
                    series("b", &[("inf", 2.0, inf), ("-inf", -inf, 0.0)]),
                ],
            ),
            (
                "all_non_finite",
                vec![series("a", &[("nan", nan, nan), ("inf", inf, 1.0)])],
            ),
            (
                "non_positive",
                vec![series("a", &[("zero", 1.0, 0.0), ("neg", 2.0, -1.0)])],
            ),
            (
                "extreme",
                vec![series(
                    "a",
                    &[("tiny", 1e-300, 1e-300), ("huge", 1e300, 1e7)],
                )],
            ),
            (
                "subnormal",
                vec![series("a", &[("s", 5e-324, 5e-324), ("t", 1e-310, 1e-320)])],
            ),
            (
                "close",
                vec![series(
                    "a",
                    &[("p", 1e12, 1.0), ("q", 1e12 + 1e-3, 1.0 + 1e-15)],
                )],
            ),
            (
                "max",
                vec![series("a", &[("m", f64::MAX, f64::MAX), ("n", 0.0, 1.0)])],
            ),
            (
                "unnamed_many",
                (0..12)
                    .map(|i| series("", &[("p", i as f64, (i * i) as f64)]))
                    .collect(),
            ),
        ];
        for (name, data) in &cases {
            for log_y in [false, true] {
                let path = dir.join(format!("{name}-{log_y}.png"));
                write_scatter_png(
                    &path,
                    name,
                    "lighting pass ms",
                    "max abs error",
                    data,
                    log_y,
                )
                .unwrap_or_else(|e| panic!("{name} (log_y {log_y}): {e}"));
                check_png(&path);
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn coordinates_too_far_apart_are_an_error() {
        let dir = temp_dir("far");
        let data = [series(
            "a",
            &[("low", -f64::MAX, 1.0), ("high", f64::MAX, 2.0)],
        )];
        let message = write_scatter_png(&dir.join("far.png"), "t", "x", "y", &data, false)
            .unwrap_err()
            .to_string();
        assert!(message.contains("far.png"), "{message}");
        // More decades than a log axis can hold (their ratio overflows f64).
        let data = [series("a", &[("tiny", 1.0, 5e-324), ("huge", 2.0, 1e300)])];
        let message = write_scatter_png(&dir.join("decades.png"), "t", "x", "y", &data, true)
            .unwrap_err()
            .to_string();
        assert!(message.contains("decades"), "{message}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn captions_count_what_is_not_drawn_as_given() {
        let data = [
            series(
                "a",
                &[("nan", f64::NAN, 1.0), ("zero", 1.0, 0.0), ("ok", 2.0, 0.5)],
            ),
            series("b", &[("inf", 1.0, f64::INFINITY), ("neg", 3.0, -2.0)]),
        ];
        assert_eq!(
            Prepared::new(&data, true).caption("t"),
            "t (2 non-finite points left out) (2 values <= 0 drawn at 0.5)"
        );
        assert_eq!(
            Prepared::new(&data, false).caption("t"),
            "t (2 non-finite points left out)"
        );
        let none: [PlotSeries; 0] = [];
        let empty = Prepared::new(&none, true);
        assert!(empty.is_empty());
        assert_eq!(empty.caption("t"), "t");
    }

    #[test]
    fn a_file_that_is_not_a_font_is_refused() {
        let dir = temp_dir("font");
        std::fs::create_dir_all(&dir).unwrap();
        let not_font = dir.join("not-a-font.ttf");
        std::fs::write(&not_font, b"not a font").unwrap();
        let message = register(&not_font).unwrap_err();
        assert!(message.contains("not a TrueType"), "{message}");
        let message = register(&dir.join("missing.ttf")).unwrap_err();
        assert!(message.contains("cannot read font"), "{message}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(format_tick(0.0), "0");
        assert_eq!(format_tick(0.05), "0.05");
        assert_eq!(format_tick(12.5), "12.5");
        assert_eq!(format_tick(1234.0), "1234");
        assert_eq!(format_tick(1.5e-3), "1.5e-3");
        assert_eq!(format_tick(1e-6), "1e-6");
        assert_eq!(format_tick(-2.5e7), "-2.5e7");
    }

    #[test]
    fn unwritable_path_is_an_error_naming_it() {
        // A path below a regular file: not creatable even by root, unlike "/nonexistent-dir".
        let dir = temp_dir("unwritable");
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("file");
        std::fs::write(&file, b"x").unwrap();
        let data = [series("a", &[("p", 1.0, 1.0)])];
        for path in [file.join("x.png"), PathBuf::from("/proc/lucent-plot/x.png")] {
            let message = write_scatter_png(&path, "t", "x", "y", &data, false)
                .unwrap_err()
                .to_string();
            assert!(message.contains("x.png"), "{message}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
