//! The tolerances flatland and 3D share, each named once with what it is
//! relative to and why it has its size. Two sizes recur: 10⁻¹² for what
//! only rounding tells apart (an f64 coordinate or angle keeps ~10⁻¹⁶ of
//! its magnitude, and the tests built on them lose a few digits more), and
//! 10⁻⁹ for what the tracer must keep apart from a surface or a feature by
//! more than any rounding, yet by less than any real gap in a scene (within
//! [`MAX_OFFSET`](crate::scene::limits::MAX_OFFSET) sizes of the origin a
//! coordinate still keeps ten digits of the geometry). Tolerances of one
//! dimension's geometry stay beside it (`mesh::bvh::ROUNDING_ULPS`,
//! `mesh::scene::TOUCH_DISTANCE`, `mesh::methods::EDGE_ON_ULPS`). Book:
//! chapter "When not to trust a number", section "Scale".

/// How far off a surface, an interface or a boundary point a nested path
/// starts, relative to the scene's size: 10³ times beyond the rounding of
/// coordinates near the origin, so the casters still see the surface it
/// left, and far below any scene's detail. The start itself goes through
/// [`Geometry::nudge`](super::Geometry::nudge), which in 3D grows this
/// far from the origin.
pub const NUDGE: f64 = 1e-9;

/// A point closer than `ON_SURFACE` times the scene's size to a surface
/// (or a plane) lies on it: a sensor on a shape, a lamp's vertex off its
/// plane, an edge at the camera's pinhole depth. As large as [`NUDGE`]: a
/// path started a nudge off such a point could start on the wrong side.
pub const ON_SURFACE: f64 = NUDGE;

/// A sight line from `x` to `y` counts hits only up to `1 − SHORT_OF_END`
/// of its length: a hit nearer `y` is `y`'s own surface met by rounding
/// (~10⁻¹⁶ of the length), and no occluder fits in the gap left.
pub const SHORT_OF_END: f64 = 1e-9;

/// How near a feature (a segment's end, relative to its length; an edge
/// function's 0, relative to the three's sum) a hit counts as on it:
/// rounding puts a ray through a vertex or an edge ~10⁻¹⁶ to either side,
/// and a ray truly this near it is as rare as one exactly on it. Used by
/// the touch tests (flatland's vertices, 3D's edges and vertices) and by
/// the sensor's view of an edge through its axis.
pub const NEAR: f64 = 1e-9;

/// Largest angle (rad), or relative distance, at which two directions or
/// points the caveats and warps compare count as aligned: corners on one
/// sight line from the sensor (flatland's ties), an edge's ends in the
/// plane through the sensor and another edge (3D's ties), a direction at
/// a pole of the 3D warp's frame. The rounding of an exact alignment.
pub const TIE: f64 = 1e-12;

/// Smallest ray distance counted as a hit, relative to the size of the
/// primitive hit (a segment's length, a triangle's longest edge): a ray
/// leaving a surface (or a corner) must not find the surface it leaves.
/// Relative, so a scene scaled by any factor validation accepts traces the
/// same (3D adds a floor far from the origin: `mesh::bvh::ROUNDING_ULPS`).
pub const T_MIN: f64 = 1e-12;

/// A polygon whose area is at most `DEGENERATE × d²`, a segment at most
/// `DEGENERATE × d` long (`d` the scene's or the mesh's size) is
/// degenerate: rounding, not geometry (a sliver the tracer could not give
/// a normal to). Validation rejects them.
pub const DEGENERATE: f64 = 1e-12;

/// Relative distance under which two things the closed-form references
/// need apart (the sensor and an emitter's line, an edge or a lamp's
/// plane; an occluder and the lamp's plane) count as coincident: the
/// rounding of an exact coincidence, refused rather than answered with a
/// number rounding dominates.
pub const COINCIDENT: f64 = 1e-12;

/// Relative padding of a culling bound (a corner's box, a sphere around a
/// mesh, a cone's cosine margin): far beyond the rounding of the tests it
/// guards (~10⁻¹⁶ relative), so nothing is culled by rounding, and small
/// enough that the bound stays as tight.
pub const CULL_PAD: f64 = 1e-9;

/// Padding of a bound against the rounding of its coordinates, relative to
/// their magnitude (a box's half-extent, a sphere's centre far from the
/// origin): a few thousand ulps.
pub const COORDINATE_PAD: f64 = 1e-12;
