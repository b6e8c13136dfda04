//! What 3D's boundary terms and warp draw edges from: the edges of the
//! opaque meshes that can be discontinuities, with their weights, facts
//! and hierarchies (`EdgeTables`), and the space's caches built on first
//! use by the derivative methods ([`EdgeSampler`]: the tables, what the
//! sensor's point sees, the moving edges each camera pixel sees, the lamp
//! overlaps at the sensor). Book: chapter "Three dimensions", section
//! "Boundary terms".
use super::camera::PixelEdges;
use super::edges::{Edge, EdgeFacts, EdgeTree};
use super::scene::Scene;
use super::sensor_view::SensorView;
use crate::path::{NO_PRIM, Prim, Surface};
use glam::DVec3;
use std::collections::HashMap;
use std::sync::OnceLock;

/// Most edges in a tree for which the edge itself is also drawn by the
/// length of its arc with a lamp behind (every edge's arc and lamp parts
/// per draw); larger trees draw by the tree alone.
pub(super) const LAMP_EDGES: usize = 64;

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

impl EdgeTables {
    /// The edges of `scene`'s opaque meshes (`normals`: per triangle, in
    /// [`Space`]'s order), their weights and facts, and their hierarchies.
    pub(super) fn new(scene: &Scene, normals: &[DVec3]) -> EdgeTables {
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

/// The space's edge caches, each built on first use: only the derivative
/// methods ask (not the intensity estimator, nor the displaced scenes of
/// finite differences).
#[derive(Debug, Clone)]
pub struct EdgeSampler {
    /// The edges and their hierarchies.
    pub(super) tables: OnceLock<EdgeTables>,
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
            tables: OnceLock::new(),
            pixel_edges: OnceLock::new(),
            sensor_view: OnceLock::new(),
            sensor_lamps: [OnceLock::new(), OnceLock::new()],
            sensor_shape_lamps: (0..shapes).map(|_| OnceLock::new()).collect(),
        }
    }
}
