//! Unit tests of the edge hierarchy: culling, draws and their probabilities.
use super::*;

/// Uniform draws in [0, 1) from `seed` (a 64-bit LCG): fixed, and free of
/// the crate's own random streams.
pub(in crate::mesh) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// 200 open edges (always discontinuities) scattered in a box, and the
/// frequency with which a fine grid of `u` draws each against the
/// probability the draw reports: the descent's probabilities must be
/// those it samples with, whatever the importance.
#[test]
fn an_edge_is_drawn_with_the_probability_reported() {
    let mut next = uniform(7);
    let mut edges = Vec::new();
    let mut facts = Vec::new();
    let mut weights = Vec::new();
    for _ in 0..200 {
        let a = DVec3::new(next() * 4.0 - 2.0, next() * 4.0 - 2.0, next() * 2.0);
        let b = a + DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.6;
        edges.push(Edge {
            a,
            b,
            faces: [0, NO_PRIM],
            shape: 0,
        });
        facts.push(EdgeFacts {
            normals: [DVec3::Z; 2],
            always: true,
        });
        weights.push((b - a).length());
    }
    let tree = EdgeTree::new(&edges, &facts, &weights, (0..200).collect());
    for x in [DVec3::new(0.1, -0.2, -1.0), DVec3::new(0.3, 0.2, 1.0)] {
        let drawn = draws_as_reported(&tree, &edges, &facts, &weights, x);
        // Nearer edges are drawn more often than far ones, per unit
        // weight: the distance enters.
        let mut by_distance: Vec<(f64, f64)> = edges
            .iter()
            .zip(&drawn)
            .zip(&weights)
            .map(|((e, &(_, p)), w)| ((0.5 * (e.a + e.b) - x).length(), p / w))
            .collect();
        by_distance.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mean = |q: &[(f64, f64)]| q.iter().map(|v| v.1).sum::<f64>() / q.len() as f64;
        let (close, far) = (mean(&by_distance[..50]), mean(&by_distance[150..]));
        assert!(close > 1.3 * far, "near {close}, far {far}");
    }
}
/// Edges of a faceted sphere (each with two faces' normals a little
/// apart, so nodes are culled and some descents dead-end): every draw of
/// an edge reports the same probability, to the last bit; it matches the
/// frequencies of a fine grid of `u`; the probabilities sum to the share of
/// `u` that draws something; and no edge outside the tree, nor one that is
/// no silhouette from the point, is ever drawn.
#[test]
fn the_probability_of_an_edge_is_that_of_its_draws() {
    let mut next = uniform(11);
    let (mut edges, mut facts, mut weights) = (Vec::new(), Vec::new(), Vec::new());
    let m = 300;
    for _ in 0..m {
        let z: f64 = 2.0 * next() - 1.0;
        let phi = 2.0 * std::f64::consts::PI * next();
        let r = (1.0 - z * z).sqrt();
        let c = DVec3::new(r * phi.cos(), r * phi.sin(), z);
        let t = c.any_orthonormal_vector();
        let t = (t * (next() - 0.5) + c.cross(t) * (next() - 0.5)).normalize();
        let side = c.cross(t);
        let tilt = 0.05 + 0.3 * next();
        edges.push(Edge {
            a: c - t * 0.05,
            b: c + t * 0.05,
            faces: [0, 1],
            shape: 0,
        });
        facts.push(EdgeFacts {
            normals: [(c + side * tilt).normalize(), (c - side * tilt).normalize()],
            always: false,
        });
        weights.push(0.1 * 2.0 * tilt.atan() / std::f64::consts::PI);
    }
    // The tree over a subset (every edge but each fifth), as the
    // moving edges are.
    let ids: Vec<u32> = (0..m as u32).filter(|i| i % 5 != 0).collect();
    let tree = EdgeTree::new(&edges, &facts, &weights, ids);
    for x in [DVec3::new(2.5, 0.3, -0.4), DVec3::new(-0.2, 1.6, 1.1)] {
        let n = 400_000;
        let mut drawn = vec![0usize; m];
        let mut probs = vec![0.0; m];
        let mut none = 0;
        for k in 0..n {
            let u = (k as f64 + 0.5) / n as f64;
            match tree.sample(x, u, &edges, &facts, &weights) {
                Some((e, p, _)) => {
                    let e = e as usize;
                    if drawn[e] > 0 {
                        assert_eq!(probs[e], p, "edge {e}: one probability per edge");
                    }
                    drawn[e] += 1;
                    probs[e] = p;
                }
                None => none += 1,
            }
        }
        let total: f64 = probs.iter().sum();
        let live = 1.0 - none as f64 / n as f64;
        assert!(
            (total - live).abs() < 2000.0 / n as f64,
            "Σ p = {total} against {live} drawn"
        );
        let silhouettes = (0..m)
            .filter(|&e| is_discontinuity(&edges[e], &facts[e], x))
            .count();
        assert!(silhouettes > 10 && silhouettes < m / 2, "{silhouettes}");
        for e in 0..m {
            if e % 5 == 0 {
                assert_eq!(drawn[e], 0, "edge {e} is not in the tree");
            }
            if !is_discontinuity(&edges[e], &facts[e], x) {
                assert_eq!(drawn[e], 0, "edge {e} is no silhouette");
            }
            // A silhouette never drawn has a probability below a few
            // strata of the grid.
            let share = drawn[e] as f64 / n as f64;
            assert!(
                (share - probs[e]).abs() < 40.0 / n as f64,
                "edge {e}: {share} against {}",
                probs[e]
            );
        }
    }
}

