//! Flatland at every scale validation accepts: the occluder scene scaled by
//! factors from 10⁻⁵⁵ to 10⁵⁵ gives the closed form's `E` (scale-free) and
//! derivatives (a translation's scales as 1/factor, a rotation's and a
//! scale's not) from every method; beyond, the scene is refused with a
//! message that names its size.
use geosens::flat::exact::Reference;
use geosens::flat::{Method, Motion, Parameter, Scene, Sensor, file};
use geosens::{Quantity, RunConfig, run};
use std::path::Path;
use std::sync::Arc;

/// The shipped occluder scene scaled about the origin by `factor`.
fn scaled(factor: f64) -> Result<Scene, geosens::Error> {
    let base =
        file::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/occluder.toml")).unwrap();
    mapped(&base, |v| v * factor)
}

/// `base` moved by `d`.
fn shifted(base: &Scene, d: glam::DVec2) -> Result<Scene, geosens::Error> {
    mapped(base, |v| v + d)
}

/// `base` with every point (vertex, sensor, pivot) mapped by `f`, a
/// similarity that keeps directions.
fn mapped(base: &Scene, f: impl Fn(glam::DVec2) -> glam::DVec2) -> Result<Scene, geosens::Error> {
    let mut shapes = base.shapes().to_vec();
    for s in &mut shapes {
        for v in &mut s.vertices {
            *v = f(*v);
        }
    }
    let parameters = base
        .parameters()
        .iter()
        .map(|p| Parameter {
            motion: match p.motion {
                Motion::Rotate { pivot } => Motion::Rotate {
                    pivot: pivot.map(&f),
                },
                Motion::Scale { pivot } => Motion::Scale {
                    pivot: pivot.map(&f),
                },
                m => m,
            },
            ..p.clone()
        })
        .collect();
    let sensor = match base.sensor() {
        Sensor::Irradiance { point, normal } => Sensor::Irradiance {
            point: f(point),
            normal,
        },
        s => s,
    };
    Scene::new(shapes, parameters, sensor)
}

#[test]
fn every_method_works_at_every_accepted_scale() {
    let unit = Reference::for_scene(&scaled(1.0).unwrap()).unwrap();
    for factor in [1e-55, 1e-13, 1e13, 1e55] {
        let scene = Arc::new(scaled(factor).unwrap());
        for method in [
            Method::Intensity,
            Method::Rendering,
            Method::Expectation,
            Method::Transport,
        ] {
            let e = method.estimator(scene.clone()).unwrap();
            let r = run(e.as_ref(), &RunConfig::new(100_000, 4).unwrap()).unwrap();
            let i = r.get(&Quantity::Intensity).unwrap();
            assert!(
                i.z_score(unit.value()) < 4.0 && i.is_reliable(),
                "{} at ×{factor:e}: {i:?} vs {}",
                method.name(),
                unit.value()
            );
            if method == Method::Intensity {
                continue;
            }
            for (j, p) in scene.parameters().iter().enumerate() {
                let s = r.get(&Quantity::sensitivity(&p.name)).unwrap();
                let exact = match p.motion {
                    Motion::TranslateX | Motion::TranslateY => unit.derivative(j) / factor,
                    _ => unit.derivative(j),
                };
                // The flag too: a translation's weights scale as 1/factor and
                // the VOV sums their fourth powers.
                assert!(
                    s.stderr > 0.0 && s.z_score(exact) < 4.0 && s.is_reliable(),
                    "{} {} at ×{factor:e}: {s:?} vs {exact:e}",
                    method.name(),
                    p.name
                );
            }
        }
    }
}

#[test]
fn scenes_beyond_the_supported_sizes_are_refused_by_name() {
    for factor in [1e-75, 1e70, 1e154] {
        let e = scaled(factor).unwrap_err().to_string();
        assert!(e.contains("size") && e.contains("rescale"), "{e}");
    }
}

