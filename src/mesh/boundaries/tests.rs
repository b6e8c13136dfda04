//! Unit tests of the boundary points' density (against the draws).
use super::*;
use crate::mesh::file;
use std::path::Path;
use std::sync::Arc;

/// `E[inv_pdf · 1{q in a piece of arc}]` is the piece's length
/// whatever the density, if `inv_pdf` is the inverse of the density
/// the points are drawn with: on the fog-free showcase (a cube, 12
/// moving edges, under a two-triangle lamp), from floor points in the
/// cube's penumbra (two), lit and in its umbra, and from a point on the
/// cube, with the moving edges (rendering) and with every edge (a vertex
/// that moves), a fine grid of `u` and `Σ inv_pdf` per eighth of each
/// edge's arc against its angle, over all the points
/// [`Space::edge_points`] gives (the one drawn, the lamp parts of
/// silhouettes, the lamp's edges), within 0.4 % (a pdf wrong by 2 % on
/// the lamp parts fails it).
#[test]
fn the_boundary_density_is_that_of_the_draws() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mesh/showcase_nofog.toml");
    let space = Space::new(Arc::new(file::load(&path).unwrap()));
    let tables = space.edge_tables();
    let n = 1_600_000;
    let bins = 8;
    let mut with_lamp = 0;
    for x in [
        DVec3::new(-0.3, 0.55, 0.0),
        DVec3::new(0.25, 0.1, 0.0),
        DVec3::new(-0.3, 0.0, 0.0),
        DVec3::new(1.5, -1.0, 0.0),
        DVec3::new(-0.3, 0.0, 0.85),
        DVec3::new(-0.9, 0.0, 0.0),
    ] {
        for all in [false, true] {
            let tree = if all {
                &tables.all_drawn
            } else {
                &tables.moving_drawn
            };
            if space.lamp_overlaps(x, tree).1 > 0.0 {
                with_lamp += 1;
            }
            let mut sums = vec![0.0; tables.edges.len() * bins];
            let mut arcs = vec![0.0; tables.edges.len()];
            for k in 0..n {
                let u = (k as f64 + 0.5) / n as f64;
                // The drawn point and those taken every time, the same
                // grid for both numbers (the sum's expectation is the sum
                // of theirs).
                let stratum = if all { Stratum::All } else { Stratum::Moving };
                space.edge_points(
                    x,
                    stratum,
                    Some((u, 1.0)),
                    u,
                    |_| true,
                    |b| {
                        assert!(b.inv_pdf.is_finite() && b.inv_pdf > 0.0);
                        let e = b.index as usize;
                        let edge = &tables.edges[e];
                        let (ra, rb, rq) = (edge.a - x, edge.b - x, b.q - x);
                        let arc = ra.cross(rb).length().atan2(ra.dot(rb));
                        let alpha = ra.cross(rq).length().atan2(ra.dot(rq));
                        let bin = ((alpha / arc * bins as f64) as usize).min(bins - 1);
                        sums[e * bins + bin] += b.inv_pdf / n as f64;
                        arcs[e] = arc;
                    },
                );
            }
            for &e in tree.edges().iter().chain(&tables.lamp_set[all as usize]) {
                let e = e as usize;
                // Every edge here is a discontinuity from everywhere
                // (open, or a reflector's crease): each must be drawn.
                assert!(arcs[e] > 0.0, "x {x}, all {all}: edge {e} never drawn");
                for bin in 0..bins {
                    let want = arcs[e] / bins as f64;
                    let got = sums[e * bins + bin];
                    assert!(
                        (got / want - 1.0).abs() < 0.004,
                        "x {x}, all {all}, edge {e}, bin {bin}: {got} against {want}"
                    );
                }
            }
        }
    }
    assert!(
        with_lamp >= 4,
        "{with_lamp} views with a lamp behind some edge"
    );
}

