//! The path core in three dimensions, untouched: a minimal triangle scene
//! (brute-force ray casting, the 3D cosine lobe, emitters drawn by area)
//! implements `geosens::path::Geometry` for `DVec3`, and the intensity
//! estimator, the very loop flatland runs, gives the closed-form irradiance
//! under a square lamp, with next-event estimation and without.
use geosens::path::intensity::{IntensityEstimator, PlainEstimator};
use geosens::path::{Coefficients, Geometry, Hit, Lobe, MediumId, Prim, Sensor, Surface};
use geosens::rng::PathRng;
use geosens::{Quantity, RunConfig, run};
use glam::DVec3;
use rand::RngExt;
use std::f64::consts::PI;

/// The 3D cosine lobe `c (ω·n)⁺`, sampled with density `(ω·n)⁺/π`.
#[derive(Debug, Clone, Copy)]
struct Cosine {
    n: DVec3,
    c: f64,
}

impl Lobe<DVec3> for Cosine {
    fn value(&self, w: DVec3) -> f64 {
        self.c * w.dot(self.n).max(0.0)
    }
    fn pdf(&self, w: DVec3) -> f64 {
        w.dot(self.n).max(0.0) / PI
    }
    fn weight(&self) -> f64 {
        self.c * PI
    }
    fn sample(&self, rng: &mut PathRng) -> DVec3 {
        // Malley: a uniform point on the disc, lifted to the hemisphere.
        let (u1, u2): (f64, f64) = (rng.random(), rng.random());
        let r = u1.sqrt();
        let (s, c) = (2.0 * PI * u2).sin_cos();
        let (t, b) = self.n.any_orthonormal_pair();
        r * c * t + r * s * b + (1.0 - u1).max(0.0).sqrt() * self.n
    }
    fn dlog(&self, w: DVec3, wd: DVec3) -> f64 {
        wd.dot(self.n) / w.dot(self.n)
    }
}

/// Triangles, each an emitter or an absorber; an irradiance sensor at the
/// origin looking up +z.
struct Triangles {
    tris: Vec<([DVec3; 3], Surface)>,
    /// Emitting triangles with their cumulative area.
    emitters: Vec<(u32, f64)>,
}

impl Triangles {
    fn new(tris: Vec<([DVec3; 3], Surface)>) -> Triangles {
        let mut total = 0.0;
        let emitters = tris
            .iter()
            .enumerate()
            .filter(|(_, t)| matches!(t.1, Surface::Emitter { .. }))
            .map(|(i, t)| {
                total += area(&t.0);
                (i as u32, total)
            })
            .collect();
        Triangles { tris, emitters }
    }
    fn emitter_area(&self) -> f64 {
        self.emitters.last().map_or(0.0, |e| e.1)
    }
}

fn area(t: &[DVec3; 3]) -> f64 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

impl Geometry for Triangles {
    type V = DVec3;
    type Lobe = Cosine;

