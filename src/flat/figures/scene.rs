//! The scenes drawn: shapes coloured by surface (lamps, black absorbers,
//! Lambertian reflectors, media shaded), the sensor, twenty backward paths
//! of the intensity estimator (the first twenty of a run's first chunk,
//! traced with [`radiance_observed`]), the path vertices on moving
//! boundaries (where rendering and transport collect medium-boundary and
//! surface terms) and the corners of moving shapes in the sensor's view
//! (where rendering's corner terms and the expectation method's warp knots
//! sit), ringed in vermillion where the first opaque surface the sensor
//! sees changes across the corner's direction (a silhouette: the corner
//! term can be nonzero) and in yellow where it does not (a reflex or front
//! corner: the term vanishes). A radiance sensor (radiance.toml) looks
//! along one direction and has no corners of its own; the line camera
//! (camera_line.toml) is drawn with its paths fanned across its field of
//! view, without corner rings.
//! One panel per shipped scene ([`SCENES`]), in two figures ([`FIGURES`]).
//!
//! The drawing helpers ([`shapes`], [`sensor`], [`ViewBox`]) serve the warp
//! figure too.
use super::{FigureOptions, load};
use crate::error::Error;
use crate::flat::geometry::{NO_SEGMENT, perp};
use crate::flat::lobe::cosine_direction;
use crate::flat::space::Plane;
use crate::flat::{Scene, Sensor, Surface};
use crate::path::intensity::radiance_observed;
use crate::path::walk::Ray;
use crate::plot::{Figure, Panel, Series};
use crate::rng;
use glam::DVec2;
use serde::Serialize;
use std::path::PathBuf;

/// The scenes drawn, one panel each.
pub const SCENES: [&str; 11] = [
    "occluder",
    "inverse_occluder",
    "design_reflector",
    "polygon_occluder",
    "absorbing_slab",
    "fog",
    "reflector",
    "three_shapes",
    "radiance",
    "submerged",
    "camera_line",
];

/// The two figures: their file names and the scenes each draws (every
/// scene of [`SCENES`] once): the scenes of opaque shapes only, then those
/// with a medium.
pub const FIGURES: [(&str, &[&str]); 2] = [
    (
        "flat_scene_opaque",
        &[
            "occluder",
            "polygon_occluder",
            "reflector",
            "camera_line",
            "inverse_occluder",
            "design_reflector",
        ],
    ),
    (
        "flat_scene_media",
        &[
            "absorbing_slab",
            "fog",
            "radiance",
            "submerged",
            "three_shapes",
        ],
    ),
];

/// What a scene shows, for its panel's title.
fn what(name: &str) -> &'static str {
    match name {
        "occluder" => "a segment shadows the lamp",
        "polygon_occluder" => "a non-convex Γ",
        "reflector" => "light after a bounce",
        "camera_line" => "a line camera",
        "inverse_occluder" => "fit to eight readings",
        "design_reflector" => "aim at a hidden receiver",
        "absorbing_slab" => "absorption only",
        "fog" => "a scattering polygon",
        "radiance" => "one line of sight",
        "submerged" => "shapes in a fog",
        "three_shapes" => "all three kinds",
        _ => "",
    }
}

/// Paths drawn per scene.
pub const PATHS: usize = 20;

/// Base of the seed salts of this figure (distinct from the other figures').
const SALT: u64 = 30_000_000;

/// Palette indices of the drawing.
mod colors {
    pub const EMITTER: usize = 4;
    pub const ABSORBER: usize = 6;
    pub const REFLECTOR: usize = 0;
    pub const MEDIUM: usize = 5;
    pub const SENSOR: usize = 1;
    pub const LIT: usize = 2;
    pub const DARK: usize = 3;
    pub const MARK: usize = 1;
    pub const STILL: usize = 7;
}

/// The region of the plane a drawing shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewBox {
    /// Lower-left corner.
    pub lo: DVec2,
    /// Upper-right corner.
    pub hi: DVec2,
}

impl ViewBox {
    /// The scene's shapes and sensor with a margin of `pad` times the scene
    /// size all round.
    pub fn of(scene: &Scene, pad: f64) -> ViewBox {
        let mut lo = scene.sensor().point();
        let mut hi = lo;
        for v in scene.shapes().iter().flat_map(|s| &s.vertices) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
        let m = DVec2::splat(pad * scene.size());
        ViewBox {
            lo: lo - m,
            hi: hi + m,
        }
    }

