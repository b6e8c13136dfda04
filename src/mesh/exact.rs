//! Closed-form references for 3D scenes: irradiance from planar Lambertian
//! polygons, with and without convex black occluders, and its exact shape
//! derivatives.
//!
//! **Lambert's formula** (Lambert 1760; Arvo 1994, "The irradiance Jacobian
//! for partially occluded polyhedral sources", SIGGRAPH). A sensor at `x`
//! with unit normal `n` sees a two-sided Lambertian polygon of uniform
//! radiance `L` with vertices `p_i`. With `r_i = p_i − x`, `β_i` the angle
//! between `r_i` and `r_{i+1}` and `γ̂_i = (r_i × r_{i+1})/|r_i × r_{i+1}|`,
//!
//! `E = (L/2) |Σ_i β_i (n·γ̂_i)|`,
//!
//! the absolute value fixing the winding as seen from `x` (the emitter is
//! two-sided). The sensor integrates `(η·n)⁺` only, so the polygon is first
//! clipped to the half-space `n·(p − x) ≥ 0` (Sutherland–Hodgman).
//!
//! **Occluders.** A convex black occluder lying strictly between `x` and the
//! lamp's plane hides exactly the lamp points inside its shadow: the central
//! projection from `x` onto the lamp's plane of the occluder, i.e. the convex
//! hull of its projected vertices (a planar convex polygon, or the
//! silhouette of a convex polyhedron such as a box). So
//! `E = E(lamp) − E(lamp ∩ shadow)`, the intersection a convex clip
//! (Sutherland–Hodgman against the shadow's edges).
//!
//! **Derivatives.** Every vertex of the final polygons is a smooth function
//! of a few input vertices: an input vertex, its central projection
//! `P(q) = x + k (q − x)/(N·(q − x))` (`N` the lamp plane's unit normal,
//! `k = N·(p_lamp − x)`), or the crossing of an edge `[p_i, p_j]` with a
//! clip plane or line `h(p) = 0`,
//! `q = (h_i p_j − h_j p_i)/(h_i − h_j)`, where `h` depends on the moving
//! shadow edge too. Each such vertex carries its Jacobian with respect to
//! the input vertices (chain rule through the projection, the hull, whose
//! vertex set is locally constant, and the clips), and Lambert's formula is
//! differentiated term by term:
//! `∂β/∂a = (â × γ̂)/|a|`, `∂β/∂b = (γ̂ × b̂)/|b|`,
//! `∂(n·γ̂)/∂a = b × (n − (n·γ̂)γ̂)/|a × b|`,
//! `∂(n·γ̂)/∂b = (n − (n·γ̂)γ̂) × a/|a × b|` for the edge `(a, b) =
//! (r_i, r_{i+1})`. The sensitivity to a shape parameter is the vertex
//! gradient dotted with each vertex's velocity ([`Motion::velocity`]).
//!
//! Non-generic configurations (a clip plane through a vertex, an occluder
//! vertex projecting onto a shadow edge or a lamp edge) are kinks of `E`;
//! the derivative there is that of the branch the tie-breaks pick.
use glam::{DMat3, DVec3};

use super::scene::Motion;
use crate::error::{Error, check};

/// A point with its sparse Jacobian with respect to the input vertices:
/// `dp = Σ_k D_k dq_k`.
#[derive(Debug, Clone)]
struct Tracked {
    p: DVec3,
    d: Vec<(usize, DMat3)>,
}

/// A scalar with its sparse gradient: `dv = Σ_k g_k · dq_k`.
#[derive(Debug, Clone)]
struct TrackedScalar {
    v: f64,
    d: Vec<(usize, DVec3)>,
}

fn add_mat(d: &mut Vec<(usize, DMat3)>, k: usize, m: DMat3) {
    match d.iter_mut().find(|(j, _)| *j == k) {
        Some((_, a)) => *a += m,
        None => d.push((k, m)),
    }
}

fn add_vec(d: &mut Vec<(usize, DVec3)>, k: usize, g: DVec3) {
    match d.iter_mut().find(|(j, _)| *j == k) {
        Some((_, a)) => *a += g,
        None => d.push((k, g)),
    }
}

/// The matrix `a gᵀ`: `(a gᵀ) v = a (g·v)`.
fn outer(a: DVec3, g: DVec3) -> DMat3 {
    DMat3::from_cols(a * g.x, a * g.y, a * g.z)
}

impl Tracked {
    fn input(k: usize, p: DVec3) -> Self {
        Tracked {
            p,
            d: vec![(k, DMat3::IDENTITY)],
        }
    }

    fn fixed(p: DVec3) -> Self {
        Tracked { p, d: Vec::new() }
    }

    /// Adds `Dᵀ g` of every dependency to `grad`.
    fn pull(&self, g: DVec3, grad: &mut [DVec3]) {
        for &(k, m) in &self.d {
            grad[k] += m.transpose() * g;
        }
    }

    /// Accumulates `Dᵀ w` into a scalar's gradient (`d(w·p)` for fixed `w`).
    fn push_dot(&self, w: DVec3, into: &mut Vec<(usize, DVec3)>) {
        for &(k, m) in &self.d {
            add_vec(into, k, m.transpose() * w);
        }
    }
}

/// Sutherland–Hodgman: the part of `poly` where `h ≥ 0`. Crossing points
/// carry the chain rule through `h`'s own dependencies.
fn clip(poly: &[Tracked], h: &dyn Fn(&Tracked) -> TrackedScalar) -> Vec<Tracked> {
    let hs: Vec<TrackedScalar> = poly.iter().map(h).collect();
    let n = poly.len();
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let j = (i + 1) % n;
        let (hi, hj) = (&hs[i], &hs[j]);
        if hi.v >= 0.0 {
            out.push(poly[i].clone());
        }
        if (hi.v > 0.0 && hj.v < 0.0) || (hi.v < 0.0 && hj.v > 0.0) {
            out.push(crossing(&poly[i], &poly[j], hi, hj));
        }
    }
    if out.len() < 3 { Vec::new() } else { out }
}

/// `q = (h_i p_j − h_j p_i)/(h_i − h_j)` and
/// `dq = [(p_j − q) dh_i − (p_i − q) dh_j + h_i dp_j − h_j dp_i]/(h_i − h_j)`.
fn crossing(pi: &Tracked, pj: &Tracked, hi: &TrackedScalar, hj: &TrackedScalar) -> Tracked {
    let den = hi.v - hj.v;
    let q = (hi.v * pj.p - hj.v * pi.p) / den;
    let mut d = Vec::new();
    for &(k, g) in &hi.d {
        add_mat(&mut d, k, outer((pj.p - q) / den, g));
    }
    for &(k, g) in &hj.d {
        add_mat(&mut d, k, outer((q - pi.p) / den, g));
    }
    for &(k, m) in &pj.d {
        add_mat(&mut d, k, m * (hi.v / den));
    }
    for &(k, m) in &pi.d {
        add_mat(&mut d, k, m * (-hj.v / den));
    }
    Tracked { p: q, d }
}

/// The term `β (n·γ̂)` of one edge `(a, b)` and its gradients in `a`, `b`.
fn edge_term(n: DVec3, a: DVec3, b: DVec3) -> (f64, DVec3, DVec3) {
    let (la, lb) = (a.length(), b.length());
    let c = a.cross(b);
    let s = c.length();
    if s <= 1e-14 * la * lb {
        // a ∥ b (same direction): T ≈ (b − a)·(n × â)/|a|, linear.
        let g = n.cross(a / la) / la;
        return (0.0, -g, g);
    }
    let beta = s.atan2(a.dot(b));
    let ch = c / s;
    let g = n.dot(ch);
    let pn = n - g * ch;
    let dbeta_a = (a / la).cross(ch) / la;
    let dbeta_b = ch.cross(b / lb) / lb;
    let dg_a = b.cross(pn) / s;
    let dg_b = pn.cross(a) / s;
    (
        beta * g,
        g * dbeta_a + beta * dg_a,
        g * dbeta_b + beta * dg_b,
    )
}

