//! The `geosens` command line.
//!
//! - `geosens rod --method M --ks F --ke F --length F --x F --omega ±1 [--json]`
//!   estimates `I`, `s = ∂I/∂length` (and `∂I/∂x` for `transport`) at one
//!   probe on a rod with one method, or evaluates the exact solution
//!   (`--method exact`), and prints a table or one JSON line;
//! - `geosens flat --scene FILE --method M [--json]` does the same for every
//!   parameter of a flatland scene file (`--fd-step H` sets the half step of
//!   `--method fd`, on both subcommands);
//! - `geosens compare` runs the four Monte Carlo methods on the paper's thin
//!   and thick rods at a few probes and prints them beside the exact solution,
//!   then writes the rod's figures and flatland's (`flat_*`) (with the
//!   `figures` feature, on by default).
//!
//! Bad input exits with status 1 and `error: …` naming the value (clap's own
//! parse errors exit with status 2).
use clap::builder::PossibleValue;
use clap::{Args, Parser, Subcommand, ValueEnum};
use geosens::error::Num;
use geosens::rod::{Direction, Probe, Rod, exact};
use geosens::{Error, Estimate, Estimator, Method, Problem, Quantity, RunConfig, RunResult, run};
use serde::Serialize;
use std::io::{self, Write};
use std::process::ExitCode;
use std::time::Instant;

/// Most worker threads accepted by `--threads`: beyond it a pool would cost
/// more to start than the runs it serves (and rayon itself stops at 65535).
const MAX_THREADS: usize = 1024;

