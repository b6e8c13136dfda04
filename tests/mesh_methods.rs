//! The 3D estimators against independent references: the closed-form
//! irradiance under a square lamp, and finite differences with common
//! random numbers at high sample counts for the sensitivities.
use geosens::mesh::cases::{cube_shape as cube, lamp, square_shape as square, up};
use geosens::mesh::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
use geosens::{Method, Quantity, RunConfig, run};
use glam::DVec3;
use std::sync::Arc;

fn params(shape: &str, motions: &[(&str, Motion)]) -> Vec<Parameter> {
    motions
        .iter()
        .map(|(n, m)| Parameter {
            name: (*n).into(),
            shape: shape.into(),
            motion: *m,
            bounds: None,
        })
        .collect()
}

/// The irradiance under a square of half-side `a` at height `h`.
fn square_irradiance(a: f64, h: f64) -> f64 {
    let x = a / h;
    let s = (1.0 + x * x).sqrt();
    4.0 * (x / s * (x / s).atan())
}

/// Each derivative method's caveats on `scene`.
fn caveats_by_method(scene: &Arc<Scene>) -> Vec<(Method, Vec<(Quantity, String)>)> {
    [
        Method::Rendering,
        Method::Transport,
        Method::Expectation,
        Method::Fd,
    ]
    .into_iter()
    .map(|m| (m, m.estimator(Arc::clone(scene)).unwrap().caveats()))
    .collect()
}

fn estimate(scene: &Arc<Scene>, m: Method, n: u64, seed: u64) -> geosens::RunResult {
    let e = m.estimator(Arc::clone(scene)).unwrap();
    run(e.as_ref(), &RunConfig::new(n, seed).unwrap()).unwrap()
}

/// `m`'s estimate of `∂I/∂name` in `r` against finite differences in
/// `fd`: printed, and within 4 combined standard errors; returns both.
fn against_fd(
    m: Method,
    name: &str,
    r: &geosens::RunResult,
    fd: &geosens::RunResult,
) -> (geosens::Estimate, geosens::Estimate) {
    let q = Quantity::sensitivity(name);
    let (a, b) = (r.get(&q).unwrap(), fd.get(&q).unwrap());
    let z = (a.mean - b.mean) / a.stderr.hypot(b.stderr);
    eprintln!(
        "{m} {name}: {:.6} ± {:.2e} vs fd {:.6} ± {:.2e} (z {z:.2})",
        a.mean, a.stderr, b.mean, b.stderr
    );
    assert!(z.abs() < 4.0, "{m} {name}: {a:?} vs fd {b:?}");
    (a, b)
}

#[test]
fn every_method_gives_the_lamps_irradiance() {
    let scene = Arc::new(Scene::new(vec![lamp()], vec![], up()).unwrap());
    let exact = square_irradiance(0.5, 2.0);
    for m in [
        Method::Intensity,
        Method::Rendering,
        Method::Transport,
        Method::Expectation,
    ] {
        let r = estimate(&scene, m, 100_000, 4);
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!(i.z_score(exact) < 4.0, "{m}: {i:?} vs {exact}");
        assert!(i.stderr < 0.01 * exact, "{m}: {i:?}");
    }
}

/// Rendering and transport against finite differences on an occluder
/// scene: a flat square occluder and a closed absorbing cube.
#[test]
fn occluders_sensitivities_match_finite_differences() {
    let rot = Motion::Rotate {
        axis: DVec3::new(0.3, 0.2, 1.0),
        pivot: None,
    };
    let motions = [
        ("tx", Motion::TranslateX),
        ("ty", Motion::TranslateY),
        ("tz", Motion::TranslateZ),
        ("rot", rot),
        ("scale", Motion::Scale { pivot: None }),
    ];
    for occ in [
        square("occ", DVec3::new(0.2, 0.1, 1.0), 0.25, Surface::Absorber),
        cube(
            "occ",
            DVec3::new(0.15, -0.1, 1.0),
            0.2,
            Surface::Absorber,
            None,
        ),
        cube(
            "occ",
            DVec3::new(0.15, -0.1, 1.0),
            0.2,
            Surface::Reflector { albedo: 0.8 },
            None,
        ),
    ] {
        let scene = Arc::new(Scene::new(vec![lamp(), occ], params("occ", &motions), up()).unwrap());
        let fd = estimate(&scene, Method::Fd, 2_000_000, 11);
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let r = estimate(&scene, m, 400_000, 5);
            for (name, _) in motions {
                against_fd(m, name, &r, &fd);
            }
        }
    }
}

/// A fog cube (a medium inside a closed transparent mesh) between the
/// sensor and the lamp, moving and growing: the moving-interface terms
/// against finite differences; the sensor inside a second fog box.
#[test]
fn fog_cubes_sensitivities_match_finite_differences() {
    let fog = Medium {
        ks: 1.0,
        ke: 1.5,
        g: 0.3,
    };
    let motions = [
        ("tx", Motion::TranslateX),
        ("tz", Motion::TranslateZ),
        (
            "rot",
            Motion::Rotate {
                axis: DVec3::Y,
                pivot: None,
            },
        ),
        ("scale", Motion::Scale { pivot: None }),
    ];
    let box_at = |c: DVec3, a: f64, name: &str| cube(name, c, a, Surface::Transparent, Some(fog));
    for extra in [None, Some(box_at(DVec3::new(0.0, 0.0, 0.1), 0.3, "around"))] {
        let mut shapes = vec![lamp(), box_at(DVec3::new(0.2, 0.1, 1.0), 0.35, "fog")];
        shapes.extend(extra);
        let scene = Arc::new(Scene::new(shapes, params("fog", &motions), up()).unwrap());
        let fd = estimate(&scene, Method::Fd, 1_000_000, 12);
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let r = estimate(&scene, m, 150_000, 6);
            for (name, _) in motions {
                against_fd(m, name, &r, &fd);
            }
        }
    }
}

/// Every derivative method against the closed forms (Lambert's polygon
/// formula with the occluder's shadow clipped out of the lamp, and its
/// analytic vertex gradient): a square occluder, unrotated and rotated, and
/// a closed box, each moved along x, y, z, rotated about the vertical
/// through its centre and scaled about it.
#[test]
fn occluders_match_the_closed_forms() {
    use geosens::mesh::exact::{BoxScene, OccluderScene};
    let names = ["tx", "ty", "tz", "rot", "scale"];
    let mut cases: Vec<(Shape, [Motion; 5], f64, [f64; 5])> = Vec::new();
    for (cx, cy, angle) in [(0.3, 0.1, 0.0), (-0.2, 0.25, 0.4)] {
        let mut o = OccluderScene::shipped(cx, cy);
        o.occ_angle = angle;
        let shape = o.occluder_shape();
        cases.push((
            shape,
            o.motions(),
            o.irradiance().unwrap(),
            o.sensitivities().unwrap(),
        ));
    }
    let b = BoxScene::shipped(DVec3::new(0.2, -0.1, 1.0), 0.3);
    cases.push((
        cube("occ", b.centre, 0.5 * b.side, Surface::Absorber, None),
        b.motions(),
        b.irradiance().unwrap(),
        b.sensitivities().unwrap(),
    ));
    for (shape, motions, e, s) in cases {
        let parameters = names
            .iter()
            .zip(motions)
            .map(|(n, m)| Parameter {
                name: (*n).into(),
                shape: "occ".into(),
                motion: m,
                bounds: None,
            })
            .collect();
        let scene = Arc::new(Scene::new(vec![lamp(), shape], parameters, up()).unwrap());
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let r = estimate(&scene, m, 200_000, 8);
            let i = r.get(&Quantity::Intensity).unwrap();
            assert!(i.z_score(e) < 4.0, "{m}: I {i:?} vs {e}");
            for (name, exact) in names.iter().zip(s) {
                let a = r.get(&Quantity::sensitivity(name)).unwrap();
                eprintln!(
                    "{m} {name}: {:.6} ± {:.2e} vs exact {exact:.6} (z {:.2})",
                    a.mean,
                    a.stderr,
                    (a.mean - exact) / a.stderr
                );
                assert!(a.z_score(exact) < 4.0, "{m} {name}: {a:?} vs {exact}");
                // Not toothless: the error bar resolves the value.
                assert!(a.stderr < 0.05 * s[0].abs(), "{m} {name}: {a:?}");
            }
        }
    }
}

