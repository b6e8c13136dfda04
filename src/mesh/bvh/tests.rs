//! The triangle test on known cases, the BVH against the linear scan (the
//! same hit, bit for bit, on random and adversarial scenes at every scale),
//! and watertightness: rays through the edges and vertices of closed
//! meshes never slip through.
use super::*;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

type Tri = [DVec3; 3];

/// A uniformly random unit vector.
fn unit(rng: &mut Xoshiro256PlusPlus) -> DVec3 {
    let z: f64 = rng.random_range(-1.0..1.0);
    let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A point uniformly in the cube `[−h, h]³`.
fn in_cube(rng: &mut Xoshiro256PlusPlus, h: f64) -> DVec3 {
    DVec3::new(
        rng.random_range(-h..h),
        rng.random_range(-h..h),
        rng.random_range(-h..h),
    )
}

use crate::mesh::cases::icosphere;

/// The triangles of an indexed mesh, scaled by `s` and moved by `shift`.
fn triangles(v: &[DVec3], f: &[[usize; 3]], s: f64, shift: DVec3) -> Vec<Tri> {
    f.iter().map(|t| t.map(|i| v[i] * s + shift)).collect()
}

/// `n` random triangles in `[−1, 1]³`, sizes from 10⁻³ to 1, a tenth of
/// them axis-aligned.
fn random_triangles(rng: &mut Xoshiro256PlusPlus, n: usize) -> Vec<Tri> {
    (0..n)
        .map(|i| {
            let a = in_cube(rng, 1.0);
            let size = 10f64.powf(rng.random_range(-3.0..0.0));
            let (e1, e2) = if i % 10 == 0 {
                (
                    DVec3::X * size,
                    DVec3::Y * size * rng.random_range(0.2..1.0),
                )
            } else {
                (unit(rng) * size, unit(rng) * size)
            };
            [a, a + e1, a + e2]
        })
        .collect()
}

/// A query: origin, direction, `t_max`, `skip`.
type Query = (DVec3, DVec3, f64, u32);

/// Checks `closest_hit` and `any_hit` of `bvh` against `scan` for one
/// query, exactly; returns the hit.
fn agree(bvh: &TriangleBvh, scan: &TriangleBvh, q: Query) -> Option<(f64, u32)> {
    let (o, d, t_max, skip) = q;
    let want = scan.closest_hit(o, d, t_max, skip);
    let got = bvh.closest_hit(o, d, t_max, skip);
    assert_eq!(
        got.map(|(t, i)| (t.to_bits(), i)),
        want.map(|(t, i)| (t.to_bits(), i)),
        "closest {q:?}"
    );
    assert_eq!(bvh.any_hit(o, d, t_max, skip), want.is_some(), "any {q:?}");
    assert_eq!(
        scan.any_hit(o, d, t_max, skip),
        want.is_some(),
        "scan {q:?}"
    );
    want
}

#[test]
fn intersect_known_cases() {
    let tri = [
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(0.0, 1.0, 1.0),
    ];
    let o = DVec3::new(0.25, 0.25, 0.0);
    assert_eq!(intersect(&tri, o, DVec3::Z), Some(1.0));
    assert_eq!(intersect(&tri, o, 4.0 * DVec3::Z), Some(0.25));
    assert_eq!(intersect(&tri, o, -DVec3::Z), None); // behind
    assert_eq!(intersect(&tri, o, DVec3::X), None); // parallel
    assert_eq!(intersect(&tri, DVec3::new(0.6, 0.6, 0.0), DVec3::Z), None);
    // Edges and vertices included, either winding.
    let rev = [tri[0], tri[2], tri[1]];
    for p in [
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.5, 0.5, 0.0),
        DVec3::new(0.0, 0.3, 0.0),
        DVec3::ZERO,
        DVec3::new(1.0, 0.0, 0.0),
    ] {
        assert_eq!(intersect(&tri, p, DVec3::Z), Some(1.0), "{p}");
        assert_eq!(intersect(&rev, p, DVec3::Z), Some(1.0), "{p}");
    }
    // Oblique, non-unit direction.
    let t = intersect(&tri, DVec3::new(0.0, 0.0, -1.0), DVec3::new(0.1, 0.2, 1.0));
    assert_eq!(t, Some(2.0));
    // Starting on the triangle, or nearer than T_MIN times its size.
    assert_eq!(intersect(&tri, DVec3::new(0.2, 0.2, 1.0), DVec3::Z), None);
    let near = DVec3::new(0.2, 0.2, 1.0 - 1e-13);
    assert_eq!(intersect(&tri, near, DVec3::Z), None);
    let just = DVec3::new(0.2, 0.2, 1.0 - 1e-11);
    assert!(intersect(&tri, just, DVec3::Z).is_some());
    // Degenerate triangles and directions.
    let flat = [tri[0], tri[1], 0.5 * (tri[0] + tri[1])];
    assert_eq!(intersect(&flat, o, DVec3::Z), None);
    assert_eq!(intersect(&tri, o, DVec3::ZERO), None);
    assert_eq!(intersect(&tri, o, DVec3::new(f64::NAN, 0.0, 1.0)), None);
}

