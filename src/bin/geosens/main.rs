//! The `geosens` command line.
//!
//! - `geosens rod --method M --ks F --ke F --length F --x F --omega ±1 [--json]`
//!   estimates `I`, `s = ∂I/∂length` (and `∂I/∂x` for `transport`) at one
//!   probe on a rod with one method, or evaluates the exact solution
//!   (`--method exact`), and prints a table or one JSON line;
//! - `geosens flat --scene FILE --method M [--json]` does the same for every
//!   parameter of a flatland scene file (`--fd-step H` sets the half step of
//!   `--method fd`, on both subcommands);
//! - `geosens mesh --scene FILE --method M [--json]`: the same for a 3D
//!   triangle-mesh scene file (gradient axes x, y, z);
//! - `geosens render --scene FILE --method M --spp N --out DIR`: every pixel
//!   of a 3D scene's camera, images of `I` and every `∂I/∂π` with their
//!   error images, and one JSON line of the images' means;
//! - every estimation command above takes `--shard I/N --state FILE` (run
//!   only shard `I` of `N` and write its exact accumulator state), and
//!   `geosens merge FILE… [--json] [--out DIR]` prints (or writes) what the
//!   single run would have, bit for bit (`--missing` lists the shards no
//!   FILE holds instead, for a rerun);
//! - `geosens optimize --scene FILE --method M [--iterations N]
//!   [--paths-per-step N] [--step F] [--json]` fits the parameters of a
//!   scene with `[objective]` and `[[measurements]]` (or designs them), one
//!   record per iteration;
//! - `geosens compare` runs the four Monte Carlo methods on the paper's thin
//!   and thick rods at a few probes and prints them beside the exact solution,
//!   then every method on two 3D occluder scenes beside their closed forms,
//!   then writes the rod's figures, flatland's (`flat_*`) and the 3D ones
//!   (`mesh_*`) (with the `figures` feature, on by default).
//!
//! Bad input exits with status 1 and `error: …` naming the value (clap's own
//! parse errors exit with status 2).
use clap::builder::PossibleValue;
use clap::{Args, Parser, Subcommand, ValueEnum};
use geosens::job::{Job, SceneSource, Target};
use geosens::report::Report;
use geosens::rod::{Direction, Probe, Rod};
use geosens::shard::{Shard, State};
use geosens::{Error, Estimate, Method, Quantity, RunConfig, RunResult, run};
use std::io::{self, Write};
use std::process::ExitCode;
use std::time::Instant;

/// Monte Carlo estimates of intensity and geometric sensitivities.
#[derive(Debug, Parser)]
#[command(name = "geosens", version, about, max_term_width = 100)]
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
    /// Compare the four methods with the exact solution on the paper's rods
    /// and with the closed forms on two 3D occluder scenes, then write the
    /// rod's figures, flatland's and the 3D ones.
    Compare(CompareArgs),
    /// Estimate I and ∂I/∂π for every parameter of a flatland scene file.
    Flat(SceneArgs),
    /// Estimate I and ∂I/∂π for every parameter of a 3D (triangle-mesh)
    /// scene file; `transport` also gives ∂I/∂x, ∂I/∂y, ∂I/∂z.
    Mesh(SceneArgs),
    /// Render a 3D scene's camera: images of I and of every ∂I/∂π with their
    /// standard-error images (EXR, .npy, PNG) and one JSON line.
    Render(render::RenderArgs),
    /// Merge the states of every shard of one run (`--shard I/N --state
    /// FILE`) and print what the single run prints.
    Merge(MergeArgs),
    /// Fit a scene's parameters to its measurements' targets, or make a
    /// weighted sum of them greatest or least (`[objective]`), by stochastic
    /// gradient descent with one method's gradients.
    Optimize(optimize::OptimizeArgs),
}

/// `--shard I/N --state FILE`, shared by the estimation commands.
#[derive(Debug, Args)]
struct ShardArgs {
    /// Run only shard I of N of the run (1 ≤ I ≤ N; the run's blocks of
    /// 65536 paths split into N contiguous shares); needs `--state`.
    #[arg(long, value_name = "I/N")]
    shard: Option<Shard>,
    /// Write the shard's exact accumulator state to FILE (JSON) instead of
    /// printing a result; `geosens merge` prints the run from all states.
    /// Without `--shard`, the whole run is one shard (1/1).
    #[arg(long, value_name = "FILE")]
    state: Option<std::path::PathBuf>,
}

