//! How far an elastic cylindrical shell carries a disturbance of its section along its length.
//! Units: mm.
//!
//! A round tube (mean radius R, wall t, Poisson's ratio ν) whose section is pushed out of round
//! at one place with m lobes (w ∝ cos mθ; m = 2 is an oval) answers with a disturbance that
//! decays along the axis as e^(λx). Morley's equation for the shell (Morley 1959, "An
//! improvement on Donnell's approximation for thin-walled circular cylinders", Q. J. Mech.
//! Appl. Math. 12; Donnell's with the hoop curvature's (m² − 1) that an oval needs),
//!
//!   D ∇⁴(∇² + 1/R²)² w + (E t / R²) ∂⁴w/∂x⁴ = 0,  D = E t³ / (12 (1 − ν²)),
//!
//! with w = e^(λx) cos mθ and s = λ², reads ((s − a)(s − b))² = −c s² with a = m²/R²,
//! b = (m² − 1)/R² and c = 12 (1 − ν²)/(t² R²): two quadratics, s² − (a + b ± i√c) s + ab = 0.
//! The slowest decaying of the eight roots λ sets the e-folding length 1/|Re λ|.
//!
//! Calladine's semi-membrane theory (*Theory of Shell Structures*, 1983, ch. 8: no axial
//! bending, no hoop stretching) gives the same length in closed form for a thin wall,
//! 1/β = R √(R/t) (48 (1 − ν²))^(1/4) / √((m² − 1) m²); Morley's is shorter by a few per cent
//! where R/t is small (9 % at R/t 7 for m = 2). For the d/t 14 PVC tube of docs/folding.md (R
//! 22.4, t 3.2, ν 0.42) an oval decays over 39 mm, three lobes over 16 mm and four over 10 mm:
//! a tube that folds in two lobes carries their oval far along its unfolded wall, elastically.
//!
//! Imports nothing from the rest of the crate.

use nalgebra::Complex;

/// The e-folding length, mm, over which an elastic tube of mean radius `r`, wall `t` and
/// Poisson's ratio `nu` carries an `m`-lobed disturbance of its section (m ≥ 2) along its
/// axis: 1/|Re λ| of the slowest decaying root of Morley's equation (module doc).
pub fn lobe_decay_mm(r: f64, t: f64, nu: f64, m: u32) -> f64 {
    1.0 / slowest_root(r, t, nu, m).re.abs()
}

/// Morley's equation as ((s − a)(s − b))² = −c s², s = λ²: (a, b, c), 1/mm², 1/mm² and 1/mm⁴.
fn coefficients(r: f64, t: f64, nu: f64, m: u32) -> (f64, f64, f64) {
    let m2 = f64::from(m * m);
    let c = 12.0 * (1.0 - nu * nu) / (t * t * r * r);
    (m2 / (r * r), (m2 - 1.0) / (r * r), c)
}

/// The root λ (1/mm) of Morley's equation with the smallest |Re λ| (module doc).
fn slowest_root(r: f64, t: f64, nu: f64, m: u32) -> Complex<f64> {
    let (a, b, c) = coefficients(r, t, nu, m);
    [1.0, -1.0]
        .into_iter()
        .flat_map(|sign| {
            // s² − B s + ab = 0, B = a + b ± i√c.
            let big_b = Complex::new(a + b, sign * c.sqrt());
            let root = (big_b * big_b - 4.0 * a * b).sqrt();
            [(big_b + root) / 2.0, (big_b - root) / 2.0]
        })
        .map(|s| s.sqrt())
        .min_by(|x, y| x.re.abs().total_cmp(&y.re.abs()))
        .expect("four roots")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Calladine's semi-membrane e-folding length for `m` lobes, mm (module doc).
    fn semi_membrane_decay_mm(r: f64, t: f64, nu: f64, m: u32) -> f64 {
        let m2 = f64::from(m * m);
        r * (r / t).sqrt() * (48.0 * (1.0 - nu * nu)).powf(0.25) / ((m2 - 1.0) * m2).sqrt()
    }

    /// Morley's characteristic polynomial at λ (module doc), divided by D.
    fn residual(r: f64, t: f64, nu: f64, m: u32, lambda: Complex<f64>) -> f64 {
        let (a, b, c) = coefficients(r, t, nu, m);
        let s = lambda * lambda;
        let p = ((s - a) * (s - b)).powi(2) + c * s * s;
        p.norm() / (c * s.norm() * s.norm())
    }

    #[test]
    fn the_decay_length_is_a_root_of_morleys_equation() {
        for (r, t, nu, m) in [
            (22.4, 3.2, 0.42, 2),
            (10.16, 1.27, 0.42, 3),
            (50.0, 1.0, 0.3, 4),
        ] {
            let lambda = slowest_root(r, t, nu, m);
            assert!(residual(r, t, nu, m, lambda) < 1e-9, "r {r} t {t} m {m}");
            // It decays and waves: an oval's disturbance changes sign along the tube.
            assert!(lambda.re.abs() > 0.0 && lambda.im.abs() > 0.0, "{lambda}");
            assert_eq!(lobe_decay_mm(r, t, nu, m), 1.0 / lambda.re.abs());
        }
    }

    #[test]
    fn a_thin_wall_decays_as_calladines_semi_membrane_theory_says() {
        // Semi-membrane theory is the thin-wall limit: within 1 % at R/t 1000 for an oval.
        let (r, nu) = (100.0, 0.3);
        let morley = lobe_decay_mm(r, 0.1, nu, 2);
        let semi = semi_membrane_decay_mm(r, 0.1, nu, 2);
        assert!(
            (morley / semi - 1.0).abs() < 0.01,
            "{morley} against {semi}"
        );
        // It scales as R √(R/t) there: a wall four times thinner carries the oval twice as far.
        let thinner = lobe_decay_mm(r, 0.025, nu, 2);
        assert!(
            (thinner / morley - 2.0).abs() < 0.02,
            "{thinner} against 2 × {morley}"
        );
    }

    #[test]
    fn more_lobes_die_out_faster() {
        let (r, t, nu) = (22.4, 3.2, 0.42);
        let lengths: Vec<f64> = (2..=5).map(|m| lobe_decay_mm(r, t, nu, m)).collect();
        assert!(lengths.windows(2).all(|w| w[1] < w[0]), "{lengths:?}");
        // On this thick PVC tube an oval reaches past a fold length (2H = 22.8 mm), a little
        // short of the thin-wall limit (Morley's hoop and axial terms shorten it).
        let semi = semi_membrane_decay_mm(r, t, nu, 2);
        assert!(lengths[0] > 22.8 && lengths[0] < semi && lengths[0] > 0.8 * semi);
    }
}
