//! The subcommands: `rod`, `compare` and `flat`, each printing a table or
//! one JSON line.
use super::output::{paragraph, progress_bar, shown};
use super::*;
use geosens::report::{RodProbe, yes_no, z_text};
use geosens::shard::Merged;

/// `geosens rod`.
pub(super) fn rod_command(
    args: &RodArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let target = Target::Rod(RodProbe {
        ks: args.ks,
        ke: args.ke,
        length: args.length,
        x: args.x,
        omega: args.omega,
    });
    estimate(target, args.method.0, &args.estimate, out)
}

/// Runs `method` (`None`: the exact solution) on `target` as `args` say
/// (or its shard, with `--state`) and prints its report.
fn estimate(
    target: Target,
    method: Option<Method>,
    args: &EstimateArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let job = Job {
        target,
        method,
        fd_step: args.fd.fd_step,
    };
    let (shard, json) = (&args.shard, args.json);
    let cfg = args.run.config(1_000_000)?;
    let method = job.method.map_or("exact", Method::name);
    let Some(path) = &shard.state else {
        if let Some(s) = shard.shard {
            return Err(Error::Config(format!(
                "--shard {s} needs --state FILE, where the shard's state goes"
            ))
            .into());
        }
        let bar = progress_bar(cfg.paths, "paths", method.to_owned());
        let report = job.run(&cfg, &shown(&bar));
        bar.finish_and_clear();
        return print_report(&report?, json, out);
    };
    if json {
        return Err(Error::Config(
            "--state writes the shard's state, not a result: `geosens merge --json` prints it"
                .into(),
        )
        .into());
    }
    super::output::writable_file(path)?;
    let which = shard.shard.unwrap_or(Shard::WHOLE);
    let bar = progress_bar(
        which.paths(cfg.paths),
        "paths",
        format!("{method} shard {which}"),
    );
    let state = job.run_shard(&cfg, which, &shown(&bar));
    bar.finish_and_clear();
    let state = state?;
    state.write(path)?;
    eprint!(
        "{}",
        paragraph(&format!(
            "wrote shard {which} ({} of {} paths, {:.2} s) to {}",
            state.paths,
            state.run.paths,
            state.seconds,
            path.display()
        ))
    );
    Ok(())
}

/// Prints `report`: its warnings on stderr, its JSON line or table on `out`.
fn print_report(
    report: &Report,
    json: bool,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let text = if json {
        report.json()? + "\n"
    } else {
        report.table()?
    };
    for w in report.warnings() {
        eprint!("{}", super::output::paragraph(&w));
    }
    out.write_all(text.as_bytes())?;
    Ok(())
}

/// `geosens merge`.
pub(super) fn merge_command(
    args: &MergeArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut states = Vec::with_capacity(args.states.len());
    for path in &args.states {
        states.push((path.display().to_string(), State::read(path)?));
    }
    if args.missing {
        return super::survey::missing_command(&states, args.shards, out);
    }
    if let Some(n) = args.shards {
        geosens::shard::survey(&states, Some(n))?;
    }
    match geosens::shard::merge(&states)? {
        Merged::Probe(report) => {
            if args.out.is_some() {
                return Err(Error::Config(
                    "--out is for a rendering's states; these are a probe's".into(),
                )
                .into());
            }
            print_report(&report, args.json, out)
        }
        Merged::Image(report) => {
            let dir = args.out.as_deref().ok_or_else(|| {
                Error::Config(
                    "these are a rendering's states: --out DIR says where its images go".into(),
                )
            })?;
            super::render::finish(&report, dir, out)
        }
    }
}

/// The paper's rods: name, κs, κe (length 2).
const RODS: [(&str, f64, f64); 2] = [("thin", 0.07, 0.1), ("thick", 2.1, 3.0)];

/// Probe positions of the comparison.
const XS: [f64; 4] = [0.0, 1.0, 1.9, 2.0];

