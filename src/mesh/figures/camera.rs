//! The showcase camera (`scenes/mesh/showcase.toml`, compiled in) rendered
//! by every derivative method: one grid of images, rows `I` then `∂I/∂π`
//! for each shape parameter, columns finite differences, rendering,
//! transport, expectation. Every panel is the image itself, one screen
//! pixel block per camera pixel: `I` in the perceptual map from 0, each
//! sensitivity in the diverging map centred on 0, with one scale per row
//! (the [`robust_scale`] of the finite-difference image) written beside it,
//! so that the columns of a row compare colour for colour. Under each panel,
//! the image's mean pixel value with its standard error.
//!
//! Written as `mesh_camera.png` only: an SVG of `16 × 128²` pixel rectangles
//! would weigh tens of megabytes. The numbers go to `mesh_camera.json`.
//!
//! Book: chapter "Three dimensions", section "A camera".
use super::FigureOptions;
use crate::error::Error;
use crate::estimator::Quantity;
use crate::image::{ImageResult, render};
use crate::image_io::{NON_FINITE_RGB, diverging_map, magnitude_map, robust_scale, scale_tag};
use crate::mesh::Scene;
use crate::method::{Method, Problem};
use crate::plot::plot_err;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Paths per pixel at effort 1: the four renders take about 10 s on 2
/// cores.
pub const SPP: u64 = 64;

/// The columns, in order: the reference first.
pub const COLUMNS: [Method; 4] = [
    Method::Fd,
    Method::Rendering,
    Method::Transport,
    Method::Expectation,
];

/// The showcase scene, from the copy of `scenes/mesh/showcase.toml`
/// compiled into the crate (so the figure runs from any folder).
pub fn showcase() -> Result<Arc<Scene>, Error> {
    let text = include_str!("../../../scenes/mesh/showcase.toml");
    Ok(Arc::new(crate::mesh::file::from_toml(text)?))
}

/// Renders `scene` with every method of [`COLUMNS`], [`SPP`] (scaled by
/// the effort) paths per pixel, all from `opts.seed`.
pub fn render_all(opts: &FigureOptions, scene: &Arc<Scene>) -> Result<Vec<ImageResult>, Error> {
    COLUMNS
        .iter()
        .map(|&method| {
            let est = scene.estimator(method, None)?;
            let pixels = est.image().map_or(0, |(w, h)| u64::from(w) * u64::from(h));
            let bar = opts.bar(pixels, &format!("camera: {}", method.name()));
            let image = render(
                est.as_ref(),
                opts.paths(SPP),
                opts.seed,
                opts.threads,
                &|done| {
                    bar.set_position(done);
                    Ok(())
                },
            );
            bar.finish_and_clear();
            image
        })
        .collect()
}

/// Row label of `q`: `I` or `∂I/∂name`.
fn row_label(q: &Quantity) -> String {
    match q {
        Quantity::Intensity => "I".into(),
        Quantity::Sensitivity(name) => format!("∂I/∂{name}"),
        Quantity::Gradient(axis) => format!("∂I/∂{axis}"),
    }
}

/// One line per method and quantity: the image mean ± its standard error,
/// and per method the seconds of its render.
pub fn table(runs: &[ImageResult]) -> String {
    let mut out = String::new();
    for r in runs {
        let _ = writeln!(
            out,
            "{} ({}×{}, {} spp): {:.2} s",
            r.method, r.width, r.height, r.spp, r.seconds
        );
        for ((q, _), m) in r.images.iter().zip(&r.means) {
            let label = row_label(q);
            let _ = writeln!(out, "  {label:<14} {:+.5e} ± {:.2e}", m.mean, m.stderr);
        }
    }
    out
}

/// The numbers behind the figure, as `mesh_camera.json` holds them.
#[derive(Debug, Serialize)]
struct Numbers {
    spp: u64,
    seed: u64,
    width: u32,
    height: u32,
    /// Per row, the quantity and the display scale.
    rows: Vec<(String, f64)>,
    runs: Vec<Run>,
}

#[derive(Debug, Serialize)]
struct Run {
    method: &'static str,
    seconds: f64,
    /// Per quantity: its label, the image mean and its standard error.
    means: Vec<(String, f64, f64)>,
}

