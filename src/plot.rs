//! Figures as plain data, drawn by plotters to PNG and SVG.
//!
//! A [`Figure`] is a grid of [`Panel`]s; a panel holds [`Series`] (lines,
//! points with ±σ error bars, markers, filled polygons in data coordinates)
//! and optionally one heat map. The experiments build figures
//! from their results and [`Figure::save`] writes `name.png` and `name.svg`.
//! Log axes are drawn by plotting `log10` of the data on linear axes with
//! `10^k` tick labels, so one code path serves every panel.
use crate::error::Error;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// What a series draws.
#[derive(Debug, Clone, PartialEq)]
pub enum Mark {
    /// A polyline through `(x, y)`.
    Line(Vec<(f64, f64)>),
    /// A dashed polyline through `(x, y)`.
    Dashed(Vec<(f64, f64)>),
    /// A wide dashed polyline: a curve that may lie on another one. Drawn
    /// before it, the other runs on top through its dashes, and both show.
    Dashes(Vec<(f64, f64)>),
    /// Points `(x, mean, σ)` with ±σ error bars.
    Points(Vec<(f64, f64, f64)>),
    /// A thin (1 px) polyline through `(x, y)`: many light lines, such as
    /// sampled paths.
    Thin(Vec<(f64, f64)>),
    /// Hollow circles at `(x, y)`.
    Circles(Vec<(f64, f64)>),
    /// Filled circles at `(x, y)`, as large as [`Mark::Circles`].
    Dots(Vec<(f64, f64)>),
    /// Hollow triangles at `(x, y)`, pointing up where the flag is set and
    /// down where not: values beyond a clamped axis, drawn at the clamp.
    Triangles(Vec<(f64, f64, bool)>),
    /// A closed polygon through `vertices` (in data coordinates), outlined
    /// and filled with the series colour at `opacity` (in `[0, 1]`).
    Polygon {
        /// The vertices, in order; the last connects back to the first.
        vertices: Vec<(f64, f64)>,
        /// Opacity of the fill (the outline is opaque).
        opacity: f64,
    },
}

/// One labelled series of a panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend label (empty: no legend entry).
    pub label: String,
    /// Index into the palette.
    pub color: usize,
    /// The data.
    pub mark: Mark,
}

impl Series {
    /// A legend entry of dots without error bars (points drawn elsewhere
    /// without a label, such as errors): a series that draws nothing.
    pub fn legend_dot(label: &str, color: usize) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Points(vec![(f64::NAN, f64::NAN, 0.0)]),
        }
    }

    /// A line series.
    pub fn line(label: &str, color: usize, xy: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Line(xy),
        }
    }

    /// A dashed line series.
    pub fn dashed(label: &str, color: usize, xy: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Dashed(xy),
        }
    }

    /// A wide dashed line series (drawn under a line it may lie on).
    pub fn dashes(label: &str, color: usize, xy: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Dashes(xy),
        }
    }

    /// Points with ±σ error bars.
    pub fn points(label: &str, color: usize, xys: Vec<(f64, f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Points(xys),
        }
    }

    /// A thin (1 px) polyline.
    pub fn thin(label: &str, color: usize, xy: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Thin(xy),
        }
    }

    /// Filled circles as large as [`Series::circles`].
    pub fn dots(label: &str, color: usize, xy: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Dots(xy),
        }
    }

    /// Hollow circles.
    pub fn circles(label: &str, color: usize, xy: Vec<(f64, f64)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Circles(xy),
        }
    }

    /// Hollow triangles at the clamp line of values beyond it (`up`:
    /// beyond the top).
    pub fn triangles(label: &str, color: usize, xyu: Vec<(f64, f64, bool)>) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Triangles(xyu),
        }
    }

    /// This series' legend entry alone: its label, colour and kind of mark
    /// without data (it draws nothing), for a legend whose entries keep
    /// their order while the data are drawn in another.
    pub fn key(&self) -> Series {
        Series {
            label: self.label.clone(),
            color: self.color,
            mark: match &self.mark {
                Mark::Points(_) => Mark::Points(match Glyph::of(&self.mark) {
                    Glyph::Dot => vec![(f64::NAN, f64::NAN, 0.0)],
                    _ => vec![],
                }),
                Mark::Circles(_) => Mark::Circles(vec![]),
                Mark::Dots(_) => Mark::Dots(vec![]),
                Mark::Triangles(_) => Mark::Triangles(vec![]),
                Mark::Thin(_) => Mark::Thin(vec![]),
                Mark::Dashed(_) => Mark::Dashed(vec![]),
                Mark::Dashes(_) => Mark::Dashes(vec![]),
                Mark::Line(_) => Mark::Line(vec![]),
                Mark::Polygon { opacity, .. } => Mark::Polygon {
                    vertices: vec![],
                    opacity: *opacity,
                },
            },
        }
    }

    /// A filled polygon in data coordinates (a bar, a shape of a scene).
    pub fn polygon(label: &str, color: usize, vertices: Vec<(f64, f64)>, opacity: f64) -> Series {
        Series {
            label: label.into(),
            color,
            mark: Mark::Polygon { vertices, opacity },
        }
    }
}

/// A heat map over a grid of cells.
#[derive(Debug, Clone, PartialEq)]
pub struct HeatMap {
    /// Cell edges along x (`nx + 1` values, in axis units).
    pub x_edges: Vec<f64>,
    /// Cell edges along y (`ny + 1` values, in axis units).
    pub y_edges: Vec<f64>,
    /// `values[iy * nx + ix]`; NaN draws grey.
    pub values: Vec<f64>,
    /// Values mapped to the two ends of the colour scale.
    pub range: (f64, f64),
}

