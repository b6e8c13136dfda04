//! 3D speed against accuracy: the work-normalised variance `σ²·t` (the
//! variance of one path's weight times the seconds one path takes on one
//! thread; the variance one second of sampling leaves) of every method,
//! finite differences included, for `E` and every parameter, as grouped
//! bars on a log axis (lower is better). Scenes: the black triangle
//! occluder ([`TriangleOccluder::NOMINAL`], translation, rotation, scale),
//! `scenes/mesh/cube_shadow.toml` (a black cube) and
//! `scenes/mesh/fog_cube.toml` (a scattering fog cube), one panel each. A
//! path estimates `E` and all the scene's sensitivities at once, so the
//! bars of one method share its `t`; finite differences pay two extra
//! readings per parameter.
//!
//! Every timing run uses one thread whatever `opts.threads`; runs shorter
//! than [`MIN_SECONDS`] are repeated (same seed) and the fastest time kept.
//! Pale bars have a VOV of at least [`Estimate::VOV_LIMIT`] (σ unreliable).
use super::{FigureOptions, METHODS, color, run_method, save};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::mesh::cases::TriangleOccluder;
use crate::mesh::{Scene, file};
use crate::method::Method;
use crate::plot::{Figure, Legend, Panel, Series, single_legend};
use crate::runner::RunResult;
use crate::stats::Estimate;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// Panel names: the triangle occluder and two shipped scenes.
pub const SCENES: [&str; 3] = ["triangle occluder", "cube_shadow.toml", "fog_cube.toml"];

/// Paths per run (times the effort).
pub const PATHS: u64 = 100_000;

/// Runs shorter than this (seconds) are repeated for a robust time.
pub const MIN_SECONDS: f64 = 0.1;

/// Most runs of one configuration when timing short runs.
pub const MAX_REPEATS: u32 = 4;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 72_000_000;

/// One method's estimate of one quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Scene (panel) name.
    pub scene: &'static str,
    /// Method name.
    pub method: &'static str,
    /// `"E"` or the parameter's name.
    pub quantity: String,
    /// Paths sampled.
    pub paths: u64,
    /// The estimate.
    pub mean: f64,
    /// Its standard error σ.
    pub stderr: f64,
    /// Relative variance of the variance.
    pub vov: f64,
    /// Sampling wall time of the run (one thread), seconds.
    pub seconds: f64,
    /// `σ²·t`: the variance per path times the seconds per path.
    pub work: f64,
}

/// The scene of panel `name`.
fn scene(name: &str) -> Result<Scene, Error> {
    let text = match name {
        "cube_shadow.toml" => include_str!("../../../scenes/mesh/cube_shadow.toml"),
        "fog_cube.toml" => include_str!("../../../scenes/mesh/fog_cube.toml"),
        _ => return TriangleOccluder::NOMINAL.scene(&[0, 1, 2]),
    };
    file::from_toml(text).map_err(|e| Error::Scene(format!("scenes/mesh/{name}: {e}")))
}

/// The run with the fastest of a few identical repeats when short.
fn timed(
    opts: &FigureOptions,
    method: Method,
    scene: &Arc<Scene>,
    salt: u64,
) -> Result<RunResult, Error> {
    let mut best = run_method(opts, method, scene, PATHS, salt, 1)?;
    let (mut total, mut repeats) = (best.seconds, 1);
    while total < MIN_SECONDS && repeats < MAX_REPEATS {
        let again = run_method(opts, method, scene, PATHS, salt, 1)?;
        total += again.seconds;
        repeats += 1;
        if again.seconds < best.seconds {
            best = again;
        }
    }
    Ok(best)
}

/// Palette index of the legend entry of pale bars (black, drawn grey).
const PALE: usize = 6;

/// Half the width of a bar, in group units.
const BAR: f64 = 0.075;

