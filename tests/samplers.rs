//! Every flatland sampler against its density, by Pearson's χ² test as
//! pbrt-v4 (`ChiSquareTest` in `src/pbrt/util/math_test.cpp`) and Mitsuba 3
//! (`mitsuba.chi2`) test theirs: draw 10⁶ samples from a fixed seed, bin
//! them over the sampler's domain, compare the counts with the expected
//! counts (the density integrated over each bin by Gauss–Legendre
//! quadrature, split at the density's kinks), pool the bins of expected
//! count below 5 into one (pbrt's rule), and compute the p-value of the
//! statistic from statrs's χ² law. Each density is also checked to
//! integrate to 1 over its domain.
//!
//! The samplers: free paths (`rng::free_path`, exponential of rate κs), the
//! 2D cosine lobe and the 2D phase functions (isotropic, Henyey–Greenstein
//! for g ∈ {−0.7, 0, 0.3, 0.9}) through the path core's `Lobe` trait,
//! emitter points (their position along the emitters, uniform by length,
//! and their direction seen from a point against `light_pdf`), and the
//! corner selection of rendering's boundary term (`sample_boundary`: each
//! corner's frequency against its density, a mixture with one component per
//! slot of weight / total over the corners that move for it, and `inv_pdf`
//! equal to one over it). Where a warp has a closed-form inverse (the cosine
//! lobe's `θ = asin(2u − 1)`, the wrapped Cauchy law's inverse CDF, the
//! isotropic `θ = 2πu`), a round-trip test maps the drawn direction back to
//! the uniform number the sampler consumed, to 10⁻¹².
//!
//! Bounds: a test fails when p < 10⁻⁴. With the 15 χ² tests here the
//! chance that a correct sampler fails any of them is below 0.2 %
//! (Bonferroni), and the seeds are fixed, so a pass is reproducible. The
//! test `the_chi2_test_has_power` guards the guard: the same machinery must
//! reject free paths tested against a rate 1 % off and Henyey–Greenstein
//! samples of g = 0.3 tested against g = 0.33 (a density ≤ 7 % off).
use geosens::flat::geometry::{Segment, cross, direction, perp};
use geosens::flat::lobe::FlatLobe;
use geosens::flat::space::Plane;
use geosens::flat::{Medium, Motion, Parameter, Phase, Scene, Sensor, Shape, Surface};
use geosens::path::deform::SlotSet;
use geosens::path::walk::{Frame, Vertex};
use geosens::path::{Boundaries, BoundaryView, Geometry, Lobe};
use geosens::rng::{PathRng, free_path, stream};
use glam::DVec2;
use rand::RngExt;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::sync::Arc;

/// Samples per χ² test.
const N: usize = 1_000_000;
/// A χ² test fails below this p-value.
const ALPHA: f64 = 1e-4;
/// Bins of expected count below this are pooled.
const MIN_EXPECTED: f64 = 5.0;

// ---------------------------------------------------------------------------
// The χ² machinery.

/// Pearson's χ² test of `observed` counts against `expected` ones: bins of
/// expected count below 5 are pooled, smallest first, into one bin that
/// grows until it reaches 5 (pbrt-v4's rule); a sample in a bin of expected
/// count 0 fails at once. Returns `(statistic, degrees of freedom, p)`.
fn chi2(observed: &[u64], expected: &[f64]) -> (f64, usize, f64) {
    assert_eq!(observed.len(), expected.len());
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut pooled_obs, mut pooled_exp) = (0.0, 0.0);
    let (mut stat, mut categories) = (0.0, 0usize);
    for i in order {
        let (o, e) = (observed[i] as f64, expected[i]);
        if e == 0.0 {
            if o > 0.0 {
                return (f64::INFINITY, 0, 0.0);
            }
        } else if e < MIN_EXPECTED || (pooled_exp > 0.0 && pooled_exp < MIN_EXPECTED) {
            pooled_obs += o;
            pooled_exp += e;
        } else {
            stat += (o - e).powi(2) / e;
            categories += 1;
        }
    }
    if pooled_exp > 0.0 {
        stat += (pooled_obs - pooled_exp).powi(2) / pooled_exp;
        categories += 1;
    }
    assert!(categories >= 2, "too few bins for a χ² test");
    let dof = categories - 1;
    let p = ChiSquared::new(dof as f64).unwrap().sf(stat);
    (stat, dof, p)
}