/// A radiance sensor looking at a white Lambertian floor under the lamp
/// and the occluder: `L = (ρ/π) E(y)` at the floor point `y` it sees, so
/// every method's `∂L/∂π` is the closed form's `∂E(y)/∂π` times `ρ/π`
/// (the edge terms now seen from a reflecting vertex). And transport's
/// `∇I` at an irradiance sensor against the closed form's derivative in
/// the sensor's position.
#[test]
fn floor_radiance_and_sensor_gradient_match_the_closed_forms() {
    use geosens::mesh::exact::{
        OccluderScene, occluded_irradiance, occluded_irradiance_with_gradient, sensitivity,
    };
    use std::f64::consts::PI;
    let o = OccluderScene::shipped(0.3, 0.1);
    let names = ["tx", "ty", "tz", "rot", "scale"];
    let occ = o.occluder_shape();
    let parameters: Vec<Parameter> = names
        .iter()
        .zip(o.motions())
        .map(|(n, m)| Parameter {
            name: (*n).into(),
            shape: "occ".into(),
            motion: m,
            bounds: None,
        })
        .collect();
    let albedo = 0.7;
    let floor = square("floor", DVec3::ZERO, 2.0, Surface::Reflector { albedo });
    let y = DVec3::new(0.1, 0.05, 0.0);
    let eye = DVec3::new(-0.5, -0.3, 0.4);
    let sensor = Sensor::Radiance {
        point: eye,
        direction: (y - eye).normalize(),
    };
    let scene =
        Arc::new(Scene::new(vec![lamp(), occ.clone(), floor], parameters.clone(), sensor).unwrap());
    let (e, g) =
        occluded_irradiance_with_gradient(y, DVec3::Z, &o.lamp(), &o.occluder(), 1.0).unwrap();
    let k = albedo / PI;
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&scene, m, 200_000, 9);
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!(i.z_score(k * e) < 4.0, "{m}: L {i:?} vs {}", k * e);
        for (name, motion) in names.iter().zip(o.motions()) {
            let exact = k * sensitivity(&g, &o.occluder(), motion);
            let a = r.get(&Quantity::sensitivity(name)).unwrap();
            eprintln!(
                "{m} {name}: {:.6} ± {:.2e} vs exact {exact:.6} (z {:.2})",
                a.mean,
                a.stderr,
                (a.mean - exact) / a.stderr
            );
            assert!(a.z_score(exact) < 4.0, "{m} {name}: {a:?} vs {exact}");
        }
    }
    // ∇E at the irradiance sensor: central differences of the closed form
    // in the sensor's position (h = 1e-5: error ~1e-10).
    let scene = Arc::new(Scene::new(vec![lamp(), occ], parameters, up()).unwrap());
    let r = estimate(&scene, Method::Transport, 400_000, 10);
    for (axis, d) in [("x", DVec3::X), ("y", DVec3::Y), ("z", DVec3::Z)] {
        let h = 1e-5;
        let at =
            |x: DVec3| occluded_irradiance(x, DVec3::Z, &o.lamp(), &o.occluder(), 1.0).unwrap();
        let exact = (at(d * h) - at(-d * h)) / (2.0 * h);
        let a = r.get(&Quantity::gradient(axis)).unwrap();
        eprintln!(
            "transport dI/d{axis}: {:.6} ± {:.2e} vs exact {exact:.6} (z {:.2})",
            a.mean,
            a.stderr,
            (a.mean - exact) / a.stderr
        );
        assert!(a.z_score(exact) < 4.0, "∂I/∂{axis}: {a:?} vs {exact}");
        assert!(a.stderr < 0.05 * exact.abs().max(0.05), "∂I/∂{axis}: {a:?}");
    }
}

/// A box face in a plane through the sensor: `E` has a kink along a motion
/// across that plane (the one-sided derivatives differ), so every method
/// reports a caveat there, not a confident number; a hair away from the
/// plane (δ = 3·10⁻⁴) there is no caveat and every method matches the
/// closed form.
#[test]
fn a_face_seen_edge_on_is_a_caveat_not_a_number() {
    use geosens::mesh::cases::box_kink;
    let (scene, _) = box_kink(0.0).unwrap();
    let scene = Arc::new(scene);
    let name = scene.parameters()[0].name.clone();
    for m in [
        Method::Rendering,
        Method::Transport,
        Method::Expectation,
        Method::Fd,
    ] {
        let e = m.estimator(Arc::clone(&scene)).unwrap();
        let caveats = e.caveats();
        assert!(
            caveats
                .iter()
                .any(|(q, why)| *q == Quantity::sensitivity(&name) && why.contains("edge-on")),
            "{m}: {caveats:?}"
        );
    }
    let (scene, exact) = box_kink(3e-4).unwrap();
    let (scene, exact) = (Arc::new(scene), exact.unwrap());
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let e = m.estimator(Arc::clone(&scene)).unwrap();
        assert!(e.caveats().is_empty(), "{m}");
        let r = run(e.as_ref(), &RunConfig::new(200_000, 14).unwrap()).unwrap();
        let s = r.get(&Quantity::sensitivity(&name)).unwrap();
        assert!(s.z_score(exact) < 4.0, "{m}: {s:?} vs {exact}");
    }
}