/// One chart.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Panel {
    /// Caption above the chart.
    pub title: String,
    /// Label of the x axis.
    pub x_label: String,
    /// Label of the y axis.
    pub y_label: String,
    /// Logarithmic x axis.
    pub x_log: bool,
    /// Logarithmic y axis.
    pub y_log: bool,
    /// The series drawn.
    pub series: Vec<Series>,
    /// A heat map drawn under the series.
    pub heat: Option<HeatMap>,
    /// Where the legend goes.
    pub legend: Legend,
    /// Names for the integer x ticks `0, 1, …` (categorical axes, e.g. heat
    /// map cells centred on integers); empty for numeric ticks.
    pub x_tick_names: Vec<String>,
    /// Names for the integer y ticks, as `x_tick_names`.
    pub y_tick_names: Vec<String>,
    /// Fixed x range in data units (instead of the data's, padded).
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range in data units (instead of the data's, padded).
    pub y_range: Option<(f64, f64)>,
    /// Draw no axes, only the legend of the series (at the upper left, in
    /// a larger font): a figure's shared legend in a panel of its own. The
    /// series should hold no data.
    pub legend_only: bool,
    /// Font size of the tick labels instead of the default (crowded
    /// categorical axes).
    pub tick_size: Option<u32>,
    /// One unit takes as many pixels along x as along y (drawings of
    /// scenes): the shorter data range is widened about its centre to the
    /// chart's aspect. Linear axes only.
    pub equal_aspect: bool,
}

/// Legend placement: a strip between a panel's title and its chart (the
/// default), or a corner inside the chart. A corner is kept only if the
/// legend's box, measured in pixels, covers no drawn point there; otherwise
/// the legend goes above the chart, so that it never hides data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Above the chart, under the title, entries side by side in rows.
    #[default]
    Above,
    /// Upper right corner.
    UpperRight,
    /// Upper left corner.
    UpperLeft,
    /// Lower left corner.
    LowerLeft,
    /// Lower right corner.
    LowerRight,
}

/// A grid of panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Panels, row by row.
    pub panels: Vec<Panel>,
    /// Panels per row.
    pub columns: usize,
    /// Size of one panel in pixels.
    pub panel_size: (u32, u32),
    /// A legend shared by every panel, drawn as a strip across the top of
    /// the figure (series without data: only their label, colour and
    /// mark count); empty: none.
    pub legend: Vec<Series>,
}

/// The palette: colour-blind-safe (Okabe–Ito).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// A plotters error as the crate's.
pub(crate) fn plot_err<E: std::fmt::Debug>(e: E) -> Error {
    Error::Output(format!("plotting failed: {e:?}"))
}

/// `v` in axis units (log10 on log axes); `None` if not drawable.
fn axis(v: f64, log: bool) -> Option<f64> {
    let a = if log { v.log10() } else { v };
    a.is_finite().then_some(a)
}

/// Data range of a panel in axis units, padded.
fn bounds(p: &Panel) -> ((f64, f64), (f64, f64)) {
    let (mut xs, mut ys) = (Vec::new(), Vec::new());
    for s in &p.series {
        match &s.mark {
            Mark::Line(v)
            | Mark::Dashed(v)
            | Mark::Dashes(v)
            | Mark::Thin(v)
            | Mark::Circles(v)
            | Mark::Dots(v)
            | Mark::Polygon { vertices: v, .. } => v.iter().for_each(|&(x, y)| {
                xs.push(axis(x, p.x_log));
                ys.push(axis(y, p.y_log));
            }),
            Mark::Points(v) => v.iter().for_each(|&(x, m, e)| {
                xs.push(axis(x, p.x_log));
                ys.push(axis(m - e, p.y_log));
                ys.push(axis(m + e, p.y_log));
                ys.push(axis(m, p.y_log));
            }),
            Mark::Triangles(v) => v.iter().for_each(|&(x, y, _)| {
                xs.push(axis(x, p.x_log));
                ys.push(axis(y, p.y_log));
            }),
        }
    }
    if let Some(h) = &p.heat {
        xs.extend(h.x_edges.iter().map(|&x| Some(x)));
        ys.extend(h.y_edges.iter().map(|&y| Some(y)));
    }
    let span = |v: Vec<Option<f64>>, pad: f64| {
        let v: Vec<f64> = v.into_iter().flatten().collect();
        let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        if !lo.is_finite() {
            return (0.0, 1.0);
        }
        let w = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
        (lo - pad * w, hi + pad * w)
    };
    let pad = if p.heat.is_some() { 0.0 } else { 0.04 };
    let fixed = |range: Option<(f64, f64)>, log: bool| {
        let (lo, hi) = range?;
        let (lo, hi) = (axis(lo, log)?, axis(hi, log)?);
        (hi > lo).then_some((lo, hi))
    };
    (
        fixed(p.x_range, p.x_log).unwrap_or_else(|| span(xs, pad)),
        fixed(p.y_range, p.y_log).unwrap_or_else(|| span(ys, pad)),
    )
}