/// Random queries on `tris`: origins in, around and far from the scene
/// (`centre`, half-size `h`), origins on a triangle (skipping it or not), random `t_max`
/// and `skip`, unit and non-unit directions. Returns the hits seen.
fn random_queries(tris: &[Tri], centre: DVec3, h: f64, n: usize, seed: u64) -> usize {
    let scan = TriangleBvh::linear(tris.to_vec());
    let bvh = TriangleBvh::new(tris.to_vec());
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let count = tris.len() as u32;
    let mut hits = 0;
    for k in 0..n {
        let (origin, skip) = match k % 4 {
            0 | 2 => {
                let skip = if k % 8 == 0 {
                    rng.random_range(0..count)
                } else {
                    NONE
                };
                (centre + in_cube(&mut rng, 1.5 * h), skip)
            }
            1 => {
                let i = rng.random_range(0..count);
                let [a, b, c] = tris[i as usize];
                let (u, v): (f64, f64) = (rng.random(), rng.random());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                let o = a + u * (b - a) + v * (c - a);
                (o, if k % 8 == 1 { i } else { NONE })
            }
            _ => (centre + in_cube(&mut rng, 1e6 * h), NONE),
        };
        let dir = match k % 10 {
            3 => DVec3::X,
            5 => -DVec3::Z,
            7 => rng.random_range(0.1..10.0) * unit(&mut rng),
            9 if k % 4 == 3 => centre + in_cube(&mut rng, h) - origin, // far, aimed at the scene
            _ => unit(&mut rng),
        };
        let t_max = match k % 3 {
            0 => f64::INFINITY,
            _ => rng.random_range(0.0..2.0 * h),
        };
        hits += usize::from(agree(&bvh, &scan, (origin, dir, t_max, skip)).is_some());
    }
    hits
}

#[test]
fn random_scenes_agree_with_the_linear_scan() {
    for seed in 0..3 {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(100 + seed);
        let tris = random_triangles(&mut rng, 2000);
        let hits = random_queries(&tris, DVec3::ZERO, 1.0, 6000, seed);
        assert!(hits > 1500, "{hits} hits: the test exercises too few");
    }
}

#[test]
fn scaled_and_moved_scenes_agree() {
    let (v, f) = icosphere(3);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
    let soup = random_triangles(&mut rng, 500);
    for (scale, shift) in [
        (1e-30, 0.0),
        (1e30, 0.0),
        (1.0, 1e8),
        (1e-3, -1e5),
        (3e7, 1e9),
        (1e-30, 1e-25),
    ] {
        let shift = DVec3::splat(shift);
        let mut tris = triangles(&v, &f, 0.5 * scale, shift);
        tris.extend(soup.iter().map(|t| t.map(|p| p * scale + shift)));
        let scan = TriangleBvh::linear(tris.clone());
        let bvh = TriangleBvh::new(tris.clone());
        let mut hits = 0;
        for k in 0..1500 {
            let o = shift + in_cube(&mut rng, 1.2 * scale);
            let u = unit(&mut rng);
            let skip = if k % 5 == 0 {
                rng.random_range(0..tris.len() as u32)
            } else {
                NONE
            };
            // Unit directions (t in scene units) and directions of the
            // scene's size (t of order 1).
            for q in [
                (o, u, f64::INFINITY, skip),
                (o, u, scale * 0.7, skip),
                (o, scale * u, 0.7, skip),
            ] {
                hits += usize::from(agree(&bvh, &scan, q).is_some());
            }
        }
        assert!(hits > 1000, "{hits} hits at scale {scale}");
        let random = random_queries(&tris, shift, scale, 1500, 9);
        assert!(random > 300, "{random} random hits at scale {scale}");
    }
}

