//! The path core's derivative walks against the closed form where the old
//! walks failed: a lamp too small or too grazing to be hit by chance (the
//! walks now connect to lamps by next-event estimation) and two corners
//! seen in the same direction to within 10⁻⁹ rad (the corner's jump is now
//! evaluated exactly at the corner, not by two rays at ±10⁻⁷ rad).
use geosens::flat::cases as stability;
use geosens::flat::exact::Reference;
use geosens::flat::space::Plane;
use geosens::flat::{Method, Motion, Parameter, Scene, Sensor, Shape, Surface};
use geosens::path::intensity::PlainEstimator;
use geosens::{Estimator, Quantity, RunConfig, run};
use glam::DVec2;
use std::sync::Arc;

fn segment(name: &str, a: [f64; 2], b: [f64; 2], surface: Surface) -> Shape {
    Shape {
        name: name.into(),
        vertices: vec![DVec2::from(a), DVec2::from(b)],
        closed: false,
        surface,
        medium: None,
    }
}

fn parameter(name: &str, shape: &str, motion: Motion) -> Parameter {
    Parameter {
        name: name.into(),
        shape: shape.into(),
        motion,
        bounds: None,
    }
}

/// Every method's `I` and sensitivities against the closed form, within 4
/// standard errors; returns `(method, σ of I)` per method.
fn check_against_closed_form(scene: Arc<Scene>, paths: u64, seed: u64) -> Vec<(Method, f64)> {
    let reference = Reference::for_scene(&scene).unwrap();
    let mut sigma = Vec::new();
    for method in [
        Method::Intensity,
        Method::Rendering,
        Method::Expectation,
        Method::Transport,
    ] {
        let e = method.estimator(scene.clone()).unwrap();
        let r = run(e.as_ref(), &RunConfig::new(paths, seed).unwrap()).unwrap();
        let i = r.get(&Quantity::Intensity).unwrap();
        let exact = reference.value();
        assert!(i.stderr > 0.0, "{}: I = {i:?}", method.name());
        assert!(
            i.z_score(exact) < 4.0,
            "{}: I = {i:?}, exact {exact}",
            method.name()
        );
        sigma.push((method, i.stderr));
        if method == Method::Intensity {
            continue;
        }
        for (j, p) in scene.parameters().iter().enumerate() {
            let s = r.get(&Quantity::sensitivity(&p.name)).unwrap();
            let exact = reference.derivative(j);
            assert!(s.stderr > 0.0, "{} {}: {s:?}", method.name(), p.name);
            assert!(
                s.z_score(exact) < 4.0,
                "{} {}: {s:?}, exact {exact}",
                method.name(),
                p.name
            );
        }
    }
    sigma
}

fn irradiance_up() -> Sensor {
    Sensor::Irradiance {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    }
}

#[test]
fn derivative_walks_connect_to_a_small_lamp() {
    // A lamp 10⁻³ long half hidden by an occluder: a path finds it by chance
    // once in ~10⁴ directions.
    let scene = Scene::new(
        vec![
            segment(
                "lamp",
                [0.4995, 2.0],
                [0.5005, 2.0],
                Surface::Emitter { radiance: 1.0 },
            ),
            segment("occ", [-0.6, 1.0], [0.25, 1.0], Surface::Absorber),
        ],
        vec![
            parameter("occ_tx", "occ", Motion::TranslateX),
            parameter("occ_rotate", "occ", Motion::Rotate { pivot: None }),
            parameter("lamp_tx", "lamp", Motion::TranslateX),
            parameter("lamp_ty", "lamp", Motion::TranslateY),
        ],
        irradiance_up(),
    )
    .unwrap();
    let sigma = check_against_closed_form(Arc::new(scene), 200_000, 5);
    // As well estimated as by the intensity estimator: the same connection.
    let intensity = sigma[0].1;
    for (m, s) in &sigma[1..] {
        assert!(
            *s < 1.5 * intensity,
            "{}: σ(I) {s} vs {intensity}",
            m.name()
        );
    }
}

#[test]
fn derivative_walks_connect_to_a_grazing_lamp() {
    // A lamp seen almost edge-on (2·10⁻⁴ rad) that moves and turns, partly
    // hidden.
    let scene = Scene::new(
        vec![
            segment(
                "lamp",
                [0.5, 1.0],
                [1.0, 2.001],
                Surface::Emitter { radiance: 2.0 },
            ),
            segment("occ", [-0.2, 0.8], [0.39992, 0.8], Surface::Absorber),
        ],
        vec![
            parameter("lamp_tx", "lamp", Motion::TranslateX),
            parameter("lamp_rotate", "lamp", Motion::Rotate { pivot: None }),
            parameter("lamp_scale", "lamp", Motion::Scale { pivot: None }),
            parameter("occ_ty", "occ", Motion::TranslateY),
        ],
        irradiance_up(),
    )
    .unwrap();
    let sigma = check_against_closed_form(Arc::new(scene), 200_000, 6);
    let intensity = sigma[0].1;
    for (m, s) in &sigma[1..] {
        assert!(
            *s < 1.5 * intensity,
            "{}: σ(I) {s} vs {intensity}",
            m.name()
        );
    }
}

