//! The expectation method's warp field at the sensor of
//! `polygon_occluder.toml`: the angular velocity `V_j(φ)` with which the
//! sampled direction `φ` moves when `π_j` changes, for every parameter
//! ([`sensor_warp`]). It is piecewise linear in `φ`, with knots at the
//! corners the sensor sees (where it equals the corner's own angular
//! velocity, so that no visibility edge moves relative to the directions)
//! and at the horizons (where it is pinned to the sensor's frame). The
//! scene panels draw it as arrows `t V_j(φ) η⊥` at the ends of a fan of
//! rays, `t` the ray's length: how the ray's end point moves.
use super::scene::{ViewBox, sensor, shapes, surface_legend};
use super::{FigureOptions, REFERENCE_COLOR, load, parameter};
use crate::error::Error;
use crate::figures_common::save;
use crate::flat::Scene;
use crate::flat::geometry::{NO_SEGMENT, direction, perp};
use crate::flat::methods::sensor_warp;
use crate::flat::space::Plane;
use crate::plot::{Figure, Panel, Series};
use glam::DVec2;
use serde::Serialize;
use std::path::PathBuf;

/// The scene.
pub const SCENE: &str = "polygon_occluder";

/// Directions of the `V_j(φ)` curves over the sensor's half circle.
pub const CURVE_POINTS: usize = 1441;

/// Rays of each fan.
pub const FAN: usize = 36;

/// The parameters drawn as arrow fields, one scene panel each.
pub const ARROWS: [&str; 3] = ["gamma_tx", "gamma_rotate", "lamp_tx"];

/// The legend's label of the arrows.
const ARROWS_LABEL: &str = "t·V(φ)·η⊥ where the ray hits (in its parameter's colour)";

/// A corner the sensor sees in front of it: a knot of the field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Knot {
    /// Its direction from the sensor, degrees from +x.
    pub phi_deg: f64,
    /// Where.
    pub point: [f64; 2],
    /// The shape it belongs to.
    pub shape: String,
}

/// One parameter's field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Field {
    /// Parameter name.
    pub parameter: String,
    /// `V_j(φ)` at `phi_deg` (radians per unit of the parameter).
    pub v: Vec<f64>,
}

/// The numbers behind `flat_warp.{png,svg}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Warp {
    /// Scene file name (without `.toml`).
    pub scene: String,
    /// Directions, degrees from +x.
    pub phi_deg: Vec<f64>,
    /// One field per parameter, in declaration order.
    pub fields: Vec<Field>,
    /// The knots.
    pub knots: Vec<Knot>,
}

/// The sensor's point and normal (the scene has an irradiance sensor).
fn frame(scene: &Scene) -> (DVec2, f64) {
    let x = scene.sensor().point();
    let phi_n = match scene.sensor() {
        crate::flat::Sensor::Irradiance { normal, .. } => normal.y.atan2(normal.x),
        crate::flat::Sensor::Radiance { direction, .. }
        | crate::flat::Sensor::Camera { direction, .. } => direction.y.atan2(direction.x),
    };
    (x, phi_n)
}

/// Every opaque corner the sensor sees in front of it.
fn knots(scene: &Scene) -> Vec<Knot> {
    let (x, phi_n) = frame(scene);
    let mut knots: Vec<Knot> = scene
        .corners()
        .iter()
        .filter(|&&(q, _)| (q - x).dot(direction(phi_n)) > 0.0 && scene.visible(x, q, NO_SEGMENT))
        .map(|&(q, k)| Knot {
            phi_deg: (q - x).y.atan2((q - x).x).to_degrees(),
            point: [q.x, q.y],
            shape: scene.shapes()[k as usize].name.clone(),
        })
        .collect();
    knots.sort_by(|a, b| a.phi_deg.total_cmp(&b.phi_deg));
    knots
}

