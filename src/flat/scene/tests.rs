//! Tests of scene validation: a valid scene resolves its pivots and
//! normals, and each kind of bad scene is rejected with a reason.
use super::{Medium, Motion, Parameter, Phase, Scene, Sensor, Shape, Surface};
use glam::DVec2;

fn square(name: &str, c: DVec2, h: f64, surface: Surface) -> Shape {
    Shape {
        name: name.into(),
        vertices: vec![
            c + DVec2::new(-h, -h),
            c + DVec2::new(h, -h),
            c + DVec2::new(h, h),
            c + DVec2::new(-h, h),
        ],
        closed: true,
        surface,
        medium: None,
    }
}

fn irradiance() -> Sensor {
    Sensor::Irradiance {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    }
}

#[test]
fn a_valid_scene_resolves_pivots_and_normals() {
    let s = Scene::new(
        vec![square("box", DVec2::new(0.0, 3.0), 1.0, Surface::Absorber)],
        vec![Parameter {
            name: "spin".into(),
            shape: "box".into(),
            motion: Motion::Rotate { pivot: None },
            bounds: None,
        }],
        irradiance(),
    )
    .unwrap();
    assert_eq!(
        s.parameters()[0].motion,
        Motion::Rotate {
            pivot: Some(DVec2::new(0.0, 3.0))
        }
    );
    // Outward normal of the bottom edge points down.
    assert!((s.normal(0) - DVec2::new(0.0, -1.0)).length() < 1e-15);
    let moved = s.displaced(0, std::f64::consts::FRAC_PI_2).unwrap();
    assert!((moved.segments()[0].a - DVec2::new(1.0, 2.0)).length() < 1e-12);
}

#[test]
fn bad_scenes_are_rejected_with_a_reason() {
    let ok = || square("a", DVec2::new(0.0, 3.0), 1.0, Surface::Absorber);
    let err = |shapes: Vec<Shape>, params: Vec<Parameter>, sensor: Sensor| {
        Scene::new(shapes, params, sensor).unwrap_err().to_string()
    };
    let mut bow = ok();
    bow.vertices.swap(2, 3);
    bow.vertices[3] = DVec2::new(2.0, 5.0); // a bow tie with non-zero area
    let e = err(vec![bow], vec![], irradiance());
    assert!(e.contains("intersects itself"), "{e}");
    let mut b = ok();
    b.name = "b".into();
    assert!(err(vec![ok(), b], vec![], irradiance()).contains("touch or cross"));
    let mut fog = ok();
    fog.surface = Surface::Transparent;
    fog.medium = Some(Medium {
        ks: 2.0,
        ke: 1.0,
        phase: Phase::Isotropic,
    });
    assert!(err(vec![fog], vec![], irradiance()).contains("κe"));
    let p = Parameter {
        name: "p".into(),
        shape: "nope".into(),
        motion: Motion::TranslateX,
        bounds: None,
    };
    assert!(err(vec![ok()], vec![p], irradiance()).contains("does not exist"));
    let inside = Sensor::Irradiance {
        point: DVec2::new(0.0, 3.0),
        normal: DVec2::Y,
    };
    assert!(err(vec![ok()], vec![], inside).contains("inside"));
    let on = Sensor::Irradiance {
        point: DVec2::new(0.0, 2.0),
        normal: DVec2::Y,
    };
    assert!(err(vec![ok()], vec![], on).contains("lies on"));
    let mut deg = ok();
    deg.vertices[1] = deg.vertices[0];
    assert!(err(vec![deg], vec![], irradiance()).contains("zero length"));
    let mut neg = ok();
    neg.surface = Surface::Reflector { albedo: 1.5 };
    assert!(err(vec![neg], vec![], irradiance()).contains("albedo"));
}
