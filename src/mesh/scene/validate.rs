//! Building a [`Scene`]: welding, checks, medium nesting.
//! (A first version: welding by exact position and closedness; the full
//! checks follow.)
use super::{Motion, Parameter, Scene, Sensor, Shape};
use crate::error::Error;
use glam::DVec3;
use std::collections::HashMap;

fn config<T>(msg: String) -> Result<T, Error> {
    Err(Error::Scene(msg))
}

/// Merges vertices at the same position; returns the welded mesh.
fn weld(shape: &mut Shape) {
    let mut index: HashMap<[u64; 3], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let map: Vec<u32> = shape
        .vertices
        .iter()
        .map(|v| {
            let key = [v.x, v.y, v.z].map(|c| (c + 0.0).to_bits());
            *index.entry(key).or_insert_with(|| {
                vertices.push(*v);
                (vertices.len() - 1) as u32
            })
        })
        .collect();
    for t in &mut shape.triangles {
        *t = t.map(|i| map[i as usize]);
    }
    shape.vertices = vertices;
}

/// Whether every edge is shared by exactly two triangles, once in each
/// direction.
fn closed(shape: &Shape) -> bool {
    let mut count: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &shape.triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry((a, b)).or_default() += 1;
        }
    }
    count
        .iter()
        .all(|(&(a, b), &n)| n == 1 && count.get(&(b, a)) == Some(&1))
}

/// Whether `p` is inside the closed mesh `s` (parity of crossings along a
/// fixed skew direction).
pub(super) fn inside(s: &Shape, p: DVec3) -> bool {
    let w = DVec3::new(0.5773, 0.5774, 0.5775).normalize();
    let mut n = 0;
    for i in 0..s.triangles.len() {
        let t = s.triangle(i);
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let q = w.cross(e2);
        let det = e1.dot(q);
        if det == 0.0 {
            continue;
        }
        let o = p - t[0];
        let u = o.dot(q) / det;
        let r = o.cross(e1);
        let v = w.dot(r) / det;
        let d = e2.dot(r) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && d > 0.0 {
            n += 1;
        }
    }
    n % 2 == 1
}

impl Scene {
    /// Validates and welds `shapes`, resolves `parameters`' pivots and axes.
    pub fn new(
        mut shapes: Vec<Shape>,
        mut parameters: Vec<Parameter>,
        sensor: Sensor,
    ) -> Result<Scene, Error> {
        for s in &mut shapes {
            weld(s);
        }
        let closed: Vec<bool> = shapes.iter().map(closed).collect();
        let mut parameter_shape = Vec::new();
        for p in &mut parameters {
            let Some(k) = shapes.iter().position(|s| s.name == p.shape) else {
                return config(format!("parameter {:?}: no shape {:?}", p.name, p.shape));
            };
            parameter_shape.push(k as u32);
            let c = shapes[k].centroid();
            p.motion = match p.motion {
                Motion::Rotate { axis, pivot } => Motion::Rotate {
                    axis: axis.normalize(),
                    pivot: Some(pivot.unwrap_or(c)),
                },
                Motion::Scale { pivot } => Motion::Scale {
                    pivot: Some(pivot.unwrap_or(c)),
                },
                m => m,
            };
        }
        let sensor = match sensor {
            Sensor::Radiance { point, direction } => Sensor::Radiance {
                point,
                direction: direction.normalize(),
            },
            Sensor::Irradiance { point, normal } => Sensor::Irradiance {
                point,
                normal: normal.normalize(),
            },
        };
        let (mut lo, mut hi) = (sensor.point(), sensor.point());
        for s in &shapes {
            for v in &s.vertices {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        let size = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        // The innermost medium mesh around a point: the smallest (by box)
        // closed medium mesh containing it.
        let around = |p: DVec3, except: usize| -> Option<u32> {
            let mut best: Option<(f64, u32)> = None;
            for (k, s) in shapes.iter().enumerate() {
                if k == except || s.medium.is_none() || !closed[k] || !inside(s, p) {
                    continue;
                }
                let extent = s
                    .vertices
                    .iter()
                    .fold(0.0f64, |m, v| m.max((*v - s.vertices[0]).length()));
                if best.is_none_or(|b| extent < b.0) {
                    best = Some((extent, k as u32));
                }
            }
            best.map(|b| b.1)
        };
        let parent = (0..shapes.len())
            .map(|k| around(shapes[k].vertices[0], k))
            .collect();
        let sensor_medium = around(sensor.point(), usize::MAX);
        Ok(Scene {
            shapes,
            parameters,
            parameter_shape,
            sensor,
            closed,
            parent,
            sensor_medium,
            size,
        })
    }
}
