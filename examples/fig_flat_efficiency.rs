//! Flatland speed against accuracy: σ²·t (variance per path × seconds per
//! path, one thread) of every method for E and every parameter of
//! polygon_occluder, fog and three_shapes, as grouped bars.
//!
//! ```text
//! cargo run --release --example fig_flat_efficiency -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_efficiency.{png,svg}` and `flat_efficiency.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::flat::figures::{FigureOptions, efficiency};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(efficiency::efficiency)
}
