//! The flow stress of a hardening, rate-sensitive metal: σ_f = σ_s(ε_p) · R(ε̇_p), the static
//! hardening curve ([`Hardening`]) times a strain-rate factor ([`Rate`]), with the slopes the
//! return mapping needs. Stress in MPa, plastic strain rate in 1/ms (the solver's time unit;
//! the case gives its rate constants in 1/s).

use crate::solver::Real;

/// Most points a tabulated curve may have (each lookup is a binary search, and the law is held
/// by value: 16 bytes a point).
pub const MAX_CURVE_POINTS: usize = 100;

/// How a tabulated curve goes on past its last point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extrapolation {
    /// The last stress, for every larger strain.
    Flat,
    /// The last segment's slope, continued.
    LastSlope,
}

/// A piecewise-linear true stress – equivalent plastic strain curve, held by value so that a
/// law stays `Copy`. Its first point is at ε_p = 0, strains increase, stresses do not decrease
/// (the case's checks hold all three).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Table {
    points: [[Real; 2]; MAX_CURVE_POINTS],
    len: usize,
    extrapolation: Extrapolation,
}

impl Table {
    /// The curve through `points` ([ε_p, σ MPa]), at most [`MAX_CURVE_POINTS`] of them (more
    /// are cut; the case's checks refuse them first). At least one point.
    pub fn new(points: &[[Real; 2]], extrapolation: Extrapolation) -> Table {
        let len = points.len().clamp(1, MAX_CURVE_POINTS);
        let mut table = Table {
            points: [[0.0; 2]; MAX_CURVE_POINTS],
            len,
            extrapolation,
        };
        table.points[..len.min(points.len())].copy_from_slice(&points[..len.min(points.len())]);
        table
    }

    /// The points of the curve.
    pub fn points(&self) -> &[[Real; 2]] {
        &self.points[..self.len]
    }

    /// σ(ε_p) and dσ/dε_p. Below the first point (never, ε_p ≥ 0) the first stress; within a
    /// segment its line (the slope of the segment the strain falls in; at a point, the segment
    /// after it); past the last point as [`Extrapolation`] says.
    #[inline]
    fn at(&self, strain: Real) -> (Real, Real) {
        let p = self.points();
        if p.len() == 1 || strain < p[0][0] {
            return (p[0][1], 0.0);
        }
        let last = p.len() - 1;
        if strain >= p[last][0] {
            let [e1, s1] = p[last];
            return match self.extrapolation {
                Extrapolation::Flat => (s1, 0.0),
                Extrapolation::LastSlope => {
                    let [e0, s0] = p[last - 1];
                    let slope = (s1 - s0) / (e1 - e0);
                    (s1 + slope * (strain - e1), slope)
                }
            };
        }
        // The segment [k, k + 1] with p[k].strain <= strain < p[k + 1].strain.
        let k = p.partition_point(|q| q[0] <= strain) - 1;
        let ([e0, s0], [e1, s1]) = (p[k], p[k + 1]);
        let slope = (s1 - s0) / (e1 - e0);
        (s0 + slope * (strain - e0), slope)
    }
}

/// The static hardening curve σ_s(ε_p): its value at ε_p = 0 is the yield stress σy.
// The table is held by value (1.6 kB) so that a law stays `Copy`; a law is built once a run and
// read by reference in the stress loop, so its size costs nothing there.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hardening {
    /// A tabulated curve.
    Table(Table),
    /// Swift: σ = K (ε₀ + ε_p)ⁿ, with ε₀ = (σy / K)^(1/n) so that σ(0) = σy.
    Swift { k: Real, e0: Real, n: Real },
    /// Ludwik: σ = σy + K ε_pⁿ (the strain term of Johnson–Cook).
    Ludwik {
        yield_stress: Real,
        k: Real,
        n: Real,
    },
}

impl Hardening {
    /// Swift's law of the yield stress σy, the strength K (MPa) and the exponent n.
    pub fn swift(yield_stress: Real, k: Real, n: Real) -> Hardening {
        Hardening::Swift {
            k,
            e0: (yield_stress / k).powf(1.0 / n),
            n,
        }
    }

    /// σ_s(ε_p) and dσ_s/dε_p, MPa. Ludwik's slope is infinite at ε_p = 0 for n < 1; the
    /// return mapping never asks there (it evaluates slopes only past the start of the step's
    /// plastic flow).
    #[inline]
    pub fn at(&self, strain: Real) -> (Real, Real) {
        match *self {
            Hardening::Table(ref t) => t.at(strain),
            Hardening::Swift { k, e0, n } => {
                let base = e0 + strain;
                let power = base.powf(n);
                (k * power, k * n * power / base)
            }
            Hardening::Ludwik { yield_stress, k, n } => {
                if strain <= 0.0 {
                    return (yield_stress, Real::INFINITY);
                }
                let power = strain.powf(n);
                (yield_stress + k * power, k * n * power / strain)
            }
        }
    }
}

/// The largest plastic strain [`Hardening::necking_strain`] looks to.
pub const NECKING_SEARCH_LIMIT: Real = 5.0;

