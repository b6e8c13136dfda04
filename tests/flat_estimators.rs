//! Every flatland estimator against an independent reference, within 4
//! standard errors at fixed seeds: the closed-form irradiance behind moving
//! occluders and the quadrature through an absorbing slab
//! (`flat::exact`), and, for scattering media and reflectors, central
//! finite differences with common random numbers at a larger step and a
//! higher path count (step 10⁻² of the scene size: its O(h²) bias is far
//! under the bounds' standard errors wherever the derivative is smooth).
use geosens::flat::exact::Reference;
use geosens::flat::methods::finite_difference;
use geosens::flat::space::Plane;
use geosens::flat::{Method, Scene, file};
use geosens::path::intensity::PlainEstimator;
use geosens::{Estimate, Quantity, RunConfig, RunResult, run};
use std::path::Path;
use std::sync::Arc;

const DERIVATIVE_METHODS: [Method; 4] = [
    Method::Rendering,
    Method::Expectation,
    Method::Transport,
    Method::Fd,
];

fn scene(name: &str) -> Arc<Scene> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    Arc::new(file::load(&path).unwrap())
}

fn estimate(method: Method, scene: &Arc<Scene>, paths: u64, seed: u64) -> RunResult {
    let e = method.estimator(scene.clone()).unwrap();
    run(e.as_ref(), &RunConfig::new(paths, seed).unwrap()).unwrap()
}

/// The estimate of `I` (`j = None`) or of parameter `j`'s sensitivity.
fn get(r: &RunResult, scene: &Scene, j: Option<usize>) -> Estimate {
    let q = match j {
        None => Quantity::Intensity,
        Some(j) => Quantity::sensitivity(&scene.parameters()[j].name),
    };
    r.get(&q).unwrap()
}

/// Largest standard error, as a fraction of `max(|reference|, floor)`, for
/// which a comparison with the analytic reference means something: 4
/// standard errors are then a fifth of the value, so an estimator off by a
/// factor, missing a term or returning 0 fails (the 3D tests' rule,
/// `tests/mesh_methods.rs`). The floor is 0 for `I` (relative error, as for
/// the 3D tests' `E`) and, for a sensitivity, a quarter of the scene's
/// largest `|∂I/∂π|`, so that a value near 0 is resolved to 1.25 % of that
/// (the 3D tests' floors: 0.02–0.05 for derivatives up to about 0.3).
const RESOLUTION: f64 = 0.05;

/// [`RESOLUTION`] for central finite differences (`Method::Fd` against the
/// closed form): their error bar is that of the few paths whose outcome the
/// step changes, over the step, wider than a derivative method's at the same
/// count (the 3D tests bound theirs at 0.15).
const FD_RESOLUTION: f64 = 0.15;

/// [`RESOLUTION`] against finite differences: the combined error bar
/// (estimate's and reference's) may reach twice as far, a tenth of the
/// value (the 3D tests' bound against finite differences).
const FD_REFERENCE_RESOLUTION: f64 = 0.1;

/// The floor of [`RESOLUTION`]: 0 for `I` (`j = None`), a quarter of the
/// largest of `sensitivities` for parameter `j`'s.
fn floor(j: Option<usize>, sensitivities: impl Iterator<Item = f64>) -> f64 {
    j.map_or(0.0, |_| {
        0.25 * sensitivities.fold(0.0, |m, s| s.abs().max(m))
    })
}

/// Asserts the error bar `sigma` of a comparison resolves `reference`: at
/// most `fraction` of the larger of `|reference|` and `floor`.
fn assert_resolves(what: &str, sigma: f64, reference: f64, floor: f64, fraction: f64) {
    let bound = fraction * reference.abs().max(floor);
    assert!(
        sigma <= bound,
        "{what}: error bar {sigma} does not resolve {reference} (above {bound})"
    );
}

