//! 3D scenes built in code for the 3D figures (`mesh::figures`, with the
//! `figures` feature) and the 3D rows of `geosens compare`: a black
//! triangle occluder under the unit-square lamp with its closed form, and
//! the configurations where the methods struggle. Every scene here has the
//! lamp of `scenes/mesh/occluder.toml` (side 1, radiance 1, at z = 2 over
//! the origin) and an irradiance sensor at the origin with normal `+z`.
use super::exact::{BoxScene, occluded_irradiance_with_gradient, occluder_motions, sensitivity};
use super::{Medium, Motion, Parameter, Scene, Sensor, Shape, Surface};
use crate::error::Error;
use glam::DVec3;
use std::f64::consts::TAU;

/// The lamp: a square of side 1 at z = 2 over the origin, radiance 1.
pub fn lamp() -> Shape {
    let v = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
        .map(|(x, y)| DVec3::new(x, y, 2.0))
        .to_vec();
    Shape {
        name: "lamp".into(),
        vertices: v,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Emitter { radiance: 1.0 },
        medium: None,
    }
}

/// The irradiance sensor at the origin, normal `+z`.
pub fn up() -> Sensor {
    Sensor::Irradiance {
        point: DVec3::ZERO,
        normal: DVec3::Z,
    }
}

/// One parameter `name` moving shape `shape` by `motion`.
fn parameter(name: &str, shape: &str, motion: Motion) -> Parameter {
    Parameter {
        name: name.into(),
        shape: shape.into(),
        motion,
        bounds: None,
    }
}

/// A closed axis-aligned box with the corners of
/// [`BoxScene::corners`](super::exact::BoxScene::corners) (bit 0: x, bit 1:
/// y, bit 2: z), outward winding.
pub fn box_shape(
    name: &str,
    corners: [DVec3; 8],
    surface: Surface,
    medium: Option<Medium>,
) -> Shape {
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    Shape {
        name: name.into(),
        vertices: corners.to_vec(),
        triangles: quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect(),
        surface,
        medium,
    }
}

/// An axis-aligned cube of half-side `half` centred at `centre` (a
/// [`box_shape`]).
pub fn cube_shape(
    name: &str,
    centre: DVec3,
    half: f64,
    surface: Surface,
    medium: Option<Medium>,
) -> Shape {
    let corners = std::array::from_fn(|i| {
        let s = |b: usize| if i >> b & 1 == 1 { half } else { -half };
        centre + DVec3::new(s(0), s(1), s(2))
    });
    box_shape(name, corners, surface, medium)
}

/// A horizontal square of half-side `half` centred at `centre`, two
/// triangles.
pub fn square_shape(name: &str, centre: DVec3, half: f64, surface: Surface) -> Shape {
    let v = [(-half, -half), (half, -half), (half, half), (-half, half)]
        .map(|(x, y)| centre + DVec3::new(x, y, 0.0));
    Shape {
        name: name.into(),
        vertices: v.to_vec(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface,
        medium: None,
    }
}

/// The unit icosphere subdivided `n` times: welded (a vertex shared by
/// several triangles is the same `DVec3`, bit for bit), `20·4ⁿ` triangles,
/// outward. Returns the vertices and the triangles as vertex indices.
pub fn icosphere(n: u32) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, g, 0.0),
        (1.0, g, 0.0),
        (-1.0, -g, 0.0),
        (1.0, -g, 0.0),
        (0.0, -1.0, g),
        (0.0, 1.0, g),
        (0.0, -1.0, -g),
        (0.0, 1.0, -g),
        (g, 0.0, -1.0),
        (g, 0.0, 1.0),
        (-g, 0.0, -1.0),
        (-g, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..n {
        let mut mid: std::collections::HashMap<(usize, usize), usize> =
            std::collections::HashMap::new();
        let mut m = |a: usize, b: usize, v: &mut Vec<DVec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((0.5 * (v[a] + v[b])).normalize());
                v.len() - 1
            })
        };
        f = f
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (m(a, b, &mut v), m(b, c, &mut v), m(c, a, &mut v));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    (v, f)
}

