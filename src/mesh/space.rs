//! 3D scenes behind the path core's traits: [`Space`] implements
//! [`Geometry`] (rays through a triangle BVH, the lobes of
//! [`lobe`](super::lobe), emitters drawn by area, the meshes' motions); its
//! discontinuities (silhouette and crease edges,
//! [`Boundaries`](crate::path::Boundaries)) are in
//! [`boundaries`](super::boundaries). Book: chapter "Three dimensions".
use super::bvh::TriangleBvh;
use super::camera::{CameraFrame, PixelEdges};
pub use super::edges::Edge;
use super::edges::{EdgeFacts, EdgeTree};
use super::lobe::SpaceLobe;
use super::poles::{MAX_FIELDS, PoleRule};
use super::scene::{Scene, Sensor as SceneSensor};
use super::sensor_view::SensorView;
use crate::path::deform::SlotSet;
use crate::path::thin_media::chord_bound;
use crate::path::{
    Coefficients, Geometry, Hit, MediumId, NO_PRIM, PixelSample, Prim, Sensor, Surface,
};
use crate::rng::PathRng;
use glam::DVec3;
use rand::RngExt;
use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

/// Most edges in a tree for which the edge itself is also drawn by the
/// length of its arc with a lamp behind (every edge's arc and lamp parts
/// per draw); larger trees draw by the tree alone.
pub(super) const LAMP_EDGES: usize = 64;

/// Most edge or vertex touches of media boundaries one cast passes
/// (`Space::touches_only`) before it reports the next hit as it is.
const MAX_TOUCHES: usize = 8;

/// A 3D scene with the tables the estimators need.
#[derive(Debug, Clone)]
pub struct Space {
    pub(super) scene: Arc<Scene>,
    /// Every triangle, meshes in order.
    pub(super) tris: Vec<[DVec3; 3]>,
    /// Mesh of each triangle.
    pub(super) owner: Vec<u32>,
    /// Unit normal of each triangle, outward for closed meshes.
    pub(super) normals: Vec<DVec3>,
    pub(super) caster: TriangleBvh,
    /// Opaque triangles only (visibility), the map from a triangle to its
    /// index there.
    opaque: TriangleBvh,
    opaque_index: Vec<u32>,
    /// Emitting triangles with their cumulative area, and the total.
    pub(super) emitters: Vec<(Prim, f64)>,
    emitter_area: f64,
    /// The edges and their hierarchies, built on first use: only the
    /// derivative methods ask (not the intensity estimator, nor the
    /// displaced scenes of finite differences).
    edge_tables: OnceLock<EdgeTables>,
    /// A camera sensor's frame, and the moving edges each pixel sees (built
    /// on first use, by the derivative methods).
    pub(super) camera: Option<CameraFrame>,
    pixel_edges: OnceLock<PixelEdges>,
    /// What the sensor's point sees of the edges (built on first use, by
    /// the expectation method).
    sensor_view: OnceLock<SensorView>,
    /// The lamp overlaps (`Space::lamp_overlaps`) of the moving edges and
    /// of all edges seen from the sensor's point, where every path starts
    /// (built on first use).
    pub(super) sensor_lamps: [OnceLock<([f64; LAMP_EDGES], f64)>; 2],
    /// The same per mesh, for its stratum (`Space::edge_strata`).
    pub(super) sensor_shape_lamps: Vec<OnceLock<([f64; LAMP_EDGES], f64)>>,
    /// Per mesh, the parameters that move it.
    pub(super) shape_params: Vec<SlotSet>,
    /// Per mesh holding a medium, a bound on its chords ([`chord_bound`]);
    /// 0 for the others (the walk asks only of media).
    chords: Vec<f64>,
    /// The warp's pole rules (distinct, at most `MAX_FIELDS`), and per
    /// parameter the index of its rule.
    pub(super) pole_rules: Vec<PoleRule>,
    pub(super) slot_field: Vec<u8>,
    /// Per pole rule, the bounding spheres of the meshes its parameters
    /// move; last, those of every moving mesh (a camera's one family).
    pub(super) field_bounds: Vec<Vec<Sphere>>,
}

