//! The BVH against the linear scan: the same hit, bit for bit, on random
//! and adversarial scenes at every scale.
use super::*;
use crate::flat::geometry::{LinearScan, direction};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;

fn seg(a: DVec2, b: DVec2) -> Segment {
    Segment { a, b }
}

/// `n` random segments in `[−1, 1]²`, lengths from 10⁻³ to 1, a tenth
/// of them axis-aligned.
fn random_segments(rng: &mut Xoshiro256PlusPlus, n: usize) -> Vec<Segment> {
    (0..n)
        .map(|i| {
            let a = DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            let len = 10f64.powf(rng.random_range(-3.0..0.0));
            let phi = match i % 20 {
                0 => 0.0,
                1 => TAU / 4.0,
                _ => rng.random_range(0.0..TAU),
            };
            seg(a, a + len * direction(phi))
        })
        .collect()
}

/// Checks `closest_hit` and `any_hit` of `bvh` against `scan` for one
/// query, exactly; returns whether it hits.
fn agree(bvh: &SegmentBvh, scan: &LinearScan, q: (DVec2, DVec2, f64, u32)) -> bool {
    let (o, d, t_max, skip) = q;
    let want = scan.closest_hit(o, d, t_max, skip);
    assert_eq!(bvh.closest_hit(o, d, t_max, skip), want, "closest {q:?}");
    assert_eq!(bvh.any_hit(o, d, t_max, skip), want.is_some(), "any {q:?}");
    assert_eq!(
        scan.any_hit(o, d, t_max, skip),
        want.is_some(),
        "scan {q:?}"
    );
    want.is_some()
}

/// 10⁴ random queries on `segments`: random origins (in and beyond the
/// scene), origins on a segment (skipping it or not), random `t_max`
/// and `skip`, unit and non-unit directions. Returns the hits seen.
fn random_queries(segments: &[Segment], seed: u64) -> usize {
    let scan = LinearScan::new(segments.to_vec());
    let bvh = SegmentBvh::new(segments.to_vec());
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let n = segments.len() as u32;
    let mut hits = 0;
    for k in 0..10_000 {
        let (origin, skip) = if k % 2 == 0 {
            let o = DVec2::new(rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5));
            let skip = if k % 6 == 0 {
                rng.random_range(0..n)
            } else {
                NO_SEGMENT
            };
            (o, skip)
        } else {
            let i = rng.random_range(0..n);
            let s = segments[i as usize];
            let o = s.a + rng.random_range(0.0..=1.0) * (s.b - s.a);
            (o, if k % 4 == 1 { i } else { NO_SEGMENT })
        };
        let dir = match k % 10 {
            3 => DVec2::X,
            5 => -DVec2::Y,
            7 => rng.random_range(0.1..10.0) * direction(rng.random_range(0.0..TAU)),
            _ => direction(rng.random_range(0.0..TAU)),
        };
        let t_max = match k % 3 {
            0 => f64::INFINITY,
            _ => rng.random_range(0.0..2.0),
        };
        hits += usize::from(agree(&bvh, &scan, (origin, dir, t_max, skip)));
    }
    hits
}

#[test]
fn random_scenes_agree_with_the_linear_scan() {
    for seed in 0..3 {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(100 + seed);
        let segments = random_segments(&mut rng, 1000);
        let hits = random_queries(&segments, seed);
        assert!(hits > 5000, "{hits} hits: the test exercises too few");
    }
}

#[test]
fn far_moved_and_scaled_scenes_agree() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    let unit = random_segments(&mut rng, 1000);
    for (scale, shift) in [
        (1e150, 0.0),
        (1e-100, 0.0),
        (1.0, 1e8),
        (1e-3, -1e5),
        (3e7, 1e9),
        (1e307, 0.0),
    ] {
        let segments: Vec<Segment> = unit
            .iter()
            .map(|s| seg(s.a * scale + shift, s.b * scale + shift))
            .collect();
        let scan = LinearScan::new(segments.clone());
        let bvh = SegmentBvh::new(segments.clone());
        let mut hits = 0;
        for k in 0..2000 {
            let i = rng.random_range(0..segments.len());
            let s = segments[i];
            let o = s.a + rng.random_range(0.0..=1.0) * (s.b - s.a);
            let u = direction(rng.random_range(0.0..TAU));
            let skip = if k % 2 == 0 { i as u32 } else { NO_SEGMENT };
            // Unit directions (t in scene units) and directions of the
            // scene's size (t of order 1, above T_MIN at any scale).
            hits += usize::from(agree(&bvh, &scan, (o, u, f64::INFINITY, skip)));
            hits += usize::from(agree(&bvh, &scan, (o, u, scale * 0.3, skip)));
            hits += usize::from(agree(&bvh, &scan, (o, scale * u, 0.3, skip)));
        }
        // At 10^307 the f64 test itself overflows: agreement on misses.
        assert!(scale > 1e300 || hits > 1000, "{hits} hits at scale {scale}");
    }
}

