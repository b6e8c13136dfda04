//! 3D speed against accuracy: the work-normalised variance `σ²·t` (the
//! variance of one path's weight times the seconds one path takes on one
//! thread; the variance one second of sampling leaves) of every method,
//! finite differences included, for `E` and every parameter, as markers
//! side by side on a log axis (lower is better). Scenes: the black triangle
//! occluder ([`TriangleOccluder::NOMINAL`], translation, rotation, scale),
//! `scenes/mesh/cube_shadow.toml` (a black cube) and
//! `scenes/mesh/fog_cube.toml` (a scattering fog cube), one panel each. A
//! path estimates `E` and all the scene's sensitivities at once, so the
//! markers of one method share its `t`; finite differences pay two extra
//! readings per parameter.
//!
//! Every timing run uses one thread whatever `opts.threads`; runs shorter
//! than [`MIN_SECONDS`] are repeated (same seed) and the fastest time kept.
//! Hollow markers have a VOV of at least [`Estimate::VOV_LIMIT`](crate::stats::Estimate::VOV_LIMIT) (σ unreliable).
use super::FigureOptions;
use crate::error::Error;
use crate::figures_common::efficiency::{self, Spec};
use crate::mesh::cases::TriangleOccluder;
use crate::mesh::{Scene, file};
use std::path::PathBuf;

pub use crate::figures_common::efficiency::{MIN_SECONDS, Record};

/// Panel names: the triangle occluder and two shipped scenes.
pub const SCENES: [&str; 3] = ["triangle occluder", "cube_shadow.toml", "fog_cube.toml"];

/// Paths per run (times the effort).
pub const PATHS: u64 = 100_000;

/// Most runs of one configuration when timing short runs.
pub const MAX_REPEATS: u32 = 4;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 72_000_000;

/// The scene of panel `name`.
fn scene(name: &str) -> Result<Scene, Error> {
    let text = match name {
        "cube_shadow.toml" => include_str!("../../../scenes/mesh/cube_shadow.toml"),
        "fog_cube.toml" => include_str!("../../../scenes/mesh/fog_cube.toml"),
        _ => return TriangleOccluder::NOMINAL.scene(&[0, 1, 2]),
    };
    file::from_toml(text).map_err(|e| Error::Scene(format!("scenes/mesh/{name}: {e}")))
}

/// `σ²·t` of every method (finite differences included) for `E` and every
/// parameter of the [`SCENES`] (one panel each, markers per quantity, log axis),
/// [`PATHS`] paths per run on one thread. Writes
/// `mesh_efficiency.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_mesh_efficiency -- [OUT_DIR] [EFFORT]
/// ```
pub fn efficiency(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let spec = Spec {
        prefix: "mesh",
        scenes: &SCENES,
        build: scene,
        title: str::to_owned,
        paths: PATHS,
        max_repeats: MAX_REPEATS,
        salt: SALT,
        panel_size: (1200, 420),
    };
    efficiency::efficiency(opts, &spec)
}