/// The issue's occluder scene: a black triangle at z = 1 under the unit
/// lamp, translated, rotated and scaled, irradiance at several points of
/// the plane z = 0 (not only under the lamp's centre), every derivative
/// method against the closed form.
#[test]
fn a_triangle_occluder_seen_from_points_on_the_floor() {
    use geosens::mesh::exact::{occluded_irradiance_with_gradient, sensitivity};
    let c = DVec3::new(0.15, 0.05, 1.0);
    let tri: Vec<DVec3> = (0..3)
        .map(|k| {
            let a = 2.0 * std::f64::consts::PI * k as f64 / 3.0 + 0.3;
            c + 0.22 * DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let motions = [
        ("tx", Motion::TranslateX),
        ("tz", Motion::TranslateZ),
        (
            "rot",
            Motion::Rotate {
                axis: DVec3::new(0.2, -0.4, 1.0).normalize(),
                pivot: Some(c),
            },
        ),
        ("scale", Motion::Scale { pivot: Some(c) }),
    ];
    let lamp_poly = lamp().vertices.clone();
    for (i, x) in [
        DVec3::ZERO,
        DVec3::new(0.3, -0.2, 0.0),
        DVec3::new(-0.45, 0.35, 0.0),
    ]
    .into_iter()
    .enumerate()
    {
        let occ = Shape {
            name: "tri".into(),
            vertices: tri.clone(),
            triangles: vec![[0, 1, 2]],
            surface: Surface::Absorber,
            medium: None,
        };
        let sensor = Sensor::Irradiance {
            point: x,
            normal: DVec3::Z,
        };
        let scene =
            Arc::new(Scene::new(vec![lamp(), occ], params("tri", &motions), sensor).unwrap());
        let (e, g) = occluded_irradiance_with_gradient(x, DVec3::Z, &lamp_poly, &tri, 1.0).unwrap();
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let r = estimate(&scene, m, 150_000, 20 + i as u64);
            let ie = r.get(&Quantity::Intensity).unwrap();
            assert!(ie.z_score(e) < 4.0, "{m} at {x}: {ie:?} vs {e}");
            for (name, motion) in motions {
                let exact = sensitivity(&g, &tri, motion);
                let a = r.get(&Quantity::sensitivity(name)).unwrap();
                assert!(
                    a.z_score(exact) < 4.0,
                    "{m} {name} at {x}: {a:?} vs {exact}"
                );
            }
        }
    }
}

/// Flatland as a limit: a lamp strip and an occluder strip 2000 long (an
/// infinitely long prism seen from its middle) give `π/2` times the
/// flatland irradiance of their cross-section (the view factor of an
/// infinite strip is half the difference of the sines, flatland's
/// irradiance that difference), and the same for every derivative: the 3D
/// estimators against flatland's closed form for `scenes/occluder.toml`.
#[test]
fn a_long_prism_is_flatland_times_pi_over_two() {
    use geosens::flat::exact::Reference;
    let flat = geosens::flat::file::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/occluder.toml"),
    )
    .unwrap();
    let reference = Reference::for_scene(&flat).unwrap();
    let half = 1000.0;
    let strip = |name: &str, x0: f64, x1: f64, z: f64, surface: Surface| Shape {
        name: name.into(),
        vertices: vec![
            DVec3::new(x0, -half, z),
            DVec3::new(x1, -half, z),
            DVec3::new(x1, half, z),
            DVec3::new(x0, half, z),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface,
        medium: None,
    };
    let pivot = DVec3::new(-0.2, 0.0, 1.0);
    // Flatland's (x, y) is (x, z) here; its counter-clockwise turn is a
    // rotation about −y.
    let motions = [
        ("occluder_tx", Motion::TranslateX),
        ("occluder_ty", Motion::TranslateZ),
        (
            "occluder_rotate",
            Motion::Rotate {
                axis: -DVec3::Y,
                pivot: Some(pivot),
            },
        ),
    ];
    let scene = Arc::new(
        Scene::new(
            vec![
                strip("lamp", -1.0, 1.0, 2.0, Surface::Emitter { radiance: 1.0 }),
                strip("occluder", -0.6, 0.2, 1.0, Surface::Absorber),
            ],
            params("occluder", &motions),
            up(),
        )
        .unwrap(),
    );
    let k = std::f64::consts::FRAC_PI_2;
    for m in [
        Method::Intensity,
        Method::Rendering,
        Method::Transport,
        Method::Expectation,
    ] {
        let r = estimate(&scene, m, 200_000, 30);
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!(
            i.z_score(k * reference.value()) < 4.0,
            "{m}: {i:?} vs {}",
            k * reference.value()
        );
        if m == Method::Intensity {
            continue;
        }
        for (j, (name, _)) in motions.iter().enumerate() {
            let exact = k * reference.derivative(j);
            let a = r.get(&Quantity::sensitivity(name)).unwrap();
            eprintln!(
                "{m} {name}: {:.6} ± {:.2e} vs {exact:.6} (z {:.2})",
                a.mean,
                a.stderr,
                (a.mean - exact) / a.stderr
            );
            assert!(a.z_score(exact) < 4.0, "{m} {name}: {a:?} vs {exact}");
            assert!(a.stderr < 0.05 * exact.abs().max(0.02), "{m} {name}: {a:?}");
        }
    }
}

/// A black cube inside a big box of fog (a mesh inside a medium), the
/// sensor in the fog too: the cube's sensitivities against finite
/// differences (the edge terms see through the medium, and the nested
/// paths start inside it).
#[test]
fn a_mesh_inside_a_medium_matches_finite_differences() {
    let fog = Medium {
        ks: 0.6,
        ke: 0.9,
        g: -0.2,
    };
    let motions = [
        ("tx", Motion::TranslateX),
        ("tz", Motion::TranslateZ),
        ("scale", Motion::Scale { pivot: None }),
    ];
    let shapes = vec![
        lamp(),
        cube(
            "fog",
            DVec3::new(0.0, 0.0, 0.9),
            1.0,
            Surface::Transparent,
            Some(fog),
        ),
        cube(
            "occ",
            DVec3::new(0.15, -0.1, 1.0),
            0.2,
            Surface::Absorber,
            None,
        ),
    ];
    let scene = Arc::new(Scene::new(shapes, params("occ", &motions), up()).unwrap());
    assert_eq!(scene.sensor_medium(), Some(1));
    let fd = estimate(&scene, Method::Fd, 3_000_000, 40);
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&scene, m, 150_000, 41);
        for (name, _) in motions {
            let (_, b) = against_fd(m, name, &r, &fd);
            assert!(b.stderr < 0.1 * b.mean.abs(), "fd {name}: {b:?}");
        }
    }
}

/// A moving lamp, tilted and off-centre (its points' velocities enter the
/// lamp connections and its edges the boundary terms), against the
/// closed form's gradient in the lamp's vertices; and the occluder scene
/// scaled by 10⁻⁸ and 10⁸, where `E` is the same and every translation's
/// derivative scales as 1/s.
#[test]
fn a_moving_lamp_and_scaled_scenes_match_the_closed_forms() {
    use geosens::mesh::exact::{OccluderScene, polygon_irradiance_with_gradient, sensitivity};
    let tilt = glam::DQuat::from_axis_angle(DVec3::new(1.0, 0.3, 0.0).normalize(), 0.5);
    let centre = DVec3::new(0.3, -0.2, 1.5);
    let poly: Vec<DVec3> = [(-0.4, -0.3), (0.4, -0.3), (0.4, 0.3), (-0.4, 0.3)]
        .iter()
        .map(|&(x, y)| centre + tilt * DVec3::new(x, y, 0.0))
        .collect();
    let tilted = Shape {
        name: "lamp".into(),
        vertices: poly.clone(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Emitter { radiance: 2.0 },
        medium: None,
    };
    let motions = [
        ("tx", Motion::TranslateX),
        ("tz", Motion::TranslateZ),
        (
            "rot",
            Motion::Rotate {
                axis: DVec3::new(0.5, -0.2, 1.0).normalize(),
                pivot: Some(centre + DVec3::new(0.1, 0.0, 0.0)),
            },
        ),
        (
            "scale",
            Motion::Scale {
                pivot: Some(centre),
            },
        ),
    ];
    let scene = Arc::new(Scene::new(vec![tilted], params("lamp", &motions), up()).unwrap());
    let (e, g) = polygon_irradiance_with_gradient(DVec3::ZERO, DVec3::Z, &poly, 2.0).unwrap();
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&scene, m, 150_000, 50);
        assert!(r.get(&Quantity::Intensity).unwrap().z_score(e) < 4.0, "{m}");
        for (name, motion) in motions {
            let exact = sensitivity(&g, &poly, motion);
            let a = r.get(&Quantity::sensitivity(name)).unwrap();
            assert!(a.z_score(exact) < 4.0, "{m} lamp {name}: {a:?} vs {exact}");
            assert!(
                a.stderr < 0.05 * exact.abs().max(0.05),
                "{m} lamp {name}: {a:?}"
            );
        }
    }
    // Scaled scenes.
    let o = OccluderScene::shipped(0.3, 0.1);
    let names = ["tx", "ty", "tz", "rot", "scale"];
    let (e, s) = (o.irradiance().unwrap(), o.sensitivities().unwrap());
    for k in [1e-8, 1e8] {
        let scaled = |sh: Shape| Shape {
            vertices: sh.vertices.iter().map(|v| *v * k).collect(),
            ..sh
        };
        let occ = o.occluder_shape();
        let motions = o.motions().map(|m| match m {
            Motion::Rotate { axis, pivot } => Motion::Rotate {
                axis,
                pivot: pivot.map(|p| p * k),
            },
            Motion::Scale { pivot } => Motion::Scale {
                pivot: pivot.map(|p| p * k),
            },
            m => m,
        });
        let parameters = names
            .iter()
            .zip(motions)
            .map(|(n, m)| Parameter {
                name: (*n).into(),
                shape: "occ".into(),
                motion: m,
                bounds: None,
            })
            .collect();
        let scene =
            Arc::new(Scene::new(vec![scaled(lamp()), scaled(occ)], parameters, up()).unwrap());
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let r = estimate(&scene, m, 100_000, 51);
            let i = r.get(&Quantity::Intensity).unwrap();
            assert!(i.z_score(e) < 4.0, "{m} ×{k}: {i:?} vs {e}");
            for (j, name) in names.iter().enumerate() {
                // Translations scale as 1/k; rotation and scale do not.
                let exact = if j < 3 { s[j] / k } else { s[j] };
                let a = r.get(&Quantity::sensitivity(name)).unwrap();
                assert!(a.z_score(exact) < 4.0, "{m} ×{k} {name}: {a:?} vs {exact}");
                assert!(a.is_reliable(), "{m} ×{k} {name}: {a:?}");
            }
        }
    }
}