/// [`chi2`], printed and asserted at [`ALPHA`]; returns p.
fn assert_fits(name: &str, observed: &[u64], expected: &[f64]) -> f64 {
    let (stat, dof, p) = chi2(observed, expected);
    eprintln!("χ² {name}: {stat:.1} on {dof} dof, p = {p:.3e}");
    assert!(
        p >= ALPHA,
        "{name}: χ² = {stat:.1} on {dof} dof, p = {p:.3e} < {ALPHA:e}"
    );
    p
}

/// Five-point Gauss–Legendre nodes and weights on [−1, 1].
const GAUSS: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// `∫_a^b f`, split at the `breaks` inside (where `f` jumps or has a kink),
/// each piece by composite five-point Gauss–Legendre on 64 panels.
fn integrate(f: &impl Fn(f64) -> f64, a: f64, b: f64, breaks: &[f64]) -> f64 {
    let mut cuts: Vec<f64> = std::iter::once(a)
        .chain(breaks.iter().copied().filter(|&t| t > a && t < b))
        .chain(std::iter::once(b))
        .collect();
    cuts.sort_by(f64::total_cmp);
    let panels = 64;
    let mut sum = 0.0;
    for piece in cuts.windows(2) {
        let h = (piece[1] - piece[0]) / panels as f64;
        for k in 0..panels {
            let mid = piece[0] + (k as f64 + 0.5) * h;
            sum += GAUSS
                .iter()
                .map(|&(x, w)| w * f(mid + 0.5 * h * x))
                .sum::<f64>()
                * 0.5
                * h;
        }
    }
    sum
}

/// Equal-width bins over `[a, b]`: counts of the `values` (a value outside
/// fails), and the expected counts `n ∫_bin pdf`.
struct Histogram {
    a: f64,
    b: f64,
    counts: Vec<u64>,
}

impl Histogram {
    fn new(a: f64, b: f64, bins: usize) -> Histogram {
        Histogram {
            a,
            b,
            counts: vec![0; bins],
        }
    }

    fn add(&mut self, x: f64) {
        assert!(
            (self.a..=self.b).contains(&x),
            "sample {x} outside [{}, {}]",
            self.a,
            self.b
        );
        let bins = self.counts.len();
        let i = ((x - self.a) / (self.b - self.a) * bins as f64) as usize;
        self.counts[i.min(bins - 1)] += 1;
    }

    fn edge(&self, i: usize) -> f64 {
        self.a + (self.b - self.a) * i as f64 / self.counts.len() as f64
    }

    fn expected(&self, n: usize, pdf: &impl Fn(f64) -> f64, breaks: &[f64]) -> Vec<f64> {
        (0..self.counts.len())
            .map(|i| n as f64 * integrate(pdf, self.edge(i), self.edge(i + 1), breaks))
            .collect()
    }
}

/// The signed angle from `a` to `b`, in `[−π, π]`.
fn angle(a: DVec2, b: DVec2) -> f64 {
    cross(a, b).atan2(a.dot(b))
}

/// `a` turned by the angle `theta`.
fn turned(a: DVec2, theta: f64) -> DVec2 {
    DVec2::from_angle(theta).rotate(a)
}

// ---------------------------------------------------------------------------
// Free paths.

/// The χ² test of free paths of rate `ks` against the density
/// `pdf(ξ) = k e^{−kξ}` (`k` = `ks` unless the power test lies): 60 bins
/// over `[0, 9/ks]` and one for the tail (its expected count integrated up
/// to 70/ks, past which the density is below e⁻⁷⁰).
fn free_path_test(ks: f64, k: f64, seed: u64) -> (f64, usize, f64) {
    let mut rng = stream(seed, 0);
    let pdf = |x: f64| if x >= 0.0 { k * (-k * x).exp() } else { 0.0 };
    let (end, far) = (9.0 / ks, 70.0 / ks);
    let mut h = Histogram::new(0.0, end, 60);
    let mut tail = 0;
    for _ in 0..N {
        let xi = free_path(ks, &mut rng);
        assert!(xi.is_finite() && xi >= 0.0, "free path {xi}");
        if xi > end { tail += 1 } else { h.add(xi) }
    }
    let mut expected = h.expected(N, &pdf, &[]);
    expected.push(N as f64 * integrate(&pdf, end, far, &[]));
    let mut observed = h.counts;
    observed.push(tail);
    chi2(&observed, &expected)
}

