//! A uniform grid over the corners of opaque shapes, answering "which corners
//! lie inside this triangle": the expectation method's warp asks it for the
//! nearest visible corner on either side of a sampled direction in scenes
//! with many corners (book: chapter "Flatland", section "Where the methods
//! fail", *Many corners*).
//!
//! Why a triangle: from a vertex `x`, let the sampled direction first hit an
//! opaque segment at `p`, and let `e` be that segment's end on one side.
//! Turning from `x→p` toward `x→e`, the first visible corner is `e` itself
//! or the corner of smallest angle strictly inside the triangle `x p e`:
//! a segment blocking the sight line to a corner `c` in the triangle cannot
//! cross `x p` (the ray reaches `p` unobstructed) nor `p e` (segments do not
//! cross), nor `x c` twice, so one of its ends lies in the triangle at a
//! smaller angle than `c`. The smallest-angle corner there is thus visible,
//! and no shadow ray is needed.
use super::geometry::cross;
use glam::DVec2;

/// Corners bucketed by cell, for triangle queries.
#[derive(Debug, Clone)]
pub struct CornerGrid {
    origin: DVec2,
    cell: f64,
    nx: usize,
    ny: usize,
    /// `start[c]..start[c + 1]` indexes `items` for cell `c`.
    start: Vec<u32>,
    /// Corner indices, grouped by cell.
    items: Vec<u32>,
}

impl CornerGrid {
    /// A grid with about two corners per cell over the corners' bounding box.
    pub fn new(corners: &[DVec2]) -> CornerGrid {
        let mut lo = DVec2::splat(f64::INFINITY);
        let mut hi = DVec2::splat(f64::NEG_INFINITY);
        for &c in corners {
            lo = lo.min(c);
            hi = hi.max(c);
        }
        let extent = (hi - lo).max(DVec2::splat(1e-12 * (hi - lo).max_element().max(1e-300)));
        let cells_wanted = (corners.len() as f64 / 2.0).max(1.0);
        let cell = (extent.x * extent.y / cells_wanted)
            .sqrt()
            .max(extent.max_element() / 4096.0);
        let nx = ((extent.x / cell).ceil() as usize).clamp(1, 4096);
        let ny = ((extent.y / cell).ceil() as usize).clamp(1, 4096);
        let mut grid = CornerGrid {
            origin: lo,
            cell,
            nx,
            ny,
            start: vec![0; nx * ny + 1],
            items: vec![0; corners.len()],
        };
        let cells: Vec<usize> = corners.iter().map(|&c| grid.cell_of(c)).collect();
        for &c in &cells {
            grid.start[c + 1] += 1;
        }
        for i in 0..nx * ny {
            grid.start[i + 1] += grid.start[i];
        }
        let mut fill = grid.start.clone();
        for (i, &c) in cells.iter().enumerate() {
            grid.items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        grid
    }

    /// The box the grid covers.
    pub fn bounds(&self) -> (DVec2, DVec2) {
        (
            self.origin,
            self.origin + self.cell * DVec2::new(self.nx as f64, self.ny as f64),
        )
    }

    fn cell_of(&self, p: DVec2) -> usize {
        let ix = (((p.x - self.origin.x) / self.cell) as usize).min(self.nx - 1);
        let iy = (((p.y - self.origin.y) / self.cell) as usize).min(self.ny - 1);
        iy * self.nx + ix
    }

    /// Calls `f` with the index of every corner in the cells the triangle
    /// `a b c` overlaps (a superset of the corners inside it; the caller
    /// tests). Rows of cells are scanned over the triangle's extent in each.
    pub fn near_triangle(&self, a: DVec2, b: DVec2, c: DVec2, mut f: impl FnMut(u32)) {
        let lo = a.min(b).min(c);
        let hi = a.max(b).max(c);
        let row = |y: f64| ((y - self.origin.y) / self.cell).floor();
        let (r0, r1) = (row(lo.y).max(0.0), row(hi.y).min(self.ny as f64 - 1.0));
        if r0 > r1 {
            return;
        }
        for r in r0 as usize..=r1 as usize {
            let y0 = self.origin.y + r as f64 * self.cell;
            let y1 = y0 + self.cell;
            // The triangle's x-extent within the strip [y0, y1].
            let (mut xmin, mut xmax) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut take = |x: f64| {
                xmin = xmin.min(x);
                xmax = xmax.max(x);
            };
            for (p, q) in [(a, b), (b, c), (c, a)] {
                for v in [p, q] {
                    if v.y >= y0 && v.y <= y1 {
                        take(v.x);
                    }
                }
                for y in [y0, y1] {
                    if (p.y - y) * (q.y - y) < 0.0 {
                        take(p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x));
                    }
                }
            }
            if xmin > xmax {
                continue;
            }
            let col = |x: f64| ((x - self.origin.x) / self.cell).floor();
            let (c0, c1) = (col(xmin).max(0.0), col(xmax).min(self.nx as f64 - 1.0));
            if c0 > c1 {
                continue;
            }
            let base = r * self.nx;
            let (s, e) = (
                self.start[base + c0 as usize],
                self.start[base + c1 as usize + 1],
            );
            for &i in &self.items[s as usize..e as usize] {
                f(i);
            }
        }
    }
}

/// Whether `q` lies strictly inside the triangle `a b c` (either
/// orientation).
#[inline]
pub fn inside(a: DVec2, b: DVec2, c: DVec2, q: DVec2) -> bool {
    let d1 = cross(b - a, q - a);
    let d2 = cross(c - b, q - b);
    let d3 = cross(a - c, q - c);
    (d1 > 0.0 && d2 > 0.0 && d3 > 0.0) || (d1 < 0.0 && d2 < 0.0 && d3 < 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn triangle_queries_find_every_corner_inside() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let corners: Vec<DVec2> = (0..5000)
            .map(|_| DVec2::new(rng.random::<f64>() * 4.0 - 1.0, rng.random::<f64>() * 2.0))
            .collect();
        let grid = CornerGrid::new(&corners);
        for _ in 0..300 {
            let mut p = || {
                DVec2::new(
                    rng.random::<f64>() * 6.0 - 2.0,
                    rng.random::<f64>() * 3.0 - 0.5,
                )
            };
            let (a, b, c) = (p(), p(), p());
            let mut found = Vec::new();
            grid.near_triangle(a, b, c, |i| {
                if inside(a, b, c, corners[i as usize]) {
                    found.push(i)
                }
            });
            found.sort();
            let all: Vec<u32> = (0..corners.len() as u32)
                .filter(|&i| inside(a, b, c, corners[i as usize]))
                .collect();
            assert_eq!(found, all);
        }
    }
}