/// Monte Carlo estimates of intensity and geometric sensitivities.
#[derive(Debug, Parser)]
#[command(name = "geosens", version, about)]
struct Cli {
    /// What to run.
    #[command(subcommand)]
    command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
enum Command {
    /// Estimate I, ∂I/∂length (and ∂I/∂x) at one probe on a rod.
    Rod(RodArgs),
    /// Compare the four methods with the exact solution on the paper's rods,
    /// then write the rod's figures and flatland's.
    Compare(CompareArgs),
    /// Estimate I and ∂I/∂π for every parameter of a flatland scene file.
    Flat(FlatArgs),
}

/// `geosens flat`: a scene file, a method, a run.
#[derive(Debug, Args)]
struct FlatArgs {
    /// Scene file (TOML or JSON; see scenes/).
    #[arg(long)]
    scene: std::path::PathBuf,
    /// Estimation method.
    #[arg(long, value_enum)]
    method: Method,
    /// The finite differences' half step.
    #[command(flatten)]
    fd: FdArgs,
    /// The run configuration.
    #[command(flatten)]
    run: RunArgs,
    /// Print one JSON line instead of a table.
    #[arg(long)]
    json: bool,
}

/// `--fd-step`, shared by `rod` and `flat`.
#[derive(Debug, Args)]
struct FdArgs {
    /// Half step of `--method fd`: relative to the scene's size (the rod's
    /// length) for a translation, radians for a rotation, the relative
    /// change for a scale; in (0, 1) [default: 0.001].
    #[arg(long, allow_hyphen_values = true)]
    fd_step: Option<f64>,
}

impl FdArgs {
    /// `method`'s estimator on `problem`, with `--fd-step` for `fd`. An
    /// invalid displaced scene's error (`path`: its file, if any) gets a hint.
    fn estimator(
        &self,
        method: Method,
        problem: impl Problem,
        path: Option<&std::path::Path>,
    ) -> Result<Box<dyn Estimator>, Error> {
        if self.fd_step.is_some() && method != Method::Fd {
            return Err(Error::Config(format!(
                "--fd-step sets the half step of --method fd, not of {method}"
            )));
        }
        problem
            .estimator(method, self.fd_step)
            .map_err(|e| match e {
                Error::Scene(msg) if msg.contains("displaced by") => {
                    let file = path.map_or(String::new(), |p| format!("{}: ", p.display()));
                    Error::Scene(format!("{file}{msg}; try a smaller --fd-step"))
                }
                other => other,
            })
    }
}

/// How to estimate: the method, the rod, the probe and the run. Float values
/// may start with `-` (`--omega -1`, `--x -inf`) so that the library, not the
/// parser, rejects them with its domain in the message.
#[derive(Debug, Args)]
#[command(allow_negative_numbers = true)]
struct RodArgs {
    /// Estimation method (`exact` evaluates the Bellman–Wing solution).
    #[arg(long, value_enum)]
    method: RodMethod,
    /// Scattering coefficient κs (≥ 0).
    #[arg(long, allow_hyphen_values = true)]
    ks: f64,
    /// Extinction coefficient κe (≥ κs).
    #[arg(long, allow_hyphen_values = true)]
    ke: f64,
    /// Rod length π̃ (> 0), the shape parameter.
    #[arg(long, allow_hyphen_values = true)]
    length: f64,
    /// Probe position x, 0 ≤ x ≤ length.
    #[arg(long, allow_hyphen_values = true)]
    x: f64,
    /// Probe direction ω: 1 (right) or -1 (left).
    #[arg(long, allow_hyphen_values = true)]
    omega: f64,
    /// The finite differences' half step.
    #[command(flatten)]
    fd: FdArgs,
    /// The run configuration.
    #[command(flatten)]
    run: RunArgs,
    /// Print one JSON line instead of a table.
    #[arg(long)]
    json: bool,
}

/// `geosens compare`: the table's run, and where the figures go.
#[derive(Debug, Args)]
struct CompareArgs {
    /// The table's run configuration (the figures use the seed and threads).
    #[command(flatten)]
    run: RunArgs,
    /// Folder the figures (PNG, SVG and the JSON of their numbers) go to.
    #[arg(long, default_value = "out/figures")]
    figures: std::path::PathBuf,
    /// Multiplies the figures' path counts (1 = the book's figures).
    #[arg(long, default_value_t = 1.0)]
    effort: f64,
    /// Print the table only.
    #[arg(long)]
    no_figures: bool,
}

/// Run configuration, shared by both subcommands.
#[derive(Debug, Args)]
struct RunArgs {
    /// Number of paths per run, at least 2 [default: 1000000 for `rod`,
    /// 200000 for `compare`] (`exact` samples none but checks it too).
    // Hyphen values allowed so that `--paths -5` is named in the error
    // ("invalid value '-5' for '--paths'") instead of an unexpected `-5`.
    #[arg(long, allow_hyphen_values = true)]
    paths: Option<u64>,
    /// Seed of the random streams.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    seed: u64,
    /// Worker threads, 0 = all cores (results do not depend on it).
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    threads: usize,
}

impl RunArgs {
    /// The validated configuration, `default_paths` if `--paths` is absent,
    /// with `--threads` capped at [`MAX_THREADS`].
    fn config(&self, default_paths: u64) -> Result<RunConfig, Error> {
        if self.threads > MAX_THREADS {
            return Err(Error::Config(format!(
                "threads = {}: expected 0 (all cores) to {MAX_THREADS}",
                self.threads
            )));
        }
        let cfg = RunConfig::new(self.paths.unwrap_or(default_paths), self.seed)?;
        Ok(cfg.threads(self.threads))
    }
}

/// `--method` of `geosens rod`: a Monte Carlo [`Method`] or, listed first,
/// `exact`, the Bellman–Wing solution (`None`).
#[derive(Debug, Clone, Copy)]
struct RodMethod(Option<Method>);

impl ValueEnum for RodMethod {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [RodMethod; 1 + Method::ALL.len()] = {
            let mut all = [RodMethod(None); 1 + Method::ALL.len()];
            let mut i = 0;
            while i < Method::ALL.len() {
                all[i + 1] = RodMethod(Some(Method::ALL[i]));
                i += 1;
            }
            all
        };
        &ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        match self.0 {
            None => Some(PossibleValue::new("exact").help("Exact Bellman–Wing solution")),
            Some(m) => m.to_possible_value(),
        }
    }
}

