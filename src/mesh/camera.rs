//! The pinhole camera of 3D scenes: each pixel's reading is its mean
//! radiance over its footprint on the image plane (a box filter),
//!
//! `P = (1/A) ∫_pixel L(e, η(ξ)) dξ = ∫ L(e, η) p(η) dη`,  `p(η) = |ξ|³ / A`
//!
//! where `ξ = f + x r + y u` is the image-plane point at unit distance along
//! the view axis `f` (`dη = dξ / |ξ|³`), `A` the footprint's area. `p` is the
//! lobe of the camera vertex ([`SpaceLobe::Pixel`](super::lobe::SpaceLobe::Pixel)), so the path core treats
//! a pixel like any other directional integral:
//!
//! - rendering's and transport's **primary edge term** (the silhouettes
//!   crossing the pixel move) draws a point on the silhouette edges
//!   projected into the footprint ([`PixelEdges`], built once per camera by
//!   cutting every projected edge at the pixel grid);
//! - expectation's **warp** at the camera is the fibre warp with its pole on
//!   the camera's right axis `r`: its fibres are then exactly the image's
//!   rows, the footprint's top and bottom are fibres (the field is tangent to
//!   them) and its left and right sides are knots where the field is 0, so
//!   the warp keeps every stratum onto itself.
//!
//! Book: chapter "Three dimensions", section "A camera".
use super::edges::Edge;
use super::edges::is_discontinuity;
use crate::path::PixelSample;
use glam::DVec3;
use serde::{Deserialize, Serialize};

pub use crate::scene::camera::{MAX_SIDE, MIN_PIXEL, view_problem};

/// A pinhole camera: file form `{ kind = "camera", position, look_at, up,
/// fov_deg, width, height }`; `fov_deg` is the horizontal field of view
/// (Mitsuba's default axis), pixels are square. The sensor's file form
/// holds this one (`crate::mesh::scene::repr`), so each field is read
/// through a reader that names it in errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// The pinhole.
    #[serde(deserialize_with = "form::position")]
    pub position: DVec3,
    /// A point on the view axis.
    #[serde(deserialize_with = "form::look_at")]
    pub look_at: DVec3,
    /// Up, roughly (not along the view axis).
    #[serde(deserialize_with = "form::up")]
    pub up: DVec3,
    /// Horizontal field of view in degrees, in `(0, 170]`.
    #[serde(deserialize_with = "form::fov_deg")]
    pub fov_deg: f64,
    /// Pixels per row.
    #[serde(deserialize_with = "form::width")]
    pub width: u32,
    /// Rows.
    #[serde(deserialize_with = "form::height")]
    pub height: u32,
}

/// The readers of [`Camera`]'s fields (`crate::scene::repr::fields`): serde
/// buffers a tagged table, so its own message would not say which field is
/// wrong.
mod form {
    use crate::scene::repr::fields;
    use glam::DVec3;
    fields!(position: DVec3, look_at: DVec3, up: DVec3);
    fields!(fov_deg: f64, width: u32, height: u32);
}

impl Camera {
    /// Why the camera is not usable, if it is not: non-finite vectors, the
    /// view axis of zero length or along `up`, a field of view outside
    /// `(0, 170]` degrees, a side outside `1..=MAX_SIDE`.
    pub fn problem(&self) -> Option<String> {
        let finite = |v: DVec3| v.is_finite();
        if !(finite(self.position) && finite(self.look_at) && finite(self.up)) {
            return Some("camera position, look_at and up must be finite".into());
        }
        let f = self.look_at - self.position;
        if f.length() <= 0.0 {
            return Some("camera look_at equals its position".into());
        }
        let up = self.up.normalize_or_zero();
        if up == DVec3::ZERO || f.normalize().cross(up).length() < 1e-6 {
            return Some("camera up is zero or along the view axis".into());
        }
        view_problem(
            self.fov_deg,
            "a horizontal field of view",
            &[("width", self.width), ("height", self.height)],
        )
    }

    /// The camera's frame and image plane.
    pub fn frame(&self) -> CameraFrame {
        let f = (self.look_at - self.position).normalize();
        let r = f.cross(self.up).normalize();
        let u = r.cross(f);
        let half_w = (0.5 * self.fov_deg.to_radians()).tan();
        CameraFrame {
            eye: self.position,
            f,
            r,
            u,
            half_w,
            half_h: half_w * self.height as f64 / self.width as f64,
            width: self.width,
            height: self.height,
        }
    }
}

