//! The camera against independent references.
//!
//! - **Floor**: `scenes/mesh/camera_shadow.toml`, the occluder's shadow on a
//!   white Lambertian floor seen frontally from under the triangle. The
//!   floor's radiance is `E/π`, so the image mean is the mean of `E/π` over
//!   the floor's footprint and its sensitivities the mean of `∂E/∂π / π`:
//!   a midpoint quadrature of the closed form
//!   (`exact::occluded_irradiance_with_gradient`). Every method's image
//!   mean agrees with it and with finite differences of two intensity
//!   renders with common random numbers (the `fd` method).
//! - **Looking up**: a camera under the triangle looking at the lamp: every
//!   pixel is the share of its footprint on the lamp's plane that sees the
//!   lamp past the triangle (convex clipping), its derivative by central
//!   differences of that area; each pixel of every method agrees (this is
//!   where the primary silhouette terms and the camera's warp act).
use geosens::image::{ImageResult, render};
use geosens::mesh::camera::Camera;
use geosens::mesh::exact::{occluded_irradiance_with_gradient, sensitivity};
use geosens::mesh::file::load;
use geosens::mesh::{Motion, Parameter, Scene, Sensor, Shape, Surface};
use geosens::{Estimate, Method, Problem, Quantity};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;
use std::sync::Arc;

const METHODS: [Method; 4] = [
    Method::Rendering,
    Method::Transport,
    Method::Expectation,
    Method::Fd,
];

fn image(scene: &Arc<Scene>, method: Method, spp: u64, seed: u64) -> ImageResult {
    let est = scene.estimator(method, None).unwrap();
    render(est.as_ref(), spp, seed, 0, &geosens::runner::quiet).unwrap()
}

fn floor_scene() -> Arc<Scene> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenes/mesh/camera_shadow.toml"
    );
    Arc::new(load(std::path::Path::new(path)).unwrap())
}

/// The mean of `E/π` and of every `∂E/∂π_j / π` over the floor's footprint
/// by the midpoint rule on `n × n` cells.
fn floor_reference(scene: &Scene, n: usize) -> (f64, Vec<f64>) {
    let Sensor::Camera(cam) = scene.sensor() else {
        panic!("a camera scene")
    };
    let f = cam.frame();
    let h = cam.position.z;
    let lamp = scene.shapes()[0].vertices.clone();
    let tri = scene.shapes()[1].vertices.clone();
    let (hx, hy) = (h * f.half_w, h * f.half_h);
    let mut e_sum = 0.0;
    let mut s_sum = vec![0.0; scene.parameters().len()];
    for i in 0..n {
        for k in 0..n {
            let x = DVec3::new(
                cam.position.x - hx + 2.0 * hx * (i as f64 + 0.5) / n as f64,
                cam.position.y - hy + 2.0 * hy * (k as f64 + 0.5) / n as f64,
                0.0,
            );
            let (e, g) = occluded_irradiance_with_gradient(x, DVec3::Z, &lamp, &tri, 1.0).unwrap();
            e_sum += e;
            for (s, p) in s_sum.iter_mut().zip(scene.parameters()) {
                *s += sensitivity(&g, &tri, p.motion);
            }
        }
    }
    let m = (n * n) as f64 * PI;
    (e_sum / m, s_sum.into_iter().map(|s| s / m).collect())
}

fn close(a: Estimate, b: f64, k: f64) -> bool {
    (a.mean - b).abs() <= k * a.stderr
}

