//! The subcommands: `rod`, `compare` and `flat`, each printing a table or
//! one JSON line.
use super::output::{FlatJsonLine, JsonLine, MeanErr, all_finite, caveat_of, z_text};
use super::*;

/// `geosens rod`.
pub(super) fn rod_command(
    args: &RodArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
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
    mesh_table(&cfg, out)?;
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

/// One cell of the 3D table: `mean ± stderr z` with the signed z-score
/// against the closed form, `!` if the error bar is unreliable.
fn mesh_cell(e: &Estimate, exact: f64) -> String {
    let z = (e.mean - exact) / e.stderr;
    let z = if e.mean == exact {
        "0.0".to_owned()
    } else if z.is_finite() {
        format!("{z:+.1}")
    } else {
        "-".to_owned()
    };
    format!(
        "{:>11.6} ± {:<7.1e} z {:>5}{}",
        e.mean,
        e.stderr,
        z,
        if e.is_reliable() { "" } else { "!" }
    )
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
        writeln!(
            out,
            "\n3D: {what} at z ≈ 1 under the unit-square lamp (radiance 1) at z = 2, \
             irradiance at the origin (normal +z); {} paths per run, seed {}",
            cfg.paths, cfg.seed
        )?;
        writeln!(
            out,
            "{:<16} {:>11} {:<12} {:<38} {:>9}",
            "quantity", "closed form", "method", "estimate", "time [s]"
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
                writeln!(
                    out,
                    "{l:<16} {x:>11} {:<12} {:<38} {:>9.3}",
                    r.method,
                    mesh_cell(&est, *exact),
                    r.seconds
                )?;
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
    check_dimension(&args.scene, 2)?;
    let scene = std::sync::Arc::new(geosens::flat::file::load(&args.scene)?);
    let (shapes, parameters) = (scene.shapes().len(), scene.parameters().len());
    scene_command(args, scene, shapes, parameters, out)
}

/// Errors if the scene file at `path` is of the other dimension than
/// `want` (its sensor's point tells): the loader's own message would be
/// about a field, not the subcommand.
fn check_dimension(path: &std::path::Path, want: usize) -> Result<(), Error> {
    let got = geosens::flat::file::dimension(path)?;
    if got == want {
        return Ok(());
    }
    let (is, use_) = if got == 2 {
        ("a flatland (2D) scene file", "geosens flat")
    } else {
        ("a 3D scene file", "geosens mesh")
    };
    Err(Error::Scene(format!(
        "{}: this is {is} (its sensor's point has {got} coordinates): use `{use_}`",
        path.display()
    )))
}

/// `geosens mesh`.
pub(super) fn mesh_command(
    args: &SceneArgs,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    check_dimension(&args.scene, 3)?;
    let scene = std::sync::Arc::new(geosens::mesh::file::load(&args.scene)?);
    let (shapes, parameters) = (scene.shapes().len(), scene.parameters().len());
    scene_command(args, scene, shapes, parameters, out)
}

/// A run of `args.method` on a scene loaded from `args.scene` (`shapes`
/// shapes, `parameters` parameters): a table or one JSON line.
fn scene_command(
    args: &SceneArgs,
    problem: impl Problem,
    shapes: usize,
    parameters: usize,
    out: &mut impl Write,
) -> Result<(), Box<dyn std::error::Error>> {
    let cfg = args.run.config(1_000_000)?;
    let estimator = args.fd.estimator(args.method, problem, Some(&args.scene))?;
    if estimator.image().is_some() {
        return Err(Error::Config(format!(
            "{}: the sensor is a camera: its images come from `geosens render`",
            args.scene.display()
        ))
        .into());
    }
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
        shapes,
        parameters
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
