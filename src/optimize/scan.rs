//! A scan of the objective over a grid of two parameters, and the quadratic
//! that fits it best: the reference for a design problem (whose answer has
//! no closed form) and the check of a problem's identifiability before a
//! method is blamed (the fitted Hessian's eigenvalues). Book: chapter
//! "Sensitivities at work", section "Invalid steps and bounds".
//!
//! Every grid point is estimated from the same seed (common random numbers),
//! so the scan's noise is smooth across the grid and its peak is steadier
//! than independent estimates would leave it.
use super::study::{Sampling, Study};
use crate::error::Error;
use crate::method::Method;
use crate::method::model::Model;
use crate::scene::config;

/// One grid point: the offsets (all parameters) and the loss there.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanPoint {
    /// The offsets.
    pub offsets: Vec<f64>,
    /// The loss (mean) and its standard error.
    pub loss: f64,
    /// Its standard error.
    pub stderr: f64,
}

/// The loss on the grid `a × b` of parameters `(ja, jb)` (the others at
/// `base`), by the intensity estimator from one seed; grid points whose
/// scene is invalid are left out.
pub fn scan<S: Model>(
    study: &Study<S>,
    base: &[f64],
    (ja, a): (usize, &[f64]),
    (jb, b): (usize, &[f64]),
    sampling: &Sampling,
) -> Result<Vec<ScanPoint>, Error> {
    let mut points = Vec::with_capacity(a.len() * b.len());
    for &x in a {
        for &y in b {
            let mut offsets = base.to_vec();
            offsets[ja] = x;
            offsets[jb] = y;
            let Ok(posed) = study.posed(&offsets) else {
                continue;
            };
            let e = study.evaluate_posed(&posed, &offsets, Method::Intensity, sampling)?;
            points.push(ScanPoint {
                offsets,
                loss: e.loss.mean,
                stderr: e.loss.stderr,
            });
        }
    }
    Ok(points)
}

/// `c + g·d + ½ dᵀ H d` about `center`, fitted to a scan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quadratic {
    /// Where the fit is centred.
    pub center: [f64; 2],
    /// Value at the centre.
    pub c: f64,
    /// Gradient at the centre.
    pub g: [f64; 2],
    /// Hessian.
    pub h: [[f64; 2]; 2],
}

impl Quadratic {
    /// The stationary point `center − H⁻¹ g` (`None`: `H` singular).
    pub fn stationary(&self) -> Option<[f64; 2]> {
        let [[a, b], [_, d]] = self.h;
        let det = a * d - b * b;
        if det.abs() < f64::MIN_POSITIVE || !det.is_finite() {
            return None;
        }
        let [gx, gy] = self.g;
        let dx = -(d * gx - b * gy) / det;
        let dy = -(-b * gx + a * gy) / det;
        Some([self.center[0] + dx, self.center[1] + dy])
    }

    /// The value at `p`.
    pub fn at(&self, p: [f64; 2]) -> f64 {
        let d = [p[0] - self.center[0], p[1] - self.center[1]];
        let [[a, b], [_, e]] = self.h;
        self.c
            + self.g[0] * d[0]
            + self.g[1] * d[1]
            + 0.5 * (a * d[0] * d[0] + 2.0 * b * d[0] * d[1] + e * d[1] * d[1])
    }
}

/// The least-squares quadratic through `(x, y, value)` points (at least 6,
/// not on one conic's degenerate set), centred at their mean.
pub fn fit_quadratic(points: &[([f64; 2], f64)]) -> Result<Quadratic, Error> {
    if points.len() < 6 {
        return config(format!(
            "{} points: a quadratic in two variables needs 6",
            points.len()
        ));
    }
    let n = points.len() as f64;
    let center = [
        points.iter().map(|p| p.0[0]).sum::<f64>() / n,
        points.iter().map(|p| p.0[1]).sum::<f64>() / n,
    ];
    // Normal equations of v ≈ c + g·d + ½(a dx² + 2 b dx dy + e dy²).
    let basis = |p: [f64; 2]| {
        let (x, y) = (p[0] - center[0], p[1] - center[1]);
        [1.0, x, y, 0.5 * x * x, x * y, 0.5 * y * y]
    };
    let mut m = [[0.0f64; 7]; 6];
    for &(p, v) in points {
        let f = basis(p);
        for i in 0..6 {
            for j in 0..6 {
                m[i][j] += f[i] * f[j];
            }
            m[i][6] += f[i] * v;
        }
    }
    let c = solve6(m)
        .ok_or_else(|| Error::Config("the scan's points do not determine a quadratic".into()))?;
    Ok(Quadratic {
        center,
        c: c[0],
        g: [c[1], c[2]],
        h: [[c[3], c[4]], [c[4], c[5]]],
    })
}

/// Gaussian elimination with partial pivoting on a 6×6 augmented system.
fn solve6(mut m: [[f64; 7]; 6]) -> Option<[f64; 6]> {
    for col in 0..6 {
        let pivot = (col..6).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[pivot][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, pivot);
        for row in 0..6 {
            if row != col {
                let f = m[row][col] / m[col][col];
                let pivot_row = m[col];
                for (k, v) in m[row].iter_mut().enumerate().skip(col) {
                    *v -= f * pivot_row[k];
                }
            }
        }
    }
    Some(std::array::from_fn(|i| m[i][6] / m[i][i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quadratic_is_fitted_exactly() {
        let q = |x: f64, y: f64| {
            3.0 - 2.0 * (x - 0.3).powi(2) - (y + 0.2).powi(2) + 0.5 * (x - 0.3) * (y + 0.2)
        };
        let mut points = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                let (x, y) = (f64::from(i) * 0.1, -0.4 + f64::from(j) * 0.1);
                points.push(([x, y], q(x, y)));
            }
        }
        let fit = fit_quadratic(&points).unwrap();
        let p = fit.stationary().unwrap();
        assert!(
            (p[0] - 0.3).abs() < 1e-9 && (p[1] + 0.2).abs() < 1e-9,
            "{p:?}"
        );
        assert!((fit.at(p) - 3.0).abs() < 1e-9);
        assert!(fit_quadratic(&points[..5]).is_err());
    }
}