#[test]
fn rays_at_icosphere_edges_and_vertices_never_slip_through() {
    let (v, f) = icosphere(3);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(17);
    let mut edges: Vec<(usize, usize)> = f
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    assert_eq!(edges.len(), 3 * f.len() / 2); // closed
    for (scale, shift) in [(1.0, 0.0), (1e-30, 0.0), (1e30, 0.0), (1.0, 1e6)] {
        let shift = DVec3::splat(shift);
        let tris = triangles(&v, &f, scale, shift);
        let scan = TriangleBvh::linear(tris.clone());
        let bvh = TriangleBvh::new(tris.clone());
        let w: Vec<DVec3> = v.iter().map(|&p| p * scale + shift).collect();
        // Targets exactly at the vertices and on the edges.
        let targets = w.iter().copied().chain(edges.iter().map(|&(a, b)| {
            let s = if rng.random::<bool>() {
                0.5
            } else {
                rng.random()
            };
            w[a] + s * (w[b] - w[a])
        }));
        let targets: Vec<DVec3> = targets.collect();
        for (k, &p) in targets.iter().enumerate() {
            let inside = shift + 0.6 * scale * unit(&mut rng) * rng.random::<f64>();
            let outside =
                p + (p - shift) * rng.random_range(0.5..3.0) + 0.3 * scale * unit(&mut rng);
            for o in [inside, outside, shift] {
                let d = if k % 2 == 0 { p - o } else { (p - o) / scale };
                let hit = agree(&bvh, &scan, (o, d, f64::INFINITY, NONE));
                assert!(hit.is_some(), "slipped through at {p} from {o}");
            }
            // From inside, the target is the first surface crossed.
            let (t, _) = scan.closest_hit(inside, p - inside, 2.0, NONE).unwrap();
            assert!((t - 1.0).abs() < 1e-9, "t = {t}");
        }
        // And any ray from inside, in any direction.
        for _ in 0..3000 {
            let o = shift + 0.9 * scale * unit(&mut rng) * rng.random::<f64>();
            let hit = agree(&bvh, &scan, (o, unit(&mut rng), f64::INFINITY, NONE));
            assert!(hit.is_some(), "escaped from {o}");
        }
    }
}

#[test]
fn axis_rays_through_a_gridded_cube_tie_to_the_lowest_index() {
    // The surface of [−4, 4]³ in unit squares, two triangles each: rays
    // along the axes through grid lines and corners meet exact ties.
    let mut tris = Vec::new();
    for axis in 0..3 {
        for side in [-4.0, 4.0] {
            for i in -4..4 {
                for j in -4..4 {
                    let p = |a: f64, b: f64| {
                        let mut q = DVec3::ZERO;
                        q[axis] = side;
                        q[(axis + 1) % 3] = a;
                        q[(axis + 2) % 3] = b;
                        q
                    };
                    let (a, b) = (i as f64, j as f64);
                    tris.push([p(a, b), p(a + 1.0, b), p(a + 1.0, b + 1.0)]);
                    tris.push([p(a, b), p(a + 1.0, b + 1.0), p(a, b + 1.0)]);
                }
            }
        }
    }
    let scan = TriangleBvh::linear(tris.clone());
    let bvh = TriangleBvh::new(tris.clone());
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(11);
    let mut ties = 0;
    for k in 0..3000 {
        let mut o = in_cube(&mut rng, 3.4); // |round| ≤ 3: inside
        // Integer coordinates put the ray on grid lines or through corners.
        for i in 0..3 {
            if (k >> i) % 2 == 0 {
                o[i] = o[i].round();
            }
        }
        let d = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ][k % 6];
        for t_max in [f64::INFINITY, 4.0, 1.0] {
            agree(&bvh, &scan, (o, d, t_max, NONE));
        }
        let (t, i) = agree(&bvh, &scan, (o, d, f64::INFINITY, NONE)).expect("closed");
        let all = tris
            .iter()
            .enumerate()
            .filter(|(_, tri)| intersect(tri, o, d) == Some(t))
            .count();
        ties += usize::from(all > 1);
        assert!(
            all >= 1
                && tris[..i as usize]
                    .iter()
                    .all(|tri| intersect(tri, o, d) != Some(t))
        );
    }
    assert!(ties > 500, "only {ties} ties: the test misses its point");
}

#[test]
fn skip_and_t_max_are_respected() {
    let (v, f) = icosphere(2);
    let mut tris = triangles(&v, &f, 1.0, DVec3::ZERO);
    tris.extend(triangles(&v, &f, 0.5, DVec3::ZERO)); // a sphere inside
    let scan = TriangleBvh::linear(tris.clone());
    let bvh = TriangleBvh::new(tris.clone());
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(23);
    for _ in 0..500 {
        let o = 0.3 * unit(&mut rng);
        let d = unit(&mut rng);
        let (t, i) = agree(&bvh, &scan, (o, d, f64::INFINITY, NONE)).unwrap();
        assert!(t > 0.15 && t < 0.85 && (i as usize) >= f.len(), "{t} {i}");
        // Skipping the hit finds the outer sphere.
        let (t2, i2) = agree(&bvh, &scan, (o, d, f64::INFINITY, i)).unwrap();
        assert!(t2 > t && (i2 as usize) < f.len());
        // t < t_max strictly.
        assert_eq!(agree(&bvh, &scan, (o, d, t, NONE)), None);
        let above = t.next_up();
        assert_eq!(agree(&bvh, &scan, (o, d, above, NONE)), Some((t, i)));
        assert_eq!(agree(&bvh, &scan, (o, d, t2, i)), None);
        // From the hit point, skipping its triangle, on to the outer sphere.
        let p = o + t * d;
        let (t3, i3) = agree(&bvh, &scan, (p, d, f64::INFINITY, i)).unwrap();
        assert!((i3 as usize) < f.len() && (t3 - (t2 - t)).abs() < 1e-9);
    }
}

