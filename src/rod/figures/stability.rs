//! Stability map (the book's chapter "Comparing the approaches"): where each
//! method's error bar on `s` cannot be trusted.
//!
//! Over the probe position `x/π̃` (a non-uniform grid closing in on the
//! moving end), the optical thickness `κe π̃` from 0.1 to 30 (log grid) and
//! the albedo `λ`, in both directions, every cell runs [`RUNS`] independent
//! estimates of `s` with [`PATHS`] paths each (distinct seeds) by expectation
//! differentiation, differentiable rendering and the transport model, and
//! records
//!
//! - the measured coverage: the fraction of runs with `|mean − s| ≤ 2σ`
//!   (0.954 for an honest error bar). The z-score needs no relative error,
//!   so cells where `s` is tiny keep their meaning; a run reporting `0 ± 0`
//!   counts as covered where `s = 0` and as a miss anywhere else;
//! - the fraction of runs the tail diagnostic flags (`VOV ≥ 0.1`);
//! - the fraction of runs reporting `σ = 0`: no path drew a non-zero weight,
//!   and a VOV of 0 calls such a run reliable.
//!
//! The figure colours each cell by its coverage (white where honest, red
//! where the error bar is too small), puts a black dot where most runs are
//! flagged and a blue one where most runs report `σ = 0`, and greys the
//! cells where `s = 0` exactly (`x = 0`, `ω = +1`, where every method
//! returns `0 ± 0`). A red cell with a black dot is a failure the diagnostic
//! sees; a red cell with a blue dot, one that no diagnostic can see.
//!
//! Without scattering (`λ = 0`) no path depends on the length: `s = 0`
//! everywhere and every method returns exactly `0 ± 0`
//! (`tests/rod_estimators.rs`). Nothing to map, so the albedos start at 0.1.
//! The failure modes the map shows are pinned by `tests/coverage.rs`.
use super::FigureOptions;
use crate::error::Error;
use crate::estimator::Quantity;
use crate::plot::{Figure, HeatMap, Panel, Series, colour_bar};
use crate::rod::{Direction, Method, PARAMETER, Probe, Rod, exact};
use crate::runner::{RunConfig, run};
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;

/// Probe positions as fractions of the length: both ends, and a non-uniform
/// grid closing in on the moving end, where the expectation method's weight
/// grows like `1/(π̃ − x)`.
pub const POSITIONS: [f64; 13] = [
    0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.98, 0.99, 0.995, 0.999, 0.9999, 1.0,
];
/// Number of optical thicknesses `κe π̃`, log-spaced over [`THICKNESS_RANGE`].
pub const THICKNESS_COUNT: usize = 9;
/// Smallest and largest optical thickness `κe π̃`.
pub const THICKNESS_RANGE: (f64, f64) = (0.1, 30.0);
/// Albedos `λ = κs/κe`.
pub const ALBEDOS: [f64; 4] = [0.1, 0.5, 0.9, 1.0];
/// The sensitivity methods mapped.
pub const METHODS: [Method; 3] = [Method::Expectation, Method::Rendering, Method::Transport];
/// Independent runs per cell.
pub const RUNS: u64 = 100;
/// Paths per run (times the effort).
pub const PATHS: u64 = 4000;
/// Coverage of `±2σ` for a normal estimate.
pub const NOMINAL: f64 = 0.9545;
/// `|s|` below which [`Cell::negligible`] marks a cell (`I0 = 1`, `π̃ = 2`):
/// its coverage is still meaningful, but no error there matters.
pub const NEGLIGIBLE: f64 = 1e-6;
/// Rod length of every cell.
const LENGTH: f64 = 2.0;

/// The optical thicknesses `κe π̃`: [`THICKNESS_COUNT`] values log-spaced
/// over [`THICKNESS_RANGE`].
pub fn thicknesses() -> Vec<f64> {
    let (lo, hi) = THICKNESS_RANGE;
    let step = (hi / lo).ln() / (THICKNESS_COUNT - 1) as f64;
    (0..THICKNESS_COUNT)
        .map(|i| lo * (step * i as f64).exp())
        .collect()
}