/// Every method's `I` and `∂I/∂π` against the analytic reference, with an
/// error bar that resolves it.
fn against_reference(name: &str, paths: u64) {
    let scene = scene(name);
    let reference = Reference::for_scene(&scene).unwrap();
    let sensitivities = || (0..scene.parameters().len()).map(|j| reference.derivative(j));
    for (seed, method) in DERIVATIVE_METHODS.into_iter().enumerate() {
        let fraction = if method == Method::Fd {
            FD_RESOLUTION
        } else {
            RESOLUTION
        };
        let r = estimate(method, &scene, paths, 11 + seed as u64);
        for j in std::iter::once(None).chain((0..scene.parameters().len()).map(Some)) {
            let e = get(&r, &scene, j);
            let exact = j.map_or(reference.value(), |j| reference.derivative(j));
            let z = e.z_score(exact);
            eprintln!(
                "{name} {} {j:?}: {:.5} ± {:.5} vs exact {exact:.5}, z = {z:.2}",
                method.name(),
                e.mean,
                e.stderr
            );
            assert!(
                e.stderr > 0.0 && z < 4.0,
                "{name} {} {j:?}: {} ± {} vs exact {exact} (z = {z:.2})",
                method.name(),
                e.mean,
                e.stderr
            );
            assert_resolves(
                &format!("{name} {} {j:?}", method.name()),
                e.stderr,
                exact,
                floor(j, sensitivities()),
                fraction,
            );
        }
    }
}

#[test]
fn transport_gradient_at_the_sensor_matches_the_closed_form() {
    for name in [
        "occluder.toml",
        "polygon_occluder.toml",
        "absorbing_slab.toml",
    ] {
        let scene = scene(name);
        let (gx, gy) = Reference::for_scene(&scene).unwrap().gradient();
        let r = estimate(Method::Transport, &scene, 400_000, 8);
        for (axis, exact) in [("x", gx), ("y", gy)] {
            let e = r.get(&Quantity::gradient(axis)).unwrap();
            assert!(
                e.stderr > 0.0 && e.z_score(exact) < 4.0,
                "{name} ∂I/∂{axis}: {e:?} vs {exact}"
            );
            let floor = 0.25 * gx.abs().max(gy.abs());
            let what = format!("{name} ∂I/∂{axis}");
            assert_resolves(&what, e.stderr, exact, floor, RESOLUTION);
        }
    }
}

#[test]
fn segment_occluder_matches_the_closed_form() {
    against_reference("occluder.toml", 400_000);
}

#[test]
fn polygon_occluder_matches_the_closed_form() {
    against_reference("polygon_occluder.toml", 400_000);
}

#[test]
fn absorbing_slab_matches_the_quadrature() {
    against_reference("absorbing_slab.toml", 400_000);
}

#[test]
fn the_intensity_estimator_matches_the_closed_form() {
    for name in [
        "occluder.toml",
        "polygon_occluder.toml",
        "absorbing_slab.toml",
    ] {
        let scene = scene(name);
        let exact = Reference::for_scene(&scene).unwrap().value();
        let e = get(
            &estimate(Method::Intensity, &scene, 400_000, 5),
            &scene,
            None,
        );
        assert!(e.z_score(exact) < 4.0, "{name}: {e:?} vs {exact}");
        assert_resolves(name, e.stderr, exact, 0.0, RESOLUTION);
    }
}

/// Scenes without a closed form: every method against CRN finite
/// differences with a 10× larger step at `fd_paths`.
fn against_finite_differences(name: &str, paths: u64, fd_paths: u64) {
    scene_against_finite_differences(name, &scene(name), paths, fd_paths);
}

fn scene_against_finite_differences(name: &str, scene: &Arc<Scene>, paths: u64, fd_paths: u64) {
    scene_against_finite_differences_with_step(name, scene, paths, fd_paths, 1e-2);
}

