//! The 3D figures (the book's 3D chapter): each is one function that runs
//! its experiment, deterministic from the seed, draws it with
//! [`crate::plot`] and writes `mesh_<name>.{png,svg}` and the numbers behind
//! it, `mesh_<name>.json`, under the output folder. They take the rod's
//! [`FigureOptions`]; the examples `examples/fig_mesh_*.rs` each call one and
//! `geosens compare --figures DIR` calls them all after flatland's.
//!
//! The scenes are built in code ([`crate::mesh::cases`]): a black triangle
//! occluder under the unit-square lamp, whose `E` and `∂E/∂π` have closed
//! forms ([`crate::mesh::exact`]), and the configurations where the methods
//! struggle. Colours per method are flatland's ([`color`], shared). The exception
//! is [`camera`]: the showcase scene file's images, drawn pixel by pixel
//! with plotters directly (PNG only).
use super::Scene;
use crate::error::Error;
use crate::figures_common;
use crate::method::Method;
use crate::runner::RunResult;
use std::path::PathBuf;
use std::sync::Arc;

pub use crate::figures_common::{
    DERIVATIVE_METHODS, METHODS, REFERENCE_COLOR, color, get, label, z,
};
pub use crate::rod::figures::{FigureFn, FigureOptions};

pub mod against_pi;
pub mod camera;
pub mod convergence;
pub mod efficiency;
pub mod stability;

/// Every 3D figure, in the book's order; returns the files written.
pub fn all(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    figures_common::all(
        opts,
        &[
            against_pi::against_pi,
            convergence::convergence,
            efficiency::efficiency,
            stability::stability,
            camera::camera,
        ],
    )
}

/// Runs `method` on `scene` with `paths` (scaled by the effort) paths, seed
/// `opts.seed + salt`, on `threads` threads.
pub fn run_method(
    opts: &FigureOptions,
    method: Method,
    scene: &Arc<Scene>,
    paths: u64,
    salt: u64,
    threads: usize,
) -> Result<RunResult, Error> {
    figures_common::run_method(opts, method, scene, paths, salt, threads)
}

/// The file names (`mesh_<name>.{png,svg}`) of a figure, saved with its
/// JSON: what every figure function returns.
pub(crate) fn save<T: serde::Serialize>(
    opts: &FigureOptions,
    name: &str,
    figure: &crate::plot::Figure,
    numbers: &T,
) -> Result<Vec<PathBuf>, Error> {
    figures_common::save(opts, "mesh", name, figure, numbers)
}
