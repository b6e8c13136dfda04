//! Wall-clock cost of each rod method, the paper's Table 1 redone (printed
//! beside the paper's times and ratios): the time
//! of `run(...)` on one thread for N = 10⁶ paths at x = 1, thin and thick
//! rods, both directions, as ratios to the intensity method and to a
//! hand-written Algorithm 3 loop (`benches/support/baseline.rs`).
//!
//! ```text
//! cargo run --release --example perf_table                 # 7 rounds
//! cargo run --release --example perf_table -- 15           # 15 rounds
//! cargo run --release --example perf_table -- 5 --speedup  # + 2 threads vs 1
//! cargo run --release --example perf_table -- --one thick -1 expectation
//! ```
//!
//! Each round runs the baseline and every method once, in turn, so a drift
//! of the machine's speed hits them alike; the table gives the median time
//! and the median over rounds of each round's ratio. `--speedup` adds, for
//! N = 10⁷ on the thick rod (ω = −1), the time on one thread over the time
//! on two. `--one ROD OMEGA METHOD [PATHS [THREADS]]` runs one method once
//! (`baseline` is a method here) and prints its estimates, for timing whole
//! processes with an external tool (`/usr/bin/time -v`, `hyperfine`).
//!
//! The estimates are deterministic (fixed seed; every round is checked to
//! give the same bits, every thread count too); the times are not: quote
//! medians and ratios, measured on an otherwise idle machine.
//! `cargo bench --bench rod` measures the same with criterion (N = 10⁵).
use geosens::rod::{Direction, Method, Probe, Rod};
use geosens::{Error, RunConfig, RunResult, run};
use std::time::Instant;

#[path = "../benches/support/baseline.rs"]
mod baseline;

const SEED: u64 = 1;
const X: f64 = 1.0;
const LENGTH: f64 = 2.0;
const RODS: [(&str, f64, f64); 2] = [("thin", 0.07, 0.1), ("thick", 2.1, 3.0)];

/// The paper's Table 1 (He et al. 2024), N = 10⁶, ms: intensity (Alg. 3),
/// rendering (Alg. 5), expectation (Alg. 4), by rod name.
fn paper_ms(rod: &str, row: Row) -> Option<f64> {
    let (intensity, rendering, expectation) = match rod {
        "thin" => (72.0, 126.0, 136.0),
        _ => (142.0, 287.0, 297.0),
    };
    match row {
        Row::Method(Method::Intensity) => Some(intensity),
        Row::Method(Method::Rendering) => Some(rendering),
        Row::Method(Method::Expectation) => Some(expectation),
        _ => None,
    }
}

/// What one row of the table runs.
#[derive(Clone, Copy)]
enum Row {
    Baseline,
    Method(Method),
}

impl Row {
    const ALL: [Row; 5] = [
        Row::Baseline,
        Row::Method(Method::Intensity),
        Row::Method(Method::Expectation),
        Row::Method(Method::Rendering),
        Row::Method(Method::Transport),
    ];

    fn name(self) -> &'static str {
        match self {
            Row::Baseline => "baseline",
            Row::Method(m) => m.name(),
        }
    }

    /// Runs the row once; returns its estimates as text.
    fn run(self, rod: &Rod, omega: Direction, paths: u64, threads: usize) -> Result<String, Error> {
        match self {
            Row::Baseline => {
                let (sum, sum2) =
                    baseline::algorithm3(rod.ks, rod.ke, rod.length, X, omega.sign(), paths, SEED);
                let n = paths as f64;
                let mean = sum / n;
                let stderr = ((sum2 / n - mean * mean) / (n - 1.0)).sqrt();
                Ok(format!("I = {mean:.5} ± {stderr:.5}"))
            }
            Row::Method(m) => {
                let probe = Probe::new(rod, X, omega)?;
                let cfg = RunConfig::new(paths, SEED)?.threads(threads);
                Ok(describe(&run(m.estimator((*rod, probe))?.as_ref(), &cfg)?))
            }
        }
    }
}

/// The estimates of a run, without its timing.
fn describe(r: &RunResult) -> String {
    let cells: Vec<String> = r
        .estimates
        .iter()
        .map(|(q, e)| format!("{q} = {:.5} ± {:.5}", e.mean, e.stderr))
        .collect();
    cells.join(", ")
}

/// Wall time of `f`, and what it returned.
fn timed<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let t = Instant::now();
    let out = f();
    (t.elapsed().as_secs_f64(), out)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn parse_rod(name: &str) -> Result<Rod, Error> {
    let (_, ks, ke) = RODS
        .into_iter()
        .find(|(n, _, _)| *n == name)
        .ok_or_else(|| Error::Config(format!("unknown rod {name:?}: thin or thick")))?;
    Rod::new(ks, ke, LENGTH)
}

fn parse_row(name: &str) -> Result<Row, Error> {
    Row::ALL
        .into_iter()
        .find(|r| r.name() == name)
        .ok_or_else(|| Error::Config(format!("unknown method {name:?}")))
}

fn parse_num<T: std::str::FromStr>(arg: Option<&String>, default: T) -> Result<T, Error> {
    arg.map_or(Ok(default), |a| {
        a.parse()
            .map_err(|_| Error::Config(format!("not a number: {a:?}")))
    })
}