/// [`scene_against_finite_differences`] with the step `h`.
fn scene_against_finite_differences_with_step(
    name: &str,
    scene: &Arc<Scene>,
    paths: u64,
    fd_paths: u64,
    h: f64,
) {
    let scene = scene.clone();
    let fd = finite_difference(&scene, h).unwrap();
    let reference = run(&fd, &RunConfig::new(fd_paths, 99).unwrap()).unwrap();
    let sensitivities =
        || (0..scene.parameters().len()).map(|j| get(&reference, &scene, Some(j)).mean);
    for (seed, method) in [Method::Rendering, Method::Expectation, Method::Transport]
        .into_iter()
        .enumerate()
    {
        let r = estimate(method, &scene, paths, 21 + seed as u64);
        for j in std::iter::once(None).chain((0..scene.parameters().len()).map(Some)) {
            let (e, f) = (get(&r, &scene, j), get(&reference, &scene, j));
            let sigma = e.stderr.hypot(f.stderr);
            let z = (e.mean - f.mean).abs() / sigma;
            eprintln!(
                "{name} {} {j:?}: {:.5} ± {:.5} vs fd {:.5} ± {:.5}, z = {z:.2}",
                method.name(),
                e.mean,
                e.stderr,
                f.mean,
                f.stderr
            );
            assert!(
                e.stderr > 0.0 && z < 4.0,
                "{name} {} {j:?}: {} ± {} vs finite differences {} ± {} (z = {z:.2})",
                method.name(),
                e.mean,
                e.stderr,
                f.mean,
                f.stderr
            );
            assert_resolves(
                &format!("{name} {} {j:?} against finite differences", method.name()),
                sigma,
                f.mean,
                floor(j, sensitivities()),
                FD_REFERENCE_RESOLUTION,
            );
        }
    }
}

#[test]
fn fog_matches_finite_differences() {
    against_finite_differences("fog.toml", 400_000, 2_000_000);
}

#[test]
fn reflector_matches_finite_differences() {
    // 800 000 paths: at 400 000 the error bars on the reflector's turn and
    // the occluder's move reached 11 % of their ∂I/∂π.
    against_finite_differences("reflector.toml", 800_000, 2_000_000);
}

/// A lamp segment from `lamp.0` to `lamp.1` over one open reflecting
/// polyline `shape` (albedo `albedo`) that `motions` move, seen by an
/// irradiance sensor at `point` facing `normal`.
fn lamp_over_reflector(
    lamp: [[f64; 2]; 2],
    (name, vertices, albedo): (&str, Vec<[f64; 2]>, f64),
    motions: Vec<(&str, geosens::flat::Motion)>,
    (point, normal): ([f64; 2], [f64; 2]),
) -> Arc<Scene> {
    use geosens::flat::{Parameter, Sensor, Shape, Surface};
    use glam::DVec2;
    let v = |p: [f64; 2]| DVec2::new(p[0], p[1]);
    let shape = |name: &str, vertices: Vec<[f64; 2]>, surface| Shape {
        name: name.into(),
        vertices: vertices.into_iter().map(v).collect(),
        closed: false,
        surface,
        medium: None,
    };
    let shapes = vec![
        shape("lamp", lamp.to_vec(), Surface::Emitter { radiance: 1.0 }),
        shape(name, vertices, Surface::Reflector { albedo }),
    ];
    let parameters = motions
        .into_iter()
        .map(|(p, motion)| Parameter {
            name: p.into(),
            shape: name.into(),
            motion,
            bounds: None,
        })
        .collect();
    let sensor = Sensor::Irradiance {
        point: v(point),
        normal: v(normal).normalize(),
    };
    Arc::new(Scene::new(shapes, parameters, sensor).unwrap())
}

#[test]
fn a_steep_gap_before_a_reflecting_vault_matches_finite_differences() {
    // The occluder scene under a wavy reflecting vault of 400 segments, one
    // of whose corners the sensor sees 10⁻⁴ rad past the occluder's moving
    // end: a steep gap of the expectation method's warp, drawn on its own
    // at the sensor (`flat::sensor_gaps`), and seen again from the vault.
    let step = (std::f64::consts::PI - 0.2) / 400.0;
    let corner = 1.0f64.atan2(0.2) + 1e-4; // past the occluder's end (0.2, 1)
    let shift = corner - 0.1 - ((corner - 0.1) / step).round() * step;
    let scene = Arc::new(geosens::flat::cases::vault(400, shift).unwrap());
    // The irradiance kinks each time the occluder's shadow on the vault
    // crosses a vault corner (about 0.008 apart): a small step keeps the
    // finite difference off the smoothed slope.
    scene_against_finite_differences_with_step("steep gap", &scene, 200_000, 2_000_000, 2e-3);
}

