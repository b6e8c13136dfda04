//! Where the flatland methods fail: σ²N of ∂E/∂π against the distance to
//! three singular configurations (warp knots meeting, a sensor near a moving
//! edge, a thin dense slab), every derivative method.
//!
//! ```text
//! cargo run --release --example fig_flat_stability -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_stability.{png,svg}` and `flat_stability.json` to `OUT_DIR`
//! (default `out/figures`).
use geosens::flat::figures::{FigureOptions, stability};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(stability::stability)
}
