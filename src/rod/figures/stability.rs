//! Stability map: where each method's error bar cannot be trusted. Over the
//! probe position `x/π̃` (denser near the moving end), the optical thickness
//! `κe π̃` from 0.1 to 30 and the albedo `λ`, every cell runs `R` independent
//! estimates of `s` with `N` paths each and records the measured coverage
//! (the fraction of runs whose ±2σ bar misses the exact `s`; 4.6 % for an
//! honest error bar) and the fraction the tail diagnostic flags
//! (VOV ≥ 0.1). The book discusses it in "Comparing the approaches"; the
//! failure modes it shows are asserted in `tests/coverage.rs`.
//!
//! Without scattering (`λ = 0`) nothing depends on the length: `s = 0` and
//! every method returns exactly 0 (`tests/rod_estimators.rs`), so the map
//! starts at `λ = 0.1`. Transport's sensitivity weight is rendering's on the rod (same boundary
//! source, same nested path), so the map shows expectation and rendering.
use super::FigureOptions;
use crate::error::Error;
use crate::estimator::Quantity;
use crate::plot::{Figure, HeatMap, Panel};
use crate::rod::{Direction, Method, PARAMETER, Probe, Rod, exact};
use crate::runner::{RunConfig, run};
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;

/// Probe positions as fractions of the length, denser near the moving end.
pub const POSITIONS: [f64; 9] = [0.0, 0.25, 0.5, 0.75, 0.9, 0.97, 0.99, 0.999, 1.0];
/// Optical thicknesses `κe π̃`.
pub const THICKNESSES: [f64; 6] = [0.1, 0.3, 1.0, 3.0, 10.0, 30.0];
/// Albedos `λ = κs/κe`.
pub const ALBEDOS: [f64; 4] = [0.1, 0.5, 0.9, 1.0];
/// Independent runs per cell.
pub const RUNS: u64 = 100;
/// Paths per run (times the effort).
pub const PATHS: u64 = 4000;
/// Rod length of every cell.
const LENGTH: f64 = 2.0;

/// The measurements of one cell.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    /// Method name.
    pub method: &'static str,
    /// `+1` or `−1`.
    pub omega: f64,
    /// Albedo `λ`.
    pub albedo: f64,
    /// Optical thickness `κe π̃`.
    pub thickness: f64,
    /// `x/π̃`.
    pub position: f64,
    /// Exact `s`.
    pub exact: f64,
    /// Fraction of runs whose ±2σ bar misses the exact value.
    pub missed_2sigma: f64,
    /// Fraction of runs whose ±3σ bar misses it.
    pub missed_3sigma: f64,
    /// Fraction of runs flagged unreliable by the VOV.
    pub flagged: f64,
    /// Paths per run.
    pub paths: u64,
    /// Runs.
    pub runs: u64,
}

/// Runs one cell: `RUNS` single-threaded runs with distinct seeds.
fn measure(
    opts: &FigureOptions,
    method: Method,
    omega: Direction,
    albedo: f64,
    thickness: f64,
    position: f64,
    salt: u64,
) -> Result<Cell, Error> {
    let ke = thickness / LENGTH;
    let rod = Rod::new(albedo * ke, ke, LENGTH)?;
    let x = position * LENGTH;
    let probe = Probe::new(&rod, x, omega)?;
    let reference = exact::solve(&rod, x, omega).sensitivity;
    let estimator = method.estimator(rod, probe);
    let q = Quantity::sensitivity(PARAMETER);
    let paths = opts.paths(PATHS);
    let (mut miss2, mut miss3, mut flagged) = (0u64, 0u64, 0u64);
    for r in 0..RUNS {
        let seed = opts.seed.wrapping_add(salt * RUNS + r);
        let cfg = RunConfig::new(paths, seed)?.threads(1);
        let e = run(estimator.as_ref(), &cfg)?
            .get(&q)
            .ok_or_else(|| Error::Output(format!("{} has no sensitivity", method.name())))?;
        let z = e.z_score(reference);
        miss2 += u64::from(z > 2.0);
        miss3 += u64::from(z > 3.0);
        flagged += u64::from(!e.is_reliable());
    }
    let n = RUNS as f64;
    Ok(Cell {
        method: method.name(),
        omega: omega.sign(),
        albedo,
        thickness,
        position,
        exact: reference,
        missed_2sigma: miss2 as f64 / n,
        missed_3sigma: miss3 as f64 / n,
        flagged: flagged as f64 / n,
        paths,
        runs: RUNS,
    })
}