/// A bounding sphere: centre and radius.
pub(super) type Sphere = (DVec3, f64);

/// A sphere around `points` (their box's centre, the farthest from it),
/// padded against rounding.
fn bounding_sphere(points: &[DVec3]) -> Sphere {
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &q| (lo.min(q), hi.max(q)),
    );
    let c = 0.5 * (lo + hi);
    let r = points.iter().map(|&q| q.distance(c)).fold(0.0, f64::max);
    use crate::path::tolerance::{COORDINATE_PAD, CULL_PAD};
    (
        c,
        r * (1.0 + CULL_PAD) + COORDINATE_PAD * c.abs().max_element().max(r),
    )
}

/// The edges of the opaque meshes that can be discontinuities, with what
/// the boundary terms and the warp need of them.
#[derive(Debug, Clone)]
pub(super) struct EdgeTables {
    /// The edges.
    pub(super) edges: Vec<Edge>,
    /// Per edge, the weight with which the boundary terms draw it: its
    /// length times `θ/π` (θ the angle between its faces' normals; 1 for an
    /// open edge): the share of viewpoints from which it is a silhouette.
    pub(super) edge_weight: Vec<f64>,
    /// Per edge, its faces' normals and whether it is a discontinuity
    /// from everywhere.
    pub(super) edge_facts: Vec<EdgeFacts>,
    /// The hierarchy over all edges (the warp's knots).
    pub(super) all_edges: EdgeTree,
    /// The lamps' edges (of emitting meshes) when they are at most
    /// [`LAMP_SET`] and the other edges at most [`LAMP_EDGES`]: every
    /// boundary term takes each of them
    /// ([`Space::lamp_edge_points`]): those of moving lamps, then all of
    /// them (indexed by `all`). Empty otherwise.
    pub(super) lamp_set: [Vec<u32>; 2],
    /// The hierarchies the boundary points are drawn from: over all edges
    /// and over those of moving meshes, without the lamp set's.
    pub(super) all_drawn: EdgeTree,
    pub(super) moving_drawn: EdgeTree,
    /// Per mesh, the hierarchy of its edges without the lamp set's (empty
    /// for a mesh no parameter moves): a parameter's stratum of the
    /// boundary term (`Space::edge_strata`).
    pub(super) shape_drawn: Vec<EdgeTree>,
    /// Per mesh, its number of edges.
    pub(super) shape_edges: Vec<u32>,
}

/// Most lamp edges that every boundary term takes each of, rather than
/// drawing one among all edges.
pub(super) const LAMP_SET: usize = 16;

