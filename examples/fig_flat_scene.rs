//! Flatland scenes drawn: shapes by surface kind, the sensor, twenty sampled
//! backward paths, the path vertices on moving boundaries and the moving
//! corners in the sensor's view, for every shipped scene: the scenes of
//! opaque shapes in one figure, those with a medium in another.
//!
//! ```text
//! cargo run --release --example fig_flat_scene -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_scene_opaque.{png,svg}`, `flat_scene_media.{png,svg}` and
//! `flat_scene.json` to `OUT_DIR` (default `out/figures`).
use geosens::flat::figures::{FigureOptions, scene};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(scene::scene)
}
