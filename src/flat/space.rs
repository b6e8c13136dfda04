//! Flatland behind the path core's traits: [`Plane`] implements
//! [`Geometry`] (rays through the scene's casters, the 2D cosine lobe and
//! the wrapped-Cauchy phase function, emitters drawn by length) and
//! [`Boundaries`] (the corners of opaque shapes, what either side of a
//! corner sees, and the expectation method's warp: piecewise linear on the
//! circle between the nearest visible corners). Book: chapter "Flatland:
//! one deformation, three estimators", sections "Corner jumps" and "The
//! warp field".
use super::geometry::{NO_SEGMENT, cross, perp};
use super::scene::{Phase, Scene, Sensor as FlatSensor};
use crate::path::walk::Vertex;
use crate::path::{
    Boundaries, BoundaryPoint, Geometry, Hit, Lobe, MediumId, NO_PRIM, Prim, Sensor, Side, Surface,
};
use crate::rng::PathRng;
use glam::DVec2;
use rand::RngExt;
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::Arc;

/// A flatland scene with the tables the derivative methods need.
#[derive(Debug, Clone)]
pub struct Plane {
    scene: Arc<Scene>,
    /// Per corner (the scene's `corners()` order), its segments: the one it
    /// starts and the one it ends (`NO_SEGMENT` at a polyline's ends).
    corner_segments: Vec<[u32; 2]>,
    /// Indices of the corners of moving shapes.
    moving_corners: Vec<u32>,
    /// Per corner, the weight with which rendering's boundary term draws
    /// it: 1 at a polyline's end, `θ/π` at a corner turning by `θ` (the
    /// share of viewpoints from which it is a silhouette; two collinear
    /// faces of one surface have no jump at all).
    corner_weight: Vec<f64>,
    /// Cumulative weights over all corners, and over the moving ones.
    all_cdf: Vec<f64>,
    moving_cdf: Vec<f64>,
    /// The corners visible from an irradiance sensor in front of it, by
    /// angle from +x: the warp's knots there, the same for every path.
    sensor_knots: Vec<Knot>,
}

/// A knot of the warp: angle from the sampled direction, corner, shape.
type Knot = (f64, DVec2, u32);

impl Plane {
    /// The tables of `scene`.
    pub fn new(scene: Arc<Scene>) -> Plane {
        let mut corner_segments = Vec::with_capacity(scene.corners().len());
        let mut first = 0u32;
        for s in scene.shapes() {
            let n = s.vertices.len() as u32;
            let m = if s.closed { n } else { n - 1 };
            if s.surface.is_opaque() {
                for i in 0..n {
                    let starts = if i < m { first + i } else { NO_SEGMENT };
                    let ends = if i > 0 {
                        first + i - 1
                    } else if s.closed {
                        first + m - 1
                    } else {
                        NO_SEGMENT
                    };
                    corner_segments.push([starts, ends]);
                }
            }
            first += m;
        }
        let params = scene.parameters().len();
        let moving = |k: u32| (0..params).any(|j| scene.parameter_shape(j) == k);
        let moving_corners: Vec<u32> = scene
            .corners()
            .iter()
            .enumerate()
            .filter(|(_, c)| moving(c.1))
            .map(|(i, _)| i as u32)
            .collect();
        let mut sensor_knots: Vec<Knot> = match scene.sensor() {
            FlatSensor::Irradiance { point, normal } => scene
                .corners()
                .iter()
                .filter(|&&(q, _)| (q - point).dot(normal) > 0.0)
                .filter(|&&(q, _)| scene.visible(point, q, NO_SEGMENT))
                .map(|&(q, k)| ((q - point).y.atan2((q - point).x), q, k))
                .collect(),
            FlatSensor::Radiance { .. } => Vec::new(),
        };
        sensor_knots.sort_by(|a, b| a.0.total_cmp(&b.0));
        let segments = scene.segments();
        let corner_weight: Vec<f64> = corner_segments
            .iter()
            .map(|&[starts, ends]| {
                if starts == NO_SEGMENT || ends == NO_SEGMENT {
                    return 1.0;
                }
                let (a, b) = (segments[ends as usize], segments[starts as usize]);
                let (da, db) = ((a.b - a.a).normalize(), (b.b - b.a).normalize());
                cross(da, db).atan2(da.dot(db)).abs() / PI
            })
            .collect();
        let cdf = |ids: &mut dyn Iterator<Item = usize>| {
            let mut total = 0.0;
            ids.map(|i| {
                total += corner_weight[i];
                total
            })
            .collect::<Vec<f64>>()
        };
        let all_cdf = cdf(&mut (0..corner_weight.len()));
        let moving_cdf = cdf(&mut moving_corners.iter().map(|&i| i as usize));
        Plane {
            scene,
            corner_segments,
            moving_corners,
            corner_weight,
            all_cdf,
            moving_cdf,
            sensor_knots,
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }
}

/// The directional integrands of flatland.
#[derive(Debug, Clone, Copy)]
pub enum FlatLobe {
    /// `c (ω·n)⁺`: the sensor (`c = 1`) or a Lambertian reflector
    /// (`c = ρ/2`), sampled with density `(ω·n)⁺/2`.
    Cosine {
        /// Unit normal.
        n: DVec2,
        /// Factor.
        c: f64,
    },
    /// The phase function about the incoming `w_in`, sampled exactly.
    Phase {
        /// The phase function.
        phase: Phase,
        /// Incoming direction.
        w_in: DVec2,
    },
}

/// The phase function at the cosine `c` of the scattering angle.
#[inline]
pub fn phase_value(phase: Phase, c: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.5 / PI,
        Phase::HenyeyGreenstein { g } => (1.0 - g * g) / (2.0 * PI * (1.0 + g * g - 2.0 * g * c)),
    }
}