/// A colour on a blue–white–red scale for `t ∈ [0, 1]`.
pub fn diverging(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let lerp = |a: f64, b: f64, u: f64| (a + (b - a) * u).round() as u8;
    if t < 0.5 {
        let u = t / 0.5;
        RGBColor(
            lerp(33.0, 247.0, u),
            lerp(102.0, 247.0, u),
            lerp(172.0, 247.0, u),
        )
    } else {
        let u = (t - 0.5) / 0.5;
        RGBColor(
            lerp(247.0, 178.0, u),
            lerp(247.0, 24.0, u),
            lerp(247.0, 43.0, u),
        )
    }
}

/// Width of [`Mark::Dashes`], in pixels: wide enough to show on both
/// sides of a 2-pixel line drawn over it.
const DASHES_WIDTH: u32 = 6;

/// Margin around every chart, in pixels.
const MARGIN: u32 = 12;
/// Height of the x axis' label area, in pixels.
const X_LABEL_AREA: u32 = 54;
/// Width of the y axis' label area, in pixels.
const Y_LABEL_AREA: u32 = 88;
/// Font size of panel titles.
const TITLE_SIZE: u32 = 20;
/// Font size of tick labels and axis descriptions.
const AXIS_SIZE: u32 = 16;
/// Font size of legend entries.
const LEGEND_SIZE: u32 = 17;
/// Font size of a figure's shared legend.
const SHARED_LEGEND_SIZE: u32 = 20;
/// Width of a legend entry's mark, in pixels.
const GLYPH_W: i32 = 28;
/// Gap between a legend mark and its text, and around a legend box.
const LEGEND_PAD: i32 = 8;
/// Gap between two entries of a legend row, in pixels.
const ENTRY_GAP: i32 = 24;
/// Distance of a corner legend from the chart's edges, in pixels.
const LEGEND_INSET: i32 = 8;

/// Smallest font size a long title shrinks to.
const MIN_TITLE_SIZE: u32 = 12;

/// The font size of `title` in an area `width` pixels wide: the title size,
/// or smaller for a title that would not fit between the margins (plotters
/// centres a caption and cuts what overhangs at both ends).
fn title_size(title: &str, width: u32) -> u32 {
    let room = width.saturating_sub(2 * MARGIN);
    let wide = |size: u32| {
        ("sans-serif", size)
            .into_font()
            .box_size(title)
            .map_or(0, |(w, _)| w)
    };
    (MIN_TITLE_SIZE..=TITLE_SIZE)
        .rev()
        .find(|&size| wide(size) <= room)
        .unwrap_or(MIN_TITLE_SIZE)
}

/// Height of a title's block in an area `width` pixels wide (plotters
/// draws a caption with half its height, at most 5 px, above and below).
fn title_height(title: &str, width: u32) -> u32 {
    if title.is_empty() {
        return 0;
    }
    let size = title_size(title, width);
    let h = ("sans-serif", size)
        .into_font()
        .box_size(title)
        .map_or(size, |(_, h)| h);
    h + 2 * (h / 2).min(5)
}

/// The chart's plotting area, in pixels, in an area of size `(w, h)` with
/// a caption `title` (plotters lays a chart out as margin, then title,
/// then label areas; this repeats that arithmetic).
fn plot_size((w, h): (u32, u32), title: &str, top_margin: u32) -> (f64, f64) {
    let pw = f64::from(w.saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1));
    let ph = f64::from(
        h.saturating_sub(MARGIN + top_margin + title_height(title, w) + X_LABEL_AREA)
            .max(1),
    );
    (pw, ph)
}

/// `x` and `y` ranges widened so that one unit spans as many pixels along
/// both axes of a plotting area of `(pw, ph)` pixels.
fn equal_aspect(
    (pw, ph): (f64, f64),
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> ((f64, f64), (f64, f64)) {
    let unit = ((x1 - x0) / pw).max((y1 - y0) / ph);
    let widen = |lo: f64, hi: f64, px: f64| {
        let (c, half) = (0.5 * (lo + hi), 0.5 * unit * px);
        (c - half, c + half)
    };
    (widen(x0, x1, pw), widen(y0, y1, ph))
}

/// What a legend entry shows for a series.
#[derive(Debug, Clone, Copy)]
enum Glyph {
    /// A short line of this width.
    Line(u32),
    /// A short dashed line of this width.
    Dash(u32),
    /// A filled box of this opacity.
    Fill(f64),
    /// A hollow circle.
    Ring,
    /// Hollow triangles, one up and one down.
    Triangles,
    /// A dot with an error bar: an estimate.
    Estimate,
    /// A dot: points without error bars.
    Dot,
}

impl Glyph {
    fn of(mark: &Mark) -> Glyph {
        match mark {
            Mark::Polygon { opacity, .. } => Glyph::Fill(opacity.max(0.3)),
            Mark::Circles(_) => Glyph::Ring,
            Mark::Dots(_) => Glyph::Dot,
            Mark::Triangles(_) => Glyph::Triangles,
            Mark::Points(v) if !v.is_empty() && v.iter().all(|p| p.2 == 0.0) => Glyph::Dot,
            Mark::Points(_) => Glyph::Estimate,
            Mark::Thin(_) => Glyph::Line(1),
            Mark::Dashed(_) => Glyph::Dash(2),
            Mark::Dashes(_) => Glyph::Dash(DASHES_WIDTH),
            Mark::Line(_) => Glyph::Line(3),
        }
    }
}

/// One legend entry.
struct Entry {
    label: String,
    color: RGBColor,
    glyph: Glyph,
}

/// The legend entries of `series`: one per label, in order.
fn entries<'a>(series: impl IntoIterator<Item = &'a Series>) -> Vec<Entry> {
    let mut out: Vec<Entry> = Vec::new();
    for s in series {
        if s.label.is_empty() || out.iter().any(|e| e.label == s.label) {
            continue;
        }
        out.push(Entry {
            label: s.label.clone(),
            color: PALETTE[s.color % PALETTE.len()],
            glyph: Glyph::of(&s.mark),
        });
    }
    out
}