/// The panel of `V_j(φ)` for every parameter, knots dashed.
fn curves_panel(warp: &Warp) -> Panel {
    let (lo, hi) = warp
        .fields
        .iter()
        .flat_map(|f| &f.v)
        .fold((0.0f64, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let pad = 0.05 * (hi - lo).max(1e-9);
    let mut series = Vec::new();
    for (i, k) in warp.knots.iter().enumerate() {
        series.push(Series::dashed(
            if i == 0 { "visible corner (knot)" } else { "" },
            REFERENCE_COLOR,
            vec![(k.phi_deg, lo - pad), (k.phi_deg, hi + pad)],
        ));
    }
    for (i, f) in warp.fields.iter().enumerate() {
        let xy = warp
            .phi_deg
            .iter()
            .copied()
            .zip(f.v.iter().copied())
            .collect();
        series.push(Series::line(&f.parameter, i, xy));
    }
    Panel {
        title: format!(
            "{}.toml: the warp V(φ) of the sensor's directions",
            warp.scene
        ),
        x_label: "φ (degrees from +x)".into(),
        y_label: "V (rad per unit of the parameter)".into(),
        series,
        x_range: Some((0.0, 180.0)),
        ..Panel::default()
    }
}

/// A polyline drawing an arrow from `a` to `b` with a head `head` long.
fn arrow(a: DVec2, b: DVec2, head: f64) -> Vec<(f64, f64)> {
    let d = b - a;
    let len = d.length();
    let mut v = vec![(a.x, a.y), (b.x, b.y)];
    if len > 0.0 {
        let u = d / len;
        let h = head.min(0.5 * len);
        for s in [1.0, -1.0] {
            let p = b - h * (0.9 * u + s * 0.45 * perp(u));
            v.extend([(p.x, p.y), (b.x, b.y)]);
        }
    }
    v
}

/// The scene with a fan of rays from the sensor and, at the end of each ray
/// that hits a shape (rays that hit nothing have no end to move), the arrow
/// `t V_j(φ) η⊥` of parameter `j` (colour `color`), scaled so the longest is
/// a tenth of the scene.
fn arrows_panel(plane: &Plane, j: usize, color: usize, knots: &[Knot]) -> Panel {
    let scene: &Scene = plane.scene();
    let view = ViewBox::of(scene, 0.08);
    let size = scene.size();
    let (x, phi_n) = frame(scene);
    let mut series = shapes(scene, 0.025 * size);
    // Per ray: its end (the first hit, or where it leaves the view) and the
    // arrow there, `None` for a ray that hits nothing (no end moves).
    let ends: Vec<(DVec2, Option<DVec2>)> = (0..FAN)
        .map(|i| {
            let phi = phi_n - std::f64::consts::FRAC_PI_2
                + std::f64::consts::PI * (i as f64 + 0.5) / FAN as f64;
            let w = direction(phi);
            match scene.cast(x, w, NO_SEGMENT) {
                Some(h) => (
                    x + h.t * w,
                    Some(h.t * sensor_warp(plane, phi)[j] * perp(w)),
                ),
                None => {
                    let t = view
                        .clip(x, x + 4.0 * size * w)
                        .map_or(0.0, |(_, b)| (b - x).length());
                    (x + t * w, None)
                }
            }
        })
        .collect();
    let longest = ends
        .iter()
        .filter_map(|e| e.1.map(DVec2::length))
        .fold(0.0, f64::max);
    let scale = if longest > 0.0 {
        0.1 * size / longest
    } else {
        0.0
    };
    for (i, &(end, _)) in ends.iter().enumerate() {
        let label = if i == 0 { "ray of the fan" } else { "" };
        series.push(Series::thin(label, 5, vec![(x.x, x.y), (end.x, end.y)]));
    }
    let p = &scene.parameters()[j];
    for (i, k) in knots.iter().filter(|k| k.shape == p.shape).enumerate() {
        let q = DVec2::new(k.point[0], k.point[1]);
        let label = if i == 0 {
            "ray to a corner it moves"
        } else {
            ""
        };
        series.push(Series::dashed(
            label,
            REFERENCE_COLOR,
            vec![(x.x, x.y), (q.x, q.y)],
        ));
    }
    let mut labelled = false;
    for &(end, v) in &ends {
        let Some(v) = v else { continue };
        if v.length() * scale > 1e-4 * size {
            let label = if labelled { "" } else { ARROWS_LABEL };
            labelled = true;
            series.push(Series::line(
                label,
                color,
                arrow(end, end + scale * v, 0.025 * size),
            ));
        }
    }
    series.extend(surface_legend(scene.shapes().iter().map(|s| s.surface)));
    series.push(sensor(scene, 0.04 * size, "sensor"));
    let mut panel = Panel {
        title: format!("{}: how the rays' ends move (arrows ×{scale:.2})", p.name),
        x_label: "x".into(),
        y_label: "y".into(),
        series,
        equal_aspect: true,
        ..Panel::default()
    };
    // Room for the arrows at the view's edge.
    let pad = DVec2::splat(0.15 * size);
    ViewBox {
        lo: view.lo - pad,
        hi: view.hi + pad,
    }
    .frame(&mut panel);
    panel
}

/// The warp field of [`SCENE`]: `V_j(φ)` for every parameter with the
/// knots, and arrow fields for the parameters of [`ARROWS`] (2 × 2 panels).
/// Writes `flat_warp.{png,svg}` and `flat_warp.json`. Samples nothing: the
/// seed and effort do not change it.
pub fn warp(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let scene = load(SCENE)?;
    let (_, phi_n) = frame(&scene);
    let lo = phi_n - std::f64::consts::FRAC_PI_2;
    let phis: Vec<f64> = (0..CURVE_POINTS)
        .map(|i| lo + std::f64::consts::PI * i as f64 / (CURVE_POINTS - 1) as f64)
        .collect();
    let plane = Plane::new(std::sync::Arc::new(scene.clone()));
    let per_phi: Vec<Vec<f64>> = phis.iter().map(|&phi| sensor_warp(&plane, phi)).collect();
    let fields = scene
        .parameters()
        .iter()
        .enumerate()
        .map(|(j, p)| Field {
            parameter: p.name.clone(),
            v: per_phi.iter().map(|v| v[j]).collect(),
        })
        .collect();
    let warp = Warp {
        scene: SCENE.into(),
        phi_deg: phis.iter().map(|p| p.to_degrees()).collect(),
        fields,
        knots: knots(&scene),
    };
    let mut panels = vec![curves_panel(&warp)];
    for name in ARROWS {
        let j = parameter(&scene, name)?;
        panels.push(arrows_panel(&plane, j, j, &warp.knots));
    }
    // One legend across the top: the panels' keys, the same in every
    // panel, and the parameters' colours, which the arrows take.
    let mut figure = Figure::new(panels, 2).share_legend();
    for s in &mut figure.legend {
        if s.label == ARROWS_LABEL {
            s.color = REFERENCE_COLOR;
        }
    }
    figure.panel_size = (720, 560);
    save(opts, "flat_warp", &figure, &warp)
}