/// The grid's geometry, in screen pixels.
struct Layout {
    /// Panel side (two per camera pixel at 128 × 128).
    panel: u32,
    /// Gap between panels.
    gap: u32,
    /// Width of the row labels on the left.
    label_w: u32,
    /// Width of the colour bar and its labels on the right.
    bar_w: u32,
    /// Height of the column titles.
    head_h: u32,
    /// Height of the caption under each panel.
    caption_h: u32,
}

/// The figure's geometry.
const LAYOUT: Layout = Layout {
    panel: 256,
    gap: 10,
    label_w: 124,
    bar_w: 92,
    head_h: 40,
    caption_h: 30,
};

impl Layout {
    /// Left edge of column `c` (past the last column: the colour bars').
    fn x(&self, c: u32) -> u32 {
        self.label_w + c * (self.panel + self.gap)
    }

    /// Top edge of row `k` (past the last row: the figure's bottom).
    fn y(&self, k: u32) -> u32 {
        self.head_h + k * (self.panel + self.caption_h + self.gap)
    }
}

/// The display scale of row `q`: [`robust_scale`] of the reference
/// (first) run's image; 1 if that is 0 (nothing to see).
fn row_scale(runs: &[ImageResult], q: &Quantity) -> f64 {
    let s = runs
        .first()
        .and_then(|r| r.image(q))
        .map(|img| robust_scale(&img.iter().map(|e| e.mean).collect::<Vec<_>>()))
        .unwrap_or(0.0);
    if s > 0.0 { s } else { 1.0 }
}

/// Draws `runs` (one per column, same camera) to the PNG `path`.
pub fn draw(runs: &[ImageResult], path: &Path) -> Result<(), Error> {
    let Some(first) = runs.first() else {
        return Err(Error::Output("no images to draw".into()));
    };
    let rows: Vec<Quantity> = first.images.iter().map(|(q, _)| q.clone()).collect();
    let (cols, nrows) = (runs.len() as u32, rows.len() as u32);
    let l = &LAYOUT;
    let size = (l.x(cols) + l.bar_w, l.y(nrows));
    let root = BitMapBackend::new(path, size).into_drawing_area();
    root.fill(&WHITE).map_err(plot_err)?;
    let centre = |size: u32| {
        ("sans-serif", size)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center))
    };
    let left = |size: u32| ("sans-serif", size).into_font().color(&BLACK);
    for (c, r) in runs.iter().enumerate() {
        let x = (l.x(c as u32) + l.panel / 2) as i32;
        let title = if r.method == "fd" {
            "finite differences".to_string()
        } else {
            r.method.to_string()
        };
        root.draw_text(&title, &centre(22), (x, (l.head_h / 2) as i32))
            .map_err(plot_err)?;
    }
    for (k, q) in rows.iter().enumerate() {
        let y0 = l.y(k as u32);
        let intensity = *q == Quantity::Intensity;
        let scale = row_scale(runs, q);
        let map: Box<dyn Fn(f64) -> [u8; 3]> = if intensity {
            Box::new(magnitude_map(scale))
        } else {
            Box::new(diverging_map(scale))
        };
        let mid = (y0 + l.panel / 2) as i32;
        root.draw_text(&row_label(q), &left(22), (8, mid - 24))
            .map_err(plot_err)?;
        let range = if intensity {
            format!("0 to {}", scale_tag(scale))
        } else {
            format!("±{}", scale_tag(scale))
        };
        root.draw_text(&range, &left(16), (8, mid + 6))
            .map_err(plot_err)?;
        for (c, r) in runs.iter().enumerate() {
            let x0 = l.x(c as u32);
            let area = root.clone().shrink((x0, y0), (l.panel, l.panel));
            let caption = (x0 + l.panel / 2, y0 + l.panel + l.caption_h / 2);
            let caption = (caption.0 as i32, caption.1 as i32);
            match (r.image(q), r.mean(q)) {
                (Some(img), Some(m)) if r.width == first.width && r.height == first.height => {
                    draw_image(&area, r.width, r.height, |p| img[p].mean, &map)?;
                    let text = format!("{:.3e} ± {:.1e}", m.mean, m.stderr);
                    root.draw_text(&text, &centre(15), caption)
                        .map_err(plot_err)?;
                }
                _ => {
                    area.fill(&RGBColor(200, 200, 200)).map_err(plot_err)?;
                    root.draw_text("not estimated", &centre(15), caption)
                        .map_err(plot_err)?;
                }
            }
        }
        let bx = l.x(cols);
        colour_bar(&root, (bx, y0), intensity, &map, scale)?;
    }
    root.present().map_err(plot_err)
}