/// The grouped-bar panel of one scene.
fn panel(scene: &str, groups: &[String], records: &[Record], floor: f64, top: f64) -> Panel {
    let mut series = Vec::new();
    let k_mid = 0.5 * (METHODS.len() - 1) as f64;
    for (k, method) in METHODS.into_iter().enumerate() {
        let offset = (k as f64 - k_mid) * 2.2 * BAR;
        let mut first = true;
        for (g, group) in groups.iter().enumerate() {
            let Some(r) = records
                .iter()
                .find(|r| r.method == method.name() && &r.quantity == group)
            else {
                continue;
            };
            if r.work <= 0.0 {
                continue;
            }
            let x = g as f64 + offset;
            let label = if first { method.name() } else { "" };
            first = false;
            let opacity = if r.vov < Estimate::VOV_LIMIT {
                0.85
            } else {
                0.3
            };
            series.push(Series::polygon(
                label,
                color(method),
                vec![
                    (x - BAR, floor),
                    (x + BAR, floor),
                    (x + BAR, r.work),
                    (x - BAR, r.work),
                ],
                opacity,
            ));
        }
        if first {
            series.push(Series::polygon(method.name(), color(method), vec![], 0.85));
        }
    }
    series.push(Series::polygon(
        &format!("pale: VOV ≥ {} (σ unreliable)", Estimate::VOV_LIMIT),
        PALE,
        vec![],
        0.3,
    ));
    Panel {
        title: format!("{scene}: σ²·t per quantity (1 thread; lower is better)"),
        x_label: "quantity".into(),
        y_label: "σ²·t (variance per path × s per path)".into(),
        y_log: true,
        series,
        x_range: Some((-0.6, groups.len() as f64 - 0.4)),
        y_range: Some((floor, top)),
        x_tick_names: groups.to_vec(),
        ..Panel::default()
    }
}

/// `σ²·t` of every method (finite differences included) for `E` and every
/// parameter of the [`SCENES`] (one panel each, grouped bars, log axis),
/// [`PATHS`] paths per run on one thread. Writes
/// `mesh_efficiency.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_mesh_efficiency -- [OUT_DIR] [EFFORT]
/// ```
pub fn efficiency(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let bar = opts.bar((SCENES.len() * METHODS.len()) as u64, "mesh: efficiency");
    let mut salt = SALT;
    let mut records = Vec::new();
    let mut groups = Vec::new();
    for name in SCENES {
        let scene = Arc::new(scene(name)?);
        let mut g = vec!["E".to_string()];
        g.extend(scene.parameters().iter().map(|p| p.name.clone()));
        for method in METHODS {
            salt += 1;
            let r = timed(opts, method, &scene, salt)?;
            for (q, e) in &r.estimates {
                let quantity = match q {
                    Quantity::Intensity => "E".to_string(),
                    Quantity::Sensitivity(p) => p.clone(),
                    _ => continue,
                };
                records.push(Record {
                    scene: name,
                    method: method.name(),
                    quantity,
                    paths: r.paths,
                    mean: e.mean,
                    stderr: e.stderr,
                    vov: e.vov,
                    seconds: r.seconds,
                    work: e.stderr * e.stderr * r.seconds,
                });
            }
            bar.inc(1);
        }
        groups.push(g);
    }
    bar.finish();
    let works = records.iter().map(|r| r.work).filter(|&w| w > 0.0);
    let lo = works.clone().fold(f64::INFINITY, f64::min);
    let hi = works.fold(0.0f64, f64::max);
    let (floor, top) = if lo.is_finite() && hi > 0.0 {
        (10f64.powf(lo.log10().floor()), hi * 30.0)
    } else {
        (1e-12, 1.0)
    };
    let mut panels: Vec<Panel> = SCENES
        .iter()
        .zip(&groups)
        .map(|(&name, g)| {
            let rs: Vec<Record> = records
                .iter()
                .filter(|r| r.scene == name)
                .cloned()
                .collect();
            panel(name, g, &rs, floor, top)
        })
        .collect();
    single_legend(&mut panels, &[Legend::UpperRight, Legend::UpperLeft]);
    let mut figure = Figure::new(panels, 1);
    figure.panel_size = (1200, 420);
    save(opts, "efficiency", &figure, &records)
}