/// A horizontal black equilateral triangle: the occluder of the 3D figures
/// and of `geosens compare`'s 3D table. Its three parameters, in the order
/// of [`TriangleOccluder::PARAMETERS`]: translation along x, rotation about
/// the vertical through its centre, scale about its centre (π = factor −
/// 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleOccluder {
    /// The centre (`0 < z < 2`).
    pub centre: DVec3,
    /// Distance from the centre to each vertex.
    pub radius: f64,
    /// Angle of the first vertex about the vertical through the centre
    /// (radians from +x, counter-clockwise seen from above).
    pub angle: f64,
}

impl TriangleOccluder {
    /// The nominal occluder: centre `(0.2, 0.05, 1)`, circumradius 0.2,
    /// first vertex at 0.3 rad. Its shadow (twice its size on the lamp's
    /// plane) crosses the lamp's right edge, no edge parallel to the lamp's.
    pub const NOMINAL: TriangleOccluder = TriangleOccluder {
        centre: DVec3::new(0.2, 0.05, 1.0),
        radius: 0.2,
        angle: 0.3,
    };

    /// The names of the three parameters.
    pub const PARAMETERS: [&'static str; 3] = ["tri_tx", "tri_rot", "tri_scale"];

    /// The vertices.
    pub fn vertices(&self) -> [DVec3; 3] {
        std::array::from_fn(|k| {
            let a = self.angle + TAU * k as f64 / 3.0;
            self.centre + self.radius * DVec3::new(a.cos(), a.sin(), 0.0)
        })
    }

    /// The three motions, pivots at the centre.
    pub fn motions(&self) -> [Motion; 3] {
        let m = occluder_motions(self.centre);
        [m[0], m[3], m[4]]
    }

    /// The occluder moved by parameter `k` to `π = pi` (the translation
    /// shifts the centre, the rotation turns the vertices, the scale
    /// multiplies the radius by `1 + pi`).
    pub fn moved(&self, k: usize, pi: f64) -> TriangleOccluder {
        let mut t = *self;
        match k {
            0 => t.centre.x += pi,
            1 => t.angle += pi,
            _ => t.radius *= 1.0 + pi,
        }
        t
    }

    /// The scene with the parameters `which` (indices into
    /// [`Self::PARAMETERS`], in that order).
    pub fn scene(&self, which: &[usize]) -> Result<Scene, Error> {
        let occ = Shape {
            name: "occ".into(),
            vertices: self.vertices().to_vec(),
            triangles: vec![[0, 1, 2]],
            surface: Surface::Absorber,
            medium: None,
        };
        let motions = self.motions();
        let parameters = which
            .iter()
            .map(|&k| parameter(Self::PARAMETERS[k], "occ", motions[k]))
            .collect();
        Scene::new(vec![lamp(), occ], parameters, up())
    }

    /// The closed form: `E` and `∂E/∂π` for the three parameters (the scale's
    /// about the current size: `r ∂E/∂r`).
    pub fn exact(&self) -> Result<(f64, [f64; 3]), Error> {
        let lamp: Vec<DVec3> = lamp().vertices;
        let q = self.vertices();
        let (e, g) = occluded_irradiance_with_gradient(DVec3::ZERO, DVec3::Z, &lamp, &q, 1.0)?;
        Ok((e, self.motions().map(|m| sensitivity(&g, &q, m))))
    }
}

/// A stability case: a scene with one parameter `p` and its closed-form
/// `∂E/∂p` where one exists.
pub type Case = (Scene, Option<f64>);

fn one(shape: Shape, motion: Motion, exact: Option<f64>) -> Result<Case, Error> {
    let name = shape.name.clone();
    let scene = Scene::new(
        vec![lamp(), shape],
        vec![parameter("p", &name, motion)],
        up(),
    )?;
    Ok((scene, exact))
}

/// A sensor close to a moving face: the nominal triangle shrunk about the
/// sensor by `d` (centre `d (0.2, 0.05, 1)`, circumradius `0.2 d`, so at
/// height `d`), translated along x. Its shadow, so `E`, does not depend on
/// `d`; `∂E/∂p` grows like `1/d`.
pub fn near_sensor(d: f64) -> Result<Case, Error> {
    let t = TriangleOccluder {
        centre: TriangleOccluder::NOMINAL.centre * d,
        radius: TriangleOccluder::NOMINAL.radius * d,
        angle: TriangleOccluder::NOMINAL.angle,
    };
    let (_, s) = t.exact()?;
    let (scene, _) = one(t.scene(&[])?.shapes()[1].clone(), Motion::TranslateX, None)?;
    Ok((scene, Some(s[0])))
}

/// Shadow edge meeting the lamp's edge: a black square (half-side 0.25 at
/// z = 1) whose shadow's left edge runs parallel to the lamp's right edge a
/// gap `g` inside it (the square's left edge on the sight lines to the
/// lamp's edge at `g = 0`), translated along x. `∂E/∂p` tends to a non-zero
/// limit as `g → 0⁺` and jumps to 0 at `g = 0`.
pub fn grazing(g: f64) -> Result<Case, Error> {
    let c = DVec3::new(0.5 - 0.5 * g, 0.05, 1.0);
    let q: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(a, b)| c + 0.25 * DVec3::new(a, b, 0.0))
        .collect();
    let lamp_v = lamp().vertices;
    let (_, grad) = occluded_irradiance_with_gradient(DVec3::ZERO, DVec3::Z, &lamp_v, &q, 1.0)?;
    let exact = sensitivity(&grad, &q, Motion::TranslateX);
    let occ = Shape {
        name: "occ".into(),
        vertices: q,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        surface: Surface::Absorber,
        medium: None,
    };
    one(occ, Motion::TranslateX, Some(exact))
}