#[test]
fn a_wavy_reflector_matches_finite_differences() {
    // A floor of 24 reflecting segments under a lamp, seen from above: every
    // corner between two of its faces, convex or concave, turns under
    // `rendering::SHARED_TURN` and is a jump between two reflector faces
    // drawn from shared draws (`nested::reflected_jump`), seen from the sensor
    // and from the floor itself; moved up and turned.
    use geosens::flat::Motion;
    let floor = (0..=24)
        .map(|i| {
            let x = -2.0 + 4.0 * i as f64 / 24.0;
            [x, 0.08 * (7.0 * x).sin() + 0.03 * x]
        })
        .collect();
    let scene = lamp_over_reflector(
        [[-1.0, 2.0], [0.7, 2.1]],
        ("floor", floor, 0.8),
        vec![
            ("floor_ty", Motion::TranslateY),
            (
                "floor_rot",
                Motion::Rotate {
                    pivot: Some(glam::DVec2::new(0.3, 0.0)),
                },
            ),
        ],
        ([0.1, 0.6], [0.0, -1.0]),
    );
    scene_against_finite_differences("wavy floor", &scene, 400_000, 2_000_000);
}

#[test]
fn a_reflecting_ridge_between_light_and_shade_matches_finite_differences() {
    // A low tent-shaped reflector (its faces turn 30°, under
    // `rendering::SHARED_TURN`) lit from low on the left, seen from above:
    // its left face bright, its right face in its own shade, so its
    // translation's derivative is mostly the jump across the ridge between
    // two reflector faces (`nested::reflected_jump`), and its rotation's too
    // in part.
    use geosens::flat::Motion;
    let scene = lamp_over_reflector(
        [[-3.0, 0.3], [-2.6, 0.9]],
        ("tent", vec![[-1.0, 0.0], [0.05, 0.28], [1.1, 0.0]], 0.7),
        vec![
            ("tent_tx", Motion::TranslateX),
            (
                "tent_rot",
                Motion::Rotate {
                    pivot: Some(glam::DVec2::new(0.2, 0.1)),
                },
            ),
        ],
        ([0.25, 1.4], [0.0, -1.0]),
    );
    scene_against_finite_differences("ridge", &scene, 400_000, 2_000_000);
}

#[test]
fn a_reflecting_corner_lit_through_itself_matches_finite_differences() {
    // An overhanging wall over a floor, one reflector: the lamp lights the
    // floor, the wall only through the floor, and the sensor sees the
    // concave corner between them, so the jump there carries the light the
    // wall gathers from the floor. The faces turn 125°, past
    // `rendering::SHARED_TURN`: two nested paths with common random numbers
    // (with shared draws rendering's variance here was four times larger).
    use geosens::flat::Motion;
    let scene = lamp_over_reflector(
        [[-0.4, 2.5], [0.6, 2.6]],
        ("corner", vec![[-0.3, 1.0], [-1.0, 0.0], [1.6, 0.05]], 0.9),
        vec![
            ("corner_tx", Motion::TranslateX),
            ("corner_ty", Motion::TranslateY),
        ],
        ([0.3, 0.35], [-1.0, -0.2]),
    );
    // 1.2·10⁶ paths: at 400 000 rendering's and transport's error bars (the
    // nested paths' jumps) reached 18 % of ∂I/∂corner_ty.
    scene_against_finite_differences("corner", &scene, 1_200_000, 2_000_000);
}