#[test]
fn floor_image_means_match_the_closed_form_and_finite_differences() {
    let scene = floor_scene();
    // 1920 × 1920 cells: since the lamps' edges and the lamp parts of
    // silhouettes are taken every time, rendering's error bars on tri_tx
    // are 1.9e-6, and 240 against 480 cells differ by 1.4e-6 (480
    // against 960 by 2.2e-7, 960 against 1920 by 1.1e-8).
    let (e, s) = floor_reference(&scene, 1920);
    let (e2, s2) = floor_reference(&scene, 960);
    let spp = 256;
    let fd = image(&scene, Method::Fd, spp, 11);
    let intensity = image(&scene, Method::Intensity, spp, 12);
    let i = intensity.mean(&Quantity::Intensity).unwrap();
    // The quadrature is far finer than the error bars.
    assert!((e - e2).abs() < 0.1 * i.stderr, "quadrature: {e} vs {e2}");
    assert!(close(i, e, 4.0), "I: {i:?} vs {e}");
    for method in METHODS {
        let r = if method == Method::Fd {
            fd.clone()
        } else {
            image(&scene, method, spp, 13)
        };
        let i = r.mean(&Quantity::Intensity).unwrap();
        assert!(close(i, e, 4.0), "{method}: I {i:?} vs {e}");
        for (j, p) in scene.parameters().iter().enumerate() {
            let q = Quantity::sensitivity(&p.name);
            let m = r.mean(&q).unwrap();
            assert!(
                (s[j] - s2[j]).abs() < 0.1 * m.stderr,
                "quadrature of {}: {} vs {}",
                p.name,
                s[j],
                s2[j]
            );
            // Error bars small enough to tell a missing term (FD's are
            // wide: it is only the second reference).
            assert!(
                method == Method::Fd || (m.stderr > 0.0 && m.stderr < 0.3 * s[j].abs().max(5e-4)),
                "{method} {}: {m:?} vs {}",
                p.name,
                s[j]
            );
            assert!(
                close(m, s[j], 4.0),
                "{method} {}: {m:?} vs closed form {}",
                p.name,
                s[j]
            );
            let f = fd.mean(&q).unwrap();
            let both = (m.stderr.powi(2) + f.stderr.powi(2)).sqrt();
            if method != Method::Fd {
                assert!(
                    (m.mean - f.mean).abs() <= 4.0 * both,
                    "{method} {}: {m:?} vs fd {f:?}",
                    p.name
                );
            }
        }
    }
}

/// Area of a convex polygon (counter-clockwise or not).
fn area(p: &[DVec2]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| p[i].perp_dot(p[(i + 1) % n]))
        .sum::<f64>()
        .abs()
        * 0.5
}

/// The convex polygon `p` clipped to the convex polygon `c`
/// (counter-clockwise), Sutherland–Hodgman.
fn clip(p: &[DVec2], c: &[DVec2]) -> Vec<DVec2> {
    let mut out = p.to_vec();
    for i in 0..c.len() {
        let (a, b) = (c[i], c[(i + 1) % c.len()]);
        let side = |q: DVec2| (b - a).perp_dot(q - a);
        let input = std::mem::take(&mut out);
        for k in 0..input.len() {
            let (s, e) = (input[k], input[(k + 1) % input.len()]);
            let (ss, se) = (side(s), side(e));
            if ss >= 0.0 {
                out.push(s);
            }
            if (ss >= 0.0) != (se >= 0.0) {
                out.push(s + (e - s) * (ss / (ss - se)));
            }
        }
        if out.is_empty() {
            break;
        }
    }
    out
}

