//! Scratch: all flatland methods on a small scene.
use geosens::flat::*;
use geosens::{RunConfig, run};
use glam::DVec2;
use std::sync::Arc;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(|s| s.as_str()).unwrap_or("occluder");
    let n: u64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(1_000_000);
    let emitter = Shape {
        name: "emitter".into(),
        vertices: vec![DVec2::new(-1.0, 2.0), DVec2::new(1.0, 2.0)],
        closed: false,
        surface: Surface::Emitter { radiance: 1.0 },
        medium: None,
    };
    let mut shapes = vec![emitter];
    let occ = match which {
        "fog" => Shape {
            name: "occ".into(),
            vertices: vec![
                DVec2::new(-0.5, 0.8),
                DVec2::new(0.7, 0.9),
                DVec2::new(0.6, 1.3),
                DVec2::new(-0.4, 1.2),
            ],
            closed: true,
            surface: Surface::Transparent,
            medium: Some(Medium {
                ks: 1.2,
                ke: 1.5,
                phase: Phase::HenyeyGreenstein { g: 0.3 },
            }),
        },
        "slab" => Shape {
            name: "occ".into(),
            vertices: vec![
                DVec2::new(-0.5, 0.8),
                DVec2::new(0.7, 0.9),
                DVec2::new(0.6, 1.3),
                DVec2::new(-0.4, 1.2),
            ],
            closed: true,
            surface: Surface::Transparent,
            medium: Some(Medium {
                ks: 0.0,
                ke: 1.5,
                phase: Phase::Isotropic,
            }),
        },
        "reflector" => Shape {
            name: "occ".into(),
            vertices: vec![
                DVec2::new(-0.5, 0.8),
                DVec2::new(0.7, 0.9),
                DVec2::new(0.6, 1.3),
                DVec2::new(-0.4, 1.2),
            ],
            closed: true,
            surface: Surface::Reflector { albedo: 0.8 },
            medium: None,
        },
        _ => Shape {
            name: "occ".into(),
            vertices: vec![DVec2::new(-0.6, 1.0), DVec2::new(0.2, 1.0)],
            closed: false,
            surface: Surface::Absorber,
            medium: None,
        },
    };
    shapes.push(occ);
    if which == "reflector" {
        shapes[0].vertices = vec![DVec2::new(-1.0, 0.5), DVec2::new(-1.0, 2.0)];
        shapes[0].vertices.reverse();
    }
    let params = vec![
        Parameter {
            name: "tx".into(),
            shape: "occ".into(),
            motion: Motion::TranslateX,
        },
        Parameter {
            name: "ty".into(),
            shape: "occ".into(),
            motion: Motion::TranslateY,
        },
        Parameter {
            name: "rot".into(),
            shape: "occ".into(),
            motion: Motion::Rotate { pivot: None },
        },
        Parameter {
            name: "scale".into(),
            shape: "occ".into(),
            motion: Motion::Scale { pivot: None },
        },
        Parameter {
            name: "etx".into(),
            shape: "emitter".into(),
            motion: Motion::TranslateX,
        },
    ];
    let sensor = Sensor::Irradiance {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    };
    let scene = Arc::new(Scene::new(shapes, params, sensor).unwrap());
    if let Some(h) = args.get(3) {
        let e = methods::FiniteDifference::new(scene.clone(), h.parse().unwrap()).unwrap();
        let r = run(&e, &RunConfig::new(n, 3).unwrap()).unwrap();
        print!("fd h={h} {:6.2}s", r.seconds);
        for (_, est) in &r.estimates {
            print!(" {:+.5}±{:.5}", est.mean, est.stderr);
        }
        println!();
        return;
    }
    for m in [
        Method::Intensity,
        Method::Fd,
        Method::Rendering,
        Method::Expectation,
        Method::Transport,
    ] {
        let e = m.estimator(scene.clone()).unwrap();
        let r = run(e.as_ref(), &RunConfig::new(n, 3).unwrap()).unwrap();
        print!("{:<12} {:6.2}s", m.name(), r.seconds);
        for (_, est) in &r.estimates {
            print!(" {:+.5}±{:.5}", est.mean, est.stderr);
        }
        println!();
    }
}