/// Width in pixels of `e` (mark, gap, text) in a font of `size`.
fn entry_width(e: &Entry, size: u32) -> i32 {
    let text = ("sans-serif", size)
        .into_font()
        .box_size(&e.label)
        .map_or(size * e.label.chars().count() as u32 / 2, |(w, _)| w);
    GLYPH_W + LEGEND_PAD + text as i32
}

/// Height of one legend row for a font of `size`.
fn row_height(size: u32) -> i32 {
    (size as f64 * 1.5).round() as i32
}

/// Legend rows: per row, each entry's index and x offset in pixels.
type Rows = Vec<Vec<(usize, i32)>>;

/// The entries laid out in rows no wider than `width`.
fn legend_rows(entries: &[Entry], size: u32, width: i32) -> Rows {
    let mut rows: Rows = Vec::new();
    let mut x = 0;
    for (i, e) in entries.iter().enumerate() {
        let w = entry_width(e, size);
        match rows.last_mut() {
            Some(row) if x + w <= width => row.push((i, x)),
            _ => {
                rows.push(vec![(i, 0)]);
                x = 0;
            }
        }
        x += w + ENTRY_GAP;
    }
    rows
}

/// A hollow triangle of [`Mark::Triangles`] centred at `c` (pixels), `r`
/// from its centre to its tip, pointing up or down.
fn triangle(c: (i32, i32), r: i32, up: bool, color: RGBColor) -> PathElement<(i32, i32)> {
    let s = if up { -1 } else { 1 };
    let tip = (c.0, c.1 + s * r);
    PathElement::new(
        vec![
            tip,
            (c.0 - r, c.1 - s * r * 2 / 3),
            (c.0 + r, c.1 - s * r * 2 / 3),
            tip,
        ],
        color.stroke_width(2),
    )
}

/// Draws `e`'s mark and label with the mark's left end at `(x, y)`
/// (pixels of `area`; `y` is the row's middle).
fn draw_entry<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    e: &Entry,
    size: u32,
) -> Result<(), Error> {
    let c = e.color;
    let mid = x + GLYPH_W / 2;
    match e.glyph {
        Glyph::Line(w) => area.draw(&PathElement::new(
            vec![(x, y), (x + GLYPH_W, y)],
            c.stroke_width(w),
        )),
        Glyph::Dash(w) => area
            .draw(&PathElement::new(
                vec![(x, y), (x + 10, y)],
                c.stroke_width(w),
            ))
            .and_then(|_| {
                area.draw(&PathElement::new(
                    vec![(x + 17, y), (x + GLYPH_W, y)],
                    c.stroke_width(w),
                ))
            }),
        Glyph::Fill(a) => area
            .draw(&Rectangle::new(
                [(x, y - 7), (x + GLYPH_W, y + 7)],
                c.mix(a).filled(),
            ))
            .and_then(|_| {
                area.draw(&Rectangle::new(
                    [(x, y - 7), (x + GLYPH_W, y + 7)],
                    c.stroke_width(1),
                ))
            }),
        Glyph::Ring => area.draw(&Circle::new((mid, y), 6, c.stroke_width(2))),
        Glyph::Triangles => area
            .draw(&triangle((mid - 7, y), 6, true, c))
            .and_then(|_| area.draw(&triangle((mid + 7, y), 6, false, c))),
        Glyph::Estimate => area
            .draw(&PathElement::new(
                vec![(mid, y - 8), (mid, y + 8)],
                c.stroke_width(1),
            ))
            .and_then(|_| {
                area.draw(&PathElement::new(
                    vec![(mid - 4, y - 8), (mid + 4, y - 8)],
                    c.stroke_width(1),
                ))
            })
            .and_then(|_| {
                area.draw(&PathElement::new(
                    vec![(mid - 4, y + 8), (mid + 4, y + 8)],
                    c.stroke_width(1),
                ))
            })
            .and_then(|_| area.draw(&Circle::new((mid, y), 5, c.filled()))),
        Glyph::Dot => area.draw(&Circle::new((mid, y), 5, c.filled())),
    }
    .map_err(plot_err)?;
    let style = ("sans-serif", size)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    area.draw(&Text::new(
        e.label.clone(),
        (x + GLYPH_W + LEGEND_PAD, y),
        style,
    ))
    .map_err(plot_err)
}

/// Draws `rows` of `entries` from `(x, y)` (the top left of the first row).
fn draw_rows<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, y): (i32, i32),
    entries: &[Entry],
    rows: &[Vec<(usize, i32)>],
    size: u32,
) -> Result<(), Error> {
    let rh = row_height(size);
    for (r, row) in rows.iter().enumerate() {
        for &(i, dx) in row {
            draw_entry(
                area,
                (x + dx, y + r as i32 * rh + rh / 2),
                &entries[i],
                size,
            )?;
        }
    }
    Ok(())
}

