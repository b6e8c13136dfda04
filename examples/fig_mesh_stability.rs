//! Where the 3D methods struggle: σ²N and the bias of ∂E/∂p of every
//! derivative method against the distance to four singular configurations
//! (a sensor near a moving face, a shadow edge along the lamp's edge, a thin
//! dense fog slab, a box face near a plane through the sensor).
//!
//! ```text
//! cargo run --release --example fig_mesh_stability -- [OUT_DIR] [EFFORT]
//! ```
//! writes `mesh_stability.{png,svg}` and `mesh_stability.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::mesh::figures::{FigureOptions, stability};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(stability::stability)
}