/// The signed Lambert sum `S = Σ β_i (n·γ̂_i)` over the part of `poly` above
/// the sensor's tangent plane, and `∂S/∂(input k)` for `inputs` inputs.
fn lambert(x: DVec3, n: DVec3, poly: &[Tracked], inputs: usize) -> (f64, Vec<DVec3>) {
    let above = clip(poly, &|t: &Tracked| {
        let mut d = Vec::new();
        t.push_dot(n, &mut d);
        TrackedScalar {
            v: n.dot(t.p - x),
            d,
        }
    });
    let mut grad = vec![DVec3::ZERO; inputs];
    let mut sum = 0.0;
    let m = above.len();
    for i in 0..m {
        let (u, v) = (&above[i], &above[(i + 1) % m]);
        let (t, ga, gb) = edge_term(n, u.p - x, v.p - x);
        sum += t;
        u.pull(ga, &mut grad);
        v.pull(gb, &mut grad);
    }
    (sum, grad)
}

/// `E = (L/2)|S|` and its gradient from the signed sum.
fn irradiance_of(radiance: f64, (s, grad): (f64, Vec<DVec3>)) -> (f64, Vec<DVec3>) {
    let f = 0.5 * radiance * s.signum();
    (
        0.5 * radiance * s.abs(),
        grad.into_iter().map(|g| f * g).collect(),
    )
}

fn finite_point(name: &'static str, q: DVec3) -> Result<(), Error> {
    let bad = [q.x, q.y, q.z]
        .into_iter()
        .find(|c| !c.is_finite())
        .unwrap_or(0.0);
    check(name, bad, q.is_finite(), "a point with finite coordinates").map(|_| ())
}

fn scene_error<T>(msg: &str) -> Result<T, Error> {
    Err(Error::Scene(msg.to_string()))
}

/// Validates the sensor and the radiance; returns the unit normal.
fn check_sensor(x: DVec3, n: DVec3, radiance: f64) -> Result<DVec3, Error> {
    finite_point("sensor position", x)?;
    finite_point("sensor normal", n)?;
    check("sensor normal length", n.length(), n.length() > 0.0, "> 0")?;
    check(
        "radiance",
        radiance,
        radiance >= 0.0,
        "a finite number >= 0",
    )?;
    Ok(n.normalize())
}

