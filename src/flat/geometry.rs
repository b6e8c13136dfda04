//! Plane geometry of flatland scenes: segments, ray–segment intersection,
//! polygon predicates, and the [`RayCast`] trait the path tracer asks for
//! closest hits and visibility (implemented by a linear scan here and by a
//! BVH in [`bvh`](super::bvh)).
use glam::DVec2;

/// The 2D cross product `a.x b.y − a.y b.x` (z of the 3D one).
#[inline]
pub fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `v` turned by +90°.
#[inline]
pub fn perp(v: DVec2) -> DVec2 {
    DVec2::new(-v.y, v.x)
}

/// The unit direction at angle `phi` (radians from +x).
#[inline]
pub fn direction(phi: f64) -> DVec2 {
    let (s, c) = phi.sin_cos();
    DVec2::new(c, s)
}

/// A segment from `a` to `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// First end.
    pub a: DVec2,
    /// Second end.
    pub b: DVec2,
}

impl Segment {
    /// Distance `t` along the ray `origin + t dir` to the segment, if the ray
    /// crosses it (ends included) farther than [`T_MIN`] times the segment's
    /// length (a threshold that scales with the scene); `dir` need not be
    /// unit.
    #[inline]
    pub fn intersect(&self, origin: DVec2, dir: DVec2) -> Option<f64> {
        let e = self.b - self.a;
        let denom = cross(dir, e);
        if denom == 0.0 {
            return None; // parallel: a grazing ray sees no area
        }
        let ao = self.a - origin;
        let t = cross(ao, e) / denom;
        let s = cross(ao, dir) / denom;
        let far = t > 0.0 && t * t * dir.length_squared() > T_MIN * T_MIN * e.length_squared();
        (far && (0.0..=1.0).contains(&s)).then_some(t)
    }

    /// Length of the segment.
    pub fn length(&self) -> f64 {
        (self.b - self.a).length()
    }

    /// Unit normal on the left of `a → b` (`perp` of the direction).
    pub fn left_normal(&self) -> DVec2 {
        perp(self.b - self.a).normalize()
    }

    /// Whether two segments share a point (touching ends included).
    pub fn touches(&self, other: &Segment) -> bool {
        let d1 = orient(other.a, other.b, self.a);
        let d2 = orient(other.a, other.b, self.b);
        let d3 = orient(self.a, self.b, other.a);
        let d4 = orient(self.a, self.b, other.b);
        if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
            && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
        {
            return true;
        }
        (d1 == 0.0 && on_segment(other, self.a))
            || (d2 == 0.0 && on_segment(other, self.b))
            || (d3 == 0.0 && on_segment(self, other.a))
            || (d4 == 0.0 && on_segment(self, other.b))
    }

    /// Distance from `p` to the segment.
    pub fn distance(&self, p: DVec2) -> f64 {
        let e = self.b - self.a;
        let s = ((p - self.a).dot(e) / e.length_squared()).clamp(0.0, 1.0);
        (self.a + s * e - p).length()
    }
}

/// Smallest ray distance counted as a hit, relative to the length of the
/// segment hit (the path core's, shared with 3D): a ray leaving a surface
/// (or a corner) must not find the surface it leaves (the tracer also
/// skips that segment by id).
pub use crate::path::tolerance::T_MIN;

/// Twice the signed area of the triangle `a b c` (> 0 counter-clockwise).
#[inline]
fn orient(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    cross(b - a, c - a)
}

/// Whether `p`, collinear with `s`, lies within its bounding box.
fn on_segment(s: &Segment, p: DVec2) -> bool {
    p.x >= s.a.x.min(s.b.x)
        && p.x <= s.a.x.max(s.b.x)
        && p.y >= s.a.y.min(s.b.y)
        && p.y <= s.a.y.max(s.b.y)
}

/// Signed area of a closed polygon (> 0 counter-clockwise).
pub fn signed_area(vertices: &[DVec2]) -> f64 {
    let n = vertices.len();
    let Some(&o) = vertices.first() else {
        return 0.0;
    };
    // About the first vertex: far from the origin the products of absolute
    // coordinates would cancel to nothing.
    0.5 * (0..n)
        .map(|i| cross(vertices[i] - o, vertices[(i + 1) % n] - o))
        .sum::<f64>()
}

/// Whether `p` is inside the closed polygon (even–odd rule).
pub fn contains(vertices: &[DVec2], p: DVec2) -> bool {
    let n = vertices.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y) {
            inside = !inside;
        }
    }
    inside
}

