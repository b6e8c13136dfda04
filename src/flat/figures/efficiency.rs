//! Speed against accuracy in flatland: the work-normalised variance `σ²·t`
//! (the variance of one path's weight times the seconds one path takes, on
//! one thread; equal to the variance of the estimate one second of
//! sampling leaves) of every method, for `E` and every parameter of
//! `polygon_occluder.toml`, `fog.toml` and `three_shapes.toml`, as grouped
//! bars on a log axis; lower is better. A path of every method estimates
//! `E` and all the scene's sensitivities at once, so `t` is the time of the
//! whole path, and the bars of one method share it; finite differences pay
//! two extra readings per parameter.
//!
//! Every timing run uses one thread whatever `opts.threads`; runs shorter
//! than [`MIN_SECONDS`] are repeated (same seed) and the fastest time kept.
//! Bars with `σ = 0` cannot be drawn on the log axis and are left out (the
//! JSON keeps them); pale bars have a relative variance of the variance
//! (VOV) of at least [`Estimate::VOV_LIMIT`]: heavy tails, their `σ` and
//! so their `σ²·t` are not to be trusted.
use super::{FigureOptions, METHODS, color, load, run_method, save};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::flat::Method;
use crate::plot::{Figure, Legend, Panel, Series, single_legend};
use crate::runner::RunResult;
use crate::stats::Estimate;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// The scenes, one panel each.
pub const SCENES: [&str; 3] = ["polygon_occluder", "fog", "three_shapes"];

/// Paths per run (times the effort).
pub const PATHS: u64 = 400_000;

/// Runs shorter than this (seconds) are repeated for a robust time.
pub const MIN_SECONDS: f64 = 0.1;

/// Most runs of one configuration when timing short runs.
pub const MAX_REPEATS: u32 = 5;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 60_000_000;

/// One method's estimate of one quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Scene file name.
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
    /// Relative variance of the variance (tail diagnostic).
    pub vov: f64,
    /// Sampling wall time of the run (one thread), seconds.
    pub seconds: f64,
    /// `σ²·t`: the variance per path times the seconds per path.
    pub work: f64,
}

/// The run with the fastest of a few identical repeats when short.
fn timed(
    opts: &FigureOptions,
    method: Method,
    scene: &Arc<crate::flat::Scene>,
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

/// The grouped-bar panel of one scene: groups `E` and the parameters,
/// one bar per method that estimates the group's quantity.
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
            // Pale: the variance estimate itself is unreliable.
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
            // A legend entry even when the method drew no bar here.
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
        title: format!("{scene}.toml: σ²·t per quantity (1 thread; lower is better)"),
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

/// `σ²·t` of every method for `E` and every parameter of the [`SCENES`]
/// (one panel each, grouped bars), [`PATHS`] paths per run on one thread.
/// Writes `flat_efficiency.{png,svg}` and `flat_efficiency.json`.
pub fn efficiency(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let bar = opts.bar((SCENES.len() * METHODS.len()) as u64, "flat: efficiency");
    let mut salt = SALT;
    let mut records = Vec::new();
    let mut groups = Vec::new();
    for name in SCENES {
        let scene = Arc::new(load(name)?);
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
        (10f64.powf(lo.log10().floor()), hi * 6.0)
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
    figure.panel_size = (1500, 440);
    save(opts, "efficiency", &figure, &records)
}
