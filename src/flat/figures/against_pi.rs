//! Estimates against the parameter value over the analytic curves: the
//! irradiance `E` (intensity estimator) and `∂E/∂π` (expectation, rendering,
//! transport and finite differences) at 13 values of `π`, each scene moved
//! by `π` with [`Scene::displaced`](crate::flat::Scene::displaced), over the
//! closed-form or quadrature reference
//! ([`Reference`](crate::flat::exact::Reference)) on a fine grid. The
//! ranges make the shadow's ends sweep over the lamp's ends, where `E` has
//! kinks and `∂E/∂π` jumps (occluder.toml: the occluder's translation and
//! rotation); the absorbing slab's scale changes `E` smoothly.
use super::{FigureOptions, REFERENCE_COLOR, exact, load, only, parameter, save};
use crate::error::Error;
use crate::figures_common::grid;
use crate::figures_common::sweep::{self, QUANTITIES, columns, markers};
use crate::plot::{Figure, Legend, Panel, Series, quiet_corner};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// One parameter swept over a range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// Scene file name (without `.toml`).
    pub scene: &'static str,
    /// The parameter.
    pub parameter: &'static str,
    /// First and last value of `π`.
    pub range: (f64, f64),
}

/// The sweeps, one column of panels each. The occluder's translation
/// crosses three jumps of `∂E/∂π` (at −0.7, 0.1 and 0.3, where an end of
/// its shadow passes an end of the lamp), its rotation one (near −0.36);
/// no value of `π` lies within a finite-difference step of a jump.
pub const SWEEPS: [Sweep; 3] = [
    Sweep {
        scene: "occluder",
        parameter: "occluder_tx",
        range: (-0.85, 0.59),
    },
    Sweep {
        scene: "occluder",
        parameter: "occluder_rotate",
        range: (-1.2, 1.2),
    },
    Sweep {
        scene: "absorbing_slab",
        parameter: "slab_scale",
        range: (-0.6, 0.9),
    },
];

/// Values of `π` per sweep (ends included).
pub const VALUES: usize = 13;

/// Points of the analytic curves per sweep.
pub const CURVE_POINTS: usize = 601;

/// Paths per run (times the effort).
pub const PATHS: u64 = 200_000;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 40_000_000;

/// One estimate at one value of `π`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    /// Scene file name.
    pub scene: &'static str,
    /// The parameter.
    pub parameter: &'static str,
    /// Its value (the scene displaced by it).
    pub pi: f64,
    /// Method name.
    pub method: &'static str,
    /// `"E"` or `"dE/dπ"`.
    pub quantity: &'static str,
    /// Paths sampled.
    pub paths: u64,
    /// The estimate.
    pub mean: f64,
    /// Its standard error.
    pub stderr: f64,
    /// The analytic value.
    pub exact: f64,
    /// `(mean − exact) / stderr`; 0 when the estimate is exact, `None`
    /// when `stderr = 0` but the estimate is not (finite differences whose
    /// step no path's visibility changes within).
    pub z: Option<f64>,
}

/// The analytic curve of one sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    /// Scene file name.
    pub scene: &'static str,
    /// The parameter.
    pub parameter: &'static str,
    /// Values of `π`.
    pub pi: Vec<f64>,
    /// `E(π)`.
    pub e: Vec<f64>,
    /// `∂E/∂π(π)`.
    pub de: Vec<f64>,
}

/// The numbers behind `flat_against_pi.{png,svg}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AgainstPi {
    /// Every estimate.
    pub records: Vec<Record>,
    /// The analytic curves.
    pub curves: Vec<Curve>,
}

/// `(π, y)` split where `y` jumps (a step far larger than its neighbours'),
/// so that a jump is drawn as a gap rather than a steep line.
fn pieces(xy: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let steps: Vec<f64> = xy.windows(2).map(|w| (w[1].1 - w[0].1).abs()).collect();
    let span = xy.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max)
        - xy.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    let mut out = vec![Vec::new()];
    for (i, &p) in xy.iter().enumerate() {
        if i > 0 {
            let s = steps[i - 1];
            let before = if i >= 2 { steps[i - 2] } else { 0.0 };
            let after = steps.get(i).copied().unwrap_or(0.0);
            if s > 1e-3 * span && s > 8.0 * before.max(after) {
                out.push(Vec::new());
            }
        }
        if let Some(last) = out.last_mut() {
            last.push(p);
        }
    }
    out
}

/// The sweep's analytic curve.
fn curve(sweep: &Sweep) -> Result<Curve, Error> {
    let base = load(sweep.scene)?;
    let j = parameter(&base, sweep.parameter)?;
    let (pi, e, de) = sweep::curve(sweep.range, CURVE_POINTS, |p| {
        exact(&base.displaced(j, p)?, j)
    })?;
    Ok(Curve {
        scene: sweep.scene,
        parameter: sweep.parameter,
        pi,
        e,
        de,
    })
}