impl Space {
    /// The tables of `scene`.
    pub fn new(scene: Arc<Scene>) -> Space {
        let mut tris = Vec::new();
        let mut owner = Vec::new();
        let mut normals = Vec::new();
        for (k, s) in scene.shapes().iter().enumerate() {
            for i in 0..s.triangles.len() {
                let t = s.triangle(i);
                tris.push(t);
                owner.push(k as u32);
                normals.push((t[1] - t[0]).cross(t[2] - t[0]).normalize());
            }
        }
        let mut opaque_tris = Vec::new();
        let opaque_index = (0..tris.len())
            .map(|i| {
                if scene.shapes()[owner[i] as usize].surface.is_opaque() {
                    opaque_tris.push(tris[i]);
                    (opaque_tris.len() - 1) as u32
                } else {
                    NO_PRIM
                }
            })
            .collect();
        let mut emitter_area = 0.0;
        let emitters = (0..tris.len())
            .filter(|&i| {
                matches!(scene.shapes()[owner[i] as usize].surface, Surface::Emitter { radiance } if radiance > 0.0)
            })
            .map(|i| {
                let t = tris[i];
                emitter_area += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
                (i as Prim, emitter_area)
            })
            .collect();
        let mut pole_rules = vec![PoleRule::Hashed];
        let mut slot_field = scene
            .parameters()
            .iter()
            .map(|p| {
                let rule = PoleRule::of(&p.motion);
                match pole_rules.iter().position(|r| *r == rule) {
                    Some(i) => i as u8,
                    None if pole_rules.len() < MAX_FIELDS => {
                        pole_rules.push(rule);
                        (pole_rules.len() - 1) as u8
                    }
                    None => 0,
                }
            })
            .collect::<Vec<u8>>();
        // The pseudo-random family only if some parameter uses it.
        if !slot_field.contains(&0) && pole_rules.len() > 1 {
            pole_rules.remove(0);
            for i in &mut slot_field {
                *i -= 1;
            }
        }
        let camera = match scene.sensor() {
            SceneSensor::Camera(c) => Some(c.frame()),
            _ => None,
        };
        let mut field_bounds = vec![Vec::new(); pole_rules.len() + 1];
        for (j, &f) in slot_field.iter().enumerate() {
            let k = scene.parameter_shape(j) as usize;
            let sphere = bounding_sphere(&scene.shapes()[k].vertices);
            for f in [f as usize, pole_rules.len()] {
                if !field_bounds[f].contains(&sphere) {
                    field_bounds[f].push(sphere);
                }
            }
        }
        let mut shape_params = vec![SlotSet::EMPTY; scene.shapes().len()];
        for j in 0..scene.parameters().len() {
            shape_params[scene.parameter_shape(j) as usize].insert(j);
        }
        Space {
            chords: scene
                .shapes()
                .iter()
                .map(|s| s.medium.map_or(0.0, |_| chord_bound(&s.vertices)))
                .collect(),
            caster: TriangleBvh::new(tris.clone()),
            opaque: TriangleBvh::new(opaque_tris),
            opaque_index,
            scene,
            tris,
            owner,
            normals,
            emitters,
            emitter_area,
            edge_tables: OnceLock::new(),
            camera,
            pixel_edges: OnceLock::new(),
            sensor_view: OnceLock::new(),
            sensor_lamps: [OnceLock::new(), OnceLock::new()],
            sensor_shape_lamps: (0..shape_params.len()).map(|_| OnceLock::new()).collect(),
            shape_params,
            pole_rules,
            slot_field,
            field_bounds,
        }
    }

    /// The scene.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The edges that can be discontinuities.
    pub fn edges(&self) -> &[Edge] {
        &self.edge_tables().edges
    }

    /// The edge tables, built on first use.
    #[inline]
    pub(super) fn edge_tables(&self) -> &EdgeTables {
        self.edge_tables
            .get_or_init(|| EdgeTables::new(&self.scene, &self.normals))
    }

    /// What the sensor's point (a probe's point, a camera's pinhole) sees
    /// of the edges, built on first use.
    #[inline]
    pub(super) fn sensor_view(&self) -> &SensorView {
        self.sensor_view.get_or_init(|| {
            let t = self.edge_tables();
            let opaque: Vec<(Prim, [DVec3; 3])> = (0..self.tris.len())
                .filter(|&i| {
                    self.scene.shapes()[self.owner[i] as usize]
                        .surface
                        .is_opaque()
                })
                .map(|i| (i as Prim, self.tris[i]))
                .collect();
            let point = self.scene.sensor().point();
            // The poles of the warp's fibres at the point: fixed there.
            let mut poles: Vec<DVec3> = self.pole_rules.iter().map(|r| r.at(point)).collect();
            if let Some(cam) = &self.camera {
                poles.extend([cam.r, cam.u]);
            }
            SensorView::new(point, &t.edges, &t.edge_facts, &t.edge_weight, &opaque)
                .with_fibres(&t.edges, poles)
        })
    }