/// `d ln p / d cos θ` of the phase function at the cosine `c`.
#[inline]
pub fn phase_dlog_dcos(phase: Phase, c: f64) -> f64 {
    match phase {
        Phase::Isotropic => 0.0,
        Phase::HenyeyGreenstein { g } => 2.0 * g / (1.0 + g * g - 2.0 * g * c),
    }
}

/// A direction about the unit normal `n` with density `cos θ / 2` over the
/// half circle (so `∫ cos θ L dθ` is estimated by `2 L`).
#[inline]
pub fn cosine_direction(n: DVec2, rng: &mut PathRng) -> DVec2 {
    let s = 2.0 * rng.random::<f64>() - 1.0;
    let c = (1.0 - s * s).max(0.0).sqrt();
    c * n + s * perp(n)
}

/// A scattering direction from the phase function about the incoming `w`.
#[inline]
pub fn phase_direction(phase: Phase, w: DVec2, rng: &mut PathRng) -> DVec2 {
    let u: f64 = rng.random();
    let theta = match phase {
        Phase::Isotropic => 2.0 * PI * u,
        // Inverse CDF of the wrapped Cauchy law.
        Phase::HenyeyGreenstein { g } => {
            2.0 * ((1.0 - g) / (1.0 + g) * (PI * (u - 0.5)).tan()).atan()
        }
    };
    DVec2::from_angle(theta).rotate(w)
}

impl Lobe<DVec2> for FlatLobe {
    #[inline]
    fn value(&self, w: DVec2) -> f64 {
        match *self {
            FlatLobe::Cosine { n, c } => c * w.dot(n).max(0.0),
            FlatLobe::Phase { phase, w_in } => phase_value(phase, w.dot(w_in)),
        }
    }
    #[inline]
    fn pdf(&self, w: DVec2) -> f64 {
        match *self {
            FlatLobe::Cosine { n, .. } => 0.5 * w.dot(n).max(0.0),
            FlatLobe::Phase { phase, w_in } => phase_value(phase, w.dot(w_in)),
        }
    }
    #[inline]
    fn weight(&self) -> f64 {
        match *self {
            FlatLobe::Cosine { c, .. } => 2.0 * c,
            FlatLobe::Phase { .. } => 1.0,
        }
    }
    #[inline]
    fn sample(&self, rng: &mut PathRng) -> DVec2 {
        match *self {
            FlatLobe::Cosine { n, .. } => cosine_direction(n, rng),
            FlatLobe::Phase { phase, w_in } => phase_direction(phase, w_in, rng),
        }
    }
    #[inline]
    fn dlog(&self, w: DVec2, wd: DVec2) -> f64 {
        match *self {
            FlatLobe::Cosine { n, .. } => wd.dot(n) / w.dot(n),
            FlatLobe::Phase { phase, w_in } => phase_dlog_dcos(phase, w.dot(w_in)) * wd.dot(w_in),
        }
    }
}