/// A thin dense fog slab: a box of side 0.6 × 0.6 and thickness `t`
/// centred at `(0.2, 0.05, 1)`, vertical optical thickness 1 (κe = 1/t,
/// albedo 0.8, isotropic), translated along x. No closed form.
pub fn thin_fog(t: f64) -> Result<Case, Error> {
    let b = BoxScene::shipped(DVec3::new(0.2, 0.05, 1.0), 1.0);
    let corners = b.corners().map(|q| {
        let r = q - b.centre;
        b.centre + DVec3::new(0.6 * r.x, 0.6 * r.y, t * r.z)
    });
    let ke = 1.0 / t;
    let fog = Medium {
        ks: 0.8 * ke,
        ke,
        g: 0.0,
    };
    one(
        box_shape("fog", corners, Surface::Transparent, Some(fog)),
        Motion::TranslateX,
        None,
    )
}

/// A box face near a plane through the sensor: a black cube of side 0.3
/// spanning `δ ≤ y ≤ δ + 0.3` (x from −0.05, z from 0.85), translated along
/// y. At `δ = 0` its face `y = 0` lies in a plane through the sensor, seen
/// edge-on: `E` has a kink there and the closed form gives the one-sided
/// derivative of the branch its tie-breaks pick
/// ([`BoxScene`]).
pub fn box_kink(delta: f64) -> Result<Case, Error> {
    let b = BoxScene::shipped(DVec3::new(0.1, delta + 0.15, 1.0), 0.3);
    let exact = b.sensitivities()?[1];
    one(
        box_shape("box", b.corners(), Surface::Absorber, None),
        Motion::TranslateY,
        Some(exact),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_triangle_and_the_cases_build() {
        let t = TriangleOccluder::NOMINAL;
        let s = t.scene(&[0, 1, 2]).unwrap();
        assert_eq!(s.parameters().len(), 3);
        let (e, d) = t.exact().unwrap();
        assert!(e > 0.0 && e < 0.25 && d.iter().all(|v| v.is_finite()));
        // The scale is about the current size.
        let h = 1e-6;
        let (ep, _) = t.moved(2, h).exact().unwrap();
        let (em, _) = t.moved(2, -h).exact().unwrap();
        assert!(((ep - em) / (2.0 * h) - d[2]).abs() < 1e-6);
        for d in [1.0, 0.01] {
            assert!(near_sensor(d).unwrap().1.unwrap().is_finite());
        }
        assert!(grazing(1e-3).unwrap().1.unwrap() > 0.0);
        thin_fog(0.01).unwrap();
        box_kink(0.0).unwrap();
    }
}
