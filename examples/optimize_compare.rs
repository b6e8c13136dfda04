//! The methods compared by what an optimisation costs to reach the answer
//! (book: "Sensitivities at work", "Comparing methods by time to the
//! answer").
//!
//! ```text
//! cargo run --release --example optimize_compare -- [OUT_DIR] [EFFORT] [SEEDS]
//! ```
//! runs every worked problem of `geosens::optimize::compare::PROBLEMS` with
//! every method (expectation, rendering, transport, fd, and fd with a half
//! step of 0.2: a biased gradient) from `SEEDS` seeds (default 10: seeds 1
//! to 10), Adam with step 0.02, each problem's budget of iterations and
//! paths per measurement (the paths multiplied by `EFFORT`, default 1).
//! Per run it records the wall time and the paths until the tail average's
//! parameter error (translations over the scene's size, rotations in
//! radians; the largest over the parameters) falls under 10⁻³ and stays
//! under it to the end of the run, and the final error. It prints the
//! table, writes it to `book/src/optimisation_results.md` (markdown) and
//! to `OUT_DIR` (default `out/figures`) as `optimise_compare.{json,csv}`,
//! and draws, from seed 1, `optimise_loss.png` (the loss against wall
//! time), `optimise_error.png` (the parameter error against wall time) and
//! `optimise_trajectories.png` (the iterates over the exact loss's
//! contours, for two-parameter problems with a closed form).
use geosens::Error;
use geosens::flat::figures::{FigureOptions, REFERENCE_COLOR, color};
use geosens::optimize::compare::{
    self, BIASED_FD, Loaded, PROBLEMS, Row, Run, TOLERANCE, Variant, variants,
};
use geosens::plot::{Figure, HeatMap, Legend, Panel, Series};
use std::time::Instant;

/// Palette index of a variant: the method's, the biased fd's its own.
fn variant_color(v: &Variant) -> usize {
    if *v == BIASED_FD { 0 } else { color(v.method) }
}

/// One problem's runs, by variant.
struct Done {
    file: String,
    loaded: Loaded,
    answer: Vec<f64>,
    runs: Vec<Vec<Run>>,
}

