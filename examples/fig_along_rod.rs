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
    let mut args = std::env::args().skip(1);
    let mut opts = FigureOptions::new(args.next().unwrap_or_else(|| "out/figures".into()));
    if let Some(e) = args.next() {
        opts.effort = e
            .parse()
            .map_err(|_| geosens::Error::Output(format!("bad effort {e:?}")))?;
    }
    for path in along::intensity_along_rod(&opts)?
        .into_iter()
        .chain(along::sensitivity_along_rod(&opts)?)
    {
        println!("wrote {}", path.display());
    }
    Ok(())
}
