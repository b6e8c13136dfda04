//! Flatland's line camera (`scenes/camera_line.toml`): the image row of `I`
//! and of its two sensitivities, per pixel, by rendering, transport and
//! expectation (markers with ±σ bars) over the exact image
//! ([`line_camera_image`], and its central differences for the
//! sensitivities). Book: chapter "Three dimensions", section "A camera", "In
//! flatland: a line camera".
use super::{FigureOptions, REFERENCE_COLOR, color, load};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::figures_common::save;
use crate::flat::exact::line_camera_image;
use crate::image::render;
use crate::method::{Method, Problem};
use crate::plot::{Figure, Panel, Series, spread};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// Paths per pixel at effort 1.
const SPP: u64 = 1024;
/// Half step of the exact image's central differences.
const H: f64 = 1e-6;
/// The derivative methods drawn.
const METHODS: [Method; 3] = [Method::Rendering, Method::Transport, Method::Expectation];

/// One method's row: its name, per pixel the mean and the standard error.
type MethodRow = (String, Vec<f64>, Vec<f64>);

/// The numbers behind the figure.
#[derive(Serialize)]
struct Numbers {
    spp: u64,
    /// Per quantity: its name, the exact row, and every method's row.
    rows: Vec<(String, Vec<f64>, Vec<MethodRow>)>,
}

/// The image row of `I` and of every sensitivity, every derivative method
/// over the exact row. Writes `flat_camera.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_flat_camera -- [OUT_DIR] [EFFORT]
/// ```
pub fn camera(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let scene = Arc::new(load("camera_line")?);
    let no_exact = || Error::Scene("camera_line.toml has no exact image".into());
    let exact = line_camera_image(&scene).ok_or_else(no_exact)?;
    let mut references = vec![(Quantity::Intensity, exact)];
    for (j, p) in scene.parameters().iter().enumerate() {
        let row = |delta: f64| -> Result<Vec<f64>, Error> {
            line_camera_image(&scene.displaced(j, delta)?).ok_or_else(no_exact)
        };
        let (plus, minus) = (row(H)?, row(-H)?);
        let d = plus
            .iter()
            .zip(&minus)
            .map(|(a, b)| (a - b) / (2.0 * H))
            .collect();
        references.push((Quantity::sensitivity(&p.name), d));
    }
    let spp = opts.paths(SPP).max(64);
    let mut runs = Vec::new();
    for m in METHODS {
        let est = scene.estimator(m, None)?;
        runs.push((
            m,
            render(
                est.as_ref(),
                spp,
                opts.seed,
                opts.threads,
                &crate::runner::quiet,
            )?,
        ));
    }
    let mut panels = Vec::new();
    let mut numbers = Numbers {
        spp,
        rows: Vec::new(),
    };
    for (q, reference) in &references {
        let mut series = vec![Series::line(
            "exact",
            REFERENCE_COLOR,
            reference
                .iter()
                .enumerate()
                .map(|(p, &v)| (p as f64, v))
                .collect(),
        )];
        let mut per_method = Vec::new();
        for (k, (m, r)) in runs.iter().enumerate() {
            let img = r.image(q).ok_or_else(|| Error::Scene(format!("no {q}")))?;
            series.push(Series::points(
                &m.to_string(),
                color(*m),
                img.iter()
                    .enumerate()
                    .map(|(p, e)| {
                        (
                            spread(p as f64, k, METHODS.len(), false, 0.18),
                            e.mean,
                            e.stderr,
                        )
                    })
                    .collect(),
            ));
            per_method.push((
                m.to_string(),
                img.iter().map(|e| e.mean).collect(),
                img.iter().map(|e| e.stderr).collect(),
            ));
        }
        numbers
            .rows
            .push((q.to_string(), reference.clone(), per_method));
        panels.push(Panel {
            title: q.to_string(),
            x_label: "pixel (left to right)".into(),
            y_label: q.to_string(),
            series,
            ..Panel::default()
        });
    }
    let mut figure = Figure::new(panels, 3).share_legend();
    figure.panel_size = (560, 420);
    save(opts, "flat_camera", &figure, &numbers)
}
