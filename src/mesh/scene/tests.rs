//! Tests of 3D scene validation: welding, orientation, pivots, medium
//! nesting, displacement, and each kind of bad scene rejected with its
//! reason.
use super::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
use glam::DVec3;

/// The 8 corners of the cube of centre `c` and half-side `h` (corner `i`
/// has x, y, z high for bits 0, 1, 2 of `i`).
fn corners(c: DVec3, h: f64) -> Vec<DVec3> {
    (0..8)
        .map(|i| {
            let s = |b: u32| if i >> b & 1 == 1 { h } else { -h };
            c + DVec3::new(s(0), s(1), s(2))
        })
        .collect()
}

/// Outward triangles of [`corners`].
const CUBE: [[u32; 3]; 12] = [
    [0, 2, 3],
    [0, 3, 1],
    [4, 5, 7],
    [4, 7, 6],
    [0, 1, 5],
    [0, 5, 4],
    [2, 6, 7],
    [2, 7, 3],
    [0, 4, 6],
    [0, 6, 2],
    [1, 3, 7],
    [1, 7, 5],
];

fn cube(name: &str, c: DVec3, h: f64, surface: Surface) -> Shape {
    Shape {
        name: name.into(),
        vertices: corners(c, h),
        triangles: CUBE.to_vec(),
        surface,
        medium: None,
    }
}

fn fog(name: &str, c: DVec3, h: f64) -> Shape {
    Shape {
        medium: Some(Medium {
            ks: 1.0,
            ke: 1.5,
            g: 0.3,
        }),
        ..cube(name, c, h, Surface::Transparent)
    }
}