    /// The moving meshes' edges each camera pixel sees, built on first use
    /// (empty without a camera).
    #[inline]
    pub(super) fn pixel_edges(&self) -> &PixelEdges {
        self.pixel_edges.get_or_init(|| match &self.camera {
            None => PixelEdges::default(),
            Some(cam) => {
                let t = self.edge_tables();
                let params = self.scene.parameters().len();
                let moving = |k: u32| (0..params).any(|j| self.scene.parameter_shape(j) == k);
                let ids = (0..t.edges.len() as u32).filter(|&i| moving(t.edges[i as usize].shape));
                PixelEdges::new(
                    cam,
                    &t.edges,
                    &t.edge_facts,
                    ids,
                    crate::path::tolerance::ON_SURFACE * self.scene.size(),
                )
            }
        })
    }

    /// Total area of the emitters.
    pub fn emitter_area(&self) -> f64 {
        self.emitter_area
    }
}

impl EdgeTables {
    /// The edges of `scene`'s opaque meshes (`normals`: per triangle, in
    /// [`Space`]'s order), their weights and facts, and their hierarchies.
    fn new(scene: &Scene, normals: &[DVec3]) -> EdgeTables {
        let mut edges = Vec::new();
        let mut edge_weight = Vec::new();
        let mut first = 0u32;
        for (k, s) in scene.shapes().iter().enumerate() {
            let first_of_shape = first;
            first += s.triangles.len() as u32;
            let first = first_of_shape;
            if !s.surface.is_opaque() {
                continue;
            }
            // Edges by their vertex pair, in first-seen order (deterministic).
            let mut index: HashMap<(u32, u32), usize> = HashMap::new();
            let mut pairs: Vec<((u32, u32), [Prim; 2])> = Vec::new();
            for (i, t) in s.triangles.iter().enumerate() {
                for e in 0..3 {
                    let (a, b) = (t[e], t[(e + 1) % 3]);
                    let key = (a.min(b), a.max(b));
                    let p = first + i as u32;
                    match index.get(&key) {
                        Some(&m) => {
                            if pairs[m].1[1] == NO_PRIM {
                                pairs[m].1[1] = p;
                            }
                        }
                        None => {
                            index.insert(key, pairs.len());
                            pairs.push((key, [p, NO_PRIM]));
                        }
                    }
                }
            }
            for ((a, b), faces) in pairs {
                let (a, b) = (s.vertices[a as usize], s.vertices[b as usize]);
                let turn = if faces[1] == NO_PRIM {
                    1.0
                } else {
                    let (n0, n1) = (normals[faces[0] as usize], normals[faces[1] as usize]);
                    n0.cross(n1).length().atan2(n0.dot(n1)) / std::f64::consts::PI
                };
                let w = (b - a).length() * turn;
                if w > 0.0 {
                    edges.push(Edge {
                        a,
                        b,
                        faces,
                        shape: k as u32,
                    });
                    edge_weight.push(w);
                }
            }
        }
        let params = scene.parameters().len();
        let moving = |k: u32| (0..params).any(|j| scene.parameter_shape(j) == k);
        let edge_facts: Vec<EdgeFacts> = edges
            .iter()
            .map(|e| {
                let n0 = normals[e.faces[0] as usize];
                let open = e.faces[1] == NO_PRIM;
                let n1 = if open {
                    n0
                } else {
                    normals[e.faces[1] as usize]
                };
                let reflector = matches!(
                    scene.shapes()[e.shape as usize].surface,
                    Surface::Reflector { .. }
                );
                EdgeFacts {
                    normals: [n0, n1],
                    always: open || reflector,
                }
            })
            .collect();
        let all_ids: Vec<u32> = (0..edges.len() as u32).collect();
        let moving_ids: Vec<u32> = (0..edges.len() as u32)
            .filter(|&i| moving(edges[i as usize].shape))
            .collect();
        let lamp = |i: &u32| {
            matches!(scene.shapes()[edges[*i as usize].shape as usize].surface,
                Surface::Emitter { radiance } if radiance > 0.0)
        };
        let lamps: Vec<u32> = all_ids.iter().copied().filter(lamp).collect();
        // Only in small scenes, as the lamp parts (`LAMP_EDGES`): over a
        // large mesh every point costs casts through a deep hierarchy (on
        // mesh_perf's sphere of 10^5 triangles transport ran 2.8 times
        // slower per path for 1.7 times less variance).
        let lamp_set = if lamps.len() <= LAMP_SET && all_ids.len() - lamps.len() <= LAMP_EDGES {
            let moving_lamps = moving_ids.iter().copied().filter(lamp).collect();
            [moving_lamps, lamps]
        } else {
            [Vec::new(), Vec::new()]
        };
        let drawn = |ids: &[u32]| -> Vec<u32> {
            ids.iter()
                .copied()
                .filter(|i| !lamp_set[1].contains(i))
                .collect()
        };
        let all_drawn = EdgeTree::new(&edges, &edge_facts, &edge_weight, drawn(&all_ids));
        let moving_drawn = EdgeTree::new(&edges, &edge_facts, &edge_weight, drawn(&moving_ids));
        let shapes = scene.shapes().len();
        let shape_drawn = (0..shapes as u32)
            .map(|k| {
                let ids: Vec<u32> = moving_ids
                    .iter()
                    .copied()
                    .filter(|&i| edges[i as usize].shape == k)
                    .collect();
                EdgeTree::new(&edges, &edge_facts, &edge_weight, drawn(&ids))
            })
            .collect();
        let mut shape_edges = vec![0u32; shapes];
        for e in &edges {
            shape_edges[e.shape as usize] += 1;
        }
        let all_edges = EdgeTree::new(&edges, &edge_facts, &edge_weight, all_ids);
        EdgeTables {
            shape_drawn,
            shape_edges,
            edges,
            edge_weight,
            edge_facts,
            all_edges,
            lamp_set,
            all_drawn,
            moving_drawn,
        }
    }
}