/// Inside a closed reflecting room (concave creases everywhere, seen from
/// inside), a lamp panel near the ceiling, a rotating two-sided reflecting
/// panel and a black cube moving about: every derivative method against
/// finite differences. The panel's rotation turns the frame of every
/// vertex on it, so rendering and transport draw their edge terms among all
/// the room's edges there: measured at these counts, their σ on `panel_rot`
/// is 5–8× expectation's (0.034 and 0.021 against 0.0043, for a value near
/// −0.02), so only the cube's parameters are required to be resolved.
#[test]
fn a_reflecting_room_matches_finite_differences() {
    let mut room = cube(
        "room",
        DVec3::new(0.0, 0.0, 1.0),
        1.5,
        Surface::Reflector { albedo: 0.6 },
        None,
    );
    // Seen from inside: the room's normals point in, as an open shell's
    // would; its winding does not matter to a two-sided reflector.
    room.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    let panel = Shape {
        name: "panel".into(),
        vertices: vec![
            DVec3::new(-0.9, -0.4, 0.6),
            DVec3::new(-0.5, -0.4, 1.3),
            DVec3::new(-0.5, 0.4, 1.3),
            DVec3::new(-0.9, 0.4, 0.6),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Reflector { albedo: 0.9 },
        medium: None,
    };
    let shapes = vec![
        square(
            "lamp",
            DVec3::new(0.2, 0.1, 2.3),
            0.3,
            Surface::Emitter { radiance: 3.0 },
        ),
        room,
        panel,
        cube(
            "occ",
            DVec3::new(0.35, 0.0, 1.2),
            0.2,
            Surface::Absorber,
            None,
        ),
    ];
    let mut parameters = params(
        "occ",
        &[
            ("occ_tx", Motion::TranslateX),
            ("occ_scale", Motion::Scale { pivot: None }),
        ],
    );
    parameters.extend(params(
        "panel",
        &[(
            "panel_rot",
            Motion::Rotate {
                axis: DVec3::Y,
                pivot: Some(DVec3::new(-0.9, 0.0, 0.6)),
            },
        )],
    ));
    let sensor = Sensor::Irradiance {
        point: DVec3::new(0.1, 0.0, 0.2),
        normal: DVec3::new(0.2, 0.1, 1.0).normalize(),
    };
    let scene = Arc::new(Scene::new(shapes, parameters.clone(), sensor).unwrap());
    let fd = estimate(&scene, Method::Fd, 2_000_000, 60);
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&scene, m, 150_000, 61);
        for p in &parameters {
            let (a, b) = against_fd(m, &p.name, &r, &fd);
            if p.shape == "occ" {
                assert!(b.stderr < 0.15 * b.mean.abs(), "fd {}: {b:?}", p.name);
                assert!(a.stderr < 0.1 * a.mean.abs(), "{m} {}: {a:?}", p.name);
            }
        }
    }
}

/// A folded reflecting sheet whose faces turn 30° at the crease (under
/// `rendering::SHARED_TURN`), lit from low on one side: one face bright,
/// the other in its own shade, so the jump across the crease (two
/// reflector faces, `nested::reflected_jump`'s shared draws) carries most of
/// the translation's derivative; against finite differences.
#[test]
fn a_folded_reflector_between_light_and_shade_matches_finite_differences() {
    let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let sheet = Shape {
        name: "sheet".into(),
        vertices: vec![
            v(-1.0, -1.0, 0.0),
            v(0.05, -1.0, 0.28),
            v(1.1, -1.0, 0.0),
            v(-1.0, 1.0, 0.0),
            v(0.05, 1.0, 0.28),
            v(1.1, 1.0, 0.0),
        ],
        triangles: vec![[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]],
        surface: Surface::Reflector { albedo: 0.7 },
        medium: None,
    };
    let low_lamp = Shape {
        name: "lamp".into(),
        vertices: vec![
            v(-3.0, -1.0, 0.1),
            v(-3.0, 1.0, 0.1),
            v(-2.6, 1.0, 0.9),
            v(-2.6, -1.0, 0.9),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Emitter { radiance: 1.0 },
        medium: None,
    };
    let motions = [
        ("sheet_tx", Motion::TranslateX),
        (
            "sheet_rot",
            Motion::Rotate {
                axis: DVec3::Y,
                pivot: Some(v(0.2, 0.0, 0.1)),
            },
        ),
    ];
    let sensor = Sensor::Irradiance {
        point: v(0.25, 0.1, 1.4),
        normal: -DVec3::Z,
    };
    let scene =
        Arc::new(Scene::new(vec![low_lamp, sheet], params("sheet", &motions), sensor).unwrap());
    let fd = estimate(&scene, Method::Fd, 2_000_000, 11);
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&scene, m, 400_000, 5);
        for (name, _) in motions {
            against_fd(m, name, &r, &fd);
        }
    }
}

/// A black quad folded a little along its diagonal (a crease that is a
/// silhouette from the sensor) under the lamp, the whole scene moved up to
/// 10⁶ from the origin: every derivative method against the closed form of
/// its shadow (the central projection of its four corners). Far from the
/// origin a point on an edge is rounded by more than `T_MIN` times the
/// triangles' size, so a nested path leaving the crease hit its own faces
/// and rendering and transport gave −0.289 ± 0.00008 for −0.329 at 10⁴
/// (found by a sweep of moved scenes); the hit threshold now also counts
/// the coordinates' ulps.
#[test]
fn a_folded_occluder_far_from_the_origin_matches_the_closed_form() {
    use geosens::mesh::exact::{occluded_irradiance_with_gradient, sensitivity};
    let corners = [
        DVec3::new(-0.2, -0.25, 0.8),
        DVec3::new(0.3, -0.2, 0.8),
        DVec3::new(0.25, 0.3, 0.85),
        DVec3::new(-0.25, 0.25, 0.8),
    ];
    let x = DVec3::new(0.45, 0.35, 0.0);
    let square = lamp();
    let (e, g) =
        occluded_irradiance_with_gradient(x, DVec3::Z, &square.vertices, &corners, 1.0).unwrap();
    let exact = sensitivity(&g, &corners, Motion::TranslateX);
    for offset in [0.0, 1e4, 1e6] {
        let shift = DVec3::new(0.0, 0.0, offset);
        let moved = |s: Shape| Shape {
            vertices: s.vertices.iter().map(|v| *v + shift).collect(),
            ..s
        };
        let occ = Shape {
            name: "occ".into(),
            vertices: corners.to_vec(),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            surface: Surface::Absorber,
            medium: None,
        };
        let sensor = Sensor::Irradiance {
            point: x + shift,
            normal: DVec3::Z,
        };
        let scene = Arc::new(
            Scene::new(
                vec![moved(lamp()), moved(occ)],
                params("occ", &[("occ_tx", Motion::TranslateX)]),
                sensor,
            )
            .unwrap(),
        );
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let r = estimate(&scene, m, 100_000, 61);
            let i = r.get(&Quantity::Intensity).unwrap();
            assert!(i.z_score(e).abs() < 4.0, "{m} at {offset}: {i:?} vs {e}");
            let a = r.get(&Quantity::sensitivity("occ_tx")).unwrap();
            eprintln!("{m} at {offset}: {a:?} vs {exact}");
            assert!(
                a.z_score(exact).abs() < 4.0,
                "{m} at {offset}: {a:?} vs {exact}"
            );
        }
    }
}