/// Where one cell is: method, direction, albedo, thickness, position.
#[derive(Debug, Clone, Copy)]
struct Site {
    method: Method,
    omega: Direction,
    albedo: f64,
    thickness: f64,
    position: f64,
}

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
    /// `|s| <` [`NEGLIGIBLE`].
    pub negligible: bool,
    /// Fraction of runs with `|mean − s| ≤ 2σ` (ideal 0.954).
    pub coverage_2sigma: f64,
    /// Fraction of runs with `|mean − s| ≤ 3σ` (ideal 0.997).
    pub coverage_3sigma: f64,
    /// Fraction of runs flagged unreliable by the VOV.
    pub flagged: f64,
    /// Fraction of runs missing `±3σ` without being flagged: failures no
    /// diagnostic sees.
    pub silent_misses: f64,
    /// Fraction of runs reporting `σ = 0` (no path carried a weight, or all
    /// carried the same).
    pub zero_stderr: f64,
    /// Median over runs of `σ/|s|` (null where `s = 0`).
    pub median_relative_stderr: f64,
    /// Paths per run.
    pub paths: u64,
    /// Runs.
    pub runs: u64,
}

/// Runs one cell: [`RUNS`] single-threaded runs with seeds
/// `seed + salt·RUNS + r`.
fn measure(opts: &FigureOptions, site: Site, salt: u64) -> Result<Cell, Error> {
    let ke = site.thickness / LENGTH;
    let rod = Rod::new(site.albedo * ke, ke, LENGTH)?;
    let x = site.position * LENGTH;
    let probe = Probe::new(&rod, x, site.omega)?;
    let reference = exact::solve(&rod, x, site.omega).sensitivity;
    let estimator = site.method.estimator((rod, probe))?;
    let q = Quantity::sensitivity(PARAMETER);
    let paths = opts.paths(PATHS);
    let (mut within2, mut within3, mut flagged, mut silent, mut zero) = (0, 0, 0, 0, 0);
    let mut relative = Vec::with_capacity(RUNS as usize);
    for r in 0..RUNS {
        let seed = opts.seed.wrapping_add(salt * RUNS + r);
        let cfg = RunConfig::new(paths, seed)?.threads(1);
        let e = run(estimator.as_ref(), &cfg)?
            .get(&q)
            .ok_or_else(|| Error::Output(format!("{} has no sensitivity", site.method.name())))?;
        let z = e.z_score(reference);
        within2 += u32::from(z <= 2.0);
        within3 += u32::from(z <= 3.0);
        flagged += u32::from(!e.is_reliable());
        silent += u32::from(z > 3.0 && e.is_reliable());
        zero += u32::from(e.stderr == 0.0);
        relative.push(e.stderr / reference.abs());
    }
    relative.sort_by(f64::total_cmp);
    let share = |k: u32| f64::from(k) / RUNS as f64;
    Ok(Cell {
        method: site.method.name(),
        omega: site.omega.sign(),
        albedo: site.albedo,
        thickness: site.thickness,
        position: site.position,
        exact: reference,
        negligible: reference.abs() < NEGLIGIBLE,
        coverage_2sigma: share(within2),
        coverage_3sigma: share(within3),
        flagged: share(flagged),
        silent_misses: share(silent),
        zero_stderr: share(zero),
        median_relative_stderr: relative[relative.len() / 2],
        paths,
        runs: RUNS,
    })
}

/// Every cell of the map, in (method, direction, albedo, thickness,
/// position) order.
fn sites() -> Vec<Site> {
    let thicknesses = thicknesses();
    let mut sites = Vec::new();
    for method in METHODS {
        for omega in [Direction::Left, Direction::Right] {
            for &albedo in &ALBEDOS {
                for &thickness in &thicknesses {
                    for &position in &POSITIONS {
                        sites.push(Site {
                            method,
                            omega,
                            albedo,
                            thickness,
                            position,
                        });
                    }
                }
            }
        }
    }
    sites
}

/// Measures every cell on `opts.threads` threads (cells in parallel, each
/// cell's runs on one thread).
pub fn measure_all(opts: &FigureOptions) -> Result<Vec<Cell>, Error> {
    let sites = sites();
    let bar = opts.bar(sites.len() as u64, "stability map");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .build()
        .map_err(|e| Error::Config(format!("cannot start {} threads: {e}", opts.threads)))?;
    let cells = pool.install(|| {
        sites
            .par_iter()
            .enumerate()
            .map(|(i, &site)| {
                let cell = measure(opts, site, i as u64);
                bar.inc(1);
                cell
            })
            .collect::<Result<Vec<_>, _>>()
    })?;
    bar.finish();
    Ok(cells)
}

