//! Figs. 5 and 6a–d of He et al. (2024): intensity and sensitivity along the
//! rod, every method over the exact curves.
//!
//! ```text
//! cargo run --release --example fig_along_rod -- [OUT_DIR] [EFFORT]
//! ```
//! writes `intensity_along_rod.{png,svg}` and `sensitivity_along_rod.{png,svg}`
//! to `OUT_DIR` (default `out/figures`); `EFFORT` scales the path counts.
use geosens::rod::figures::{FigureOptions, along};

fn main() -> Result<(), geosens::Error> {
    FigureOptions::run_example(|opts| {
        let mut written = along::intensity_along_rod(opts)?;
        written.extend(along::sensitivity_along_rod(opts)?);
        Ok(written)
    })
}