/// `mean ± stderr z score`: the estimate column of the comparison tables,
/// `z` printed as given.
fn estimate_cell(e: &Estimate, z: &str) -> String {
    format!("{:>11.6} ± {:<7.1e} z {z:>5}", e.mean, e.stderr)
}

/// The columns of the comparison tables after the rod's probe (or the 3D
/// table's quantity): the reference value, the method, its estimate,
/// whether the error bar can be trusted, the run's time.
fn comparison_row(lead: &str, exact: &str, r: &RunResult, e: &Estimate, z: &str) -> String {
    format!(
        "{lead} {exact:>11} {:<11} {:<29} {:>8} {:>9.3}",
        r.method,
        estimate_cell(e, z),
        yes_no(e.is_reliable()),
        r.seconds
    )
}

/// One method's totals over the rod tables: sampling time, largest
/// z-score, unreliable estimates.
type MethodTotals = (f64, f64, usize);

/// The rod tables of `geosens compare`: per rod, per probe, per quantity, a
/// row per method that estimates it, beside the exact value; returns per
/// method the total sampling time, the largest z-score and the number of
/// unreliable estimates.
fn rod_tables(
    cfg: &RunConfig,
    out: &mut impl Write,
) -> Result<[MethodTotals; 4], Box<dyn std::error::Error>> {
    let mut totals = [(0.0, 0.0f64, 0usize); 4];
    let qs = quantities();
    for (name, ks, ke) in RODS {
        let rod = Rod::new(ks, ke, 2.0)?;
        write!(
            out,
            "\n{}",
            paragraph(&format!(
                "{name} rod: κs = {ks}, κe = {ke}, length 2; {} paths per run, seed {}",
                cfg.paths, cfg.seed
            ))
        )?;
        writeln!(
            out,
            "{:<7} {:<10} {:>11} {:<11} {:<29} {:>8} {:>9}",
            "x, ω", "quantity", "exact", "method", "estimate", "reliable", "time [s]"
        )?;
        for x in XS {
            for omega in [Direction::Right, Direction::Left] {
                let probe = Probe::new(&rod, x, omega)?;
                let ex = geosens::report::rod_exact(&rod, &probe);
                let mut runs = Vec::with_capacity(Method::UNBIASED.len());
                for m in Method::UNBIASED {
                    runs.push(run(m.estimator((rod, probe))?.as_ref(), cfg)?);
                }
                let mut label = format!("{x}, {:+}", omega.sign());
                for (q, exact) in qs.iter().zip(ex) {
                    let mut quantity = q.to_string();
                    let mut reference = format!("{exact:>11.6}");
                    for r in &runs {
                        let Some(e) = r.get(q) else { continue };
                        let lead = format!("{label:<7} {quantity:<10}");
                        let row = comparison_row(&lead, &reference, r, &e, &z_text(&e, exact));
                        writeln!(out, "{row}")?;
                        (label, quantity, reference) = Default::default();
                    }
                }
                for (r, total) in runs.iter().zip(&mut totals) {
                    total.0 += r.seconds;
                    for (q, e) in &r.estimates {
                        total.1 = total.1.max(e.z_score(ex[slot(q)]));
                        total.2 += usize::from(!e.is_reliable());
                    }
                }
            }
        }
    }
    Ok(totals)
}

