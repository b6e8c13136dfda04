//! The differentiated path core that flatland and 3D scenes share.
//!
//! One event loop ([`walk`]) samples backward paths from a sensor: free
//! paths in homogeneous media (absorption carried as a weight), surface
//! events (emitters, black absorbers, Lambertian reflectors, transparent
//! medium boundaries), next-event estimation with multiple importance
//! sampling at every scattering vertex, Russian roulette. It is generic over
//! two small traits:
//!
//! - [`Geometry`]: what differs between the plane and space: the vector and
//!   direction types, ray casting, the medium lookup, lobe and phase
//!   sampling with the log-density's derivative, emitter sampling, and how
//!   parameters move material points and turn frames;
//! - [`Boundaries`]: where the integrand over directions jumps (2D: the
//!   corners of opaque shapes; 3D: silhouette edges) and the expectation
//!   method's warp built on them.
//!
//! The methods are [`Hooks`](walk::Hooks) the loop calls at its events, one file each,
//! beside their derivation in the book: [`intensity`] (no hooks: the loop
//! alone), [`rendering`] (Leibniz and corner terms, double randomisation),
//! [`expectation`] (stretched free paths and the warp), [`transport`]
//! (Eulerian sources coupled to the radiance gradient). Their shared
//! bookkeeping of the path's deformation (vertex and direction velocities,
//! the running score) is in [`deform`]. Book: chapters "Flatland" and
//! "Flatland: one deformation, three estimators".
pub mod deform;
pub mod derivative_walk;
pub mod estimator;
pub mod expectation;
pub mod intensity;
pub mod media;
pub mod nested;
pub mod record;
pub mod rendering;
pub mod thin_media;
pub mod tolerance;
pub mod transport;
pub mod walk;

use crate::rng::PathRng;
use glam::{DVec2, DVec3};
use std::ops::{Add, Mul, Neg, Sub};

/// What happens to light arriving at a surface, in the plane as in space.
/// (Flatland's scene files read and write it through their own file form.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface {
    /// Two-sided Lambertian emitter of uniform radiance; absorbs what arrives.
    Emitter {
        /// Emitted radiance (≥ 0).
        radiance: f64,
    },
    /// Black: absorbs everything.
    Absorber,
    /// Two-sided Lambertian reflector.
    Reflector {
        /// Albedo in `[0, 1]`.
        albedo: f64,
    },
    /// An index-matched interface: the boundary of a medium.
    Transparent,
}

impl Surface {
    /// Whether the surface stops rays (all but [`Surface::Transparent`]).
    pub fn is_opaque(&self) -> bool {
        !matches!(self, Surface::Transparent)
    }
}

/// The vector type of a scene's space: points, velocities, directions and a
/// direction's velocity (a vector tangent to the circle or the sphere).
pub trait Vector:
    Copy
    + PartialEq
    + Send
    + Sync
    + std::fmt::Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Neg<Output = Self>
    + Mul<f64, Output = Self>
{
    /// The zero vector.
    const ZERO: Self;
    /// The rate at which a frame turns: an angle rate in the plane, an
    /// angular-velocity vector in space.
    type Spin: Copy + PartialEq + std::fmt::Debug + Send + Sync;
    /// A frame that does not turn.
    const STILL: Self::Spin;
    /// Number of coordinates.
    const DIM: usize;
    /// `1 / ∫ (η·n)⁺ dη` over the directions: a Lambertian reflector of
    /// albedo ρ has the lobe `ρ · LAMBERT · (η·n)⁺` (1/2 in the plane, 1/π
    /// in space).
    const LAMBERT: f64;
    /// The unit vector along coordinate axis `i`.
    fn axis(i: usize) -> Self;
    /// Scalar product.
    fn dot(self, o: Self) -> f64;
    /// Euclidean length.
    fn length(self) -> f64;
    /// The velocity of the unit direction `w` carried by a frame turning at
    /// `spin`.
    fn turn(spin: Self::Spin, w: Self) -> Self;
    /// The turn rate of a frame that carries the unit direction `w` at
    /// velocity `wd` (the smallest rotation doing so).
    fn spin_of(w: Self, wd: Self) -> Self::Spin;
}