/// Validates a polygon: 3 or more finite vertices, the sensor on none of its
/// edges.
fn check_polygon(name: &'static str, x: DVec3, poly: &[DVec3]) -> Result<(), Error> {
    check(
        name,
        poly.len() as f64,
        poly.len() >= 3,
        "3 or more vertices",
    )?;
    poly.iter().try_for_each(|&q| finite_point(name, q))?;
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let e = b - a;
        let t = if e.length_squared() > 0.0 {
            ((x - a).dot(e) / e.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let dist = (a + t * e - x).length();
        let scale = (a - x).length().max((b - x).length());
        if dist <= crate::path::tolerance::COINCIDENT * scale || scale == 0.0 {
            return scene_error("the sensor lies on an edge or vertex of a polygon");
        }
    }
    Ok(())
}

/// Irradiance at `x` (unit normal `n`, normalised here) from the planar
/// two-sided Lambertian polygon `polygon` (any winding) of uniform radiance
/// `radiance`, by Lambert's formula after clipping the polygon to the
/// sensor's upper half-space `n·(p − x) ≥ 0`. Always `≥ 0`.
///
/// Errors: non-finite input, `radiance < 0`, `n = 0`, fewer than 3
/// vertices, or `x` on an edge or a vertex of the polygon. Planarity is not
/// checked: for a non-planar contour the formula gives the irradiance from
/// a surface spanning it (when `x` sees that surface once).
pub fn polygon_irradiance(
    x: DVec3,
    n: DVec3,
    polygon: &[DVec3],
    radiance: f64,
) -> Result<f64, Error> {
    polygon_irradiance_with_gradient(x, n, polygon, radiance).map(|(e, _)| e)
}

/// `∂E/∂p_i` for every vertex `p_i` of `polygon`, `E` the
/// [`polygon_irradiance`] (same arguments and errors): Lambert's formula
/// differentiated analytically, chained through the tangent-plane clip.
pub fn polygon_irradiance_gradient(
    x: DVec3,
    n: DVec3,
    polygon: &[DVec3],
    radiance: f64,
) -> Result<Vec<DVec3>, Error> {
    polygon_irradiance_with_gradient(x, n, polygon, radiance).map(|(_, g)| g)
}

/// [`polygon_irradiance`] and [`polygon_irradiance_gradient`] together.
pub fn polygon_irradiance_with_gradient(
    x: DVec3,
    n: DVec3,
    polygon: &[DVec3],
    radiance: f64,
) -> Result<(f64, Vec<DVec3>), Error> {
    let n = check_sensor(x, n, radiance)?;
    check_polygon("polygon", x, polygon)?;
    let poly: Vec<Tracked> = polygon
        .iter()
        .enumerate()
        .map(|(k, &p)| Tracked::input(k, p))
        .collect();
    Ok(irradiance_of(radiance, lambert(x, n, &poly, polygon.len())))
}

/// The lamp's plane: unit normal `N` (Newell) and offset `N·p`.
fn lamp_plane(lamp: &[DVec3]) -> Result<(DVec3, f64), Error> {
    let mut newell = DVec3::ZERO;
    for (i, &a) in lamp.iter().enumerate() {
        newell += a.cross(lamp[(i + 1) % lamp.len()]);
    }
    let size = lamp
        .iter()
        .map(|&p| (p - lamp[0]).length())
        .fold(0.0, f64::max);
    if newell.length() <= crate::path::tolerance::DEGENERATE * size * size {
        return scene_error("the lamp has no area");
    }
    let nn = newell.normalize();
    let c = nn.dot(lamp[0]);
    if lamp
        .iter()
        .any(|&p| (nn.dot(p) - c).abs() > crate::path::tolerance::ON_SURFACE * size)
    {
        return scene_error("the lamp is not planar");
    }
    Ok((nn, c))
}

/// Convex hull (indices, counter-clockwise about `N`, no collinear points)
/// of points lying in the plane with unit normal `N` (Andrew's monotone
/// chain).
fn hull(points: &[DVec3], nn: DVec3) -> Vec<usize> {
    let (e1, e2) = nn.any_orthonormal_pair();
    let uv: Vec<(f64, f64)> = points.iter().map(|p| (e1.dot(*p), e2.dot(*p))).collect();
    let mut idx: Vec<usize> = (0..points.len()).collect();
    idx.sort_by(|&a, &b| {
        uv[a]
            .partial_cmp(&uv[b])
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let turn = |o: usize, a: usize, b: usize| {
        (uv[a].0 - uv[o].0) * (uv[b].1 - uv[o].1) - (uv[a].1 - uv[o].1) * (uv[b].0 - uv[o].0)
    };
    let mut h: Vec<usize> = Vec::with_capacity(2 * idx.len());
    for pass in 0..2 {
        let start = h.len();
        for &i in &idx {
            while h.len() >= start + 2 && turn(h[h.len() - 2], h[h.len() - 1], i) <= 0.0 {
                h.pop();
            }
            h.push(i);
        }
        h.pop();
        if pass == 0 {
            idx.reverse();
        }
    }
    h
}

/// Whether `order` lists `0..n` in cyclic order, either way round.
fn same_cycle(order: &[usize], n: usize) -> bool {
    let Some(start) = order.iter().position(|&i| i == 0) else {
        return false;
    };
    let at = |k: usize| order[(start + k) % n];
    order.len() == n && ((0..n).all(|k| at(k) == k) || (0..n).all(|k| at(k) == (n - k) % n))
}

/// What blocks the lamp.
#[derive(Clone, Copy)]
enum Blocker<'a> {
    /// A planar convex polygon (its projection must stay strictly convex).
    Polygon(&'a [DVec3]),
    /// A convex body given by its vertices.
    Body(&'a [DVec3]),
}

/// `E` and `∂E/∂q_k` for the blocker's vertices `q_k`.
fn occluded(
    x: DVec3,
    n: DVec3,
    lamp: &[DVec3],
    blocker: Blocker,
    radiance: f64,
) -> Result<(f64, Vec<DVec3>), Error> {
    let n = check_sensor(x, n, radiance)?;
    check_polygon("lamp", x, lamp)?;
    let (nn, c) = lamp_plane(lamp)?;
    let verts = match blocker {
        Blocker::Polygon(v) => {
            check(
                "occluder vertex count",
                v.len() as f64,
                v.len() >= 3,
                "3 or more",
            )?;
            v
        }
        Blocker::Body(v) => {
            check(
                "occluder vertex count",
                v.len() as f64,
                v.len() >= 4,
                "4 or more",
            )?;
            v
        }
    };
    verts
        .iter()
        .try_for_each(|&q| finite_point("occluder vertex", q))?;
    let k = c - nn.dot(x);
    let size = lamp.iter().map(|&p| (p - x).length()).fold(0.0, f64::max);
    if k.abs() <= crate::path::tolerance::COINCIDENT * size {
        return scene_error("the sensor lies in the lamp's plane");
    }
    // Central projection onto the lamp's plane, with its Jacobian.
    let mut projected = Vec::with_capacity(verts.len());
    for (i, &q) in verts.iter().enumerate() {
        let r = q - x;
        let s = nn.dot(r);
        let lambda = s / k;
        use crate::path::tolerance::COINCIDENT;
        if !(lambda > COINCIDENT && lambda < 1.0 - COINCIDENT) {
            return scene_error(
                "the occluder must lie strictly between the sensor and the lamp's plane",
            );
        }
        let j = (DMat3::IDENTITY - outer(r / s, nn)) * (k / s);
        projected.push(Tracked {
            p: x + r * (k / s),
            d: vec![(i, j)],
        });
    }
    let pts: Vec<DVec3> = projected.iter().map(|t| t.p).collect();
    let order = hull(&pts, nn);
    if order.len() < 3 {
        return scene_error("the occluder's shadow has no area");
    }
    if matches!(blocker, Blocker::Polygon(_)) && !same_cycle(&order, verts.len()) {
        return scene_error("the occluder's shadow is not a strictly convex polygon");
    }
    let shadow: Vec<Tracked> = order.iter().map(|&i| projected[i].clone()).collect();
    // Orientation of the shadow about N: its inside is where σ h ≥ 0.
    let mut newell = DVec3::ZERO;
    for (i, t) in shadow.iter().enumerate() {
        newell += t.p.cross(shadow[(i + 1) % shadow.len()].p);
    }
    let sigma = nn.dot(newell).signum();
    let full: Vec<Tracked> = lamp.iter().map(|&p| Tracked::fixed(p)).collect();
    let mut cut = full.clone();
    for (i, u) in shadow.iter().enumerate() {
        if cut.is_empty() {
            break;
        }
        let v = &shadow[(i + 1) % shadow.len()];
        // h(p) = σ N·((v − u) × (p − u)).
        let h = |p: &Tracked| {
            let (w, z) = (v.p - u.p, p.p - u.p);
            let (gw, gz) = (sigma * z.cross(nn), sigma * nn.cross(w));
            let mut d = Vec::new();
            v.push_dot(gw, &mut d);
            u.push_dot(-gw - gz, &mut d);
            p.push_dot(gz, &mut d);
            TrackedScalar {
                v: sigma * nn.dot(w.cross(z)),
                d,
            }
        };
        cut = clip(&cut, &h);
    }
    let inputs = verts.len();
    let (e_lamp, _) = irradiance_of(radiance, lambert(x, n, &full, inputs));
    let (e_cut, g_cut) = irradiance_of(radiance, lambert(x, n, &cut, inputs));
    Ok((e_lamp - e_cut, g_cut.into_iter().map(|g| -g).collect()))
}

/// Irradiance at `x` (unit normal `n`) from the planar two-sided Lambertian
/// polygon `lamp` of uniform radiance, partly hidden by the planar convex
/// black polygon `occluder`: `E(lamp) − E(lamp ∩ P(occluder))`, `P` the
/// central projection from `x` onto the lamp's plane.
///
/// Errors, besides those of [`polygon_irradiance`]: a lamp without area or
/// not planar (relative tolerance 1e-9), `x` in the lamp's plane, an
/// occluder vertex not strictly between `x` and the lamp's plane, or an
/// occluder whose shadow is not strictly convex (collinear vertices
/// included).
pub fn occluded_irradiance(
    x: DVec3,
    n: DVec3,
    lamp: &[DVec3],
    occluder: &[DVec3],
    radiance: f64,
) -> Result<f64, Error> {
    occluded(x, n, lamp, Blocker::Polygon(occluder), radiance).map(|(e, _)| e)
}

/// [`occluded_irradiance`] and its gradient `∂E/∂q_k` with respect to the
/// occluder's vertices (chained through the projection and the clip).
pub fn occluded_irradiance_with_gradient(
    x: DVec3,
    n: DVec3,
    lamp: &[DVec3],
    occluder: &[DVec3],
    radiance: f64,
) -> Result<(f64, Vec<DVec3>), Error> {
    occluded(x, n, lamp, Blocker::Polygon(occluder), radiance)
}

/// Irradiance at `x` (unit normal `n`) from the planar lamp hidden in part by
/// the convex black body with vertices `body` (a closed convex polyhedron,
/// e.g. a box), with its gradient with respect to those vertices. The
/// body's shadow is the convex hull of its projected vertices (the
/// projection of its silhouette); hull vertices are locally fixed, the
/// others have zero gradient. Errors as [`occluded_irradiance`] (fewer than
/// 4 vertices, or a body partly outside the slab between `x` and the lamp's
/// plane).
pub fn body_irradiance_with_gradient(
    x: DVec3,
    n: DVec3,
    lamp: &[DVec3],
    body: &[DVec3],
    radiance: f64,
) -> Result<(f64, Vec<DVec3>), Error> {
    occluded(x, n, lamp, Blocker::Body(body), radiance)
}

/// The sensitivity `Σ_k ∂E/∂q_k · q̇_k` for vertices `q_k` moving by
/// `motion` (pivots resolved).
pub fn sensitivity(gradient: &[DVec3], vertices: &[DVec3], motion: Motion) -> f64 {
    gradient
        .iter()
        .zip(vertices)
        .map(|(g, &q)| g.dot(motion.velocity(q)))
        .sum()
}

/// The five motions of an occluder centred at `c`, in the order of
/// [`OccluderScene::sensitivities`]: translations along x, y, z; rotation
/// about the vertical axis through `c`; scale about `c` (π = factor − 1).
pub fn occluder_motions(c: DVec3) -> [Motion; 5] {
    [
        Motion::TranslateX,
        Motion::TranslateY,
        Motion::TranslateZ,
        Motion::Rotate {
            axis: DVec3::Z,
            pivot: Some(c),
        },
        Motion::Scale { pivot: Some(c) },
    ]
}

/// The square lamp of side `2 half` in the plane `z = height`, centred over
/// the origin (counter-clockwise seen from above).
fn square_lamp(half: f64, height: f64) -> [DVec3; 4] {
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| DVec3::new(a * half, b * half, height))
}

/// The shipped 3D test scene: an irradiance sensor at the origin with normal
/// `+z`; a horizontal square lamp of half-side `lamp_half` and radiance
/// `radiance` at `z = lamp_height`, centred over the origin; a horizontal
/// square black occluder of half-side `occ_half` centred at `occ_centre`,
/// rotated by `occ_angle` about the vertical axis through its centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OccluderScene {
    /// Half the lamp's side.
    pub lamp_half: f64,
    /// Height of the lamp's plane.
    pub lamp_height: f64,
    /// The lamp's radiance.
    pub radiance: f64,
    /// The occluder's centre (`0 < z < lamp_height`).
    pub occ_centre: DVec3,
    /// Half the occluder's side.
    pub occ_half: f64,
    /// The occluder's rotation about the vertical through its centre
    /// (radians, counter-clockwise seen from above).
    pub occ_angle: f64,
}

impl OccluderScene {
    /// The shipped scene (lamp side 1 at height 2, radiance 1; occluder side
    /// 0.5 at height 1, unrotated) with the occluder centred at `(cx, cy, 1)`.
    pub fn shipped(cx: f64, cy: f64) -> Self {
        OccluderScene {
            lamp_half: 0.5,
            lamp_height: 2.0,
            radiance: 1.0,
            occ_centre: DVec3::new(cx, cy, 1.0),
            occ_half: 0.25,
            occ_angle: 0.0,
        }
    }

    /// The lamp's four corners.
    pub fn lamp(&self) -> [DVec3; 4] {
        square_lamp(self.lamp_half, self.lamp_height)
    }

    /// The occluder's four corners.
    pub fn occluder(&self) -> [DVec3; 4] {
        let (s, c) = self.occ_angle.sin_cos();
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(a, b)| {
            let (u, v) = (a * self.occ_half, b * self.occ_half);
            self.occ_centre + DVec3::new(c * u - s * v, s * u + c * v, 0.0)
        })
    }

    /// The occluder as a black mesh named `occ` (two triangles).
    pub fn occluder_shape(&self) -> super::scene::Shape {
        super::scene::Shape {
            name: "occ".into(),
            vertices: self.occluder().to_vec(),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            surface: crate::path::Surface::Absorber,
            medium: None,
        }
    }

    /// The five motions of [`Self::sensitivities`], pivots at the occluder's
    /// centre.
    pub fn motions(&self) -> [Motion; 5] {
        occluder_motions(self.occ_centre)
    }

    /// The irradiance at the sensor.
    pub fn irradiance(&self) -> Result<f64, Error> {
        occluded_irradiance(
            DVec3::ZERO,
            DVec3::Z,
            &self.lamp(),
            &self.occluder(),
            self.radiance,
        )
    }

    /// `∂E/∂π` for the occluder's translations along x, y, z, its rotation
    /// about the vertical axis through its centre and its scale about its
    /// centre (π = factor − 1), in that order.
    pub fn sensitivities(&self) -> Result<[f64; 5], Error> {
        let occ = self.occluder();
        let (_, g) = occluded_irradiance_with_gradient(
            DVec3::ZERO,
            DVec3::Z,
            &self.lamp(),
            &occ,
            self.radiance,
        )?;
        Ok(self.motions().map(|m| sensitivity(&g, &occ, m)))
    }
}

/// The occluder scene with a closed box instead of the square: the same
/// sensor and lamp, and an axis-aligned black cube of side `side` centred at
/// `centre`. A box face lying in a plane through the sensor (e.g. the face
/// `y = 0` of a box spanning `0 ≤ y ≤ a`) is seen edge-on: `E` has a kink
/// there (which face bounds the shadow switches), and the sensitivities are
/// one-sided.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxScene {
    /// Half the lamp's side.
    pub lamp_half: f64,
    /// Height of the lamp's plane.
    pub lamp_height: f64,
    /// The lamp's radiance.
    pub radiance: f64,
    /// The box's centre.
    pub centre: DVec3,
    /// The box's side.
    pub side: f64,
}

