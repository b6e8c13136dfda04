//! The singular configurations where flatland methods fail, as scenes:
//! two warp knots meeting, a sensor near a moving boundary, a thin dense
//! slab; and the scaling benchmark's many-corner vault. The tests of `tests/flat_failures.rs` and the stability figure
//! (`flat::figures::stability`, with the `figures` feature) build them here,
//! so the tests run without plotting. Book: chapter "Flatland: one
//! deformation, three estimators", section "Where the methods fail".
use super::{Medium, Motion, Parameter, Phase, Scene, Sensor, Shape, Surface};
use crate::error::Error;
use glam::DVec2;

fn lamp() -> Shape {
    Shape {
        name: "lamp".into(),
        vertices: vec![DVec2::new(-1.0, 2.0), DVec2::new(1.0, 2.0)],
        closed: false,
        surface: Surface::Emitter { radiance: 1.0 },
        medium: None,
    }
}

fn parameter(shape: &str, motion: Motion) -> Vec<Parameter> {
    vec![Parameter {
        name: "p".into(),
        shape: shape.into(),
        motion,
        bounds: None,
    }]
}

fn up() -> Sensor {
    Sensor::Irradiance {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    }
}

/// Case 1: the occluder's left corner a gap `g` inside the lamp's left end.
pub fn knots(g: f64) -> Result<Scene, Error> {
    let occluder = Shape {
        name: "occluder".into(),
        vertices: vec![DVec2::new(-0.5 + g, 1.0), DVec2::new(0.2, 1.0)],
        closed: false,
        surface: Surface::Absorber,
        medium: None,
    };
    Scene::new(
        vec![lamp(), occluder],
        parameter("occluder", Motion::TranslateX),
        up(),
    )
}

/// Case 2: the sensor inside an absorbing box, `d` from its moving left edge.
pub fn sensor_near_edge(d: f64) -> Result<Scene, Error> {
    let fog = Shape {
        name: "box".into(),
        vertices: vec![
            DVec2::new(-d, -0.5),
            DVec2::new(1.5, -0.5),
            DVec2::new(1.5, 1.5),
            DVec2::new(-d, 1.5),
        ],
        closed: true,
        surface: Surface::Transparent,
        medium: Some(Medium {
            ks: 0.0,
            ke: 1.0,
            phase: Phase::Isotropic,
        }),
    };
    Scene::new(
        vec![lamp(), fog],
        parameter("box", Motion::TranslateX),
        up(),
    )
}

/// Case 3: a scattering slab of thickness `t`, optical thickness 0.3,
/// albedo 0.8, translated in y.
pub fn thin_slab(t: f64) -> Result<Scene, Error> {
    let ke = 0.3 / t;
    let slab = Shape {
        name: "slab".into(),
        vertices: vec![
            DVec2::new(-0.8, 1.0),
            DVec2::new(0.8, 1.1),
            DVec2::new(0.8, 1.1 + t),
            DVec2::new(-0.8, 1.0 + t),
        ],
        closed: true,
        surface: Surface::Transparent,
        medium: Some(Medium {
            ks: 0.8 * ke,
            ke,
            phase: Phase::Isotropic,
        }),
    };
    Scene::new(
        vec![lamp(), slab],
        parameter("slab", Motion::TranslateY),
        up(),
    )
}

/// The scaling benchmark (`examples/flat_perf.rs`): the occluder scene (a
/// lamp, a black segment from (−0.6, 1) to (0.2, 1) translated, rotated
/// and scaled) under a wavy reflecting vault of `n` segments, albedo 0.5,
/// `r = 3 + 0.05 sin 40a` for `a` from `0.1 + shift` to `π − 0.1 + shift`,
/// translated vertically (`vault_ty`). Book: chapter "Flatland: one
/// deformation, three estimators", section "The cost of a derivative".
pub fn vault(n: usize, shift: f64) -> Result<Scene, Error> {
    let occluder = Shape {
        name: "occluder".into(),
        vertices: vec![DVec2::new(-0.6, 1.0), DVec2::new(0.2, 1.0)],
        closed: false,
        surface: Surface::Absorber,
        medium: None,
    };
    let n = n.max(1);
    let vertices = (0..=n)
        .map(|i| {
            let a = 0.1 + shift + (std::f64::consts::PI - 0.2) * i as f64 / n as f64;
            let r = 3.0 + 0.05 * (40.0 * a).sin();
            DVec2::new(r * a.cos(), r * a.sin())
        })
        .collect();
    let vault = Shape {
        name: "vault".into(),
        vertices,
        closed: false,
        surface: Surface::Reflector { albedo: 0.5 },
        medium: None,
    };
    let pivot = Some(DVec2::new(-0.2, 1.0));
    let parameters = [
        ("occluder_tx", "occluder", Motion::TranslateX),
        ("occluder_ty", "occluder", Motion::TranslateY),
        ("occluder_rotate", "occluder", Motion::Rotate { pivot }),
        ("occluder_scale", "occluder", Motion::Scale { pivot }),
        ("vault_ty", "vault", Motion::TranslateY),
    ]
    .into_iter()
    .map(|(name, shape, motion)| Parameter {
        name: name.into(),
        shape: shape.into(),
        motion,
        bounds: None,
    })
    .collect();
    Scene::new(vec![lamp(), occluder, vault], parameters, up())
}
