//! `geosens optimize`: an inverse problem or a design run on a scene file
//! with `[objective]` and `[[measurements]]` (flatland or 3D, after the
//! file's points), one record per iteration as a table or JSON lines.
use super::output::progress_bar;
use clap::Args;
use geosens::method::model::Model;
use geosens::optimize::{Optimizer, Product, Record, Sampling, Settings, Study, optimize};
use geosens::{Error, Method};
use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// `geosens optimize`'s arguments.
#[derive(Debug, Args)]
pub(super) struct OptimizeArgs {
    /// The scene file (TOML or JSON) with `[objective]` and
    /// `[[measurements]]`; its pose is the start.
    #[arg(long, value_name = "FILE")]
    scene: PathBuf,
    /// The method that estimates the gradient.
    #[arg(long, value_enum)]
    method: Method,
    /// The step rule.
    #[arg(long, value_enum, default_value = "adam")]
    optimizer: Optimizer,
    /// Iterations at most.
    #[arg(long, default_value_t = 100)]
    iterations: u32,
    /// Paths per measurement (a camera's: per pixel) and iteration.
    #[arg(long, default_value_t = 16384)]
    paths_per_step: u64,
    /// The first step: Adam's in parameter units (scene units, radians),
    /// gradient descent's multiplier of the gradient.
    #[arg(long, default_value_t = 0.02)]
    step: f64,
    /// Independent batches the paths split into (the gradient's products
    /// are taken between batches, so it is unbiased).
    #[arg(long, default_value_t = 8)]
    batches: u32,
    /// The finite-difference half step (`--method fd`).
    #[arg(long)]
    fd_step: Option<f64>,
    /// Stop once no parameter moves more than this in a step (0: never).
    #[arg(long, default_value_t = 0.0)]
    tolerance: f64,
    /// Seed of the run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (0: all cores); the records do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// One JSON line per iteration instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs `geosens optimize`.
pub(super) fn optimize_command(
    args: &OptimizeArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    if !(args.step.is_finite() && args.step > 0.0) {
        return Err(Error::Config(format!("--step {} is not a positive number", args.step)).into());
    }
    if args.iterations == 0 {
        return Err(Error::Config("--iterations must be at least 1".into()).into());
    }
    let settings = Settings {
        method: args.method,
        optimizer: args.optimizer,
        iterations: args.iterations,
        step: args.step,
        sampling: Sampling {
            paths: args.paths_per_step,
            batches: args.batches,
            seed: args.seed,
            threads: args.threads,
            fd_step: args.fd_step,
            product: Product::Independent,
        },
        tolerance: args.tolerance,
    };
    match geosens::scene::file::dimension(&args.scene)? {
        Some(3) => run(
            &geosens::mesh::file::load_study(&args.scene)?,
            &settings,
            args,
            out,
        ),
        _ => run(
            &geosens::flat::file::load_study(&args.scene)?,
            &settings,
            args,
            out,
        ),
    }
}

fn run<S: Model>(
    study: &Study<S>,
    settings: &Settings,
    args: &OptimizeArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = Arc::clone(&stop);
        // A second handler cannot be set (a test harness calling twice):
        // the run then simply cannot be interrupted early.
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    let names = study.parameter_names();
    let bar = progress_bar(
        u64::from(settings.iterations),
        "iterations",
        format!("{} {}", settings.method.name(), study.objective().name()),
    );
    if !args.json {
        writeln!(out, "{}", header(&names))?;
    }
    let mut failed = None;
    let records = optimize(study, settings, |r| {
        bar.set_position(u64::from(r.iteration));
        let line = if args.json {
            serde_json::to_string(r).map_err(|e| Error::Output(e.to_string()))
        } else {
            Ok(row(r, &names))
        };
        match line.and_then(|l| writeln!(out, "{l}").map_err(|e| Error::Output(e.to_string()))) {
            Ok(()) => {}
            Err(e) => {
                failed = Some(e);
                return false;
            }
        }
        !stop.load(Ordering::SeqCst)
    })?;
    bar.finish_and_clear();
    if let Some(e) = failed {
        return Err(e.into());
    }
    let listed = |values: &std::collections::BTreeMap<String, f64>| {
        values
            .iter()
            .map(|(k, v)| format!("{k} = {v:.6}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(last) = records.last() {
        if stop.load(Ordering::SeqCst) {
            eprintln!(
                "stopped by Ctrl-C after iteration {}: {} (tail average {})",
                last.iteration,
                listed(&last.parameters),
                listed(&last.average)
            );
        }
        if !args.json {
            write!(
                out,
                "{}",
                super::output::paragraph(&format!(
                    "mean of iterates {}..{}: {}",
                    last.iteration.div_ceil(2),
                    last.iteration,
                    listed(&last.average)
                ))
            )?;
        }
    }
    Ok(())
}

/// Width of the table's parameter column: the longest name.
fn name_width(names: &[String]) -> usize {
    names
        .iter()
        .map(|n| n.chars().count())
        .chain(["parameter".len()])
        .max()
        .unwrap_or(0)
}

/// The table's column titles. A row per parameter, not a column pair: a
/// scene of three parameters made lines of 169 characters.
fn header(names: &[String]) -> String {
    let w = name_width(names);
    format!(
        "{:>5} {:>22} {:>8} {:>7}  {:<w$} {:>10} {:>20}",
        "iter", "loss ± stderr", "paths", "seconds", "parameter", "value", "∂loss/∂π ± stderr"
    )
}

/// One iteration's rows: the loss, paths and time on the first, then one
/// row per parameter (its value and the gradient's component), and its
/// notes on lines of their own.
fn row(r: &Record, names: &[String]) -> String {
    let w = name_width(names);
    let mut s = String::new();
    for (k, n) in names.iter().enumerate() {
        let g = r.gradient[n];
        let lead = if k == 0 {
            format!(
                "{:>5} {:>22} {:>8} {:>7.3}",
                r.iteration,
                format!("{:.6e} ± {:.1e}", r.loss.mean, r.loss.stderr),
                r.paths,
                r.seconds
            )
        } else {
            " ".repeat(45)
        };
        if k > 0 {
            s.push('\n');
        }
        s += &format!(
            "{lead}  {n:<w$} {:>10.6} {:>20}",
            r.parameters[n],
            format!("{:.4e} ± {:.1e}", g.mean, g.stderr)
        );
    }
    for note in &r.notes {
        s.push('\n');
        s += super::output::paragraph(&format!("note: {note}")).trim_end();
    }
    s
}
