//! The expectation method's direction density at an irradiance sensor: the
//! cosine lobe mixed with uniform densities on the narrow gaps between the
//! sensor's knots where the warp is steep.
//!
//! Why: between two neighbouring knots at angles `ψ_a < ψ_b` (corners seen
//! from the sensor, or the lobe's horizons), the warp of slot `j` is linear,
//! so its divergence there is `Δα_j / g` (`Δα_j` the difference of the two
//! knots' angular velocities, `g = ψ_b − ψ_a`). Drawn with the lobe's
//! density `p`, the divergence term `f Δα_j/(g p)` has a second moment of
//! about `f² Δα_j² / (g p)` on that gap: unbounded as `g → 0`, whatever the
//! warp (any continuous field that goes from `α_a` to `α_b` across `g` has
//! `∫ V′² ≥ Δα²/g`). Where a moving corner sits 10⁻⁴ rad from a still one
//! (the occluder's end before a 10⁴-segment vault), that is the method's
//! whole variance.
//!
//! The density `q = (1 − B) p + Σ_i β_i 𝟙_i / g_i` bounds it: the gap's
//! second moment becomes `f² Δα² / (ℓ_i + β_i)`, `ℓ_i = (1 − B) p g_i` the
//! lobe's share of the gap, at most `f² Δα² / β_i` whatever `g_i`. With
//! every slot's jump measured in its largest knot rate `A_j`,
//! `D_i = Σ_j (Δα_ij / A_j)²`, and `f ≈ p` (the lobe's value is its density
//! up to a constant), a gap is steep where the lobe alone would give it a
//! second moment `p D_i / g_i` above ten times a typical `M` (2 per slot),
//! and then gets `β_i = p² D_i / M`, the share that brings it down to `M`;
//! the total `B = Σ β_i` is capped at [`MAX_SHARE`] (all `β` scaled down
//! together). A scene with no steep gap gets `B = 0`: the lobe alone, bit
//! for bit as before.
//!
//! The density is fixed at the scene's `π₀`: the derivative is taken at
//! `π₀`, so `q` enters only as the weight `f/q` of the sample, never the
//! score (book: chapter "Flatland: one deformation, three estimators",
//! section "The warp field", *Steep gaps*). Next-event estimation's
//! multiple importance sampling at the sensor weighs against `q`.
use super::geometry::cross;
use super::scene::Scene;
use crate::rng::PathRng;
use glam::DVec2;
use rand::RngExt;
use std::f64::consts::FRAC_PI_2;

/// The second moment (in units of every slot's rate scale squared) the
/// sensor's draws are taken to have per slot, whatever the gaps.
const TYPICAL: f64 = 2.0;

/// A gap is steep, and gets its own share, where the lobe alone would give
/// it a second moment above `STEEP` times the typical.
const STEEP: f64 = 10.0;

/// Largest share `B` of the draws the gaps take from the lobe.
pub const MAX_SHARE: f64 = 0.5;

/// The mixture: the lobe's normal and the gaps, by angle `ψ` from it.
#[derive(Debug, Clone, Default)]
pub struct SensorGaps {
    /// Unit normal of the sensor.
    n: DVec2,
    /// Total share `B` of the gaps (0: none).
    pub share: f64,
    /// Gap starts and widths (ψ, radians), sorted by start.
    start: Vec<f64>,
    width: Vec<f64>,
    /// `β_i` summed up to gap `i` (inclusive): a cumulative distribution
    /// ending at `share`.
    cdf: Vec<f64>,
}