#[test]
fn radiance_through_fog_matches_finite_differences() {
    against_finite_differences("radiance.toml", 400_000, 2_000_000);
}

#[test]
fn moving_surfaces_inside_a_medium_match_finite_differences() {
    against_finite_differences("submerged.toml", 400_000, 2_000_000);
}

#[test]
fn three_shapes_match_finite_differences() {
    against_finite_differences("three_shapes.toml", 200_000, 1_000_000);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let scene = scene("three_shapes.toml");
    for method in DERIVATIVE_METHODS {
        let e = method.estimator(scene.clone()).unwrap();
        let one = run(e.as_ref(), &RunConfig::new(9_000, 3).unwrap().threads(1)).unwrap();
        let two = run(e.as_ref(), &RunConfig::new(9_000, 3).unwrap().threads(2)).unwrap();
        assert_eq!(one.estimates, two.estimates, "{}", method.name());
    }
}

#[test]
fn next_event_estimation_agrees_with_plain_path_tracing() {
    // The intensity estimator connects every collision and reflection (and
    // an irradiance sensor) to a point drawn on the lamps, weighted against
    // the lobe by multiple importance sampling; plain path tracing finds
    // lamps only by hitting them. Two independent estimators of I.
    for name in [
        "fog.toml",
        "reflector.toml",
        "submerged.toml",
        "radiance.toml",
        "three_shapes.toml",
    ] {
        let scene = scene(name);
        let nee = get(
            &estimate(Method::Intensity, &scene, 1_000_000, 31),
            &scene,
            None,
        );
        let plain = {
            let e = PlainEstimator {
                geometry: Plane::new(scene.clone()),
            };
            let r = run(&e, &RunConfig::new(1_000_000, 32).unwrap()).unwrap();
            r.get(&Quantity::Intensity).unwrap()
        };
        let z = (nee.mean - plain.mean).abs() / (nee.stderr.powi(2) + plain.stderr.powi(2)).sqrt();
        eprintln!("{name}: NEE {nee:?} plain {plain:?} z = {z:.2}");
        assert!(
            z < 4.0,
            "{name}: NEE {nee:?} vs plain {plain:?} (z = {z:.2})"
        );
        assert!(
            nee.stderr < plain.stderr,
            "{name}: NEE does not serve: {nee:?} vs {plain:?}"
        );
    }
}

#[test]
fn finite_differences_take_any_number_of_parameters_and_name_a_bad_displacement() {
    use geosens::Problem;
    let scene = scene("three_shapes.toml");
    // I and twelve sensitivities, in declaration order, from one estimator.
    let fd = Method::Fd.estimator(&scene).unwrap();
    let names: Vec<String> = scene.parameters().iter().map(|p| p.name.clone()).collect();
    let want: Vec<Quantity> = std::iter::once(Quantity::Intensity)
        .chain(names.iter().map(|n| Quantity::sensitivity(n)))
        .collect();
    assert_eq!(fd.quantities(), want);
    // A step that pushes the block into the fog.
    for e in [
        scene.estimator(Method::Fd, Some(0.1)).err().unwrap(),
        finite_difference(&scene, 0.1).err().unwrap(),
    ] {
        let e = e.to_string();
        for w in [
            "finite differences",
            "\"block_tx\"",
            "+0.3",
            "touch or cross",
        ] {
            assert!(e.contains(w), "{w:?} not in {e}");
        }
    }
}

