//! The shipped 3D inverse problems (`scenes/mesh/inverse_*.toml`): their
//! true poses and the closed forms their targets are computed from. Book:
//! chapter "Sensitivities at work".
//!
//! Every problem lights its scene with one planar emitter (the lamp) and
//! measures it past one moving shape, so each measurement has a closed
//! form at any pose ([`closed_form`]):
//!
//! - an irradiance sensor past a black planar polygon: Lambert's formula
//!   on the lamp clipped by the polygon's shadow
//!   ([`exact::occluded_irradiance`]);
//! - a radiance sensor through an absorbing box (`κs = 0`): the lamp's
//!   radiance times `exp(−κe · chord)` if the ray meets the lamp;
//! - a camera looking straight at the lamp's plane past a black polygon:
//!   each pixel the share of its footprint on that plane that sees the lamp
//!   past the polygon's central projection, times the lamp's radiance
//!   (convex clipping: the camera samples its pixels uniformly on an image
//!   plane parallel to the lamp, so shares of area are exact).
use super::exact;
use super::{Scene, Sensor, Surface};
use crate::error::Error;
use crate::estimator::PixelSample;
use crate::optimize::Study;
use crate::scene::config;
use glam::{DVec2, DVec3};

/// A shipped inverse problem: its file (relative to the repository) and
/// the true offsets of its parameters from the file's pose, in the file's
/// parameter order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Problem {
    /// The scene file, relative to the repository's root.
    pub file: &'static str,
    /// The offsets the targets were computed at.
    pub truth: &'static [f64],
}

/// A black triangle's translation and turn from the irradiance at nine
/// points on the ground.
pub const TRIANGLE: Problem = Problem {
    file: "scenes/mesh/inverse_triangle.toml",
    truth: &[0.08, -0.05, 0.25],
};

/// The same triangle from a 12 × 12 image of it against the lamp.
pub const CAMERA: Problem = Problem {
    file: "scenes/mesh/inverse_camera.toml",
    truth: &[0.08, -0.05, 0.25],
};

/// An absorbing fog cube's horizontal position from the lamp's radiance
/// seen through it along five rays.
pub const FOG: Problem = Problem {
    file: "scenes/mesh/inverse_fog.toml",
    truth: &[0.05, -0.04],
};

/// The three problems.
pub const PROBLEMS: [Problem; 3] = [TRIANGLE, CAMERA, FOG];

impl Problem {
    /// The file's path under `root` (the repository).
    pub fn path(&self, root: &std::path::Path) -> std::path::PathBuf {
        root.join(self.file)
    }
}

/// Every measurement's closed form (a camera's per pixel, row-major) with
/// the study's scene at `offsets`.
pub fn targets(study: &Study<Scene>, offsets: &[f64]) -> Result<Vec<Vec<f64>>, Error> {
    let scene = study.posed(offsets)?;
    study
        .measurements()
        .iter()
        .map(|m| closed_form(&scene, &m.sensor))
        .collect()
}