/// A camera's orthonormal frame (`f` forward, `r` right, `u` up) and its
/// image plane at unit distance: `x ∈ [−half_w, half_w]` to the right,
/// `y ∈ [−half_h, half_h]` up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraFrame {
    /// The pinhole.
    pub eye: DVec3,
    /// View axis.
    pub f: DVec3,
    /// Right.
    pub r: DVec3,
    /// Up.
    pub u: DVec3,
    /// Half the image plane's width and height at unit distance.
    pub half_w: f64,
    /// See `half_w`.
    pub half_h: f64,
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// A rectangle of the image plane, `[x0, x1] × [y0, y1]`.
pub type Rect = [f64; 4];

impl CameraFrame {
    /// Width of one pixel on the image plane (pixels are square).
    #[inline]
    pub fn pixel_size(&self) -> f64 {
        2.0 * self.half_w / self.width as f64
    }

    /// The footprint of the stratum of `s` on the image plane.
    pub fn rect(&self, s: PixelSample) -> Rect {
        let d = self.pixel_size();
        let (col, row) = (s.pixel % self.width, s.pixel / self.width);
        let x0 = -self.half_w + d * col as f64;
        let y1 = self.half_h - d * row as f64;
        let m = s.strata.max(1);
        let (sc, sr) = ((s.stratum % m) as f64, (s.stratum / m) as f64);
        let e = d / m as f64;
        let (x0, y1) = (x0 + e * sc, y1 - e * sr);
        [x0, x0 + e, y1 - e, y1]
    }

    /// The unit direction through the image-plane point `(x, y)`.
    #[inline]
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        (self.f + self.r * x + self.u * y).normalize()
    }

    /// The pixel (row-major, row 0 at the top) the image-plane point lies
    /// in, clamped to the image.
    #[inline]
    fn cell(&self, x: f64, y: f64) -> u32 {
        let d = self.pixel_size();
        let col = (((x + self.half_w) / d).floor() as i64).clamp(0, self.width as i64 - 1);
        let row = (((self.half_h - y) / d).floor() as i64).clamp(0, self.height as i64 - 1);
        (row * self.width as i64 + col) as u32
    }
}

/// The part of the segment `a + t (b − a)`, `t ∈ [0, 1]`, inside `rect`
/// (Liang–Barsky): its parameter range, if any.
#[inline]
pub fn clip(a: [f64; 2], b: [f64; 2], rect: &Rect) -> Option<(f64, f64)> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d[0], a[0] - rect[0]),
        (d[0], rect[1] - a[0]),
        (-d[1], a[1] - rect[2]),
        (d[1], rect[3] - a[1]),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 < t1).then_some((t0, t1))
}

/// A piece of a projected edge inside one pixel, in image-plane coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// The edge (index into the scene's edge table).
    pub edge: u32,
    /// Its ends on the image plane.
    pub a: [f64; 2],
    /// Second end.
    pub b: [f64; 2],
}

/// The moving meshes' edges that can be discontinuities seen from the
/// camera, projected onto the image plane and cut at the pixel grid: per
/// pixel, the pieces inside it (compressed rows: pixel `p`'s pieces are
/// `pieces[start[p]..start[p + 1]]`).
#[derive(Debug, Clone, Default)]
pub struct PixelEdges {
    start: Vec<u32>,
    pieces: Vec<Piece>,
    /// Per pixel, whether its pieces cross the image's rows more steeply
    /// than its columns (their total vertical extent is at least their
    /// horizontal one): the expectation method's warp at the camera then
    /// slides along rows.
    along_rows: Vec<bool>,
}