    fn size(&self) -> f64 {
        4.0
    }
    fn sensor(&self) -> Sensor<DVec3> {
        Sensor::Irradiance {
            point: DVec3::ZERO,
            normal: DVec3::Z,
        }
    }
    fn sensor_medium(&self) -> MediumId {
        None
    }
    /// Möller–Trumbore against every triangle.
    fn cast(&self, x: DVec3, w: DVec3, skip: Prim) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for (i, (t, _)) in self.tris.iter().enumerate() {
            if i as u32 == skip {
                continue;
            }
            let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
            let p = w.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-300 {
                continue;
            }
            let s = x - t[0];
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = w.dot(q) / det;
            let d = e2.dot(q) / det;
            if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && d > 1e-12 && best.is_none_or(|b| d < b.t) {
                best = Some(Hit {
                    t: d,
                    prim: i as u32,
                });
            }
        }
        best
    }
    fn visible(&self, x: DVec3, y: DVec3, skip: Prim) -> bool {
        let d = y - x;
        let len = d.length();
        self.cast(x, d / len, skip)
            .is_none_or(|h| h.t >= len * (1.0 - 1e-9))
    }
    fn shape(&self, p: Prim) -> u32 {
        p
    }
    fn surface(&self, p: Prim) -> Surface {
        self.tris[p as usize].1
    }
    fn normal(&self, p: Prim, _y: DVec3) -> DVec3 {
        let t = &self.tris[p as usize].0;
        (t[1] - t[0]).cross(t[2] - t[0]).normalize()
    }
    fn coefficients(&self, _m: MediumId) -> Option<Coefficients> {
        None
    }
    fn medium_chord(&self, _m: MediumId) -> f64 {
        f64::INFINITY
    }
    fn crossed(&self, m: MediumId, _k: u32) -> MediumId {
        m
    }
    fn cosine_lobe(&self, n: DVec3, c: f64) -> Cosine {
        Cosine { n, c }
    }
    fn phase_lobe(&self, _m: MediumId, w: DVec3) -> Cosine {
        Cosine { n: w, c: 0.0 }
    }
    fn emitter_point(&self, rng: &mut PathRng) -> Option<(DVec3, Prim)> {
        let total = self.emitter_area();
        let s = rng.random::<f64>() * total;
        let i = self
            .emitters
            .partition_point(|e| e.1 <= s)
            .min(self.emitters.len() - 1);
        let p = self.emitters[i].0;
        let t = &self.tris[p as usize].0;
        // A uniform point of the triangle: fold the unit square.
        let (r1, r2): (f64, f64) = (rng.random(), rng.random());
        let (b0, b1) = if r1 + r2 > 1.0 {
            (1.0 - r1, 1.0 - r2)
        } else {
            (r1, r2)
        };
        Some((t[0] + b0 * (t[1] - t[0]) + b1 * (t[2] - t[0]), p))
    }
    fn light_pdf(&self, x: DVec3, y: DVec3, p: Prim) -> f64 {
        let d = y - x;
        let r2 = d.length_squared();
        let c = (d / r2.sqrt()).dot(self.normal(p, y)).abs();
        if c > 0.0 {
            r2 / (c * self.emitter_area())
        } else {
            f64::INFINITY
        }
    }
    fn parameters(&self) -> usize {
        0
    }
    fn parameter_shape(&self, _j: usize) -> u32 {
        unreachable!("no parameters")
    }
    fn velocity(&self, _j: usize, _q: DVec3) -> DVec3 {
        DVec3::ZERO
    }
    fn spin(&self, _j: usize) -> DVec3 {
        DVec3::ZERO
    }
}

/// A square lamp of half-side `a` at height `h` over the origin.
fn lamp(a: f64, h: f64) -> Triangles {
    let v = [(-a, -a), (a, -a), (a, a), (-a, a)].map(|(x, y)| DVec3::new(x, y, h));
    let lit = Surface::Emitter { radiance: 1.0 };
    Triangles::new(vec![([v[0], v[1], v[2]], lit), ([v[0], v[2], v[3]], lit)])
}

/// The irradiance under the square: `π L` times its view factor, four
/// corner rectangles of sides `a × a` at distance `h`.
fn exact(a: f64, h: f64) -> f64 {
    let x = a / h;
    let s = (1.0 + x * x).sqrt();
    let corner = (x / s * (x / s).atan() + x / s * (x / s).atan()) / (2.0 * PI);
    PI * 4.0 * corner
}

#[test]
fn the_one_loop_traces_a_triangle_scene() {
    let (a, h) = (0.8, 1.0);
    let e = exact(a, h);
    let cfg = RunConfig::new(400_000, 12).unwrap();
    let nee = run(
        &IntensityEstimator {
            geometry: lamp(a, h),
        },
        &cfg,
    )
    .unwrap();
    let plain = run(
        &PlainEstimator {
            geometry: lamp(a, h),
        },
        &cfg,
    )
    .unwrap();
    for r in [nee, plain] {
        let i = r.get(&Quantity::Intensity).unwrap();
        assert!(i.z_score(e) < 4.0, "{}: {i:?} vs {e}", r.method);
        assert!(i.stderr < 0.01 * e, "{}: {i:?}", r.method);
    }
}