#[test]
fn corners_in_the_same_direction_give_the_closed_form() {
    // The occluder's end seen 10⁻⁹ (along x at y = 1, ~4·10⁻¹⁰ rad) inside
    // the lamp's end: two rays at ±10⁻⁷ rad both miss what lies between.
    let scene = Arc::new(stability::knots(1e-9).unwrap());
    let exact = Reference::for_scene(&scene).unwrap().derivative(0);
    for method in [Method::Rendering, Method::Transport] {
        let e = method.estimator(scene.clone()).unwrap();
        let r = run(e.as_ref(), &RunConfig::new(400_000, 8).unwrap()).unwrap();
        let s = r.get(&Quantity::sensitivity("p")).unwrap();
        assert!(
            s.z_score(exact) < 4.0 && s.stderr < 0.05 * exact.abs(),
            "{}: {s:?}, exact {exact}",
            method.name()
        );
    }
}

#[test]
fn forty_parameters_on_one_path() {
    // Twenty copies each of two motions of the occluder: every copy gets the
    // closed form's derivative, from the same paths, with no cap in the way.
    let mut parameters = Vec::new();
    for i in 0..20 {
        parameters.push(parameter(&format!("tx{i}"), "occ", Motion::TranslateX));
        parameters.push(parameter(
            &format!("rot{i}"),
            "occ",
            Motion::Rotate {
                pivot: Some(DVec2::new(-0.2, 1.0)),
            },
        ));
    }
    let scene = Arc::new(
        Scene::new(
            vec![
                segment(
                    "lamp",
                    [-1.0, 2.0],
                    [1.0, 2.0],
                    Surface::Emitter { radiance: 1.0 },
                ),
                segment("occ", [-0.6, 1.0], [0.2, 1.0], Surface::Absorber),
            ],
            parameters,
            irradiance_up(),
        )
        .unwrap(),
    );
    let reference = Reference::for_scene(&scene).unwrap();
    for method in [Method::Rendering, Method::Expectation, Method::Transport] {
        let e = method.estimator(scene.clone()).unwrap();
        let r = run(e.as_ref(), &RunConfig::new(50_000, 3).unwrap()).unwrap();
        for (j, p) in scene.parameters().iter().enumerate() {
            let s = r.get(&Quantity::sensitivity(&p.name)).unwrap();
            let first = r.get(&Quantity::sensitivity(&scene.parameters()[j % 2].name));
            assert_eq!(Some(s), first, "{} {}", method.name(), p.name);
            let exact = reference.derivative(j);
            assert!(
                s.z_score(exact) < 4.0,
                "{} {}: {s:?} vs {exact}",
                method.name(),
                p.name
            );
        }
    }
}