/// Transport carries the nested frozen walks of a moving reflector on the
/// path itself, in a twin slot per parameter, where twins fit in a walk's
/// slots (up to 126 parameters); past that it walks them. The two must
/// agree: the submerged wedge (a moving reflector in fog) with 130 copies
/// of its translation, every original parameter against the same scene's
/// twin-carried estimate, and every copy equal to the first.
#[test]
fn transport_with_and_without_twins_agrees() {
    use geosens::flat::Parameter;
    let base = scene("submerged.toml");
    let mut parameters = base.parameters().to_vec();
    let wedge = parameters
        .iter()
        .find(|p| p.name == "wedge_tx")
        .unwrap()
        .clone();
    for k in 0..130 {
        parameters.push(Parameter {
            name: format!("wedge_tx_{k}"),
            ..wedge.clone()
        });
    }
    let many = Arc::new(Scene::new(base.shapes().to_vec(), parameters, base.sensor()).unwrap());
    let twins = estimate(Method::Transport, &base, 400_000, 71);
    let walked = estimate(Method::Transport, &many, 400_000, 72);
    for j in 0..base.parameters().len() {
        let (a, b) = (get(&twins, &base, Some(j)), get(&walked, &many, Some(j)));
        let z = (a.mean - b.mean) / (a.stderr.powi(2) + b.stderr.powi(2)).sqrt();
        eprintln!(
            "{}: twins {a:?}, walked {b:?}, z = {z:.2}",
            base.parameters()[j].name
        );
        assert!(z.abs() < 4.0, "{}: z = {z:.2}", base.parameters()[j].name);
    }
    // The two runs took the two routes: twins where a parameter moves a
    // reflector and they fit, none past 126 parameters, nor without a
    // moving reflector.
    use geosens::flat::methods::derivative;
    use geosens::path::estimator::Scheme;
    let twins = |s: &Arc<Scene>| derivative(s.clone(), Scheme::Transport).slots.twins;
    assert_eq!(twins(&base), base.parameters().len());
    assert_eq!(twins(&many), 0);
    assert_eq!(twins(&scene("occluder.toml")), 0);
    let first = walked.get(&Quantity::sensitivity("wedge_tx")).unwrap();
    let copy = walked.get(&Quantity::sensitivity("wedge_tx_129")).unwrap();
    assert_eq!(first.mean, copy.mean);
}

/// A radiance sensor's ray that meets an absorbing polygon exactly at a
/// corner and only touches it stays outside: `I` is the lamp's radiance,
/// `e⁰ = 1`, by every method (the walk had counted the touch as entering
/// and read `e^{−2·1}` ± 0, reliable). A ray that leaves through a corner
/// still reads `e^{−κe ℓ}`, chord `ℓ = 0.3`; one that enters and leaves
/// through corners (a diamond's), `ℓ = 0.6`.
#[test]
fn a_sensor_ray_touching_a_medium_at_a_corner_stays_outside() {
    let cases = [
        ("[[0.0, 1.0], [0.5, 0.7], [0.6, 1.5]]", 1.0),
        (
            "[[-0.3, 0.7], [0.0, 1.0], [0.3, 0.7]]",
            (-2.0f64 * 0.3).exp(),
        ),
        (
            "[[0.0, 0.7], [0.3, 1.0], [0.0, 1.3], [-0.3, 1.0]]",
            (-2.0f64 * 0.6).exp(),
        ),
    ];
    for (k, (vertices, exact)) in cases.iter().enumerate() {
        let text = format!(
            "[sensor]\nkind = \"radiance\"\npoint = [0.0, 0.0]\ndirection = [0.0, 1.0]\n\
             [[shapes]]\nname = \"lamp\"\nvertices = [[-1.0, 2.0], [1.0, 2.0]]\n\
             surface = {{ kind = \"emitter\", radiance = 1.0 }}\n\
             [[shapes]]\nname = \"fog\"\nclosed = true\nvertices = {vertices}\n\
             surface = {{ kind = \"transparent\" }}\nmedium = {{ ks = 0.0, ke = 2.0 }}\n\
             [[parameters]]\nname = \"fog_ty\"\nshape = \"fog\"\n\
             motion = {{ kind = \"translate_y\" }}\n"
        );
        let scene = Arc::new(file::from_toml(&text).unwrap());
        for m in [
            Method::Intensity,
            Method::Expectation,
            Method::Rendering,
            Method::Transport,
        ] {
            let e = m.estimator(Arc::clone(&scene)).unwrap();
            let r = run(e.as_ref(), &RunConfig::new(2000, 4).unwrap()).unwrap();
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