/// A horizontal square of centre `c` and half-side `h`, two triangles.
fn square(name: &str, c: DVec3, h: f64, surface: Surface) -> Shape {
    Shape {
        name: name.into(),
        vertices: vec![
            c + DVec3::new(-h, -h, 0.0),
            c + DVec3::new(h, -h, 0.0),
            c + DVec3::new(h, h, 0.0),
            c + DVec3::new(-h, h, 0.0),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface,
        medium: None,
    }
}

fn lamp() -> Shape {
    square(
        "lamp",
        DVec3::new(0.0, 0.0, 2.0),
        0.5,
        Surface::Emitter { radiance: 1.0 },
    )
}

fn irradiance() -> Sensor {
    Sensor::Irradiance {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    }
}

fn param(name: &str, shape: &str, motion: Motion) -> Parameter {
    Parameter {
        name: name.into(),
        shape: shape.into(),
        motion,
        bounds: None,
    }
}

fn err(shapes: Vec<Shape>, params: Vec<Parameter>, sensor: Sensor) -> String {
    match Scene::new(shapes, params, sensor) {
        Ok(_) => panic!("the scene was accepted"),
        Err(e) => e.to_string(),
    }
}

fn assert_err(shapes: Vec<Shape>, params: Vec<Parameter>, sensor: Sensor, part: &str) {
    let e = err(shapes, params, sensor);
    assert!(e.contains(part), "expected {part:?} in: {e}");
}

#[test]
fn a_valid_scene_resolves_pivots_axes_and_normals() {
    let c = DVec3::new(0.2, 0.1, 1.0);
    let s = Scene::new(
        vec![lamp(), cube("box", c, 0.25, Surface::Absorber)],
        vec![
            param(
                "spin",
                "box",
                Motion::Rotate {
                    axis: DVec3::new(0.0, 0.0, 2.0),
                    pivot: None,
                },
            ),
            param("grow", "box", Motion::Scale { pivot: None }),
        ],
        Sensor::Radiance {
            point: DVec3::ZERO,
            direction: DVec3::new(0.0, 0.0, 3.0),
        },
    )
    .unwrap();
    let Motion::Rotate {
        axis,
        pivot: Some(p),
    } = s.parameters()[0].motion
    else {
        panic!("{:?}", s.parameters()[0].motion)
    };
    assert_eq!(axis, DVec3::Z);
    assert!((p - c).length() < 1e-15);
    let Motion::Scale { pivot: Some(q) } = s.parameters()[1].motion else {
        panic!("{:?}", s.parameters()[1].motion)
    };
    assert_eq!(p, q);
    assert_eq!(s.parameter_shape(1), 1);
    assert_eq!(
        s.sensor(),
        Sensor::Radiance {
            point: DVec3::ZERO,
            direction: DVec3::Z
        }
    );
    assert!(!s.is_closed(0) && s.is_closed(1));
    assert_eq!(s.size(), 1.25);
    assert_eq!(s.parent_medium(1), None);
    assert_eq!(s.sensor_medium(), None);
}

#[test]
fn a_triangle_soup_cube_is_welded_and_closed() {
    let mut soup = cube("soup", DVec3::new(0.0, 0.0, 1.0), 0.5, Surface::Absorber);
    let v = soup.vertices.clone();
    soup.vertices = CUBE.iter().flat_map(|t| t.map(|i| v[i as usize])).collect();
    soup.triangles = (0..12).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    // Minus zero welds with zero; an unused vertex is dropped.
    soup.vertices.push(DVec3::new(9.0, 9.0, 9.0));
    let s = Scene::new(vec![soup], vec![], irradiance()).unwrap();
    assert_eq!(s.shapes()[0].vertices.len(), 8);
    assert_eq!(s.shapes()[0].triangles.len(), 12);
    assert!(s.is_closed(0));
    let mut signed = square("sq", DVec3::new(0.0, 0.0, 1.0), 0.5, Surface::Absorber);
    signed.vertices.push(DVec3::new(0.0, -0.0, 1.0));
    signed.vertices.push(DVec3::new(-0.0, 0.0, 1.0));
    signed.triangles = vec![[0, 1, 4], [1, 2, 5], [2, 3, 4], [3, 0, 5]];
    let s = Scene::new(vec![signed], vec![], irradiance()).unwrap();
    assert_eq!(s.shapes()[0].vertices.len(), 5);
}

/// Whether every triangle's normal points away from the mesh's centroid.
fn outward(s: &Shape) -> bool {
    let c = s.centroid();
    (0..s.triangles.len()).all(|i| {
        let [a, b, d] = s.triangle(i);
        (b - a).cross(d - a).dot((a + b + d) / 3.0 - c) > 0.0
    })
}

#[test]
fn an_inward_cube_is_turned_outward() {
    let mut inward = cube("in", DVec3::new(0.0, 0.0, 1.0), 0.5, Surface::Absorber);
    assert!(outward(&inward));
    for t in &mut inward.triangles {
        t.swap(0, 1);
    }
    assert!(!outward(&inward));
    let s = Scene::new(vec![inward], vec![], irradiance()).unwrap();
    assert!(outward(&s.shapes()[0]));
}

#[test]
fn media_nest() {
    let shapes = vec![
        lamp(),
        fog("big", DVec3::new(0.0, 0.0, 0.5), 1.0),
        fog("small", DVec3::new(0.0, 0.0, 0.2), 0.4),
        cube("stone", DVec3::new(0.5, 0.5, 1.0), 0.1, Surface::Absorber),
    ];
    let s = Scene::new(shapes, vec![], irradiance()).unwrap();
    assert_eq!(s.sensor_medium(), Some(2));
    assert_eq!(s.parent_medium(2), Some(1));
    assert_eq!(s.parent_medium(3), Some(1));
    assert_eq!(s.parent_medium(1), None);
    assert_eq!(s.parent_medium(0), None);
    assert_eq!(s.medium(s.sensor_medium()).map(|m| m.ke), Some(1.5));
    // The sensor on the line through the cubes' edges and corners: the
    // winding number has no parity trap.
    let shapes = vec![fog("f", DVec3::new(1.0, 1.0, 1.0), 0.5)];
    let corner = Sensor::Irradiance {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    };
    assert_eq!(
        Scene::new(shapes, vec![], corner).unwrap().sensor_medium(),
        None
    );
}

#[test]
fn displacement_moves_the_parameters_mesh() {
    let c = DVec3::new(0.2, 0.1, 1.0);
    let s = Scene::new(
        vec![lamp(), cube("box", c, 0.25, Surface::Absorber)],
        vec![
            param("tx", "box", Motion::TranslateX),
            param(
                "rz",
                "box",
                Motion::Rotate {
                    axis: DVec3::Z,
                    pivot: None,
                },
            ),
        ],
        irradiance(),
    )
    .unwrap();
    let moved = s.displaced(0, 0.1).unwrap();
    assert_eq!(moved.shapes()[0], s.shapes()[0]);
    for (a, b) in moved.shapes()[1]
        .vertices
        .iter()
        .zip(&s.shapes()[1].vertices)
    {
        assert!((*a - *b - DVec3::new(0.1, 0.0, 0.0)).length() < 1e-15);
    }
    let turned = s.displaced(1, std::f64::consts::FRAC_PI_2).unwrap();
    let v0 = s.shapes()[1].vertices[0] - c;
    let t0 = turned.shapes()[1].vertices[0] - c;
    assert!((t0 - DVec3::new(-v0.y, v0.x, v0.z)).length() < 1e-12);
    assert!(s.displaced(2, 0.1).is_err());
    assert!(s.displaced(0, f64::NAN).is_err());
    // Moving the box into the lamp is refused.
    let e = s.displaced(0, 0.0).and_then(|s| {
        Scene::new(
            s.shapes().to_vec(),
            vec![param("tz", "box", Motion::TranslateZ)],
            irradiance(),
        )?
        .displaced(0, 0.8)
    });
    assert!(e.unwrap_err().to_string().contains("touch or cross"));
}

#[test]
fn bad_shapes_are_rejected_with_a_reason() {
    let ok = || cube("a", DVec3::new(0.0, 0.0, 3.0), 1.0, Surface::Absorber);
    let s = irradiance;
    assert_err(vec![], vec![], s(), "at least one shape");
    let mut e = ok();
    e.name.clear();
    assert_err(vec![e], vec![], s(), "shape 0 has an empty name");
    assert_err(vec![ok(), ok()], vec![], s(), "two shapes are named \"a\"");
    let mut e = ok();
    e.triangles.clear();
    assert_err(vec![e], vec![], s(), "\"a\" has no triangles");
    let mut e = ok();
    e.vertices[3].y = f64::NAN;
    assert_err(
        vec![e],
        vec![],
        s(),
        "\"a\" vertex 3 = [1, NaN, 2] is not finite",
    );
    let mut e = ok();
    e.vertices[3].z = f64::INFINITY;
    assert_err(vec![e], vec![], s(), "vertex 3");
    let mut e = ok();
    e.triangles[5][2] = 8;
    assert_err(vec![e], vec![], s(), "triangle 5 uses vertex 8");
    let mut e = ok();
    e.vertices[1] = e.vertices[0];
    assert_err(
        vec![e],
        vec![],
        s(),
        "triangle 1 is degenerate: two of its corners",
    );
    let mut e = square("flat", DVec3::new(0.0, 0.0, 1.0), 0.5, Surface::Absorber);
    e.vertices[1] = DVec3::new(0.0, 0.0, 1.0); // between corners 0 and 2
    assert_err(vec![e], vec![], s(), "triangle 0 is degenerate: its area");
    let mut e = square("fan", DVec3::new(0.0, 0.0, 1.0), 0.5, Surface::Absorber);
    e.vertices.push(DVec3::new(0.0, 0.0, 2.0));
    e.triangles.push([0, 2, 4]);
    assert_err(vec![e], vec![], s(), "shared by triangles 0, 1 and 2");
    let mut e = ok();
    e.triangles[7].swap(0, 1);
    assert_err(vec![e], vec![], s(), "oriented consistently");
    let mut e = square("sq", DVec3::new(0.0, 0.0, 1.0), 0.5, Surface::Transparent);
    e.medium = fog("x", DVec3::ZERO, 1.0).medium;
    assert_err(vec![e], vec![], s(), "has a medium but is not closed");
    let mut e = ok();
    e.medium = fog("x", DVec3::ZERO, 1.0).medium;
    assert_err(vec![e], vec![], s(), "medium behind an opaque surface");
    let mut e = ok();
    e.surface = Surface::Transparent;
    assert_err(vec![e], vec![], s(), "transparent but holds no medium");
    let thin = |ks, ke, g| Shape {
        medium: Some(Medium { ks, ke, g }),
        ..fog("f", DVec3::new(0.0, 0.0, 3.0), 1.0)
    };
    assert_err(vec![thin(-1.0, 1.0, 0.0)], vec![], s(), "κs = -1");
    assert_err(vec![thin(2.0, 1.0, 0.0)], vec![], s(), "κe = 1 must be");
    assert_err(vec![thin(1.0, f64::INFINITY, 0.0)], vec![], s(), "κe = inf");
    assert_err(vec![thin(1.0, 1.0, 1.0)], vec![], s(), "g = 1 is not in");
    assert_err(vec![thin(1.0, 1e4, 0.0)], vec![], s(), "exceeds");
    let mut e = ok();
    e.surface = Surface::Emitter { radiance: -1.0 };
    assert_err(vec![e], vec![], s(), "radiance -1");
    let mut e = ok();
    e.surface = Surface::Reflector { albedo: 1.5 };
    assert_err(vec![e], vec![], s(), "albedo 1.5");
    let tiny = cube("t", DVec3::new(0.0, 0.0, 1e-62), 1e-62, Surface::Absorber);
    assert_err(vec![tiny], vec![], s(), "the scene's size");
    let huge = cube("h", DVec3::new(0.0, 0.0, 1e62), 1e61, Surface::Absorber);
    assert_err(vec![huge], vec![], s(), "the scene's size");
    // A doubly covered tetrahedron flattened into a plane: closed, no volume.
    let mut flat = ok();
    flat.vertices = vec![
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
        DVec3::new(0.3, 0.3, 1.0),
    ];
    flat.triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    assert_err(vec![flat], vec![], s(), "encloses no volume");
}

#[test]
fn meshes_that_cross_or_touch_are_rejected() {
    let a = || cube("a", DVec3::new(0.0, 0.0, 3.0), 1.0, Surface::Absorber);
    let b = |c: DVec3| cube("b", c, 0.5, Surface::Absorber);
    let s = irradiance;
    // Crossing.
    let e = err(vec![a(), b(DVec3::new(1.0, 0.0, 3.0))], vec![], s());
    assert!(
        e.contains("shapes \"a\" (triangle") && e.contains("\"b\" (triangle"),
        "{e}"
    );
    assert!(e.contains("touch or cross"), "{e}");
    // Touching face to face, edge to edge, corner to corner.
    for c in [
        DVec3::new(1.5, 0.0, 3.0),
        DVec3::new(1.5, 1.5, 3.0),
        DVec3::new(1.5, 1.5, 4.5),
    ] {
        assert_err(vec![a(), b(c)], vec![], s(), "touch or cross");
    }
    // A triangle's corner on the other's face.
    let mut spike = square("spike", DVec3::new(0.0, 0.0, 4.5), 0.5, Surface::Absorber);
    spike.vertices[0] = DVec3::new(0.0, 0.0, 4.0);
    assert_err(vec![a(), spike], vec![], s(), "touch or cross");
    // Coplanar overlap.
    let lid = square("lid", DVec3::new(0.5, 0.5, 4.0), 0.8, Surface::Absorber);
    assert_err(vec![a(), lid], vec![], s(), "touch or cross");
    // Nested but apart is fine, and so is a gap.
    let inner = b(DVec3::new(0.0, 0.0, 3.0));
    assert!(Scene::new(vec![a(), inner], vec![], s()).is_ok());
    assert!(Scene::new(vec![a(), b(DVec3::new(1.5 + 1e-9, 0.0, 3.0))], vec![], s()).is_ok());
}

#[test]
fn a_medium_whose_mesh_crosses_itself_is_rejected() {
    // Two overlapping cubes given as one closed mesh: its parity of
    // crossings would put the overlap outside the medium.
    let two = |offset: DVec3| {
        let (a, b) = (
            fog("blob", DVec3::new(0.0, 0.0, 1.0), 0.3),
            fog("b", DVec3::new(0.0, 0.0, 1.0) + offset, 0.3),
        );
        let mut vertices = a.vertices.clone();
        vertices.extend(&b.vertices);
        let mut triangles = a.triangles.clone();
        triangles.extend(b.triangles.iter().map(|t| t.map(|i| i + 8)));
        Shape {
            vertices,
            triangles,
            ..a
        }
    };
    assert_err(
        vec![lamp(), two(DVec3::new(0.2, 0.1, 0.05))],
        vec![],
        irradiance(),
        "shape \"blob\" crosses itself (triangles",
    );
    // Apart, the two cubes bound two regions of one medium: fine; so is one
    // cube, whose triangles touch only where they share a vertex.
    assert!(
        Scene::new(
            vec![lamp(), two(DVec3::new(0.7, 0.0, 0.0))],
            vec![],
            irradiance()
        )
        .is_ok()
    );
    assert!(
        Scene::new(
            vec![lamp(), fog("f", DVec3::new(0.0, 0.0, 1.0), 0.3)],
            vec![],
            irradiance()
        )
        .is_ok()
    );
}

#[test]
fn bad_parameters_and_sensors_are_rejected_with_a_reason() {
    let shapes = || vec![cube("a", DVec3::new(0.0, 0.0, 3.0), 1.0, Surface::Absorber)];
    let s = irradiance;
    let tx = |name: &str, shape: &str| param(name, shape, Motion::TranslateX);
    assert_err(shapes(), vec![tx("p", "nope")], s(), "which does not exist");
    assert_err(
        shapes(),
        vec![tx("", "a")],
        s(),
        "parameter 0 has an empty name",
    );
    assert_err(
        shapes(),
        vec![tx("p", "a"), tx("p", "a")],
        s(),
        "two parameters are named \"p\"",
    );
    let many = (0..300).map(|j| tx(&format!("p{j}"), "a")).collect();
    assert_err(shapes(), many, s(), "at most");
    let rot = |axis, pivot| vec![param("r", "a", Motion::Rotate { axis, pivot })];
    assert_err(
        shapes(),
        rot(DVec3::ZERO, None),
        s(),
        "axis = [0, 0, 0] has no direction",
    );
    assert_err(
        shapes(),
        rot(DVec3::new(f64::NAN, 0.0, 1.0), None),
        s(),
        "axis = [NaN, 0, 1] is not finite",
    );
    assert_err(
        shapes(),
        rot(DVec3::Z, Some(DVec3::new(0.0, f64::INFINITY, 0.0))),
        s(),
        "\"r\" pivot",
    );
    let at = |point, normal| Sensor::Irradiance { point, normal };
    assert_err(shapes(), vec![], at(DVec3::NAN, DVec3::Z), "sensor point");
    assert_err(
        shapes(),
        vec![],
        at(DVec3::ZERO, DVec3::ZERO),
        "sensor normal",
    );
    let on = at(DVec3::new(0.3, 0.2, 2.0), DVec3::Z);
    assert_err(shapes(), vec![], on, "lies on shape \"a\"");
    let inside = at(DVec3::new(0.3, 0.2, 3.0), DVec3::Z);
    assert_err(shapes(), vec![], inside, "inside the opaque shape \"a\"");
    let radiance = Sensor::Radiance {
        point: DVec3::ZERO,
        direction: DVec3::new(0.0, f64::NAN, 1.0),
    };
    assert_err(shapes(), vec![], radiance, "sensor direction");
}

/// A mesh whose triangles meet anywhere but at shared vertices and edges
/// is refused: the boundary terms counted an edge lying on another edge or
/// face twice (2× the derivative, "reliable"), and lost the edge of a fold.
/// Each bad mesh beside its sound twin, which loads.
#[test]
fn a_mesh_touching_itself_is_rejected() {
    let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    let occ = |vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>| Shape {
        name: "occ".into(),
        vertices,
        triangles,
        surface: Surface::Absorber,
        medium: None,
    };
    let check = |shape: Shape, part: Option<&str>| {
        let r = Scene::new(vec![lamp(), shape], vec![], irradiance());
        match (r, part) {
            (Err(e), Some(part)) => assert!(e.to_string().contains(part), "{part:?} not in {e}"),
            (Ok(_), None) => {}
            (r, part) => panic!("{part:?}: {:?}", r.err()),
        }
    };
    // An "L": a square at z = 1 and a wall rising from its edge x = -0.05,
    // split at y = 0.1: a T-junction on the fold. With the floor's edge
    // split there too, the same L is sound.
    let floor = [
        v(-0.05, -0.15, 1.0),
        v(0.45, -0.15, 1.0),
        v(0.45, 0.35, 1.0),
        v(-0.05, 0.35, 1.0),
    ];
    let wall = [
        v(-0.05, -0.15, 1.5),
        v(-0.05, 0.35, 1.5),
        v(-0.05, 0.1, 1.0),
        v(-0.05, 0.1, 1.5),
    ];
    let all: Vec<DVec3> = floor.iter().chain(&wall).copied().collect();
    let wall_tris = [[0, 6, 7], [0, 7, 4], [6, 3, 5], [6, 5, 7]];
    let mut t = vec![[0, 1, 2], [0, 2, 3]];
    t.extend(wall_tris);
    check(occ(all.clone(), t), Some("overlaps itself at a vertex"));
    let mut t = vec![[0, 1, 2], [0, 2, 6], [6, 2, 3]];
    t.extend(wall_tris);
    check(occ(all, t), None);
    // The wall's own corners 1e-9 inside the floor (an unwelded seam): its
    // bottom edge lies on the floor. 1e-6 above it, apart: sound.
    for (dz, dx, part) in [(0.0, 1e-9, Some("crosses itself")), (1e-6, 0.0, None)] {
        let mut vs = floor.to_vec();
        vs.extend([
            v(-0.05 + dx, -0.15, 1.0 + dz),
            v(-0.05 + dx, 0.35, 1.0 + dz),
            wall[0],
            wall[1],
        ]);
        check(
            occ(vs, vec![[0, 1, 2], [0, 2, 3], [4, 5, 7], [4, 7, 6]]),
            part,
        );
    }
    // A triangle folded back onto its neighbour, both windings; unfolded
    // (its third corner across the edge), a flat face.
    let (a, b, c) = (
        v(-0.05, -0.15, 1.0),
        v(0.45, -0.15, 1.0),
        v(0.45, 0.35, 1.0),
    );
    for (m, tri, part) in [
        (v(0.3, 0.0, 1.0), [0, 2, 3], Some("folds onto itself")),
        (v(0.3, 0.0, 1.0), [0, 3, 2], Some("folds onto itself")),
        (v(0.0, 0.3, 1.0), [0, 2, 3], None),
    ] {
        check(occ(vec![a, b, c, m], vec![[0, 1, 2], tri]), part);
    }
    // A concave pentagon fanned from a convex corner: its first and last
    // triangles overlap, meeting at that corner only.
    let pentagon = vec![
        v(0.0, -0.2, 1.0),
        v(0.4, -0.2, 1.0),
        v(0.1, 0.0, 1.0),
        v(0.4, 0.2, 1.0),
        v(0.0, 0.2, 1.0),
    ];
    check(
        occ(pentagon.clone(), vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]),
        Some("itself"),
    );
    // Fanned from the reflex corner: a sound triangulation.
    check(occ(pentagon, vec![[2, 3, 4], [2, 4, 0], [2, 0, 1]]), None);
}