/// A closest hit: the ray distance and the segment's index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f64,
    /// Index of the segment hit, in the caster's segment list.
    pub segment: u32,
}

/// No segment to skip.
pub const NO_SEGMENT: u32 = u32::MAX;

/// Ray queries against a fixed list of segments.
pub trait RayCast: Send + Sync {
    /// The closest segment crossed by `origin + t dir` with `T_MIN·length < t < t_max`,
    /// ignoring segment `skip` (the one the ray leaves, or [`NO_SEGMENT`]).
    fn closest_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> Option<Hit>;
    /// Whether any segment other than `skip` is crossed with `T_MIN·length < t < t_max`.
    fn any_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> bool {
        self.closest_hit(origin, dir, t_max, skip).is_some()
    }
}

/// The reference caster: tests every segment.
#[derive(Debug, Clone)]
pub struct LinearScan {
    segments: Vec<Segment>,
}

impl LinearScan {
    /// A caster over `segments` (indices are positions in the list).
    pub fn new(segments: Vec<Segment>) -> LinearScan {
        LinearScan { segments }
    }
}

impl RayCast for LinearScan {
    fn closest_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_best = t_max;
        for (i, s) in self.segments.iter().enumerate() {
            if i as u32 == skip {
                continue;
            }
            if let Some(t) = s.intersect(origin, dir).filter(|&t| t < t_best) {
                t_best = t;
                best = Some(Hit {
                    t,
                    segment: i as u32,
                });
            }
        }
        best
    }

    fn any_hit(&self, origin: DVec2, dir: DVec2, t_max: f64, skip: u32) -> bool {
        self.segments
            .iter()
            .enumerate()
            .any(|(i, s)| i as u32 != skip && s.intersect(origin, dir).is_some_and(|t| t < t_max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(ax: f64, ay: f64, bx: f64, by: f64) -> Segment {
        Segment {
            a: DVec2::new(ax, ay),
            b: DVec2::new(bx, by),
        }
    }

    #[test]
    fn rays_hit_segments_at_the_right_distance() {
        let s = seg(1.0, -1.0, 1.0, 1.0);
        let t = s.intersect(DVec2::ZERO, DVec2::X).unwrap();
        assert!((t - 1.0).abs() < 1e-15);
        assert_eq!(s.intersect(DVec2::ZERO, -DVec2::X), None);
        assert_eq!(s.intersect(DVec2::ZERO, DVec2::Y), None);
        let d = DVec2::new(1.0, 0.5).normalize();
        let t = s.intersect(DVec2::ZERO, d).unwrap();
        assert!((DVec2::ZERO + t * d - DVec2::new(1.0, 0.5)).length() < 1e-15);
    }

    #[test]
    fn the_linear_scan_finds_the_closest_and_skips() {
        let c = LinearScan::new(vec![seg(2.0, -1.0, 2.0, 1.0), seg(1.0, -1.0, 1.0, 1.0)]);
        let h = c.closest_hit(DVec2::ZERO, DVec2::X, f64::INFINITY, NO_SEGMENT);
        assert_eq!(h.map(|h| h.segment), Some(1));
        let h = c.closest_hit(DVec2::ZERO, DVec2::X, f64::INFINITY, 1);
        assert_eq!(h.map(|h| h.segment), Some(0));
        assert!(!c.any_hit(DVec2::ZERO, DVec2::X, 0.5, NO_SEGMENT));
        assert!(c.any_hit(DVec2::ZERO, DVec2::X, 1.5, NO_SEGMENT));
    }

    #[test]
    fn polygon_predicates() {
        let sq = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ];
        assert!((signed_area(&sq) - 1.0).abs() < 1e-15);
        assert!(contains(&sq, DVec2::new(0.5, 0.5)));
        assert!(!contains(&sq, DVec2::new(1.5, 0.5)));
        assert!(seg(0.0, 0.0, 1.0, 1.0).touches(&seg(0.0, 1.0, 1.0, 0.0)));
        assert!(seg(0.0, 0.0, 1.0, 0.0).touches(&seg(1.0, 0.0, 2.0, 1.0)));
        assert!(!seg(0.0, 0.0, 1.0, 0.0).touches(&seg(0.0, 1.0, 1.0, 1.0)));
        assert!((seg(0.0, 0.0, 1.0, 0.0).distance(DVec2::new(0.5, 2.0)) - 2.0).abs() < 1e-15);
    }
}