#[test]
fn polygon_vertices_go_to_the_lowest_index() {
    // A wavy 200-gon; rays from inside aimed exactly at vertices, where
    // two segments meet at (nearly) the same t.
    let n = 200;
    let v: Vec<DVec2> = (0..n)
        .map(|i| {
            let phi = TAU * i as f64 / n as f64;
            (1.0 + 0.2 * (7.0 * phi).sin()) * direction(phi)
        })
        .collect();
    let segments: Vec<Segment> = (0..n).map(|i| seg(v[i], v[(i + 1) % n])).collect();
    let scan = LinearScan::new(segments.clone());
    let bvh = SegmentBvh::new(segments.clone());
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(3);
    let mut ties = 0;
    for k in 0..4000 {
        let o = 0.5 * DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let d = v[k % n] - o; // not unit
        let want = scan.closest_hit(o, d, f64::INFINITY, NO_SEGMENT);
        let [before, after] = [(k + n - 1) % n, k % n].map(|i| segments[i].intersect(o, d));
        ties += usize::from(before.is_some() && before == after);
        assert!(want.is_some());
        agree(&bvh, &scan, (o, d, f64::INFINITY, NO_SEGMENT));
    }
    assert!(
        ties > 100,
        "only {ties} exact ties: the test misses its point"
    );
}

#[test]
fn axis_aligned_grids_and_axis_rays_agree() {
    // Horizontal and vertical unit segments on an integer grid: boxes
    // of zero width, rays along the axes and along grid lines.
    let mut segments = Vec::new();
    for i in -5..5 {
        for j in -5..5 {
            let p = DVec2::new(i as f64, j as f64);
            segments.push(seg(p, p + DVec2::X));
            segments.push(seg(p, p + DVec2::Y));
        }
    }
    let scan = LinearScan::new(segments.clone());
    let bvh = SegmentBvh::new(segments);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    for k in 0..4000 {
        let o = match k % 3 {
            0 => DVec2::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0)),
            1 => DVec2::new(rng.random_range(-6..6) as f64, rng.random_range(-6.0..6.0)),
            _ => DVec2::new(
                rng.random_range(-6.0..6.0),
                rng.random_range(-6..6) as f64 + 0.5,
            ),
        };
        let d = [DVec2::X, -DVec2::X, DVec2::Y, -DVec2::Y][k % 4];
        for t_max in [f64::INFINITY, 2.5, 1.0] {
            agree(&bvh, &scan, (o, d, t_max, NO_SEGMENT));
        }
    }
}

#[test]
fn degenerate_lists_and_queries() {
    let one = vec![seg(DVec2::new(1.0, -1.0), DVec2::new(1.0, 1.0))];
    let scan = LinearScan::new(one.clone());
    let bvh = SegmentBvh::new(one);
    for q in [
        (DVec2::ZERO, DVec2::X, f64::INFINITY, NO_SEGMENT),
        (DVec2::ZERO, DVec2::X, f64::INFINITY, 0),
        (DVec2::ZERO, DVec2::X, 1.0, NO_SEGMENT),
        (DVec2::ZERO, DVec2::X, f64::NAN, NO_SEGMENT),
        (DVec2::ZERO, DVec2::ZERO, f64::INFINITY, NO_SEGMENT),
        (
            DVec2::ZERO,
            DVec2::new(1e-300, 1e-301),
            f64::INFINITY,
            NO_SEGMENT,
        ),
        (
            DVec2::ZERO,
            DVec2::new(1e300, 1e299),
            f64::INFINITY,
            NO_SEGMENT,
        ),
        (DVec2::new(-1e20, 0.0), DVec2::X, f64::INFINITY, NO_SEGMENT),
        (
            DVec2::new(f64::NAN, 0.0),
            DVec2::X,
            f64::INFINITY,
            NO_SEGMENT,
        ),
        (
            DVec2::ZERO,
            DVec2::new(f64::INFINITY, 0.0),
            f64::INFINITY,
            NO_SEGMENT,
        ),
    ] {
        agree(&bvh, &scan, q);
    }
    let empty = SegmentBvh::new(Vec::new());
    assert_eq!(
        empty.closest_hit(DVec2::ZERO, DVec2::X, 1.0, NO_SEGMENT),
        None
    );
    let odd = vec![
        seg(DVec2::new(f64::NAN, 0.0), DVec2::ONE),
        seg(DVec2::new(2.0, -1.0), DVec2::new(2.0, 1.0)),
        seg(DVec2::ONE, DVec2::ONE),
    ];
    let bvh = SegmentBvh::new(odd.clone());
    let scan = LinearScan::new(odd);
    agree(
        &bvh,
        &scan,
        (DVec2::ZERO, DVec2::X, f64::INFINITY, NO_SEGMENT),
    );
    agree(
        &bvh,
        &scan,
        (DVec2::ZERO, DVec2::ONE, f64::INFINITY, NO_SEGMENT),
    );
}