/// Runs every method at every value of `π` of `sweep`.
fn measure(
    opts: &FigureOptions,
    sweep: &Sweep,
    salt: &mut u64,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<Record>, Error> {
    let base = load(sweep.scene)?;
    let j = parameter(&base, sweep.parameter)?;
    let values = grid(sweep.range, VALUES);
    let runs = sweep::measure(opts, values, sweep.parameter, PATHS, salt, bar, |pi| {
        let scene = Arc::new(only(&base.displaced(j, pi)?, j)?);
        let (e, de) = exact(&scene, 0)?;
        Ok((scene, (e, de, 1.0)))
    })?;
    Ok(runs
        .into_iter()
        .map(|r| Record {
            scene: sweep.scene,
            parameter: sweep.parameter,
            pi: r.pi,
            method: r.method,
            quantity: r.quantity,
            paths: r.paths,
            mean: r.mean,
            stderr: r.stderr,
            exact: r.exact,
            z: r.z,
        })
        .collect())
}

/// The two panels of one sweep: `E` over its curve, `∂E/∂π` over its curve.
fn panels(sweep: &Sweep, curve: &Curve, records: &[Record]) -> [Panel; 2] {
    let step = (sweep.range.1 - sweep.range.0) / (VALUES - 1) as f64;
    let corners = [
        Legend::UpperRight,
        Legend::UpperLeft,
        Legend::LowerRight,
        Legend::LowerLeft,
    ];
    QUANTITIES.map(|(quantity, y_label)| {
        let ys = if quantity == "E" { &curve.e } else { &curve.de };
        let xy: Vec<(f64, f64)> = curve.pi.iter().copied().zip(ys.iter().copied()).collect();
        let mut series = Vec::new();
        for (i, piece) in pieces(&xy).into_iter().enumerate() {
            let label = if i == 0 { "analytic" } else { "" };
            series.push(Series::line(label, REFERENCE_COLOR, piece));
        }
        series.extend(markers(quantity, step, true, |method| {
            records
                .iter()
                .filter(|r| r.method == method.name() && r.quantity == quantity)
                .map(|r| (r.pi, r.mean, r.stderr))
                .collect()
        }));
        let mut panel = Panel {
            title: format!(
                "{}.toml: {} against {}",
                sweep.scene,
                quantity.replace("dE/dπ", "∂E/∂π"),
                sweep.parameter
            ),
            x_label: format!("π = {}", sweep.parameter),
            y_label: y_label.into(),
            series,
            ..Panel::default()
        };
        panel.legend = quiet_corner(&panel, &corners, (0.35, 0.3)).0;
        panel
    })
}

/// E and ∂E/∂π against π for the [`SWEEPS`] (columns; `E` on the top row,
/// `∂E/∂π` below), [`PATHS`] paths per run on `opts.threads`. Writes
/// `flat_against_pi.{png,svg}` and `flat_against_pi.json`.
pub fn against_pi(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let runs = SWEEPS.len() * VALUES * sweep::methods().count();
    let bar = opts.bar(runs as u64, "flat: against π");
    let mut salt = SALT;
    let columns = columns(
        &SWEEPS,
        curve,
        |w| measure(opts, w, &mut salt, &bar),
        panels,
    )?;
    bar.finish();
    let (records, curves, mut top) = (columns.records, columns.curves, columns.top);
    top.extend(columns.bottom);
    let mut figure = Figure::new(top, SWEEPS.len());
    figure.panel_size = (640, 480);
    save(opts, "against_pi", &figure, &AgainstPi { records, curves })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::Method;

    #[test]
    fn jumps_break_the_curve() {
        let xy: Vec<(f64, f64)> = (0..20)
            .map(|i| {
                let x = f64::from(i) / 19.0;
                (x, x + if x > 0.5 { 1.0 } else { 0.0 })
            })
            .collect();
        let p = pieces(&xy);
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].len() + p[1].len(), 20);
        // A kink is not a jump.
        let kink: Vec<(f64, f64)> = (0..20)
            .map(|i| {
                let x = f64::from(i) / 19.0 - 0.5;
                (x, x.abs())
            })
            .collect();
        assert_eq!(pieces(&kink).len(), 1);
    }

    #[test]
    fn sweeps_stay_valid_and_keep_off_the_jumps() {
        for sweep in &SWEEPS {
            let base = load(sweep.scene).unwrap();
            let j = parameter(&base, sweep.parameter).unwrap();
            for pi in grid(sweep.range, VALUES) {
                // The scene and its finite-difference neighbours are valid.
                let scene = Arc::new(only(&base.displaced(j, pi).unwrap(), j).unwrap());
                assert!(Method::Fd.estimator(scene).is_ok(), "{sweep:?} at {pi}");
            }
        }
        let jumps = [-0.7, 0.1, 0.3];
        for pi in grid(SWEEPS[0].range, VALUES) {
            assert!(jumps.iter().all(|&x| (pi - x).abs() > 0.005), "{pi}");
        }
    }
}