/// The lamps' edges are taken every time ([`Space::lamp_edge_points`]),
/// never drawn (not in the drawn trees): between them every edge that can
/// be a discontinuity is covered once. On the fog-free showcase, from
/// floor and cube points: the lamp set holds the lamp's four edges and
/// the drawn tree the cube's and the floor's; each lamp edge that is a
/// discontinuity from `x` gets one point at the fraction `u` of its arc
/// with `inv_pdf` its arc (so `E[inv_pdf · 1{q in a piece}]` over `u` is
/// the piece's angle, per eighth of the arc to 1e-9).
#[test]
fn the_lamp_edges_are_taken_once_and_never_drawn() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mesh/showcase_nofog.toml");
    let space = Space::new(Arc::new(file::load(&path).unwrap()));
    let tables = space.edge_tables();
    let lamp = |e: u32| tables.edges[e as usize].shape == 0;
    assert_eq!(tables.lamp_set[1], vec![0, 1, 2, 3]);
    assert!(tables.lamp_set[0].is_empty(), "the lamp stands still");
    let mut covered: Vec<u32> = tables.all_drawn.edges().to_vec();
    covered.extend(&tables.lamp_set[1]);
    covered.sort();
    assert_eq!(covered, (0..tables.edges.len() as u32).collect::<Vec<_>>());
    assert!(tables.all_drawn.edges().iter().all(|&e| !lamp(e)));
    let bins = 8;
    let n = 10_000;
    for x in [
        DVec3::new(-0.3, 0.55, 0.0),
        DVec3::new(1.5, -1.0, 0.0),
        DVec3::new(-0.3, 0.0, 0.85),
    ] {
        let mut sums = vec![0.0; 4 * bins];
        for k in 0..n {
            let u = (k as f64 + 0.5) / n as f64;
            let mut seen = Vec::new();
            space.lamp_edge_points(
                x,
                Stratum::All,
                u,
                |_| true,
                |b| {
                    seen.push(b.index);
                    let edge = &tables.edges[b.index as usize];
                    let (ra, rb, rq) = (edge.a - x, edge.b - x, b.q - x);
                    let arc = ra.cross(rb).length().atan2(ra.dot(rb));
                    assert!((b.inv_pdf - arc).abs() < 1e-12 * arc);
                    let alpha = ra.cross(rq).length().atan2(ra.dot(rq));
                    assert!(
                        (alpha - u * arc).abs() < 1e-9,
                        "x {x}: {alpha} against {}",
                        u * arc
                    );
                    let bin = ((alpha / arc * bins as f64) as usize).min(bins - 1);
                    sums[b.index as usize * bins + bin] += b.inv_pdf / n as f64;
                },
            );
            assert_eq!(seen, vec![0, 1, 2, 3], "x {x}: every lamp edge once");
            space.lamp_edge_points(
                x,
                Stratum::Moving,
                u,
                |_| true,
                |b| panic!("the lamp stands still: {b:?}"),
            );
        }
        for e in 0..4 {
            let edge = &tables.edges[e];
            let (ra, rb) = (edge.a - x, edge.b - x);
            let arc = ra.cross(rb).length().atan2(ra.dot(rb));
            for bin in 0..bins {
                let got = sums[e * bins + bin];
                assert!(
                    (got - arc / bins as f64).abs() < 1e-9,
                    "x {x}, edge {e}, bin {bin}: {got}"
                );
            }
        }
    }
}

/// The split of the edges among the slots ([`Space::edge_strata`],
/// [`Space::split_points`]) covers every edge once with the density it
/// reports: on the fog-free showcase, with a slot that sees every edge
/// move beside the cube's two parameters (two strata: the cube's edges,
/// drawn three times in four, and the rest), `Σ inv_pdf` per eighth of
/// each edge's arc against its angle, over a joint grid of the draws and
/// the stratum's number (so each stratum gets its share exactly), within
/// 0.4 %. A share left out of a density fails it.
#[test]
fn the_split_among_the_slots_covers_every_edge_once() {
    use crate::path::deform::SlotSet;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mesh/showcase_nofog.toml");
    let space = Space::new(Arc::new(file::load(&path).unwrap()));
    let tables = space.edge_tables();
    let mut all = SlotSet::EMPTY;
    all.insert(2);
    let view = BoundaryView {
        all,
        own: SlotSet::first(2),
    };
    assert_eq!(space.edge_strata(&view), Strata::Mixed { n_all: 1 });
    // Four numbers for the stratum, each at the middle of its quarter:
    // the cube's stratum for three, the rest for the fourth, and either's
    // drawn points still on a grid of spacing 4/n.
    let (n, picks, bins) = (1_600_000, 4, 8);
    for x in [
        DVec3::new(-0.3, 0.55, 0.0),
        DVec3::new(0.25, 0.1, 0.0),
        DVec3::new(-0.3, 0.0, 0.85),
    ] {
        let mut sums = vec![0.0; tables.edges.len() * bins];
        let mut arcs = vec![0.0; tables.edges.len()];
        for k in 0..n {
            let u = (k as f64 + 0.5) / n as f64;
            let u_pick = ((k % picks) as f64 + 0.5) / picks as f64;
            space.split_points(x, &view, 1, [u, u, u_pick], |b| {
                assert!(b.inv_pdf.is_finite() && b.inv_pdf > 0.0);
                let e = b.index as usize;
                let edge = &tables.edges[e];
                let (ra, rb, rq) = (edge.a - x, edge.b - x, b.q - x);
                let arc = ra.cross(rb).length().atan2(ra.dot(rb));
                let alpha = ra.cross(rq).length().atan2(ra.dot(rq));
                let bin = ((alpha / arc * bins as f64) as usize).min(bins - 1);
                sums[e * bins + bin] += b.inv_pdf / n as f64;
                arcs[e] = arc;
            });
        }
        for &e in tables.all_drawn.edges().iter().chain(&tables.lamp_set[1]) {
            let e = e as usize;
            assert!(arcs[e] > 0.0, "x {x}: edge {e} never drawn");
            for bin in 0..bins {
                let want = arcs[e] / bins as f64;
                let got = sums[e * bins + bin];
                assert!(
                    (got / want - 1.0).abs() < 0.004,
                    "x {x}, edge {e}, bin {bin}: {got} against {want}"
                );
            }
        }
    }
}
