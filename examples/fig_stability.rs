//! Stability map (the book's "Comparing the approaches"): the coverage of
//! every method's error bar on `s`, and where the tail diagnostic flags it,
//! over the probe position, the optical thickness, the albedo and both
//! directions.
//!
//! ```text
//! cargo run --release --example fig_stability -- [OUT_DIR] [EFFORT]
//! ```
//! writes `stability_expectation.{png,svg}`, `stability_rendering.{png,svg}`
//! and `stability_transport.{png,svg}` (one figure per method) and
//! `stability.json` (every cell's numbers) to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::rod::figures::{FigureOptions, stability};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(stability::stability)
}