/// A small moving occluder beside a large moving mesh that the sensor
/// cannot see (an icosphere of 1 280 triangles below the sensor's plane,
/// with a parameter of its own): every method still matches the
/// occluder's closed forms, and rendering's and transport's error bars on
/// the occluder stay within 1.5× of those without the sphere's parameter.
/// Drawn from the union of the moving edges, the occluder's few edges
/// were lost among the sphere's and its lamp parts were no longer taken
/// every time (the union is too large): rendering's error bar on `tx`
/// was 730× larger (± 5.5·10⁻³ against ± 7.5·10⁻⁶).
#[test]
fn a_small_moving_mesh_keeps_its_error_bars_beside_a_large_one() {
    use geosens::mesh::exact::OccluderScene;
    let names = ["tx", "ty", "tz", "rot", "scale"];
    let o = OccluderScene::shipped(0.3, 0.1);
    let (e, s) = (o.irradiance().unwrap(), o.sensitivities().unwrap());
    let occ = o.occluder_shape();
    let (v, t) = geosens::mesh::cases::icosphere(3);
    let ball = Shape {
        name: "ball".into(),
        vertices: v
            .iter()
            .map(|&p| 2.0 * p + DVec3::new(0.0, 0.0, -4.0))
            .collect(),
        triangles: t.iter().map(|f| f.map(|i| i as u32)).collect(),
        surface: Surface::Absorber,
        medium: None,
    };
    let scene = |with_ball: bool| {
        let mut parameters: Vec<Parameter> = names
            .iter()
            .zip(o.motions())
            .map(|(n, m)| Parameter {
                name: (*n).into(),
                shape: "occ".into(),
                motion: m,
                bounds: None,
            })
            .collect();
        if with_ball {
            parameters.extend(params("ball", &[("ball_tz", Motion::TranslateZ)]));
        }
        let shapes = vec![lamp(), occ.clone(), ball.clone()];
        Arc::new(Scene::new(shapes, parameters, up()).unwrap())
    };
    let (alone, beside) = (scene(false), scene(true));
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&beside, m, 100_000, 12);
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!(i.z_score(e) < 4.0, "{m}: I {i:?} vs {e}");
        let ball = r.get(&Quantity::sensitivity("ball_tz")).unwrap();
        assert!(
            ball.mean == 0.0,
            "{m}: the unseen sphere moves nothing: {ball:?}"
        );
        let reference = (m != Method::Expectation).then(|| estimate(&alone, m, 100_000, 12));
        for (name, exact) in names.iter().zip(s) {
            let a = r.get(&Quantity::sensitivity(name)).unwrap();
            eprintln!(
                "{m} {name}: {:.6} ± {:.2e} vs exact {exact:.6} (z {:.2})",
                a.mean,
                a.stderr,
                (a.mean - exact) / a.stderr
            );
            assert!(a.z_score(exact) < 4.0, "{m} {name}: {a:?} vs {exact}");
            if let Some(alone) = &reference {
                let b = alone.get(&Quantity::sensitivity(name)).unwrap();
                eprintln!("  without the sphere's parameter: ± {:.2e}", b.stderr);
                assert!(
                    a.stderr < 1.5 * b.stderr,
                    "{m} {name}: ± {:.2e} beside the sphere, ± {:.2e} without",
                    a.stderr,
                    b.stderr
                );
            }
        }
    }
}

/// A black tetrahedron under a lamp that holds its whole shadow, one face
/// `graze` rad from edge-on as seen from the sensor (its back turned to
/// it): every method's three sensitivities against the closed form of a
/// convex body's shadow (`body_irradiance_with_gradient`).
///
/// The path past a silhouette edge used to start exactly on the edge: the
/// nearly edge-on face at that edge was then hit by rounding a hair along
/// the ray (at t ~ 10⁻¹⁶/γ, beyond the casters' T_MIN once γ < 10⁻⁴) and
/// hid the lamp. Found by a random-scene campaign: at γ = 4·10⁻⁵ rendering
/// and transport were 4–17 % off (z = 170–310), at 2.5·10⁻⁶ up to 56 %.
#[test]
fn a_face_nearly_edge_on_does_not_hide_its_silhouettes_jump() {
    use geosens::mesh::exact::{body_irradiance_with_gradient, sensitivity};
    let body = [
        DVec3::new(0.452175, -0.076276, 1.178488),
        DVec3::new(0.376552, -0.277115, 1.079515),
        DVec3::new(0.337658, -0.070366, 0.971844),
        DVec3::new(0.220892, -0.124127, 1.170153),
    ];
    let c = body.iter().copied().sum::<DVec3>() / 4.0;
    let axis = DVec3::new(0.824951, -0.506413, -0.251001).normalize();
    let lamp_z = 1.881125;
    let lamp = [
        DVec3::new(0.2, -0.6, lamp_z),
        DVec3::new(0.9, -0.6, lamp_z),
        DVec3::new(0.9, 0.1, lamp_z),
        DVec3::new(0.2, 0.1, lamp_z),
    ];
    // Face (0, 2, 3), seen from the origin at 4.2·10⁻⁵ rad, its back turned.
    let n = (body[2] - body[0]).cross(body[3] - body[0]).normalize();
    let graze = n.dot(body[0]) / body[0].length();
    assert!(graze.abs() > 1e-5 && graze.abs() < 1e-4, "{graze}");
    let motions = [
        Motion::Rotate {
            axis,
            pivot: Some(c),
        },
        Motion::Scale { pivot: Some(c) },
        Motion::TranslateZ,
    ];
    let shape = |name: &str, v: &[DVec3], triangles: Vec<[u32; 3]>, surface| Shape {
        name: name.into(),
        vertices: v.to_vec(),
        triangles,
        surface,
        medium: None,
    };
    let lamp_shape = shape(
        "lamp",
        &lamp,
        vec![[0, 1, 2], [0, 2, 3]],
        Surface::Emitter { radiance: 1.0 },
    );
    let tet = shape(
        "tet",
        &body,
        vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        Surface::Absorber,
    );
    let names = ["rot", "scale", "tz"];
    let parameters: Vec<(&str, Motion)> = names.into_iter().zip(motions).collect();
    let scene =
        Arc::new(Scene::new(vec![lamp_shape, tet], params("tet", &parameters), up()).unwrap());
    let (e, grad) =
        body_irradiance_with_gradient(DVec3::ZERO, DVec3::Z, &lamp, &body, 1.0).unwrap();
    // Finite differences at the default step straddle the face's turn (it
    // faces the sensor at one end of the step and not at the other): a
    // caveat (they gave −0.0017 ± 0.0003 on `rot`, marked reliable); at a
    // step of 10⁻⁶ they do not.
    let fd_caveat = |step: f64| {
        use geosens::Estimator;
        let fd = geosens::mesh::methods::finite_difference(&scene, step).unwrap();
        fd.caveats()
            .into_iter()
            .find(|(q, _)| *q == Quantity::sensitivity("rot"))
    };
    let (_, why) = fd_caveat(1e-3).expect("a caveat at the default step");
    assert!(why.contains("turns from facing the sensor"), "{why}");
    assert_eq!(fd_caveat(1e-6), None);
    for m in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = estimate(&scene, m, 100_000, 4);
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!((i.mean - e).abs() < 4.0 * i.stderr, "{m} I: {i:?} vs {e}");
        for (name, motion) in names.into_iter().zip(motions) {
            let exact = sensitivity(&grad, &body, motion);
            let s = r.get(&Quantity::sensitivity(name)).unwrap();
            let z = (s.mean - exact) / s.stderr;
            eprintln!(
                "{m} {name}: {:.6} ± {:.1e} vs {exact:.6} (z {z:.2})",
                s.mean, s.stderr
            );
            assert!(
                s.is_reliable() && z.abs() < 4.0,
                "{m} {name}: {s:?} vs {exact}"
            );
        }
    }
}