/// Size in pixels of a boxed legend listing `entries` one per row.
fn list_size(entries: &[Entry], size: u32) -> (i32, i32) {
    let w = entries
        .iter()
        .map(|e| entry_width(e, size))
        .max()
        .unwrap_or(0);
    (
        w + 2 * LEGEND_PAD,
        entries.len() as i32 * row_height(size) + LEGEND_PAD,
    )
}

/// Draws `entries` one per row in a white box with its top left at `at`.
fn draw_list<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    at: (i32, i32),
    entries: &[Entry],
    size: u32,
    boxed: bool,
) -> Result<(), Error> {
    let (w, h) = list_size(entries, size);
    if boxed {
        let rect = [at, (at.0 + w, at.1 + h)];
        area.draw(&Rectangle::new(rect, WHITE.mix(0.9).filled()))
            .and_then(|_| area.draw(&Rectangle::new(rect, BLACK.stroke_width(1))))
            .map_err(plot_err)?;
    }
    let rows: Vec<Vec<(usize, i32)>> = (0..entries.len()).map(|i| vec![(i, 0)]).collect();
    draw_rows(
        area,
        (at.0 + LEGEND_PAD, at.1 + LEGEND_PAD / 2),
        entries,
        &rows,
        size,
    )
}

/// The points a panel draws, in axis units: every point and error bar,
/// lines and polygon outlines sampled along their segments.
fn drawn_points(panel: &Panel) -> Vec<(f64, f64)> {
    let to_axis = |v: f64, log: bool| if log { v.log10() } else { v };
    let mut pts = Vec::new();
    let mut push = |x: f64, y: f64| {
        let (x, y) = (to_axis(x, panel.x_log), to_axis(y, panel.y_log));
        if x.is_finite() && y.is_finite() {
            pts.push((x, y));
        }
    };
    for s in &panel.series {
        let (v, closed) = match &s.mark {
            Mark::Points(v) => {
                for &(x, y, e) in v {
                    push(x, y);
                    for k in 1..=4 {
                        let d = e * f64::from(k) / 4.0;
                        push(x, y - d);
                        push(x, y + d);
                    }
                }
                continue;
            }
            Mark::Circles(v) | Mark::Dots(v) => {
                v.iter().for_each(|&(x, y)| push(x, y));
                continue;
            }
            Mark::Triangles(v) => {
                v.iter().for_each(|&(x, y, _)| push(x, y));
                continue;
            }
            Mark::Line(v) | Mark::Dashed(v) | Mark::Dashes(v) | Mark::Thin(v) => (v, false),
            Mark::Polygon { vertices, .. } => (vertices, true),
        };
        let close = if closed { v.first().copied() } else { None };
        let line: Vec<(f64, f64)> = v.iter().copied().chain(close).collect();
        for w in line.windows(2) {
            for k in 0..16 {
                let t = f64::from(k) / 16.0;
                push(
                    w[0].0 + t * (w[1].0 - w[0].0),
                    w[0].1 + t * (w[1].1 - w[0].1),
                );
            }
        }
        if let Some(&(x, y)) = line.last() {
            push(x, y);
        }
    }
    pts
}