impl PixelEdges {
    /// The pieces of the edges `ids` of `edges` (with their `facts`).
    pub fn new(
        cam: &CameraFrame,
        edges: &[Edge],
        facts: &[super::edges::EdgeFacts],
        ids: impl Iterator<Item = u32>,
        near: f64,
    ) -> PixelEdges {
        let image = [-cam.half_w, cam.half_w, -cam.half_h, cam.half_h];
        let d = cam.pixel_size();
        let mut cut: Vec<(u32, Piece)> = Vec::new();
        let mut ts: Vec<f64> = Vec::new();
        for i in ids {
            let e = &edges[i as usize];
            if !is_discontinuity(e, &facts[i as usize], cam.eye) {
                continue;
            }
            // The part in front of the pinhole (depth ≥ near).
            let (da, db) = ((e.a - cam.eye).dot(cam.f), (e.b - cam.eye).dot(cam.f));
            if da < near && db < near {
                continue;
            }
            let at = |t: f64| e.a + (e.b - e.a) * t;
            let (mut qa, mut qb) = (e.a, e.b);
            if da < near {
                qa = at((near - da) / (db - da));
            } else if db < near {
                qb = at((near - da) / (db - da));
            }
            let project = |q: DVec3| {
                let v = q - cam.eye;
                let z = v.dot(cam.f);
                [v.dot(cam.r) / z, v.dot(cam.u) / z]
            };
            let (pa, pb) = (project(qa), project(qb));
            let Some((t0, t1)) = clip(pa, pb, &image) else {
                continue;
            };
            let lerp = |t: f64| [pa[0] + (pb[0] - pa[0]) * t, pa[1] + (pb[1] - pa[1]) * t];
            let (a, b) = (lerp(t0), lerp(t1));
            // Cut at every grid line the piece crosses; each interval lies
            // in the pixel of its midpoint.
            ts.clear();
            ts.extend([0.0, 1.0]);
            for axis in 0..2 {
                let (lo, hi) = (a[axis].min(b[axis]), a[axis].max(b[axis]));
                if hi <= lo {
                    continue;
                }
                let origin = if axis == 0 { -cam.half_w } else { -cam.half_h };
                let first = ((lo - origin) / d).ceil() as i64;
                let last = ((hi - origin) / d).floor() as i64;
                for k in first..=last {
                    let g = origin + d * k as f64;
                    ts.push((g - a[axis]) / (b[axis] - a[axis]));
                }
            }
            ts.sort_by(f64::total_cmp);
            let at2 = |t: f64| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
            for w in ts.windows(2) {
                let (s0, s1) = (w[0].clamp(0.0, 1.0), w[1].clamp(0.0, 1.0));
                if s1 <= s0 {
                    continue;
                }
                let m = at2(0.5 * (s0 + s1));
                cut.push((
                    cam.cell(m[0], m[1]),
                    Piece {
                        edge: i,
                        a: at2(s0),
                        b: at2(s1),
                    },
                ));
            }
        }
        cut.sort_by_key(|c| c.0);
        let pixels = (cam.width * cam.height) as usize;
        let mut start = vec![0u32; pixels + 1];
        for (p, _) in &cut {
            start[*p as usize + 1] += 1;
        }
        for p in 0..pixels {
            start[p + 1] += start[p];
        }
        let pieces: Vec<Piece> = cut.into_iter().map(|c| c.1).collect();
        let along_rows = (0..pixels)
            .map(|p| {
                let own = &pieces[start[p] as usize..start[p + 1] as usize];
                let (mut across_rows, mut across_columns) = (0.0, 0.0);
                for c in own {
                    across_rows += (c.b[1] - c.a[1]).abs();
                    across_columns += (c.b[0] - c.a[0]).abs();
                }
                across_rows >= across_columns
            })
            .collect();
        PixelEdges {
            start,
            pieces,
            along_rows,
        }
    }

    /// Whether the warp at pixel `p` slides along the image's rows (else
    /// along its columns); rows for a pixel without pieces.
    #[inline]
    pub fn along_rows(&self, p: u32) -> bool {
        self.along_rows.get(p as usize).copied().unwrap_or(true)
    }

