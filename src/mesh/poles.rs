//! Where the expectation method's fibres on the sphere of directions have
//! their pole ([`PoleRule`]): a translation's direction, or a pseudo-random
//! direction fixed by the vertex's position (`pole`). The warp
//! (`super::warp`) builds one fibre field per rule; the space keeps the
//! rules its parameters use. Book: chapter "Three dimensions", section "A
//! warp on the sphere".
use super::scene::{Motion, Scene};
use glam::DVec3;
use std::f64::consts::PI;

/// Most fibre families one warp builds (distinct poles): the motions use at
/// most four rules (the pseudo-random pole and the three axes); parameters
/// beyond would share the pseudo-random one. Small, because a warp is
/// copied per vertex.
pub const MAX_FIELDS: usize = 4;

/// How a parameter's fibres are laid out from a vertex `x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PoleRule {
    /// A pseudo-random pole fixed by `x` (rotations).
    Hashed,
    /// A fixed pole (a translation's direction): every fibre plane holds
    /// the velocity, so crossings at a silhouette's vertex slide alike.
    Along(DVec3),
}

impl PoleRule {
    /// The rule for a parameter's motion.
    pub fn of(motion: &Motion) -> PoleRule {
        match *motion {
            Motion::TranslateX => PoleRule::Along(DVec3::X),
            Motion::TranslateY => PoleRule::Along(DVec3::Y),
            Motion::TranslateZ => PoleRule::Along(DVec3::Z),
            // Toward the pivot would hold a scale's velocities in every
            // fibre plane too, but the pole then lies inside the mesh's
            // silhouette and the silhouette's crossings of static edges
            // (the lamp's) weigh more: measured on the closed-form scenes,
            // its error bars covered worse (tests/mesh_coverage.rs).
            Motion::Scale { .. } | Motion::Rotate { .. } => PoleRule::Hashed,
        }
    }

    /// The pole at `x`.
    #[inline]
    pub(super) fn at(&self, x: DVec3) -> DVec3 {
        match *self {
            PoleRule::Hashed => pole(x),
            PoleRule::Along(d) => d,
        }
    }
}

/// A pseudo-random unit vector fixed by the bits of `x`.
pub(super) fn pole(x: DVec3) -> DVec3 {
    let mut h: u64 = 0x9E37_79B9_7F4A_7C15;
    for c in [x.x, x.y, x.z] {
        h ^= (c + 0.0).to_bits();
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 31;
    }
    let mut next = || {
        h = h.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = h;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let z = 2.0 * next() - 1.0;
    let phi = 2.0 * PI * next();
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// A bounding sphere: centre and radius.
pub(super) type Sphere = (DVec3, f64);

/// A sphere around `points` (their box's centre, the farthest from it),
/// padded against rounding.
pub(super) fn bounding_sphere(points: &[DVec3]) -> Sphere {
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &q| (lo.min(q), hi.max(q)),
    );
    let c = 0.5 * (lo + hi);
    let r = points.iter().map(|&q| q.distance(c)).fold(0.0, f64::max);
    use crate::path::tolerance::{COORDINATE_PAD, CULL_PAD};
    (
        c,
        r * (1.0 + CULL_PAD) + COORDINATE_PAD * c.abs().max_element().max(r),
    )
}

/// A scene's fibre families: the warp's pole rules (distinct, at most
/// [`MAX_FIELDS`]), per parameter the index of its rule, and per rule the
/// bounding spheres of the meshes its parameters move; last, those of
/// every moving mesh (a camera's one family).
#[derive(Debug, Clone)]
pub struct PoleTable {
    pub(super) rules: Vec<PoleRule>,
    pub(super) slot_field: Vec<u8>,
    pub(super) field_bounds: Vec<Vec<Sphere>>,
}

impl PoleTable {
    /// The families of `scene`'s parameters.
    pub(super) fn new(scene: &Scene) -> PoleTable {
        let mut rules = vec![PoleRule::Hashed];
        let mut slot_field = scene
            .parameters()
            .iter()
            .map(|p| {
                let rule = PoleRule::of(&p.motion);
                match rules.iter().position(|r| *r == rule) {
                    Some(i) => i as u8,
                    None if rules.len() < MAX_FIELDS => {
                        rules.push(rule);
                        (rules.len() - 1) as u8
                    }
                    None => 0,
                }
            })
            .collect::<Vec<u8>>();
        // The pseudo-random family only if some parameter uses it.
        if !slot_field.contains(&0) && rules.len() > 1 {
            rules.remove(0);
            for i in &mut slot_field {
                *i -= 1;
            }
        }
        let mut field_bounds = vec![Vec::new(); rules.len() + 1];
        for (j, &f) in slot_field.iter().enumerate() {
            let k = scene.parameter_shape(j) as usize;
            let sphere = bounding_sphere(&scene.shapes()[k].vertices);
            for f in [f as usize, rules.len()] {
                if !field_bounds[f].contains(&sphere) {
                    field_bounds[f].push(sphere);
                }
            }
        }
        PoleTable {
            rules,
            slot_field,
            field_bounds,
        }
    }
}