/// A lamp, a fixed floor cube and a moving box: posing the box, or seeing
/// the scene from another sensor, keeps the lamp's and the floor's tables
/// (the same caster and edges, not copies), and builds the box's anew.
#[test]
fn a_pose_rebuilds_only_the_moved_meshes_tables() {
    use crate::method::model::Model;
    let s = Scene::new(
        vec![
            lamp(),
            cube("floor", DVec3::new(0.0, 0.0, -2.0), 0.5, Surface::Absorber),
            cube("box", DVec3::new(0.2, 0.1, 1.0), 0.25, Surface::Absorber),
        ],
        vec![
            param("tx", "box", Motion::TranslateX),
            param(
                "rz",
                "box",
                Motion::Rotate {
                    axis: DVec3::Z,
                    pivot: None,
                },
            ),
        ],
        irradiance(),
    )
    .unwrap();
    let same = |a: &Scene, b: &Scene, k: usize| std::sync::Arc::ptr_eq(&a.part(k), &b.part(k));
    let posed = Model::posed(&s, &[0.1, 0.3]).unwrap();
    assert!(same(&s, &posed, 0) && same(&s, &posed, 1));
    assert!(!same(&s, &posed, 2));
    // The pose with no offset is the scene itself, tables and all.
    let still = Model::posed(&s, &[0.0, 0.0]).unwrap();
    assert!((0..3).all(|k| same(&s, &still, k)));
    let seen = s
        .with_sensor(Sensor::Radiance {
            point: DVec3::new(0.0, 0.0, 0.5),
            direction: DVec3::Z,
        })
        .unwrap();
    assert!((0..3).all(|k| same(&s, &seen, k)));
    let displaced = s.displaced(1, 0.01).unwrap();
    assert!(same(&s, &displaced, 0) && same(&s, &displaced, 1) && !same(&s, &displaced, 2));
}