/// An edge-on lamp (its ends 3·10⁻⁷ rad apart as seen from the sensor)
/// rotating about its near end, the sensor inside an absorbing pentagon,
/// 480 sizes from the origin (found by a random-scene campaign). The ray
/// aimed at the lamp's far end grazes the lamp and met it, by rounding,
/// ~10⁻⁷ short of the end: the corner was "hidden", rendering and transport
/// read 0 (0.11 with a reflector beside it: wrong and marked reliable).
/// Every method against the closed form, there and at the origin.
#[test]
fn an_edge_on_lamp_far_from_the_origin_keeps_its_corner() {
    let scene_at = |o: [f64; 2]| {
        let p = |x: f64, y: f64| format!("[{:?}, {:?}]", x - o[0], y - o[1]);
        let text = format!(
            r#"
[sensor]
kind = "irradiance"
point = {s}
normal = [-0.305211882058486, 0.9522844675044936]

[[shapes]]
name = "lamp"
vertices = [{l0}, {l1}]
surface = {{ kind = "emitter", radiance = 0.78 }}

[[shapes]]
name = "room"
vertices = [{r0}, {r1}, {r2}, {r3}, {r4}]
closed = true
surface = {{ kind = "transparent" }}
medium = {{ ks = 0.0, ke = 0.563 }}

[[parameters]]
name = "lamp_rotate"
shape = "lamp"
motion = {{ kind = "rotate", pivot = {l0} }}
"#,
            s = p(-476.86888153604, 878.9744420758582),
            l0 = p(-477.0725701911312, 880.4958390434773),
            l1 = p(-477.1714772522132, 881.2345927980987),
            r0 = p(-475.16003642226644, 879.4001318601527),
            r1 = p(-477.3458392214908, 880.5126357693001),
            r2 = p(-478.4459129677018, 878.4580961919189),
            r3 = p(-476.98490184599007, 877.1962338095426),
            r4 = p(-475.3662418481978, 877.9535487197684),
        );
        Arc::new(file::from_toml(&text).unwrap())
    };
    let origin = [-476.86888153604, 878.9744420758582];
    let exact = Reference::for_scene(&scene_at(origin))
        .unwrap()
        .derivative(0);
    assert!(exact > 0.1, "{exact}");
    for o in [origin, [0.0, 0.0]] {
        let scene = scene_at(o);
        for method in [Method::Rendering, Method::Expectation, Method::Transport] {
            let e = method.estimator(scene.clone()).unwrap();
            let r = run(e.as_ref(), &RunConfig::new(100_000, 2).unwrap()).unwrap();
            let s = r.get(&Quantity::sensitivity("lamp_rotate")).unwrap();
            assert!(
                s.z_score(exact) < 4.0 && s.is_reliable(),
                "{} at {o:?}: {s:?} vs {exact}",
                method.name()
            );
        }
    }
}

/// A lamp exactly on a sight line from the sensor, its coordinates not
/// round (campaign): its far end is hidden behind the near one, a tie
/// whose derivative is a kink (±47.7 one-sided). The tie test took the
/// near end as hidden by the lamp itself (the grazing rounding above), so
/// no caveat was printed and rendering reported 234 ± 0.4, reliable.
#[test]
fn a_lamp_on_a_sight_line_with_unround_coordinates_is_a_caveat() {
    let text = r#"
[sensor]
kind = "irradiance"
point = [0.009926716869978616, 0.001208425497613291]
normal = [-0.7393989077337133, 0.6732675955682048]

[[shapes]]
name = "lamp0"
vertices = [[0.008619761004118829, 0.0015190527994969302], [0.00835255769936419, 0.001582559642978384]]
surface = { kind = "emitter", radiance = 1.867 }

[[parameters]]
name = "lamp0_translate_x"
shape = "lamp0"
motion = { kind = "translate_x" }
"#;
    let scene = Arc::new(file::from_toml(text).unwrap());
    for method in [
        Method::Rendering,
        Method::Expectation,
        Method::Transport,
        Method::Fd,
    ] {
        let e = method.estimator(scene.clone()).unwrap();
        let caveats = e.caveats();
        assert!(
            caveats
                .iter()
                .any(|(q, why)| *q == Quantity::sensitivity("lamp0_translate_x")
                    && (method == Method::Fd || why.contains("one sight line"))),
            "{}: {caveats:?}",
            method.name()
        );
    }
}

