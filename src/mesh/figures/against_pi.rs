//! 3D estimates against the parameter value over the closed form: the black
//! triangle occluder ([`TriangleOccluder::NOMINAL`]) under the unit-square
//! lamp, irradiance at the origin. For each motion (translation along x,
//! rotation about the vertical through its centre, scale about its centre)
//! the occluder is moved to [`VALUES`] values of `π` and every method run
//! there: `E` from the intensity estimator, `∂E/∂π` from expectation,
//! rendering, transport and finite differences, over
//! [`occluded_irradiance_with_gradient`](crate::mesh::exact::occluded_irradiance_with_gradient)
//! on a fine grid. The translation slides the shadow (twice the triangle's
//! size on the lamp's plane) from across the lamp's left edge to off its
//! right edge: `E` is C¹ there (a shadow vertex crossing a lamp edge is a
//! kink of `∂E/∂π`, not a jump, as no shadow edge is parallel to a lamp
//! edge).
//!
//! The scale's `∂E/∂π` is the derivative of the plotted `E(π)` (the
//! triangle's size `r₀(1 + π)`): the estimators differentiate a scale about
//! the *current* size, `r ∂E/∂r`, so their estimates (and the closed form's)
//! are divided by `1 + π`.
use super::FigureOptions;
use crate::error::Error;
use crate::figures_common::save;
use crate::figures_common::sweep::{self, Column, Exact, Spec};
use crate::mesh::Scene;
use crate::mesh::cases::TriangleOccluder;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

pub use crate::figures_common::sweep::{Curve, Record, VALUES};

/// One parameter swept over a range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sweep {
    /// Index into [`TriangleOccluder::PARAMETERS`].
    pub parameter: usize,
    /// First and last value of `π`.
    pub range: (f64, f64),
}

/// The sweeps, one column of panels each: the translation from the shadow
/// across the lamp's left edge (π = −0.45) to just off its right edge; a
/// third of a turn and more; the scale from 0.4 to 1.9 times.
pub const SWEEPS: [Sweep; 3] = [
    Sweep {
        parameter: 0,
        range: (-0.45, 0.35),
    },
    Sweep {
        parameter: 1,
        range: (-1.2, 1.2),
    },
    Sweep {
        parameter: 2,
        range: (-0.6, 0.9),
    },
];

/// Points of the closed-form curves per sweep.
pub const CURVE_POINTS: usize = 481;

/// Paths per run (times the effort).
pub const PATHS: u64 = 100_000;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 70_000_000;

/// The numbers behind `mesh_against_pi.{png,svg}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AgainstPi {
    /// The nominal occluder: centre, circumradius, angle of its first
    /// vertex.
    pub occluder: ([f64; 3], f64, f64),
    /// Every estimate and the closed-form curves.
    #[serde(flatten)]
    pub sweeps: sweep::AgainstPi,
}

/// `E` and `∂E/∂π` of the plotted curve at `π` (see the module docs for the
/// scale), and the factor applied to the estimators' derivative.
fn exact_at(sweep: &Sweep, pi: f64) -> Result<Exact, Error> {
    let k = sweep.parameter;
    let (e, d) = TriangleOccluder::NOMINAL.moved(k, pi).exact()?;
    let factor = if k == 2 { 1.0 / (1.0 + pi) } else { 1.0 };
    Ok((e, d[k] * factor, factor))
}

impl Column for Sweep {
    type Scene = Scene;
    fn parameter(&self) -> &'static str {
        TriangleOccluder::PARAMETERS[self.parameter]
    }
    fn range(&self) -> (f64, f64) {
        self.range
    }
    fn file(&self) -> Option<&'static str> {
        None
    }
    fn title(&self) -> String {
        "triangle occluder".into()
    }
    fn axis(&self) -> String {
        match self.parameter {
            0 => "π = translation along x",
            1 => "π = rotation about the vertical (rad)",
            _ => "π = scale − 1",
        }
        .into()
    }
    fn curve_at(&self, pi: f64) -> Result<(f64, f64), Error> {
        exact_at(self, pi).map(|(v, d, _)| (v, d))
    }
    fn at(&self, pi: f64) -> Result<(Arc<Scene>, Exact), Error> {
        let k = self.parameter;
        let scene = Arc::new(TriangleOccluder::NOMINAL.moved(k, pi).scene(&[k])?);
        Ok((scene, exact_at(self, pi)?))
    }
}

/// `E` and `∂E/∂π` against `π` for the black triangle occluder's
/// translation along x, rotation and scale ([`SWEEPS`], columns; `E` on the
/// top row, `∂E/∂π` below, the legend across the top),
/// every Monte Carlo method as markers with ±σ bars ([`PATHS`] paths per
/// run on `opts.threads`) over the closed form as a line. Writes
/// `mesh_against_pi.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_mesh_against_pi -- [OUT_DIR] [EFFORT]
/// ```
pub fn against_pi(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let spec = Spec {
        prefix: "mesh",
        curve_points: CURVE_POINTS,
        paths: PATHS,
        salt: SALT,
        reference: "closed form (black triangle at z = 1 under the unit lamp at z = 2)",
    };
    let (sweeps, mut figure) = sweep::figure(opts, &spec, &SWEEPS)?;
    figure.panel_size = (560, 440);
    let o = TriangleOccluder::NOMINAL;
    let numbers = AgainstPi {
        occluder: (o.centre.to_array(), o.radius, o.angle),
        sweeps,
    };
    save(opts, "mesh_against_pi", &figure, &numbers)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures_common::grid;
    use crate::method::Method;

    #[test]
    fn sweeps_stay_valid() {
        for sweep in &SWEEPS {
            for pi in grid(sweep.range, VALUES) {
                let t = TriangleOccluder::NOMINAL.moved(sweep.parameter, pi);
                let scene = Arc::new(t.scene(&[sweep.parameter]).unwrap());
                assert!(Method::Fd.estimator(scene).is_ok(), "{sweep:?} at {pi}");
                assert!(exact_at(sweep, pi).unwrap().1.is_finite());
            }
        }
    }
}
