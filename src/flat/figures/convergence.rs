//! Convergence to the closed form: the standard error σ and the actual
//! error |mean − exact| against the number of paths N (10³ to 10⁶ in half
//! decades, a fresh seed per run), log–log, for every method on one
//! parameter of `polygon_occluder.toml` (the Γ's rotation), the intensity
//! estimator judged on `E`, the others on `∂E/∂π`. A dashed `∝ 1/√N` line
//! is the rate an unbiased finite-variance estimator shows. Every run has
//! its own seed. On this scene (black shapes, no medium, no bounce)
//! transport's Eulerian sources vanish (the radiance just in front of a
//! black surface has no gradient) and what is left are rendering's corner
//! terms: the two estimators are the same here (with one seed they agree
//! bit for bit), so their curves differ only by their seeds.
use super::{FigureOptions, exact, load, only, parameter};
use crate::error::Error;
use crate::figures_common::convergence::{measure, panel};
use crate::figures_common::save;
use crate::plot::Figure;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

/// The scene.
pub const SCENE: &str = "polygon_occluder";

/// The parameter judged.
pub const PARAMETER: &str = "gamma_rotate";

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 50_000_000;

pub use crate::figures_common::convergence::Record;

/// The numbers behind `flat_convergence.{png,svg}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Convergence {
    /// Scene file name.
    pub scene: &'static str,
    /// The parameter.
    pub parameter: &'static str,
    /// Every run (without the parameter, named above).
    pub records: Vec<Record>,
}

/// σ and |error| against N for every method on [`PARAMETER`] of [`SCENE`]
/// (a scene with that one parameter, so each run pays for one
/// sensitivity), 10³ to 10⁶ paths in half decades times the effort, on
/// `opts.threads`. Writes `flat_convergence.{png,svg}` and
/// `flat_convergence.json`.
pub fn convergence(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let base = load(SCENE)?;
    let j = parameter(&base, PARAMETER)?;
    let scene = Arc::new(only(&base, j)?);
    let (e, de) = exact(&scene, 0)?;
    let what = "flat: convergence";
    let mut records = measure(opts, what, &scene, e, &[(PARAMETER, de)], SALT)?;
    let title = format!("{SCENE}.toml, π = {PARAMETER}: error against paths");
    let mut figure = Figure::new(vec![panel(title, &records, PARAMETER)], 1);
    figure.panel_size = (900, 620);
    for r in &mut records {
        r.parameter = None;
    }
    let c = Convergence {
        scene: SCENE,
        parameter: PARAMETER,
        records,
    };
    save(opts, "flat_convergence", &figure, &c)
}
