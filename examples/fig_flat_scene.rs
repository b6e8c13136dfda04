//! Flatland scenes drawn: shapes by surface kind, the sensor, twenty sampled
//! backward paths, the path vertices on moving boundaries and the moving
//! corners in the sensor's view, for occluder, reflector, fog and
//! three_shapes.
//!
//! ```text
//! cargo run --release --example fig_flat_scene -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_scene.{png,svg}` and `flat_scene.json` to `OUT_DIR` (default
//! `out/figures`).
use geosens::flat::figures::{FigureOptions, scene};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(scene::scene)
}
