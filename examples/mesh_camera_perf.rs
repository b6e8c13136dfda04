//! Time per method for a 128×128 image of the showcase scene at a mean
//! per-pixel relative standard error of 5 % on every sensitivity image.
//!
//! The error measure, per image of a quantity `q` with per-pixel estimates
//! `(v_p, s_p)`:
//!
//! `rel(q) = mean_p s_p / mean_p |v_p|`
//!
//! a ratio of means, not a mean of per-pixel ratios: a sensitivity image is
//! zero (or nearly so) on most pixels (away from the cube, its shadow and
//! the fog), where `s_p / |v_p|` is meaningless or infinite.
//! `benches/mitsuba_camera.py` uses the same measure.
//!
//! Per method: a pilot render at `PILOT` paths per pixel (seed 1), `rel` per
//! parameter, the spp predicted for `rel = 5 %` on the worst parameter
//! (`spp ∝ rel²`), a render at that spp (seed 2) capped so it takes at most
//! `BUDGET` seconds; the time to 5 % per parameter is then extrapolated from
//! the measured `rel` and time, `t₅ = t (rel / 0.05)²`.
//!
//! Caveat: at the pilot's spp most pixels of a derivative image are noise,
//! which inflates `mean_p |v_p|`: the pilot's `rel` is too low and its
//! prediction too small (showcase_nofog, 2026-11-24: pilot 0.79 at 16 spp
//! predicted 4015 spp; 2331 spp measured 11 % and 24 %). The final
//! extrapolation, from a `rel` of 10–30 %, is the number to use.
//!
//! Measured 2026-11-24 after the lamp-overlap draws (2 shared cores, budget
//! 20 s): time to 5 % (cube_x, cube_rot) rendering 34 s, 325 s; transport
//! 119 s, 503 s; expectation 212 s; fd 129 s (cube_x). Later that day, with
//! the lamp edges and the silhouettes' lamp parts taken at every vertex and
//! two points with two pairs of nested paths per camera pixel (the code
//! before run back to back: rendering 34 s, 324 s; transport 113 s,
//! 486 s): rendering 3.4 s, 10.9 s; transport 4.3 s, 14.6 s; expectation
//! 212 s, 1072 s; fd 116 s (cube_x).
//!
//! `cargo run --release --no-default-features --example mesh_camera_perf --
//! [SCENE] [PILOT] [BUDGET] [THREADS] [OUT]`: defaults
//! `scenes/mesh/showcase.toml`, 16, 50 s, 0 (all cores); with `OUT`, writes
//! each final image as `OUT/<method>_<quantity>.npy` (and its stderr as
//! `…_se.npy`).
use geosens::image::{ImageResult, render};
use geosens::image_io::{Plane, write_npy};
use geosens::mesh::file;
use geosens::{Estimate, Method, Problem, Quantity};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Target mean relative standard error of the sensitivity images.
const TARGET: f64 = 0.05;

/// `mean_p s_p / mean_p |v_p|` over the pixels of one image.
fn rel(img: &[Estimate]) -> f64 {
    let se: f64 = img.iter().map(|e| e.stderr).sum();
    let v: f64 = img.iter().map(|e| e.mean.abs()).sum();
    se / v
}

fn label(q: &Quantity) -> String {
    match q {
        Quantity::Intensity => "I".into(),
        Quantity::Sensitivity(n) => format!("d{n}"),
        Quantity::Gradient(a) => format!("grad_{a}"),
    }
}

/// `rel` of every sensitivity image, in the estimator's order.
fn rels(r: &ImageResult) -> Vec<(String, f64)> {
    r.images
        .iter()
        .filter(|(q, _)| matches!(q, Quantity::Sensitivity(_)))
        .map(|(q, img)| (label(q), rel(img)))
        .collect()
}

fn write_images(out: &Path, method: Method, r: &ImageResult) {
    std::fs::create_dir_all(out).expect("create OUT");
    let (w, h) = (r.width as usize, r.height as usize);
    for (q, img) in &r.images {
        let stem = format!("{}_{}", method.name(), label(q));
        let mean: Vec<f64> = img.iter().map(|e| e.mean).collect();
        let se: Vec<f64> = img.iter().map(|e| e.stderr).collect();
        for (suffix, data) in [("", &mean), ("_se", &se)] {
            let plane = Plane {
                width: w,
                height: h,
                data,
            };
            write_npy(&out.join(format!("{stem}{suffix}.npy")), &plane).expect("write npy");
        }
    }
}