    /// Whether `p` lies inside (edges included).
    pub fn contains(&self, p: DVec2) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }

    /// The part of the segment `a → b` inside the box (Liang–Barsky), if any.
    pub fn clip(&self, a: DVec2, b: DVec2) -> Option<(DVec2, DVec2)> {
        let d = b - a;
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, q) in [
            (-d.x, a.x - self.lo.x),
            (d.x, self.hi.x - a.x),
            (-d.y, a.y - self.lo.y),
            (d.y, self.hi.y - a.y),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else if p < 0.0 {
                t0 = t0.max(q / p);
            } else {
                t1 = t1.min(q / p);
            }
        }
        (t0 <= t1).then(|| (a + t0 * d, a + t1 * d))
    }

    /// The polyline through `points` cut to the box: its pieces inside.
    pub fn clip_polyline(&self, points: &[DVec2]) -> Vec<Vec<(f64, f64)>> {
        let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut open = false;
        for w in points.windows(2) {
            match self.clip(w[0], w[1]) {
                Some((a, b)) => {
                    if !open || a != w[0] {
                        pieces.push(vec![(a.x, a.y)]);
                    }
                    if let Some(piece) = pieces.last_mut() {
                        piece.push((b.x, b.y));
                    }
                    open = b == w[1];
                }
                None => open = false,
            }
        }
        pieces
    }

    /// Sets `panel`'s ranges to the box.
    pub fn frame(&self, panel: &mut Panel) {
        panel.x_range = Some((self.lo.x, self.hi.x));
        panel.y_range = Some((self.lo.y, self.hi.y));
    }
}

/// `(x, y)` of a point.
fn xy(p: DVec2) -> (f64, f64) {
    (p.x, p.y)
}

/// Colour, opacity and legend label of a surface.
fn style(surface: Surface) -> (usize, f64, &'static str) {
    match surface {
        Surface::Emitter { .. } => (colors::EMITTER, 1.0, "lamp (emitter)"),
        Surface::Absorber => (colors::ABSORBER, 1.0, "absorber"),
        Surface::Reflector { .. } => (colors::REFLECTOR, 1.0, "reflector"),
        Surface::Transparent => (colors::MEDIUM, 0.35, "medium"),
    }
}

/// The shapes of `scene` as filled polygons, unlabelled: closed shapes as
/// themselves, open ones as strips `width` wide along each segment; lamps
/// orange, absorbers black, reflectors blue, media sky blue and translucent.
pub fn shapes(scene: &Scene, width: f64) -> Vec<Series> {
    let mut series = Vec::new();
    for s in scene.shapes() {
        let (color, opacity, _) = style(s.surface);
        if s.closed {
            let v = s.vertices.iter().map(|&p| xy(p)).collect();
            series.push(Series::polygon("", color, v, opacity));
        } else {
            for seg in s.segments() {
                let n = 0.5 * width * seg.left_normal();
                let v = vec![xy(seg.a - n), xy(seg.b - n), xy(seg.b + n), xy(seg.a + n)];
                series.push(Series::polygon("", color, v, opacity));
            }
        }
    }
    series
}

/// Legend entries (empty series) for the surface kinds of `surfaces`, each
/// once, in the order lamp, absorber, reflector, medium.
pub fn surface_legend(surfaces: impl IntoIterator<Item = Surface>) -> Vec<Series> {
    let mut kinds: Vec<Surface> = Vec::new();
    for s in surfaces {
        if !kinds
            .iter()
            .any(|k| std::mem::discriminant(k) == std::mem::discriminant(&s))
        {
            kinds.push(s);
        }
    }
    let rank = |s: &Surface| match s {
        Surface::Emitter { .. } => 0,
        Surface::Absorber => 1,
        Surface::Reflector { .. } => 2,
        Surface::Transparent => 3,
    };
    kinds.sort_by_key(rank);
    kinds
        .into_iter()
        .map(|s| {
            let (color, opacity, label) = style(s);
            Series::polygon(label, color, vec![], opacity)
        })
        .collect()
}

/// Every surface kind once (for a legend shared by several scenes).
pub const ALL_SURFACES: [Surface; 4] = [
    Surface::Emitter { radiance: 1.0 },
    Surface::Absorber,
    Surface::Reflector { albedo: 1.0 },
    Surface::Transparent,
];

