//! Flatland behind the path core's traits: [`Plane`] implements
//! [`Geometry`] (rays through the scene's casters, the lobes of
//! [`lobe`](super::lobe), emitters drawn by length, the parameters'
//! motions); its discontinuities ([`Boundaries`](crate::path::Boundaries): corners and the warp) are
//! in [`boundaries`](super::boundaries). Book: chapter "Flatland: one
//! deformation, three estimators", section "One path core".
use super::geometry::{NO_SEGMENT, cross};
use super::lobe::FlatLobe;
use super::scene::{Phase, Scene, Sensor as FlatSensor};
use crate::path::deform::SlotSet;
use crate::path::media::Media;
use crate::path::{Coefficients, Geometry, Hit, MediumId, PixelSample, Prim, Sensor, Surface};
use crate::rng::PathRng;
use glam::DVec2;
use rand::RngExt;
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};

/// A flatland scene with the tables the derivative methods need.
#[derive(Debug, Clone)]
pub struct Plane {
    pub(super) scene: Arc<Scene>,
    /// Per corner (the scene's `corners()` order), its segments: the one it
    /// starts and the one it ends (`NO_SEGMENT` at a polyline's ends).
    pub(super) corner_segments: Vec<[u32; 2]>,
    /// Indices of the corners of moving shapes.
    pub(super) moving_corners: Vec<u32>,
    /// Per corner, the weight with which rendering's boundary term draws
    /// it: 1 at a polyline's end, `θ/π` at a corner turning by `θ` (the
    /// share of viewpoints from which it is a silhouette; two collinear
    /// faces of one surface have no jump at all).
    pub(super) corner_weight: Vec<f64>,
    /// Cumulative weights over all corners.
    pub(super) all_cdf: Vec<f64>,
    /// Per corner, the cumulative weight over its shape's corners up to it.
    pub(super) shape_cdf: Vec<f64>,
    /// Per shape, its corners `start..end` (empty for a transparent one).
    pub(super) shape_corners: Vec<(u32, u32)>,
    /// Per shape, the parameters that move it.
    pub(super) shape_params: Vec<SlotSet>,
    /// The media, for the walk.
    media: Media,
    /// The shapes some parameter moves whose corners weigh (> 0).
    pub(super) weighed_shapes: Vec<u32>,
    /// Every parameter's slot, and for that view the parameters with a
    /// component, the shapes among them and the last such shape.
    pub(super) all_params: (SlotSet, (usize, usize, Option<u32>)),
    /// The corners visible from an irradiance sensor in front of it, by
    /// angle from +x: the warp's knots there, the same for every path
    /// (found on first use: only the expectation method asks).
    sensor_knots: OnceLock<Vec<Knot>>,
    /// The expectation method's direction density at that sensor
    /// ([`super::sensor_gaps`]; found on first use).
    sensor_gaps: OnceLock<super::sensor_gaps::SensorGaps>,
    /// A line camera's corners (see [`Plane::camera_corner_list`]).
    camera_corners: OnceLock<Vec<(f64, u32)>>,
}

/// A line camera's frame: view axis `f`, image line direction `r`
/// (clockwise from `f`), half-width `half` of the image line at unit
/// distance, `width` pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LineCamera {
    /// View axis.
    pub f: DVec2,
    /// Image line direction (pixel 0 at `x = −half`).
    pub r: DVec2,
    /// `tan(fov / 2)`.
    pub half: f64,
    /// Pixels.
    pub width: u32,
}

impl LineCamera {
    /// The footprint `[x0, x1]` on the image line of the stratum of `s`
    /// (a pixel's `strata²` equal parts).
    pub fn rect(&self, s: PixelSample) -> (f64, f64) {
        let d = 2.0 * self.half / f64::from(self.width);
        let parts = f64::from(s.strata.max(1)).powi(2);
        let e = d / parts;
        let x0 = -self.half + d * f64::from(s.pixel) + e * f64::from(s.stratum);
        (x0, x0 + e)
    }
}