/// How many of `pts` (axis units) fall in the box of `size` (fractions of
/// the ranges `(x0, x1)`, `(y0, y1)`) in `corner`.
fn count_in_corner(
    pts: &[(f64, f64)],
    ((x0, x1), (y0, y1)): ((f64, f64), (f64, f64)),
    corner: Legend,
    size: (f64, f64),
) -> usize {
    let (left, low) = match corner {
        Legend::UpperLeft => (true, false),
        Legend::UpperRight | Legend::Above => (false, false),
        Legend::LowerLeft => (true, true),
        Legend::LowerRight => (false, true),
    };
    let (w, h) = (size.0 * (x1 - x0), size.1 * (y1 - y0));
    pts.iter()
        .filter(|&&(x, y)| {
            (if left { x <= x0 + w } else { x >= x1 - w })
                && (if low { y <= y0 + h } else { y >= y1 - h })
        })
        .count()
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, p: &Panel) -> Result<(), Error> {
    let title_style = ("sans-serif", title_size(&p.title, area.dim_in_pixel().0));
    if p.legend_only {
        let body = if p.title.is_empty() {
            area.clone()
        } else {
            area.titled(&p.title, title_style).map_err(plot_err)?
        };
        let list = entries(&p.series);
        let at = (MARGIN as i32, MARGIN as i32);
        return draw_list(&body, at, &list, TITLE_SIZE, false);
    }
    let list = entries(&p.series);
    let dim = area.dim_in_pixel();
    let aspect = p.equal_aspect && !p.x_log && !p.y_log;
    let ranges = |plot: (f64, f64)| {
        let (xr, yr) = bounds(p);
        if aspect {
            equal_aspect(plot, xr, yr)
        } else {
            (xr, yr)
        }
    };
    // A corner legend stays only where its measured box covers nothing.
    let mut place = (!list.is_empty()).then_some(p.legend);
    if let Some(corner) = place.filter(|&c| c != Legend::Above) {
        let plot = plot_size(dim, &p.title, MARGIN);
        let (bw, bh) = list_size(&list, LEGEND_SIZE);
        let size = (
            f64::from(bw + 2 * LEGEND_INSET) / plot.0,
            f64::from(bh + 2 * LEGEND_INSET) / plot.1,
        );
        if count_in_corner(&drawn_points(p), ranges(plot), corner, size) > 0 {
            place = Some(Legend::Above);
        }
    }
    let (chart_area, title, top) = if place == Some(Legend::Above) {
        let left = (MARGIN + Y_LABEL_AREA) as i32;
        let width = dim.0 as i32 - left - MARGIN as i32;
        let rows = legend_rows(&list, LEGEND_SIZE, width);
        let strip = rows.len() as i32 * row_height(LEGEND_SIZE) + LEGEND_PAD;
        let head_title = title_height(&p.title, dim.0) as i32;
        let (head, body) = area.split_vertically(MARGIN as i32 + head_title + strip);
        if !p.title.is_empty() {
            let style = title_style
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Top));
            head.draw(&Text::new(
                p.title.clone(),
                (dim.0 as i32 / 2, MARGIN as i32 + 5.min(head_title / 4)),
                style,
            ))
            .map_err(plot_err)?;
        }
        draw_rows(
            &head,
            (left, MARGIN as i32 + head_title),
            &list,
            &rows,
            LEGEND_SIZE,
        )?;
        (body, "", 4)
    } else {
        (area.clone(), p.title.as_str(), MARGIN)
    };
    let ((x0, x1), (y0, y1)) = ranges(plot_size(chart_area.dim_in_pixel(), title, top));
    let mut builder = ChartBuilder::on(&chart_area);
    if !title.is_empty() {
        builder.caption(title, title_style);
    }
    let mut chart = builder
        .margin(MARGIN)
        .margin_top(top)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_err)?;
    let fmt_x = |v: &f64| named_tick(*v, p.x_log, &p.x_tick_names);
    let fmt_y = |v: &f64| named_tick(*v, p.y_log, &p.y_tick_names);
    chart
        .configure_mesh()
        .x_desc(p.x_label.as_str())
        .y_desc(p.y_label.as_str())
        .x_label_formatter(&fmt_x)
        .y_label_formatter(&fmt_y)
        .x_labels(label_count(&p.x_tick_names))
        .y_labels(label_count(&p.y_tick_names))
        .label_style(("sans-serif", p.tick_size.unwrap_or(AXIS_SIZE)))
        .axis_desc_style(("sans-serif", AXIS_SIZE))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_err)?;
    if let Some(h) = &p.heat {
        let nx = h.x_edges.len() - 1;
        let cells = h.values.iter().enumerate().map(|(i, &v)| {
            let (ix, iy) = (i % nx, i / nx);
            let color = if v.is_finite() {
                diverging((v - h.range.0) / (h.range.1 - h.range.0))
            } else {
                RGBColor(160, 160, 160)
            };
            Rectangle::new(
                [
                    (h.x_edges[ix], h.y_edges[iy]),
                    (h.x_edges[ix + 1], h.y_edges[iy + 1]),
                ],
                color.filled(),
            )
        });
        chart.draw_series(cells).map_err(plot_err)?;
    }
    for s in &p.series {
        let color = PALETTE[s.color % PALETTE.len()];
        let to_axis = |&(x, y): &(f64, f64)| Some((axis(x, p.x_log)?, axis(y, p.y_log)?));
        match &s.mark {
            Mark::Line(v) => chart
                .draw_series(LineSeries::new(
                    v.iter().filter_map(to_axis),
                    color.stroke_width(2),
                ))
                .map(|_| ()),
            Mark::Dashed(v) => chart
                .draw_series(DashedLineSeries::new(
                    v.iter().filter_map(to_axis),
                    6,
                    4,
                    color.stroke_width(1),
                ))
                .map(|_| ()),
            Mark::Dashes(v) => chart
                .draw_series(DashedLineSeries::new(
                    v.iter().filter_map(to_axis),
                    10,
                    6,
                    color.stroke_width(DASHES_WIDTH),
                ))
                .map(|_| ()),
            Mark::Points(v) => chart
                .draw_series(v.iter().filter_map(|&(x, m, e)| {
                    let x = axis(x, p.x_log)?;
                    let mid = axis(m, p.y_log)?;
                    let lo = axis(m - e, p.y_log).unwrap_or(y0);
                    let hi = axis(m + e, p.y_log)?;
                    Some(ErrorBar::new_vertical(x, lo, mid, hi, color.filled(), 6))
                }))
                .map(|_| ()),
            Mark::Thin(v) => chart
                .draw_series(LineSeries::new(
                    v.iter().filter_map(to_axis),
                    color.stroke_width(1),
                ))
                .map(|_| ()),
            Mark::Circles(v) => chart
                .draw_series(
                    v.iter()
                        .filter_map(to_axis)
                        .map(|c| Circle::new(c, 6, color.stroke_width(2))),
                )
                .map(|_| ()),
            Mark::Dots(v) => chart
                .draw_series(
                    v.iter()
                        .filter_map(to_axis)
                        .map(|c| Circle::new(c, 6, color.filled())),
                )
                .map(|_| ()),
            Mark::Triangles(v) => chart
                .draw_series(v.iter().filter_map(|&(x, y, up)| {
                    let c = to_axis(&(x, y))?;
                    Some(EmptyElement::at(c) + triangle((0, 0), 7, up, color))
                }))
                .map(|_| ()),
            Mark::Polygon { vertices, opacity } => {
                let v: Vec<(f64, f64)> = vertices.iter().filter_map(to_axis).collect();
                let outline = v.first().map(|&first| v.iter().copied().chain([first]));
                let fill = chart
                    .draw_series(std::iter::once(Polygon::new(
                        v.clone(),
                        color.mix(opacity.clamp(0.0, 1.0)).filled(),
                    )))
                    .map(|_| ());
                fill.and_then(|_| {
                    chart
                        .draw_series(outline.map(|o| {
                            PathElement::new(o.collect::<Vec<_>>(), color.stroke_width(1))
                        }))
                        .map(|_| ())
                })
            }
        }
        .map_err(plot_err)?;
    }
    if let Some(corner) = place.filter(|&c| c != Legend::Above) {
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        let base = chart_area.get_base_pixel();
        let (w, h) = list_size(&list, LEGEND_SIZE);
        let x = match corner {
            Legend::UpperLeft | Legend::LowerLeft => xs.start + LEGEND_INSET,
            _ => xs.end - LEGEND_INSET - w,
        };
        let y = match corner {
            Legend::LowerLeft | Legend::LowerRight => ys.end - LEGEND_INSET - h,
            _ => ys.start + LEGEND_INSET,
        };
        draw_list(
            &chart_area,
            (x - base.0, y - base.1),
            &list,
            LEGEND_SIZE,
            true,
        )?;
    }
    Ok(())
}