fn main() {
    let mut args = std::env::args().skip(1);
    let scene_path = args.next().map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mesh/showcase.toml"),
        PathBuf::from,
    );
    let pilot: u64 = args.next().map_or(16, |a| a.parse().expect("PILOT"));
    let budget: f64 = args.next().map_or(50.0, |a| a.parse().expect("BUDGET"));
    let threads: usize = args.next().map_or(0, |a| a.parse().expect("THREADS"));
    let out = args.next().map(PathBuf::from);
    let scene = Arc::new(file::load(&scene_path).expect("scene loads"));
    let cores = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    };
    println!(
        "{}: target rel = {:.0} % (rel = mean_p stderr_p / mean_p |value_p|), pilot {pilot} spp, \
         budget {budget} s per render, {cores} threads",
        scene_path.display(),
        100.0 * TARGET
    );
    let mut rows = Vec::new();
    for method in [
        Method::Rendering,
        Method::Transport,
        Method::Expectation,
        Method::Fd,
    ] {
        let est = scene.estimator(method, None).expect("estimator");
        let quiet = geosens::runner::quiet;
        let p = render(est.as_ref(), pilot, 1, threads, &quiet).expect("pilot render");
        let worst = rels(&p).iter().map(|x| x.1).fold(0.0, f64::max);
        let predicted = ((pilot as f64) * (worst / TARGET).powi(2)).ceil().max(2.0) as u64;
        let per_spp = p.seconds / pilot as f64;
        let capped = predicted as f64 * per_spp > budget;
        let spp = if capped {
            ((budget / per_spp) as u64).max(2)
        } else {
            predicted
        };
        println!(
            "{method}: pilot {pilot} spp {:.2} s, worst rel {:.3} -> {predicted} spp predicted \
             ({:.1} s){}",
            p.seconds,
            worst,
            predicted as f64 * per_spp,
            if capped {
                format!(", capped at {spp} spp")
            } else {
                String::new()
            }
        );
        let r = render(est.as_ref(), spp, 2, threads, &quiet).expect("render");
        if let Some(dir) = &out {
            write_images(dir, method, &r);
        }
        rows.push((method, p, r, capped));
    }

    println!();
    println!(
        "{:<12} {:>6} {:>8} {:>9} {:>11}  rel per parameter [t to 5 % in s]",
        "method", "spp", "seconds", "ns/path", "ns/path/thr"
    );
    for (method, _, r, capped) in &rows {
        let ns = 1e9 * r.seconds / r.paths() as f64;
        let cols: Vec<String> = rels(r)
            .iter()
            .map(|(n, x)| {
                format!(
                    "{n} {:.2} % [{:.1}]",
                    100.0 * x,
                    r.seconds * (x / TARGET).powi(2)
                )
            })
            .collect();
        println!(
            "{:<12} {:>6} {:>8.2} {:>9.1} {:>11.1}  {}{}",
            method.name(),
            r.spp,
            r.seconds,
            ns,
            ns * cores as f64,
            cols.join("  "),
            if *capped { "  (capped)" } else { "" }
        );
    }
    println!();
    println!("image means ± stderr (final renders)");
    for (method, _, r, _) in &rows {
        let cols: Vec<String> = r
            .images
            .iter()
            .zip(&r.means)
            .map(|((q, _), m)| format!("{} {:.6} ± {:.6}", label(q), m.mean, m.stderr))
            .collect();
        println!("{:<12} {}", method.name(), cols.join("  "));
    }
    println!();
    println!("time to rel = 5 % per parameter (s; measured rel and time, t ∝ rel²)");
    for (method, _, r, _) in &rows {
        let cols: Vec<String> = rels(r)
            .iter()
            .map(|(n, x)| format!("{n} {:.2}", r.seconds * (x / TARGET).powi(2)))
            .collect();
        println!("{:<12} {}", method.name(), cols.join("  "));
    }
}