/// A knot of the warp: angle from the sampled direction, corner, shape.
pub(super) type Knot = (f64, DVec2, u32);

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
        let segments = scene.segments();
        // ANCHOR: corner_weight
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
        // ANCHOR_END: corner_weight
        let cdf = |ids: &mut dyn Iterator<Item = usize>| {
            let mut total = 0.0;
            ids.map(|i| {
                total += corner_weight[i];
                total
            })
            .collect::<Vec<f64>>()
        };
        let all_cdf = cdf(&mut (0..corner_weight.len()));
        let mut shape_corners = vec![(0u32, 0u32); scene.shapes().len()];
        for (i, c) in scene.corners().iter().enumerate() {
            let r = &mut shape_corners[c.1 as usize];
            if r.1 == 0 {
                r.0 = i as u32;
            }
            r.1 = i as u32 + 1;
        }
        let mut shape_cdf = Vec::with_capacity(corner_weight.len());
        for &(start, end) in &shape_corners {
            shape_cdf.extend(cdf(&mut (start as usize..end as usize)));
        }
        let mut shape_params = vec![SlotSet::EMPTY; scene.shapes().len()];
        for j in 0..params {
            shape_params[scene.parameter_shape(j) as usize].insert(j);
        }
        let weighed_shapes: Vec<u32> = (0..scene.shapes().len() as u32)
            .filter(|&k| {
                let (start, end) = shape_corners[k as usize];
                !shape_params[k as usize].is_empty()
                    && end > start
                    && shape_cdf[end as usize - 1] > 0.0
            })
            .collect();
        let media = Media::new(scene.shapes().iter().enumerate().map(|(k, s)| {
            let coefficients = s.medium.map(|m| Coefficients { ks: m.ks, ke: m.ke });
            (coefficients, &s.vertices[..], scene.parent_medium(k as u32))
        }));
        Plane {
            media,
            scene,
            corner_segments,
            moving_corners,
            corner_weight,
            all_cdf,
            shape_cdf,
            shape_corners,
            all_params: (
                SlotSet::first(params),
                weighed_shapes.iter().fold((0, 0, None), |(n, m, _), &k| {
                    (n + shape_params[k as usize].len(), m + 1, Some(k))
                }),
            ),
            shape_params,
            weighed_shapes,
            sensor_knots: OnceLock::new(),
            sensor_gaps: OnceLock::new(),
            camera_corners: OnceLock::new(),
        }
    }

    /// The total corner weight of shape `k` (0 for a transparent one).
    #[inline]
    pub(super) fn shape_weight(&self, k: u32) -> f64 {
        let (start, end) = self.shape_corners[k as usize];
        if end > start {
            self.shape_cdf[end as usize - 1]
        } else {
            0.0
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The line camera's frame, if the sensor is one.
    pub(super) fn line_camera(&self) -> Option<LineCamera> {
        match self.scene.sensor() {
            FlatSensor::Camera {
                direction,
                fov_deg,
                width,
                ..
            } => Some(LineCamera {
                f: direction,
                r: DVec2::new(direction.y, -direction.x),
                half: (0.5 * fov_deg.to_radians()).tan(),
                width,
            }),
            _ => None,
        }
    }

    /// The moving shapes' corners in front of a line camera that can be
    /// discontinuities (weight > 0), by their place on its image line:
    /// `(x, corner)`, sorted (built on first use).
    pub(super) fn camera_corner_list(&self) -> &[(f64, u32)] {
        self.camera_corners.get_or_init(|| {
            let Some(cam) = self.line_camera() else {
                return Vec::new();
            };
            let eye = self.scene.sensor().point();
            let corners = self.scene.corners();
            let mut list: Vec<(f64, u32)> = self
                .moving_corners
                .iter()
                .filter(|&&i| self.corner_weight[i as usize] > 0.0)
                .filter_map(|&i| {
                    let r = corners[i as usize].0 - eye;
                    let z = r.dot(cam.f);
                    (z > 0.0).then(|| (r.dot(cam.r) / z, i))
                })
                .collect();
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            list
        })
    }

    /// The expectation method's direction density at the irradiance sensor.
    pub(super) fn sensor_gaps(&self) -> &super::sensor_gaps::SensorGaps {
        self.sensor_gaps.get_or_init(|| {
            super::sensor_gaps::SensorGaps::new(&self.scene, self.sensor_knot_list())
        })
    }

    /// The warp's knots at an irradiance sensor (see the field).
    pub(super) fn sensor_knot_list(&self) -> &[Knot] {
        self.sensor_knots.get_or_init(|| {
            let corners = self.scene.corners();
            sensor_corners(&self.scene)
                .into_iter()
                .map(|(angle, i)| (angle, corners[i].0, corners[i].1))
                .collect()
        })
    }
}

/// The corners an irradiance sensor (or a camera) sees in front of it, by
/// angle from +x: `(angle, index into scene.corners())`; none for a
/// radiance sensor.
pub(super) fn sensor_corners(scene: &Scene) -> Vec<(f64, usize)> {
    let Some((point, ahead)) = corners_ahead(scene) else {
        return Vec::new();
    };
    ahead
        .into_iter()
        .filter(|&(_, _, i)| scene.sees_corner(point, i, NO_SEGMENT))
        .map(|(angle, _, i)| (angle, i))
        .collect()
}

/// A corner in front of the sensor: `(angle from +x, distance, index into
/// scene.corners())`.
pub(super) type CornerAhead = (f64, f64, usize);

/// The sensor's point (a camera's position) and every corner in front of
/// it, hidden or not, by angle ([`CornerAhead`]); `None` for a radiance
/// sensor.
pub(super) fn corners_ahead(scene: &Scene) -> Option<(DVec2, Vec<CornerAhead>)> {
    let (point, normal) = match scene.sensor() {
        FlatSensor::Irradiance { point, normal } => (point, normal),
        FlatSensor::Camera {
            position,
            direction,
            ..
        } => (position, direction),
        FlatSensor::Radiance { .. } => return None,
    };
    let mut ahead: Vec<CornerAhead> = scene
        .corners()
        .iter()
        .enumerate()
        .filter(|(_, (q, _))| (*q - point).dot(normal) > 0.0)
        .map(|(i, (q, _))| {
            let r = *q - point;
            (r.y.atan2(r.x), r.length(), i)
        })
        .collect();
    ahead.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some((point, ahead))
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
            FlatSensor::Camera { position, .. } => Sensor::Camera { point: position },
        }
    }
    fn pixel_lobe(&self, s: PixelSample) -> Option<FlatLobe> {
        let cam = self.line_camera()?;
        let (x0, x1) = cam.rect(s);
        Some(FlatLobe::Pixel {
            f: cam.f,
            r: cam.r,
            x0,
            x1,
            pixel: s.pixel,
        })
    }
    fn image(&self) -> Option<(u32, u32)> {
        self.line_camera().map(|c| (c.width, 1))
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
    fn solid(&self, p: Prim) -> bool {
        let s = self.scene.shape_of(p);
        s.closed && s.surface != Surface::Transparent
    }
    #[inline]
    fn media(&self) -> &Media {
        &self.media
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
    fn emitter_point(&self, rng: &mut PathRng) -> Option<(DVec2, Prim)> {
        self.scene.emitter_point(rng.random())
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
    fn sensor_mixture(&self) -> bool {
        self.sensor_gaps().share > 0.0
    }
    #[inline]
    fn sensor_mixture_sample(&self, lobe: &FlatLobe, rng: &mut PathRng) -> DVec2 {
        self.sensor_gaps().sample(lobe, rng)
    }
    #[inline]
    fn sensor_mixture_pdf(&self, lobe: &FlatLobe, w: DVec2) -> f64 {
        self.sensor_gaps().pdf(lobe, w)
    }
    #[inline]
    fn spin(&self, j: usize) -> f64 {
        self.scene.parameters()[j].motion.spin()
    }
}
