//! Finite differences of two Monte Carlo runs, independent and with common
//! random numbers, against the half step (the book's "Introduction").
//!
//! ```text
//! cargo run --release --example fig_finite_difference -- [OUT_DIR] [EFFORT]
//! ```
//! writes `finite_difference.{png,svg,json}` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::rod::figures::{FigureOptions, finite_difference};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(finite_difference::finite_difference)
}
