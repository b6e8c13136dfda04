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
    let mut args = std::env::args().skip(1);
    let mut opts = FigureOptions::new(args.next().unwrap_or_else(|| "out/figures".into()));
    if let Some(e) = args.next() {
        opts.effort = e
            .parse()
            .map_err(|_| geosens::Error::Output(format!("bad effort {e:?}")))?;
    }
    for path in efficiency::efficiency(&opts)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}
