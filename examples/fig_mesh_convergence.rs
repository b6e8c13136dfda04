//! 3D convergence: σ and |mean − exact| against the number of paths (10³ to
//! 10⁶), log–log, for every method on the black triangle occluder's
//! translation and rotation, against the closed form.
//!
//! ```text
//! cargo run --release --example fig_mesh_convergence -- [OUT_DIR] [EFFORT]
//! ```
//! writes `mesh_convergence.{png,svg}` and `mesh_convergence.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::mesh::figures::{FigureOptions, convergence};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(convergence::convergence)
}