fn ccw(mut p: Vec<DVec2>) -> Vec<DVec2> {
    let n = p.len();
    let s: f64 = (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum();
    if s < 0.0 {
        p.reverse();
    }
    p
}

/// The looking-up scene: lamp, the nominal triangle, a camera at
/// `(0.1, 0, 0)` looking up at them.
fn up_scene(width: u32) -> Arc<Scene> {
    let lamp = geosens::mesh::cases::lamp();
    let occ = geosens::mesh::cases::TriangleOccluder::NOMINAL;
    let tri = Shape {
        name: "tri".into(),
        vertices: occ.vertices().to_vec(),
        triangles: vec![[0, 1, 2]],
        surface: Surface::Absorber,
        medium: None,
    };
    let c = occ.centre;
    let parameters = [
        ("tx", Motion::TranslateX),
        ("tz", Motion::TranslateZ),
        (
            "rot",
            Motion::Rotate {
                axis: DVec3::Z,
                pivot: Some(c),
            },
        ),
        ("scale", Motion::Scale { pivot: Some(c) }),
    ]
    .map(|(name, motion)| Parameter {
        name: name.into(),
        shape: "tri".into(),
        motion,
        bounds: None,
    })
    .to_vec();
    let camera = Camera {
        position: DVec3::new(0.1, 0.0, 0.0),
        look_at: DVec3::new(0.1, 0.0, 1.0),
        up: DVec3::Y,
        fov_deg: 40.0,
        width,
        height: width,
    };
    Arc::new(Scene::new(vec![lamp, tri], parameters, Sensor::Camera(camera)).unwrap())
}

/// Pixel `p`'s exact value with the triangle at `tri`: the share of its
/// footprint on the lamp's plane that sees the lamp past the triangle.
fn up_pixel(scene: &Scene, tri: &[DVec3], p: u32) -> f64 {
    let Sensor::Camera(cam) = scene.sensor() else {
        panic!()
    };
    let f = cam.frame();
    let r = f.rect(geosens::path::PixelSample {
        pixel: p,
        stratum: 0,
        strata: 1,
    });
    let eye = cam.position;
    // The image point (x, y) at unit distance lands on z = 2 at
    // eye + 2 (f + x r + y u).
    let on_lamp = |x: f64, y: f64| {
        let q = eye + (f.f + f.r * x + f.u * y) * 2.0;
        DVec2::new(q.x, q.y)
    };
    let rect = ccw(vec![
        on_lamp(r[0], r[2]),
        on_lamp(r[1], r[2]),
        on_lamp(r[1], r[3]),
        on_lamp(r[0], r[3]),
    ]);
    let lamp = ccw(scene.shapes()[0]
        .vertices
        .iter()
        .map(|v| DVec2::new(v.x, v.y))
        .collect());
    let shadow = ccw(tri
        .iter()
        .map(|&q| {
            let s = eye + (q - eye) * (2.0 / q.z);
            DVec2::new(s.x, s.y)
        })
        .collect());
    let lit = clip(&rect, &lamp);
    if lit.len() < 3 {
        return 0.0;
    }
    let hidden = clip(&lit, &shadow);
    let hidden = if hidden.len() < 3 { 0.0 } else { area(&hidden) };
    (area(&lit) - hidden) / area(&rect)
}

/// Paths per pixel of the looking-up images.
const SPP: u64 = 512;

#[test]
fn looking_up_every_pixel_matches_the_clipped_areas() {
    let width = 24;
    let scene = up_scene(width);
    let tri = scene.shapes()[1].vertices.clone();
    let pixels = width * width;
    let exact: Vec<f64> = (0..pixels).map(|p| up_pixel(&scene, &tri, p)).collect();
    let h = 1e-6;
    let derivative: Vec<Vec<f64>> = scene
        .parameters()
        .iter()
        .map(|par| {
            let moved =
                |d: f64| -> Vec<DVec3> { tri.iter().map(|&q| par.motion.apply(q, d)).collect() };
            let (plus, minus) = (moved(h), moved(-h));
            (0..pixels)
                .map(|p| (up_pixel(&scene, &plus, p) - up_pixel(&scene, &minus, p)) / (2.0 * h))
                .collect()
        })
        .collect();
    let edge_pixels = derivative[0].iter().filter(|d| d.abs() > 0.0).count();
    assert!(
        edge_pixels > 20,
        "the triangle's outline crosses {edge_pixels} pixels"
    );
    for method in [Method::Rendering, Method::Transport, Method::Expectation] {
        let r = image(&scene, method, SPP, 21);
        let mut quantities = vec![(Quantity::Intensity, &exact)];
        for (par, d) in scene.parameters().iter().zip(&derivative) {
            quantities.push((Quantity::sensitivity(&par.name), d));
        }
        for (q, reference) in quantities {
            let img = r.image(&q).unwrap();
            // Per pixel z-scores: their median (0.67 for a normal law; up
            // to 1.25 allowed, as expectation's heavy tails at silhouette
            // ends make its per-pixel error bars small more often) is blind
            // to the rare pixel whose strata all missed a sliver of a
            // feature (its error bar is then too small: eight paths per
            // stratum cannot see what none of them hits), but not to a
            // bias in most pixels; few pixels may lie beyond 5 error bars.
            let (mut z, mut unseen): (Vec<f64>, usize) = (Vec::new(), 0);
            let largest = reference.iter().fold(0.0f64, |a, x| a.max(x.abs()));
            // A bias in proportion to the value (a boundary term too large
            // by 10 %, say) hides in each pixel's noise but not in their
            // sum weighted by the value's sign.
            let (mut signed, mut var) = (0.0, 0.0);
            for (e, &x) in img.iter().zip(reference.iter()) {
                if x != 0.0 {
                    signed += x.signum() * (e.mean - x);
                    var += e.stderr * e.stderr + (1e-7 * (1.0 + x.abs())).powi(2);
                }
                if e.stderr > 0.0 {
                    // The reference's own error: central differences of
                    // clipped areas, ~1e-9 (rendering's weights along a
                    // straight piece are constant for a translation: its
                    // error bars can be smaller still).
                    let se = e.stderr.hypot(1e-7 * (1.0 + x.abs()));
                    z.push(((e.mean - x) / se).abs());
                } else if (e.mean - x).abs() > 4.0 / SPP as f64 * largest {
                    // No path saw a change that is not a sliver: expectation's
                    // derivative lives where the lamp is seen, and a pixel
                    // that sees it through a sliver its paths all miss
                    // reports 0 ± 0 (rendering draws the edge itself).
                    unseen += 1;
                }
            }
            z.sort_by(f64::total_cmp);
            let median = z[z.len() / 2];
            let beyond = z.iter().filter(|&&z| z > 5.0).count() + unseen;
            let z_signed = signed / var.sqrt();
            assert!(
                z.len() >= 20
                    && median < 1.25
                    && beyond <= 1 + z.len() / 50
                    && z_signed.abs() < 4.0,
                "{method} {q}: median |z| {median} over {} pixels, {beyond} beyond 5 or unseen, \
                 signed z {z_signed}",
                z.len()
            );
        }
    }
}

#[test]
fn images_are_identical_for_any_thread_count() {
    let scene = up_scene(8);
    for method in [Method::Expectation, Method::Fd] {
        let est = scene.estimator(method, None).unwrap();
        let one = render(est.as_ref(), 16, 5, 1, &geosens::runner::quiet).unwrap();
        let two = render(est.as_ref(), 16, 5, 2, &geosens::runner::quiet).unwrap();
        assert_eq!(one.images, two.images);
        assert_eq!(one.means, two.means);
    }
}

#[test]
fn renders_refuse_what_they_cannot_do() {
    let probe = Arc::new(
        geosens::mesh::cases::TriangleOccluder::NOMINAL
            .scene(&[0])
            .unwrap(),
    );
    let est = probe.estimator(Method::Intensity, None).unwrap();
    let e = render(est.as_ref(), 16, 1, 0, &geosens::runner::quiet).unwrap_err();
    assert!(e.to_string().contains("not a camera"), "{e}");
    let scene = up_scene(4);
    let est = scene.estimator(Method::Rendering, None).unwrap();
    let e = render(est.as_ref(), 1, 1, 0, &geosens::runner::quiet).unwrap_err();
    assert!(e.to_string().contains("spp"), "{e}");
}