/// The sensor: a half disc of radius `r` on its normal (irradiance) or a
/// wedge along its direction (radiance).
pub fn sensor(scene: &Scene, r: f64, label: &str) -> Series {
    let (x, n) = match scene.sensor() {
        Sensor::Irradiance { point, normal } => (point, normal),
        Sensor::Radiance { point, direction }
        | Sensor::Camera {
            position: point,
            direction,
            ..
        } => (point, direction),
    };
    let t = perp(n);
    let v: Vec<(f64, f64)> = match scene.sensor() {
        Sensor::Irradiance { .. } => (0..=16)
            .map(|k| {
                let a = std::f64::consts::PI * f64::from(k) / 16.0;
                xy(x + r * (a.cos() * t + a.sin() * n))
            })
            .collect(),
        Sensor::Radiance { .. } | Sensor::Camera { .. } => vec![
            xy(x + 0.6 * r * t),
            xy(x + 2.0 * r * n),
            xy(x - 0.6 * r * t),
        ],
    };
    Series::polygon(label, colors::SENSOR, v, 1.0)
}

/// One sampled path: its vertices from the sensor on, and what it brought.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathRecord {
    /// Vertices `[x, y]`, the sensor first; the last leg of a path that
    /// leaves the scene ends two scene sizes out.
    pub vertices: Vec<[f64; 2]>,
    /// The path's one-sample estimate of the sensor's reading.
    pub weight: f64,
}

/// A corner of a moving shape in the sensor's view.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CornerRecord {
    /// Where.
    pub point: [f64; 2],
    /// The shape it belongs to.
    pub shape: String,
    /// Whether the first opaque surface the sensor sees changes across its
    /// direction (a silhouette: rendering's corner term can be nonzero).
    pub jump: bool,
}

/// The numbers behind one panel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneRecord {
    /// Scene file name (without `.toml`).
    pub scene: String,
    /// The sampled paths.
    pub paths: Vec<PathRecord>,
    /// Path vertices on moving boundaries.
    pub moving_hits: Vec<[f64; 2]>,
    /// Corners of moving shapes in the sensor's view.
    pub corners: Vec<CornerRecord>,
}

/// The first [`PATHS`] paths of the intensity estimator's first chunk with
/// seed `seed` (an irradiance sensor draws its direction first, as the
/// estimator does; a camera's paths fan out evenly across its field of
/// view, one direction each, instead of one pixel's).
pub fn sample_paths(scene: &Scene, seed: u64) -> Vec<PathRecord> {
    let mut rng = rng::stream(seed, 0);
    let x = scene.sensor().point();
    let plane = Plane::new(std::sync::Arc::new(scene.clone()));
    (0..PATHS)
        .map(|i| {
            let (w, factor) = match scene.sensor() {
                Sensor::Radiance { direction, .. } => (direction, 1.0),
                // A camera's paths fan out evenly across its field of view.
                Sensor::Camera {
                    direction, fov_deg, ..
                } => {
                    let u = (i as f64 + 0.5) / PATHS as f64 - 0.5;
                    (
                        DVec2::from_angle(u * fov_deg.to_radians()).rotate(direction),
                        1.0,
                    )
                }
                Sensor::Irradiance { normal, .. } => (cosine_direction(normal, &mut rng), 2.0),
            };
            let mut vertices = vec![[x.x, x.y]];
            let weight = factor
                * radiance_observed(
                    &plane,
                    &mut rng,
                    Ray {
                        x,
                        w,
                        medium: scene.sensor_medium(),
                        skip: NO_SEGMENT,
                    },
                    |v| vertices.push([v.x, v.y]),
                );
            PathRecord { vertices, weight }
        })
        .collect()
}

/// Whether shape `k` moves with some parameter.
fn moving(scene: &Scene, k: u32) -> bool {
    (0..scene.parameters().len()).any(|j| scene.parameter_shape(j) == k)
}

/// The path vertices lying on a segment of a moving shape.
fn moving_hits(scene: &Scene, paths: &[PathRecord]) -> Vec<[f64; 2]> {
    let tol = crate::path::tolerance::ON_SURFACE * scene.size();
    let segments: Vec<_> = (0..scene.segments().len() as u32)
        .filter(|&i| moving(scene, scene.owner(i)))
        .map(|i| scene.segments()[i as usize])
        .collect();
    paths
        .iter()
        .flat_map(|p| p.vertices.iter().skip(1))
        .filter(|v| {
            let p = DVec2::new(v[0], v[1]);
            segments.iter().any(|s| s.distance(p) <= tol)
        })
        .copied()
        .collect()
}

/// The first opaque surface along the ray from `x` along `w` (through any
/// media): its shape and distance.
fn first_opaque(scene: &Scene, x: DVec2, w: DVec2) -> Option<(u32, f64)> {
    let (mut t, mut skip) = (0.0, NO_SEGMENT);
    loop {
        let h = scene.cast(x + t * w, w, skip)?;
        t += h.t;
        let k = scene.owner(h.segment);
        if scene.shapes()[k as usize].surface.is_opaque() {
            return Some((k, t));
        }
        skip = h.segment;
    }
}

