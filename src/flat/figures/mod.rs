//! Flatland's figures (the book's chapter "Flatland"): each is one function
//! that runs its experiment, deterministic from the seed, draws it with
//! [`crate::plot`] and writes `flat_<name>.{png,svg}` and the numbers behind
//! it, `flat_<name>.json`, under the output folder. They take the
//! [`FigureOptions`] every figure takes; the examples `examples/fig_flat_*.rs`
//! each call one and `geosens compare --figures DIR` calls them all after
//! the rod's. What does not depend on the dimension (the methods, their
//! colours and labels, running one, and the experiments against `π`, of
//! convergence, efficiency and stability) is written once, for the 3D
//! figures too; these files say what flatland's scenes and references are.
//!
//! The scenes are the files of `scenes/`, compiled in ([`scene_file`]), so
//! the figures do not depend on the working directory.
use super::exact::Reference;
use super::{Scene, file};
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
pub mod scene;
pub mod stability;
pub mod warp;

/// Every flatland figure, in the book's order; returns the files written.
pub fn all(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    figures_common::all(
        opts,
        &[
            scene::scene,
            warp::warp,
            against_pi::against_pi,
            convergence::convergence,
            efficiency::efficiency,
            stability::stability,
            camera::camera,
        ],
    )
}

/// The text of `scenes/<name>.toml`, compiled in; `None` for a name that is
/// not one of the shipped scenes.
pub fn scene_file(name: &str) -> Option<&'static str> {
    Some(match name {
        "occluder" => include_str!("../../../scenes/occluder.toml"),
        "polygon_occluder" => include_str!("../../../scenes/polygon_occluder.toml"),
        "absorbing_slab" => include_str!("../../../scenes/absorbing_slab.toml"),
        "fog" => include_str!("../../../scenes/fog.toml"),
        "reflector" => include_str!("../../../scenes/reflector.toml"),
        "three_shapes" => include_str!("../../../scenes/three_shapes.toml"),
        "radiance" => include_str!("../../../scenes/radiance.toml"),
        "submerged" => include_str!("../../../scenes/submerged.toml"),
        "camera_line" => include_str!("../../../scenes/camera_line.toml"),
        "inverse_occluder" => include_str!("../../../scenes/inverse_occluder.toml"),
        "design_reflector" => include_str!("../../../scenes/design_reflector.toml"),
        _ => return None,
    })
}

/// The shipped scene `scenes/<name>.toml`.
pub fn load(name: &str) -> Result<Scene, Error> {
    let text =
        scene_file(name).ok_or_else(|| Error::Scene(format!("no shipped scene {name:?}")))?;
    file::from_toml(text).map_err(|e| Error::Scene(format!("scenes/{name}.toml: {e}")))
}

/// `scene` with parameter `j` only (pivots stay resolved), so that a run
/// pays for that one sensitivity; its index becomes 0.
pub fn only(scene: &Scene, j: usize) -> Result<Scene, Error> {
    let p = scene
        .parameters()
        .get(j)
        .ok_or_else(|| Error::Scene(format!("no parameter {j}")))?;
    Scene::new(scene.shapes().to_vec(), vec![p.clone()], scene.sensor())
}

/// The analytic `E` and `∂E/∂π_j` of `scene`.
pub fn exact(scene: &Scene, j: usize) -> Result<(f64, f64), Error> {
    let r = Reference::for_scene(scene)?;
    Ok((r.value(), r.derivative(j)))
}