#[test]
fn free_paths_are_exponential() {
    for (i, ks) in [0.25, 1.0, 6.0].into_iter().enumerate() {
        let norm = integrate(&|x: f64| ks * (-ks * x).exp(), 0.0, 70.0 / ks, &[]);
        assert!((norm - 1.0).abs() < 1e-12, "∫ pdf = {norm}");
        let (stat, dof, p) = free_path_test(ks, ks, 100 + i as u64);
        eprintln!("χ² free path κs = {ks}: {stat:.1} on {dof} dof, p = {p:.3e}");
        assert!(p >= ALPHA, "free path κs = {ks}: p = {p:.3e}");
    }
    // No scattering: no collision, ever.
    let mut rng = stream(1, 0);
    assert_eq!(free_path(0.0, &mut rng), f64::INFINITY);
}

// ---------------------------------------------------------------------------
// Directional lobes.

/// The χ² test of `lobe`'s samples, as angles from `axis` in 100 bins over
/// `[lo, hi]`, against `pdf` (by default the lobe's own). Also checks every
/// sample is a unit vector with `value / pdf = weight`.
fn lobe_test(
    name: &str,
    lobe: FlatLobe,
    axis: DVec2,
    (lo, hi): (f64, f64),
    pdf: &impl Fn(f64) -> f64,
    breaks: &[f64],
    seed: u64,
) -> (f64, usize, f64) {
    let mut rng = stream(seed, 0);
    let mut h = Histogram::new(lo, hi, 100);
    for _ in 0..N {
        let w = lobe.sample(&mut rng);
        assert!(
            (w.length() - 1.0).abs() < 1e-12,
            "{name}: |ω| = {}",
            w.length()
        );
        let ratio = lobe.value(w) / lobe.pdf(w);
        assert!(
            (ratio - lobe.weight()).abs() <= 1e-12 * lobe.weight(),
            "{name}: f/pdf = {ratio}, weight {}",
            lobe.weight()
        );
        h.add(angle(axis, w));
    }
    let expected = h.expected(N, pdf, breaks);
    chi2(&h.counts, &expected)
}

#[test]
fn the_cosine_lobe_samples_its_density() {
    for (i, n) in [DVec2::Y, direction(-2.4)].into_iter().enumerate() {
        let lobe = FlatLobe::Cosine { n, c: 0.35 };
        let pdf = |theta: f64| lobe.pdf(turned(n, theta));
        let kinks = [-FRAC_PI_2, FRAC_PI_2];
        let norm = integrate(&pdf, -PI, PI, &kinks);
        assert!((norm - 1.0).abs() < 1e-12, "∫ pdf = {norm}");
        // Nothing behind the surface: the domain is the half circle.
        assert_eq!(pdf(FRAC_PI_2 + 0.1), 0.0);
        let name = format!("cosine lobe n = {n:.3}");
        let (stat, dof, p) = lobe_test(
            &name,
            lobe,
            n,
            (-FRAC_PI_2, FRAC_PI_2),
            &pdf,
            &[],
            200 + i as u64,
        );
        eprintln!("χ² {name}: {stat:.1} on {dof} dof, p = {p:.3e}");
        assert!(p >= ALPHA, "{name}: p = {p:.3e}");
    }
}

/// The phase functions tested: isotropic and Henyey–Greenstein.
fn phases() -> Vec<Phase> {
    std::iter::once(Phase::Isotropic)
        .chain([-0.7, 0.0, 0.3, 0.9].map(|g| Phase::HenyeyGreenstein { g }))
        .collect()
}