fn main() -> Result<(), Error> {
    let start = Instant::now();
    let opts = FigureOptions::from_args()?;
    let seeds: u64 = match std::env::args().nth(3) {
        Some(s) => s
            .parse()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| Error::Output(format!("bad seed count {s:?}")))?,
        None => 10,
    };
    // The worked problems with every method and seed, then the biased
    // gradient's demonstration: the flatland problem with noisy targets.
    let mut plans = Vec::new();
    for p in PROBLEMS {
        let loaded = Loaded::load(&compare::resolve(p.file))?;
        let budget = compare::Budget {
            paths: opts.paths(p.budget.paths),
            ..p.budget
        };
        let answer = match p.truth {
            Some(t) => t.to_vec(),
            None => compare::scan(&loaded, 4 * budget.paths)?,
        };
        plans.push((p.file.to_owned(), loaded, answer, budget, variants(), seeds));
    }
    {
        let p = PROBLEMS[0];
        let text = std::fs::read_to_string(compare::resolve(p.file))
            .map_err(|e| Error::Output(format!("cannot read {}: {e}", p.file)))?;
        let loaded = Loaded::flat_toml(&noisy(&text))?;
        // The minimum of the exact loss: the truth no longer fits exactly.
        let answer = compare::scan(&loaded, 0)?;
        let budget = compare::Budget {
            paths: opts.paths(p.budget.paths),
            ..p.budget
        };
        plans.push((
            NOISY.to_owned(),
            loaded,
            answer,
            budget,
            vec![Variant::of(geosens::Method::Transport), BIASED_FD],
            seeds.min(5),
        ));
    }
    let total: u64 = plans
        .iter()
        .map(|(_, _, _, b, v, n)| u64::from(b.iterations + 1) * n * v.len() as u64)
        .sum();
    let bar = opts.bar(total, "optimisations");
    let mut done = Vec::new();
    for (file, loaded, answer, budget, variants, seeds) in plans {
        let mut runs = Vec::new();
        for v in &variants {
            bar.set_message(format!("{} {}", compare::problem_name(&file), v.label()));
            let mut these = Vec::new();
            for seed in 1..=seeds {
                these.push(compare::run_one(
                    &loaded,
                    &answer,
                    *v,
                    seed,
                    budget,
                    opts.threads,
                    || bar.inc(1),
                )?);
            }
            runs.push(these);
        }
        done.push(Done {
            file,
            loaded,
            answer,
            runs,
        });
    }
    bar.finish_and_clear();
    let rows: Vec<Row> = done
        .iter()
        .flat_map(|d| d.runs.iter().map(|r| compare::row(&d.file, r)))
        .collect();
    let seconds = start.elapsed().as_secs_f64();
    let budgets: Vec<String> = PROBLEMS
        .iter()
        .map(|p| {
            format!(
                "{}: {} iterations of {} paths per measurement",
                compare::problem_name(p.file),
                p.budget.iterations,
                opts.paths(p.budget.paths)
            )
        })
        .collect();
    let notes = format!(
        "Adam, first step {}, {} batches; seeds 1 to {seeds}; {}. The error is \
         the tail average's, the largest over the parameters of |θ̄ − θ*| (a \
         translation's over the scene's size, a rotation's in radians); \"to \
         tol.\" is the time (paths) until it falls under {TOLERANCE:e} and \
         stays under it to the end of the run, medians over the runs that \
         reach it (\"reached\": how many do). \"run\" is a whole run's median \
         wall time. fd (step 0.2) is a finite difference with half step 0.2 \
         (of the size, or rad): a biased gradient. \"{NOISY}\" is the same \
         problem with its targets moved by ±0.01 in turn (measurement noise), \
         seeds 1 to {}: its answer is the exact loss's minimum (a scan of \
         the closed form), where residuals remain. Measured on {} threads; \
         the whole comparison took {seconds:.0} s.",
        compare::STEP,
        compare::BATCHES,
        budgets.join("; "),
        seeds.min(5),
        if opts.threads == 0 {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        } else {
            opts.threads
        },
    );
    println!("{}\n\n{notes}", compare::text_table(&rows));
    let book = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("book")
        .join("src")
        .join("optimisation_results.md");
    let md = format!(
        "*Generated by `cargo run --release --example optimize_compare -- book/src/figures 1` \
         (examples/optimize_compare.rs); do not edit.*\n\n{}\n{notes}\n",
        compare::markdown_table(&rows)
    );
    std::fs::write(&book, md)
        .map_err(|e| Error::Output(format!("cannot write {}: {e}", book.display())))?;
    println!("wrote {}", book.display());
    let runs: Vec<&Run> = done.iter().flat_map(|d| d.runs.iter().flatten()).collect();
    let json = serde_json::json!({ "notes": notes, "rows": rows, "runs": runs });
    let mut written = vec![opts.write_json("optimise_compare", &json)?];
    let csv = opts.out.join("optimise_compare.csv");
    std::fs::write(&csv, compare::csv(&rows))
        .map_err(|e| Error::Output(format!("cannot write {}: {e}", csv.display())))?;
    written.push(csv);
    written.extend(figures(&opts, &done)?);
    for path in written {
        println!("wrote {}", path.display());
    }
    println!("total {:.1} s", start.elapsed().as_secs_f64());
    Ok(())
}

/// The name of the biased gradient's demonstration in the table.
const NOISY: &str = "inverse_occluder, noisy targets";

/// The scene file `text` with its targets moved by ±0.01 in turn
/// (measurement noise): the loss's minimum keeps residuals, which weigh a
/// biased derivative's error, so a biased gradient stops elsewhere.
fn noisy(text: &str) -> String {
    let mut sign = 1.0;
    text.lines()
        .map(|line| match line.strip_prefix("target = ") {
            Some(v) => {
                let t: f64 = v.trim().parse().unwrap_or(0.0) + sign * 0.01;
                sign = -sign;
                format!("target = {t}\n")
            }
            None => format!("{line}\n"),
        })
        .collect()
}

