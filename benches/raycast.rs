//! Closest-hit throughput of the flatland ray casters: `SegmentBvh` (obvhs
//! BVH) against `LinearScan`.
//!
//! ```text
//! cargo bench --bench raycast                 # everything, about 1 min
//! cargo bench --bench raycast -- 10000        # the large scene only
//! cargo bench --bench raycast -- crossover    # the small scenes only
//! ```
//!
//! - `raycast/closest_hit/10000`: a closed wavy polygon of 10⁴ vertices
//!   (`r = 1 + 0.1 sin 12φ`) around three small shapes (a square, a
//!   triangle, a hexagon: 10 013 segments), [`RAYS`] rays per iteration
//!   from random points within radius 0.6 of the centre, random directions;
//!   `bvh` vs `linear`, throughput in rays per second. Also `any_hit` with
//!   `t_max = 0.5` (half the rays blocked) and the BVH's build time.
//! - `raycast/crossover/{4..128}`: the wavy polygon alone with n vertices,
//!   the same rays: below which n the linear scan wins.
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use geosens::flat::bvh::SegmentBvh;
use geosens::flat::geometry::{LinearScan, NO_SEGMENT, RayCast, Segment, direction};
use glam::DVec2;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;
use std::hint::black_box;
use std::time::Duration;

/// Rays per iteration.
const RAYS: usize = 1024;

/// The closed polygon through `vertices`.
fn polygon(vertices: &[DVec2]) -> impl Iterator<Item = Segment> + '_ {
    let n = vertices.len();
    (0..n).map(move |i| Segment {
        a: vertices[i],
        b: vertices[(i + 1) % n],
    })
}

/// A regular `n`-gon of radius `r` about `c`.
fn regular(n: usize, c: DVec2, r: f64) -> Vec<DVec2> {
    (0..n)
        .map(|i| c + r * direction(TAU * i as f64 / n as f64))
        .collect()
}

/// The wavy polygon with `n` vertices.
fn wavy(n: usize) -> Vec<Segment> {
    let v: Vec<DVec2> = (0..n)
        .map(|i| {
            let phi = TAU * i as f64 / n as f64;
            (1.0 + 0.1 * (12.0 * phi).sin()) * direction(phi)
        })
        .collect();
    polygon(&v).collect()
}

/// The wavy polygon with `n` vertices around three small shapes.
fn scene(n: usize) -> Vec<Segment> {
    let mut s = wavy(n);
    s.extend(polygon(&regular(4, DVec2::new(0.4, 0.1), 0.1)));
    s.extend(polygon(&regular(3, DVec2::new(-0.3, 0.35), 0.12)));
    s.extend(polygon(&regular(6, DVec2::new(-0.1, -0.45), 0.08)));
    s
}

/// [`RAYS`] rays (origin, unit direction) from within radius 0.6.
fn rays(seed: u64) -> Vec<(DVec2, DVec2)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..RAYS)
        .map(|_| {
            let r = 0.6 * rng.random::<f64>().sqrt();
            let o = r * direction(rng.random_range(0.0..TAU));
            (o, direction(rng.random_range(0.0..TAU)))
        })
        .collect()
}

/// Sum of the closest-hit distances of `rays` (so nothing is optimised away).
fn trace(caster: &dyn RayCast, rays: &[(DVec2, DVec2)]) -> f64 {
    rays.iter()
        .filter_map(|&(o, d)| caster.closest_hit(o, d, f64::INFINITY, NO_SEGMENT))
        .map(|h| h.t)
        .sum()
}

/// How many of `rays` are blocked within `t_max`.
fn blocked(caster: &dyn RayCast, rays: &[(DVec2, DVec2)], t_max: f64) -> usize {
    rays.iter()
        .filter(|&&(o, d)| caster.any_hit(o, d, t_max, NO_SEGMENT))
        .count()
}

fn large(c: &mut Criterion) {
    let segments = scene(10_000);
    let bvh = SegmentBvh::new(segments.clone());
    let linear = LinearScan::new(segments.clone());
    let rays = rays(1);
    assert_eq!(trace(&bvh, &rays), trace(&linear, &rays));
    let mut g = c.benchmark_group("raycast/closest_hit/10000");
    g.throughput(Throughput::Elements(RAYS as u64))
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.bench_function("bvh", |b| b.iter(|| trace(black_box(&bvh), &rays)));
    g.bench_function("linear", |b| b.iter(|| trace(black_box(&linear), &rays)));
    g.finish();

    let mut g = c.benchmark_group("raycast/any_hit/10000");
    g.throughput(Throughput::Elements(RAYS as u64))
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.bench_function("bvh", |b| b.iter(|| blocked(black_box(&bvh), &rays, 0.5)));
    g.bench_function("linear", |b| {
        b.iter(|| blocked(black_box(&linear), &rays, 0.5))
    });
    g.finish();

    let mut g = c.benchmark_group("raycast/build/10000");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.bench_function("bvh", |b| {
        b.iter(|| SegmentBvh::new(black_box(segments.clone())))
    });
    g.finish();
}

fn crossover(c: &mut Criterion) {
    let rays = rays(2);
    for n in [4, 8, 16, 32, 64, 128] {
        let segments = wavy(n);
        let bvh = SegmentBvh::new(segments.clone());
        let linear = LinearScan::new(segments);
        assert_eq!(trace(&bvh, &rays), trace(&linear, &rays));
        let mut g = c.benchmark_group(format!("raycast/crossover/{n}"));
        g.throughput(Throughput::Elements(RAYS as u64))
            .sample_size(30)
            .warm_up_time(Duration::from_millis(300))
            .measurement_time(Duration::from_secs(1));
        g.bench_function("bvh", |b| b.iter(|| trace(black_box(&bvh), &rays)));
        g.bench_function("linear", |b| b.iter(|| trace(black_box(&linear), &rays)));
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().without_plots();
    targets = large, crossover
}
criterion_main!(benches);
