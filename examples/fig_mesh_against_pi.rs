//! 3D estimates against the parameter value over the closed form: E (intensity)
//! and ∂E/∂π (expectation, rendering, transport, fd) for a black triangle
//! occluder's translation, rotation and scale under the unit-square lamp.
//!
//! ```text
//! cargo run --release --example fig_mesh_against_pi -- [OUT_DIR] [EFFORT]
//! ```
//! writes `mesh_against_pi.{png,svg}` and `mesh_against_pi.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::mesh::figures::{FigureOptions, against_pi};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(against_pi::against_pi)
}