/// Legend-sized box of [`quiet_corner`]'s callers: 45% of a chart's width,
/// 40% of its height.
pub const LEGEND_BOX: (f64, f64) = (0.45, 0.4);

/// The corner of `panel`'s chart, out of `prefer` (in order of preference),
/// whose legend-sized box (`size`: fractions of the data ranges' width and
/// height, e.g. [`LEGEND_BOX`]) covers the fewest drawn points (lines and
/// polygon outlines sampled along their segments, error bars), with that
/// count. The drawing moves the legend above the chart if its measured box
/// there still covers a point.
pub fn quiet_corner(panel: &Panel, prefer: &[Legend], size: (f64, f64)) -> (Legend, usize) {
    let pts = drawn_points(panel);
    let span = |f: fn(&(f64, f64)) -> f64| {
        pts.iter()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let ranges = (span(|p| p.0), span(|p| p.1));
    prefer
        .iter()
        .map(|&c| (c, count_in_corner(&pts, ranges, c, size)))
        .min_by_key(|&(_, n)| n)
        .unwrap_or_default()
}

/// `x` moved by a small step (2.5 % of a decade on a log axis, of `step`
/// on a linear one) for the `k`-th of `n` series drawn at the same
/// abscissae, so that equal estimates of different series stand side by
/// side instead of on top of each other.
pub fn spread(x: f64, k: usize, n: usize, log: bool, step: f64) -> f64 {
    let offset = k as f64 - 0.5 * (n.max(1) - 1) as f64;
    if log {
        x * 10f64.powf(0.025 * offset)
    } else {
        x + step * offset
    }
}

/// Tick label on an axis with `names` for its integer ticks (categorical),
/// or the value if `names` is empty.
fn named_tick(v: f64, log: bool, names: &[String]) -> String {
    if names.is_empty() {
        return tick(v, log);
    }
    let i = v.round();
    let name = (i >= 0.0 && (v - i).abs() < 1e-9).then(|| names.get(i as usize));
    name.flatten().cloned().unwrap_or_default()
}

/// How many tick labels an axis asks for: every name of a categorical axis
/// (plotters then puts one at each integer), plotters' default of 10 else.
fn label_count(names: &[String]) -> usize {
    if names.is_empty() { 10 } else { names.len() }
}

/// A colour legend for heat maps: a panel whose heat map is a horizontal
/// strip of the colours that a heat map with `range` (as [`HeatMap::range`];
/// it may decrease) gives the values `span.0..span.1`, with the values on the
/// x axis labelled `label`. The strip fills the lower third of the chart; the
/// room above is for the legend of any series the caller adds (markers drawn
/// over the heat maps, say).
pub fn colour_bar(title: &str, label: &str, range: (f64, f64), span: (f64, f64)) -> Panel {
    const STEPS: usize = 200;
    let (lo, hi) = (span.0.min(span.1), span.0.max(span.1));
    let x_edges: Vec<f64> = (0..=STEPS)
        .map(|i| lo + (hi - lo) * i as f64 / STEPS as f64)
        .collect();
    let values = x_edges.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    Panel {
        title: title.into(),
        x_label: label.into(),
        // One invisible point lifts the y range above the strip.
        series: vec![Series::line("", 0, vec![(lo, 2.5)])],
        heat: Some(HeatMap {
            x_edges,
            y_edges: vec![-0.5, 0.5],
            values,
            range,
        }),
        y_tick_names: vec![String::new()],
        ..Panel::default()
    }
}

/// Tick label: the value, or `10^v` on a log axis.
fn tick(v: f64, log: bool) -> String {
    if log {
        let p = 10f64.powf(v);
        if (v - v.round()).abs() < 1e-9 {
            format!("1e{}", v.round())
        } else {
            format!("{p:.1e}")
        }
    } else if v.abs() < 1e-12 {
        "0".into()
    } else if v.abs() < 1e-2 || v.abs() >= 1e4 {
        format!("{v:.1e}")
    } else {
        // Four significant digits at least, so that ticks a quarter of a
        // step apart (−0.03075, −0.0308) keep different labels.
        let decimals = (3 - v.abs().log10().floor() as i32).max(4) as usize;
        format!("{v:.decimals$}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    }
}

impl Figure {
    /// A figure of `panels`, `columns` per row, 640×440 pixels each.
    pub fn new(panels: Vec<Panel>, columns: usize) -> Figure {
        Figure {
            panels,
            columns: columns.max(1),
            panel_size: (640, 440),
            legend: Vec::new(),
        }
    }

    /// Moves the labels of every panel's series (one entry per label) into
    /// the figure's shared [`legend`](Figure::legend), for panels that
    /// share their series' styles.
    pub fn share_legend(mut self) -> Figure {
        for p in &mut self.panels {
            for s in &mut p.series {
                if !s.label.is_empty() && !self.legend.iter().any(|l| l.label == s.label) {
                    self.legend.push(s.key());
                }
                s.label.clear();
            }
        }
        self
    }

    /// The shared legend's entries and rows, and the strip's height.
    fn legend_strip(&self) -> (Vec<Entry>, Rows, u32) {
        let list = entries(&self.legend);
        if list.is_empty() {
            return (list, Vec::new(), 0);
        }
        let width =
            (self.panel_size.0 * self.columns as u32) as i32 - 2 * (MARGIN + Y_LABEL_AREA) as i32;
        let rows = legend_rows(&list, SHARED_LEGEND_SIZE, width);
        let h = rows.len() as i32 * row_height(SHARED_LEGEND_SIZE) + 2 * MARGIN as i32;
        (list, rows, h as u32)
    }

    fn size(&self) -> (u32, u32) {
        let rows = self.panels.len().div_ceil(self.columns) as u32;
        (
            self.panel_size.0 * self.columns as u32,
            self.panel_size.1 * rows.max(1) + self.legend_strip().2,
        )
    }

    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), Error> {
        root.fill(&WHITE).map_err(plot_err)?;
        let (list, rows, strip) = self.legend_strip();
        let (head, body) = root.split_vertically(strip);
        if !list.is_empty() {
            // The rows centred across the figure.
            let widest = rows
                .iter()
                .filter_map(|r| {
                    let &(i, x) = r.last()?;
                    Some(x + entry_width(&list[i], SHARED_LEGEND_SIZE))
                })
                .max()
                .unwrap_or(0);
            let x = (head.dim_in_pixel().0 as i32 - widest) / 2;
            draw_rows(&head, (x, MARGIN as i32), &list, &rows, SHARED_LEGEND_SIZE)?;
        }
        let grid = self.panels.len().div_ceil(self.columns).max(1);
        let areas = body.split_evenly((grid, self.columns));
        for (p, area) in self.panels.iter().zip(areas.iter()) {
            draw_panel(area, p)?;
        }
        root.present().map_err(plot_err)
    }

    /// Writes `dir/name.png` and `dir/name.svg`, creating `dir`.
    pub fn save(&self, dir: &Path, name: &str) -> Result<Vec<PathBuf>, Error> {
        std::fs::create_dir_all(dir)
            .map_err(|e| Error::Output(format!("cannot create {}: {e}", dir.display())))?;
        let png = dir.join(format!("{name}.png"));
        let svg = dir.join(format!("{name}.svg"));
        self.draw(BitMapBackend::new(&png, self.size()).into_drawing_area())?;
        self.draw(SVGBackend::new(&svg, self.size()).into_drawing_area())?;
        Ok(vec![png, svg])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn panel(series: Vec<Series>) -> Panel {
        Panel {
            title: "t".into(),
            series,
            ..Panel::default()
        }
    }

    #[test]
    fn fixed_ranges_override_the_data() {
        let mut p = panel(vec![Series::line("", 0, vec![(0.0, 0.0), (1.0, 1.0)])]);
        p.x_range = Some((-2.0, 3.0));
        let ((x0, x1), (y0, y1)) = bounds(&p);
        assert_eq!((x0, x1), (-2.0, 3.0));
        assert!(y0 < 0.0 && y1 > 1.0);
    }

    #[test]
    fn polygons_count_for_the_quiet_corner() {
        // A filled box in the upper right: the legend goes elsewhere.
        let p = panel(vec![
            Series::polygon(
                "box",
                0,
                vec![(0.6, 0.6), (1.0, 0.6), (1.0, 1.0), (0.6, 1.0)],
                0.5,
            ),
            Series::circles("", 1, vec![(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]),
        ]);
        let (corner, _) = quiet_corner(&p, &[Legend::UpperRight, Legend::LowerLeft], LEGEND_BOX);
        assert_eq!(corner, Legend::LowerLeft);
    }

    #[test]
    fn every_mark_draws() {
        let dir = std::env::temp_dir().join(format!("geosens-plot-{}", std::process::id()));
        let mut scene = panel(vec![
            Series::polygon("shape", 0, vec![(0.0, 0.0), (2.0, 0.0), (1.0, 1.0)], 0.3),
            Series::thin("path", 1, vec![(0.0, 0.0), (1.0, 2.0)]),
            Series::circles("corner", 2, vec![(2.0, 0.0)]),
            Series::points("dot", 3, vec![(1.0, 1.0, 0.0)]),
        ]);
        scene.equal_aspect = true;
        let legend = Panel {
            series: vec![Series::polygon("only a legend", 4, vec![], 1.0)],
            legend_only: true,
            ..Panel::default()
        };
        let written = Figure::new(vec![scene, legend], 2)
            .save(&dir, "marks")
            .unwrap();
        for path in &written {
            assert!(std::fs::metadata(path).unwrap().len() > 1000);
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