impl BoxScene {
    /// The shipped lamp (side 1 at height 2, radiance 1) over a box of side
    /// `side` centred at `centre`.
    pub fn shipped(centre: DVec3, side: f64) -> Self {
        BoxScene {
            lamp_half: 0.5,
            lamp_height: 2.0,
            radiance: 1.0,
            centre,
            side,
        }
    }

    /// The lamp's four corners.
    pub fn lamp(&self) -> [DVec3; 4] {
        square_lamp(self.lamp_half, self.lamp_height)
    }

    /// The box's eight corners.
    pub fn corners(&self) -> [DVec3; 8] {
        let h = 0.5 * self.side;
        std::array::from_fn(|i| {
            let s = |b: usize| if i >> b & 1 == 1 { h } else { -h };
            self.centre + DVec3::new(s(0), s(1), s(2))
        })
    }

    /// The five motions of [`Self::sensitivities`], pivots at the centre.
    pub fn motions(&self) -> [Motion; 5] {
        occluder_motions(self.centre)
    }

    /// The irradiance at the sensor.
    pub fn irradiance(&self) -> Result<f64, Error> {
        self.with_gradient().map(|(e, _)| e)
    }

    fn with_gradient(&self) -> Result<(f64, Vec<DVec3>), Error> {
        body_irradiance_with_gradient(
            DVec3::ZERO,
            DVec3::Z,
            &self.lamp(),
            &self.corners(),
            self.radiance,
        )
    }

    /// `∂E/∂π` for the box's translations along x, y, z, its rotation about
    /// the vertical axis through its centre and its scale about its centre,
    /// in that order.
    pub fn sensitivities(&self) -> Result<[f64; 5], Error> {
        let (_, g) = self.with_gradient()?;
        let q = self.corners();
        Ok(self.motions().map(|m| sensitivity(&g, &q, m)))
    }
}

/// The closed form of a whole 3D [`Scene`](super::Scene), where one exists:
/// an irradiance sensor, one emitter that is a flat convex polygon (any
/// triangulation of it), and at most one black occluder, convex and lying
/// strictly between the sensor and the emitter's plane: a flat convex
/// polygon or a closed convex body (a box). `E` by Lambert's formula less
/// the occluder's shadow, and every parameter's `∂E/∂π` from the vertex
/// gradients; a parameter may move the occluder, or the emitter when no
/// occluder is there. Built once: [`Self::value`] and [`Self::derivative`]
/// only read.
///
/// Every other scene is an error that says why: a radiance sensor or a
/// camera, a reflector or a medium, several emitters or occluders (their
/// shadows may overlap), a curved or non-convex shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    value: f64,
    derivatives: Vec<f64>,
}

/// `Err` with the reason a scene has no closed form.
fn no_reference<T>(why: impl std::fmt::Display) -> Result<T, Error> {
    Err(Error::Scene(format!("no analytic reference: {why}")))
}