#[test]
fn the_phase_functions_sample_their_density() {
    let w_in = direction(2.1);
    for (i, phase) in phases().into_iter().enumerate() {
        let lobe = FlatLobe::Phase { phase, w_in };
        let pdf = |theta: f64| lobe.pdf(turned(w_in, theta));
        let norm = integrate(&pdf, -PI, PI, &[0.0]);
        assert!((norm - 1.0).abs() < 1e-10, "{phase:?}: ∫ pdf = {norm}");
        let name = format!("{phase:?}");
        let (stat, dof, p) = lobe_test(&name, lobe, w_in, (-PI, PI), &pdf, &[0.0], 300 + i as u64);
        eprintln!("χ² phase {name}: {stat:.1} on {dof} dof, p = {p:.3e}");
        assert!(p >= ALPHA, "{name}: p = {p:.3e}");
    }
}

// ---------------------------------------------------------------------------
// Round trips through the warps' inverses.

/// Draws `count` directions from `lobe`, each with the uniform number it
/// consumed (read from a copy of the generator), and returns the largest
/// distance on the unit circle between that number and `cdf(θ)`, `θ` the
/// drawn angle from `axis`.
fn round_trip(lobe: FlatLobe, axis: DVec2, cdf: impl Fn(f64) -> f64, seed: u64) -> f64 {
    let mut rng: PathRng = stream(seed, 0);
    let mut worst: f64 = 0.0;
    for _ in 0..100_000 {
        let u: f64 = rng.clone().random();
        let theta = angle(axis, lobe.sample(&mut rng));
        let d = (cdf(theta) - u).rem_euclid(1.0);
        worst = worst.max(d.min(1.0 - d));
    }
    worst
}

