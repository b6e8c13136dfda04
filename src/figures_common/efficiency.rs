//! The `σ²·t` of the flatland and 3D efficiency figures: every method
//! ([`METHODS`]) timed on one thread on a few scenes, one panel of markers
//! per scene on a log axis, one group per quantity (`E` and every
//! parameter).
use super::{FigureOptions, run_method, save};
use super::{METHODS, color};
use crate::error::Error;
use crate::estimator::Quantity;
use crate::method::Method;
use crate::method::model::Model;
use crate::plot::{Figure, Panel, Series};
use crate::runner::RunResult;
use crate::stats::Estimate;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

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
    /// Relative variance of the variance (tail diagnostic).
    pub vov: f64,
    /// Sampling wall time of the run (one thread), seconds.
    pub seconds: f64,
    /// `σ²·t`: the variance per path times the seconds per path.
    pub work: f64,
}

/// Runs shorter than this (seconds) are repeated for a robust time.
pub const MIN_SECONDS: f64 = 0.1;

/// The ends of the log axis beyond the smallest and largest value, as a
/// factor.
const HEADROOM: f64 = 2.0;

/// What differs between the flatland and the 3D efficiency figure.
pub(crate) struct Spec<S: 'static> {
    /// Prefix of the files (`flat`, `mesh`).
    pub prefix: &'static str,
    /// The scenes (panel names).
    pub scenes: &'static [&'static str],
    /// The scene of a panel name.
    pub build: fn(&str) -> Result<S, Error>,
    /// A panel's title before `": σ²·t per quantity …"`.
    pub title: fn(&str) -> String,
    /// Paths per run (times the effort).
    pub paths: u64,
    /// Most runs of one configuration when timing short runs.
    pub max_repeats: u32,
    /// Base of the seed salts.
    pub salt: u64,
    /// Pixels per panel.
    pub panel_size: (u32, u32),
}

/// The run with the fastest of a few identical repeats when short.
fn timed<S: Model>(
    opts: &FigureOptions,
    spec: &Spec<S>,
    method: Method,
    scene: &Arc<S>,
    salt: u64,
) -> Result<RunResult, Error> {
    let mut best = run_method(opts, method, scene, spec.paths, salt, 1)?;
    let (mut total, mut repeats) = (best.seconds, 1);
    while total < MIN_SECONDS && repeats < spec.max_repeats {
        let again = run_method(opts, method, scene, spec.paths, salt, 1)?;
        total += again.seconds;
        repeats += 1;
        if again.seconds < best.seconds {
            best = again;
        }
    }
    Ok(best)
}

/// Palette index of the legend entry of hollow markers (black).
const HOLLOW: usize = 6;

/// Distance between two methods' markers in a group, in group units.
const STEP: f64 = 0.15;

/// The panel of one scene: groups `E` and the parameters, one marker per
/// method that estimates the group's quantity, side by side on a log axis
/// from `lo` to `hi`. Markers, not bars: a bar's length on a log axis would
/// be set by where the axis starts.
fn panel(title: String, groups: &[String], records: &[Record], (lo, hi): (f64, f64)) -> Panel {
    let mut series = Vec::new();
    let k_mid = 0.5 * (METHODS.len() - 1) as f64;
    for (k, method) in METHODS.into_iter().enumerate() {
        let offset = (k as f64 - k_mid) * STEP;
        let (mut solid, mut hollow) = (Vec::new(), Vec::new());
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
            // Hollow: the variance estimate itself is unreliable.
            if r.vov < Estimate::VOV_LIMIT {
                solid.push((x, r.work));
            } else {
                hollow.push((x, r.work));
            }
        }
        series.push(Series::dots(method.name(), color(method), solid));
        series.push(Series::circles("", color(method), hollow));
    }
    series.push(Series::circles(
        &format!("hollow: VOV ≥ {} (σ unreliable)", Estimate::VOV_LIMIT),
        HOLLOW,
        vec![],
    ));
    Panel {
        title: format!("{title}: σ²·t per quantity (1 thread; lower is better)"),
        x_label: "quantity".into(),
        y_label: "σ²·t (variance per path × s per path)".into(),
        y_log: true,
        series,
        x_range: Some((-0.6, groups.len() as f64 - 0.4)),
        y_range: Some((lo, hi)),
        x_tick_names: groups.to_vec(),
        ..Panel::default()
    }
}

/// Times every method on every scene of `spec`, draws the markers and writes
/// `<prefix>_efficiency.{png,svg,json}`.
pub(crate) fn efficiency<S: Model>(
    opts: &FigureOptions,
    spec: &Spec<S>,
) -> Result<Vec<PathBuf>, Error> {
    let what = format!("{}: efficiency", spec.prefix);
    let bar = opts.bar((spec.scenes.len() * METHODS.len()) as u64, &what);
    let mut salt = spec.salt;
    let mut records = Vec::new();
    let mut groups = Vec::new();
    for &name in spec.scenes {
        let scene = Arc::new((spec.build)(name)?);
        let mut g = vec!["E".to_string()];
        g.extend(scene.parameter_names().map(str::to_owned));
        for method in METHODS {
            salt += 1;
            let r = timed(opts, spec, method, &scene, salt)?;
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
    // One axis for every panel, so that the scenes compare too.
    let range = if lo.is_finite() && hi > 0.0 {
        (lo / HEADROOM, hi * HEADROOM)
    } else {
        (1e-12, 1.0)
    };
    let panels: Vec<Panel> = spec
        .scenes
        .iter()
        .zip(&groups)
        .map(|(&name, g)| {
            let rs: Vec<Record> = records
                .iter()
                .filter(|r| r.scene == name)
                .cloned()
                .collect();
            panel((spec.title)(name), g, &rs, range)
        })
        .collect();
    let mut figure = Figure::new(panels, 1).share_legend();
    figure.panel_size = spec.panel_size;
    let name = format!("{}_efficiency", spec.prefix);
    save(opts, &name, &figure, &records)
}