#[test]
fn degenerate_lists_and_queries() {
    let (v, f) = icosphere(1);
    let tris = triangles(&v, &f, 1.0, DVec3::ZERO);
    let scan = TriangleBvh::linear(tris.clone());
    let bvh = TriangleBvh::new(tris);
    assert_eq!((bvh.len(), scan.len()), (80, 80));
    for q in [
        (DVec3::ZERO, DVec3::X, f64::INFINITY, NONE),
        (DVec3::ZERO, DVec3::X, 0.5, NONE),
        (DVec3::ZERO, DVec3::X, 0.0, NONE),
        (DVec3::ZERO, DVec3::X, -1.0, NONE),
        (DVec3::ZERO, DVec3::X, f64::NAN, NONE),
        (DVec3::ZERO, DVec3::ZERO, f64::INFINITY, NONE),
        (
            DVec3::ZERO,
            DVec3::new(1e-300, 1e-301, 0.0),
            f64::INFINITY,
            NONE,
        ),
        (
            DVec3::ZERO,
            DVec3::new(1e300, 1e299, 0.0),
            f64::INFINITY,
            NONE,
        ),
        (
            DVec3::ZERO,
            DVec3::new(1e-320, 0.0, 0.0),
            f64::INFINITY,
            NONE,
        ),
        (DVec3::new(-1e20, 0.0, 0.0), DVec3::X, f64::INFINITY, NONE),
        (DVec3::new(-1e20, 0.1, 0.0), DVec3::X, f64::INFINITY, NONE),
        (DVec3::new(-3.0, 0.0, 0.0), DVec3::X, f64::INFINITY, NONE),
        (DVec3::new(-3.0, 5.0, 0.0), DVec3::X, f64::INFINITY, NONE),
        (
            DVec3::new(f64::NAN, 0.0, 0.0),
            DVec3::X,
            f64::INFINITY,
            NONE,
        ),
        (
            DVec3::ZERO,
            DVec3::new(f64::INFINITY, 0.0, 0.0),
            f64::INFINITY,
            NONE,
        ),
    ] {
        agree(&bvh, &scan, q);
    }
    let empty = TriangleBvh::new(Vec::new());
    assert!(empty.is_empty() && TriangleBvh::linear(Vec::new()).is_empty());
    assert_eq!(empty.closest_hit(DVec3::ZERO, DVec3::X, 1.0, NONE), None);
    assert!(!empty.any_hit(DVec3::ZERO, DVec3::X, 1.0, NONE));
    // Non-finite triangles are never hit, small and large lists alike.
    let wall = |x: f64| {
        [
            DVec3::new(x, -1.0, -1.0),
            DVec3::new(x, 1.0, -1.0),
            DVec3::new(x, 0.0, 1.0),
        ]
    };
    let mut odd = vec![
        [DVec3::new(f64::NAN, 0.0, 0.0), DVec3::Y, DVec3::Z],
        wall(2.0),
        [DVec3::ONE; 3],
        [
            DVec3::new(f64::INFINITY, -1.0, -1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(1.0, 0.0, 1.0),
        ],
    ];
    for n in [0, 40] {
        odd.extend((0..n).map(|i| wall(3.0 + i as f64)));
        let bvh = TriangleBvh::new(odd.clone());
        let scan = TriangleBvh::linear(odd.clone());
        assert_eq!(bvh.len(), odd.len());
        for d in [DVec3::X, DVec3::ONE, -DVec3::X] {
            agree(&bvh, &scan, (DVec3::ZERO, d, f64::INFINITY, NONE));
        }
        assert_eq!(
            bvh.closest_hit(DVec3::ZERO, DVec3::X, f64::INFINITY, NONE),
            Some((2.0, 1))
        );
        // Only non-finite triangles: never hit.
        let nan = TriangleBvh::new(vec![odd[0]; n + 1]);
        assert!(!nan.any_hit(DVec3::ZERO, DVec3::X, f64::INFINITY, NONE));
    }
}