/// The three quantities a rod run can report, in table and JSON order.
fn quantities() -> [Quantity; 3] {
    [
        Quantity::Intensity,
        Quantity::sensitivity(geosens::rod::PARAMETER),
        Quantity::gradient("x"),
    ]
}

/// Position of `q` in [`quantities`].
fn slot(q: &Quantity) -> usize {
    match q {
        Quantity::Intensity => 0,
        Quantity::Sensitivity(_) => 1,
        Quantity::Gradient(_) => 2,
    }
}

/// The exact values of [`quantities`] at a probe.
fn exact_values(rod: &Rod, probe: &Probe) -> [f64; 3] {
    let e = exact::solve(rod, probe.x, probe.omega);
    [e.intensity, e.sensitivity, e.gradient_x]
}

/// The exact solution as a [`RunResult`] (stderr 0, `paths` 0: nothing is
/// sampled; `seconds` is the time of the evaluation).
fn exact_result(rod: &Rod, probe: &Probe) -> RunResult {
    let start = Instant::now();
    let values = exact_values(rod, probe);
    let seconds = start.elapsed().as_secs_f64();
    RunResult {
        method: "exact",
        estimates: quantities()
            .into_iter()
            .zip(values.map(Estimate::exact))
            .collect(),
        paths: 0,
        seconds,
    }
}

/// Mean and standard error, as the JSON line prints them, with the count
/// of non-zero weights and whether the error bar can be trusted.
#[derive(Serialize)]
struct MeanErr {
    /// Estimated value.
    mean: f64,
    /// Its standard error (0 for `exact`).
    stderr: f64,
    /// Paths whose weight was not zero (0 for `exact`).
    nonzero: u64,
    /// Whether the error bar can be trusted ([`Estimate::is_reliable`] and
    /// no caveat).
    reliable: bool,
    /// Why the estimate may be far off whatever its error bar, if the
    /// estimator said so when it was built.
    #[serde(skip_serializing_if = "Option::is_none")]
    caveat: Option<String>,
}

impl MeanErr {
    /// The JSON form of `e`, with the caveat on its quantity if any.
    fn of(e: &Estimate, caveat: Option<&String>) -> MeanErr {
        MeanErr {
            mean: e.mean,
            stderr: e.stderr,
            nonzero: e.nonzero,
            reliable: e.is_reliable() && caveat.is_none(),
            caveat: caveat.cloned(),
        }
    }
}

/// The caveat the estimator raised on quantity `q`, if any.
fn caveat_of<'a>(caveats: &'a [(Quantity, String)], q: &Quantity) -> Option<&'a String> {
    caveats.iter().find(|(k, _)| k == q).map(|(_, why)| why)
}

/// `z` as the tables print it: `-` where the error bar is 0 and the
/// estimate is off (no finite z; `reliable` says why).
fn z_text(e: &Estimate, exact: f64) -> String {
    let z = e.z_score(exact);
    if z.is_finite() {
        format!("{z:.1}")
    } else {
        "-".to_owned()
    }
}

/// The one JSON line of `geosens rod --json`; `None` prints `null` for a
/// quantity the method does not estimate.
#[derive(Serialize)]
struct JsonLine<'a> {
    /// Method name.
    method: &'a str,
    /// `I`.
    intensity: Option<MeanErr>,
    /// `∂I/∂length`.
    sensitivity: Option<MeanErr>,
    /// `∂I/∂x`.
    gradient_x: Option<MeanErr>,
    /// Paths sampled (0 for `exact`).
    paths: u64,
    /// Wall time of the sampling (or evaluation), in seconds.
    seconds: f64,
}

/// Refuses a result with a non-finite estimate: serde_json would print a
/// NaN as `null`, indistinguishable from "not estimated".
fn all_finite(result: &RunResult) -> Result<(), String> {
    match result
        .estimates
        .iter()
        .find(|(_, e)| !(e.mean.is_finite() && e.stderr.is_finite()))
    {
        Some((q, e)) => Err(format!(
            "method {} gives {q} = {} ± {} at these inputs (floating-point overflow)",
            result.method,
            Num(e.mean),
            Num(e.stderr)
        )),
        None => Ok(()),
    }
}