/// What `sensor` reads in `scene` (a camera: one value per pixel,
/// row-major, row 0 at the top), when the scene is one of the forms above;
/// an error says which assumption fails otherwise.
pub fn closed_form(scene: &Scene, sensor: &Sensor) -> Result<Vec<f64>, Error> {
    let (lamp, radiance) = lamp(scene)?;
    match *sensor {
        Sensor::Irradiance { point, normal } => {
            let occ = single(scene, |s| s == Surface::Absorber, "black")?;
            Ok(vec![exact::occluded_irradiance(
                point,
                normal.normalize(),
                &lamp,
                &occ,
                radiance,
            )?])
        }
        Sensor::Radiance { point, direction } => {
            let d = direction.normalize();
            if scene
                .shapes()
                .iter()
                .any(|s| s.surface == Surface::Absorber)
            {
                return config(
                    "closed form: a radiance sensor's scene may hold no black shape".into(),
                );
            }
            let Some(x) = plane_hit(&lamp, point, d) else {
                return Ok(vec![0.0]);
            };
            if !inside(&lamp, x) {
                return Ok(vec![0.0]);
            }
            let mut tau = 0.0;
            for s in scene.shapes() {
                let Some(m) = s.medium else { continue };
                if m.ks != 0.0 {
                    return config(format!(
                        "closed form: medium {:?} scatters (ks = {})",
                        s.name, m.ks
                    ));
                }
                tau += m.ke * box_chord(&s.vertices, point, d, (x - point).length())?;
            }
            Ok(vec![radiance * (-tau).exp()])
        }
        Sensor::Camera(cam) => {
            let occ = single(scene, |s| s == Surface::Absorber, "black")?;
            let f = cam.frame();
            let (nn, c) = plane(&lamp);
            if nn.dot(f.r).abs() > 1e-12 || nn.dot(f.u).abs() > 1e-12 {
                return config(
                    "closed form: the camera's image plane must be parallel to the lamp".into(),
                );
            }
            let eye = f.eye;
            let depth = c - nn.dot(eye);
            // The image point (x, y) at unit distance along f lands on the
            // lamp's plane at eye + (f + x r + y u) depth / (N·f).
            let scale = depth / nn.dot(f.f);
            if scale.is_nan() || scale <= 0.0 {
                return config("closed form: the camera must face the lamp's plane".into());
            }
            let (e1, e2) = nn.any_orthonormal_pair();
            let flat = |p: DVec3| DVec2::new(e1.dot(p), e2.dot(p));
            let on_lamp = |x: f64, y: f64| flat(eye + (f.f + f.r * x + f.u * y) * scale);
            let lamp2 = ccw(lamp.iter().map(|&p| flat(p)).collect());
            let mut shadow = Vec::new();
            for &q in &occ {
                let s = nn.dot(q - eye);
                if !(s > 0.0 && s < depth) {
                    return config(
                        "closed form: the black polygon must lie between the camera and the lamp"
                            .into(),
                    );
                }
                shadow.push(flat(eye + (q - eye) * (depth / s)));
            }
            let shadow = ccw(shadow);
            (0..cam.width * cam.height)
                .map(|pixel| {
                    let r = f.rect(PixelSample {
                        pixel,
                        stratum: 0,
                        strata: 1,
                    });
                    let rect = ccw(vec![
                        on_lamp(r[0], r[2]),
                        on_lamp(r[1], r[2]),
                        on_lamp(r[1], r[3]),
                        on_lamp(r[0], r[3]),
                    ]);
                    let lit = clip(&rect, &lamp2);
                    let hidden = clip(&lit, &shadow);
                    Ok(radiance * (area(&lit) - area(&hidden)) / area(&rect))
                })
                .collect()
        }
    }
}

/// The scene's one emitter (its vertices as a polygon, in the file's
/// order) and its radiance.
fn lamp(scene: &Scene) -> Result<(Vec<DVec3>, f64), Error> {
    let lamp = single(scene, |s| matches!(s, Surface::Emitter { .. }), "emitting")?;
    let radiance = scene
        .shapes()
        .iter()
        .find_map(|s| match s.surface {
            Surface::Emitter { radiance } => Some(radiance),
            _ => None,
        })
        .unwrap_or(0.0);
    Ok((lamp, radiance))
}

/// The vertices of the one shape whose surface passes `is`.
fn single(scene: &Scene, is: impl Fn(Surface) -> bool, what: &str) -> Result<Vec<DVec3>, Error> {
    let mut found = scene.shapes().iter().filter(|s| is(s.surface));
    match (found.next(), found.next()) {
        (Some(s), None) => Ok(s.vertices.clone()),
        _ => config(format!("closed form: the scene must hold one {what} shape")),
    }
}

/// The unit normal (Newell) and offset of a planar polygon's plane.
fn plane(poly: &[DVec3]) -> (DVec3, f64) {
    let mut n = DVec3::ZERO;
    for (i, &a) in poly.iter().enumerate() {
        n += a.cross(poly[(i + 1) % poly.len()]);
    }
    let n = n.normalize();
    (n, n.dot(poly[0]))
}