impl Geometry for Space {
    type V = DVec3;
    type Lobe = SpaceLobe;

    #[inline]
    fn size(&self) -> f64 {
        self.scene.size()
    }
    #[inline]
    fn sensor(&self) -> Sensor<DVec3> {
        match self.scene.sensor() {
            SceneSensor::Radiance { point, direction } => Sensor::Radiance { point, direction },
            SceneSensor::Irradiance { point, normal } => Sensor::Irradiance { point, normal },
            SceneSensor::Camera(c) => Sensor::Camera { point: c.position },
        }
    }
    fn pixel_lobe(&self, s: PixelSample) -> Option<SpaceLobe> {
        let cam = self.camera.as_ref()?;
        Some(SpaceLobe::Pixel {
            frame: [cam.f, cam.r, cam.u],
            rect: cam.rect(s),
            pixel: s.pixel,
        })
    }
    fn image(&self) -> Option<(u32, u32)> {
        self.camera.map(|c| (c.width, c.height))
    }
    #[inline]
    fn sensor_medium(&self) -> MediumId {
        self.scene.sensor_medium()
    }
    #[inline]
    fn cast(&self, x: DVec3, w: DVec3, skip: Prim) -> Option<Hit> {
        // A medium's boundary only touched at an edge or a vertex is passed
        // (`touch`), a few times at most.
        let (mut from, mut skip, mut before, mut touches) = (x, skip, 0.0, 0);
        loop {
            let (t, prim) = self.caster.closest_hit(from, w, f64::INFINITY, skip)?;
            if touches == MAX_TOUCHES
                || self.surface(prim) != Surface::Transparent
                || !self.touches_only(from, w, prim, t)
            {
                return Some(Hit {
                    t: before + t,
                    prim,
                });
            }
            before += t;
            from += w * t;
            skip = prim;
            touches += 1;
        }
    }
    #[inline]
    fn visible(&self, x: DVec3, y: DVec3, skip: Prim) -> bool {
        let d = y - x;
        let len = d.length();
        let skip = if skip == NO_PRIM {
            NO_PRIM
        } else {
            self.opaque_index[skip as usize]
        };
        !self.opaque.any_hit(
            x,
            d / len,
            len * (1.0 - crate::path::tolerance::SHORT_OF_END),
            skip,
        )
    }
    #[inline]
    fn shape(&self, p: Prim) -> u32 {
        self.owner[p as usize]
    }
    #[inline]
    fn surface(&self, p: Prim) -> Surface {
        self.scene.shapes()[self.owner[p as usize] as usize].surface
    }
    #[inline]
    fn normal(&self, p: Prim, _y: DVec3) -> DVec3 {
        self.normals[p as usize]
    }
    #[inline]
    fn nudge(&self, y: DVec3) -> f64 {
        // A thousand times the casters' floor at y (`bvh::ROUNDING_ULPS`
        // ulps of its largest coordinate): a nested path's first hit on
        // the surface it left is then skipped only at grazing angles.
        // Within 70 sizes of the origin this is 10⁻⁹ of the size.
        let floor = super::bvh::ROUNDING_ULPS * f64::EPSILON * y.abs().max_element();
        (crate::path::tolerance::NUDGE * self.scene.size()).max(1e3 * floor)
    }
    #[inline]
    fn solid(&self, p: Prim) -> bool {
        self.scene.is_solid(self.owner[p as usize])
    }
    #[inline]
    fn coefficients(&self, m: MediumId) -> Option<Coefficients> {
        self.scene
            .medium(m)
            .map(|m| Coefficients { ks: m.ks, ke: m.ke })
    }
    #[inline]
    fn medium_chord(&self, m: MediumId) -> f64 {
        m.map_or(f64::INFINITY, |k| self.chords[k as usize])
    }
    #[inline]
    fn crossed(&self, m: MediumId, k: u32) -> MediumId {
        if m == Some(k) {
            self.scene.parent_medium(k)
        } else {
            Some(k)
        }
    }
    #[inline]
    fn cosine_lobe(&self, n: DVec3, c: f64) -> SpaceLobe {
        SpaceLobe::Cosine { n, c }
    }
    #[inline]
    fn phase_lobe(&self, m: MediumId, w: DVec3) -> SpaceLobe {
        SpaceLobe::Phase {
            g: self.scene.medium(m).map_or(0.0, |m| m.g),
            w_in: w,
        }
    }
    /// A point drawn uniformly by area on the emitters: the triangle by a
    /// binary search in the cumulative areas, the point by folding the unit
    /// square.
    #[inline]
    fn emitter_point(&self, rng: &mut PathRng) -> Option<(DVec3, Prim)> {
        let (&(_, total), _) = self.emitters.split_last()?;
        let s = rng.random::<f64>() * total;
        let i = self
            .emitters
            .partition_point(|e| e.1 <= s)
            .min(self.emitters.len() - 1);
        let p = self.emitters[i].0;
        let t = &self.tris[p as usize];
        let (r1, r2): (f64, f64) = (rng.random(), rng.random());
        let (b0, b1) = if r1 + r2 > 1.0 {
            (1.0 - r1, 1.0 - r2)
        } else {
            (r1, r2)
        };
        Some((t[0] + b0 * (t[1] - t[0]) + b1 * (t[2] - t[0]), p))
    }
    /// `r² / (|cos θ_e| A)` for a point drawn by area on emitters of total
    /// area `A`.
    #[inline]
    fn light_pdf(&self, x: DVec3, y: DVec3, p: Prim) -> f64 {
        let d = y - x;
        let r2 = d.length_squared();
        let c = (d / r2.sqrt()).dot(self.normals[p as usize]).abs();
        if c > 0.0 {
            r2 / (c * self.emitter_area)
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
    fn velocity(&self, j: usize, q: DVec3) -> DVec3 {
        self.scene.parameters()[j].motion.velocity(q)
    }
    #[inline]
    fn spin(&self, j: usize) -> DVec3 {
        self.scene.parameters()[j].motion.spin()
    }
}