/// `geosens rod`.
fn rod_command(args: &RodArgs, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let rod = Rod::new(args.ks, args.ke, args.length)?;
    let probe = Probe::new(&rod, args.x, Direction::from_sign(args.omega)?)?;
    let cfg = args.run.config(1_000_000)?;
    let result = match args.method.0 {
        Some(m) => run(args.fd.estimator(m, (rod, probe), None)?.as_ref(), &cfg)?,
        None if args.fd.fd_step.is_some() => {
            return Err(Error::Config(
                "--fd-step sets the half step of --method fd, not of exact".into(),
            )
            .into());
        }
        None => exact_result(&rod, &probe),
    };
    all_finite(&result)?;
    if args.json {
        let [i, s, g] = quantities().map(|q| result.get(&q).map(|e| MeanErr::of(&e, None)));
        let line = JsonLine {
            method: result.method,
            intensity: i,
            sensitivity: s,
            gradient_x: g,
            paths: result.paths,
            seconds: result.seconds,
        };
        writeln!(out, "{}", serde_json::to_string(&line)?)?;
        return Ok(());
    }
    writeln!(
        out,
        "rod κs = {:?}, κe = {:?}, length {:?}; probe x = {:?}, ω = {:+}",
        rod.ks,
        rod.ke,
        rod.length,
        probe.x,
        probe.omega.sign()
    )?;
    writeln!(
        out,
        "method {}: {} paths, seed {}, {:.3} s",
        result.method, result.paths, cfg.seed, result.seconds
    )?;
    writeln!(
        out,
        "{:<12} {:>14} {:>11} {:>9} {:>9} {:>9} {:>9} {:>8} {:>14} {:>6}",
        "quantity", "mean", "stderr", "n", "nonzero", "vov", "max_share", "reliable", "exact", "z"
    )?;
    let exact = exact_values(&rod, &probe);
    for (q, e) in &result.estimates {
        let ex = exact[slot(q)];
        let mc = e.n > 0;
        writeln!(
            out,
            "{:<12} {:>14.6e} {:>11.2e} {:>9} {:>9} {:>9} {:>9} {:>8} {:>14} {:>6}",
            q.to_string(),
            e.mean,
            e.stderr,
            e.n,
            dash(mc, || e.nonzero.to_string()),
            dash(mc, || format!("{:.1e}", e.vov)),
            dash(mc, || format!("{:.1e}", e.max_share)),
            dash(mc, || yes_no(e.is_reliable()).to_owned()),
            dash(mc, || format!("{ex:.6e}")),
            dash(mc, || z_text(e, ex)),
        )?;
    }
    Ok(())
}

/// `text()` if `show`, else `-`.
fn dash(show: bool, text: impl FnOnce() -> String) -> String {
    if show { text() } else { "-".to_owned() }
}

/// `yes` or `no`.
fn yes_no(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}

/// The paper's rods: name, κs, κe (length 2).
const RODS: [(&str, f64, f64); 2] = [("thin", 0.07, 0.1), ("thick", 2.1, 3.0)];
/// Probe positions of the comparison.
const XS: [f64; 4] = [0.0, 1.0, 1.9, 2.0];
/// Width of one quantity cell of the comparison table.
const CELL: usize = 32;

/// One comparison cell: `mean ± stderr z`, a `!` if the error bar is
/// unreliable, the bare value for an exact estimate (`n = 0`), `-` if absent.
fn cell(e: Option<Estimate>, exact: f64) -> String {
    match e {
        None => format!("{:>10}", "-"),
        Some(e) if e.n == 0 => format!("{:>10.6}", e.mean),
        Some(e) => format!(
            "{:>10.6} ± {:<7.1e} z {:>4}{}",
            e.mean,
            e.stderr,
            z_text(&e, exact),
            if e.is_reliable() { "" } else { "!" }
        ),
    }
}