/// A pose validated where it moved agrees with the same meshes validated
/// whole ([`Scene::new`]): the same verdict (the box driven into the floor
/// or the lamp, or the scene grown, or shrunk) and the same tables.
#[test]
fn a_pose_is_validated_as_a_new_scene() {
    use crate::method::model::Model;
    let s = Scene::new(
        vec![
            lamp(),
            cube("floor", DVec3::new(0.0, 0.0, -2.0), 0.5, Surface::Absorber),
            cube("box", DVec3::new(0.2, 0.1, 1.0), 0.25, Surface::Absorber),
            fog("fog", DVec3::new(-1.5, 0.0, 0.0), 0.4),
        ],
        vec![
            param("tz", "box", Motion::TranslateZ),
            param("fx", "fog", Motion::TranslateX),
            param("grow", "box", Motion::Scale { pivot: None }),
        ],
        irradiance(),
    )
    .unwrap();
    let whole = |offsets: &[f64]| {
        let params = s.parameters();
        let owner: Vec<u32> = (0..params.len()).map(|j| s.parameter_shape(j)).collect();
        let (shapes, params) =
            crate::scene::pose::pose(s.shapes(), params, &owner, offsets).unwrap();
        Scene::new(shapes, params, s.sensor())
    };
    let cases: [&[f64]; 7] = [
        &[0.1, 0.0, 0.0],
        &[-2.4, 0.0, 0.0],  // into the floor
        &[0.0, 1.8, 0.0],   // the fog around the sensor
        &[0.0, 1.2, 0.0],   // the fog into the box's way, not touching
        &[0.0, -30.0, 0.0], // the scene grows
        &[0.0, 0.0, 3.0],   // the box grows into the lamp
        &[0.0, 0.0, -0.5],  // the box shrinks
    ];
    for offsets in cases {
        let (a, b) = (Model::posed(&s, offsets), whole(offsets));
        match (&a, &b) {
            (Ok(a), Ok(b)) => {
                assert_eq!(a.shapes(), b.shapes(), "{offsets:?}");
                assert_eq!(a.size(), b.size());
                assert_eq!(a.sensor_medium(), b.sensor_medium(), "{offsets:?}");
                for k in 0..4 {
                    assert_eq!(a.parent_medium(k), b.parent_medium(k));
                    assert_eq!(a.is_solid(k), b.is_solid(k));
                    assert_eq!(a.is_closed(k), b.is_closed(k));
                }
                assert_eq!(a.volume, b.volume);
            }
            (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{offsets:?}"),
            _ => panic!("{offsets:?}: posed {a:?}, whole {b:?}"),
        }
    }
}