/// The outline of shape `s` if it is flat and convex: its vertices' convex
/// hull in its plane, counter-clockwise about the plane's normal, as indices
/// into `s.vertices` (no collinear vertex). `None` if the vertices are not
/// in one plane; an error if they are but the triangles do not cover their
/// hull once (a concave outline, a hole).
fn flat_outline(s: &super::Shape) -> Result<Option<Vec<usize>>, Error> {
    let area = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a);
    let newell: DVec3 = (0..s.triangles.len())
        .map(|i| {
            let [a, b, c] = s.triangle(i);
            area(a, b, c)
        })
        .sum();
    let size = s
        .vertices
        .iter()
        .map(|&p| (p - s.vertices[0]).length())
        .fold(0.0, f64::max);
    if newell.length() <= crate::path::tolerance::DEGENERATE * size * size {
        return Ok(None);
    }
    let nn = newell.normalize();
    let c = nn.dot(s.vertices[0]);
    let flat = s
        .vertices
        .iter()
        .all(|&p| (nn.dot(p) - c).abs() <= crate::path::tolerance::ON_SURFACE * size);
    if !flat {
        return Ok(None);
    }
    let order = hull(&s.vertices, nn);
    let hull_area: f64 = (1..order.len().saturating_sub(1))
        .map(|i| {
            let v = |k: usize| s.vertices[order[k]];
            0.5 * area(v(0), v(i), v(i + 1)).length()
        })
        .sum();
    let covered: f64 = (0..s.triangles.len())
        .map(|i| {
            let [a, b, c] = s.triangle(i);
            0.5 * area(a, b, c).length()
        })
        .sum();
    if order.len() < 3 || (covered - hull_area).abs() > 1e-9 * hull_area {
        return no_reference(format!(
            "shape {:?} is flat but not a convex polygon (its triangles cover {covered} of its \
             outline's area {hull_area})",
            s.name
        ));
    }
    Ok(Some(order))
}

/// Whether the closed mesh `s` bounds a convex body: every vertex on the
/// inner side of every triangle's plane.
fn is_convex_body(s: &super::Shape) -> bool {
    let size = s
        .vertices
        .iter()
        .map(|&p| (p - s.vertices[0]).length())
        .fold(0.0, f64::max);
    (0..s.triangles.len()).all(|i| {
        let [a, b, c] = s.triangle(i);
        let n = (b - a).cross(c - a).normalize();
        let side = |p: DVec3| n.dot(p - a);
        let tol = crate::path::tolerance::ON_SURFACE * size;
        s.vertices.iter().all(|&p| side(p) <= tol) || s.vertices.iter().all(|&p| side(p) >= -tol)
    })
}

impl Reference {
    /// The closed form for `scene`, or an error saying why it has none.
    pub fn for_scene(scene: &super::Scene) -> Result<Reference, Error> {
        use super::{Sensor, Surface};
        let (x, n) = match scene.sensor() {
            Sensor::Irradiance { point, normal } => (point, normal),
            Sensor::Radiance { .. } => return no_reference("the sensor measures radiance"),
            Sensor::Camera(_) => return no_reference("the sensor is a camera"),
        };
        let mut emitter = None;
        let mut occluder = None;
        for (k, s) in scene.shapes().iter().enumerate() {
            match s.surface {
                Surface::Emitter { radiance } => {
                    if emitter.is_some() {
                        return no_reference("more than one emitter");
                    }
                    let Some(outline) = flat_outline(s)? else {
                        return no_reference(format!("the emitter {:?} is not flat", s.name));
                    };
                    emitter = Some((k, outline, radiance));
                }
                Surface::Absorber => {
                    if occluder.is_some() {
                        return no_reference("more than one occluder (their shadows may overlap)");
                    }
                    occluder = Some(k);
                }
                _ => return no_reference("reflectors and media have none"),
            }
        }
        let Some((lamp_k, outline, radiance)) = emitter else {
            return no_reference("no emitter");
        };
        let shapes = scene.shapes();
        let lamp: Vec<DVec3> = outline
            .iter()
            .map(|&i| shapes[lamp_k].vertices[i])
            .collect();
        // E, the shape whose vertices the gradient is about, and those
        // vertices.
        let (value, moving, vertices, gradient) = match occluder {
            None => {
                let (e, g) = polygon_irradiance_with_gradient(x, n, &lamp, radiance)?;
                (e, lamp_k, lamp.clone(), g)
            }
            Some(k) => {
                let s = &shapes[k];
                let (vertices, eg) = match flat_outline(s)? {
                    Some(order) => {
                        let v: Vec<DVec3> = order.iter().map(|&i| s.vertices[i]).collect();
                        let eg = occluded_irradiance_with_gradient(x, n, &lamp, &v, radiance);
                        (v, eg)
                    }
                    None if scene.is_closed(k as u32) && is_convex_body(s) => {
                        let eg = body_irradiance_with_gradient(x, n, &lamp, &s.vertices, radiance);
                        (s.vertices.clone(), eg)
                    }
                    None => {
                        return no_reference(format!(
                            "the occluder {:?} is neither a flat convex polygon nor a closed \
                             convex body",
                            s.name
                        ));
                    }
                };
                // The closed form's own refusals (an occluder not between
                // the sensor and the lamp) are reasons too.
                let (e, g) = eg.or_else(|e| match e {
                    Error::Scene(why) => no_reference(why),
                    other => Err(other),
                })?;
                (e, k, vertices, g)
            }
        };
        let derivatives = scene
            .parameters()
            .iter()
            .enumerate()
            .map(|(j, p)| {
                let k = scene.parameter_shape(j) as usize;
                if k == moving {
                    Ok(sensitivity(&gradient, &vertices, p.motion))
                } else {
                    no_reference(format!(
                        "parameter {:?} moves the emitter, whose derivative is known here only \
                         with no occluder",
                        p.name
                    ))
                }
            })
            .collect::<Result<Vec<f64>, Error>>()?;
        Ok(Reference { value, derivatives })
    }

    /// The irradiance `E`.
    pub fn value(&self) -> f64 {
        self.value
    }

