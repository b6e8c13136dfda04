//! The singular configurations where flatland methods fail, as scenes:
//! two warp knots meeting, a sensor near a moving boundary, a thin dense
//! slab. The tests of `tests/flat_failures.rs` and the stability figure
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
