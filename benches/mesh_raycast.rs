//! Ray casting on triangle meshes: `TriangleBvh` (obvhs's tree, `f64`
//! watertight triangle test) against obvhs's own `f32` traversal and
//! triangle test, and against `TriangleBvh::linear` on small meshes.
//!
//! ```text
//! cargo bench --bench mesh_raycast                 # everything, about 1.5 min
//! cargo bench --bench mesh_raycast -- 106496       # the large scene only
//! cargo bench --bench mesh_raycast -- crossover    # the small meshes only
//! ```
//!
//! - `mesh_raycast/closest_hit/106496`: a unit icosphere subdivided 6 times
//!   (81 920 triangles) around a torus (`R = 0.5`, `r = 0.15`, 128 × 96
//!   quads, 24 576 triangles), [`RAYS`] rays per iteration from random
//!   points in `[−1.1, 1.1]³` in random directions; `bvh` is
//!   `TriangleBvh::closest_hit`, `obvhs` is `Bvh2::ray_traverse` with
//!   obvhs's `f32` `Triangle::intersect` (triangles stored in BVH order, as
//!   `TriangleBvh` stores them). Throughput in rays per second, one core.
//! - `mesh_raycast/any_hit/106496`: the same rays with `t_max = 0.5`
//!   (about half blocked): `TriangleBvh::any_hit` against obvhs's
//!   `ray_traverse_miss`.
//! - `mesh_raycast/build/106496`: `TriangleBvh::new` against obvhs's
//!   `build_bvh2_from_tris` (both PLOC, `medium_build`).
//! - `mesh_raycast/crossover/{4..512}`: n triangles evenly picked from a
//!   torus of 512 (`R = 0.7`, `r = 0.3`), the same rays, a tree forced at
//!   every size (`bvh`) against `TriangleBvh::linear`:
//!   below which n the scan wins (`geosens::mesh::bvh::LINEAR_BELOW`).
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use geosens::mesh::bvh::TriangleBvh;
use glam::{DVec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;
use std::hint::black_box;
use std::time::Duration;

/// Rays per iteration.
const RAYS: usize = 1024;

/// No triangle to skip.
const NONE: u32 = u32::MAX;

type Tri = [DVec3; 3];

/// The unit icosphere subdivided `n` times (`geosens::mesh::cases`), as
/// triangles.
fn icosphere(n: u32) -> Vec<Tri> {
    let (v, f) = geosens::mesh::cases::icosphere(n);
    f.iter().map(|t| t.map(|i| v[i])).collect()
}

/// A torus about the z axis (radii `big`, `small`) of `nu × nv` quads,
/// two triangles each.
fn torus(big: f64, small: f64, nu: usize, nv: usize) -> Vec<Tri> {
    let p = |i: usize, j: usize| {
        let (u, v) = (
            TAU * (i % nu) as f64 / nu as f64,
            TAU * (j % nv) as f64 / nv as f64,
        );
        let r = big + small * v.cos();
        DVec3::new(r * u.cos(), r * u.sin(), small * v.sin())
    };
    (0..nu)
        .flat_map(|i| {
            (0..nv).flat_map(move |j| {
                let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                [[a, b, c], [a, c, d]]
            })
        })
        .collect()
}

/// The large scene: icosphere(6) around a torus, 106 496 triangles.
fn scene() -> Vec<Tri> {
    let mut s = icosphere(6);
    s.extend(torus(0.5, 0.15, 128, 96));
    s
}

/// [`RAYS`] rays (origin in `[−1.1, 1.1]³`, unit direction).
fn rays(seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..RAYS)
        .map(|_| {
            let o = DVec3::new(
                rng.random_range(-1.1..1.1),
                rng.random_range(-1.1..1.1),
                rng.random_range(-1.1..1.1),
            );
            let z: f64 = rng.random_range(-1.0..1.0);
            let phi: f64 = rng.random_range(0.0..TAU);
            let r = (1.0 - z * z).sqrt();
            (o, DVec3::new(r * phi.cos(), r * phi.sin(), z))
        })
        .collect()
}

/// obvhs alone: its tree over its `f32` triangles, stored in BVH order.
struct Obvhs {
    bvh: obvhs::bvh2::Bvh2,
    tris: Vec<Triangle>,
}

/// `tris` as obvhs's `f32` triangles.
fn f32_tris(tris: &[Tri]) -> Vec<Triangle> {
    tris.iter()
        .map(|t| Triangle {
            v0: t[0].as_vec3a(),
            v1: t[1].as_vec3a(),
            v2: t[2].as_vec3a(),
        })
        .collect()
}

impl Obvhs {
    fn new(tris: &[Tri]) -> Obvhs {
        let tris = f32_tris(tris);
        let bvh = build_bvh2_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let tris = bvh
            .primitive_indices
            .iter()
            .map(|&i| tris[i as usize])
            .collect();
        Obvhs { bvh, tris }
    }

