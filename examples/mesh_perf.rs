//! Paths per second per thread of every 3D method, each method's cost over
//! the intensity estimator's, and σ²·t per method and parameter, on three
//! scenes: the shipped occluder (5 parameters), a box and a square
//! occluder (10 parameters), and a UV sphere of about 10⁵ triangles
//! casting its shadow (2 parameters).
//!
//! `cargo run --release --example mesh_perf -- [ROUNDS] [PATHS] [SPHERE_PATHS]`:
//! medians of ROUNDS (default 3) one-thread runs of PATHS paths (default
//! 100000; SPHERE_PATHS, default 20000, on the sphere).
use geosens::mesh::{Motion, Parameter, Scene, Shape, Surface, file};
use geosens::{Method, Quantity, RunConfig, RunResult, run};
use glam::DVec3;
use std::f64::consts::PI;
use std::path::Path;
use std::sync::Arc;

/// A closed UV sphere of `rings × segments × 2` triangles (minus the caps'
/// degenerate halves), outward.
fn uv_sphere(name: &str, c: DVec3, r: f64, rings: u32, segments: u32) -> Shape {
    let mut vertices = vec![c + DVec3::Z * r];
    for i in 1..rings {
        let th = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let ph = 2.0 * PI * j as f64 / segments as f64;
            vertices.push(c + r * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    vertices.push(c - DVec3::Z * r);
    let south = vertices.len() as u32 - 1;
    let at = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, at(1, j), at(1, j + 1)]);
        triangles.push([south, at(rings - 1, j + 1), at(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, cc, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
            triangles.push([a, cc, d]);
            triangles.push([a, d, b]);
        }
    }
    Shape {
        name: name.into(),
        vertices,
        triangles,
        surface: Surface::Absorber,
        medium: None,
    }
}

fn scene_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mesh")
}

/// The shipped cube-shadow scene's lamp and sensor with `occluders`, each
/// moved along x, y, z, rotated and scaled.
fn with_occluders(occluders: Vec<Shape>, motions: &[(&str, Motion)]) -> Scene {
    let base = file::load(&scene_dir().join("occluder.toml")).expect("occluder.toml loads");
    let lamp = base.shapes()[0].clone();
    let mut parameters = Vec::new();
    for o in &occluders {
        for (n, m) in motions {
            parameters.push(Parameter {
                name: format!("{}_{n}", o.name),
                shape: o.name.clone(),
                motion: *m,
                bounds: None,
            });
        }
    }
    let mut shapes = vec![lamp];
    shapes.extend(occluders);
    Scene::new(shapes, parameters, base.sensor()).expect("valid scene")
}

fn cube(name: &str, c: DVec3, a: f64) -> Shape {
    geosens::mesh::cases::cube_shape(name, c, a, Surface::Absorber, None)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let rounds: usize = args.next().map_or(3, |a| a.parse().expect("ROUNDS"));
    let paths: u64 = args.next().map_or(100_000, |a| a.parse().expect("PATHS"));
    let sphere_paths: u64 = args
        .next()
        .map_or(20_000, |a| a.parse().expect("SPHERE_PATHS"));
    let rot = Motion::Rotate {
        axis: DVec3::new(0.3, 0.2, 1.0).normalize(),
        pivot: None,
    };
    let five = [
        ("tx", Motion::TranslateX),
        ("ty", Motion::TranslateY),
        ("tz", Motion::TranslateZ),
        ("rot", rot),
        ("scale", Motion::Scale { pivot: None }),
    ];
    let square = Shape {
        name: "sq".into(),
        vertices: vec![
            DVec3::new(-0.35, 0.0, 0.8),
            DVec3::new(-0.05, 0.0, 0.8),
            DVec3::new(-0.05, 0.3, 0.8),
            DVec3::new(-0.35, 0.3, 0.8),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Absorber,
        medium: None,
    };
    let sphere = uv_sphere("ball", DVec3::new(0.15, -0.1, 1.0), 0.2, 160, 320);
    let scenes: Vec<(String, Arc<Scene>, u64)> = vec![
        (
            "occluder".into(),
            Arc::new(file::load(&scene_dir().join("occluder.toml")).unwrap()),
            paths,
        ),
        (
            "box+square".into(),
            Arc::new(with_occluders(
                vec![cube("box", DVec3::new(0.2, -0.1, 1.2), 0.15), square],
                &five,
            )),
            paths,
        ),
        (
            format!("sphere {}", sphere.triangles.len()),
            Arc::new(with_occluders(vec![sphere], &five[..3])),
            sphere_paths,
        ),
    ];
    let methods = [
        Method::Intensity,
        Method::Rendering,
        Method::Expectation,
        Method::Transport,
        Method::Fd,
    ];
    println!("{rounds} rounds, one thread; medians");
    println!(
        "{:<16} {:>4} {:<12} {:>12} {:>9}",
        "scene", "par", "method", "paths/s", "cost/int"
    );
    let mut efficiency = Vec::new();
    for (name, scene, n) in &scenes {
        let mut base_rate = f64::NAN;
        for m in methods {
            let est = m.estimator(Arc::clone(scene)).expect("estimator");
            let mut rates = Vec::new();
            let mut last: Option<RunResult> = None;
            for r in 0..rounds {
                let cfg = RunConfig::new(*n, 100 + r as u64).unwrap().threads(1);
                let res = run(est.as_ref(), &cfg).unwrap();
                rates.push(*n as f64 / res.seconds);
                last = Some(res);
            }
            let rate = median(rates);
            if m == Method::Intensity {
                base_rate = rate;
            }
            println!(
                "{:<16} {:>4} {:<12} {:>12.0} {:>9.2}",
                name,
                scene.parameters().len(),
                m.name(),
                rate,
                base_rate / rate
            );
            if m != Method::Intensity {
                efficiency.push((name.clone(), m, last.unwrap(), 1.0 / rate));
            }
        }
    }
    println!("\nσ²·t per path (variance × seconds per path), ratio to the best unbiased method");
    for (name, scene, _) in &scenes {
        println!("{name}:");
        for p in scene.parameters() {
            let q = Quantity::sensitivity(&p.name);
            let rows: Vec<(Method, f64, f64, f64)> = efficiency
                .iter()
                .filter(|e| &e.0 == name)
                .map(|(_, m, r, t)| {
                    let e = r.get(&q).unwrap();
                    let var = e.stderr * e.stderr * r.paths as f64;
                    (*m, var * t, e.mean, e.stderr)
                })
                .collect();
            let best = rows
                .iter()
                .filter(|r| r.0 != Method::Fd)
                .map(|r| r.1)
                .fold(f64::INFINITY, f64::min);
            let cells: Vec<String> = rows
                .iter()
                .map(|(m, v, mean, se)| {
                    format!(
                        "{}: {:.2e} ({:.1}×, {mean:.4}±{se:.4})",
                        m.name(),
                        v,
                        v / best
                    )
                })
                .collect();
            println!("  {:<10} {}", p.name, cells.join("  "));
        }
    }
}