/// The corners of moving opaque shapes that an irradiance sensor sees in
/// front of it, each with whether the first opaque surface seen changes
/// across its direction (a silhouette, where the corner term of the
/// directional integral can be nonzero). A radiance sensor integrates over
/// no directions: none.
pub fn visible_corners(scene: &Scene) -> Vec<CornerRecord> {
    let Sensor::Irradiance { point: x, normal } = scene.sensor() else {
        return Vec::new();
    };
    scene
        .corners()
        .iter()
        .filter(|&&(q, k)| {
            moving(scene, k) && (q - x).dot(normal) > 0.0 && scene.visible(x, q, NO_SEGMENT)
        })
        .map(|&(q, k)| {
            let w = (q - x).normalize();
            let eps = 1e-6;
            let (a, b) = (
                first_opaque(scene, x, DVec2::from_angle(eps).rotate(w)),
                first_opaque(scene, x, DVec2::from_angle(-eps).rotate(w)),
            );
            let jump = match (a, b) {
                (Some((ka, ta)), Some((kb, tb))) => {
                    ka != kb || (ta - tb).abs() > 1e-3 * scene.size()
                }
                (None, None) => false,
                _ => true,
            };
            CornerRecord {
                point: [q.x, q.y],
                shape: scene.shapes()[k as usize].name.clone(),
                jump,
            }
        })
        .collect()
}

/// One scene's panel and its numbers.
fn panel(name: &str, scene: &Scene, seed: u64) -> (Panel, SceneRecord) {
    let view = ViewBox::of(scene, 0.08);
    let size = scene.size();
    let paths = sample_paths(scene, seed);
    let hits = moving_hits(scene, &paths);
    let corners = visible_corners(scene);
    let mut series = shapes(scene, 0.025 * size);
    for p in &paths {
        let pts: Vec<DVec2> = p.vertices.iter().map(|v| DVec2::new(v[0], v[1])).collect();
        let color = if p.weight > 0.0 {
            colors::LIT
        } else {
            colors::DARK
        };
        for piece in view.clip_polyline(&pts) {
            series.push(Series::thin("", color, piece));
        }
    }
    series.push(sensor(scene, 0.04 * size, ""));
    series.push(Series::points(
        "",
        colors::MARK,
        hits.iter().map(|v| (v[0], v[1], 0.0)).collect(),
    ));
    for (jump, color) in [(false, colors::STILL), (true, colors::MARK)] {
        series.push(Series::circles(
            "",
            color,
            corners
                .iter()
                .filter(|c| c.jump == jump)
                .map(|c| (c.point[0], c.point[1]))
                .collect(),
        ));
    }
    let title = format!(
        "{name}: {} ({} parameter{})",
        what(name),
        scene.parameters().len(),
        if scene.parameters().len() == 1 {
            ""
        } else {
            "s"
        }
    );
    let mut panel = Panel {
        title,
        x_label: "x".into(),
        y_label: "y".into(),
        series,
        equal_aspect: true,
        ..Panel::default()
    };
    view.frame(&mut panel);
    let record = SceneRecord {
        scene: name.into(),
        paths,
        moving_hits: hits,
        corners,
    };
    (panel, record)
}

/// The scenes drawn with their paths and boundary points, one panel per
/// scene, in two figures ([`FIGURES`]: opaque shapes only, 2 by 2 under a
/// shared legend; scenes with a medium, 2 per row, the legend last).
/// Writes `flat_scene_opaque.{png,svg}`, `flat_scene_media.{png,svg}` and
/// `flat_scene.json` (the paths, the hits and the corners of every scene of
/// [`SCENES`]). Samples only 20 paths per scene: the effort does not change
/// it.
pub fn scene(opts: &FigureOptions) -> Result<Vec<PathBuf>, Error> {
    let mut drawn = Vec::new();
    for (i, name) in SCENES.iter().enumerate() {
        let scene = load(name)?;
        let (p, r) = panel(name, &scene, opts.seed.wrapping_add(SALT + i as u64));
        drawn.push((scene, p, r));
    }
    let mut written = Vec::new();
    for (file, names) in FIGURES {
        let of = |name: &&str| SCENES.iter().position(|s| s == name).map(|i| &drawn[i]);
        let group: Vec<_> = names.iter().filter_map(of).collect();
        let surfaces = group
            .iter()
            .flat_map(|(scene, _, _)| scene.shapes().iter().map(|s| s.surface));
        let legend = legend(surfaces);
        let mut panels: Vec<Panel> = group.iter().map(|(_, p, _)| p.clone()).collect();
        let mut figure = if panels.len() % 2 == 1 {
            // An odd count leaves a slot for the legend.
            panels.push(Panel {
                title: format!("{PATHS} backward paths per scene"),
                series: legend,
                legend_only: true,
                ..Panel::default()
            });
            Figure::new(panels, 2)
        } else {
            let mut figure = Figure::new(panels, 2);
            figure.legend = legend;
            figure
        };
        figure.panel_size = (500, 500);
        written.extend(figure.save(&opts.out, file)?);
    }
    let records: Vec<SceneRecord> = drawn.into_iter().map(|(_, _, r)| r).collect();
    written.push(opts.write_json("flat_scene", &records)?);
    Ok(written)
}