/// 200 open edges in a box, as five meshes of 40: the hierarchy joined
/// from the meshes' own trees draws each edge with the probability it
/// reports (a fine grid of `u` against the reported probabilities), every
/// edge can be drawn, and one mesh's tree joined alone is the tree built
/// over its edges in the scene's numbering (the same draws, bit for bit).
#[test]
fn a_tree_joined_from_meshes_draws_as_it_reports() {
    let mut next = uniform(3);
    let (mut edges, mut facts, mut weights) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..200 {
        // Each mesh in its own part of the box, as meshes that do not cross.
        let c = DVec3::new((k / 40) as f64 - 2.0, 0.0, 0.0);
        let a = c + DVec3::new(next() * 0.8, next() * 4.0 - 2.0, next() * 2.0);
        let b = a + DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.6;
        edges.push(Edge {
            a,
            b,
            faces: [0, NO_PRIM],
            shape: (k / 40) as u32,
        });
        facts.push(EdgeFacts {
            normals: [DVec3::Z; 2],
            always: true,
        });
        weights.push((b - a).length());
    }
    let local: Vec<EdgeTree> = (0..5)
        .map(|m| {
            let r = 40 * m..40 * (m + 1);
            EdgeTree::new(
                &edges[r.clone()],
                &facts[r.clone()],
                &weights[r],
                (0..40).collect(),
            )
        })
        .collect();
    let parts: Vec<(&EdgeTree, u32)> = local.iter().zip((0..5).map(|m| 40 * m)).collect();
    let tree = EdgeTree::join(&parts, &edges, &facts, &weights);
    let mut order = tree.edges().to_vec();
    order.sort_unstable();
    assert_eq!(order, (0..200).collect::<Vec<u32>>());
    for x in [DVec3::new(0.1, -0.2, -1.0), DVec3::new(1.3, 0.2, 1.0)] {
        let drawn = draws_as_reported(&tree, &edges, &facts, &weights, x);
        assert!(drawn.iter().all(|d| d.0 > 0), "an edge is never drawn");
    }
    // One mesh joined alone: the tree over its edges, numbered in the scene.
    let alone = EdgeTree::join(&[(&local[2], 80)], &edges, &facts, &weights);
    let built = EdgeTree::new(&edges, &facts, &weights, (80..120).collect());
    assert_eq!(alone.edges(), built.edges());
    let x = DVec3::new(0.3, 0.1, 0.5);
    for k in 0..1000 {
        let u = (k as f64 + 0.5) / 1000.0;
        assert_eq!(
            alone.sample(x, u, &edges, &facts, &weights),
            built.sample(x, u, &edges, &facts, &weights)
        );
    }
}

/// Draws from `tree` at `x` with a fine grid of `u` over every edge (all
/// always discontinuities, so every draw succeeds): each edge is drawn
/// with one probability, the probabilities sum to 1, and each edge's share
/// of the draws is its probability. Returns per edge its draws and
/// probability.
fn draws_as_reported(
    tree: &EdgeTree,
    edges: &[Edge],
    facts: &[EdgeFacts],
    weights: &[f64],
    x: DVec3,
) -> Vec<(u32, f64)> {
    let n = 400_000;
    let mut drawn: Vec<(u32, f64)> = vec![(0, 0.0); edges.len()];
    for k in 0..n {
        let u = (k as f64 + 0.5) / n as f64;
        let (e, p, rest) = tree.sample(x, u, edges, facts, weights).unwrap();
        assert!((0.0..1.0).contains(&rest));
        let slot = &mut drawn[e as usize];
        if slot.0 > 0 {
            assert_eq!(slot.1, p, "edge {e}: one probability per edge");
        }
        *slot = (slot.0 + 1, p);
    }
    let total: f64 = drawn.iter().map(|d| d.1).sum();
    assert!((total - 1.0).abs() < 1e-12, "Σ p = {total}");
    for (e, &(count, p)) in drawn.iter().enumerate() {
        // The grid of u is stratified: an edge's count is its share of
        // [0, 1) to within the strata its ends cut, a few per level of the
        // tree.
        let share = count as f64 / n as f64;
        assert!(
            (share - p).abs() < 40.0 / n as f64,
            "edge {e}: {share} against {p}"
        );
    }
    drawn
}
