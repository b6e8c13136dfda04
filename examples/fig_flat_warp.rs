//! The expectation method's warp field at the sensor of polygon_occluder:
//! V_j(φ) for every parameter with its knots at the visible corners, and
//! arrow fields on the scene.
//!
//! ```text
//! cargo run --release --example fig_flat_warp -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_warp.{png,svg}` and `flat_warp.json` to `OUT_DIR` (default
//! `out/figures`).
use geosens::flat::figures::{FigureOptions, warp};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(warp::warp)
}
