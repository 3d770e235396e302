//! Richardson extrapolation: from one quantity computed at three or more mesh sizes, the value
//! at h → 0 and the observed order of convergence p (f(h) ≈ f* + C·hᵖ). Pure arithmetic on the
//! figures; the convergence study, the sweep table and the error bar of a run all use it.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A Richardson extrapolation f(h) ≈ f* + C·hᵖ through the three finest runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Extrapolation {
    /// f*, the extrapolated value at h → 0.
    pub value: f64,
    /// The observed order p.
    pub order: f64,
    /// False when the three values do not converge monotonically or p is outside [0.5, 4]:
    /// the estimate is then printed but not used for errors.
    pub trustworthy: bool,
}

/// Orders accepted as plausible for the Richardson estimate.
pub const TRUSTED_ORDERS: (f64, f64) = (0.5, 4.0);

/// Richardson extrapolation from (h, f) pairs, using the three smallest h. None when there are
/// fewer than three distinct h or the differences change sign (oscillatory convergence: no
/// order can be fitted).
pub fn richardson(points: &[(f64, f64)]) -> Option<Extrapolation> {
    let mut p: Vec<(f64, f64)> = points.to_vec();
    p.sort_by(|a, b| b.0.total_cmp(&a.0));
    p.dedup_by(|a, b| a.0 == b.0);
    if p.len() < 3 {
        return None;
    }
    let [(h1, f1), (h2, f2), (h3, f3)] = [p[p.len() - 3], p[p.len() - 2], p[p.len() - 1]];
    let (d12, d23) = (f1 - f2, f2 - f3);
    if d23 == 0.0 {
        // Converged to round-off between the two finest.
        return Some(Extrapolation {
            value: f3,
            order: f64::INFINITY,
            trustworthy: d12 == 0.0,
        });
    }
    if d12 * d23 <= 0.0 {
        return None;
    }
    let ratio = d12 / d23;
    // (h1ᵖ − h2ᵖ)/(h2ᵖ − h3ᵖ) grows with p; bisect for the p that matches the observed ratio.
    let g = |q: f64| (h1.powf(q) - h2.powf(q)) / (h2.powf(q) - h3.powf(q)) - ratio;
    let (mut lo, mut hi) = (0.01, 12.0);
    if g(lo) * g(hi) > 0.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(lo) * g(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let order = 0.5 * (lo + hi);
    let value = f3 - d23 * h3.powf(order) / (h2.powf(order) - h3.powf(order));
    Some(Extrapolation {
        value,
        order,
        trustworthy: (TRUSTED_ORDERS.0..=TRUSTED_ORDERS.1).contains(&order),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) {
        assert!((a - b).abs() <= tol * b.abs().max(1.0), "{a} vs {b}");
    }

    /// f = 10 + 3·h² sampled at n = 2, 3, 4, 6: the extrapolation recovers 10 and p = 2 (any
    /// three points of an exact power law determine it).
    #[test]
    fn richardson_recovers_an_exact_power_law() {
        let pts: Vec<(f64, f64)> = [2.0, 3.0, 4.0, 6.0]
            .iter()
            .map(|n| (1.0 / n, 10.0 + 3.0 / (n * n)))
            .collect();
        let e = richardson(&pts).unwrap();
        close(e.value, 10.0, 1e-9);
        close(e.order, 2.0, 1e-6);
        assert!(e.trustworthy);
        // First order from above and below.
        for c in [5.0, -5.0] {
            let pts: Vec<(f64, f64)> = [2.0, 4.0, 8.0]
                .iter()
                .map(|n| (1.0 / n, 7.0 + c / n))
                .collect();
            let e = richardson(&pts).unwrap();
            close(e.value, 7.0, 1e-9);
            close(e.order, 1.0, 1e-6);
        }
    }

    #[test]
    fn oscillation_and_too_few_points_give_no_extrapolation() {
        assert!(richardson(&[(0.5, 1.0), (0.25, 2.0)]).is_none());
        assert!(richardson(&[(0.5, 1.0), (0.25, 2.0), (0.125, 1.5)]).is_none());
        // A very high apparent order is reported but not trusted.
        let e = richardson(&[(0.5, 2.0), (0.25, 1.0), (0.125, 0.999)]).unwrap();
        assert!(!e.trustworthy, "{e:?}");
    }
}
