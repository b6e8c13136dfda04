//! One mesh's own tables: its triangles and normals, its ray caster, and
//! (built on first use, for the derivative methods) its discontinuity
//! edges with their hierarchy. A [`Scene`](super::Scene) keeps one per
//! mesh, shared by every scene derived from it that holds the mesh
//! unmoved (another sensor, another pose of other meshes, a finite
//! difference's displaced mesh): an optimiser's step rebuilds the moved
//! meshes' tables only, and [`Space`](super::Space) assembles the scene's
//! from them (book: chapter "Sensitivities at work", section "What one
//! step costs").
use super::bvh::TriangleBvh;
use super::edges::{Edge, EdgeFacts, EdgeTree};
use super::scene::Shape;
use crate::path::{NO_PRIM, Prim, Surface};
use glam::DVec3;
use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

/// A mesh's tables, once built shared through an `Arc`.
pub(crate) type PartCell = Arc<OnceLock<Arc<MeshPart>>>;

/// A new, empty [`PartCell`].
pub(crate) fn part_cell() -> PartCell {
    Arc::new(OnceLock::new())
}

/// The tables of one mesh, indices local to it (triangle `i` is the
/// mesh's `i`th).
#[derive(Debug)]
pub(crate) struct MeshPart {
    /// The triangles' corners.
    pub(super) tris: Vec<[DVec3; 3]>,
    /// Unit normal of each triangle, outward for closed meshes.
    pub(super) normals: Vec<DVec3>,
    /// The ray caster over `tris`.
    pub(super) bvh: TriangleBvh,
    /// The discontinuity edges (opaque meshes only), built on first use.
    edges: OnceLock<MeshEdges>,
}

/// One opaque mesh's edges that can be discontinuities, faces numbered in
/// the mesh, `shape` 0: [`EdgeTables`](super::edge_sampler::EdgeTables)
/// shifts both into the scene's numbering.
#[derive(Debug, Default)]
pub(crate) struct MeshEdges {
    /// The edges.
    pub(super) edges: Vec<Edge>,
    /// Per edge, its weight: length × dihedral turn / π (1 for an open edge).
    pub(super) weights: Vec<f64>,
    /// Per edge, its faces' normals and whether it is always a
    /// discontinuity.
    pub(super) facts: Vec<EdgeFacts>,
    /// The hierarchy over all of them (ids `0..edges.len()`).
    pub(super) tree: EdgeTree,
}

impl MeshPart {
    /// The triangles, normals and caster of `shape`.
    pub(super) fn new(shape: &Shape) -> MeshPart {
        let tris: Vec<[DVec3; 3]> = (0..shape.triangles.len())
            .map(|i| shape.triangle(i))
            .collect();
        let normals = tris
            .iter()
            .map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize())
            .collect();
        MeshPart {
            bvh: TriangleBvh::new(tris.clone()),
            tris,
            normals,
            edges: OnceLock::new(),
        }
    }

    /// Number of triangles.
    pub(super) fn len(&self) -> u32 {
        self.tris.len() as u32
    }

    /// The mesh's discontinuity edges (`shape` must be the mesh this part
    /// was built of; none for a transparent mesh).
    pub(super) fn edges(&self, shape: &Shape) -> &MeshEdges {
        self.edges
            .get_or_init(|| MeshEdges::new(shape, &self.normals))
    }
}

