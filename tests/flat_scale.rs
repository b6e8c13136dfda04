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

fn scaled(factor: f64) -> Result<Scene, geosens::Error> {
    let base =
        file::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/occluder.toml")).unwrap();
    let mut shapes = base.shapes().to_vec();
    for s in &mut shapes {
        for v in &mut s.vertices {
            *v *= factor;
        }
    }
    let parameters = base
        .parameters()
        .iter()
        .map(|p| Parameter {
            motion: match p.motion {
                Motion::Rotate { pivot } => Motion::Rotate {
                    pivot: pivot.map(|c| c * factor),
                },
                Motion::Scale { pivot } => Motion::Scale {
                    pivot: pivot.map(|c| c * factor),
                },
                m => m,
            },
            ..p.clone()
        })
        .collect();
    let sensor = match base.sensor() {
        Sensor::Irradiance { point, normal } => Sensor::Irradiance {
            point: point * factor,
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