impl Hardening {
    /// The plastic strain at which a bar of this curve necks in tension: the first ε_p in
    /// [0, [`NECKING_SEARCH_LIMIT`]] where the hardening slope has fallen to the stress,
    /// dσ/dε_p ≤ σ (Considère's criterion, reading the true strain as ε_p, the elastic strain
    /// left out); the limit itself if the curve hardens faster than that all the way there.
    /// 0 for a perfectly plastic curve.
    pub fn necking_strain(&self) -> Real {
        let necked = |e: Real| {
            let (stress, slope) = self.at(e);
            slope <= stress
        };
        if necked(0.0) {
            return 0.0;
        }
        // A scan to bracket the first crossing, then bisection within the bracket.
        const STEP: Real = 1e-4;
        let steps = (NECKING_SEARCH_LIMIT / STEP) as usize;
        let Some(k) = (1..=steps).find(|&k| necked(k as Real * STEP)) else {
            return NECKING_SEARCH_LIMIT;
        };
        let (mut lo, mut hi) = ((k - 1) as Real * STEP, k as Real * STEP);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if necked(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }

    /// The engineering ultimate tensile stress, MPa: the true stress at the necking strain ε_u
    /// over the bar's stretch e^(ε_u). At least σy (the engineering stress rises until the bar
    /// necks); σy for a perfectly plastic curve.
    pub fn ultimate_tensile_stress(&self) -> Real {
        let e = self.necking_strain();
        self.at(e).0 * (-e).exp()
    }
}

/// The factor R(ε̇_p) ≥ 1 on the static flow stress, of the equivalent plastic strain rate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rate {
    /// Rate-independent: R = 1.
    None,
    /// Cowper–Symonds: R = 1 + (ε̇_p / D)^(1/q); `d` in 1/ms.
    CowperSymonds { d: Real, inverse_q: Real },
    /// Johnson–Cook's rate term: R = 1 + C ln(ε̇_p / ε̇₀) above the reference rate ε̇₀ (1/ms),
    /// 1 below it (the term is not let fall below the static curve).
    JohnsonCook { c: Real, reference: Real },
}

impl Rate {
    /// Cowper–Symonds of D (1/s) and q.
    pub fn cowper_symonds(d_per_s: Real, q: Real) -> Rate {
        Rate::CowperSymonds {
            d: d_per_s * 1e-3,
            inverse_q: 1.0 / q,
        }
    }

    /// Johnson–Cook's rate term of C and the reference rate ε̇₀ (1/s).
    pub fn johnson_cook(c: Real, reference_per_s: Real) -> Rate {
        Rate::JohnsonCook {
            c,
            reference: reference_per_s * 1e-3,
        }
    }

    /// The law read at every strain rate times `scale`: R(scale · ε̇), by dividing its rate
    /// constant (Cowper–Symonds' D, Johnson–Cook's ε̇₀) by `scale`. 1 leaves it as it is.
    pub fn at_rates_scaled(self, scale: Real) -> Rate {
        match self {
            Rate::None => Rate::None,
            Rate::CowperSymonds { d, inverse_q } => Rate::CowperSymonds {
                d: d / scale,
                inverse_q,
            },
            Rate::JohnsonCook { c, reference } => Rate::JohnsonCook {
                c,
                reference: reference / scale,
            },
        }
    }

