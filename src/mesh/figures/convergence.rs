//! 3D convergence to the closed form: the standard error σ (lines) and the
//! actual error |mean − exact| (dots) against the number of paths N (10³
//! to 10⁶ in half decades times the effort, a fresh seed per run),
//! log–log, for every method on the nominal black triangle occluder
//! ([`TriangleOccluder::NOMINAL`]) with two parameters, its translation
//! along x and its rotation about the vertical (one panel each; one run of
//! a method gives both). The intensity estimator is judged on `E`, the
//! others on `∂E/∂π`. A dashed `∝ 1/√N` line is the rate an unbiased
//! finite-variance estimator shows.
use super::FigureOptions;
use crate::error::Error;
use crate::figures_common::convergence::{measure, panel};
use crate::figures_common::save;
use crate::mesh::cases::TriangleOccluder;
use crate::plot::Figure;
use std::path::PathBuf;
use std::sync::Arc;

/// The parameters judged (indices into [`TriangleOccluder::PARAMETERS`]).
pub const PARAMETERS: [usize; 2] = [0, 1];

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 71_000_000;

pub use crate::figures_common::convergence::Record;

/// σ and |mean − exact| against N for every method on the triangle
/// occluder's translation along x and rotation (one panel each), 10³ to
/// 10⁶ paths in half decades times the effort on `opts.threads`, against
/// the closed form. Writes `mesh_convergence.{png,svg,json}`:
///
/// ```text
/// cargo run --release --example fig_mesh_convergence -- [OUT_DIR] [EFFORT]
/// ```
pub fn convergence(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let t = TriangleOccluder::NOMINAL;
    let scene = Arc::new(t.scene(&PARAMETERS)?);
    let (e, de) = t.exact()?;
    let parameters = PARAMETERS.map(|k| (TriangleOccluder::PARAMETERS[k], de[k]));
    let records = measure(opts, "mesh: convergence", &scene, e, &parameters, SALT)?;
    let panels = PARAMETERS
        .iter()
        .map(|&k| {
            let parameter = TriangleOccluder::PARAMETERS[k];
            let title = format!("triangle occluder, π = {parameter}: error against paths");
            panel(title, &records, parameter)
        })
        .collect();
    let mut figure = Figure::new(panels, 2).share_legend();
    figure.panel_size = (760, 560);
    save(opts, "mesh_convergence", &figure, &records)
}