/// Everything `stability.json` holds: the grid and every cell.
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    /// Probe positions `x/π̃`.
    pub positions: Vec<f64>,
    /// Optical thicknesses `κe π̃`.
    pub thicknesses: Vec<f64>,
    /// Albedos.
    pub albedos: Vec<f64>,
    /// Rod length `π̃` of every cell.
    pub length: f64,
    /// Runs per cell.
    pub runs: u64,
    /// Paths per run.
    pub paths: u64,
    /// Every cell.
    pub cells: Vec<Cell>,
}

/// Short names of the positions for the x ticks (`.999` for 0.999).
fn position_names() -> Vec<String> {
    POSITIONS
        .iter()
        .map(|&p| {
            let s = format!("{p}");
            s.strip_prefix("0.").map_or(s.clone(), |t| format!(".{t}"))
        })
        .collect()
}

/// Two significant digits: `0.42`, `7.2`, `15`.
fn two_digits(v: f64) -> String {
    let decimals = (1.0 - v.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The colour range of the coverage: white at [`NOMINAL`], red at 0.4 below,
/// faint blue above (over-coverage is at most 0.046).
const COVERAGE_RANGE: (f64, f64) = (NOMINAL + 0.4, NOMINAL - 0.4);
/// Palette index of the "most runs flagged" marker (black).
const FLAGGED_COLOR: usize = 6;
/// Palette index of the "most runs report σ = 0" marker (sky blue).
const ZERO_COLOR: usize = 5;

/// One heat map of the 2σ coverage over (position, thickness) for one
/// (method, direction, albedo), with markers where most runs are flagged or
/// report `σ = 0`; grey where `s = 0`.
fn panel(cells: &[&Cell], thicknesses: &[f64], title: String) -> Panel {
    let at = |ix: usize, iy: usize| {
        cells
            .iter()
            .find(|c| c.position == POSITIONS[ix] && c.thickness == thicknesses[iy])
    };
    let grid =
        || (0..thicknesses.len()).flat_map(|iy| (0..POSITIONS.len()).map(move |ix| (ix, iy)));
    let values = grid()
        .map(|(ix, iy)| match at(ix, iy) {
            Some(c) if c.exact != 0.0 => c.coverage_2sigma,
            _ => f64::NAN,
        })
        .collect();
    let markers = |color: usize, share: fn(&Cell) -> f64| {
        let points = grid()
            .filter(|&(ix, iy)| at(ix, iy).is_some_and(|c| c.exact != 0.0 && share(c) > 0.5))
            .map(|(ix, iy)| (ix as f64, iy as f64, 0.0))
            .collect();
        Series::points("", color, points)
    };
    let edges = |n: usize| (0..=n).map(|i| i as f64 - 0.5).collect();
    Panel {
        title,
        x_label: "x / length (non-uniform grid)".into(),
        x_tick_names: position_names(),
        tick_size: Some(14),
        y_label: "optical thickness κe × length".into(),
        y_tick_names: thicknesses.iter().map(|&t| two_digits(t)).collect(),
        series: vec![
            markers(FLAGGED_COLOR, |c| c.flagged),
            markers(ZERO_COLOR, |c| c.zero_stderr),
        ],
        heat: Some(HeatMap {
            x_edges: edges(POSITIONS.len()),
            y_edges: edges(thicknesses.len()),
            values,
            range: COVERAGE_RANGE,
        }),
        ..Panel::default()
    }
}

/// The colour legend, with the markers' and grey cells' meaning.
fn legend(record: &Record) -> Panel {
    let mut bar = colour_bar(
        &format!(
            "λ = κs/κe, the albedo; {} runs of {} paths per cell",
            record.runs, record.paths
        ),
        "colour: coverage, fraction of runs with |mean − s| ≤ 2σ (honest: 0.954)",
        COVERAGE_RANGE,
        (0.0, 1.0),
    );
    // The scale is linear down to its red end and saturates below it.
    let red = COVERAGE_RANGE.1;
    bar.series.extend([
        Series::line(
            &format!("colour saturates below {red:.2}"),
            FLAGGED_COLOR,
            vec![(red, -0.5), (red, 0.5)],
        ),
        Series::legend_dot("most runs flagged (VOV ≥ 0.1)", FLAGGED_COLOR),
        Series::legend_dot("most runs report σ = 0 (no weight drawn)", ZERO_COLOR),
        // Black at this opacity on white is the heat map's grey (160).
        Series::polygon(
            "grey: s = 0 exactly (x = 0, ω = +1)",
            FLAGGED_COLOR,
            vec![],
            0.373,
        ),
    ]);
    bar
}

/// The figure of one method: its coverage over (position, thickness), one
/// row per albedo and one column per direction, the colour bar last.
fn method_figure(record: &Record, thicknesses: &[f64], method: Method) -> Figure {
    let mut panels = Vec::new();
    for &albedo in &ALBEDOS {
        for omega in [Direction::Left, Direction::Right] {
            let of_panel: Vec<&Cell> = record
                .cells
                .iter()
                .filter(|c| {
                    c.method == method.name() && c.omega == omega.sign() && c.albedo == albedo
                })
                .collect();
            let going = match omega {
                Direction::Left => "−1 (left-going)",
                Direction::Right => "+1 (right-going)",
            };
            let title = format!(
                "{}: ω = {going}, albedo λ = κs/κe = {albedo}",
                method.name()
            );
            panels.push(panel(&of_panel, thicknesses, title));
        }
    }
    panels.push(legend(record));
    let mut figure = Figure::new(panels, 2);
    figure.panel_size = (560, 300);
    figure
}

/// Writes `stability_{expectation,rendering,transport}.{png,svg}`, one
/// figure per method (the coverage of every cell, markers where the
/// diagnostic flags most runs or most runs report `σ = 0`), and
/// `stability.json` (every cell's numbers).
pub fn stability(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let thicknesses = thicknesses();
    let cells = measure_all(opts)?;
    let record = Record {
        positions: POSITIONS.to_vec(),
        thicknesses: thicknesses.clone(),
        albedos: ALBEDOS.to_vec(),
        length: LENGTH,
        runs: RUNS,
        paths: opts.paths(PATHS),
        cells,
    };
    let mut written = Vec::new();
    for method in METHODS {
        let figure = method_figure(&record, &thicknesses, method);
        written.extend(figure.save(&opts.out, &format!("stability_{}", method.name()))?);
    }
    written.push(opts.write_json("stability", &record)?);
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_and_labels() {
        let t = thicknesses();
        assert_eq!(t.len(), THICKNESS_COUNT);
        assert!((t[0] - 0.1).abs() < 1e-12 && (t[t.len() - 1] - 30.0).abs() < 1e-9);
        let names: Vec<String> = t.iter().map(|&v| two_digits(v)).collect();
        assert_eq!(names[0], "0.10");
        assert_eq!(names[4], "1.7");
        assert_eq!(names[8], "30");
        let p = position_names();
        assert_eq!((p[0].as_str(), p[2].as_str()), ("0", ".25"));
        assert_eq!((p[11].as_str(), p[12].as_str()), (".9999", "1"));
    }

    #[test]
    fn writes_the_figure_and_every_cell() {
        let dir = std::env::temp_dir().join(format!("geosens-stability-{}", std::process::id()));
        let opts = FigureOptions {
            effort: 1e-4,
            progress: false,
            ..FigureOptions::new(&dir)
        };
        let written = stability(&opts).unwrap();
        let names: Vec<_> = written.iter().filter_map(|p| p.file_name()).collect();
        assert_eq!(
            names,
            [
                "stability_expectation.png",
                "stability_expectation.svg",
                "stability_rendering.png",
                "stability_rendering.svg",
                "stability_transport.png",
                "stability_transport.svg",
                "stability.json"
            ]
        );
        let json = std::fs::read_to_string(dir.join("stability.json")).unwrap();
        let cells = serde_json::from_str::<serde_json::Value>(&json).unwrap()["cells"]
            .as_array()
            .map(Vec::len);
        let expected = METHODS.len() * 2 * ALBEDOS.len() * THICKNESS_COUNT * POSITIONS.len();
        assert_eq!(cells, Some(expected));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