/// A lamp 4·10⁻¹² rad from edge-on, 10⁸ from the origin (campaign): the
/// angles of its ends carry ~5·10⁻¹⁰ rad of rounding there, so the two
/// cannot be told apart, yet the tie test (10⁻¹² rad) passed it and
/// expectation read −0.0015 against rendering's 0.0433, both "reliable".
/// The tie's tolerance now grows with the coordinates' rounding.
#[test]
fn an_edge_on_lamp_far_out_is_a_tie_within_its_rounding() {
    let text = r#"{"sensor": {"kind": "irradiance", "point": [-75887305.78481811, 65123857.538704745], "normal": [-0.42254594313287286, -0.9063415062447218]},
 "shapes": [{"name": "lamp0", "vertices": [[-75887251.8604876, 65121007.04355613], [-75887238.15108676, 65120282.350636]], "surface": {"kind": "emitter", "radiance": 0.56}}],
 "parameters": [{"name": "lamp0_rotate", "shape": "lamp0", "motion": {"kind": "rotate", "pivot": [-75887251.8604876, 65121007.04355613]}}]}"#;
    let scene = Arc::new(file::from_json(text).unwrap());
    let caveats = geosens::flat::methods::ties(&scene);
    assert!(
        caveats
            .iter()
            .any(|(q, why)| *q == Quantity::sensitivity("lamp0_rotate")
                && why.contains("one sight line")),
        "{caveats:?}"
    );
    // The shipped occluder scene 10⁵ from the origin (within the
    // supported offset) keeps no tie.
    let far = shifted(&scaled(1.0).unwrap(), glam::DVec2::new(-8e4, 6e4)).unwrap();
    assert!(geosens::flat::methods::ties(&far).is_empty());
}

/// A closed reflecting sliver (its corners ~10⁻⁴ rad sharp) 10⁵ from the
/// origin (campaign): the nested paths of a corner term started 10⁻⁹ sizes
/// along one face, ~3·10⁻¹³ from the other face, below the coordinates'
/// rounding (3·10⁻¹¹): they started across it, and rendering and transport
/// read −0.076 where the scene at the origin gives −0.151, "reliable".
/// Each method far out against rendering at the origin.
#[test]
fn a_sharp_reflecting_corner_far_out_keeps_its_corner_term() {
    let text = r#"{"sensor": {"kind": "irradiance", "point": [-57909.023983268904, -81526.34507510555], "normal": [-0.4868922763733052, -0.8734620261969155]}, "shapes": [{"name": "lamp0", "vertices": [[-57912.30068554195, -81526.59364277095], [-57910.59722609934, -81525.71007874192]], "surface": {"kind": "emitter", "radiance": 1.228}}, {"name": "lamp1", "vertices": [[-57909.86821651675, -81527.23370538071], [-57909.5499046855, -81526.71603653954]], "surface": {"kind": "emitter", "radiance": 1.898}}, {"name": "o0", "vertices": [[-57909.1328040033, -81527.0383361286], [-57908.7579048943, -81526.75655676471], [-57908.635652140176, -81526.34911494979]], "surface": {"kind": "absorber"}}, {"name": "o1", "vertices": [[-57910.10933807514, -81525.80277040825], [-57910.08443996384, -81526.506446327], [-57910.09685383569, -81526.15460712272]], "closed": true, "surface": {"kind": "reflector", "albedo": 0.495}}, {"name": "o2", "vertices": [[-57910.4201865064, -81527.78917755434], [-57910.701903802226, -81527.47027705132]], "surface": {"kind": "reflector", "albedo": 0.797}}], "parameters": [{"name": "o0_rotate", "shape": "o0", "motion": {"kind": "rotate"}}, {"name": "o0_translate_y", "shape": "o0", "motion": {"kind": "translate_y"}}, {"name": "o1_translate_y", "shape": "o1", "motion": {"kind": "translate_y"}}]}"#;
    let far = Arc::new(file::from_json(text).unwrap());
    let to_origin = -match far.sensor() {
        Sensor::Irradiance { point, .. } => point,
        _ => unreachable!(),
    };
    let near = Arc::new(shifted(&far, to_origin).unwrap());
    let q = Quantity::sensitivity("o1_translate_y");
    let estimate = |scene: &Arc<Scene>, method: Method| {
        let e = method.estimator(scene.clone()).unwrap();
        run(e.as_ref(), &RunConfig::new(200_000, 5).unwrap())
            .unwrap()
            .get(&q)
            .unwrap()
    };
    let reference = estimate(&near, Method::Rendering);
    assert!(
        reference.is_reliable() && reference.mean < -0.14,
        "{reference:?}"
    );
    for method in [Method::Rendering, Method::Transport, Method::Expectation] {
        let s = estimate(&far, method);
        let z = (s.mean - reference.mean).abs() / s.stderr.hypot(reference.stderr);
        assert!(
            s.is_reliable() && z < 4.0,
            "{} far out: {s:?} against {reference:?}",
            method.name()
        );
    }
}