impl SensorGaps {
    /// The mixture for `scene`'s irradiance sensor (empty for other
    /// sensors, or when no gap is steep), given the corners it sees in
    /// angular order (`(angle, corner, shape)`, the plane's sensor knots).
    pub fn new(scene: &Scene, knot_list: &[(f64, DVec2, u32)]) -> SensorGaps {
        let (point, n) = match scene.sensor() {
            super::scene::Sensor::Irradiance { point, normal } => (point, normal),
            _ => return SensorGaps::default(),
        };
        let params = scene.parameters().len();
        // The knots by ψ with every slot's angular velocity, the horizons
        // (still) at both ends.
        let psi = |q: DVec2| {
            let r = q - point;
            cross(n, r).atan2(n.dot(r))
        };
        let mut knots: Vec<(f64, Vec<f64>)> = vec![(-FRAC_PI_2, vec![0.0; params])];
        for &(_, q, k) in knot_list {
            let r = q - point;
            let rates = (0..params)
                .map(|j| {
                    if scene.parameter_shape(j) == k {
                        cross(r, scene.parameters()[j].motion.velocity(q)) / r.length_squared()
                    } else {
                        0.0
                    }
                })
                .collect();
            knots.push((psi(q), rates));
        }
        knots.push((FRAC_PI_2, vec![0.0; params]));
        knots.sort_by(|a, b| a.0.total_cmp(&b.0));
        let pdf = |psi: f64| 0.5 * psi.cos().max(0.0);
        // A_j: slot j's largest knot rate, its scale.
        let mut scale = vec![0.0f64; params];
        for (_, rates) in &knots {
            for (a, r) in scale.iter_mut().zip(rates) {
                *a = a.max(r.abs());
            }
        }
        let slots = scale.iter().filter(|&&a| a > 0.0).count();
        if slots == 0 {
            return SensorGaps::default();
        }
        let typical = TYPICAL * slots as f64;
        let mut gaps = SensorGaps {
            n,
            ..SensorGaps::default()
        };
        let mut total = 0.0;
        for pair in knots.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            let g = b.0 - a.0;
            // A gap too narrow for its density `β/g` to stay finite is left
            // to the lobe (a denormal width: never in practice).
            if g <= 1e-150 {
                continue;
            }
            // D = Σ_j (Δα_j / A_j)², the gap's jump over every slot.
            let jump: f64 = (0..params)
                .filter(|&j| scale[j] > 0.0)
                .map(|j| ((b.1[j] - a.1[j]) / scale[j]).powi(2))
                .sum();
            let p = pdf(0.5 * (a.0 + b.0));
            // The lobe alone: second moment p D / g; steep past STEEP times
            // the typical, then the share that brings it to the typical.
            if p * jump / g > STEEP * typical {
                total += p * p * jump / typical;
                gaps.start.push(a.0);
                gaps.width.push(g);
                gaps.cdf.push(total);
            }
        }
        if total > MAX_SHARE {
            for c in &mut gaps.cdf {
                *c *= MAX_SHARE / total;
            }
            total = MAX_SHARE;
        }
        gaps.share = total;
        gaps
    }

    // ANCHOR: mixture
    /// A direction drawn with the mixture's density (the lobe is drawn as
    /// the lobe draws itself, after one uniform number picks the part).
    #[inline]
    pub fn sample(&self, lobe: &super::lobe::FlatLobe, rng: &mut PathRng) -> DVec2 {
        use crate::path::Lobe;
        if self.share == 0.0 {
            return lobe.sample(rng);
        }
        let u = rng.random::<f64>();
        if u >= self.share {
            return lobe.sample(rng);
        }
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        let psi = self.start[i] + self.width[i] * rng.random::<f64>();
        DVec2::from_angle(psi).rotate(self.n)
    }

    /// The mixture's density at `w`, `lobe` the sensor's cosine lobe.
    #[inline]
    pub fn pdf(&self, lobe: &super::lobe::FlatLobe, w: DVec2) -> f64 {
        use crate::path::Lobe;
        let lobe = (1.0 - self.share) * lobe.pdf(w);
        let psi = cross(self.n, w).atan2(self.n.dot(w));
        let i = self.start.partition_point(|&s| s <= psi);
        if i == 0 {
            return lobe;
        }
        let i = i - 1;
        if psi >= self.start[i] + self.width[i] {
            return lobe;
        }
        let below = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        lobe + (self.cdf[i] - below) / self.width[i]
    }
    // ANCHOR_END: mixture
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flat::space::Plane;
    use rand::SeedableRng;
    use std::sync::Arc;

    /// The stability case whose occluder corner is seen 10⁻³ (along the
    /// occluder's line) inside the lamp's end: one steep gap.
    fn gaps() -> SensorGaps {
        let scene = crate::flat::cases::knots(1e-3).unwrap();
        {
            let plane = Plane::new(Arc::new(scene));
            SensorGaps::new(plane.scene(), plane.sensor_knot_list())
        }
    }

    /// The sensor's cosine lobe.
    fn cosine(g: &SensorGaps) -> crate::flat::lobe::FlatLobe {
        crate::flat::lobe::FlatLobe::Cosine { n: g.n, c: 1.0 }
    }

    /// ∫ q over the circle by the midpoint rule, each gap with its own
    /// fine grid.
    fn integral(g: &SensorGaps, from: f64, to: f64, steps: usize) -> f64 {
        let h = (to - from) / steps as f64;
        (0..steps)
            .map(|i| {
                let psi = from + (i as f64 + 0.5) * h;
                g.pdf(&cosine(g), DVec2::from_angle(psi).rotate(g.n)) * h
            })
            .sum()
    }

    #[test]
    fn the_density_is_that_of_the_draws() {
        let g = gaps();
        assert!(g.share > 0.01 && g.share <= MAX_SHARE, "share {}", g.share);
        assert_eq!(g.start.len(), 1, "one steep gap");
        let (a, w) = (g.start[0], g.width[0]);
        assert!(w < 1e-3, "the gap is narrow: {w}");
        // Normalised: the lobe part away from the gap, the gap on its own grid.
        let total = integral(&g, -FRAC_PI_2, a, 200_000)
            + integral(&g, a, a + w, 1000)
            + integral(&g, a + w, FRAC_PI_2, 200_000);
        assert!((total - 1.0).abs() < 1e-6, "∫ q = {total}");
        // Draws: the share of each bin (the gap one of them) against ∫ q.
        let lobe = cosine(&g);
        let mut rng = crate::rng::PathRng::seed_from_u64(4);
        let n = 1_000_000;
        let mut edges: Vec<f64> = (0..=16).map(|i| -FRAC_PI_2 + PI_16 * i as f64).collect();
        edges.extend([a, a + w]);
        edges.sort_by(f64::total_cmp);
        let mut counts = vec![0u64; edges.len() - 1];
        for _ in 0..n {
            let d = g.sample(&lobe, &mut rng);
            let psi = cross(g.n, d).atan2(g.n.dot(d));
            let i = edges
                .partition_point(|&e| e <= psi)
                .clamp(1, edges.len() - 1)
                - 1;
            counts[i] += 1;
        }
        for (i, &c) in counts.iter().enumerate() {
            let p = integral(&g, edges[i], edges[i + 1], 20_000);
            let expected = p * n as f64;
            let sd = (expected * (1.0 - p)).sqrt().max(1.0);
            assert!(
                (c as f64 - expected).abs() < 5.0 * sd,
                "bin {i} [{}, {}]: {c} draws, {expected:.0} expected",
                edges[i],
                edges[i + 1]
            );
        }
    }

    #[test]
    fn scenes_without_steep_gaps_keep_the_lobe() {
        let scene = crate::flat::cases::knots(0.1).unwrap();
        assert_eq!(
            {
                let plane = Plane::new(Arc::new(scene));
                SensorGaps::new(plane.scene(), plane.sensor_knot_list())
            }
            .share,
            0.0
        );
    }

    const PI_16: f64 = std::f64::consts::PI / 16.0;
}
