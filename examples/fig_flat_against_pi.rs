//! Flatland estimates against the parameter value over the analytic curves:
//! E (intensity) and ∂E/∂π (expectation, rendering, transport, fd) for
//! occluder.toml's translation and rotation and absorbing_slab.toml's
//! scale.
//!
//! ```text
//! cargo run --release --example fig_flat_against_pi -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_against_pi.{png,svg}` and `flat_against_pi.json` to
//! `OUT_DIR` (default `out/figures`); `EFFORT` scales the path counts.
use geosens::flat::figures::{FigureOptions, against_pi};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(against_pi::against_pi)
}