impl MeshEdges {
    /// The edges of `shape` (`normals`: its triangles') whose weight is
    /// positive, in first-seen order (deterministic), with their tree.
    fn new(shape: &Shape, normals: &[DVec3]) -> MeshEdges {
        if !shape.surface.is_opaque() {
            return MeshEdges::default();
        }
        let mut index: HashMap<(u32, u32), usize> = HashMap::new();
        let mut pairs: Vec<((u32, u32), [Prim; 2])> = Vec::new();
        for (i, t) in shape.triangles.iter().enumerate() {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                let key = (a.min(b), a.max(b));
                match index.get(&key) {
                    Some(&m) => {
                        if pairs[m].1[1] == NO_PRIM {
                            pairs[m].1[1] = i as Prim;
                        }
                    }
                    None => {
                        index.insert(key, pairs.len());
                        pairs.push((key, [i as Prim, NO_PRIM]));
                    }
                }
            }
        }
        let reflector = matches!(shape.surface, Surface::Reflector { .. });
        let mut out = MeshEdges::default();
        for ((a, b), faces) in pairs {
            let (a, b) = (shape.vertices[a as usize], shape.vertices[b as usize]);
            let open = faces[1] == NO_PRIM;
            let n0 = normals[faces[0] as usize];
            let n1 = if open { n0 } else { normals[faces[1] as usize] };
            let turn = if open {
                1.0
            } else {
                n0.cross(n1).length().atan2(n0.dot(n1)) / std::f64::consts::PI
            };
            let w = (b - a).length() * turn;
            if w > 0.0 {
                out.edges.push(Edge {
                    a,
                    b,
                    faces,
                    shape: 0,
                });
                out.weights.push(w);
                out.facts.push(EdgeFacts {
                    normals: [n0, n1],
                    always: open || reflector,
                });
            }
        }
        let ids = (0..out.edges.len() as u32).collect();
        out.tree = EdgeTree::new(&out.edges, &out.facts, &out.weights, ids);
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::mesh::bvh::TriangleBvh;
    use crate::mesh::file::load;
    use crate::mesh::space::Space;
    use crate::path::NO_PRIM;
    use glam::DVec3;
    use std::sync::Arc;

    /// The meshes' casters together answer as one scan of every triangle
    /// ([`TriangleBvh::linear`]), index and distance bit for bit, skips and
    /// ties included: rays from random points in random directions, and
    /// rays aimed at the triangles' corners and edge midpoints (where two
    /// triangles tie); the opaque casters as a scan of the opaque
    /// triangles.
    #[test]
    fn the_meshes_casters_answer_as_one_scan() {
        let root = env!("CARGO_MANIFEST_DIR");
        for file in ["room", "dome", "occluder"] {
            let scene = load(std::path::Path::new(&format!(
                "{root}/scenes/mesh/{file}.toml"
            )))
            .unwrap();
            let space = Space::new(Arc::new(scene));
            let scan = TriangleBvh::linear(space.tris.clone());
            let opaque: Vec<usize> = (0..space.tris.len())
                .filter(|&i| {
                    space.scene.shapes()[space.owner[i] as usize]
                        .surface
                        .is_opaque()
                })
                .collect();
            let opaque_scan = TriangleBvh::linear(opaque.iter().map(|&i| space.tris[i]).collect());
            let mut uniform = crate::mesh::edges::tests::uniform(5);
            let mut next = || uniform() * 2.0 - 1.0;
            let size = space.scene.size();
            let mut hits = 0;
            for n in 0..4000 {
                let o = DVec3::new(next(), next(), next()) * size;
                let d = if n % 2 == 0 {
                    DVec3::new(next(), next(), next())
                } else {
                    // At a corner or an edge's midpoint of some triangle.
                    let t = space.tris[n % space.tris.len()];
                    let k = n / 2 % 3;
                    let target = if n % 4 == 1 {
                        t[k]
                    } else {
                        0.5 * (t[k] + t[(k + 1) % 3])
                    };
                    target - o
                };
                let skip = if n % 3 == 0 {
                    (n % space.tris.len()) as u32
                } else {
                    NO_PRIM
                };
                let got = space.caster.closest_hit(o, d, f64::INFINITY, skip);
                assert_eq!(
                    got,
                    scan.closest_hit(o, d, f64::INFINITY, skip),
                    "{file} ray {n}"
                );
                hits += usize::from(got.is_some());
                for t_max in [0.3, 1.0, 3.0] {
                    let local = if skip == NO_PRIM {
                        NO_PRIM
                    } else {
                        opaque
                            .iter()
                            .position(|&i| i == skip as usize)
                            .map_or(NO_PRIM, |i| i as u32)
                    };
                    assert_eq!(
                        space.opaque.any_hit(o, d, t_max, skip),
                        opaque_scan.any_hit(o, d, t_max, local),
                        "{file} ray {n}, t_max {t_max}"
                    );
                }
            }
            assert!(hits > 1000, "{file}: only {hits} hits");
        }
    }
}