/// The panels' row order: (method, direction).
const ROWS: [(Method, Direction); 4] = [
    (Method::Expectation, Direction::Left),
    (Method::Expectation, Direction::Right),
    (Method::Rendering, Direction::Left),
    (Method::Rendering, Direction::Right),
];

/// One heat map of `value` over (position, thickness) for a (row, albedo).
fn panel(
    cells: &[Cell],
    (method, omega): (Method, Direction),
    albedo: f64,
    what: &str,
    value: fn(&Cell) -> f64,
) -> Panel {
    let values = THICKNESSES
        .iter()
        .flat_map(|&t| POSITIONS.iter().map(move |&p| (t, p)))
        .map(|(t, p)| {
            cells
                .iter()
                .find(|c| {
                    c.method == method.name()
                        && c.omega == omega.sign()
                        && c.albedo == albedo
                        && c.thickness == t
                        && c.position == p
                })
                .map_or(f64::NAN, value)
        })
        .collect();
    let log_t: Vec<f64> = THICKNESSES.iter().map(|t| t.log10()).collect();
    let half = 0.5 * (log_t[1] - log_t[0]);
    let mut y_edges: Vec<f64> = log_t.iter().map(|t| t - half).collect();
    y_edges.push(log_t[log_t.len() - 1] + half);
    Panel {
        title: format!("{}, ω = {:+}, λ = {albedo}", method.name(), omega.sign()),
        x_label: format!("x/π̃; colour: {what}"),
        x_tick_names: POSITIONS.iter().map(|p| format!("{p}")).collect(),
        y_label: "optical thickness κe·π̃".into(),
        y_log: true,
        heat: Some(HeatMap {
            x_edges: (0..=POSITIONS.len()).map(|i| i as f64 - 0.5).collect(),
            y_edges,
            values,
            range: (0.0, 0.5),
        }),
        ..Panel::default()
    }
}

/// Writes `stability.{png,svg}` (fraction of runs whose ±2σ bar misses the
/// exact `s`), `stability_flagged.{png,svg}` (fraction flagged by the VOV)
/// and `stability.json` (every cell).
pub fn stability(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let mut jobs = Vec::new();
    for (method, omega) in ROWS {
        for &albedo in &ALBEDOS {
            for &thickness in &THICKNESSES {
                for &position in &POSITIONS {
                    jobs.push((method, omega, albedo, thickness, position));
                }
            }
        }
    }
    let bar = opts.bar(jobs.len() as u64, "stability map");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| Error::Config(format!("cannot start {} threads: {e}", opts.threads)))?;
    let cells: Vec<Cell> = pool.install(|| {
        jobs.par_iter()
            .enumerate()
            .map(|(i, &(method, omega, albedo, thickness, position))| {
                let cell = measure(opts, method, omega, albedo, thickness, position, i as u64);
                bar.inc(1);
                cell
            })
            .collect::<Result<_, _>>()
    })?;
    bar.finish();
    let figure = |what: &str, value: fn(&Cell) -> f64| {
        let panels = ROWS
            .iter()
            .flat_map(|&row| ALBEDOS.iter().map(move |&a| (row, a)))
            .map(|(row, a)| panel(&cells, row, a, what, value))
            .collect();
        let mut f = Figure::new(panels, ALBEDOS.len());
        f.panel_size = (560, 400);
        f
    };
    let scale = "blue 0, white .25, red ≥ .5";
    let missed = format!("share of runs missing ±2σ ({scale}; honest .046)");
    let flagged = format!("share of runs flagged by VOV ≥ 0.1 ({scale})");
    let mut written = figure(&missed, |c| c.missed_2sigma).save(&opts.out, "stability")?;
    written.extend(figure(&flagged, |c| c.flagged).save(&opts.out, "stability_flagged")?);
    written.push(opts.write_json("stability", &cells)?);
    Ok(written)
}
