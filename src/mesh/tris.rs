//! Stand-in ray caster (linear scan) until the BVH lands.
use glam::DVec3;

/// Relative hit threshold.
pub const T_MIN: f64 = 1e-9;

/// Möller–Trumbore in f64.
#[inline]
pub fn intersect(t: &[DVec3; 3], origin: DVec3, dir: DVec3) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let s = origin - t[0];
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    let d = e2.dot(q) / det;
    let size = e1.length().max(e2.length());
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && d * dir.length() > T_MIN * size).then_some(d)
}

/// Linear scan over triangles.
#[derive(Debug, Clone)]
pub struct TriangleBvh {
    tris: Vec<[DVec3; 3]>,
}

impl TriangleBvh {
    /// Caster over `triangles`.
    pub fn new(triangles: Vec<[DVec3; 3]>) -> TriangleBvh {
        TriangleBvh { tris: triangles }
    }
    /// Closest hit other than `skip` below `t_max`.
    pub fn closest_hit(&self, o: DVec3, d: DVec3, t_max: f64, skip: u32) -> Option<(f64, u32)> {
        let mut best: Option<(f64, u32)> = None;
        for (i, t) in self.tris.iter().enumerate() {
            if i as u32 == skip {
                continue;
            }
            if let Some(h) = intersect(t, o, d)
                && h < t_max
                && best.is_none_or(|b| h < b.0)
            {
                best = Some((h, i as u32));
            }
        }
        best
    }
    /// Any hit other than `skip` below `t_max`.
    pub fn any_hit(&self, o: DVec3, d: DVec3, t_max: f64, skip: u32) -> bool {
        self.closest_hit(o, d, t_max, skip).is_some()
    }
}
