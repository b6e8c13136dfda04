//! A ray that meets a medium's closed boundary at a vertex may cross it
//! there or only touch it (a radiance sensor's ray grazing a polygon's
//! corner). The walk changes medium at every hit on a medium's boundary, so
//! a touch must not be reported as a hit. The two segments at the vertex
//! fold back to one side of the ray exactly when it only touches; a ray
//! just inside the corner meets both, and both hits count. The 3D twin is
//! `mesh::touch` (edges and vertices). Book: chapter "Flatland", section
//! "Scenes".
use super::super::geometry::{Hit, cross};
use super::Scene;
use super::Surface;
use glam::DVec2;

// How near a segment's end, relative to its length, a hit counts as at
// the vertex: the path core's `NEAR`.
use crate::path::tolerance::NEAR;

/// Most touches one cast passes before it reports the next hit as it is.
const MAX_TOUCHES: usize = 8;

impl Scene {
    /// Closest segment (any surface) other than `skip` along `origin + t
    /// dir`; a medium's corner the ray only touches is passed.
    #[inline]
    pub fn cast(&self, origin: DVec2, dir: DVec2, skip: u32) -> Option<Hit> {
        let (mut from, mut skip, mut before, mut touches) = (origin, skip, 0.0, 0);
        loop {
            let h = self.caster.closest_hit(from, dir, f64::INFINITY, skip)?;
            if touches == MAX_TOUCHES || !self.touches_only(from, dir, h) {
                return Some(Hit {
                    t: before + h.t,
                    ..h
                });
            }
            before += h.t;
            from += dir * h.t;
            skip = h.segment;
            touches += 1;
        }
    }

    /// Whether the ray from `x` along `dir` meets a medium's boundary at
    /// `h` on one of its corners and only touches the polygon there (see
    /// the [module docs](self)).
    fn touches_only(&self, x: DVec2, dir: DVec2, h: Hit) -> bool {
        let i = h.segment as usize;
        let k = self.owner[i];
        if self.shapes[k as usize].surface != Surface::Transparent {
            return false;
        }
        let s = self.segments[i];
        let q = x + dir * h.t;
        let near = NEAR * s.length();
        let (v, other) = if (q - s.a).length() <= near {
            (s.a, s.b)
        } else if (q - s.b).length() <= near {
            (s.b, s.a)
        } else {
            return false;
        };
        let Some(j) = (0..self.segments.len()).find(|&j| {
            j != i && self.owner[j] == k && (self.segments[j].a == v || self.segments[j].b == v)
        }) else {
            return false;
        };
        let n = self.segments[j];
        let next = if n.a == v { n.b } else { n.a };
        if cross(dir, other - v) * cross(dir, next - v) <= 0.0 {
            return false;
        }
        // Folded back: a touch unless the ray goes on to meet the other
        // segment (a chord the caster resolves).
        self.caster
            .closest_hit(q, dir, f64::INFINITY, h.segment)
            .is_none_or(|h2| h2.segment as usize != j)
    }
}