/// `geosens compare`.
pub(super) fn compare_command(
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
    if !args.no_figures {
        super::output::writable_dir(&args.figures)?;
    }
    let start = Instant::now();
    let totals = rod_tables(&cfg, out)?;
    write!(
        out,
        "\n{}",
        paragraph(&format!(
            "per method over the 16 probes (z: distance to the exact value in standard \
             errors; reliable: no where the error bar cannot be trusted: VOV ≥ {}, fewer \
             than {} non-zero weights (for fd, also fewer than {} jumps or more than half \
             the pairs), or not finite)",
            Estimate::VOV_LIMIT,
            Estimate::MIN_NONZERO,
            Estimate::MIN_NONZERO
        ))
    )?;
    writeln!(
        out,
        "{:<12} {:>9} {:>7} {:>11}",
        "method", "time [s]", "max z", "unreliable"
    )?;
    for (m, (seconds, z, bad)) in Method::UNBIASED.iter().zip(totals) {
        writeln!(out, "{:<12} {seconds:>9.3} {z:>7.1} {bad:>11}", m.name())?;
    }
    mesh_table(&cfg, out)?;
    optimisation_table(&cfg, out)?;
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
        // Without a bar, a line per picture: a log shows how far it got.
        opts.log = !opts.progress;
        let start = Instant::now();
        let mut written = figures::all(&opts)?;
        written.extend(geosens::flat::figures::all(&opts)?);
        written.extend(geosens::mesh::figures::all(&opts)?);
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

/// Seeds of the quick optimisation table.
const OPTIMISATION_SEEDS: u64 = 3;

/// The budget of the quick optimisation table's runs: the example's
/// iterations, an eighth of its paths.
const OPTIMISATION_BUDGET: geosens::optimize::compare::Budget =
    geosens::optimize::compare::Budget {
        iterations: 400,
        paths: 1024,
    };

/// The short version of `examples/optimize_compare.rs`: every method
/// optimising the flatland inverse problem (scenes/inverse_occluder.toml)
/// from a few seeds with a small budget, the median wall time until the
/// tail average's error falls under the tolerance for good, and the final
/// error.
fn optimisation_table(
    cfg: &RunConfig,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    use geosens::optimize::compare::{self, Loaded, TOLERANCE, Variant};
    let loaded = Loaded::flat_toml(compare::INVERSE_OCCLUDER)?;
    let truth = compare::PROBLEMS[0].truth.unwrap_or(&[0.12, 0.2]);
    let budget = OPTIMISATION_BUDGET;
    write!(
        out,
        "\n{}",
        paragraph(&format!(
            "optimisation: the flatland inverse problem (inverse_occluder.toml), Adam, \
             {} iterations of {} paths per measurement, seeds {} to {}, medians (min–max) \
             over the seeds; time to tolerance: until the tail average's error (translation \
             / size, rotation in rad) falls under {TOLERANCE:e} and stays there \
             (examples/optimize_compare for the full table)",
            budget.iterations,
            budget.paths,
            cfg.seed,
            cfg.seed + OPTIMISATION_SEEDS - 1
        ))
    )?;
    let mut rows = Vec::new();
    for method in [
        Method::Expectation,
        Method::Rendering,
        Method::Transport,
        Method::Fd,
    ] {
        let bar = progress_bar(
            u64::from(budget.iterations + 1) * OPTIMISATION_SEEDS,
            "iterations",
            format!("optimise {}", method.name()),
        );
        let runs = (0..OPTIMISATION_SEEDS)
            .map(|k| {
                compare::run_one(
                    &loaded,
                    truth,
                    Variant::of(method),
                    cfg.seed + k,
                    budget,
                    cfg.threads,
                    || bar.inc(1),
                )
            })
            .collect::<Result<Vec<_>, _>>();
        bar.finish_and_clear();
        rows.push(compare::row("inverse_occluder", &runs?));
    }
    write!(out, "{}", optimisation_text(&rows))?;
    Ok(())
}

/// The optimisation rows as a table without their problem column (the
/// title names the one problem), columns padded, within 100 characters.
fn optimisation_text(rows: &[geosens::optimize::compare::Row]) -> String {
    const COLUMNS: [&str; 6] = [
        "method",
        "to tol. [s] (min–max)",
        "paths to tol.",
        "reached",
        "final error (min–max)",
        "run [s]",
    ];
    let cells: Vec<Vec<String>> = rows.iter().map(|r| r.cells()[1..].to_vec()).collect();
    geosens::optimize::compare::padded(&COLUMNS, &cells) + "\n"
}

/// The signed z-score of `e` against `exact` as the 3D table prints it:
/// `0.0` where the estimate is the closed form, `-` where no z is finite.
fn signed_z(e: &Estimate, exact: f64) -> String {
    let z = (e.mean - exact) / e.stderr;
    if e.mean == exact {
        "0.0".to_owned()
    } else if z.is_finite() {
        format!("{z:+.1}")
    } else {
        "-".to_owned()
    }
}

/// The 3D rows of `geosens compare`: every method on two occluder scenes
/// (a black triangle, a black box, under the unit-square lamp) against the
/// closed forms of `geosens::mesh::exact`, one run per method giving `E`
/// and every `∂E/∂π`.
fn mesh_table(cfg: &RunConfig, out: &mut impl Write) -> Result<(), Box<dyn std::error::Error>> {
    use geosens::mesh::cases::{TriangleOccluder, box_shape, lamp, up};
    use geosens::mesh::exact::BoxScene;
    use geosens::mesh::{Parameter, Scene, Surface};
    use glam::DVec3;
    let t = TriangleOccluder::NOMINAL;
    let (e, s) = t.exact()?;
    let triangle = (
        "black triangle (centre (0.2, 0.05, 1), circumradius 0.2, first vertex at 0.3 rad)",
        t.scene(&[0, 1, 2])?,
        e,
        s.to_vec(),
    );
    let b = BoxScene::shipped(DVec3::new(0.2, -0.1, 1.0), 0.3);
    let names = ["box_tx", "box_ty", "box_tz", "box_rot", "box_scale"];
    let parameters = names
        .iter()
        .zip(b.motions())
        .map(|(n, m)| Parameter {
            name: (*n).into(),
            shape: "box".into(),
            motion: m,
            bounds: None,
        })
        .collect();
    let cube = box_shape("box", b.corners(), Surface::Absorber, None);
    let boxed = (
        "black cube (side 0.3, centred at (0.2, -0.1, 1))",
        Scene::new(vec![lamp(), cube], parameters, up())?,
        b.irradiance()?,
        b.sensitivities()?.to_vec(),
    );
    for (what, scene, e, s) in [triangle, boxed] {
        let scene = std::sync::Arc::new(scene);
        write!(
            out,
            "\n{}",
            paragraph(&format!(
                "3D: {what} at z ≈ 1 under the unit-square lamp (radiance 1) at z = 2, \
                 irradiance at the origin (normal +z); {} paths per run, seed {}",
                cfg.paths, cfg.seed
            ))
        )?;
        writeln!(
            out,
            "{:<16} {:>11} {:<11} {:<29} {:>8} {:>9}",
            "quantity", "closed form", "method", "estimate", "reliable", "time [s]"
        )?;
        let mut runs = Vec::new();
        for m in Method::ALL {
            runs.push(run(
                m.estimator(std::sync::Arc::clone(&scene))?.as_ref(),
                cfg,
            )?);
        }
        let mut quantities = vec![(Quantity::Intensity, "E".to_owned(), e)];
        for (p, &x) in scene.parameters().iter().zip(&s) {
            quantities.push((Quantity::sensitivity(&p.name), format!("∂E/∂{}", p.name), x));
        }
        for (q, label, exact) in &quantities {
            let mut first = true;
            for r in &runs {
                let Some(est) = r.get(q) else { continue };
                let (l, x) = if first {
                    (label.as_str(), format!("{exact:>11.6}"))
                } else {
                    ("", String::new())
                };
                first = false;
                let row = comparison_row(&format!("{l:<16}"), &x, r, &est, &signed_z(&est, *exact));
                writeln!(out, "{row}")?;
            }
        }
    }
    Ok(())
}

/// `geosens flat`.
pub(super) fn flat_command(
    args: &SceneArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let target = Target::Flat(SceneSource::File(args.scene.clone()));
    estimate(target, Some(args.method), &args.estimate, out)
}

/// `geosens mesh`.
pub(super) fn mesh_command(
    args: &SceneArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let target = Target::Mesh(SceneSource::File(args.scene.clone()));
    estimate(target, Some(args.method), &args.estimate, out)
}