#[test]
fn too_many_parameters_is_a_clear_error() {
    let parameters = (0..254)
        .map(|i| parameter(&format!("p{i}"), "occ", Motion::TranslateX))
        .collect();
    let e = Scene::new(
        vec![
            segment(
                "lamp",
                [-1.0, 2.0],
                [1.0, 2.0],
                Surface::Emitter { radiance: 1.0 },
            ),
            segment("occ", [-0.6, 1.0], [0.2, 1.0], Surface::Absorber),
        ],
        parameters,
        irradiance_up(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("254 parameters: at most 253"), "{e}");
}

#[test]
fn a_thick_conservative_fog_does_not_collapse_to_zero() {
    // κs = κe = 20 over a box 2 wide around the sensor: paths need ~10³
    // collisions to leave it. A survival probability capped at 0.95 per
    // event returned ~0 with a small error bar; roulette on the weight lets
    // every path walk out. Two independent estimators of I agree.
    let fog = Shape {
        name: "fog".into(),
        vertices: vec![
            DVec2::new(-1.0, -0.5),
            DVec2::new(1.0, -0.5),
            DVec2::new(1.0, 1.5),
            DVec2::new(-1.0, 1.5),
        ],
        closed: true,
        surface: Surface::Transparent,
        medium: Some(geosens::flat::Medium {
            ks: 20.0,
            ke: 20.0,
            phase: geosens::flat::Phase::Isotropic,
        }),
    };
    let scene = Arc::new(
        Scene::new(
            vec![
                segment(
                    "lamp",
                    [-1.0, 2.0],
                    [1.0, 2.0],
                    Surface::Emitter { radiance: 1.0 },
                ),
                fog,
            ],
            vec![],
            irradiance_up(),
        )
        .unwrap(),
    );
    let cfg = RunConfig::new(20_000, 2).unwrap();
    let e = Method::Intensity.estimator(scene.clone()).unwrap();
    let nee = run(e.as_ref(), &cfg)
        .unwrap()
        .get(&Quantity::Intensity)
        .unwrap();
    let plain = PlainEstimator {
        geometry: Plane::new(scene),
    };
    let plain = run(&plain, &cfg)
        .unwrap()
        .get(&Quantity::Intensity)
        .unwrap();
    assert!(nee.stderr < 0.05 * nee.mean, "{nee:?}");
    let z = (nee.mean - plain.mean).abs() / nee.stderr.hypot(plain.stderr);
    assert!(z < 4.0, "NEE {nee:?} vs plain {plain:?}");
}

#[test]
fn finite_differences_warn_when_the_step_changes_what_the_sensor_sees() {
    // An occluder's corner 10⁻⁴ above the sensor: the default half step
    // (10⁻³ × size) carries it past the sensor's zenith both ways, and the
    // quotient gave −223.5 ± 0.3 for an exact −10⁴, reported reliable.
    let scene = Arc::new(
        Scene::new(
            vec![
                segment(
                    "lamp",
                    [-1.0, 2.0],
                    [1.0, 2.0],
                    Surface::Emitter { radiance: 1.0 },
                ),
                segment("occ", [-0.6, 1e-4], [0.0, 1e-4], Surface::Absorber),
            ],
            vec![parameter("occ_tx", "occ", Motion::TranslateX)],
            irradiance_up(),
        )
        .unwrap(),
    );
    let exact = Reference::for_scene(&scene).unwrap().derivative(0);
    let coarse = Method::Fd.estimator(scene.clone()).unwrap();
    let caveats = coarse.caveats();
    assert_eq!(caveats.len(), 1, "{caveats:?}");
    assert!(caveats[0].1.contains("occ_tx"), "{caveats:?}");
    // A step well inside the corner's height sees one view both ways, and
    // the quotient the closed form.
    let fine = geosens::flat::methods::finite_difference(&scene, 1e-6).unwrap();
    assert!(fine.caveats().is_empty(), "{:?}", fine.caveats());
    let r = run(&fine, &RunConfig::new(200_000, 3).unwrap()).unwrap();
    let s = r.get(&Quantity::sensitivity("occ_tx")).unwrap();
    assert!(s.z_score(exact) < 4.0, "{s:?} vs {exact}");
}

#[test]
fn the_shipped_scenes_raise_no_finite_difference_caveat() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = Arc::new(geosens::flat::file::load(&path).unwrap());
            let fd = Method::Fd.estimator(scene).unwrap();
            assert!(
                fd.caveats().is_empty(),
                "{}: {:?}",
                path.display(),
                fd.caveats()
            );
        }
    }
}

#[test]
fn a_reflectors_concave_corner_lights_itself() {
    // The sensor looks into an asymmetric V-shaped reflector: the corner's
    // two faces see each other near it. Rendering and transport evaluate the
    // corner's jump with paths leaving each face there; expectation has no
    // jump term at all (its warp follows the corner), so it is an
    // independent reference.
    let vee = Shape {
        name: "vee".into(),
        vertices: vec![
            DVec2::new(-1.0, 1.9),
            DVec2::new(0.0, 1.0),
            DVec2::new(1.0, 1.4),
        ],
        closed: false,
        surface: Surface::Reflector { albedo: 0.9 },
        medium: None,
    };
    let scene = Arc::new(
        Scene::new(
            vec![
                segment(
                    "lamp",
                    [-2.0, 3.0],
                    [0.5, 3.0],
                    Surface::Emitter { radiance: 1.0 },
                ),
                vee,
            ],
            vec![
                parameter("vee_tx", "vee", Motion::TranslateX),
                parameter(
                    "vee_rot",
                    "vee",
                    Motion::Rotate {
                        pivot: Some(DVec2::new(0.3, 1.2)),
                    },
                ),
            ],
            Sensor::Irradiance {
                point: DVec2::new(0.25, 1.5),
                normal: -DVec2::Y,
            },
        )
        .unwrap(),
    );
    let cfg = RunConfig::new(1_000_000, 5).unwrap();
    let get = |m: Method| {
        let r = run(m.estimator(scene.clone()).unwrap().as_ref(), &cfg).unwrap();
        ["vee_tx", "vee_rot"].map(|p| r.get(&Quantity::sensitivity(p)).unwrap())
    };
    let reference = get(Method::Expectation);
    for m in [Method::Rendering, Method::Transport] {
        for (s, e) in get(m).iter().zip(&reference) {
            let z = (s.mean - e.mean).abs() / s.stderr.hypot(e.stderr);
            assert!(z < 4.0, "{}: {s:?} vs expectation {e:?}", m.name());
        }
    }
}
