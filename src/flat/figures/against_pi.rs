//! Estimates against the parameter value over the analytic curves: the
//! irradiance `E` (intensity estimator) and `∂E/∂π` (expectation, rendering,
//! transport and finite differences) at 13 values of `π`, each scene moved
//! by `π` with [`Scene::displaced`](crate::flat::Scene::displaced), over the
//! closed-form or quadrature reference
//! ([`Reference`](crate::flat::exact::Reference)) on a fine grid. The
//! ranges make the shadow's ends sweep over the lamp's ends, where `E` has
//! kinks and `∂E/∂π` jumps (occluder.toml: the occluder's translation and
//! rotation); the absorbing slab's scale changes `E` smoothly.
use super::{FigureOptions, exact, load, only, parameter};
use crate::error::Error;
use crate::figures_common::save;
use crate::figures_common::sweep::{self, Column, Exact, Spec};
use crate::flat::Scene;
use std::path::PathBuf;
use std::sync::Arc;

pub use crate::figures_common::sweep::{AgainstPi, Curve, Record, VALUES};

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

/// Points of the analytic curves per sweep.
pub const CURVE_POINTS: usize = 601;

/// Paths per run (times the effort).
pub const PATHS: u64 = 200_000;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 40_000_000;

/// A sweep with its scene loaded: parameter `j` of `base` moved.
struct Loaded {
    sweep: Sweep,
    base: Scene,
    j: usize,
}

impl Loaded {
    fn new(sweep: &Sweep) -> Result<Loaded, Error> {
        let base = load(sweep.scene)?;
        let j = parameter(&base, sweep.parameter)?;
        Ok(Loaded {
            sweep: *sweep,
            base,
            j,
        })
    }
}

impl Column for Loaded {
    type Scene = Scene;
    fn parameter(&self) -> &'static str {
        self.sweep.parameter
    }
    fn range(&self) -> (f64, f64) {
        self.sweep.range
    }
    fn file(&self) -> Option<&'static str> {
        Some(self.sweep.scene)
    }
    fn title(&self) -> String {
        format!("{}.toml", self.sweep.scene)
    }
    fn axis(&self) -> String {
        format!("π = {}", self.sweep.parameter)
    }
    fn curve_at(&self, pi: f64) -> Result<(f64, f64), Error> {
        exact(&self.base.displaced(self.j, pi)?, self.j)
    }
    /// The scene with the swept parameter only (its index 0), so that a
    /// run pays for that one sensitivity.
    fn at(&self, pi: f64) -> Result<(Arc<Scene>, Exact), Error> {
        let scene = Arc::new(only(&self.base.displaced(self.j, pi)?, self.j)?);
        let (e, de) = exact(&scene, 0)?;
        Ok((scene, (e, de, 1.0)))
    }
}

/// E and ∂E/∂π against π for the [`SWEEPS`] (columns; `E` on the top row,
/// `∂E/∂π` below), [`PATHS`] paths per run on `opts.threads`. Writes
/// `flat_against_pi.{png,svg}` and `flat_against_pi.json`.
pub fn against_pi(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let sweeps = SWEEPS
        .iter()
        .map(Loaded::new)
        .collect::<Result<Vec<_>, _>>()?;
    let spec = Spec {
        prefix: "flat",
        curve_points: CURVE_POINTS,
        paths: PATHS,
        salt: SALT,
        reference: "analytic",
    };
    let (mut numbers, mut figure) = sweep::figure(opts, &spec, &sweeps)?;
    // This figure's JSON has never held the VOV.
    for r in &mut numbers.records {
        r.vov = None;
    }
    figure.panel_size = (640, 480);
    save(opts, "flat_against_pi", &figure, &numbers)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures_common::grid;
    use crate::method::Method;

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