impl FlatLobe {
    /// Angles from `w` to the lobe's horizon counter-clockwise and clockwise
    /// (`2π` for the full circle). Horizons are fixed in the lobe's frame, so
    /// the warp they pin is one field whatever direction was drawn.
    #[inline]
    fn horizons(&self, w: DVec2) -> (f64, f64) {
        match *self {
            FlatLobe::Cosine { n, .. } => {
                // φ − φ_n in (−π/2, π/2).
                let a = cross(n, w).atan2(n.dot(w));
                (FRAC_PI_2 - a, FRAC_PI_2 + a)
            }
            // The whole circle: a knot found one way is found the other way
            // too, and none found means no corner at all.
            FlatLobe::Phase { .. } => (TAU, TAU),
        }
    }
}

impl Geometry for Plane {
    type V = DVec2;
    type Lobe = FlatLobe;

    #[inline]
    fn size(&self) -> f64 {
        self.scene.size()
    }
    #[inline]
    fn sensor(&self) -> Sensor<DVec2> {
        match self.scene.sensor() {
            FlatSensor::Radiance { point, direction } => Sensor::Radiance { point, direction },
            FlatSensor::Irradiance { point, normal } => Sensor::Irradiance { point, normal },
        }
    }
    #[inline]
    fn sensor_medium(&self) -> MediumId {
        self.scene.sensor_medium()
    }
    #[inline]
    fn cast(&self, x: DVec2, w: DVec2, skip: Prim) -> Option<Hit> {
        self.scene.cast(x, w, skip).map(|h| Hit {
            t: h.t,
            prim: h.segment,
        })
    }
    #[inline]
    fn visible(&self, x: DVec2, y: DVec2, skip: Prim) -> bool {
        self.scene.visible(x, y, skip)
    }
    #[inline]
    fn shape(&self, p: Prim) -> u32 {
        self.scene.owner(p)
    }
    #[inline]
    fn surface(&self, p: Prim) -> Surface {
        self.scene.shape_of(p).surface
    }
    #[inline]
    fn normal(&self, p: Prim, _y: DVec2) -> DVec2 {
        self.scene.normal(p)
    }
    #[inline]
    fn coefficients(&self, m: MediumId) -> Option<(f64, f64)> {
        self.scene.medium(m).map(|m| (m.ks, m.ke))
    }
    #[inline]
    fn crossed(&self, m: MediumId, k: u32) -> MediumId {
        if m == Some(k) {
            self.scene.parent_medium(k)
        } else {
            Some(k)
        }
    }
    #[inline]
    fn cosine_lobe(&self, n: DVec2, c: f64) -> FlatLobe {
        FlatLobe::Cosine { n, c }
    }
    #[inline]
    fn phase_lobe(&self, m: MediumId, w: DVec2) -> FlatLobe {
        FlatLobe::Phase {
            phase: self.scene.medium(m).map_or(Phase::Isotropic, |m| m.phase),
            w_in: w,
        }
    }
    #[inline]
    fn emitter_point(&self, u: f64) -> Option<(DVec2, Prim)> {
        self.scene.emitter_point(u)
    }
    /// `r / (|cos θ_e| L)` for a point drawn by length on emitters of total
    /// length `L`.
    #[inline]
    fn light_pdf(&self, x: DVec2, y: DVec2, p: Prim) -> f64 {
        let d = y - x;
        let r = d.length();
        let c = (d / r).dot(self.scene.normal(p)).abs();
        if c > 0.0 {
            r / (c * self.scene.emitter_length())
        } else {
            f64::INFINITY
        }
    }
    #[inline]
    fn parameters(&self) -> usize {
        self.scene.parameters().len()
    }
    #[inline]
    fn parameter_shape(&self, j: usize) -> u32 {
        self.scene.parameter_shape(j)
    }
    #[inline]
    fn velocity(&self, j: usize, q: DVec2) -> DVec2 {
        self.scene.parameters()[j].motion.velocity(q)
    }
    #[inline]
    fn spin(&self, j: usize) -> f64 {
        self.scene.parameters()[j].motion.spin()
    }
}

