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
    let mut args = std::env::args().skip(1);
    let mut opts = FigureOptions::new(args.next().unwrap_or_else(|| "out/figures".into()));
    if let Some(e) = args.next() {
        opts.effort = e
            .parse()
            .map_err(|_| geosens::Error::Output(format!("bad effort {e:?}")))?;
    }
    for path in convergence::convergence(&opts)? {
        println!("wrote {}", path.display());
    }
    Ok(())
}