#[test]
fn the_cosine_warp_inverts() {
    // s = 2u − 1 = sin θ, so u = (1 + sin θ) / 2 (θ counter-clockwise).
    let n = direction(0.8);
    assert_eq!(perp(n).dot(turned(n, FRAC_PI_2)).round(), 1.0);
    let lobe = FlatLobe::Cosine { n, c: 1.0 };
    let worst = round_trip(lobe, n, |theta| 0.5 * (1.0 + theta.sin()), 400);
    eprintln!("cosine warp round trip: worst |u − F(θ)| = {worst:.2e}");
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn the_phase_warps_invert() {
    // The wrapped Cauchy law's CDF on (−π, π]:
    // F(θ) = 1/2 + atan(((1 + g)/(1 − g)) tan(θ/2)) / π; isotropic: θ/2π.
    let w_in = direction(-1.3);
    for (i, phase) in phases().into_iter().enumerate() {
        let cdf = |theta: f64| match phase {
            Phase::Isotropic => theta / TAU,
            Phase::HenyeyGreenstein { g } => {
                0.5 + ((1.0 + g) / (1.0 - g) * (0.5 * theta).tan()).atan() / PI
            }
        };
        let lobe = FlatLobe::Phase { phase, w_in };
        let worst = round_trip(lobe, w_in, cdf, 500 + i as u64);
        eprintln!("{phase:?} warp round trip: worst |u − F(θ)| = {worst:.2e}");
        assert!(worst < 1e-12, "{phase:?}: {worst}");
    }
}

// ---------------------------------------------------------------------------
// Emitter points.

fn shape(name: &str, vertices: &[[f64; 2]], closed: bool, surface: Surface) -> Shape {
    Shape {
        name: name.into(),
        vertices: vertices.iter().map(|&[x, y]| DVec2::new(x, y)).collect(),
        closed,
        surface,
        medium: None,
    }
}

/// Three lamps of different lengths (a two-segment polyline, a short
/// segment, a long one behind it seen from the right) and an emitter of
/// radiance 0, which must never be drawn, with an occluder (emitter
/// sampling ignores visibility).
fn lamps() -> Plane {
    let lamp = |radiance| Surface::Emitter { radiance };
    let shapes = vec![
        shape(
            "a",
            &[[-2.0, 3.0], [-1.0, 3.0], [1.5, 3.6]],
            false,
            lamp(1.0),
        ),
        shape("b", &[[2.5, -1.0], [2.5, -0.6]], false, lamp(3.0)),
        shape("c", &[[-2.5, -1.5], [-2.5, 0.5]], false, lamp(0.5)),
        shape("dark", &[[-3.0, -1.0], [-3.0, 1.0]], false, lamp(0.0)),
        shape("wall", &[[-0.5, 1.0], [0.5, 1.2]], false, Surface::Absorber),
    ];
    let sensor = Sensor::Irradiance {
        point: DVec2::ZERO,
        normal: DVec2::Y,
    };
    Plane::new(Arc::new(Scene::new(shapes, vec![], sensor).unwrap()))
}

/// The segments of emitters of positive radiance, with their indices.
fn lit_segments(scene: &Scene) -> Vec<(u32, Segment)> {
    let mut first = 0u32;
    let mut lit = Vec::new();
    for s in scene.shapes() {
        let m = s.segments().count() as u32;
        if matches!(s.surface, Surface::Emitter { radiance } if radiance > 0.0) {
            lit.extend((first..first + m).zip(s.segments()));
        }
        first += m;
    }
    lit
}

#[test]
fn emitter_points_are_uniform_by_length() {
    let plane = lamps();
    let scene = plane.scene();
    let lit = lit_segments(scene);
    assert_eq!(lit.len(), 4);
    // Each lit segment's start along the lamps laid end to end.
    let mut offset = Vec::new();
    let mut total = 0.0;
    for (_, seg) in &lit {
        offset.push(total);
        total += seg.length();
    }
    assert!((scene.emitter_length() - total).abs() < 1e-12 * total);
    let mut h = Histogram::new(0.0, total, 120);
    let mut rng = stream(600, 0);
    for _ in 0..N {
        let (y, p) = plane.emitter_point(&mut rng).unwrap();
        let k = lit
            .iter()
            .position(|&(i, _)| i == p)
            .unwrap_or_else(|| panic!("segment {p} is not a lit emitter"));
        let seg = lit[k].1;
        assert!(
            seg.distance(y) <= 1e-12 * scene.size(),
            "{y} off its segment"
        );
        h.add((offset[k] + (y - seg.a).length()).min(total));
    }
    let expected = h.expected(N, &|_| 1.0 / total, &offset);
    assert_fits("emitter points by length", &h.counts, &expected);
}

/// The point where the ray from `x` along `w` meets `seg`, if it does.
fn ray_hit(x: DVec2, w: DVec2, seg: &Segment) -> Option<DVec2> {
    let e = seg.b - seg.a;
    let den = cross(w, e);
    if den == 0.0 {
        return None;
    }
    let t = cross(seg.a - x, e) / den;
    let s = cross(seg.a - x, w) / den;
    (t > 0.0 && (0.0..=1.0).contains(&s)).then(|| x + t * w)
}

#[test]
fn emitter_directions_follow_the_light_pdf() {
    // From the origin the lamps are apart; from (4, −0.8) lamp b hides part
    // of lamp c, so some directions reach two emitter points and the
    // density there is the sum of both points' light_pdf.
    let plane = lamps();
    let lit = lit_segments(plane.scene());
    for (i, x) in [DVec2::ZERO, DVec2::new(4.0, -0.8)].into_iter().enumerate() {
        let pdf = |phi: f64| {
            let w = direction(phi);
            lit.iter()
                .filter_map(|&(p, seg)| ray_hit(x, w, &seg).map(|y| plane.light_pdf(x, y, p)))
                .sum::<f64>()
        };
        let ends: Vec<f64> = lit
            .iter()
            .flat_map(|(_, s)| [s.a, s.b])
            .map(|q| (q - x).y.atan2((q - x).x))
            .collect();
        let norm = integrate(&pdf, -PI, PI, &ends);
        assert!((norm - 1.0).abs() < 1e-9, "from {x}: ∫ pdf = {norm}");
        let mut h = Histogram::new(-PI, PI, 720);
        let mut rng = stream(700 + i as u64, 0);
        for _ in 0..N {
            let (y, _) = plane.emitter_point(&mut rng).unwrap();
            h.add((y - x).y.atan2((y - x).x));
        }
        let expected = h.expected(N, &pdf, &ends);
        assert_fits(
            &format!("emitter directions from {x}"),
            &h.counts,
            &expected,
        );
    }
}

// ---------------------------------------------------------------------------
// Corner selection.

/// Polylines and polygons of every opaque kind, a collinear vertex (weight
/// 0), a non-convex polygon (a reflex corner), and a medium whose vertices
/// are no corners; parameters move the block, the lamp and the medium.
fn corners_scene() -> Plane {
    let shapes = vec![
        shape(
            "frame",
            &[
                [-3.0, 0.0],
                [-3.0, 2.0],
                [-1.0, 2.5],
                [0.0, 2.5],
                [1.0, 2.5],
            ],
            false,
            Surface::Absorber,
        ),
        shape(
            "block",
            &[[1.0, 0.5], [2.0, 0.5], [2.0, 1.5], [1.5, 1.0], [1.0, 1.5]],
            true,
            Surface::Absorber,
        ),
        shape(
            "mirror",
            &[[-2.0, -1.0], [-1.0, -1.5], [-1.2, -0.6]],
            true,
            Surface::Reflector { albedo: 0.5 },
        ),
        shape(
            "lamp",
            &[[2.5, -1.0], [3.5, -0.5]],
            false,
            Surface::Emitter { radiance: 1.0 },
        ),
        Shape {
            medium: Some(Medium {
                ks: 0.5,
                ke: 1.0,
                phase: Phase::Isotropic,
            }),
            ..shape(
                "fog",
                &[[-0.5, -0.5], [0.5, -0.5], [0.5, 0.3], [-0.5, 0.3]],
                true,
                Surface::Transparent,
            )
        },
    ];
    let parameter = |name: &str, shape: &str, motion| Parameter {
        name: name.into(),
        shape: shape.into(),
        motion,
        bounds: None,
    };
    let parameters = vec![
        parameter("block_tx", "block", Motion::TranslateX),
        parameter("lamp_rotate", "lamp", Motion::Rotate { pivot: None }),
        parameter("fog_tx", "fog", Motion::TranslateX),
    ];
    let sensor = Sensor::Irradiance {
        point: DVec2::new(0.0, -3.0),
        normal: DVec2::Y,
    };
    Plane::new(Arc::new(Scene::new(shapes, parameters, sensor).unwrap()))
}

/// Per corner (the scene's order: opaque shapes, vertices in order) its
/// weight, computed here from the shapes: 1 at a polyline's end, `θ/π` at a
/// vertex where the outline turns by `θ`; and whether a parameter moves it.
fn corner_weights(scene: &Scene) -> Vec<(DVec2, f64, bool)> {
    let moving =
        |k: usize| (0..scene.parameters().len()).any(|j| scene.parameter_shape(j) == k as u32);
    let mut out = Vec::new();
    for (k, s) in scene.shapes().iter().enumerate() {
        if !s.surface.is_opaque() {
            continue;
        }
        let v = &s.vertices;
        let n = v.len();
        for i in 0..n {
            let ends = !s.closed && (i == 0 || i == n - 1);
            let weight = if ends {
                1.0
            } else {
                let (din, dout) = (v[i] - v[(i + n - 1) % n], v[(i + 1) % n] - v[i]);
                angle(din, dout).abs() / PI
            };
            out.push((v[i], weight, moving(k)));
        }
    }
    out
}

#[test]
fn corners_are_drawn_by_weight() {
    let plane = corners_scene();
    let scene = plane.scene();
    let weights = corner_weights(scene);
    let listed: Vec<DVec2> = scene.corners().iter().map(|c| c.0).collect();
    let ours: Vec<DVec2> = weights.iter().map(|c| c.0).collect();
    assert_eq!(listed, ours, "the corners are the opaque shapes' vertices");
    // The collinear vertex (0, 2.5) of the frame weighs nothing.
    assert!(
        weights
            .iter()
            .any(|&(q, w, _)| q == DVec2::new(0.0, 2.5) && w < 1e-15)
    );
    // The draws are shared out equally among the view's slots: a slot
    // that sees all corners move draws among all of them by weight, a
    // parameter among its own shape's (none for the fog's: it has no
    // corner). Slot 3 stands for a gradient slot.
    let slots = |js: &[usize]| {
        let mut s = SlotSet::EMPTY;
        for &j in js {
            s.insert(j);
        }
        s
    };
    let views = [
        ("all corners", slots(&[3]), SlotSet::EMPTY),
        ("moving corners", SlotSet::EMPTY, slots(&[0, 1, 2])),
        ("a mixture", slots(&[3]), slots(&[0, 1])),
        ("one shape", SlotSet::EMPTY, slots(&[1, 2])),
    ];
    for (name, all, own) in views {
        let view = BoundaryView { all, own };
        // The components: `None` for all corners, else a shape.
        let mut components: Vec<Option<u32>> = all.iter().map(|_| None).collect();
        for j in own.iter() {
            let k = scene.parameter_shape(j);
            if weights
                .iter()
                .zip(scene.corners())
                .any(|(w, c)| c.1 == k && w.1 > 0.0)
            {
                components.push(Some(k));
            }
        }
        let in_component = |i: usize, c: Option<u32>| c.is_none_or(|k| scene.corners()[i].1 == k);
        let pdf: Vec<f64> = (0..weights.len())
            .map(|i| {
                components
                    .iter()
                    .map(|&c| {
                        let total: f64 = (0..weights.len())
                            .filter(|&m| in_component(m, c))
                            .map(|m| weights[m].1)
                            .sum();
                        if in_component(i, c) {
                            weights[i].1 / total
                        } else {
                            0.0
                        }
                    })
                    .sum::<f64>()
                    / components.len() as f64
            })
            .collect();
        let mut counts = vec![0u64; weights.len()];
        let mut rng = stream(800 + components.len() as u64, all.len() as u64);
        let v = Vertex::<Plane> {
            x: DVec2::ZERO,
            medium: None,
            skip: geosens::path::NO_PRIM,
            lobe: FlatLobe::Cosine {
                n: DVec2::Y,
                c: 1.0,
            },
            frame: Frame::Sensor,
            w_in: DVec2::ZERO,
            beta: 1.0,
            at_sensor: false,
            mixed: false,
        };
        for _ in 0..N {
            let b = plane.sample_boundary(&v, &view, rng.random()).unwrap();
            let i = b.index as usize;
            assert_eq!((b.q, b.shape), scene.corners()[i]);
            assert!(pdf[i] > 0.0, "corner {i} of probability 0 drawn ({name})");
            assert!(
                (b.inv_pdf - 1.0 / pdf[i]).abs() <= 1e-12 * b.inv_pdf,
                "corner {i}: inv_pdf {} for 1/pdf {} ({name})",
                b.inv_pdf,
                1.0 / pdf[i]
            );
            counts[i] += 1;
        }
        let expected: Vec<f64> = pdf.iter().map(|p| N as f64 * p).collect();
        assert_fits(name, &counts, &expected);
    }
}

// ---------------------------------------------------------------------------
// The guard's guard.

#[test]
fn the_chi2_test_has_power() {
    // Free paths of rate 1 tested as if of rate 1.01.
    let (_, _, p) = free_path_test(1.0, 1.01, 900);
    eprintln!("free paths against a 1 % wrong rate: p = {p:.3e}");
    assert!(p < ALPHA, "a 1 % wrong rate passes: p = {p:.3e}");
    // Henyey–Greenstein g = 0.3 tested against g = 0.33.
    let w_in = DVec2::X;
    let lobe = FlatLobe::Phase {
        phase: Phase::HenyeyGreenstein { g: 0.3 },
        w_in,
    };
    let wrong = FlatLobe::Phase {
        phase: Phase::HenyeyGreenstein { g: 0.33 },
        w_in,
    };
    let pdf = |theta: f64| wrong.pdf(turned(w_in, theta));
    let (_, _, p) = lobe_test("HG", lobe, w_in, (-PI, PI), &pdf, &[0.0], 901);
    eprintln!("HG g = 0.3 against g = 0.33: p = {p:.3e}");
    assert!(p < ALPHA, "a wrong g passes: p = {p:.3e}");
    // A sample where the density is 0 fails outright.
    assert_eq!(chi2(&[10, 1], &[11.0, 0.0]).2, 0.0);
}