/// The legend shared by a figure's panels: the kinds of `surfaces`, the
/// sensor, the paths and the marks.
fn legend(surfaces: impl IntoIterator<Item = Surface>) -> Vec<Series> {
    let mut series = surface_legend(surfaces);
    series.extend([
        Series::polygon("sensor", colors::SENSOR, vec![], 1.0),
        Series::thin(
            "path carrying light (lamp hit or connection)",
            colors::LIT,
            vec![],
        ),
        Series::thin("path carrying none", colors::DARK, vec![]),
        Series::legend_dot("path meets a moving boundary", colors::MARK),
        Series::circles("moving silhouette corner in view", colors::MARK, vec![]),
        Series::circles("other moving corner in view", colors::STILL, vec![]),
    ]);
    series
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_scene_is_drawn() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
        let mut shipped: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| {
                let path = e.ok()?.path();
                (path.extension()? == "toml")
                    .then(|| path.file_stem()?.to_str().map(String::from))?
            })
            .collect();
        shipped.sort();
        let mut drawn: Vec<String> = SCENES.iter().map(|s| s.to_string()).collect();
        drawn.sort();
        assert_eq!(shipped, drawn);
    }

    #[test]
    fn clipping_keeps_the_inside() {
        let view = ViewBox {
            lo: DVec2::ZERO,
            hi: DVec2::ONE,
        };
        let (a, b) = view
            .clip(DVec2::new(0.5, 0.5), DVec2::new(2.5, 0.5))
            .unwrap();
        assert_eq!((a, b), (DVec2::new(0.5, 0.5), DVec2::new(1.0, 0.5)));
        assert!(
            view.clip(DVec2::new(2.0, 2.0), DVec2::new(3.0, 2.0))
                .is_none()
        );
        // In, out, back in: two pieces.
        let pieces = view.clip_polyline(&[
            DVec2::new(0.5, 0.5),
            DVec2::new(0.5, 2.0),
            DVec2::new(0.8, 0.2),
        ]);
        assert_eq!(pieces.len(), 2);
        assert_eq!(pieces[0], vec![(0.5, 0.5), (0.5, 1.0)]);
    }

    #[test]
    fn corners_in_view() {
        // The occluder's two ends are silhouettes (the right end hides part
        // of the lamp, the left one the sky beyond it).
        let c = visible_corners(&load("occluder").unwrap());
        assert_eq!(c.len(), 2);
        assert!(c.iter().all(|c| c.jump));
        // The Γ's reflex corner and its leg's lower-left corner are in view
        // but no silhouette; its two outer corners and the lamp's ends are.
        let c = visible_corners(&load("polygon_occluder").unwrap());
        let jumps: Vec<[f64; 2]> = c.iter().filter(|c| c.jump).map(|c| c.point).collect();
        let still: Vec<[f64; 2]> = c.iter().filter(|c| !c.jump).map(|c| c.point).collect();
        assert_eq!(still, vec![[0.05, 0.9], [0.05, 1.25]]);
        assert_eq!(jumps.len(), 4);
        // A radiance sensor has none.
        assert!(visible_corners(&load("radiance").unwrap()).is_empty());
    }

    #[test]
    fn paths_start_at_the_sensor_and_are_reproducible() {
        let scene = load("fog").unwrap();
        let a = sample_paths(&scene, 3);
        assert_eq!(a.len(), PATHS);
        assert!(
            a.iter()
                .all(|p| p.vertices[0] == [0.0, 0.0] && p.vertices.len() >= 2)
        );
        assert_eq!(a, sample_paths(&scene, 3));
    }
}