/// A monotone stand-in for the counter-clockwise angle in `[0, 4)` of a
/// vector with cosine part `c` and sine part `s` relative to a direction.
#[inline]
fn pseudo_angle(c: f64, s: f64) -> f64 {
    let t = c / (c.abs() + s.abs());
    if s >= 0.0 { 1.0 - t } else { 3.0 + t }
}

/// The warp at a vertex for a sampled direction: the nearest visible corner
/// (or the lobe's horizon) on each side.
#[derive(Debug, Clone, Copy)]
pub struct FlatWarp {
    ccw: Option<Knot>,
    cw: Option<Knot>,
    horizons: (f64, f64),
}

impl Boundaries for Plane {
    #[inline]
    /// A corner drawn with probability proportional to its weight (a binary
    /// search in the cumulative weights).
    fn sample_boundary(&self, _x: DVec2, all: bool, u: f64) -> Option<BoundaryPoint<DVec2>> {
        let cdf = if all { &self.all_cdf } else { &self.moving_cdf };
        let total = *cdf.last()?;
        if total <= 0.0 {
            return None;
        }
        let pick = cdf.partition_point(|&c| c <= u * total).min(cdf.len() - 1);
        let index = if all {
            pick as u32
        } else {
            self.moving_corners[pick]
        };
        let (q, shape) = self.scene.corners()[index as usize];
        Some(BoundaryPoint {
            q,
            shape,
            index,
            inv_pdf: total / self.corner_weight[index as usize],
        })
    }

    /// The segments at the corner that lie on either side of the sight line
    /// `ω` from `x`; on each side the ray just past the line meets the one
    /// whose direction `d` from the corner has the least `(d·ω)/|ω × d|`
    /// (it is crossed first), or none.
    fn sides(&self, x: DVec2, b: &BoundaryPoint<DVec2>) -> (Side, Side) {
        let w = (b.q - x).normalize();
        let segments = self.scene.segments();
        let (mut ccw, mut cw) = ((f64::INFINITY, Side::Past), (f64::INFINITY, Side::Past));
        for s in self.corner_segments[b.index as usize] {
            if s == NO_SEGMENT {
                continue;
            }
            let seg = segments[s as usize];
            let other = if (seg.a - b.q).length_squared() < (seg.b - b.q).length_squared() {
                seg.b
            } else {
                seg.a
            };
            let d = other - b.q;
            let c = cross(w, d);
            if c == 0.0 {
                continue; // along the sight line: a grazing ray sees none of it
            }
            let order = d.dot(w) / c.abs();
            let side = if c > 0.0 { &mut ccw } else { &mut cw };
            if order < side.0 {
                *side = (order, Side::Surface(s));
            }
        }
        (ccw.1, cw.1)
    }

    #[inline]
    fn boundary_normal(&self, x: DVec2, b: &BoundaryPoint<DVec2>) -> DVec2 {
        perp((b.q - x).normalize())
    }

    type Warp = FlatWarp;

    fn warp(&self, v: &Vertex<Self>, w: DVec2) -> FlatWarp {
        let horizons = v.lobe.horizons(w);
        let (ccw, cw) = if v.at_sensor {
            self.sensor_knots(w, horizons)
        } else {
            self.nearest_knots(v.x, v.skip, w, horizons)
        };
        FlatWarp { ccw, cw, horizons }
    }

    #[inline]
    fn warp_shapes(&self, warp: &FlatWarp, mut f: impl FnMut(u32)) {
        for k in [warp.ccw, warp.cw].into_iter().flatten() {
            f(k.2);
        }
    }

    #[inline]
    fn warp_velocity(
        &self,
        warp: &FlatWarp,
        x: DVec2,
        w: DVec2,
        u: DVec2,
        spin: f64,
        velocity: impl Fn(DVec2, u32) -> DVec2,
    ) -> (DVec2, f64) {
        // Knot values: a corner's angular velocity, or the frame's at a
        // horizon (which keeps the integrand's domain in place).
        let rate = |q: DVec2, k: u32| {
            let r = q - x;
            cross(r, velocity(q, k) - u) / r.length_squared()
        };
        let (db, vb) = match warp.ccw {
            Some((delta, q, k)) => (delta, rate(q, k)),
            None => (warp.horizons.0, spin),
        };
        let (da, va) = match warp.cw {
            Some((delta, q, k)) => (delta, rate(q, k)),
            None => (warp.horizons.1, spin),
        };
        let slope = (vb - va) / (da + db);
        (perp(w) * (va + slope * da), slope)
    }
}