impl Vector for DVec2 {
    const ZERO: Self = DVec2::ZERO;
    type Spin = f64;
    const STILL: f64 = 0.0;
    const DIM: usize = 2;
    const LAMBERT: f64 = 0.5;
    #[inline]
    fn axis(i: usize) -> Self {
        [DVec2::X, DVec2::Y][i]
    }
    #[inline]
    fn dot(self, o: Self) -> f64 {
        DVec2::dot(self, o)
    }
    #[inline]
    fn length(self) -> f64 {
        DVec2::length(self)
    }
    #[inline]
    fn turn(spin: f64, w: Self) -> Self {
        spin * w.perp()
    }
    #[inline]
    fn spin_of(w: Self, wd: Self) -> f64 {
        w.perp_dot(wd)
    }
}

impl Vector for DVec3 {
    const ZERO: Self = DVec3::ZERO;
    type Spin = DVec3;
    const STILL: DVec3 = DVec3::ZERO;
    const DIM: usize = 3;
    const LAMBERT: f64 = std::f64::consts::FRAC_1_PI;
    #[inline]
    fn axis(i: usize) -> Self {
        [DVec3::X, DVec3::Y, DVec3::Z][i]
    }
    #[inline]
    fn dot(self, o: Self) -> f64 {
        DVec3::dot(self, o)
    }
    #[inline]
    fn length(self) -> f64 {
        DVec3::length(self)
    }
    #[inline]
    fn turn(spin: DVec3, w: Self) -> Self {
        spin.cross(w)
    }
    #[inline]
    fn spin_of(w: Self, wd: Self) -> DVec3 {
        w.cross(wd)
    }
}

/// What a sensor measures at its (static) point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sensor<V> {
    /// The radiance arriving at `point` from `direction` (where it looks).
    Radiance {
        /// Where.
        point: V,
        /// Looking direction (unit).
        direction: V,
    },
    /// The irradiance `∫ L (η·n)⁺ dη` at `point` with unit normal `normal`.
    Irradiance {
        /// Where.
        point: V,
        /// Unit normal.
        normal: V,
    },
    /// A pinhole camera at `point`: a reading is one pixel's mean radiance
    /// over its footprint ([`Geometry::pixel_lobe`]), so it needs a
    /// [`PixelSample`].
    Camera {
        /// The pinhole.
        point: V,
    },
}

pub use crate::estimator::PixelSample;

/// A primitive (segment, triangle) index; [`NO_PRIM`] for none.
pub type Prim = u32;
/// No primitive (nothing to skip).
pub const NO_PRIM: Prim = u32::MAX;
/// A medium: the index of the shape that holds it, `None` for vacuum.
pub type MediumId = Option<u32>;

/// The coefficients of a homogeneous medium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Scattering coefficient κs.
    pub ks: f64,
    /// Extinction coefficient κe ≥ κs.
    pub ke: f64,
}

/// A closest hit along a unit ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the ray.
    pub t: f64,
    /// The primitive hit.
    pub prim: Prim,
}

/// The integrand over directions at a scattering vertex, up to the
/// radiance: a cosine lobe (the irradiance sensor, a Lambertian reflector)
/// or a phase function, with the density that samples it.
pub trait Lobe<V: Vector>: Copy {
    /// The integrand's factor `f(η)`.
    fn value(&self, w: V) -> f64;
    /// The density with which [`Lobe::sample`] draws `w`.
    fn pdf(&self, w: V) -> f64;
    /// `f / pdf`, the same for every direction the lobe draws.
    fn weight(&self) -> f64;
    /// A direction drawn with density [`Lobe::pdf`].
    fn sample(&self, rng: &mut PathRng) -> V;
    /// The derivative of `ln f(η)` when `η` moves at `wd` relative to the
    /// lobe's frame.
    fn dlog(&self, w: V, wd: V) -> f64;
}

/// The media and surfaces of a scene, its rays and emitters, and its
/// parameters' motions: what the path core needs of a geometry.
pub trait Geometry: Sync {
    /// Points, directions and velocities.
    type V: Vector;
    /// The directional lobes.
    type Lobe: Lobe<Self::V>;