/// One row of the comparison table: probe label, method, one cell per
/// quantity, reliability of the whole row, sampling time.
fn row(label: &str, r: &RunResult, exact: &[f64; 3]) -> String {
    let qs = quantities();
    let cells: Vec<String> = qs
        .iter()
        .zip(exact)
        .map(|(q, &x)| format!("{:<CELL$}", cell(r.get(q), x)))
        .collect();
    let reliable = r.estimates.iter().all(|(_, e)| e.is_reliable());
    format!(
        "{label:<10} {:<12} {} {:>8} {:>9.3}",
        r.method,
        cells.join(" "),
        if r.paths == 0 { "-" } else { yes_no(reliable) },
        r.seconds
    )
}

/// `geosens compare`.
fn compare_command(
    args: &CompareArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let effort = args.effort;
    if !(effort.is_finite() && effort > 0.0) {
        return Err(Error::InvalidParameter {
            name: "effort",
            value: effort,
            expected: "a finite number > 0",
        }
        .into());
    }
    let cfg = args.run.config(200_000)?;
    let start = Instant::now();
    // Per method: total sampling time, largest z-score, unreliable estimates.
    let mut totals = [(0.0, 0.0f64, 0usize); 4];
    for (name, ks, ke) in RODS {
        let rod = Rod::new(ks, ke, 2.0)?;
        writeln!(
            out,
            "\n{name} rod: κs = {ks}, κe = {ke}, length 2; {} paths per run, seed {}",
            cfg.paths, cfg.seed
        )?;
        writeln!(
            out,
            "{:<10} {:<12} {:<CELL$} {:<CELL$} {:<CELL$} {:>8} {:>9}",
            "x, ω", "method", "I", "∂I/∂length", "∂I/∂x", "reliable", "time [s]"
        )?;
        for x in XS {
            for omega in [Direction::Right, Direction::Left] {
                let probe = Probe::new(&rod, x, omega)?;
                let ex = exact_values(&rod, &probe);
                let label = format!("{x}, {:+}", omega.sign());
                writeln!(out, "{}", row(&label, &exact_result(&rod, &probe), &ex))?;
                for (m, total) in Method::UNBIASED.iter().zip(&mut totals) {
                    let r = run(m.estimator((rod, probe))?.as_ref(), &cfg)?;
                    writeln!(out, "{}", row("", &r, &ex))?;
                    total.0 += r.seconds;
                    for (q, e) in &r.estimates {
                        total.1 = total.1.max(e.z_score(ex[slot(q)]));
                        total.2 += usize::from(!e.is_reliable());
                    }
                }
            }
        }
    }
    writeln!(
        out,
        "\nper method over the 16 probes (z: distance to exact in stderrs; \
         !: error bar unreliable: VOV ≥ {}, fewer than {} non-zero weights, or not finite)",
        Estimate::VOV_LIMIT,
        Estimate::MIN_NONZERO
    )?;
    writeln!(
        out,
        "{:<12} {:>9} {:>7} {:>11}",
        "method", "time [s]", "max z", "unreliable"
    )?;
    for (m, (seconds, z, bad)) in Method::UNBIASED.iter().zip(totals) {
        writeln!(out, "{:<12} {seconds:>9.3} {z:>7.1} {bad:>11}", m.name())?;
    }
    writeln!(
        out,
        "total wall time {:.2} s",
        start.elapsed().as_secs_f64()
    )?;
    #[cfg(feature = "figures")]
    if !args.no_figures {
        use geosens::rod::figures::{self, FigureOptions};
        use std::io::IsTerminal;
        out.flush()?;
        let mut opts = FigureOptions::new(&args.figures);
        opts.seed = cfg.seed;
        opts.threads = cfg.threads;
        opts.effort = effort;
        opts.progress = io::stderr().is_terminal();
        let start = Instant::now();
        let mut written = figures::all(&opts)?;
        written.extend(geosens::flat::figures::all(&opts)?);
        writeln!(
            out,
            "\nwrote {} files to {} in {:.1} s",
            written.len(),
            args.figures.display(),
            start.elapsed().as_secs_f64()
        )?;
    }
    #[cfg(not(feature = "figures"))]
    if !args.no_figures {
        eprintln!(
            "note: no figures written to {}: this build lacks the `figures` \
             feature (on by default; build without --no-default-features)",
            args.figures.display()
        );
    }
    Ok(())
}