/// Where the ray from `p` along `d` meets the polygon's plane, if ahead.
fn plane_hit(poly: &[DVec3], p: DVec3, d: DVec3) -> Option<DVec3> {
    let (n, c) = plane(poly);
    let t = (c - n.dot(p)) / n.dot(d);
    (t > 0.0 && t.is_finite()).then(|| p + d * t)
}

/// Whether `x` (in the plane of the convex polygon `poly`) lies inside it.
fn inside(poly: &[DVec3], x: DVec3) -> bool {
    let (n, _) = plane(poly);
    let sides: Vec<f64> = (0..poly.len())
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            n.dot((b - a).cross(x - a))
        })
        .collect();
    sides.iter().all(|&s| s > 0.0) || sides.iter().all(|&s| s < 0.0)
}

/// The length of the ray `p + t d`, `t ∈ [0, t_max]`, inside the
/// axis-aligned box whose corners are `vertices` (refused if they are not
/// the eight corners of one).
fn box_chord(vertices: &[DVec3], p: DVec3, d: DVec3, t_max: f64) -> Result<f64, Error> {
    let lo = vertices.iter().fold(DVec3::INFINITY, |a, &v| a.min(v));
    let hi = vertices.iter().fold(DVec3::NEG_INFINITY, |a, &v| a.max(v));
    let corner = |v: DVec3| {
        (0..3).all(|k| v[k] == lo[k] || v[k] == hi[k])
            && (0..3).all(|k| v[k] != lo[k] || v[k] != hi[k])
    };
    if vertices.len() != 8 || !vertices.iter().all(|&v| corner(v)) {
        return config("closed form: a medium must be an axis-aligned box".into());
    }
    let (mut t0, mut t1) = (0.0_f64, t_max);
    for k in 0..3 {
        let (a, b) = ((lo[k] - p[k]) / d[k], (hi[k] - p[k]) / d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    Ok((t1 - t0).max(0.0))
}

/// The polygon counter-clockwise.
fn ccw(mut p: Vec<DVec2>) -> Vec<DVec2> {
    if signed_area(&p) < 0.0 {
        p.reverse();
    }
    p
}

fn signed_area(p: &[DVec2]) -> f64 {
    (0..p.len())
        .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
        .sum::<f64>()
        / 2.0
}

/// The area of a polygon (0 for fewer than 3 vertices).
fn area(p: &[DVec2]) -> f64 {
    if p.len() < 3 {
        0.0
    } else {
        signed_area(p).abs()
    }
}

/// `p` clipped by the convex counter-clockwise polygon `c`
/// (Sutherland–Hodgman).
fn clip(p: &[DVec2], c: &[DVec2]) -> Vec<DVec2> {
    let mut out = p.to_vec();
    for i in 0..c.len() {
        if out.is_empty() {
            break;
        }
        let (a, b) = (c[i], c[(i + 1) % c.len()]);
        let side = |q: DVec2| (b - a).perp_dot(q - a);
        let input = std::mem::take(&mut out);
        for k in 0..input.len() {
            let (s, e) = (input[k], input[(k + 1) % input.len()]);
            let (hs, he) = (side(s), side(e));
            if hs >= 0.0 {
                out.push(s);
            }
            if (hs >= 0.0) != (he >= 0.0) {
                out.push(s + (e - s) * (hs / (hs - he)));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_clipped_by_itself_shifted_keeps_the_overlap() {
        let sq = |x: f64, y: f64| {
            vec![
                DVec2::new(x, y),
                DVec2::new(x + 1.0, y),
                DVec2::new(x + 1.0, y + 1.0),
                DVec2::new(x, y + 1.0),
            ]
        };
        let c = clip(&sq(0.0, 0.0), &sq(0.5, 0.25));
        assert!((area(&c) - 0.375).abs() < 1e-15);
        assert_eq!(area(&clip(&sq(0.0, 0.0), &sq(2.0, 0.0))), 0.0);
    }

    #[test]
    fn a_chord_through_a_unit_box() {
        let v: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        let d = DVec3::new(1.0, 1.0, 0.0).normalize();
        let l = box_chord(&v, DVec3::new(-0.5, 0.0, 0.5), d, 10.0).unwrap();
        assert!((l - 0.5 * 2f64.sqrt()).abs() < 1e-15);
    }
}
