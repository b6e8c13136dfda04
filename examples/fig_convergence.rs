//! Convergence against N (extends the paper's Fig. 6e): σ and |error| of every
//! method against the number of paths, thin and thick rods, at x = 1 and 1.95.
//!
//! ```text
//! cargo run --release --example fig_convergence -- [OUT_DIR] [EFFORT]
//! ```
//! writes `convergence.{png,svg}` and `convergence.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::rod::figures::{FigureOptions, convergence};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(convergence::convergence)
}