    /// The pieces inside pixel `p`.
    #[inline]
    pub fn of(&self, p: u32) -> &[Piece] {
        let p = p as usize;
        match (self.start.get(p), self.start.get(p + 1)) {
            (Some(&a), Some(&b)) => &self.pieces[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Number of pieces over the image.
    pub fn len(&self) -> usize {
        self.pieces.len()
    }

    /// Whether no edge is seen.
    pub fn is_empty(&self) -> bool {
        self.pieces.is_empty()
    }

    /// A point drawn uniformly by image-plane length on the pieces of pixel
    /// `p` clipped to `rect`: the piece's edge, the point, the unit
    /// direction of the piece on the image plane and the pieces' total
    /// clipped length; `None` if no piece enters `rect`.
    #[inline]
    pub fn sample(&self, p: u32, rect: &Rect, u: f64) -> Option<(u32, [f64; 2], [f64; 2], f64)> {
        let pieces = self.of(p);
        let clipped = |c: &Piece| {
            clip(c.a, c.b, rect).map(|(t0, t1)| {
                let len = (c.b[0] - c.a[0]).hypot(c.b[1] - c.a[1]);
                (t0, t1, len * (t1 - t0), len)
            })
        };
        let total: f64 = pieces.iter().filter_map(clipped).map(|c| c.2).sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let mut left = (u * total).min(total * (1.0 - f64::EPSILON));
        let mut last = None;
        for c in pieces {
            let Some((t0, t1, l, len)) = clipped(c) else {
                continue;
            };
            last = Some((c, t0, t1, len));
            if left < l {
                break;
            }
            left -= l;
        }
        let (c, t0, t1, len) = last?;
        let s = (t0 + left / len).clamp(t0, t1);
        let dir = [(c.b[0] - c.a[0]) / len, (c.b[1] - c.a[1]) / len];
        let point = [
            c.a[0] + (c.b[0] - c.a[0]) * s,
            c.a[1] + (c.b[1] - c.a[1]) * s,
        ];
        Some((c.edge, point, dir, total))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(width: u32, height: u32) -> Camera {
        Camera {
            position: DVec3::new(0.0, 0.0, 5.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_deg: 60.0,
            width,
            height,
        }
    }

    /// The strata of a pixel tile it, and the pixels tile the image.
    #[test]
    fn strata_tile_the_image() {
        let cam = camera(7, 5).frame();
        let mut area = 0.0;
        for p in 0..35 {
            for k in 0..9 {
                let r = cam.rect(PixelSample {
                    pixel: p,
                    stratum: k,
                    strata: 3,
                });
                assert!(r[0] >= -cam.half_w - 1e-12 && r[1] <= cam.half_w + 1e-12);
                assert!(r[2] >= -cam.half_h - 1e-12 && r[3] <= cam.half_h + 1e-12);
                area += (r[1] - r[0]) * (r[3] - r[2]);
                let c = cam.cell(0.5 * (r[0] + r[1]), 0.5 * (r[2] + r[3]));
                assert_eq!(c, p);
            }
        }
        let whole = 4.0 * cam.half_w * cam.half_h;
        assert!((area - whole).abs() < 1e-12 * whole);
        // Row 0 is at the top, column 0 at the left; r is to the right.
        let r = cam.rect(PixelSample {
            pixel: 0,
            stratum: 0,
            strata: 1,
        });
        assert!(r[0] < 0.0 && r[3] > 0.0);
        assert!((cam.r - DVec3::X).length() < 1e-12 && (cam.u - DVec3::Y).length() < 1e-12);
    }

    /// The cut pieces of an edge cover its projection exactly once.
    #[test]
    fn pieces_cover_the_projection() {
        let cam = camera(16, 12).frame();
        let edge = Edge {
            a: DVec3::new(-1.3, -0.7, 0.2),
            b: DVec3::new(1.1, 0.9, -0.4),
            faces: [0, crate::path::NO_PRIM],
            shape: 0,
        };
        let facts = super::super::edges::EdgeFacts {
            normals: [DVec3::Z; 2],
            always: true,
        };
        let pe = PixelEdges::new(&cam, &[edge], &[facts], [0u32].into_iter(), 1e-6);
        let project = |q: DVec3| {
            let v = q - cam.eye;
            let z = v.dot(cam.f);
            [v.dot(cam.r) / z, v.dot(cam.u) / z]
        };
        let (pa, pb) = (project(edge.a), project(edge.b));
        let whole = (pb[0] - pa[0]).hypot(pb[1] - pa[1]);
        let mut sum = 0.0;
        for p in 0..16 * 12 {
            for c in pe.of(p) {
                sum += (c.b[0] - c.a[0]).hypot(c.b[1] - c.a[1]);
                let m = [0.5 * (c.a[0] + c.b[0]), 0.5 * (c.a[1] + c.b[1])];
                assert_eq!(cam.cell(m[0], m[1]), p);
            }
        }
        assert!((sum - whole).abs() < 1e-12 * whole, "{sum} vs {whole}");
    }

    #[test]
    fn bad_cameras_are_named() {
        let mut c = camera(4, 4);
        assert!(c.problem().is_none());
        c.fov_deg = 180.0;
        assert!(c.problem().unwrap().contains("fov_deg"));
        let mut c = camera(0, 4);
        assert!(c.problem().unwrap().contains("width"));
        c = camera(4, 4);
        c.up = DVec3::Z;
        assert!(c.problem().unwrap().contains("up"));
        c = camera(4, 4);
        c.look_at = c.position;
        assert!(c.problem().unwrap().contains("look_at"));
    }
}
