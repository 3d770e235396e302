//! Grid shape functions, one axis at a time, in grid units (position divided by the cell size).
//! A 3D weight is the product of three 1D weights; gradients get the 1/cell factor at the caller.

/// A separable shape function with `N` nodes per axis in a particle's stencil.
pub trait Stencil: Send + Sync + 'static {
    /// Nodes per axis that may carry weight.
    const N: usize;
    /// For a particle at `x` (grid units) with half-size `lp` (grid units): the first node of its
    /// stencil, the weights and the weight derivatives (per grid unit) of nodes `base..base+N`.
    fn eval(x: f64, lp: f64) -> (i32, [f64; 3], [f64; 3]);
}

/// Trilinear hat functions: two nodes per axis.
pub struct Linear;

impl Stencil for Linear {
    const N: usize = 2;
    #[inline(always)]
    fn eval(x: f64, _lp: f64) -> (i32, [f64; 3], [f64; 3]) {
        let base = x.floor();
        let f = x - base;
        (base as i32, [1.0 - f, f, 0.0], [-1.0, 1.0, 0.0])
    }
}

/// Uniform GIMP: the particle is a box of half-width `lp` ≤ ½ cell that never changes.
/// At most three nodes per axis carry weight.
pub struct Gimp;

impl Gimp {
    /// Weight and derivative of a node at signed distance `d = x − x_i` (grid units).
    #[inline(always)]
    fn node(d: f64, lp: f64) -> (f64, f64) {
        let a = d.abs();
        let s = d.signum();
        if a < lp {
            (1.0 - (d * d + lp * lp) / (2.0 * lp), -d / lp)
        } else if a <= 1.0 - lp {
            (1.0 - a, -s)
        } else if a < 1.0 + lp {
            let r = 1.0 + lp - a;
            (r * r / (4.0 * lp), -s * r / (2.0 * lp))
        } else {
            (0.0, 0.0)
        }
    }
}

impl Stencil for Gimp {
    const N: usize = 3;
    #[inline(always)]
    fn eval(x: f64, lp: f64) -> (i32, [f64; 3], [f64; 3]) {
        let base = (x - lp).floor();
        let mut w = [0.0; 3];
        let mut g = [0.0; 3];
        for k in 0..3 {
            let (wk, gk) = Gimp::node(x - (base + k as f64), lp);
            w[k] = wk;
            g[k] = gk;
        }
        (base as i32, w, g)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Partition of unity, zero-sum gradients and linear completeness (Σ x_i N_i = x, so
    /// Σ x_i ∂N_i = 1) must hold to round-off for any position.
    fn check<S: Stencil>(lp: f64) {
        for k in 0..1000 {
            let x = -3.0 + k as f64 * 0.00731;
            let (base, w, g) = S::eval(x, lp);
            let sum: f64 = w[..S::N].iter().sum();
            let gsum: f64 = g[..S::N].iter().sum();
            let first: f64 = (0..S::N).map(|i| (base + i as i32) as f64 * w[i]).sum();
            let slope: f64 = (0..S::N).map(|i| (base + i as i32) as f64 * g[i]).sum();
            assert!((sum - 1.0).abs() < 1e-12, "sum {sum} at {x}");
            assert!(gsum.abs() < 1e-12, "gradient sum {gsum} at {x}");
            assert!((first - x).abs() < 1e-12, "first moment {first} at {x}");
            assert!((slope - 1.0).abs() < 1e-12, "slope {slope} at {x}");
            assert!(w.iter().all(|&v| v >= 0.0));
        }
    }

    #[test]
    fn linear_is_a_partition_of_unity_and_linearly_complete() {
        check::<Linear>(0.25);
    }

    #[test]
    fn gimp_is_a_partition_of_unity_and_linearly_complete() {
        check::<Gimp>(0.25);
        check::<Gimp>(0.5);
        check::<Gimp>(0.1);
    }
}
