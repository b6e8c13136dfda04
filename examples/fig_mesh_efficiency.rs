//! 3D speed against accuracy: σ²·t (variance per path × seconds per path,
//! one thread) of every method, fd included, for E and every parameter of
//! the triangle occluder, cube_shadow and fog_cube, as grouped bars.
//!
//! ```text
//! cargo run --release --example fig_mesh_efficiency -- [OUT_DIR] [EFFORT]
//! ```
//! writes `mesh_efficiency.{png,svg}` and `mesh_efficiency.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::mesh::figures::{FigureOptions, efficiency};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(efficiency::efficiency)
}