    /// Largest extent of the scene (for relative offsets).
    fn size(&self) -> f64;
    /// What the sensor measures, and where.
    fn sensor(&self) -> Sensor<Self::V>;
    /// For a camera: the lobe over directions of the footprint of `s`'s
    /// stratum, `p(η)` uniform over that part of the image plane (as a
    /// density over directions), value = density, so a path's reading is
    /// the stratum's mean radiance. `None` where the geometry has no camera.
    fn pixel_lobe(&self, s: PixelSample) -> Option<Self::Lobe> {
        let _ = s;
        None
    }
    /// For a camera: its image's `(width, height)` in pixels.
    fn image(&self) -> Option<(u32, u32)> {
        None
    }
    /// The medium around the sensor.
    fn sensor_medium(&self) -> MediumId;
    /// The closest primitive along the unit ray, other than `skip`.
    fn cast(&self, x: Self::V, w: Self::V, skip: Prim) -> Option<Hit>;
    /// Whether no opaque primitive (other than `skip`) lies strictly between
    /// `x` and `y`.
    fn visible(&self, x: Self::V, y: Self::V, skip: Prim) -> bool;
    /// The shape that owns primitive `p`.
    fn shape(&self, p: Prim) -> u32;
    /// The surface of primitive `p`.
    fn surface(&self, p: Prim) -> Surface;
    /// Unit normal of primitive `p` at its point `y` (outward for closed
    /// shapes).
    fn normal(&self, p: Prim, y: Self::V) -> Self::V;
    /// How far off a surface, an interface or a boundary point at `y` a
    /// nested path starts: [`tolerance::NUDGE`] of the scene's size, and far
    /// from the origin (3D) enough more that the casters, which skip hits
    /// within the rounding of their coordinates, still see the surface it
    /// left (at 10⁵ sizes from the origin a moving fog's derivative was 4×
    /// off with the fixed step, and at 4·10⁵ transport's derivative for a
    /// mirror moving inside fog +1.4e-2 against −2.5e-3 at the origin,
    /// while its in-scattering start took a fixed half step). Every start
    /// a hair off a surface goes through here.
    #[inline]
    fn nudge(&self, _y: Self::V) -> f64 {
        tolerance::NUDGE * self.size()
    }
    /// Whether primitive `p` bounds a solid no path reaches the inside of:
    /// flatland's closed opaque polygons, 3D's closed opaque meshes the
    /// sensor is outside (around the sensor, one is a room). A ray that meets such a primitive from
    /// behind (along its outward normal) got there by rounding, along a
    /// sight line through a corner; the walk takes the back as black (see
    /// [`walk::walk`]).
    #[inline]
    fn solid(&self, _p: Prim) -> bool {
        false
    }
    /// The scene's media (none by default).
    fn media(&self) -> &media::Media {
        &media::NO_MEDIA
    }
    /// The coefficients of medium `m` (`None`: vacuum).
    #[inline]
    fn coefficients(&self, m: MediumId) -> Option<Coefficients> {
        self.media().coefficients(m)
    }
    /// An upper bound on the length of a straight path inside medium `m`
    /// ([`thin_media::chord_bound`] of its boundary's vertices): in an
    /// optically thin medium the walk draws collisions as if it were
    /// [`thin_media::THIN_DEPTH`] thick over this length
    /// ([`thin_media::collision_rate`]).
    #[inline]
    fn medium_chord(&self, m: MediumId) -> f64 {
        self.media().chord(m)
    }
    /// The medium entered or left when a ray in `m` crosses the transparent
    /// boundary of shape `k`.
    #[inline]
    fn crossed(&self, m: MediumId, k: u32) -> MediumId {
        self.media().crossed(m, k)
    }
    /// The cosine lobe `c (η·n)⁺` about the unit normal `n`.
    fn cosine_lobe(&self, n: Self::V, c: f64) -> Self::Lobe;
    /// The phase function of medium `m` about the incoming direction `w`.
    fn phase_lobe(&self, m: MediumId, w: Self::V) -> Self::Lobe;
    /// A point drawn on the emitters (by length in the plane, by area in
    /// space: as many uniform numbers as the geometry needs): the point and
    /// its primitive; `None` without emitters.
    fn emitter_point(&self, rng: &mut PathRng) -> Option<(Self::V, Prim)>;
    /// The density over directions at `x` of drawing the emitter point `y`
    /// of primitive `p` with [`Geometry::emitter_point`].
    fn light_pdf(&self, x: Self::V, y: Self::V, p: Prim) -> f64;
    /// Number of shape parameters.
    fn parameters(&self) -> usize;
    /// The shape parameter `j` moves.
    fn parameter_shape(&self, j: usize) -> u32;
    /// Velocity `∂q/∂π_j` of the point `q` of the shape parameter `j` moves.
    fn velocity(&self, j: usize, q: Self::V) -> Self::V;
    /// Turn rate of that shape's frame under parameter `j`.
    fn spin(&self, j: usize) -> <Self::V as Vector>::Spin;
    /// Whether the geometry offers its own direction density at the
    /// irradiance sensor for the methods that ask for one
    /// ([`walk::Hooks::SENSOR_MIXTURE`]; flatland: the lobe mixed with the
    /// warp's steep gaps, [`crate::flat::sensor_gaps`]).
    fn sensor_mixture(&self) -> bool {
        false
    }
    /// A direction drawn at the sensor with that density.
    fn sensor_mixture_sample(&self, lobe: &Self::Lobe, rng: &mut PathRng) -> Self::V {
        lobe.sample(rng)
    }
    /// That density at `w`.
    fn sensor_mixture_pdf(&self, lobe: &Self::Lobe, w: Self::V) -> f64 {
        lobe.pdf(w)
    }
}