    fn ray(o: DVec3, d: DVec3, t_max: f32) -> Ray {
        Ray::new(o.as_vec3a(), Vec3A::from(d.as_vec3()), 0.0, t_max)
    }

    fn closest(&self, o: DVec3, d: DVec3) -> Option<f32> {
        let mut hit = RayHit::none();
        self.bvh
            .ray_traverse(Obvhs::ray(o, d, f32::INFINITY), &mut hit, |r, id| {
                self.tris[id].intersect(r)
            })
            .then_some(hit.t)
    }

    fn any(&self, o: DVec3, d: DVec3, t_max: f32) -> bool {
        !self
            .bvh
            .ray_traverse_miss(Obvhs::ray(o, d, t_max), |r, id| self.tris[id].intersect(r))
    }
}

/// Sum of the closest-hit distances (so nothing is optimised away).
fn trace(bvh: &TriangleBvh, rays: &[(DVec3, DVec3)]) -> f64 {
    rays.iter()
        .filter_map(|&(o, d)| bvh.closest_hit(o, d, f64::INFINITY, NONE))
        .map(|h| h.0)
        .sum()
}

/// The same with the linear scan.
fn trace_linear(scan: &TriangleBvh, rays: &[(DVec3, DVec3)]) -> f64 {
    rays.iter()
        .filter_map(|&(o, d)| scan.closest_hit(o, d, f64::INFINITY, NONE))
        .map(|h| h.0)
        .sum()
}

/// The same with obvhs alone.
fn trace_obvhs(o: &Obvhs, rays: &[(DVec3, DVec3)]) -> f64 {
    rays.iter()
        .filter_map(|&(p, d)| o.closest(p, d))
        .map(f64::from)
        .sum()
}

fn group<'a>(
    c: &'a mut Criterion,
    name: &str,
    secs: u64,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(secs));
    g
}

fn large(c: &mut Criterion) {
    let tris = scene();
    let n = tris.len();
    let bvh = TriangleBvh::new(tris.clone());
    let ob = Obvhs::new(&tris);
    let rays = rays(1);
    // Both see the same scene: the same hits, distances within f32 noise.
    let (ours, theirs) = (trace(&bvh, &rays), trace_obvhs(&ob, &rays));
    assert!((ours - theirs).abs() < 1e-2 * ours, "{ours} vs {theirs}");
    let blocked = rays
        .iter()
        .filter(|&&(o, d)| bvh.any_hit(o, d, 0.5, NONE))
        .count();
    eprintln!("{n} triangles, {RAYS} rays, {blocked} blocked within 0.5, {bvh:?}");

    let mut g = group(c, &format!("mesh_raycast/closest_hit/{n}"), 4);
    g.throughput(Throughput::Elements(RAYS as u64));
    g.bench_function("bvh", |b| b.iter(|| trace(black_box(&bvh), &rays)));
    g.bench_function("obvhs", |b| b.iter(|| trace_obvhs(black_box(&ob), &rays)));
    g.finish();

    let mut g = group(c, &format!("mesh_raycast/any_hit/{n}"), 4);
    g.throughput(Throughput::Elements(RAYS as u64));
    g.bench_function("bvh", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|&&(o, d)| black_box(&bvh).any_hit(o, d, 0.5, NONE))
                .count()
        })
    });
    g.bench_function("obvhs", |b| {
        b.iter(|| {
            rays.iter()
                .filter(|&&(o, d)| black_box(&ob).any(o, d, 0.5))
                .count()
        })
    });
    g.finish();

    let mut g = group(c, &format!("mesh_raycast/build/{n}"), 8);
    g.sample_size(10);
    g.bench_function("bvh", |b| {
        b.iter(|| TriangleBvh::new(black_box(tris.clone())))
    });
    let f32s = f32_tris(&tris);
    g.bench_function("obvhs", |b| {
        b.iter(|| {
            build_bvh2_from_tris(
                black_box(&f32s),
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        })
    });
    g.finish();
}

fn crossover(c: &mut Criterion) {
    let rays = rays(2);
    let full = torus(0.7, 0.3, 16, 16);
    for n in [4, 8, 12, 16, 24, 32, 64, 512] {
        let tris: Vec<Tri> = full.iter().step_by(512 / n).take(n).copied().collect();
        let bvh = TriangleBvh::with_linear_below(tris.clone(), 0);
        let scan = TriangleBvh::linear(tris);
        assert_eq!(trace(&bvh, &rays), trace_linear(&scan, &rays));
        let mut g = c.benchmark_group(format!("mesh_raycast/crossover/{n}"));
        g.throughput(Throughput::Elements(RAYS as u64))
            .sample_size(30)
            .warm_up_time(Duration::from_millis(300))
            .measurement_time(Duration::from_secs(1));
        g.bench_function("bvh", |b| b.iter(|| trace(black_box(&bvh), &rays)));
        g.bench_function("linear", |b| {
            b.iter(|| trace_linear(black_box(&scan), &rays))
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = large, crossover
}
criterion_main!(benches);
