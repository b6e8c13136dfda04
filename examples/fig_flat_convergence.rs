//! Flatland convergence: σ and |mean − exact| against the number of paths
//! (10³ to 10⁶), log–log, for every method on polygon_occluder.toml's
//! rotation, against the closed form.
//!
//! ```text
//! cargo run --release --example fig_flat_convergence -- [OUT_DIR] [EFFORT]
//! ```
//! writes `flat_convergence.{png,svg}` and `flat_convergence.json` to `OUT_DIR` (default
//! `out/figures`); `EFFORT` scales the path counts.
use geosens::flat::figures::{FigureOptions, convergence};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(convergence::convergence)
}