/// An occluder's edge whose shadow falls exactly on the lamp's edge: `E`
/// has a kink in the occluder's x (its slope drops as the shadow leaves
/// the lamp), the methods return different sides (expectation 0.199,
/// rendering 0.0226, finite differences 0.119, all marked reliable before),
/// and every derivative method carries a caveat; moved by 10⁻⁷ the edges
/// no longer align and there is none.
#[test]
fn edges_aligned_from_the_sensor_are_a_caveat_for_every_method() {
    use geosens::mesh::exact::occluded_irradiance;
    // A square of half-side 0.125 at z = 1 whose right edge, at x = 0.25 +
    // `dx`, casts its shadow on the lamp's edge x = 0.5 when `dx` = 0.
    let occ = |dx: f64| {
        let half = 0.125;
        square(
            "occ",
            DVec3::new(half + dx, 0.0, 1.0),
            half,
            Surface::Absorber,
        )
    };
    let e = |dx: f64| {
        occluded_irradiance(
            DVec3::ZERO,
            DVec3::Z,
            &lamp().vertices,
            &occ(dx).vertices,
            1.0,
        )
        .unwrap()
    };
    let h = 1e-4;
    let (right, left) = ((e(h) - e(0.0)) / h, (e(0.0) - e(-h)) / h);
    assert!(
        (right - left).abs() > 0.1 * left.abs(),
        "no kink: {left} vs {right}"
    );
    // The edges' planes are searched by a sort, not pair by pair: the tie
    // is also found beside a ball of 1 280 triangles whose silhouette
    // edges crowd the sorted planes, and mirrored (the occluder's left edge
    // on the lamp's left edge, with the other orientation).
    let (v, f) = geosens::mesh::cases::icosphere(3);
    let ball = Shape {
        name: "ball".into(),
        vertices: v
            .iter()
            .map(|&p| DVec3::new(0.3, 0.35, 1.2) + 0.1 * p)
            .collect(),
        triangles: f.iter().map(|t| t.map(|i| i as u32)).collect(),
        surface: Surface::Absorber,
        medium: None,
    };
    let mirrored = |s: Shape| Shape {
        vertices: s
            .vertices
            .iter()
            .map(|p| DVec3::new(-p.x, p.y, p.z))
            .collect(),
        triangles: s.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        ..s
    };
    // A reflecting ball: each of its edges is a discontinuity from
    // everywhere, so its 1 920 planes outnumber the occluder's by far and
    // each moved edge scans them rather than sorting them all.
    let shiny = Shape {
        surface: Surface::Reflector { albedo: 0.5 },
        ..ball.clone()
    };
    for (dx, tied, others) in [
        (0.0, true, vec![]),
        (1e-7, false, vec![]),
        (0.0, true, vec![ball.clone()]),
        (1e-7, false, vec![ball.clone()]),
        (0.0, true, vec![mirrored(ball.clone())]),
        (0.0, true, vec![shiny.clone()]),
        (1e-7, false, vec![shiny.clone()]),
    ] {
        let parameters = params("occ", &[("occ_tx", Motion::TranslateX)]);
        let occ = if others.iter().any(|o| o.vertices[0].x < 0.0) {
            mirrored(occ(dx))
        } else {
            occ(dx)
        };
        let mut shapes = vec![lamp(), occ];
        shapes.extend(others);
        let scene = Arc::new(Scene::new(shapes, parameters, up()).unwrap());
        for m in [Method::Rendering, Method::Transport, Method::Expectation] {
            let caveats = m.estimator(Arc::clone(&scene)).unwrap().caveats();
            let found = caveats
                .iter()
                .any(|(q, why)| *q == Quantity::sensitivity("occ_tx") && why.contains("one plane"));
            assert_eq!(found, tied, "{m} at dx = {dx}: {caveats:?}");
        }
    }
}

#[test]
fn a_moving_fog_far_from_the_origin_keeps_its_derivatives() {
    // A fog box (size 1.7 with the lamp) moved 1.4·10⁵ sizes from the
    // origin, well inside the offsets accepted: the nested paths at its
    // moving interface started 10⁻⁹ sizes off it, inside the casters'
    // rounding floor there, and lost track of the medium (transport's
    // fog_tz −0.032 against −0.008, its fog_sc −0.037 against −0.048,
    // marked reliable; rendering 2× off). Each method at the offset
    // against the same method at the origin.
    let fog = |shift: DVec3| Shape {
        vertices: cube(
            "fog",
            DVec3::new(-0.025, 0.025, 0.9),
            0.6,
            Surface::Transparent,
            None,
        )
        .vertices
        .iter()
        .map(|v| DVec3::new(v.x * 1.15 / 1.2, v.y * 1.15 / 1.2, v.z) + shift)
        .collect(),
        medium: Some(Medium {
            ks: 1.0,
            ke: 1.3,
            g: 0.0,
        }),
        ..cube("fog", DVec3::ZERO, 0.6, Surface::Transparent, None)
    };
    let scene = |shift: DVec3| {
        let lamp = lamp();
        let lamp = Shape {
            vertices: lamp.vertices.iter().map(|v| *v + shift).collect(),
            ..lamp
        };
        let sensor = Sensor::Irradiance {
            point: shift,
            normal: DVec3::Z,
        };
        let parameters = params(
            "fog",
            &[
                ("fog_tz", Motion::TranslateZ),
                ("fog_sc", Motion::Scale { pivot: None }),
            ],
        );
        Arc::new(Scene::new(vec![lamp, fog(shift)], parameters, sensor).unwrap())
    };
    let (near, far) = (scene(DVec3::ZERO), scene(DVec3::new(-1e5, 2e5, 1e5)));
    for m in [Method::Rendering, Method::Transport] {
        let (a, b) = (
            estimate(&near, m, 200_000, 5),
            estimate(&far, m, 200_000, 5),
        );
        for q in ["fog_tz", "fog_sc"] {
            let q = Quantity::sensitivity(q);
            let (a, b) = (a.get(&q).unwrap(), b.get(&q).unwrap());
            let z = (a.mean - b.mean) / a.stderr.hypot(b.stderr);
            assert!(z.abs() < 4.0, "{m} {q:?}: {a:?} at the origin, {b:?} far");
        }
    }
}

#[test]
fn a_step_wider_than_the_lamp_is_a_caveat_for_finite_differences() {
    // A lamp 10⁻³ wide (radiance 10⁶) at z = 2, a black triangle at z = 1
    // whose edge shadows part of it: dI/dtx = 2 L a / d² = 500 exactly
    // (a the lamp's side, d = 2: the edge's shadow sweeps the lamp at
    // twice its own speed). At the default step one half step moves the
    // edge's shadow past the lamp: the quotient saturated at 125.000 ±
    // 7·10⁻⁹, marked reliable.
    let a = 1e-3;
    let lamp = Shape {
        name: "lamp".into(),
        vertices: [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, y)| DVec3::new(0.5 * a * x, 0.5 * a * y, 2.0))
            .to_vec(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Emitter { radiance: 1e6 },
        medium: None,
    };
    let tri = Shape {
        name: "tri".into(),
        vertices: vec![
            DVec3::new(0.0002, -0.3, 1.0),
            DVec3::new(0.3, 0.0, 1.0),
            DVec3::new(0.0002, 0.3, 1.0),
        ],
        triangles: vec![[0, 1, 2]],
        surface: Surface::Absorber,
        medium: None,
    };
    let scene = Arc::new(
        Scene::new(
            vec![lamp, tri],
            params("tri", &[("tx", Motion::TranslateX)]),
            up(),
        )
        .unwrap(),
    );
    // The shadow's edge x_s = 4·10⁻⁴ on the lamp moves at 2 per unit tx and
    // uncovers radiance L seen with the kernel cos θ cos θ' / r² = 4/r⁴:
    // dE/dtx = 2 L ∫ 4/(c² + y²)² dy over the lamp's side, c² = 4 + x_s²
    // (500 up to 10⁻⁷: rendering resolves the difference).
    let (c2, half) = (4.0 + 4e-4f64 * 4e-4, 0.5 * a);
    let c = c2.sqrt();
    let primitive = |y: f64| y / (2.0 * c2 * (c2 + y * y)) + (y / c).atan() / (2.0 * c2 * c);
    let exact = 2.0 * 1e6 * 4.0 * (primitive(half) - primitive(-half));
    assert!((exact - 500.0).abs() < 1e-4, "{exact}");
    let q = Quantity::sensitivity("tx");
    let caveat = |step: f64| {
        let fd = geosens::mesh::methods::finite_difference(&scene, step).unwrap();
        geosens::Estimator::caveats(&fd)
            .iter()
            .any(|(c, why)| *c == q && why.contains("cross the lamp"))
    };
    assert!(caveat(geosens::fd::DEFAULT_STEP));
    assert!(!caveat(1e-5));
    let fine = geosens::mesh::methods::finite_difference(&scene, 1e-5).unwrap();
    let r = run(&fine, &RunConfig::new(400_000, 2).unwrap()).unwrap();
    let e = r.get(&q).unwrap();
    assert!(e.z_score(exact) < 4.0, "{e:?} against {exact}");
    let r = estimate(&scene, Method::Rendering, 100_000, 2);
    let e = r.get(&q).unwrap();
    assert!(e.z_score(exact) < 4.0, "{e:?} against {exact}");
}

