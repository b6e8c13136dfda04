//! What 3D's boundary terms and warp draw edges from: the edges of the
//! opaque meshes that can be discontinuities, with their weights, facts
//! and hierarchies (`EdgeTables`), and the space's caches built on first
//! use by the derivative methods ([`EdgeSampler`]: the tables, what the
//! sensor's point sees, the moving edges each camera pixel sees, the lamp
//! overlaps at the sensor). Book: chapter "Three dimensions", section
//! "Boundary terms".
use super::camera::PixelEdges;
use super::edges::{Edge, EdgeFacts, EdgeTree};
use super::part::MeshPart;
use super::scene::Scene;
use super::sensor_view::SensorView;
use crate::path::{NO_PRIM, Surface};
use std::sync::{Arc, OnceLock};

/// Most edges in a tree for which the edge itself is also drawn by the
/// length of its arc with a lamp behind (every edge's arc and lamp parts
/// per draw); larger trees draw by the tree alone.
pub(super) const LAMP_EDGES: usize = 64;

/// The edges of the opaque meshes that can be discontinuities, with what
/// the boundary terms and the warp need of them.
#[derive(Debug, Clone)]
pub(crate) struct EdgeTables {
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

impl EdgeTables {
    /// The edges of `scene`'s opaque meshes, their weights and facts, and
    /// their hierarchies, assembled from the meshes' own (`parts`, in the
    /// scene's order): each hierarchy joins whole meshes' trees
    /// ([`EdgeTree::join`]), so no mesh's edges are found or sorted again.
    pub(super) fn new(scene: &Scene, parts: &[Arc<MeshPart>]) -> EdgeTables {
        let shapes = scene.shapes();
        let mut edges = Vec::new();
        let mut edge_weight = Vec::new();
        let mut edge_facts = Vec::new();
        // Per mesh, its edges' first index.
        let mut first_edge = Vec::with_capacity(shapes.len());
        let mut first_tri = 0;
        for (k, (s, part)) in shapes.iter().zip(parts).enumerate() {
            let own = part.edges(s);
            first_edge.push(edges.len() as u32);
            edges.extend(own.edges.iter().map(|e| {
                Edge {
                    faces: e
                        .faces
                        .map(|f| if f == NO_PRIM { NO_PRIM } else { f + first_tri }),
                    shape: k as u32,
                    ..*e
                }
            }));
            edge_weight.extend_from_slice(&own.weights);
            edge_facts.extend_from_slice(&own.facts);
            first_tri += part.len();
        }
        let params = scene.parameters().len();
        let moving = |k: usize| (0..params).any(|j| scene.parameter_shape(j) as usize == k);
        let lamp =
            |k: usize| matches!(shapes[k].surface, Surface::Emitter { radiance } if radiance > 0.0);
        let count = |k: usize| parts[k].edges(&shapes[k]).edges.len();
        let lamp_edges: usize = (0..shapes.len()).filter(|&k| lamp(k)).map(count).sum();
        // Only in small scenes, as the lamp parts (`LAMP_EDGES`): over a
        // large mesh every point costs casts through a deep hierarchy (on
        // mesh_perf's sphere of 10^5 triangles transport ran 2.8 times
        // slower per path for 1.7 times less variance).
        let small = lamp_edges <= LAMP_SET && edges.len() - lamp_edges <= LAMP_EDGES;
        let ids_of = |k: usize| first_edge[k]..first_edge[k] + count(k) as u32;
        let lamp_set = if small {
            let of = |pick: &dyn Fn(usize) -> bool| -> Vec<u32> {
                (0..shapes.len())
                    .filter(|&k| lamp(k) && pick(k))
                    .flat_map(ids_of)
                    .collect()
            };
            [of(&moving), of(&|_| true)]
        } else {
            [Vec::new(), Vec::new()]
        };
        // The lamp set is whole meshes: the drawn hierarchies join the
        // trees of the meshes outside it.
        let join = |pick: &dyn Fn(usize) -> bool| {
            let chosen: Vec<(&EdgeTree, u32)> = (0..shapes.len())
                .filter(|&k| pick(k))
                .map(|k| (&parts[k].edges(&shapes[k]).tree, first_edge[k]))
                .collect();
            EdgeTree::join(&chosen, &edges, &edge_facts, &edge_weight)
        };
        let drawn = |k: usize| !(small && lamp(k));
        let all_edges = join(&|_| true);
        let all_drawn = join(&drawn);
        let moving_drawn = join(&|k| moving(k) && drawn(k));
        let shape_drawn = (0..shapes.len())
            .map(|k| join(&|l| l == k && moving(k) && drawn(k)))
            .collect();
        let shape_edges = (0..shapes.len()).map(|k| count(k) as u32).collect();
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

/// The space's edge caches that depend on the sensor, each built on first
/// use (the edge tables themselves are the scene's: see [`Scene`]): only
/// the derivative methods ask (not the intensity estimator, nor the
/// displaced scenes of finite differences).
#[derive(Debug, Clone)]
pub struct EdgeSampler {
    /// The moving edges each camera pixel sees (built on first use, by the
    /// derivative methods).
    pub(super) pixel_edges: OnceLock<PixelEdges>,
    /// What the sensor's point sees of the edges (built on first use, by
    /// the expectation method).
    pub(super) sensor_view: OnceLock<SensorView>,
    /// The lamp overlaps (`Space::lamp_overlaps`) of the moving edges and
    /// of all edges seen from the sensor's point, where every path starts
    /// (built on first use).
    pub(super) sensor_lamps: [OnceLock<([f64; LAMP_EDGES], f64)>; 2],
    /// The same per mesh, for its stratum (`Space::edge_strata`).
    pub(super) sensor_shape_lamps: Vec<OnceLock<([f64; LAMP_EDGES], f64)>>,
}

impl EdgeSampler {
    /// Empty caches for a scene of `shapes` meshes.
    pub(super) fn new(shapes: usize) -> EdgeSampler {
        EdgeSampler {
            pixel_edges: OnceLock::new(),
            sensor_view: OnceLock::new(),
            sensor_lamps: [OnceLock::new(), OnceLock::new()],
            sensor_shape_lamps: (0..shapes).map(|_| OnceLock::new()).collect(),
        }
    }
}