    /// `∂E/∂π_j` for the scene's parameter `j`.
    pub fn derivative(&self, j: usize) -> f64 {
        self.derivatives[j]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n).
    fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
                let mut dp = 1.0;
                for _ in 0..100 {
                    let (mut p0, mut p1) = (1.0, x);
                    for k in 2..=n {
                        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                        (p0, p1) = (p1, p2);
                    }
                    dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                    let dx = p1 / dp;
                    x -= dx;
                    if dx.abs() < 1e-16 {
                        break;
                    }
                }
                (x, 2.0 / ((1.0 - x * x) * dp * dp))
            })
            .collect()
    }

    fn gl(f: &dyn Fn(f64) -> f64, a: f64, b: f64, rule: &[(f64, f64)]) -> f64 {
        let (c, h) = (0.5 * (a + b), 0.5 * (b - a));
        h * rule.iter().map(|&(x, w)| w * f(c + h * x)).sum::<f64>()
    }

    /// Adaptive bisection: accepts a piece where the two halves agree with
    /// the whole.
    fn adaptive(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64, rule: &[(f64, f64)]) -> f64 {
        fn go(
            f: &dyn Fn(f64) -> f64,
            a: f64,
            b: f64,
            whole: f64,
            tol: f64,
            rule: &[(f64, f64)],
            depth: u32,
        ) -> f64 {
            let m = 0.5 * (a + b);
            let (l, r) = (gl(f, a, m, rule), gl(f, m, b, rule));
            if (l + r - whole).abs() <= tol * (b - a) || depth == 0 {
                l + r
            } else {
                go(f, a, m, l, tol, rule, depth - 1) + go(f, m, b, r, tol, rule, depth - 1)
            }
        }
        go(f, a, b, gl(f, a, b, rule), tol, rule, 50)
    }

    /// Richardson-extrapolated central difference of `f` at 0.
    fn richardson(f: &dyn Fn(f64) -> f64, h: f64) -> f64 {
        let d = |h: f64| (f(h) - f(-h)) / (2.0 * h);
        (4.0 * d(0.5 * h) - d(h)) / 3.0
    }

    fn close(a: f64, b: f64, rel: f64, what: &str) {
        let tol = rel * a.abs().max(b.abs()).max(1e-3);
        assert!(
            (a - b).abs() <= tol,
            "{what}: {a} vs {b} (diff {:e})",
            a - b
        );
    }

    /// Independent quadrature of `L cos⁺θ cosθ'/r²` over the horizontal
    /// square lamp `|x|, |y| ≤ a` at height `height`, hidden where the sight
    /// line crosses the convex occluder with edges `edges`: each row `y` is
    /// cut by the plane through the sensor and the row; the plane meets the
    /// occluder in a convex slice whose vertices (crossings of the edges)
    /// project to the row's hidden interval. Rows are integrated by
    /// Gauss–Legendre on the visible pieces (split where `cos θ` changes
    /// sign), the row integral by adaptive Gauss–Legendre.
    fn quadrature(x0: DVec3, n: DVec3, a: f64, height: f64, edges: &[(DVec3, DVec3)]) -> f64 {
        let rule20 = gauss_legendre(20);
        let rule10 = gauss_legendre(10);
        let row = |y: f64| {
            let f = |x: f64| {
                let r = DVec3::new(x, y, height) - x0;
                let d2 = r.length_squared();
                n.dot(r).max(0.0) * (height - x0.z).abs() / (d2 * d2)
            };
            let m = DVec3::X.cross(DVec3::new(0.0, y, height) - x0);
            let mut hidden = (f64::INFINITY, f64::NEG_INFINITY);
            for &(e0, e1) in edges {
                let (h0, h1) = (m.dot(e0 - x0), m.dot(e1 - x0));
                if h0 * h1 <= 0.0 && h0 != h1 {
                    let q = e0 + (e1 - e0) * (h0 / (h0 - h1));
                    let t = (height - x0.z) / (q.z - x0.z);
                    let px = x0.x + t * (q.x - x0.x);
                    hidden = (hidden.0.min(px), hidden.1.max(px));
                }
            }
            let mut cuts = vec![-a, a];
            // where n·r = 0 along the row
            if n.x != 0.0 {
                let k = -(n.y * (y - x0.y) + n.z * (height - x0.z)) / n.x + x0.x;
                if k > -a && k < a {
                    cuts.push(k);
                }
            }
            for h in [hidden.0, hidden.1] {
                if h > -a && h < a {
                    cuts.push(h);
                }
            }
            cuts.sort_by(f64::total_cmp);
            cuts.windows(2)
                .filter(|w| {
                    let mid = 0.5 * (w[0] + w[1]);
                    !(mid > hidden.0 && mid < hidden.1)
                })
                .map(|w| gl(&f, w[0], w[1], &rule20))
                .sum::<f64>()
        };
        adaptive(&row, -a, a, 1e-13, &rule10)
    }

    fn polygon_edges(p: &[DVec3]) -> Vec<(DVec3, DVec3)> {
        (0..p.len()).map(|i| (p[i], p[(i + 1) % p.len()])).collect()
    }

    fn box_edges(q: &[DVec3; 8]) -> Vec<(DVec3, DVec3)> {
        let mut e = Vec::new();
        for i in 0..8 {
            for b in 0..3 {
                if i >> b & 1 == 0 {
                    e.push((q[i], q[i | 1 << b]));
                }
            }
        }
        e
    }

    /// View factor from a point to a parallel rectangle `[0, a] × [0, b]` at
    /// distance `h` above one of its corners.
    fn corner(a: f64, b: f64, h: f64) -> f64 {
        let (x, y) = (a / h, b / h);
        let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
        (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
    }

    fn rect(x1: f64, x2: f64, y1: f64, y2: f64, z: f64) -> Vec<DVec3> {
        vec![
            DVec3::new(x1, y1, z),
            DVec3::new(x2, y1, z),
            DVec3::new(x2, y2, z),
            DVec3::new(x1, y2, z),
        ]
    }

    const O: DVec3 = DVec3::ZERO;

    #[test]
    fn square_over_point_matches_closed_form() {
        let e = polygon_irradiance(O, DVec3::Z, &rect(-0.5, 0.5, -0.5, 0.5, 2.0), 1.0).unwrap();
        close(e, PI * 4.0 * corner(0.5, 0.5, 2.0), 1e-13, "centred");
        let e = polygon_irradiance(O, DVec3::Z, &rect(-0.2, 0.7, -0.6, 0.3, 1.5), 2.0).unwrap();
        let f = corner(0.2, 0.6, 1.5)
            + corner(0.7, 0.6, 1.5)
            + corner(0.2, 0.3, 1.5)
            + corner(0.7, 0.3, 1.5);
        close(e, 2.0 * PI * f, 1e-13, "off-centre");
        let q = quadrature(O, DVec3::Z, 0.5, 2.0, &[]);
        close(q, PI * 4.0 * corner(0.5, 0.5, 2.0), 1e-10, "quadrature");
    }

    #[test]
    fn winding_and_start_do_not_matter() {
        let x = DVec3::new(0.1, -0.2, 0.05);
        let n = DVec3::new(0.3, 0.1, 1.0).normalize();
        let p = vec![
            DVec3::new(-0.4, -0.3, 1.8),
            DVec3::new(0.6, -0.5, 2.1),
            DVec3::new(0.7, 0.4, 2.2),
            DVec3::new(-0.3, 0.6, 1.9),
        ];
        let (e, g) = polygon_irradiance_with_gradient(x, n, &p, 1.0).unwrap();
        assert!(e > 0.0);
        let rev: Vec<DVec3> = p.iter().rev().copied().collect();
        let (er, gr) = polygon_irradiance_with_gradient(x, n, &rev, 1.0).unwrap();
        close(er, e, 1e-14, "reversed");
        for i in 0..4 {
            assert!((gr[3 - i] - g[i]).length() < 1e-13);
        }
        let rot = [p[2], p[3], p[0], p[1]];
        close(
            polygon_irradiance(x, n, &rot, 1.0).unwrap(),
            e,
            1e-14,
            "rotated",
        );
        // occluded: both lamp and occluder reversed
        let s = OccluderScene {
            occ_angle: 0.4,
            ..OccluderScene::shipped(0.3, 0.1)
        };
        let (lamp, occ) = (s.lamp(), s.occluder());
        let e = s.irradiance().unwrap();
        let lr: Vec<DVec3> = lamp.iter().rev().copied().collect();
        let or: Vec<DVec3> = occ.iter().rev().copied().collect();
        for (l, o) in [
            (&lr[..], &occ[..]),
            (&lamp[..], &or[..]),
            (&lr[..], &or[..]),
        ] {
            close(
                occluded_irradiance(O, DVec3::Z, l, o, 1.0).unwrap(),
                e,
                1e-14,
                "occluded winding",
            );
        }
    }

    #[test]
    fn polygon_straddling_the_tangent_plane() {
        let phi: f64 = 0.5;
        let (c, u, v) = (
            DVec3::new(0.3, 0.8, 0.1),
            DVec3::X * 0.5,
            DVec3::new(0.0, -phi.sin(), phi.cos()) * 0.5,
        );
        let p = vec![c - u - v, c + u - v, c + u + v, c - u + v];
        let e = polygon_irradiance(O, DVec3::Z, &p, 1.0).unwrap();
        let normal = u.cross(v).normalize();
        let rule = gauss_legendre(20);
        let row = |t: f64| {
            let f = |s: f64| {
                let r = c + s * u + t * v;
                let d2 = r.length_squared();
                r.z.max(0.0) * normal.dot(r).abs() / (d2 * d2)
            };
            0.25 * gl(&f, -1.0, 1.0, &rule)
        };
        let t0 = -c.z / v.z;
        assert!(t0 > -1.0 && t0 < 1.0);
        let q = adaptive(&row, t0, 1.0, 1e-13, &gauss_legendre(10));
        close(e, q, 1e-10, "straddling vs quadrature");
        // the unclipped formula would differ
        let unclipped: f64 = {
            let m = p.len();
            0.5 * (0..m)
                .map(|i| edge_term(DVec3::Z, p[i], p[(i + 1) % m]).0)
                .sum::<f64>()
                .abs()
        };
        assert!((unclipped - e).abs() > 1e-3 * e);
        // entirely below: nothing
        let below: Vec<DVec3> = p.iter().map(|q| *q - DVec3::Z).collect();
        assert_eq!(polygon_irradiance(O, DVec3::Z, &below, 1.0).unwrap(), 0.0);
        check_polygon_gradient(O, DVec3::Z, &p);
    }

    fn check_polygon_gradient(x: DVec3, n: DVec3, p: &[DVec3]) {
        let g = polygon_irradiance_gradient(x, n, p, 1.3).unwrap();
        for i in 0..p.len() {
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                let f = |h: f64| {
                    let mut q = p.to_vec();
                    q[i] += h * axis;
                    polygon_irradiance(x, n, &q, 1.3).unwrap()
                };
                close(
                    g[i].dot(axis),
                    richardson(&f, 1e-3),
                    1e-7,
                    "polygon gradient",
                );
            }
        }
    }

    #[test]
    fn polygon_gradient_matches_finite_differences() {
        let p = vec![
            DVec3::new(-0.4, -0.3, 1.8),
            DVec3::new(0.6, -0.5, 2.1),
            DVec3::new(0.9, 0.1, 2.0),
            DVec3::new(0.7, 0.4, 2.2),
            DVec3::new(-0.3, 0.6, 1.9),
        ];
        check_polygon_gradient(
            DVec3::new(0.1, -0.2, 0.05),
            DVec3::new(0.3, 0.1, 1.0).normalize(),
            &p,
        );
        // a triangle seen from its back, crossing the tangent plane
        let t = vec![
            DVec3::new(1.0, 0.2, -0.5),
            DVec3::new(0.3, 1.1, 0.9),
            DVec3::new(-0.8, 0.4, 0.6),
        ];
        check_polygon_gradient(O, DVec3::new(0.2, -0.3, 1.0).normalize(), &t);
    }

    fn scenes() -> Vec<OccluderScene> {
        vec![
            OccluderScene {
                occ_angle: 0.4,
                ..OccluderScene::shipped(0.3, 0.1)
            },
            OccluderScene::shipped(0.35, -0.2),
            OccluderScene {
                occ_angle: -0.7,
                occ_half: 0.2,
                ..OccluderScene::shipped(-0.1, 0.05)
            },
            OccluderScene {
                occ_centre: DVec3::new(0.2, 0.3, 1.4),
                occ_angle: 0.2,
                ..OccluderScene::shipped(0.0, 0.0)
            },
        ]
    }

    #[test]
    fn occluded_irradiance_matches_quadrature() {
        for s in scenes() {
            let e = s.irradiance().unwrap();
            let q = quadrature(
                O,
                DVec3::Z,
                s.lamp_half,
                s.lamp_height,
                &polygon_edges(&s.occluder()),
            );
            let full = polygon_irradiance(O, DVec3::Z, &s.lamp(), 1.0).unwrap();
            assert!(e > 0.0 && e < full);
            close(e, q, 1e-9, "occluded vs quadrature");
        }
        // a tilted sensor: the tangent plane cuts the lamp and the shadow
        let n = DVec3::new(0.9, 0.2, 0.35).normalize();
        let s = OccluderScene {
            occ_angle: 0.4,
            ..OccluderScene::shipped(0.1, 0.1)
        };
        let e = occluded_irradiance(O, n, &s.lamp(), &s.occluder(), 1.0).unwrap();
        let q = quadrature(O, n, 0.5, 2.0, &polygon_edges(&s.occluder()));
        close(e, q, 1e-9, "tilted sensor");
        let (_, g) =
            occluded_irradiance_with_gradient(O, n, &s.lamp(), &s.occluder(), 1.0).unwrap();
        check_occluder_fd(O, n, &s.lamp(), &s.occluder(), &g);
    }

    #[test]
    fn occlusion_limits() {
        // shadow inside the lamp: lamp minus the shadow square
        let s = OccluderScene {
            occ_centre: DVec3::new(0.0, 0.0, 1.5),
            ..OccluderScene::shipped(0.0, 0.0)
        };
        let k = 0.25 * 2.0 / 1.5;
        let expect = PI * 4.0 * (corner(0.5, 0.5, 2.0) - corner(k, k, 2.0));
        close(s.irradiance().unwrap(), expect, 1e-13, "inside");
        // shadow off the lamp
        let s = OccluderScene::shipped(0.6, 0.0);
        close(
            s.irradiance().unwrap(),
            PI * 4.0 * corner(0.5, 0.5, 2.0),
            1e-14,
            "off",
        );
        assert_eq!(s.sensitivities().unwrap(), [0.0; 5]);
        // shadow covering the lamp
        let s = OccluderScene {
            occ_half: 0.4,
            ..OccluderScene::shipped(0.0, 0.0)
        };
        assert!(s.irradiance().unwrap().abs() < 1e-15);
    }

    fn check_occluder_fd(x: DVec3, n: DVec3, lamp: &[DVec3], occ: &[DVec3], g: &[DVec3]) {
        for i in 0..occ.len() {
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                let f = |h: f64| {
                    let mut q = occ.to_vec();
                    q[i] += h * axis;
                    occluded_irradiance(x, n, lamp, &q, 1.0).unwrap()
                };
                close(
                    g[i].dot(axis),
                    richardson(&f, 1e-3),
                    1e-7,
                    "occluder vertex gradient",
                );
            }
        }
    }

    #[test]
    fn occluder_sensitivities_match_finite_differences() {
        for s in scenes() {
            let sens = s.sensitivities().unwrap();
            let occ = s.occluder();
            for (m, d) in s.motions().into_iter().zip(sens) {
                let f = |h: f64| {
                    let q = occ.map(|q| m.apply(q, h));
                    occluded_irradiance(O, DVec3::Z, &s.lamp(), &q, 1.0).unwrap()
                };
                close(d, richardson(&f, 1e-3), 1e-7, &format!("{m:?}"));
            }
            assert!(sens.iter().all(|d| d.abs() > 1e-6), "{sens:?}");
            let (_, g) =
                occluded_irradiance_with_gradient(O, DVec3::Z, &s.lamp(), &occ, 1.0).unwrap();
            check_occluder_fd(O, DVec3::Z, &s.lamp(), &occ, &g);
        }
    }

    fn boxes() -> Vec<BoxScene> {
        vec![
            BoxScene::shipped(DVec3::new(0.2, -0.1, 1.0), 0.3),
            // (not 0.25: a face in a plane through the sensor is a kink of E)
            BoxScene::shipped(DVec3::new(0.3, 0.27, 0.8), 0.5),
            BoxScene::shipped(DVec3::new(-0.05, 0.02, 1.2), 0.2),
        ]
    }

    #[test]
    fn box_matches_quadrature_and_finite_differences() {
        for b in boxes() {
            let e = b.irradiance().unwrap();
            let q = quadrature(
                O,
                DVec3::Z,
                b.lamp_half,
                b.lamp_height,
                &box_edges(&b.corners()),
            );
            close(e, q, 1e-9, "box vs quadrature");
            let sens = b.sensitivities().unwrap();
            let c = b.corners();
            for (m, d) in b.motions().into_iter().zip(sens) {
                let f = |h: f64| {
                    let q = c.map(|q| m.apply(q, h));
                    body_irradiance_with_gradient(O, DVec3::Z, &b.lamp(), &q, 1.0)
                        .unwrap()
                        .0
                };
                close(d, richardson(&f, 1e-3), 1e-7, &format!("box {m:?} {b:?}"));
            }
        }
    }

    #[test]
    fn bad_input_is_rejected() {
        let s = OccluderScene::shipped(0.1, 0.0);
        let (lamp, occ) = (s.lamp(), s.occluder());
        let lift = |dz: f64| occ.map(|q| q + DVec3::Z * dz);
        assert!(occluded_irradiance(O, DVec3::Z, &lamp, &lift(1.5), 1.0).is_err());
        assert!(occluded_irradiance(O, DVec3::Z, &lamp, &lift(-1.0), 1.0).is_err());
        assert!(occluded_irradiance(O, DVec3::Z, &lamp, &lift(-1.5), 1.0).is_err());
        assert!(
            occluded_irradiance(lamp[0] * 0.5 + lamp[1] * 0.5, DVec3::Z, &lamp, &occ, 1.0).is_err()
        );
        assert!(
            occluded_irradiance(DVec3::new(3.0, 0.0, 2.0), DVec3::Z, &lamp, &occ, 1.0).is_err()
        );
        assert!(occluded_irradiance(O, DVec3::ZERO, &lamp, &occ, 1.0).is_err());
        assert!(occluded_irradiance(O, DVec3::Z, &lamp, &occ, -1.0).is_err());
        assert!(occluded_irradiance(O, DVec3::Z, &lamp, &occ[..2], 1.0).is_err());
        let bow = [occ[0], occ[2], occ[1], occ[3]];
        assert!(occluded_irradiance(O, DVec3::Z, &lamp, &bow, 1.0).is_err());
        let mut bent = lamp;
        bent[2].z += 0.1;
        assert!(occluded_irradiance(O, DVec3::Z, &bent, &occ, 1.0).is_err());
        assert!(polygon_irradiance(DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Z, &lamp, 1.0).is_err());
        assert!(polygon_irradiance(lamp[1], DVec3::Z, &lamp, 1.0).is_err());
    }

    /// A shipped scene file.
    fn shipped(name: &str) -> crate::mesh::Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/mesh")
            .join(name);
        crate::mesh::file::load(&path).unwrap()
    }

    #[test]
    fn reference_of_the_square_occluder_file_is_its_closed_form() {
        // The file's mesh comes from an OBJ with its own vertex order, and
        // its scale has no pivot (the centroid): the reference must find the
        // outline and the pivot as `OccluderScene` states them.
        let r = Reference::for_scene(&shipped("occluder.toml")).unwrap();
        let s = OccluderScene::shipped(0.2, 0.1);
        close(r.value(), s.irradiance().unwrap(), 1e-12, "E");
        for (j, want) in s.sensitivities().unwrap().into_iter().enumerate() {
            close(r.derivative(j), want, 1e-12, "dE");
        }
    }

    #[test]
    fn reference_of_the_triangle_scene_is_its_closed_form() {
        let t = crate::mesh::cases::TriangleOccluder::NOMINAL;
        let r = Reference::for_scene(&t.scene(&[0, 1, 2]).unwrap()).unwrap();
        let (e, s) = t.exact().unwrap();
        close(r.value(), e, 1e-12, "E");
        for (j, want) in s.into_iter().enumerate() {
            close(r.derivative(j), want, 1e-12, "dE");
        }
    }

    #[test]
    fn reference_of_the_cube_file_is_the_box_closed_form() {
        let r = Reference::for_scene(&shipped("cube_shadow.toml")).unwrap();
        let b = BoxScene::shipped(DVec3::new(0.2, 0.1, 1.0), 0.5);
        close(r.value(), b.irradiance().unwrap(), 1e-12, "E");
        let s = b.sensitivities().unwrap();
        // cube_tx, cube_tz, cube_rot: the box's x, z and vertical rotation.
        for (j, want) in [(0, s[0]), (1, s[2]), (2, s[3])] {
            close(r.derivative(j), want, 1e-12, "dE");
        }
        // cube_tilt, about x through the centre: a Richardson difference of
        // the tilted box's irradiance.
        let tilt = Motion::Rotate {
            axis: DVec3::X,
            pivot: Some(b.centre),
        };
        let e = |h: f64| {
            let q = b.corners().map(|q| tilt.apply(q, h));
            body_irradiance_with_gradient(O, DVec3::Z, &b.lamp(), &q, 1.0)
                .unwrap()
                .0
        };
        close(r.derivative(3), richardson(&e, 1e-3), 1e-7, "dE/dtilt");
    }

    #[test]
    fn reference_moves_the_emitter_when_nothing_occludes() {
        use crate::mesh::cases::lamp;
        use crate::mesh::{Parameter, Scene};
        let motions = [
            Motion::TranslateX,
            Motion::TranslateZ,
            Motion::Rotate {
                axis: DVec3::new(1.0, 1.0, 0.0).normalize(),
                pivot: None,
            },
        ];
        let parameters = motions
            .iter()
            .enumerate()
            .map(|(j, &motion)| Parameter {
                name: format!("p{j}"),
                shape: "lamp".into(),
                motion,
                bounds: None,
            })
            .collect();
        let sensor = crate::mesh::Sensor::Irradiance {
            point: DVec3::new(0.3, 0.0, 0.5),
            normal: DVec3::new(0.2, 0.0, 1.0),
        };
        let scene = Scene::new(vec![lamp()], parameters, sensor).unwrap();
        let r = Reference::for_scene(&scene).unwrap();
        let (x, n) = (DVec3::new(0.3, 0.0, 0.5), DVec3::new(0.2, 0.0, 1.0));
        let corners = lamp().vertices;
        close(
            r.value(),
            polygon_irradiance(x, n, &corners, 1.0).unwrap(),
            1e-12,
            "E",
        );
        for j in 0..motions.len() {
            // Pivots resolved (the lamp's centroid).
            let m = scene.parameters()[j].motion;
            let e = |h: f64| {
                let q: Vec<DVec3> = corners.iter().map(|&q| m.apply(q, h)).collect();
                polygon_irradiance(x, n, &q, 1.0).unwrap()
            };
            close(r.derivative(j), richardson(&e, 1e-3), 1e-7, "dE/dπ");
        }
    }

    #[test]
    fn scenes_without_a_closed_form_say_why() {
        for (name, why) in [
            ("fog_cube.toml", "reflectors and media"),
            ("camera_shadow.toml", "camera"),
            ("dome.toml", ""),
            ("room.toml", ""),
        ] {
            let e = Reference::for_scene(&shipped(name))
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("no analytic reference") && e.contains(why),
                "{name}: {e}"
            );
        }
        use crate::mesh::cases::{lamp, square_shape, up};
        let above = square_shape(
            "occ",
            DVec3::new(0.0, 0.0, 2.5),
            0.2,
            crate::mesh::Surface::Absorber,
        );
        let scene = crate::mesh::Scene::new(vec![lamp(), above], Vec::new(), up()).unwrap();
        let e = Reference::for_scene(&scene).unwrap_err().to_string();
        assert!(
            e.contains("no analytic reference") && e.contains("strictly between"),
            "{e}"
        );
    }
}