/// A discontinuity of the integrand over directions seen from a vertex,
/// drawn for a boundary term: a point `q` where what the ray sees changes
/// (2D: a corner; 3D: a point on a silhouette edge) and what each side sees
/// there.
#[derive(Debug, Clone, Copy)]
pub struct BoundaryPoint<V> {
    /// The point.
    pub q: V,
    /// The shape it belongs to.
    pub shape: u32,
    /// The drawn index (the geometry's own numbering).
    pub index: u32,
    /// The inverse of its selection probability.
    pub inv_pdf: f64,
}

/// A scattering vertex as one slot moves it: its position `x`, its
/// velocity `u` and the turn rate `spin` of the frame its directions are
/// attached to. A warp's knots move relative to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingVertex<V: Vector> {
    /// Position.
    pub x: V,
    /// Velocity `u_j`.
    pub u: V,
    /// The frame's turn rate `Ω_j`.
    pub spin: V::Spin,
}

/// What a ray just to one side of a boundary point sees there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Side {
    /// The surface of this primitive, at the boundary point.
    Surface(Prim),
    /// Nothing: the ray passes the point and goes on.
    Past,
}

/// What rays just to either side of the sight line `w` meet at a boundary
/// point, of the surfaces there given as `(p, d, c)`: primitive `p`, its
/// direction `d` from the point, `c` its component across the line
/// (positive on the first side, negative on the second). On each side the
/// ray meets first the surface of least `(d·w)/|c|`; one along the line
/// (`c = 0`) a grazing ray sees nothing of. Flatland's corners and 3D's
/// edges both (`Boundaries::sides`).
pub fn nearest_sides<V: Vector>(
    w: V,
    surfaces: impl IntoIterator<Item = (Prim, V, f64)>,
) -> (Side, Side) {
    let (mut first, mut second) = ((f64::INFINITY, Side::Past), (f64::INFINITY, Side::Past));
    for (p, d, c) in surfaces {
        if c == 0.0 {
            continue;
        }
        let order = d.dot(w) / c.abs();
        let side = if c > 0.0 { &mut first } else { &mut second };
        if order < side.0 {
            *side = (order, Side::Surface(p));
        }
    }
    (first.1, second.1)
}

/// Whom the boundary term at a vertex serves, as the draw of its boundary
/// point needs to know: a slot whose vertex or frame moves sees every
/// discontinuity move; a shape parameter otherwise sees only its own
/// shape's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BoundaryView {
    /// The slots whose vertex or frame moves at the vertex.
    pub all: deform::SlotSet,
    /// The shape parameters not in `all` (their own shapes' discontinuities
    /// move).
    pub own: deform::SlotSet,
}

impl BoundaryView {
    /// Whether some slot sees every discontinuity move.
    #[inline]
    pub fn sees_all(&self) -> bool {
        !self.all.is_empty()
    }
}

