use super::*;
use crate::flat::scene::{Scene, Sensor as FlatSensor, Shape, Surface};
use rand::{RngExt, SeedableRng};
use std::f64::consts::PI;
use std::sync::Arc;

/// A reflecting vault open at the bottom (rays escape there) over an
/// occluder and a lamp, with enough corners for the tree.
fn vault() -> Plane {
    let arc = |n: usize, r0: f64| -> Vec<DVec2> {
        (0..=n)
            .map(|i| {
                let a = 0.1 + (PI - 0.2) * i as f64 / n as f64;
                let r = r0 + 0.05 * (40.0 * a).sin();
                DVec2::new(r * a.cos(), r * a.sin())
            })
            .collect()
    };
    let shape = |name: &str, vertices: Vec<DVec2>, surface| Shape {
        name: name.into(),
        vertices,
        closed: false,
        surface,
        medium: None,
    };
    let scene = Scene::new(
        vec![
            shape("vault", arc(500, 3.0), Surface::Reflector { albedo: 0.5 }),
            shape(
                "lamp",
                vec![DVec2::new(-1.0, 2.0), DVec2::new(1.0, 2.0)],
                Surface::Emitter { radiance: 1.0 },
            ),
            shape(
                "occ",
                vec![DVec2::new(-0.6, 1.0), DVec2::new(0.2, 1.0)],
                Surface::Absorber,
            ),
        ],
        vec![],
        FlatSensor::Irradiance {
            point: DVec2::ZERO,
            normal: DVec2::Y,
        },
    )
    .unwrap();
    Plane::new(Arc::new(scene))
}

#[test]
fn the_tree_finds_the_knots_the_scan_finds() {
    let plane = vault();
    assert!(plane.scene.corner_tree().is_some());
    let mut rng = crate::rng::PathRng::seed_from_u64(9);
    let (mut escaping, mut hitting) = (0, 0);
    for _ in 0..4000 {
        let x = DVec2::new(
            rng.random::<f64>() * 5.0 - 2.5,
            rng.random::<f64>() * 2.6 - 0.3,
        );
        let w = super::super::geometry::direction(rng.random::<f64>() * TAU);
        let limits = [(4.0, 4.0), (2.0, 2.0), (1.5, 0.7)];
        let (lim_ccw, lim_cw) = limits[rng.random_range(0..3)];
        let Some(tree) = plane.knots_in_triangles(x, NO_SEGMENT, w, None, lim_ccw, lim_cw) else {
            continue;
        };
        if plane.scene.opaque_hit(x, w, NO_SEGMENT).is_some() {
            hitting += 1;
        } else {
            escaping += 1;
        }
        let scan = plane.scan_knots(x, NO_SEGMENT, w, lim_ccw, lim_cw);
        let key = |k: Option<Knot>| k.map(|k| (k.1.x, k.1.y));
        assert_eq!(key(tree.0), key(scan.0), "ccw at {x} along {w}");
        assert_eq!(key(tree.1), key(scan.1), "cw at {x} along {w}");
    }
    assert!(escaping > 300 && hitting > 300, "{escaping} {hitting}");
}
