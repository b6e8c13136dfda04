//! 3D scenes behind the path core's traits: [`Space`] implements
//! [`Geometry`] (rays through a triangle BVH, the lobes of
//! [`lobe`](super::lobe), emitters drawn by area, the meshes' motions); its
//! discontinuities (silhouette and crease edges,
//! [`Boundaries`](crate::path::Boundaries)) are in
//! [`boundaries`](super::boundaries). Book: chapter "Three dimensions".
use super::bvh::TriangleBvh;
use super::camera::{CameraFrame, PixelEdges};
use super::edge_sampler::{EdgeSampler, EdgeTables};
pub use super::edges::Edge;
use super::lobe::SpaceLobe;
use super::part::MeshPart;
use super::poles::PoleTable;
use super::scene::{Scene, Sensor as SceneSensor};
use super::sensor_view::SensorView;
use crate::path::deform::SlotSet;
use crate::path::media::Media;
use crate::path::{
    Coefficients, Geometry, Hit, MediumId, NO_PRIM, PixelSample, Prim, Sensor, Surface,
};
use crate::rng::PathRng;
use glam::DVec3;
use rand::RngExt;
use std::sync::Arc;

/// Most edge or vertex touches of media boundaries one cast passes
/// (`Space::touches_only`) before it reports the next hit as it is.
const MAX_TOUCHES: usize = 8;

/// Ray casting against several meshes, each through its own
/// [`TriangleBvh`], triangles numbered as [`Space`] numbers them (meshes in
/// order): exactly the answers of one caster over all the triangles, since
/// each mesh's tree answers as a scan of its triangles and a later mesh is
/// asked only for hits strictly nearer than the best so far (a tie stays
/// with the lower index, as in one scan).
#[derive(Debug, Clone)]
pub(super) struct MeshCaster {
    /// The meshes cast against, with the index of their first triangle.
    parts: Vec<(Arc<MeshPart>, Prim)>,
}

impl MeshCaster {
    /// A caster over the meshes `pick` keeps.
    fn new(parts: &[Arc<MeshPart>], pick: impl Fn(usize) -> bool) -> MeshCaster {
        let mut first = 0;
        let mut chosen = Vec::new();
        for (k, p) in parts.iter().enumerate() {
            if pick(k) && p.len() > 0 {
                chosen.push((p.clone(), first));
            }
            first += p.len();
        }
        MeshCaster { parts: chosen }
    }

    /// `skip` in `part`'s numbering (`NO_PRIM` if it is not there).
    #[inline(always)]
    fn local(part: &MeshPart, first: Prim, skip: Prim) -> Prim {
        let i = skip.wrapping_sub(first);
        if i < part.len() { i } else { NO_PRIM }
    }

    /// [`TriangleBvh::closest_hit`](super::bvh::TriangleBvh::closest_hit)
    /// over all the meshes.
    #[inline]
    pub(super) fn closest_hit(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        skip: Prim,
    ) -> Option<(f64, Prim)> {
        let ray = TriangleBvh::ray(origin, dir);
        let mut best = None;
        let mut t_max = t_max;
        for (part, first) in &self.parts {
            let skip = Self::local(part, *first, skip);
            if let Some((t, i)) = part.bvh.closest_hit_along(&ray, origin, dir, t_max, skip) {
                t_max = t;
                best = Some((t, first + i));
            }
        }
        best
    }

    /// [`TriangleBvh::any_hit`](super::bvh::TriangleBvh::any_hit) over all
    /// the meshes.
    #[inline]
    pub(super) fn any_hit(&self, origin: DVec3, dir: DVec3, t_max: f64, skip: Prim) -> bool {
        let ray = TriangleBvh::ray(origin, dir);
        self.parts.iter().any(|(part, first)| {
            let skip = Self::local(part, *first, skip);
            part.bvh.any_hit_along(&ray, origin, dir, t_max, skip)
        })
    }
}

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
    /// The meshes' own tables, in order.
    pub(super) parts: Vec<Arc<MeshPart>>,
    /// Every mesh's caster, and the opaque meshes' (visibility).
    pub(super) caster: MeshCaster,
    pub(super) opaque: MeshCaster,
    /// Emitting triangles with their cumulative area, and the total.
    pub(super) emitters: Vec<(Prim, f64)>,
    emitter_area: f64,
    /// A camera sensor's frame.
    pub(super) camera: Option<CameraFrame>,
    /// The edges, and what the derivative methods build of them on first
    /// use.
    pub(super) sampler: EdgeSampler,
    /// Per mesh, the parameters that move it.
    pub(super) shape_params: Vec<SlotSet>,
    /// The media, for the walk.
    media: Media,
    /// The warp's fibre families.
    pub(super) poles: PoleTable,
}

impl Space {
    /// The tables of `scene`, assembled from its meshes' own (built on
    /// first use and shared by the scenes that hold a mesh unmoved).
    pub fn new(scene: Arc<Scene>) -> Space {
        let parts: Vec<Arc<MeshPart>> = (0..scene.shapes().len()).map(|k| scene.part(k)).collect();
        let total: usize = parts.iter().map(|p| p.tris.len()).sum();
        let mut tris = Vec::with_capacity(total);
        let mut owner = Vec::with_capacity(total);
        let mut normals = Vec::with_capacity(total);
        for (k, p) in parts.iter().enumerate() {
            tris.extend_from_slice(&p.tris);
            normals.extend_from_slice(&p.normals);
            owner.extend(std::iter::repeat_n(k as u32, p.tris.len()));
        }
        let opaque = |k: usize| scene.shapes()[k].surface.is_opaque();
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
        let camera = match scene.sensor() {
            SceneSensor::Camera(c) => Some(c.frame()),
            _ => None,
        };
        let poles = PoleTable::new(&scene);
        let mut shape_params = vec![SlotSet::EMPTY; scene.shapes().len()];
        for j in 0..scene.parameters().len() {
            shape_params[scene.parameter_shape(j) as usize].insert(j);
        }
        Space {
            media: Media::new(scene.shapes().iter().enumerate().map(|(k, s)| {
                let coefficients = s.medium.map(|m| Coefficients { ks: m.ks, ke: m.ke });
                (coefficients, &s.vertices[..], scene.parent_medium(k as u32))
            })),
            caster: MeshCaster::new(&parts, |_| true),
            opaque: MeshCaster::new(&parts, opaque),
            parts,
            scene,
            tris,
            owner,
            normals,
            emitters,
            emitter_area,
            camera,
            sampler: EdgeSampler::new(shape_params.len()),
            shape_params,
            poles,
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

    /// The edge tables, built on first use and shared by the scenes that
    /// differ from this one in their sensor only.
    #[inline]
    pub(super) fn edge_tables(&self) -> &EdgeTables {
        self.scene
            .edge_tables(|| EdgeTables::new(&self.scene, &self.parts))
    }

    /// What the sensor's point (a probe's point, a camera's pinhole) sees
    /// of the edges, built on first use.
    #[inline]
    pub(super) fn sensor_view(&self) -> &SensorView {
        self.sampler.sensor_view.get_or_init(|| {
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
            let mut poles: Vec<DVec3> = self.poles.rules.iter().map(|r| r.at(point)).collect();
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
        self.sampler.pixel_edges.get_or_init(|| match &self.camera {
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
    fn media(&self) -> &Media {
        &self.media
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