#[test]
fn edges_of_one_mesh_aligned_from_the_sensor_are_a_caveat_too() {
    // One mesh of two black quads: the near one (z = 1) ends at x = 0.2,
    // the far one (z = 1.5) starts at x = 0.3 + dx; at dx = 0 both edges
    // lie in the plane x = 0.2 z through the sensor and the lamp is just
    // hidden. Moving the mesh left opens a gap (one-sided derivative
    // −0.148), right does not (0): rendering read 0.0049 and finite
    // differences −0.074, both marked reliable.
    let pair = |dx: f64| Shape {
        name: "pair".into(),
        vertices: vec![
            DVec3::new(-0.6, -0.6, 1.0),
            DVec3::new(0.2, -0.6, 1.0),
            DVec3::new(0.2, 0.6, 1.0),
            DVec3::new(-0.6, 0.6, 1.0),
            DVec3::new(0.3 + dx, -0.9, 1.5),
            DVec3::new(0.9, -0.9, 1.5),
            DVec3::new(0.9, 0.9, 1.5),
            DVec3::new(0.3 + dx, 0.9, 1.5),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        surface: Surface::Absorber,
        medium: None,
    };
    for (dx, tied) in [(0.0, true), (1e-6, false)] {
        let parameters = params("pair", &[("tx", Motion::TranslateX)]);
        let scene = Arc::new(Scene::new(vec![lamp(), pair(dx)], parameters, up()).unwrap());
        for (m, caveats) in caveats_by_method(&scene) {
            let on = |q: &Quantity| {
                caveats
                    .iter()
                    .any(|(c, why)| c == q && why.contains("edges of mesh \"pair\""))
            };
            assert_eq!(
                on(&Quantity::sensitivity("tx")),
                tied,
                "{m} at {dx}: {caveats:?}"
            );
            if m == Method::Transport {
                // The sensor's own motion crosses the same kink.
                assert_eq!(on(&Quantity::gradient("x")), tied, "{caveats:?}");
            }
        }
    }
    // Two corner edges of a room on either side of the sensor lie in one
    // plane through it but face opposite ways: no tie (their arcs, taken as
    // the min and max of angles, had wrapped round the back and overlapped).
    let room = Arc::new(
        geosens::mesh::file::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/mesh/room.toml"
        )))
        .unwrap(),
    );
    let caveats = Method::Rendering.estimator(room).unwrap().caveats();
    assert!(
        !caveats.iter().any(|(_, why)| why.contains("one plane")),
        "{caveats:?}"
    );
    // A box whose face x = 0 holds the sensor: its top and bottom edges
    // there tie, but a motion along the face slides them along the tie
    // (tz: smooth, no caveat), while one across it is a kink (tx).
    let face_on = cube(
        "box",
        DVec3::new(0.15, 0.0, 1.15),
        0.15,
        Surface::Absorber,
        None,
    );
    let parameters = params(
        "box",
        &[("tx", Motion::TranslateX), ("tz", Motion::TranslateZ)],
    );
    let scene = Arc::new(Scene::new(vec![lamp(), face_on], parameters, up()).unwrap());
    for (m, caveats) in caveats_by_method(&scene) {
        let on = |name: &str| {
            caveats
                .iter()
                .any(|(c, _)| *c == Quantity::sensitivity(name))
        };
        assert!(on("tx") && !on("tz"), "{m}: {caveats:?}");
    }
}

#[test]
fn a_translation_seen_from_a_scattering_vertex_is_not_biased() {
    // A black box above a box of isotropic fog that holds the sensor, moved
    // along z. The warp's fibres for z ran from the fixed pole z at every
    // vertex, so the box's vertical edges lay along fibres, where the warp
    // cannot move them: right seen from the still sensor, but a scattering
    // vertex that a warped direction had moved sees them slide sideways.
    // Expectation read ∂I/∂tz 3 % off (−0.1096 ± 0.0007 and −0.1103 ±
    // 0.0008, marked reliable, against rendering's −0.10676 ± 0.00009).
    use geosens::mesh::cases::box_shape;
    let cuboid = |lo: DVec3, hi: DVec3| -> [DVec3; 8] {
        std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
    };
    let lamp = Shape {
        name: "lamp".into(),
        vertices: [(-0.7, -0.7), (0.7, -0.7), (0.7, 0.7), (-0.7, 0.7)]
            .map(|(x, y)| DVec3::new(x, y, 2.0))
            .to_vec(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Emitter { radiance: 1.0 },
        medium: None,
    };
    let fog = box_shape(
        "fog",
        cuboid(DVec3::new(-0.51, -0.33, 0.6), DVec3::new(0.29, 0.07, 1.0)),
        Surface::Transparent,
        Some(Medium {
            ks: 1.5,
            ke: 1.8,
            g: 0.0,
        }),
    );
    let black = box_shape(
        "abs",
        cuboid(DVec3::new(0.0, -0.2, 1.1), DVec3::new(0.2, 0.0, 1.3)),
        Surface::Absorber,
        None,
    );
    let sensor = Sensor::Irradiance {
        point: DVec3::new(-0.3, -0.17, 0.7),
        normal: DVec3::new(0.1, 0.1, 1.0).normalize(),
    };
    let parameters = params("abs", &[("abs_tz", Motion::TranslateZ)]);
    let scene = Arc::new(Scene::new(vec![lamp, fog, black], parameters, sensor).unwrap());
    let q = Quantity::sensitivity("abs_tz");
    let reference = estimate(&scene, Method::Rendering, 400_000, 11);
    let reference = reference.get(&q).unwrap();
    let e = estimate(&scene, Method::Expectation, 6_400_000, 3);
    let e = e.get(&q).unwrap();
    let z = (e.mean - reference.mean) / e.stderr.hypot(reference.stderr);
    assert!(z.abs() < 4.0, "{e:?} against rendering's {reference:?}");
}

/// A lamp 9 ulps of 9·10⁵ off edge-on (10⁻⁹ rad), 9·10⁵ from the origin
/// along its normal (campaign): I read 54σ and rendering's ∂I/∂tz 350σ
/// off the same scene at the origin, "reliable", the bias going as one
/// over the tilt in ulps. It is now an edge-on caveat (`kinks` allows for
/// the coordinates' rounding); at the origin, where every method agrees,
/// and 10⁻⁶ rad off edge-on at the same offset, it is not.
#[test]
fn a_lamp_a_few_ulps_off_edge_on_far_out_is_a_caveat() {
    let scene = |z: f64, far: f64| {
        let text = format!(
            r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0, {z:?}]
normal = [0.0, 1.0, 0.0]

[[shapes]]
name = "lamp"
vertices = [[-0.5, 1.0, {z:?}], [0.5, 1.0, {z:?}], [0.5, 2.0, {far:?}], [-0.5, 2.0, {far:?}]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "emitter", radiance = 1.0 }}

[[parameters]]
name = "rot"
shape = "lamp"
motion = {{ kind = "rotate", axis = [1.0, 0.0, 0.0], pivot = [0.0, 1.0, {z:?}] }}

[[parameters]]
name = "tz"
shape = "lamp"
motion = {{ kind = "translate_z" }}
"#
        );
        geosens::mesh::file::from_toml(&text).unwrap()
    };
    let caveated = |s: &Scene| geosens::mesh::methods::kinks(s).len();
    let delta = 9.0 * 2f64.powi(-33);
    assert_eq!(caveated(&scene(9e5, 9e5 + delta)), 2);
    assert_eq!(caveated(&scene(0.0, delta)), 0);
    assert_eq!(caveated(&scene(9e5, 9e5 + 1e-6)), 0);
}