/// `geosens merge`: the states of one run.
#[derive(Debug, Args)]
struct MergeArgs {
    /// The state files, one per shard, in any order.
    #[arg(required_unless_present = "missing", value_name = "FILE")]
    states: Vec<std::path::PathBuf>,
    /// Print one JSON line instead of a table (a rendering's merge prints
    /// its JSON line whatever).
    #[arg(long)]
    json: bool,
    /// Folder a rendering's images go to (its states only).
    #[arg(long)]
    out: Option<std::path::PathBuf>,
    /// Merge nothing: print the shards that no FILE holds, as a Slurm array
    /// (`2,5-7`; nothing when none is), and on stderr how far the run has
    /// got. The states must be of one run (of N shards, with `--shards N`).
    #[arg(long, conflicts_with_all = ["json", "out"])]
    missing: bool,
    /// The run's number of shards: states of a run of another number are
    /// refused (a folder holding another run's states). With `--missing`
    /// and no FILE, every shard is missing.
    #[arg(long, value_name = "N")]
    shards: Option<u64>,
}

/// `geosens flat` and `geosens mesh`: a scene file, a method, a run.
#[derive(Debug, Args)]
struct SceneArgs {
    /// Scene file (TOML or JSON; see scenes/ and scenes/mesh/).
    #[arg(long)]
    scene: std::path::PathBuf,
    /// Estimation method.
    #[arg(long, value_enum)]
    method: Method,
    /// The fd half step, the run, the sharding and the output form.
    #[command(flatten)]
    estimate: EstimateArgs,
}

/// What `rod`, `flat` and `mesh` take after the probe: how to run the
/// estimation and print its result (one struct, so that the three
/// subcommands' options stay alike).
#[derive(Debug, Args)]
struct EstimateArgs {
    /// The finite differences' half step.
    #[command(flatten)]
    fd: FdArgs,
    /// The run configuration.
    #[command(flatten)]
    run: RunArgs,
    /// Sharding.
    #[command(flatten)]
    shard: ShardArgs,
    /// Print one JSON line instead of a table.
    #[arg(long)]
    json: bool,
}

/// `--fd-step`, shared by `rod`, `flat` and `mesh`.
#[derive(Debug, Args)]
struct FdArgs {
    /// Half step of `--method fd`: relative to the scene's size (the rod's
    /// length) for a translation, radians for a rotation, the relative
    /// change for a scale; in [1e-12, 1) [default: 0.001].
    #[arg(long, allow_hyphen_values = true)]
    fd_step: Option<f64>,
}

/// How to estimate: the method, the rod, the probe and the run. Float values
/// may start with `-` (`--omega -1`, `--x -inf`) so that the library, not the
/// parser, rejects them with its domain in the message.
#[derive(Debug, Args)]
#[command(
    allow_negative_numbers = true,
    // clap does not wrap the usage line: the probe's six values on two.
    override_usage = "geosens rod --method <METHOD> --ks <KS> --ke <KE> --length <LENGTH> \
                      --x <X>\n           --omega <OMEGA> [OPTIONS]"
)]
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
    /// The fd half step, the run, the sharding and the output form.
    #[command(flatten)]
    estimate: EstimateArgs,
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
    /// Number of paths per run, at least 2 [default: 1000000; 200000 for
    /// `compare`] (the rod's `exact` samples none but checks it too).
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
    /// with `--threads` checked first ([`geosens::runner::check_threads`]).
    fn config(&self, default_paths: u64) -> Result<RunConfig, Error> {
        geosens::runner::check_threads(self.threads)?;
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
    geosens::report::rod_quantities()
}

/// Position of `q` in [`quantities`].
fn slot(q: &Quantity) -> usize {
    match q {
        Quantity::Intensity => 0,
        Quantity::Sensitivity(_) => 1,
        Quantity::Gradient(_) => 2,
    }
}

mod commands;
mod optimize;
mod output;
mod render;
mod survey;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let mut out = io::stdout().lock();
    let result = match &cli.command {
        Command::Rod(args) => commands::rod_command(args, &mut out),
        Command::Compare(args) => commands::compare_command(args, &mut out),
        Command::Flat(args) => commands::flat_command(args, &mut out),
        Command::Mesh(args) => commands::mesh_command(args, &mut out),
        Command::Render(args) => render::render_command(args, &mut out),
        Command::Merge(args) => commands::merge_command(args, &mut out),
        Command::Optimize(args) => optimize::optimize_command(args, &mut out),
    };
    match result.and_then(|()| Ok(out.flush()?)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