    /// R(ε̇) and dR/dε̇ (ms) at the plastic strain rate `rate` ≥ 0 (1/ms).
    #[inline]
    pub fn at(&self, rate: Real) -> (Real, Real) {
        match *self {
            Rate::None => (1.0, 0.0),
            Rate::CowperSymonds { d, inverse_q } => {
                if rate <= 0.0 {
                    return (1.0, Real::INFINITY);
                }
                let power = (rate / d).powf(inverse_q);
                (1.0 + power, inverse_q * power / rate)
            }
            Rate::JohnsonCook { c, reference } => {
                if rate <= reference {
                    return (1.0, 0.0);
                }
                (1.0 + c * (rate / reference).ln(), c / rate)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_is_linear_between_its_points_and_extrapolates_as_asked() {
        let points = [[0.0, 100.0], [0.1, 150.0], [0.3, 170.0]];
        let flat = Table::new(&points, Extrapolation::Flat);
        assert_eq!(flat.at(0.0), (100.0, 500.0));
        assert_eq!(flat.at(0.05), (125.0, 500.0));
        let (s, slope) = flat.at(0.2);
        assert!((s - 160.0).abs() < 1e-12 && (slope - 100.0).abs() < 1e-9);
        assert_eq!(flat.at(0.5), (170.0, 0.0));
        let sloped = Table::new(&points, Extrapolation::LastSlope);
        let (s, slope) = sloped.at(0.5);
        assert!((s - 190.0).abs() < 1e-9 && (slope - 100.0).abs() < 1e-9);
        assert_eq!(
            Table::new(&[[0.0, 80.0]], Extrapolation::LastSlope).at(2.0),
            (80.0, 0.0)
        );
    }

    #[test]
    fn swift_starts_at_the_yield_stress_and_ludwik_adds_to_it() {
        let (s, _) = Hardening::swift(250.0, 600.0, 0.2).at(0.0);
        assert!((s - 250.0).abs() < 1e-9, "{s}");
        // K (ε₀ + 0.1)ⁿ with ε₀ = (250/600)^5.
        let e0 = (250.0f64 / 600.0).powi(5);
        let (s, slope) = Hardening::swift(250.0, 600.0, 0.2).at(0.1);
        assert!((s - 600.0 * (e0 + 0.1).powf(0.2)).abs() < 1e-9);
        assert!((slope - 0.2 * s / (e0 + 0.1)).abs() < 1e-9);
        let ludwik = Hardening::Ludwik {
            yield_stress: 324.0,
            k: 114.0,
            n: 0.42,
        };
        assert_eq!(ludwik.at(0.0).0, 324.0);
        assert!((ludwik.at(1.0).0 - 438.0).abs() < 1e-12);
    }

    /// Swift's law necks where ε₀ + ε_p = n (dσ/dε = n σ / (ε₀ + ε_p) = σ): true stress K nⁿ,
    /// engineering stress K nⁿ e^(−(n − ε₀)).
    #[test]
    fn swift_necks_where_its_strain_equals_its_exponent() {
        let law = Hardening::swift(205.0, 1400.0, 0.44);
        let Hardening::Swift { e0, .. } = law else {
            unreachable!()
        };
        let eu = law.necking_strain();
        assert!((eu - (0.44 - e0)).abs() < 1e-9, "{eu}");
        let uts = 1400.0 * 0.44f64.powf(0.44) * (-(0.44 - e0)).exp();
        assert!((law.ultimate_tensile_stress() - uts).abs() < 1e-6);
        // By hand: 0.44^0.44 = e^(0.44 ln 0.44) = e^(−0.36123) = 0.69677; 1400 · 0.69677 = 975.5
        // MPa true; ε₀ = (205/1400)^(1/0.44) = 0.012697, e^(−0.427303) = 0.65226: 636.3 MPa.
        assert!((law.ultimate_tensile_stress() - 636.3).abs() < 0.1);
    }

    #[test]
    fn a_curve_that_does_not_harden_necks_at_once_at_its_yield_stress() {
        let flat = Hardening::Table(Table::new(&[[0.0, 250.0]], Extrapolation::Flat));
        assert_eq!(flat.necking_strain(), 0.0);
        assert_eq!(flat.ultimate_tensile_stress(), 250.0);
    }

    /// A table necks at the first point past which its segment's slope is at most the stress,
    /// or within a segment where the stress climbs to the slope.
    #[test]
    fn a_table_necks_where_its_slope_falls_to_its_stress() {
        // Slope 1000 up to 0.1 (stress 100 → 200), then 150 < 200: necks at 0.1.
        let t = Table::new(
            &[[0.0, 100.0], [0.1, 200.0], [0.3, 230.0]],
            Extrapolation::Flat,
        );
        let h = Hardening::Table(t);
        assert!((h.necking_strain() - 0.1).abs() < 1e-9);
        assert!((h.ultimate_tensile_stress() - 200.0 * (-0.1f64).exp()).abs() < 1e-6);
        // One segment of slope 300 from 100 MPa, extrapolated by that slope: σ = 100 + 300 ε
        // reaches 300 at ε = 2/3.
        let t = Table::new(&[[0.0, 100.0], [0.5, 250.0]], Extrapolation::LastSlope);
        assert!((Hardening::Table(t).necking_strain() - 2.0 / 3.0).abs() < 1e-9);
    }

    /// Ludwik's law necks where K n ε^(n−1) = σy + K εⁿ; the root is checked by putting it back.
    #[test]
    fn ludwik_necks_where_its_slope_meets_its_stress() {
        let h = Hardening::Ludwik {
            yield_stress: 324.0,
            k: 114.0,
            n: 0.42,
        };
        let e = h.necking_strain();
        let (s, slope) = h.at(e);
        assert!((slope - s).abs() < 1e-6 * s, "{e}: {slope} against {s}");
        assert!(e > 0.03 && e < 0.035, "{e}");
        // Swift of exponent 10 has ε₀ + ε_p < n all the way to the search's end: no neck there.
        let steep = Hardening::swift(100.0, 200.0, 10.0);
        assert_eq!(steep.necking_strain(), NECKING_SEARCH_LIMIT);
    }

    #[test]
    fn rate_factors_are_one_at_rest_and_the_closed_forms_above() {
        let cs = Rate::cowper_symonds(40.4, 5.0);
        assert_eq!(cs.at(0.0).0, 1.0);
        // ε̇ = 40.4 /s = 0.0404 /ms: R = 2.
        assert!((cs.at(0.0404).0 - 2.0).abs() < 1e-12);
        let jc = Rate::johnson_cook(0.002, 1.0);
        assert_eq!(jc.at(1e-4), (1.0, 0.0));
        // 1000 /s = 1 /ms: 1 + 0.002 ln 1000.
        assert!((jc.at(1.0).0 - (1.0 + 0.002 * 1000f64.ln())).abs() < 1e-12);
    }
}
