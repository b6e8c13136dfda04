//! Stability map: where each method's error bar cannot be trusted, over the
//! probe position, the optical thickness and the albedo.
//!
//! ```text
//! cargo run --release --example fig_stability -- [OUT_DIR] [EFFORT]
//! ```
//! writes `stability.{png,svg}`, `stability_flagged.{png,svg}` and
//! `stability.json` to `OUT_DIR` (default `out/figures`); `EFFORT` scales the
//! path counts.
use geosens::rod::figures::{FigureOptions, stability};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(stability::stability)
}
