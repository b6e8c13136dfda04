//! How a boundary term splits the edges among the slots it serves: one
//! stratum per mesh of an own parameter, and the rest (book: chapter
//! "Three dimensions", section "Silhouette edges", *Which edges*).
use super::super::space::Space;
use crate::path::{BoundaryPoint, BoundaryView};
use glam::DVec3;

/// The edges a boundary term covers: all of them, those of the moving
/// meshes, or one mesh's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Stratum {
    /// Every edge.
    All,
    /// The edges of the meshes some parameter moves.
    Moving,
    /// The edges of mesh `k`.
    Shape(u32),
}

/// How a boundary term covers its edges ([`Space::edge_strata`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Strata {
    /// No edge moves for any slot.
    None,
    /// One stratum covers them all.
    One(Stratum),
    /// One stratum per mesh of the own parameters, and the rest if some
    /// slot (`n_all` of them) sees every edge move.
    Mixed { n_all: usize },
}

impl Space {
    // ANCHOR: edge_strata
    /// How the boundary term at a vertex splits its edges (see
    /// [`BoundaryView`]): a slot whose vertex or frame moves needs every
    /// edge, a parameter only its own mesh's. With one kind of need, one
    /// stratum as before (all edges; the moving meshes' when one mesh's
    /// parameters are all that need them). Otherwise the edges are split
    /// into strata, one per mesh moved by a parameter of `view.own`, and
    /// the rest (every other edge, if some slot sees all move): every
    /// stratum's points taken every time are taken, the one drawn point
    /// comes from a stratum drawn ([`Space::split_points`]). A few edges of
    /// a small moving mesh then get the draws their parameters need, not
    /// their share of the estimated contribution among thousands.
    #[inline]
    pub(super) fn edge_strata(&self, view: &BoundaryView) -> Strata {
        let tables = self.edge_tables();
        let n_all = view.all.len();
        let (mut n_own, mut single) = (0, None);
        for (k, _) in self.mesh_strata(view, n_all) {
            n_own += 1;
            single = Some(k);
        }
        match (n_all, n_own) {
            (0, 0) => Strata::None,
            (_, 0) => Strata::One(Stratum::All),
            // The moving meshes' tree when it is this mesh's.
            (0, 1) => match single {
                Some(k)
                    if tables.moving_drawn.edges().len()
                        == tables.shape_drawn[k as usize].edges().len() =>
                {
                    Strata::One(Stratum::Moving)
                }
                Some(k) => Strata::One(Stratum::Shape(k)),
                None => Strata::None,
            },
            _ => Strata::Mixed { n_all },
        }
    }

    /// The boundary points at `x` under [`Space::edge_strata`]'s split
    /// (`Strata::Mixed`), passed to `f`: every stratum's points taken
    /// every time (near-certain terms such as a shadow's edge on the lamp
    /// are not left to a draw), and the one drawn point (`u_draw`) from the
    /// stratum drawn with `u_pick`, its density times that stratum's
    /// probability. The rest stratum is every edge but the own meshes'.
    #[inline]
    pub(super) fn split_points(
        &self,
        x: DVec3,
        view: &BoundaryView,
        n_all: usize,
        [u_draw, u_set, u_pick]: [f64; 3],
        mut f: impl FnMut(BoundaryPoint<DVec3>),
    ) {
        let (chosen, share) = self.pick_stratum(view, n_all, u_pick);
        let own = |k: u32| !view.own.and(self.shape_params[k as usize]).is_empty();
        let mut take = |stratum: Stratum| {
            let draw = (stratum == chosen).then_some((u_draw, share));
            let keep = |k: u32| stratum != Stratum::All || !own(k);
            self.edge_points(x, stratum, draw, u_set, keep, &mut f);
        };
        if n_all > 0 {
            take(Stratum::All);
        }
        for (k, _) in self.mesh_strata(view, n_all) {
            take(Stratum::Shape(k));
        }
    }

    /// The stratum of [`Space::edge_strata`]'s split whose point is drawn,
    /// drawn with `u`, and its probability: each mesh's in proportion to
    /// the slots it serves (its own parameters and every slot that sees
    /// all), the rest's to the slots that see all.
    #[inline]
    fn pick_stratum(&self, view: &BoundaryView, n_all: usize, u: f64) -> (Stratum, f64) {
        let total = self.mesh_strata(view, n_all).map(|(_, w)| w).sum::<f64>() + n_all as f64;
        let mut s = u * total;
        let mut last = (Stratum::All, n_all as f64 / total);
        for (k, w) in self.mesh_strata(view, n_all) {
            last = (Stratum::Shape(k), w / total);
            if s < w {
                return last;
            }
            s -= w;
        }
        if n_all > 0 {
            (Stratum::All, n_all as f64 / total)
        } else {
            last
        }
    }

    /// The meshes' strata of [`Space::edge_strata`]'s split, each once (at
    /// its first own parameter), with the number of slots it serves.
    #[inline]
    fn mesh_strata<'a>(
        &'a self,
        view: &'a BoundaryView,
        n_all: usize,
    ) -> impl Iterator<Item = (u32, f64)> + 'a {
        let tables = self.edge_tables();
        view.own.iter().filter_map(move |j| {
            let k = self.scene.parameter_shape(j);
            let params = view.own.and(self.shape_params[k as usize]);
            (params.iter().next() == Some(j) && tables.shape_edges[k as usize] > 0)
                .then(|| (k, (params.len() + n_all) as f64))
        })
    }

    // ANCHOR_END: edge_strata
}
