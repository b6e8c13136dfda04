//! The f64 predicates scene validation needs, on triangles given by their
//! corners: closest points (Ericson, *Real-Time Collision Detection*, §5.1),
//! whether two triangles come within a distance of each other (crossing,
//! touching, coplanar overlap), signed volume and the generalized winding
//! number (Jacobson et al. 2013) of a closed mesh around a point.
//!
//! Two closed triangles meet exactly when an edge of one meets the other
//! (their intersection, if any, is a segment or polygon whose boundary lies
//! on their edges), and when they do not meet their distance is attained
//! between a vertex and a triangle or between two edges: so
//! [`triangles_within`] is the minimum of six segment–triangle distances,
//! each of which is zero when the segment pierces the triangle's plane
//! inside it, else the least of two point–triangle and three
//! segment–segment distances.
use glam::DVec3;
use std::f64::consts::PI;

/// The corners of the vertices' bounding box.
pub(crate) fn bounds(vertices: &[DVec3]) -> (DVec3, DVec3) {
    vertices
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        })
}

/// The point of triangle `[a, b, c]` closest to `p`.
pub fn closest_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom <= 0.0 {
        // A degenerate triangle (validation removes them): its nearest
        // corner.
        return [a, b, c]
            .into_iter()
            .min_by(|u, v| {
                (*u - p)
                    .length_squared()
                    .total_cmp(&(*v - p).length_squared())
            })
            .unwrap_or(a);
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// Distance from `p` to the triangle `t`.
pub fn point_triangle_distance(p: DVec3, t: [DVec3; 3]) -> f64 {
    (closest_on_triangle(p, t) - p).length()
}

/// Distance between the segments `[p1, q1]` and `[p2, q2]`.
pub fn segment_distance(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (s, t);
    if a <= 0.0 && e <= 0.0 {
        return r.length();
    }
    if a <= 0.0 {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= 0.0 {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            (s, t) = if t0 < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t0 > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s0, t0)
            };
        }
    }
    (p1 + d1 * s - (p2 + d2 * t)).length()
}

/// Distance from the segment `[p, q]` to the triangle `t`.
pub fn segment_triangle_distance(p: DVec3, q: DVec3, t: [DVec3; 3]) -> f64 {
    let [a, b, c] = t;
    let n = (b - a).cross(c - a);
    let (dp, dq) = (n.dot(p - a), n.dot(q - a));
    // Crossing the plane (strictly on both sides, or ending on it): the
    // crossing point's distance to the triangle decides.
    let mut best = f64::INFINITY;
    if (dp <= 0.0 && dq >= 0.0 || dp >= 0.0 && dq <= 0.0) && dp != dq {
        let x = p + (q - p) * (dp / (dp - dq));
        best = point_triangle_distance(x, t);
        if best == 0.0 {
            return 0.0;
        }
    }
    best = best
        .min(point_triangle_distance(p, t))
        .min(point_triangle_distance(q, t));
    for i in 0..3 {
        best = best.min(segment_distance(p, q, t[i], t[(i + 1) % 3]));
    }
    best
}

/// Whether the closed triangles `s` and `t` come within `tol` of each other.
/// Distances are computed in f64, so touching is only decided up to
/// rounding: pass a tolerance of a few ulps of the coordinates at least
/// (validation passes [`TOUCH_DISTANCE`](super::TOUCH_DISTANCE) × size).
pub fn triangles_within(s: [DVec3; 3], t: [DVec3; 3], tol: f64) -> bool {
    (0..3).any(|i| {
        segment_triangle_distance(s[i], s[(i + 1) % 3], t) <= tol
            || segment_triangle_distance(t[i], t[(i + 1) % 3], s) <= tol
    })
}

/// Signed volume enclosed by the triangles (`corners` yields each
/// triangle's corners), positive when their normals `(b−a)×(c−a)` point
/// out. Measured from `origin` (a point near the mesh, for precision).
pub fn signed_volume(triangles: impl Iterator<Item = [DVec3; 3]>, origin: DVec3) -> f64 {
    triangles
        .map(|[a, b, c]| (a - origin).dot((b - origin).cross(c - origin)))
        .sum::<f64>()
        / 6.0
}

/// Generalized winding number of the triangles around `p`: the solid angle
/// they subtend, signed, over 4π (Van Oosterom–Strackee formula per
/// triangle). For a closed mesh oriented outward it is 1 inside and 0
/// outside, up to rounding, wherever `p` is off the surface; rays through
/// edges and vertices, the trap of crossing parity, do not arise.
pub fn winding_number(triangles: impl Iterator<Item = [DVec3; 3]>, p: DVec3) -> f64 {
    triangles
        .map(|t| {
            let [a, b, c] = t.map(|v| v - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
            2.0 * num.atan2(den)
        })
        .sum::<f64>()
        / (4.0 * PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [DVec3; 3] {
        [a, b, c].map(DVec3::from)
    }

    #[test]
    fn triangle_pairs_are_classified() {
        // Touching is decided up to rounding (a point's distance to a
        // triangle it lies on comes out ~1e-17, not 0).
        const TOL: f64 = 1e-12;
        let t = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Piercing through the interior.
        let s = tri([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [0.3, 0.25, 1.0]);
        assert!(triangles_within(s, t, TOL));
        // Touching at a vertex of s on t's interior.
        let s = tri([0.2, 0.2, 0.0], [0.2, 0.2, 1.0], [0.3, 0.25, 1.0]);
        assert!(triangles_within(s, t, TOL));
        // Just above.
        let s = tri([0.2, 0.2, 1e-6], [0.2, 0.2, 1.0], [0.3, 0.25, 1.0]);
        assert!(!triangles_within(s, t, TOL));
        assert!(triangles_within(s, t, 2e-6));
        // Coplanar overlap with no vertex inside the other (a star of David).
        let u = tri([0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [1.5, 2.6, 0.0]);
        let v = tri([0.0, 1.7, 0.0], [3.0, 1.7, 0.0], [1.5, -0.9, 0.0]);
        assert!(triangles_within(u, v, TOL));
        // Coplanar, one inside the other.
        let w = tri([1.4, 0.5, 0.0], [1.6, 0.5, 0.0], [1.5, 0.7, 0.0]);
        assert!(triangles_within(u, w, TOL));
        // Coplanar and apart.
        let x = tri([4.0, 0.0, 0.0], [5.0, 0.0, 0.0], [4.5, 1.0, 0.0]);
        assert!(!triangles_within(u, x, TOL));
        // Sharing an edge in different planes.
        let y = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        assert!(triangles_within(t, y, TOL));
    }

    #[test]
    fn winding_numbers_of_a_tetrahedron() {
        let v = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ]
        .map(DVec3::from);
        let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        let tris = || faces.iter().map(|f| f.map(|i| v[i]));
        assert!(signed_volume(tris(), DVec3::ZERO) > 0.0);
        let inside = winding_number(tris(), DVec3::splat(0.1));
        let outside = winding_number(tris(), DVec3::splat(1.0));
        assert!((inside - 1.0).abs() < 1e-12 && outside.abs() < 1e-12);
        // On the line through a vertex and an edge: no parity trap.
        let edge = winding_number(tris(), DVec3::new(-1.0, 0.0, 0.0));
        assert!(edge.abs() < 1e-12);
    }
}
