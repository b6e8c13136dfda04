//! Speed against accuracy (extends the paper's Fig. 6e): the work-normalised
//! variance σ²·t of every method along the rod, and |error| against wall time
//! (timing runs on one thread).
//!
//! ```text
//! cargo run --release --example fig_efficiency -- [OUT_DIR] [EFFORT]
//! ```
//! writes `efficiency.{png,svg}` and `efficiency.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::rod::figures::{FigureOptions, efficiency};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(efficiency::efficiency)
}