/// Transport's sensor gradient across the plane of a face seen edge-on
/// (campaign: a lamp edge-on from the sensor over a reflecting floor, ∇z
/// 0.400 at the origin and 0.417 at 9·10⁵, "reliable"): a caveat on the
/// axes that cross the plane (z), none on the axes in it, none without
/// such a plane.
#[test]
fn the_sensor_gradient_across_an_edge_on_face_is_a_caveat() {
    let scene = |lamp_z: f64, floor_z: f64| {
        let text = format!(
            r#"
[sensor]
kind = "irradiance"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]

[[shapes]]
name = "lamp"
vertices = [[-0.5, 1.0, {lamp_z:?}], [0.5, 1.0, {lamp_z:?}], [0.5, 2.0, {lamp_z:?}], [-0.5, 2.0, {lamp_z:?}]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "emitter", radiance = 1.0 }}

[[shapes]]
name = "floor"
vertices = [[-1.0, -0.5, {floor_z:?}], [1.0, -0.5, {floor_z:?}], [1.0, 2.5, {floor_z:?}], [-1.0, 2.5, {floor_z:?}]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = {{ kind = "reflector", albedo = 0.8 }}
"#
        );
        geosens::mesh::file::from_toml(&text).unwrap()
    };
    let axes = |s: &Scene| -> Vec<String> {
        geosens::mesh::methods::plane_kinks_of_the_gradient(s)
            .into_iter()
            .map(|(q, _)| q.to_string())
            .collect()
    };
    // The lamp edge-on (its plane z = 0 holds the sensor, off the lamp).
    assert_eq!(
        axes(&scene(0.0, -0.5)),
        [Quantity::gradient("z").to_string()]
    );
    // The lamp above, the floor below: no plane through the sensor.
    assert!(axes(&scene(0.5, -0.5)).is_empty());
    // And the estimator carries it.
    let e = Method::Transport
        .estimator(Arc::new(scene(0.0, -0.5)))
        .unwrap();
    assert!(
        e.caveats()
            .iter()
            .any(|(q, _)| *q == Quantity::gradient("z"))
    );
}

/// A radiance sensor's ray that meets an absorbing medium's closed
/// boundary exactly at an edge or a vertex and only touches it stays
/// outside: `I` is the lamp's radiance, `e⁰ = 1`, by every method (the
/// walk had counted the touch as entering and read `e^{−κe·1}` ± 0,
/// reliable). A ray that crosses the boundary through edges (a cube's face
/// diagonals) and through a vertex still reads `e^{−κe ℓ}` with the chord
/// `ℓ` of the geometry. Each ray is the sensor's, so every path repeats it.
#[test]
fn a_sensor_ray_touching_a_medium_at_an_edge_or_vertex_stays_outside() {
    let lamp = r#"
[[shapes]]
name = "lamp"
vertices = [[-2.0, -2.0, 2.0], [2.0, -2.0, 2.0], [2.0, 2.0, 2.0], [-2.0, 2.0, 2.0]]
triangles = [[0, 1, 2], [0, 2, 3]]
surface = { kind = "emitter", radiance = 1.0 }
"#;
    let tetra = |vertices: &str| {
        format!(
            "[[shapes]]\nname = \"fog\"\nvertices = {vertices}\n\
             triangles = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]\n\
             surface = {{ kind = \"transparent\" }}\nmedium = {{ ks = 0.0, ke = 2.0 }}\n"
        )
    };
    let cube = "[[shapes]]\nname = \"fog\"\n\
        vertices = [[-0.4, -0.4, 0.6], [0.4, -0.4, 0.6], [-0.4, 0.4, 0.6], [0.4, 0.4, 0.6], \
        [-0.4, -0.4, 1.4], [0.4, -0.4, 1.4], [-0.4, 0.4, 1.4], [0.4, 0.4, 1.4]]\n\
        triangles = [[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4], \
        [2, 6, 7], [2, 7, 3], [0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5]]\n\
        surface = { kind = \"transparent\" }\nmedium = { ks = 0.0, ke = 1.5 }\n";
    let sensor = |point: &str, direction: &str| {
        format!("[sensor]\nkind = \"radiance\"\npoint = {point}\ndirection = {direction}\n")
    };
    let motion = "[[parameters]]\nname = \"fog_tz\"\nshape = \"fog\"\n\
                  motion = { kind = \"translate_z\" }\n";
    let cases = [
        // Along z, touching the edge (0, ±0.25, 1) from outside.
        (
            sensor("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]"),
            tetra("[[0.0, -0.25, 1.0], [0.0, 0.25, 1.0], [0.5, 0.0, 0.75], [0.5, 0.0, 1.5]]"),
            1.0,
        ),
        // Along z, touching the vertex (0, 0, 1) only.
        (
            sensor("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]"),
            tetra("[[0.0, 0.0, 1.0], [0.5, -0.25, 1.0], [0.5, 0.25, 0.9], [0.6, 0.0, 1.4]]"),
            1.0,
        ),
        // At 45°, grazing the cube's edge x = 0.4, z = 0.6 (the direction's
        // rounding puts the ray a hair inside one face).
        (
            sensor("[0.2, 0.0, 0.4]", "[1.0, 0.0, 1.0]"),
            cube.to_string(),
            1.0,
        ),
        // Through the cube along z: in and out through the faces' shared
        // diagonals, chord 0.8.
        (
            sensor("[0.0, 0.0, 0.0]", "[0.0, 0.0, 1.0]"),
            cube.to_string(),
            (-1.5f64 * 0.8).exp(),
        ),
        // Through the cube's corners (−0.4, −0.4, 0.6) and (0.4, 0.4, 1.4):
        // chord 0.8·√3.
        (
            sensor("[-0.6, -0.6, 0.4]", "[1.0, 1.0, 1.0]"),
            cube.to_string(),
            (-1.5f64 * 0.8 * 3f64.sqrt()).exp(),
        ),
    ];
    for (k, (sensor, fog, exact)) in cases.iter().enumerate() {
        let text = format!("{sensor}{lamp}{fog}{motion}");
        let scene = Arc::new(geosens::mesh::file::from_toml(&text).unwrap());
        for m in [
            Method::Intensity,
            Method::Expectation,
            Method::Rendering,
            Method::Transport,
        ] {
            let r = estimate(&scene, m, 2000, 4);
            let i = r.get(&Quantity::Intensity).unwrap();
            assert!(
                (i.mean - exact).abs() < 1e-9 * exact,
                "case {k}, {m}: I = {} ± {}, exact {exact}",
                i.mean,
                i.stderr
            );
        }
    }
}

/// Shadow edges 10⁻⁴ inside and outside the lamp's edges: the default
/// step of the finite differences carries them across, so the quotient
/// straddles the kinks where the shadow's edges start or stop cutting the
/// lamp (a campaign's occluder, one edge 10⁻⁴ inside: −0.1477 ± 0.0069
/// against the closed form's −0.0206, marked reliable; here 0.028 ± 0.010
/// against 0.386). The caveat says so. A step that stays on one side
/// carries none and matches the closed form; nor does the shipped
/// occluder, whose shadow edges lie far from the lamp's, get one.
#[test]
fn a_step_across_a_shadow_edge_reaching_the_lamps_is_a_caveat_for_finite_differences() {
    use geosens::mesh::exact::OccluderScene;
    // Left shadow edge at 2 (cx − 0.25) = −0.4999; the others far inside
    // or outside the lamp.
    let o = OccluderScene::shipped(0.00005, 0.05);
    let occ = o.occluder_shape();
    let exact = o.sensitivities().unwrap()[0];
    let scene = Arc::new(
        Scene::new(
            vec![lamp(), occ],
            params("occ", &[("tx", Motion::TranslateX)]),
            up(),
        )
        .unwrap(),
    );
    let fd = |step: f64| {
        let e = geosens::mesh::methods::finite_difference(&scene, step).unwrap();
        let caveats = geosens::Estimator::caveats(&e);
        let r = run(&e, &RunConfig::new(400_000, 7).unwrap()).unwrap();
        (caveats, r.get(&Quantity::sensitivity("tx")).unwrap())
    };
    let (caveats, wide) = fd(1e-3);
    eprintln!("step 1e-3: {wide:?} vs exact {exact}; {caveats:?}");
    assert!(
        caveats
            .iter()
            .any(|(q, why)| *q == Quantity::sensitivity("tx") && why.contains("sweeps")),
        "{caveats:?}"
    );
    // The caveat is needed: the quotient is far off.
    assert!(wide.z_score(exact) > 6.0, "{wide:?} vs {exact}");
    let (caveats, narrow) = fd(2e-5);
    eprintln!("step 2e-5: {narrow:?} vs exact {exact}; {caveats:?}");
    assert!(caveats.is_empty(), "{caveats:?}");
    assert!(narrow.z_score(exact) < 4.0, "{narrow:?} vs {exact}");
    let shipped = Arc::new(
        geosens::mesh::file::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scenes/mesh/occluder.toml"
        )))
        .unwrap(),
    );
    let caveats = geosens::Estimator::caveats(
        &geosens::mesh::methods::finite_difference(&shipped, 1e-3).unwrap(),
    );
    assert!(caveats.is_empty(), "{caveats:?}");
}