impl Plane {
    /// The visible corners nearest to `w` counter-clockwise and clockwise,
    /// closer than the lobe's horizons `(h_ccw, h_cw)` radians: `(angle,
    /// corner, shape)` each. One pass orders the corners by a pseudo-angle
    /// (monotone in the angle, no trigonometry); only the winners get a
    /// shadow ray, and a hidden winner makes its side scan again past it.
    fn nearest_knots(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        (h_ccw, h_cw): (f64, f64),
    ) -> (Option<Knot>, Option<Knot>) {
        let limit = |h: f64| {
            if h >= TAU {
                4.0
            } else {
                let (s, c) = h.sin_cos();
                pseudo_angle(c, s)
            }
        };
        let (lim_ccw, lim_cw) = (limit(h_ccw), limit(h_cw));
        if let Some(knots) = self.knots_in_triangles(x, skip, w, lim_ccw, lim_cw) {
            return knots;
        }
        self.scan_knots(x, skip, w, lim_ccw, lim_cw)
    }

    /// [`Self::nearest_knots`] by a scan of every corner (pseudo-angle
    /// limits).
    fn scan_knots(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> (Option<Knot>, Option<Knot>) {
        let scene = &*self.scene;
        let corners = scene.corners();
        let (mut bound_ccw, mut bound_cw) = (0.0, 0.0);
        let (mut done_ccw, mut done_cw) = (false, false);
        let (mut ccw, mut cw) = (None, None);
        while !(done_ccw && done_cw) {
            let (mut best_ccw, mut best_cw) = (lim_ccw, lim_cw);
            let (mut i_ccw, mut i_cw) = (usize::MAX, usize::MAX);
            for (i, &(q, _)) in corners.iter().enumerate() {
                let r = q - x;
                let p = pseudo_angle(w.dot(r), cross(w, r));
                if !done_ccw && p > bound_ccw && p < best_ccw {
                    best_ccw = p;
                    i_ccw = i;
                }
                let pc = 4.0 - p;
                if !done_cw && pc > bound_cw && pc < best_cw {
                    best_cw = pc;
                    i_cw = i;
                }
            }
            // A side is settled when its nearest candidate is visible or it
            // has none; a hidden one moves that side's bound past it.
            let settle = |done: &mut bool, i: usize, best: f64, bound: &mut f64| {
                if *done {
                    return None;
                }
                if i == usize::MAX {
                    *done = true;
                    None
                } else if scene.visible(x, corners[i].0, skip) {
                    *done = true;
                    Some(i)
                } else {
                    *bound = best;
                    None
                }
            };
            ccw = ccw.or(settle(&mut done_ccw, i_ccw, best_ccw, &mut bound_ccw));
            cw = cw.or(settle(&mut done_cw, i_cw, best_cw, &mut bound_cw));
        }
        let knot = |i: Option<usize>, ccw: bool| i.map(|i| knot(x, w, corners[i], ccw));
        (knot(ccw, true), knot(cw, false))
    }

    /// [`Self::nearest_knots`] through the corner grid: the nearest visible
    /// corner on each side is the hit segment's end there or the
    /// smallest-angle corner inside the triangle (vertex, hit point, end);
    /// the module `corners` proves it. `None` (use the scan) without a grid
    /// or when the direction hits nothing opaque.
    fn knots_in_triangles(
        &self,
        x: DVec2,
        skip: u32,
        w: DVec2,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> Option<(Option<Knot>, Option<Knot>)> {
        let scene = &*self.scene;
        let grid = scene.corner_grid()?;
        let Some((t, seg, k_hit)) = scene.opaque_hit(x, w, skip) else {
            return Some(self.knots_escaping(grid, x, w, lim_ccw, lim_cw));
        };
        let p = x + t * w;
        let (sa, sb) = (cross(w, seg.a - x), cross(w, seg.b - x));
        let (e_ccw, e_cw) = if sa > 0.0 && sb < 0.0 {
            (seg.a, seg.b)
        } else if sb > 0.0 && sa < 0.0 {
            (seg.b, seg.a)
        } else {
            return None; // the ray grazes an end: let the scan decide
        };
        let corners = scene.corners();
        let side = |e: DVec2, lim: f64, ccw: bool| -> Option<Knot> {
            let angle = |q: DVec2| {
                let r = q - x;
                let pa = pseudo_angle(w.dot(r), cross(w, r));
                if ccw { pa } else { 4.0 - pa }
            };
            let mut best: Option<(f64, DVec2, u32)> = None;
            let pe = angle(e);
            if pe < lim {
                best = Some((pe, e, k_hit));
            }
            grid.near_triangle(x, p, e, |i| {
                let (q, k) = corners[i as usize];
                let pq = angle(q);
                if pq < lim && best.is_none_or(|b| pq < b.0) && super::corners::inside(x, p, e, q) {
                    best = Some((pq, q, k));
                }
            });
            best.map(|(_, q, k)| knot(x, w, (q, k), ccw))
        };
        Some((side(e_ccw, lim_ccw, true), side(e_cw, lim_cw, false)))
    }

    /// The nearest visible corners on either side of a direction that hits
    /// nothing opaque: the same triangle argument with the edges of a box
    /// around the scene (and `x`) in the place of the hit segment. The ray
    /// leaves the box at `p` on an edge no segment crosses; if no corner
    /// lies inside the triangle (`x`, `p`, the edge's end `e`), no segment
    /// enters it (it could cross only `x e`, and at most once), so the sight
    /// line to `e` is clear and the search goes on in (`x`, `e`, next box
    /// corner), around the box up to the lobe's horizon.
    fn knots_escaping(
        &self,
        grid: &super::corners::CornerGrid,
        x: DVec2,
        w: DVec2,
        lim_ccw: f64,
        lim_cw: f64,
    ) -> (Option<Knot>, Option<Knot>) {
        let (lo, hi) = grid.bounds();
        let margin = 0.01 * (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let (lo, hi) = (lo.min(x) - margin, hi.max(x) + margin);
        // Box corners counter-clockwise; the exit edge i runs box[i] → box[i+1].
        let boxc = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
        let mut exit = (f64::INFINITY, 0usize);
        for i in 0..4 {
            let (a, b) = (boxc[i], boxc[(i + 1) % 4]);
            let e = b - a;
            let denom = cross(w, e);
            if denom == 0.0 {
                continue;
            }
            let t = cross(a - x, e) / denom;
            let s = cross(a - x, w) / denom;
            if t > 0.0 && (0.0..=1.0).contains(&s) && t < exit.0 {
                exit = (t, i);
            }
        }
        let p = x + exit.0 * w;
        let corners = self.scene.corners();
        let side = |lim: f64, ccw: bool| -> Option<Knot> {
            let angle = |q: DVec2| {
                let r = q - x;
                let pa = pseudo_angle(w.dot(r), cross(w, r));
                if ccw { pa } else { 4.0 - pa }
            };
            let mut from = p;
            // Around the box and back to p: five triangles cover the circle.
            for step in 0..5 {
                let i = exit.1;
                let e = match (step, ccw) {
                    (4, _) => p,
                    (_, true) => boxc[(i + 1 + step) % 4],
                    (_, false) => boxc[(i + 4 - step) % 4],
                };
                let mut best: Option<(f64, DVec2, u32)> = None;
                grid.near_triangle(x, from, e, |c| {
                    let (q, k) = corners[c as usize];
                    let pq = angle(q);
                    if pq < lim
                        && best.is_none_or(|b| pq < b.0)
                        && super::corners::inside(x, from, e, q)
                    {
                        best = Some((pq, q, k));
                    }
                });
                if let Some((_, q, k)) = best {
                    return Some(knot(x, w, (q, k), ccw));
                }
                if angle(e) >= lim {
                    return None;
                }
                from = e;
            }
            None
        };
        (side(lim_ccw, true), side(lim_cw, false))
    }

    /// The neighbours of `w` among the sensor's knots (precomputed: the
    /// sensor does not move).
    fn sensor_knots(&self, w: DVec2, (h_ccw, h_cw): (f64, f64)) -> (Option<Knot>, Option<Knot>) {
        let knots = &self.sensor_knots;
        if knots.is_empty() {
            return (None, None);
        }
        let phi = w.y.atan2(w.x);
        let i = knots.partition_point(|k| k.0 <= phi);
        let (b, b_angle) = if i < knots.len() {
            (knots[i], knots[i].0 - phi)
        } else {
            (knots[0], knots[0].0 + TAU - phi)
        };
        let (a, a_angle) = if i > 0 {
            (knots[i - 1], phi - knots[i - 1].0)
        } else {
            (knots[knots.len() - 1], phi - knots[knots.len() - 1].0 + TAU)
        };
        (
            (b_angle < h_ccw).then_some((b_angle, b.1, b.2)),
            (a_angle < h_cw && a_angle > 0.0).then_some((a_angle, a.1, a.2)),
        )
    }
}

/// The knot at corner `(q, k)` seen from `x`: its angle from `w`
/// counter-clockwise (`ccw`) or clockwise, in `(0, 2π]`.
#[inline]
fn knot(x: DVec2, w: DVec2, (q, k): (DVec2, u32), ccw: bool) -> Knot {
    let r = q - x;
    let sign = if ccw { 1.0 } else { -1.0 };
    let mut a = sign * cross(w, r).atan2(w.dot(r));
    if a <= 0.0 {
        a += TAU;
    }
    (a, q, k)
}

/// The warp field at the sensor for figures: `V_j(φ)` (rad per unit of
/// parameter `j`) of the looking direction at angle `phi` from +x. For an
/// irradiance sensor, directions behind it get 0 (the field is pinned to the
/// frame at the horizons).
pub fn sensor_warp(plane: &Plane, phi: f64) -> Vec<f64> {
    let scene = &plane.scene;
    let n = scene.parameters().len();
    let w = super::geometry::direction(phi);
    let (x, lobe, at_sensor) = match scene.sensor() {
        FlatSensor::Irradiance { point, normal } => {
            if w.dot(normal) <= 0.0 {
                return vec![0.0; n];
            }
            (point, FlatLobe::Cosine { n: normal, c: 1.0 }, true)
        }
        FlatSensor::Radiance { point, direction } => (
            point,
            FlatLobe::Phase {
                phase: Phase::Isotropic,
                w_in: direction,
            },
            false,
        ),
    };
    let v = Vertex {
        x,
        medium: scene.sensor_medium(),
        skip: NO_PRIM,
        lobe,
        w_in: w,
        frame: crate::path::walk::Frame::Sensor,
        beta: 1.0,
        at_sensor,
    };
    let field = plane.warp(&v, w);
    (0..n)
        .map(|j| {
            let velocity = |q: DVec2, k: u32| {
                if scene.parameter_shape(j) == k {
                    scene.parameters()[j].motion.velocity(q)
                } else {
                    DVec2::ZERO
                }
            };
            let (wd, _) = plane.warp_velocity(&field, x, w, DVec2::ZERO, 0.0, velocity);
            wd.dot(perp(w))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flat::scene::{Shape, Surface};
    use rand::SeedableRng;

    /// A reflecting vault open at the bottom (rays escape there) over an
    /// occluder and a lamp, with enough corners for the grid.
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
    fn the_grid_finds_the_knots_the_scan_finds() {
        let plane = vault();
        assert!(plane.scene.corner_grid().is_some());
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
            let Some(grid) = plane.knots_in_triangles(x, NO_SEGMENT, w, lim_ccw, lim_cw) else {
                continue;
            };
            if plane.scene.opaque_hit(x, w, NO_SEGMENT).is_some() {
                hitting += 1;
            } else {
                escaping += 1;
            }
            let scan = plane.scan_knots(x, NO_SEGMENT, w, lim_ccw, lim_cw);
            let key = |k: Option<Knot>| k.map(|k| (k.1.x, k.1.y));
            assert_eq!(key(grid.0), key(scan.0), "ccw at {x} along {w}");
            assert_eq!(key(grid.1), key(scan.1), "cw at {x} along {w}");
        }
        assert!(escaping > 300 && hitting > 300, "{escaping} {hitting}");
    }
}
