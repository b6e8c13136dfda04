//! Unit tests of the boundary points' density (against the draws).
use super::*;
use crate::mesh::edges::Edge;
use crate::mesh::file;
use std::path::Path;
use std::sync::Arc;

/// The fog-free showcase (a cube, 12 moving edges, under a two-triangle
/// lamp), the scene of every test here.
fn showcase_nofog() -> Space {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/mesh/showcase_nofog.toml");
    Space::new(Arc::new(file::load(&path).unwrap()))
}

/// The angle under which `x` sees the segment from `a` to `b`.
fn angle(x: DVec3, a: DVec3, b: DVec3) -> f64 {
    let (ra, rb) = (a - x, b - x);
    ra.cross(rb).length().atan2(ra.dot(rb))
}

/// `Σ inv_pdf / n` per `bins`-th of each edge's arc seen from `x`, over the
/// boundary points added, and the arc of each edge drawn: what the density
/// tests compare, each bin against its share of the arc.
struct ArcBins<'t> {
    x: DVec3,
    edges: &'t [Edge],
    n: usize,
    bins: usize,
    sums: Vec<f64>,
    arcs: Vec<f64>,
}

impl<'t> ArcBins<'t> {
    /// Empty bins for `n` draws from `x` over `edges`.
    fn new(x: DVec3, edges: &'t [Edge], n: usize, bins: usize) -> ArcBins<'t> {
        ArcBins {
            x,
            edges,
            n,
            bins,
            sums: vec![0.0; edges.len() * bins],
            arcs: vec![0.0; edges.len()],
        }
    }

    /// Adds boundary point `b`, whose `inv_pdf` must be finite and
    /// positive.
    fn add(&mut self, b: BoundaryPoint<DVec3>) {
        assert!(b.inv_pdf.is_finite() && b.inv_pdf > 0.0);
        let e = b.index as usize;
        let edge = &self.edges[e];
        let arc = angle(self.x, edge.a, edge.b);
        let alpha = angle(self.x, edge.a, b.q);
        let bin = ((alpha / arc * self.bins as f64) as usize).min(self.bins - 1);
        self.sums[e * self.bins + bin] += b.inv_pdf / self.n as f64;
        self.arcs[e] = arc;
    }

    /// Checks that every edge of `drawn` was drawn and that each bin of its
    /// arc holds its share of the arc within 0.4 % (`at` names the case in
    /// the messages).
    fn check<'e>(&self, drawn: impl Iterator<Item = &'e u32>, at: &str) {
        for &e in drawn {
            let e = e as usize;
            assert!(self.arcs[e] > 0.0, "{at}: edge {e} never drawn");
            for bin in 0..self.bins {
                let want = self.arcs[e] / self.bins as f64;
                let got = self.sums[e * self.bins + bin];
                assert!(
                    (got / want - 1.0).abs() < 0.004,
                    "{at}, edge {e}, bin {bin}: {got} against {want}"
                );
            }
        }
    }
}

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
    let space = showcase_nofog();
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
            let mut arc_bins = ArcBins::new(x, &tables.edges, n, bins);
            for k in 0..n {
                let u = (k as f64 + 0.5) / n as f64;
                // The drawn point and those taken every time, the same
                // grid for both numbers (the sum's expectation is the sum
                // of theirs).
                let stratum = if all { Stratum::All } else { Stratum::Moving };
                space.edge_points(x, stratum, Some((u, 1.0)), u, |_| true, |b| arc_bins.add(b));
            }
            // Every edge here is a discontinuity from everywhere (open, or
            // a reflector's crease): each must be drawn.
            let drawn = tree.edges().iter().chain(&tables.lamp_set[all as usize]);
            arc_bins.check(drawn, &format!("x {x}, all {all}"));
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
    let space = showcase_nofog();
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
                    let arc = angle(x, edge.a, edge.b);
                    assert!((b.inv_pdf - arc).abs() < 1e-12 * arc);
                    let alpha = angle(x, edge.a, b.q);
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
            let arc = angle(x, edge.a, edge.b);
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
    let space = showcase_nofog();
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
        let mut arc_bins = ArcBins::new(x, &tables.edges, n, bins);
        for k in 0..n {
            let u = (k as f64 + 0.5) / n as f64;
            let u_pick = ((k % picks) as f64 + 0.5) / picks as f64;
            space.split_points(x, &view, 1, [u, u, u_pick], |b| arc_bins.add(b));
        }
        let drawn = tables.all_drawn.edges().iter().chain(&tables.lamp_set[1]);
        arc_bins.check(drawn, &format!("x {x}"));
    }
}