/// Fills `area` (a square panel) with the `width × height` image whose
/// pixel `p` (row-major, row 0 at the top) has the value `value(p)`,
/// nearest-neighbour, letterboxed to keep the pixels square.
fn draw_image<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    width: u32,
    height: u32,
    value: impl Fn(usize) -> f64,
    map: &dyn Fn(f64) -> [u8; 3],
) -> Result<(), Error> {
    let (w, h) = area.dim_in_pixel();
    let zoom = (f64::from(w) / f64::from(width)).min(f64::from(h) / f64::from(height));
    let (dw, dh) = (
        (f64::from(width) * zoom) as u32,
        (f64::from(height) * zoom) as u32,
    );
    let (ox, oy) = ((w - dw) / 2, (h - dh) / 2);
    for sy in 0..dh {
        let row = ((f64::from(sy) / zoom) as u32).min(height - 1);
        for sx in 0..dw {
            let col = ((f64::from(sx) / zoom) as u32).min(width - 1);
            let v = value((row * width + col) as usize);
            let [r, g, b] = if v.is_finite() {
                map(v)
            } else {
                NON_FINITE_RGB
            };
            area.draw_pixel(((ox + sx) as i32, (oy + sy) as i32), &RGBColor(r, g, b))
                .map_err(plot_err)?;
        }
    }
    Ok(())
}

/// A vertical colour bar at `(x, y)` as tall as a panel, labelled with its
/// ends and (for a diverging map) its centre 0.
fn colour_bar<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    (x, y): (u32, u32),
    intensity: bool,
    map: &dyn Fn(f64) -> [u8; 3],
    scale: f64,
) -> Result<(), Error> {
    const STRIP: u32 = 16;
    let tag = scale_tag(scale);
    let panel = LAYOUT.panel;
    for sy in 0..panel {
        // Top is the high end.
        let t = 1.0 - (f64::from(sy) + 0.5) / f64::from(panel);
        let v = if intensity {
            t * scale
        } else {
            (2.0 * t - 1.0) * scale
        };
        let [r, g, b] = map(v);
        let bar = Rectangle::new(
            [
                (x as i32, (y + sy) as i32),
                ((x + STRIP) as i32, (y + sy + 1) as i32),
            ],
            RGBColor(r, g, b).filled(),
        );
        root.draw(&bar).map_err(plot_err)?;
    }
    let style = ("sans-serif", 14)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let lx = (x + STRIP + 4) as i32;
    let (top, bottom) = if intensity {
        (tag.clone(), "0".to_string())
    } else {
        (format!("+{tag}"), format!("−{tag}"))
    };
    root.draw_text(&top, &style, (lx, (y + 6) as i32))
        .map_err(plot_err)?;
    root.draw_text(&bottom, &style, (lx, (y + panel - 6) as i32))
        .map_err(plot_err)?;
    if !intensity {
        root.draw_text("0", &style, (lx, (y + panel / 2) as i32))
            .map_err(plot_err)?;
    }
    Ok(())
}

/// Draws `runs` to `mesh_camera.png` and writes their numbers to
/// `mesh_camera.json` under `opts.out`; returns the files written.
pub fn save(opts: &FigureOptions, runs: &[ImageResult]) -> Result<Vec<PathBuf>, Error> {
    let first = runs
        .first()
        .ok_or_else(|| Error::Output("no images to save".into()))?;
    std::fs::create_dir_all(&opts.out)
        .map_err(|e| Error::Output(format!("cannot create {}: {e}", opts.out.display())))?;
    let png = opts.out.join("mesh_camera.png");
    draw(runs, &png)?;
    let numbers = Numbers {
        spp: first.spp,
        seed: opts.seed,
        width: first.width,
        height: first.height,
        rows: (first.images.iter())
            .map(|(q, _)| (row_label(q), row_scale(runs, q)))
            .collect(),
        runs: runs
            .iter()
            .map(|r| Run {
                method: r.method,
                seconds: r.seconds,
                means: (r.images.iter().zip(&r.means))
                    .map(|((q, _), m)| (row_label(q), m.mean, m.stderr))
                    .collect(),
            })
            .collect(),
    };
    let json = opts.write_json("mesh_camera", &numbers)?;
    Ok(vec![png, json])
}

/// The figure: renders the showcase with every method and saves it.
pub fn camera(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    save(opts, &render_all(opts, &showcase()?)?)
}