/// Seed 1's run of every variant of `d`.
fn first_runs(d: &Done) -> impl Iterator<Item = &Run> {
    d.runs.iter().filter_map(|r| r.first())
}

/// The loss, error and trajectory figures.
fn figures(opts: &FigureOptions, done: &[Done]) -> Result<Vec<std::path::PathBuf>, Error> {
    let mut written = Vec::new();
    // (a) The loss (exact where a closed form exists) and the error
    // against wall time, seed 1.
    let mut loss_panels = Vec::new();
    let mut error_panels = Vec::new();
    for d in done {
        let name = compare::problem_name(&d.file);
        let exact = d.loaded.exact_loss(&d.answer).is_some();
        let mut loss = Panel {
            title: format!(
                "{name}: {} loss, seed 1",
                if exact { "exact" } else { "estimated" }
            ),
            x_label: "wall time [s]".into(),
            y_label: "loss".into(),
            x_log: true,
            y_log: true,
            legend: Legend::UpperRight,
            ..Panel::default()
        };
        let mut error = Panel {
            title: format!("{name}: error of the average, seed 1"),
            x_label: "wall time [s]".into(),
            y_label: "largest scaled parameter error".into(),
            x_log: true,
            y_log: true,
            legend: Legend::LowerLeft,
            ..Panel::default()
        };
        let mut t_max: f64 = 0.0;
        for r in first_runs(d) {
            let c = variant_color(&r.variant);
            let xy = |f: &dyn Fn(&compare::Point) -> f64| {
                r.trace
                    .iter()
                    .map(|p| (p.seconds, f(p)))
                    .filter(|&(_, y)| y > 0.0)
                    .collect::<Vec<_>>()
            };
            let loss_of = |p: &compare::Point| d.loaded.exact_loss(&p.parameters).unwrap_or(p.loss);
            loss.series
                .push(Series::line(&r.variant.label(), c, xy(&loss_of)));
            error
                .series
                .push(Series::line(&r.variant.label(), c, xy(&|p| p.error)));
            t_max = t_max.max(r.seconds);
        }
        let t_min = first_runs(d)
            .filter_map(|r| r.trace.first().map(|p| p.seconds))
            .fold(f64::INFINITY, f64::min);
        error.series.push(Series::dashed(
            "tolerance",
            REFERENCE_COLOR,
            vec![(t_min, TOLERANCE), (t_max, TOLERANCE)],
        ));
        loss_panels.push(loss);
        error_panels.push(error);
    }
    let columns = done.len().clamp(1, 2);
    let numbers: Vec<serde_json::Value> = done
        .iter()
        .map(|d| {
            serde_json::json!({
                "problem": d.file,
                "answer": d.answer,
                "runs": first_runs(d).map(|r| serde_json::json!({
                    "method": r.variant.label(),
                    "trace": r.trace,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    written.extend(Figure::new(loss_panels, columns).save(&opts.out, "optimise_loss")?);
    written.extend(Figure::new(error_panels, columns).save(&opts.out, "optimise_error")?);
    written.push(opts.write_json("optimise_seed1", &numbers)?);
    // (b) The iterates over the exact loss, two-parameter problems.
    let mut panels = Vec::new();
    for d in done {
        if d.answer.len() != 2 || d.loaded.exact_loss(&d.answer).is_none() {
            continue;
        }
        panels.push(trajectories(d));
    }
    if !panels.is_empty() {
        let columns = panels.len().min(2);
        written.extend(Figure::new(panels, columns).save(&opts.out, "optimise_trajectories")?);
    }
    Ok(written)
}

/// Grid cells a side of the contour plot.
const GRID: usize = 120;

/// The iterates of seed 1's runs over the exact loss's `log10` (a heat map
/// with contour lines every half decade), the start and the answer marked.
fn trajectories(d: &Done) -> Panel {
    let names = d.loaded.names();
    // The box: the iterates' and the answer's, padded.
    let (mut lo, mut hi) = ([0.0f64; 2], [0.0f64; 2]);
    for k in 0..2 {
        let all = first_runs(d)
            .flat_map(|r| r.trace.iter().map(move |p| p.parameters[k]))
            .chain([d.answer[k], 0.0]);
        let (a, b) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        let pad = 0.08 * (b - a).max(1e-3);
        let bounds = d.loaded.bounds()[k];
        (lo[k], hi[k]) = ((a - pad).max(bounds[0]), (b + pad).min(bounds[1]));
    }
    let edges = |k: usize| -> Vec<f64> {
        (0..=GRID)
            .map(|i| lo[k] + (hi[k] - lo[k]) * i as f64 / GRID as f64)
            .collect()
    };
    let (xe, ye) = (edges(0), edges(1));
    let centre = |e: &[f64], i: usize| 0.5 * (e[i] + e[i + 1]);
    let mut values = vec![f64::NAN; GRID * GRID];
    for iy in 0..GRID {
        for ix in 0..GRID {
            let x = [centre(&xe, ix), centre(&ye, iy)];
            if let Some(l) = d.loaded.exact_loss(&x) {
                values[iy * GRID + ix] = l.max(1e-12).log10();
            }
        }
    }
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let (vmin, vmax) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let mut series = Vec::new();
    // Contours every half decade, by marching squares over cell centres.
    let mut level = (2.0 * vmin).ceil() / 2.0;
    while level < vmax {
        for seg in contour(&values, &xe, &ye, level) {
            series.push(Series::thin("", REFERENCE_COLOR, seg));
        }
        level += 0.5;
    }
    for r in first_runs(d) {
        let xy = r
            .trace
            .iter()
            .map(|p| (p.parameters[0], p.parameters[1]))
            .collect();
        series.push(Series::line(
            &r.variant.label(),
            variant_color(&r.variant),
            xy,
        ));
    }
    series.push(Series::circles(
        "answer",
        REFERENCE_COLOR,
        vec![(d.answer[0], d.answer[1])],
    ));
    series.push(Series::points(
        "start",
        REFERENCE_COLOR,
        vec![(0.0, 0.0, 0.0)],
    ));
    Panel {
        title: format!(
            "{}: iterates, seed 1; log10 exact loss",
            compare::problem_name(&d.file)
        ),
        x_label: names[0].clone(),
        y_label: names[1].clone(),
        series,
        heat: Some(HeatMap {
            x_edges: xe,
            y_edges: ye,
            values,
            // Low loss white, high red (the lower half of the scale is
            // left unused, so that the lines stay visible).
            range: (2.0 * vmin - vmax, vmax),
        }),
        legend: Legend::Above,
        ..Panel::default()
    }
}

/// The segments of the `level` contour of `values` (cell centres of the
/// grid with edges `xe`, `ye`), by marching squares.
fn contour(values: &[f64], xe: &[f64], ye: &[f64], level: f64) -> Vec<Vec<(f64, f64)>> {
    let n = xe.len() - 1;
    let c = |e: &[f64], i: usize| 0.5 * (e[i] + e[i + 1]);
    let v = |ix: usize, iy: usize| values[iy * n + ix];
    let mut out = Vec::new();
    for iy in 0..n - 1 {
        for ix in 0..n - 1 {
            let corners = [
                (c(xe, ix), c(ye, iy), v(ix, iy)),
                (c(xe, ix + 1), c(ye, iy), v(ix + 1, iy)),
                (c(xe, ix + 1), c(ye, iy + 1), v(ix + 1, iy + 1)),
                (c(xe, ix), c(ye, iy + 1), v(ix, iy + 1)),
            ];
            if corners.iter().any(|p| !p.2.is_finite()) {
                continue;
            }
            // Crossings of the level along the square's four sides.
            let mut cross = Vec::new();
            for k in 0..4 {
                let (a, b) = (corners[k], corners[(k + 1) % 4]);
                if (a.2 < level) != (b.2 < level) {
                    let t = (level - a.2) / (b.2 - a.2);
                    cross.push((a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1)));
                }
            }
            // Two crossings: one segment; four (a saddle): two.
            for pair in cross.chunks_exact(2) {
                out.push(vec![pair[0], pair[1]]);
            }
        }
    }
    out
}
