//! Flatland's line camera: the image row of `I` and of its sensitivities by
//! every derivative method over the exact row.
//!
//! ```text
//! cargo run --release --example fig_flat_camera -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_camera.{png,svg}` and `flat_camera.json` to `OUT_DIR`
//! (default `out/figures`).
use geosens::flat::figures::{FigureOptions, camera};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(camera::camera)
}
