//! The showcase camera (`scenes/mesh/showcase.toml`) rendered by finite
//! differences, rendering, transport and expectation: one grid of images,
//! rows `I` and each parameter's `∂I/∂π`, one colour scale per row.
//!
//! ```text
//! cargo run --release --example fig_mesh_camera -- [OUT_DIR] [EFFORT]
//! ```
//! writes `mesh_camera.png` and `mesh_camera.json` to `OUT_DIR` (default
//! `out/figures`) and prints every image's mean ± standard error and each
//! render's seconds; `EFFORT` scales the 64 paths per pixel.
use geosens::mesh::figures::{FigureOptions, camera};

fn main() -> Result<(), geosens::Error> {
    let opts = FigureOptions::from_args()?;
    let runs = camera::render_all(&opts, &camera::showcase()?)?;
    print!("{}", camera::table(&runs));
    for path in camera::save(&opts, &runs)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}