/// `--one ROD OMEGA METHOD [PATHS [THREADS]]`.
fn one(args: &[String]) -> Result<(), Error> {
    let [rod, omega, row, rest @ ..] = args else {
        return Err(Error::Config(
            "usage: --one ROD OMEGA METHOD [PATHS [THREADS]]".into(),
        ));
    };
    let rod = parse_rod(rod)?;
    let omega = Direction::from_sign(parse_num(Some(omega), 0.0)?)?;
    let row = parse_row(row)?;
    let paths = parse_num(rest.first(), 1_000_000)?;
    let threads = parse_num(rest.get(1), 1)?;
    println!("{}: {}", row.name(), row.run(&rod, omega, paths, threads)?);
    Ok(())
}

fn table(rounds: usize) -> Result<(), Error> {
    let n = 1_000_000;
    println!("N = {n} paths, x = {X}, 1 thread, seed {SEED}, {rounds} rounds");
    let bar = progress((RODS.len() * 2 * rounds) as u64, "Table 1 rounds");
    for (name, ks, ke) in RODS {
        let rod = Rod::new(ks, ke, LENGTH)?;
        for omega in [Direction::Left, Direction::Right] {
            println!(
                "\n{name} rod (κs = {ks}, κe = {ke}), ω = {:+}",
                omega.sign()
            );
            println!(
                "  {:<12} {:>9} {:>9} {:>8} {:>8} {:>15}   estimates",
                "method", "ms", "Mpaths/s", "/intens", "/base", "paper ms (/int)"
            );
            // times[round][row]
            let mut times = Vec::with_capacity(rounds);
            let mut estimates: Vec<String> = Vec::new();
            for round in 0..rounds {
                bar.inc(1);
                let mut t = Vec::with_capacity(Row::ALL.len());
                for (k, row) in Row::ALL.into_iter().enumerate() {
                    let (s, e) = timed(|| row.run(&rod, omega, n, 1));
                    let e = e?;
                    if round == 0 {
                        estimates.push(e);
                    } else {
                        assert_eq!(estimates[k], e, "a round changed the estimates");
                    }
                    t.push(s);
                }
                times.push(t);
            }
            for (k, row) in Row::ALL.into_iter().enumerate() {
                let t = median(times.iter().map(|t| t[k]).collect());
                let per_intensity = median(times.iter().map(|t| t[k] / t[1]).collect());
                let per_baseline = median(times.iter().map(|t| t[k] / t[0]).collect());
                let paper = match paper_ms(name, row) {
                    Some(ms) => {
                        let base = paper_ms(name, Row::Method(Method::Intensity)).unwrap_or(ms);
                        format!("{ms:.0} ({:.2})", ms / base)
                    }
                    None => "-".into(),
                };
                println!(
                    "  {:<12} {:>9.1} {:>9.2} {:>8.2} {:>8.2} {:>15}   {}",
                    row.name(),
                    t * 1e3,
                    n as f64 / t / 1e6,
                    per_intensity,
                    per_baseline,
                    paper,
                    estimates[k]
                );
            }
        }
    }
    Ok(())
}

/// A progress bar on standard error (indicatif hides it off a terminal),
/// cleared before the table it belongs to is printed.
fn progress(len: u64, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len).with_message(what.to_owned());
    if let Ok(style) = indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

fn speedup(rounds: usize) -> Result<(), Error> {
    let n = 10_000_000;
    let rod = parse_rod("thick")?;
    let omega = Direction::Left;
    println!("\nthick rod, ω = -1, N = {n}: one thread against two, {rounds} rounds");
    println!(
        "  {:<12} {:>9} {:>9} {:>8}",
        "method", "1 thr ms", "2 thr ms", "speed-up"
    );
    for method in Method::UNBIASED {
        let row = Row::Method(method);
        let mut pairs = Vec::with_capacity(rounds);
        let mut first: Option<String> = None;
        for _ in 0..rounds {
            let (t1, e1) = timed(|| row.run(&rod, omega, n, 1));
            let (t2, e2) = timed(|| row.run(&rod, omega, n, 2));
            let (e1, e2) = (e1?, e2?);
            assert_eq!(e1, e2, "the thread count changed the estimates");
            assert_eq!(first.get_or_insert(e1.clone()), &e1);
            pairs.push((t1, t2));
        }
        println!(
            "  {:<12} {:>9.1} {:>9.1} {:>8.2}",
            method.name(),
            median(pairs.iter().map(|p| p.0).collect()) * 1e3,
            median(pairs.iter().map(|p| p.1).collect()) * 1e3,
            median(pairs.iter().map(|p| p.0 / p.1).collect())
        );
    }
    Ok(())
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(i) = args.iter().position(|a| a == "--one") {
        return one(&args[i + 1..]);
    }
    let rounds: usize = args.iter().find_map(|a| a.parse().ok()).unwrap_or(7).max(1);
    table(rounds)?;
    if args.iter().any(|a| a == "--speedup") {
        speedup(rounds)?;
    }
    Ok(())
}