/// The one JSON line of `geosens flat --json`: the rod's shape, with one
/// sensitivity per parameter.
#[derive(Serialize)]
struct FlatJsonLine<'a> {
    /// Method name.
    method: &'a str,
    /// The sensor's reading.
    intensity: MeanErr,
    /// `∂I/∂π` keyed by parameter name (declaration order).
    sensitivity: serde_json::Map<String, serde_json::Value>,
    /// `∂I/∂x`, `∂I/∂y` at the sensor (`transport` only).
    gradient: Option<serde_json::Map<String, serde_json::Value>>,
    /// Paths sampled.
    paths: u64,
    /// Wall time of the sampling, in seconds.
    seconds: f64,
}

/// `geosens flat`.
fn flat_command(args: &FlatArgs, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    let scene = std::sync::Arc::new(geosens::flat::file::load(&args.scene)?);
    let cfg = args.run.config(1_000_000)?;
    let estimator = args
        .fd
        .estimator(args.method, scene.clone(), Some(&args.scene))?;
    let result = run(estimator.as_ref(), &cfg)?;
    all_finite(&result)?;
    let caveats = estimator.caveats();
    for (q, why) in &caveats {
        eprintln!("warning: {q}: {why}");
    }
    if args.json {
        let value = |q: &Quantity, e: &Estimate| {
            serde_json::to_value(MeanErr::of(e, caveat_of(&caveats, q)))
        };
        let mut intensity = None;
        let mut sensitivity = serde_json::Map::new();
        let mut gradient = serde_json::Map::new();
        for (q, e) in &result.estimates {
            match q {
                Quantity::Intensity => intensity = Some(MeanErr::of(e, caveat_of(&caveats, q))),
                Quantity::Sensitivity(p) => {
                    sensitivity.insert(p.clone(), value(q, e)?);
                }
                Quantity::Gradient(a) => {
                    gradient.insert(a.clone(), value(q, e)?);
                }
            }
        }
        let line = FlatJsonLine {
            method: result.method,
            intensity: intensity.ok_or("no intensity estimate")?,
            sensitivity,
            gradient: (!gradient.is_empty()).then_some(gradient),
            paths: result.paths,
            seconds: result.seconds,
        };
        writeln!(out, "{}", serde_json::to_string(&line)?)?;
        return Ok(());
    }
    writeln!(
        out,
        "scene {}: {} shapes, {} parameters",
        args.scene.display(),
        scene.shapes().len(),
        scene.parameters().len()
    )?;
    writeln!(
        out,
        "method {}: {} paths, seed {}, {:.3} s",
        result.method, result.paths, cfg.seed, result.seconds
    )?;
    writeln!(
        out,
        "{:<20} {:>14} {:>11} {:>9} {:>9} {:>9} {:>8}",
        "quantity", "mean", "stderr", "nonzero", "vov", "max_share", "reliable"
    )?;
    for (q, e) in &result.estimates {
        let caveat = caveat_of(&caveats, q);
        writeln!(
            out,
            "{:<20} {:>14.6e} {:>11.2e} {:>9} {:>9.1e} {:>9.1e} {:>8}",
            q.to_string(),
            e.mean,
            e.stderr,
            e.nonzero,
            e.vov,
            e.max_share,
            match (e.is_reliable(), caveat) {
                (true, None) => "yes",
                (_, Some(_)) => "caveat",
                (false, None) => "no",
            }
        )?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let mut out = io::stdout().lock();
    let result = match &cli.command {
        Command::Rod(args) => rod_command(args, &mut out),
        Command::Compare(args) => compare_command(args, &mut out),
        Command::Flat(args) => flat_command(args, &mut out),
    };
    match result.and_then(|()| Ok(out.flush()?)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
