//! The 3D figures (the book's 3D chapter): each is one function that runs
//! its experiment, deterministic from the seed, draws it with
//! [`crate::plot`] and writes `mesh_<name>.{png,svg}` and the numbers behind
//! it, `mesh_<name>.json`, under the output folder. They take the
//! [`FigureOptions`] every figure takes; the examples `examples/fig_mesh_*.rs`
//! each call one and `geosens compare --figures DIR` calls them all after
//! flatland's. Their experiments but the camera's are flatland's, written
//! once for both dimensions.
//!
//! The scenes are built in code ([`crate::mesh::cases`]): a black triangle
//! occluder under the unit-square lamp, whose `E` and `∂E/∂π` have closed
//! forms ([`crate::mesh::exact`]), and the configurations where the methods
//! struggle. Colours per method are flatland's ([`color`], shared). The
//! exception is [`camera`]: the showcase scene file's images, drawn pixel
//! by pixel with plotters directly (PNG only).
use crate::error::Error;
use crate::figures_common;
use std::path::PathBuf;

pub use crate::figures_common::{
    DERIVATIVE_METHODS, FigureFn, FigureOptions, METHODS, REFERENCE_COLOR, color, get, label,
    parameter, run_method, z,
};

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
