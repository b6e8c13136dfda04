//! What the 3D inverse-problem examples share: run the optimiser on a
//! shipped problem by several methods and print a table of the outcome.
use geosens::Method;
use geosens::mesh::file::load_study;
use geosens::mesh::inverse::Problem;
use geosens::optimize::{Optimizer, Product, Record, Sampling, Settings, optimize};
use std::path::Path;

/// Settings from the command line: `--iterations N`, `--paths N` (per
/// measurement, a camera's per pixel), `--step F`, `--seed N`,
/// `--methods a,b`, with the problem's defaults.
pub struct Args {
    pub iterations: u32,
    pub paths: u64,
    pub step: f64,
    pub seed: u64,
    pub methods: Vec<Method>,
}

impl Args {
    pub fn parse(iterations: u32, paths: u64, step: f64, methods: &[Method]) -> Args {
        let mut a = Args {
            iterations,
            paths,
            step,
            seed: 1,
            methods: methods.to_vec(),
        };
        let argv: Vec<String> = std::env::args().skip(1).collect();
        for w in argv.chunks(2) {
            let v = w.get(1).map(String::as_str).unwrap_or("");
            match w[0].as_str() {
                "--iterations" => a.iterations = v.parse().expect("--iterations N"),
                "--paths" => a.paths = v.parse().expect("--paths N"),
                "--step" => a.step = v.parse().expect("--step F"),
                "--seed" => a.seed = v.parse().expect("--seed N"),
                "--methods" => {
                    a.methods = v
                        .split(',')
                        .map(|m| clap::ValueEnum::from_str(m, true).expect("a method"))
                        .collect()
                }
                other => panic!("unknown argument {other}"),
            }
        }
        a
    }
}

/// The mean of the parameters over the last quarter of the iterations.
pub fn averaged(records: &[Record]) -> Vec<f64> {
    let tail = &records[records.len() - (records.len() / 4).max(1)..];
    let n = tail.len() as f64;
    let names: Vec<&String> = records[0].parameters.keys().collect();
    names
        .iter()
        .map(|k| tail.iter().map(|r| r.parameters[*k]).sum::<f64>() / n)
        .collect()
}

/// The median over the iterations of (wall − sampling) / sampling.
pub fn overhead(records: &[Record]) -> f64 {
    let mut o: Vec<f64> = records
        .iter()
        .map(|r| (r.seconds - r.sampling_seconds) / r.sampling_seconds)
        .collect();
    o.sort_by(f64::total_cmp);
    o[o.len() / 2]
}

/// Runs `problem` by each method and prints the table.
pub fn solve(problem: Problem, args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let path = problem.path(Path::new(env!("CARGO_MANIFEST_DIR")));
    let study = load_study(&path)?;
    let names = study.parameter_names();
    // The records key parameters by name (sorted); the truth is in file order.
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by_key(|&j| names[j].clone());
    let truth: Vec<f64> = order.iter().map(|&j| problem.truth[j]).collect();
    let sorted: Vec<&String> = order.iter().map(|&j| &names[j]).collect();
    println!(
        "{}: {} iterations, {} paths per measurement{} and step, Adam from {}, seed {}",
        problem.file,
        args.iterations,
        args.paths,
        if study.measurements().len() == 1 {
            " (pixel)"
        } else {
            ""
        },
        args.step,
        args.seed
    );
    let head: Vec<String> = sorted.iter().map(|n| format!("{n:>10}")).collect();
    println!(
        "{:<12} {:>5} {}  {:>10} {:>10} {:>8} {:>9}",
        "method",
        "iters",
        head.join(" "),
        "max |err|",
        "avg |err|",
        "wall s",
        "overhead"
    );
    let t: Vec<String> = truth.iter().map(|v| format!("{v:>10.5}")).collect();
    println!("{:<12} {:>5} {}", "truth", "", t.join(" "));
    for &method in &args.methods {
        let settings = Settings {
            method,
            optimizer: Optimizer::Adam,
            iterations: args.iterations,
            step: args.step,
            sampling: Sampling {
                paths: args.paths,
                batches: 8,
                seed: args.seed,
                threads: 0,
                fd_step: None,
                product: Product::Independent,
            },
            tolerance: 0.0,
        };
        let start = std::time::Instant::now();
        let records = optimize(&study, &settings, |_| true)?;
        let wall = start.elapsed().as_secs_f64();
        let last = records.last().expect("a record");
        let fin: Vec<f64> = last.parameters.values().copied().collect();
        let avg = averaged(&records);
        let err = |p: &[f64]| {
            p.iter()
                .zip(&truth)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        };
        let v: Vec<String> = fin.iter().map(|v| format!("{v:>10.5}")).collect();
        println!(
            "{:<12} {:>5} {}  {:>10.2e} {:>10.2e} {:>8.1} {:>8.2}%",
            method.to_string(),
            last.iteration,
            v.join(" "),
            err(&fin),
            err(&avg),
            wall,
            100.0 * overhead(&records)
        );
    }
    println!(
        "max |err|: the last iterate's largest error (scene units, radians); avg |err|: that of \
         the mean of the last quarter's iterates; overhead: median over iterations of \
         (wall - sampling) / sampling"
    );
    Ok(())
}