/// Where the integrand over directions jumps, and the warp that follows
/// those jumps: the discontinuity machinery of a geometry.
pub trait Boundaries: Warping {
    /// Draws one boundary point for the directional integral at `v` (see
    /// [`Boundaries::boundary_points`] for all of them), among those that
    /// move for some slot of `view`: all of them for a slot whose vertex or
    /// frame moves, else those of the shapes its parameter moves (a
    /// geometry may share the draws out per slot); at a camera, among those
    /// inside the stratum's footprint (where `v`'s lobe is not 0).
    fn sample_boundary(
        &self,
        v: &walk::Vertex<Self>,
        view: &BoundaryView,
        u: f64,
    ) -> Option<BoundaryPoint<Self::V>>
    where
        Self: Sized;
    /// Calls `f` with the boundary points whose terms estimate the
    /// boundary term of the directional integral at `v` (as
    /// [`Boundaries::sample_boundary`] chooses among them), their sum
    /// unbiased, numbers drawn from `rng` (which `f` gets back to evaluate
    /// each term). By default the one point `sample_boundary` draws; a
    /// geometry may take some boundaries every time (3D: the lamps'
    /// edges, and the lamp parts of silhouettes) and draw among the rest.
    #[inline]
    fn boundary_points(
        &self,
        v: &walk::Vertex<Self>,
        view: &BoundaryView,
        rng: &mut crate::rng::PathRng,
        mut f: impl FnMut(&mut crate::rng::PathRng, BoundaryPoint<Self::V>),
    ) where
        Self: Sized,
    {
        use rand::RngExt;
        if let Some(b) = self.sample_boundary(v, view, rng.random()) {
            f(rng, b);
        }
    }
    /// How many pairs of nested paths estimate the jump across each
    /// boundary point at `v` (averaged): 1 by default. Where boundary
    /// points are few and their terms weigh much (a camera pixel that a
    /// moving silhouette crosses), more pairs cost little overall and cut
    /// the jump's share of the variance.
    #[inline]
    fn jump_paths(&self, v: &walk::Vertex<Self>) -> u32
    where
        Self: Sized,
    {
        let _ = v;
        1
    }
    /// What rays just to either side of the direction from `x` to the
    /// boundary point see there: first the side
    /// [`Boundaries::boundary_normal`] points to (plane: counter-clockwise),
    /// then the other.
    fn sides(&self, x: Self::V, b: &BoundaryPoint<Self::V>) -> (Side, Side);
    /// Whether primitive `p` holds the boundary point (plane: a segment
    /// ending at the corner; 3D: a face along the edge). A ray aimed at the
    /// point meets such a primitive only there, so a hit on it short of the
    /// point is rounding: a grazing ray finds it up to ~ε·|q|/γ early (γ
    /// the angle between them), which 500 sizes from the origin hid an
    /// edge-on lamp's far end from every corner term.
    fn holds(&self, b: &BoundaryPoint<Self::V>, p: Prim) -> bool;
    /// The unit vector tangent to the directions at `η_q` (the direction
    /// from `x` to the boundary point), normal to the boundary there and
    /// pointing to the side [`Boundaries::sides`] names first.
    fn boundary_normal(&self, x: Self::V, b: &BoundaryPoint<Self::V>) -> Self::V;
    /// A point of primitive `p` a hair (10⁻⁹ of the scene's size) from the
    /// boundary point, where a path leaving `p`'s surface "at" the boundary
    /// starts: at the point itself its rays would slip past the
    /// neighbouring faces (a reflector's concave corner lights itself).
    fn off_boundary(&self, b: &BoundaryPoint<Self::V>, p: Prim) -> Self::V;
}

/// The expectation method's warp of the directions at a vertex: a
/// continuous velocity field over directions that equals each
/// discontinuity's velocity at the discontinuity and the frame's at the
/// lobe's horizon, so no boundary term is left. It follows the
/// discontinuities [`Boundaries`] finds.
pub trait Warping: Geometry {
    /// The field at one vertex.
    type Warp;
    /// The warp at `v` around the direction `w` drawn there. `ahead`, when
    /// the caller has cast the ray already, is its first hit (`Some(None)`:
    /// it escapes); a geometry whose search starts from that hit then need
    /// not cast it again. `frame` holds the slots whose vertex or frame
    /// may move at `v`; the others have `u = 0` and `Ω = 0`, so their field
    /// is zero wherever no moving discontinuity is near (a geometry may
    /// skip its search there).
    fn warp(
        &self,
        v: &walk::Vertex<Self>,
        w: Self::V,
        ahead: Option<Option<Hit>>,
        frame: deform::SlotSet,
    ) -> Self::Warp
    where
        Self: Sized;
    /// Calls `f` with every shape whose motion the warp at `w` follows.
    fn warp_shapes(&self, warp: &Self::Warp, f: impl FnMut(u32));
    /// Slot `slot`'s velocity of the direction `w` under the warp, and the
    /// warp's divergence there: `vertex` is the vertex as the slot moves it,
    /// `velocity(q, k)` the velocity of point `q` of shape `k`. (A geometry
    /// may build a different field per slot: 3D aligns its fibres with each
    /// parameter's motion.)
    fn warp_velocity(
        &self,
        warp: &Self::Warp,
        slot: usize,
        vertex: MovingVertex<Self::V>,
        w: Self::V,
        velocity: impl Fn(Self::V, u32) -> Self::V,
    ) -> (Self::V, f64);
}

/// The power heuristic's weight of a strategy of density `a` against `b`.
#[inline]
pub fn mis(a: f64, b: f64) -> f64 {
    if a.is_infinite() {
        1.0
    } else {
        a * a / (a * a + b * b)
    }
}
