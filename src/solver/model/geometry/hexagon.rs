//! A hexagonal tube's cross-section: the wall's mid-line is a regular hexagon of side s whose
//! corners are rounded to circular arcs of radius r, centred on the tube's axis; the wall is t
//! thick about it. One corner points along +u, so that two flats face ±v: the plates of a
//! lateral crush (normal to v) meet flats. Units: mm, mm², mm⁴.
//!
//! With the apothem a = s·√3/2 (half the width across the flats), each flat is
//! f = s − 2r/√3 long, and each corner's arc, turning 60°, is centred c = (a − r)/cos 30° from
//! the axis. The curves the lattice lays particles on are the mid-line offset by e through the
//! wall (−t/2 < e < t/2): the same flats and arcs of radius r + e, so their length is
//! P(e) = 6f + 2π(r + e). As for a rectangle, a band of the wall h thick about such a curve has
//! area h·P(e) exactly and any piece of it h times the length of the curve it holds: particles
//! spread evenly along a curve have equal and exact volumes, and they add up to t·P(0)·l.
//!
//! The wall-line metric reads a point by the nearest point of the undeformed mid-line: its arc
//! length from the corner at +u as an angle (the corners at multiples of 60°, the flats' middles
//! between, as a round tube's polar angle), which flat's middle half it lies beside, and how far
//! out it is by the signed distance from the undeformed outer surface. Its folds are read face
//! by face (six faces).

use super::outline::{OffsetCurves, Outline, Ring};
use crate::solver::model::checker::Checker;
use crate::solver::model::spec::Tube;
use crate::solver::Real;
use std::f64::consts::PI;

/// The fields of a hexagonal tube's own.
pub const FIELDS: &[&str] = &["tube.side_mm", "tube.corner_radius_mm"];

/// Sides of the polygon.
const SIDES: usize = 6;

/// Half the angle a side subtends at the axis, π/6: half a corner's turn.
const HALF: Real = PI / SIDES as Real;

/// The cross-section of a regular hexagonal tube with rounded corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hexagon {
    /// Wall thickness t.
    pub thickness_mm: Real,
    /// Side s of the mid-line's hexagon, corner to corner with its corners sharp.
    pub side_mm: Real,
    /// Radius r of the mid-line's corners.
    pub corner_radius_mm: Real,
}

impl Hexagon {
    /// The hexagon a tube's spec describes, its omitted corner radius (= t) filled in. A
    /// missing side reads NaN: the checks name it.
    pub fn of(tube: &Tube) -> Hexagon {
        Hexagon {
            thickness_mm: tube.thickness_mm,
            side_mm: tube.side_mm.unwrap_or(Real::NAN),
            corner_radius_mm: tube.corner_radius_mm.unwrap_or(tube.thickness_mm),
        }
    }

    /// A hexagonal tube's own checks: a side given and positive, the wall thinner than the
    /// apothem, the corner radius from t/2 (a sharp inner corner) to the apothem (a circle).
    pub(in crate::solver::model) fn check(c: &mut Checker, t: &Tube) {
        match t.side_mm {
            None => c.fail("tube.side_mm", "is required for a hexagonal section"),
            Some(s) => c.positive("tube.side_mm", s),
        }
        let h = Hexagon::of(t);
        let fine = |v: f64| v.is_finite() && v > 0.0;
        if !(fine(h.thickness_mm) && fine(h.side_mm)) {
            return;
        }
        let a = h.apothem();
        if h.thickness_mm >= a {
            c.fail(
                "tube.thickness_mm",
                &format!(
                    "must be < half the width across the flats, side_mm · √3 / 2 = {a} mm (the \
                     wall would close the bore)"
                ),
            );
            return;
        }
        if let Some(radius) = t.corner_radius_mm {
            let field = "tube.corner_radius_mm";
            if !radius.is_finite() || radius < h.thickness_mm / 2.0 {
                c.fail(
                    field,
                    &format!(
                        "must be at least thickness_mm / 2 = {} mm (the radius of the wall's \
                         mid-line at a corner: below it the inner surface's corner would have a \
                         negative radius)",
                        h.thickness_mm / 2.0
                    ),
                );
            } else if radius > a {
                c.fail(
                    field,
                    &format!(
                        "must be at most half the width across the flats, side_mm · √3 / 2 = \
                         {a} mm (the corners would meet: a round tube)"
                    ),
                );
            }
        }
    }

    /// The apothem a = s·√3/2 of the mid-line's hexagon: half its width across the flats, mm.
    pub fn apothem(&self) -> Real {
        self.side_mm / (2.0 * HALF.tan())
    }

    /// A flat's length, f = s − 2r·tan 30°, mm.
    pub fn flat_mm(&self) -> Real {
        self.side_mm - 2.0 * self.corner_radius_mm * HALF.tan()
    }

    /// The corner arcs' centres' distance from the axis, c = (a − r)/cos 30°, mm.
    fn centre(&self) -> Real {
        (self.apothem() - self.corner_radius_mm) / HALF.cos()
    }

    /// Its lattice: the mid-line offset through the wall ([`OffsetCurves`]).
    fn curves(
        &self,
    ) -> OffsetCurves<impl Fn(Real) -> Real + '_, impl Fn(Real, Real) -> (Real, Real) + '_> {
        OffsetCurves {
            thickness_mm: self.thickness_mm,
            perimeter: |e| self.perimeter_at(e),
            point_at: |e, s| self.point_at(e, s),
        }
    }

    /// Length of the mid-line offset by `e` outward, P(e) = 6f + 2π(r + e), mm.
    pub fn perimeter_at(&self, e: Real) -> Real {
        SIDES as Real * self.flat_mm() + 2.0 * PI * (self.corner_radius_mm + e)
    }

    /// The point at arc length `s` along the mid-line offset by `e`, counted anticlockwise
    /// from the corner at +u, as (u, v).
    pub fn point_at(&self, e: Real, s: Real) -> (Real, Real) {
        let radius = self.corner_radius_mm + e;
        let piece = self.flat_mm() + 2.0 * HALF * radius;
        let s = s.rem_euclid(SIDES as Real * piece);
        let k = (s / piece + 0.5).floor();
        let sigma = s - k * piece;
        let arc = HALF * radius;
        let c = self.centre();
        // About the corner at +u: round the arc, then along the flat beyond it.
        let (x, y) = if sigma.abs() <= arc {
            let phi = sigma / radius;
            (c + radius * phi.cos(), radius * phi.sin())
        } else {
            let along = sigma.abs() - arc;
            let y = radius * HALF.sin() + along * HALF.cos();
            (
                c + radius * HALF.cos() - along * HALF.sin(),
                y.copysign(sigma),
            )
        };
        let (sin, cos) = (2.0 * HALF * k).sin_cos();
        (x * cos - y * sin, x * sin + y * cos)
    }

    /// The nearest point of the mid-line to (u, v): which corner's piece it is on (0 to 5 from
    /// +u), on which side of the corner (+1 anticlockwise), its arc length from the corner,
    /// its distance beyond the mid-line (signed, positive outward), and whether it lies beside
    /// the middle half of a flat.
    fn nearest(&self, u: Real, v: Real) -> (usize, Real, Real, Real, bool) {
        let step = 2.0 * HALF;
        let k = ((v.atan2(u) / step).round() as i64).rem_euclid(SIDES as i64) as usize;
        let (sin, cos) = (step * k as Real).sin_cos();
        let (x, y) = (u * cos + v * sin, v * cos - u * sin);
        let side = if y >= 0.0 { 1.0 } else { -1.0 };
        let r = self.corner_radius_mm;
        let f = self.flat_mm();
        let (qx, qy) = (x - self.centre(), y.abs());
        let along = qy * HALF.cos() - qx * HALF.sin();
        if along <= 0.0 {
            let phi = qy.atan2(qx).clamp(0.0, HALF);
            (k, side, r * phi, qx.hypot(qy) - r, false)
        } else {
            let beyond = qx * HALF.cos() + qy * HALF.sin() - r;
            let middle = f > 0.0 && along >= 0.25 * f;
            (k, side, HALF * r + along.min(0.5 * f), beyond, middle)
        }
    }

    /// The signed distance of (u, v) from the undeformed outer surface (positive outside), mm.
    pub fn beyond_outer(&self, u: Real, v: Real) -> Real {
        self.nearest(u, v).3 - 0.5 * self.thickness_mm
    }

    /// The wall's second moment of area about any axis through the centre, mm⁴ (the same about
    /// every axis, by the hexagon's symmetry): half the polar moment J = ∫ r² dA, integrated
    /// exactly over the offset curves through the wall, each flat at distance a + e and each
    /// arc of radius r + e about its centre c from the axis.
    pub fn second_moment_mm4(&self) -> Real {
        let (t, a, r, f, c) = (
            self.thickness_mm,
            self.apothem(),
            self.corner_radius_mm,
            self.flat_mm(),
            self.centre(),
        );
        let t3 = t.powi(3);
        // Per side: the flat, ∫∫ (p² + x²) dx de; the arc, ∫∫ (c² + ρ² + 2cρ cos φ) ρ dφ de.
        let flat = f * (a * a * t + t3 / 12.0) + f.powi(3) * t / 12.0;
        let arc = 2.0 * HALF * (c * c * r * t + r.powi(3) * t + r * t3 / 4.0)
            + 4.0 * c * HALF.sin() * (r * r * t + t3 / 12.0);
        0.5 * SIDES as Real * (flat + arc)
    }
}

impl Outline for Hexagon {
    fn name(&self) -> &'static str {
        "hexagonal"
    }

    fn thickness_mm(&self) -> Real {
        self.thickness_mm
    }

    /// The width across the flats, 2a = s·√3.
    fn width_mm(&self) -> Real {
        2.0 * self.apothem()
    }

    fn width_symbol(&self) -> &'static str {
        "w"
    }

    fn width_name(&self) -> &'static str {
        "width across the flats"
    }

    /// Out to a corner: c + r + t/2.
    fn outer_mm(&self) -> Real {
        self.centre() + self.corner_radius_mm + 0.5 * self.thickness_mm
    }

    /// Out to a flat: a + t/2.
    fn half_height_mm(&self) -> Real {
        self.apothem() + 0.5 * self.thickness_mm
    }

    /// 2a − t.
    fn bore_mm(&self) -> Real {
        2.0 * self.apothem() - self.thickness_mm
    }

    fn bore_formula(&self) -> &'static str {
        "the bore between the plates' flats (side_mm · √3 - thickness_mm)"
    }

    /// t·P(0).
    fn area_mm2(&self) -> Real {
        self.thickness_mm * self.perimeter_at(0.0)
    }

    fn describe(&self) -> String {
        format!(
            "t {} mm, hexagon side {} mm, corner r {} mm",
            self.thickness_mm, self.side_mm, self.corner_radius_mm
        )
    }

    fn revolved(&self) -> (Real, Real) {
        (self.thickness_mm, self.perimeter_at(0.0) / PI)
    }

    fn around(&self, j: u32, h: Real) -> u64 {
        self.curves().around(j, h)
    }

    fn around_f64(&self, j: u32, h: Real) -> f64 {
        self.curves().around_f64(j, h)
    }

    fn ring(&self, j: u32, h: Real, dz: Real) -> Ring {
        self.curves().ring(j, h, dz)
    }

    fn point(&self, ring: &Ring, i: usize) -> (Real, Real) {
        self.curves().point(ring, i)
    }

    /// The nearest mid-line point's arc length from the corner at +u, as a share of the
    /// perimeter, as an angle in (−π, π].
    fn angle(&self, dx: Real, dy: Real) -> Real {
        let (k, side, s, _, _) = self.nearest(dx, dy);
        let piece = self.flat_mm() + 2.0 * HALF * self.corner_radius_mm;
        let turn = 2.0 * PI * (k as Real * piece + side * s) / (SIDES as Real * piece);
        if turn > PI {
            turn - 2.0 * PI
        } else {
            turn
        }
    }

    /// [`Outline::outer_mm`] plus the signed distance from the undeformed outer surface.
    fn reach(&self, dx: Real, dy: Real) -> Real {
        self.outer_mm() + self.beyond_outer(dx, dy)
    }

    /// The flat between corners k and k + 1 is face k, its middle at (2k + 1)·30°.
    fn face(&self, dx: Real, dy: Real) -> Option<usize> {
        let (k, side, _, _, middle) = self.nearest(dx, dy);
        middle.then_some(if side > 0.0 {
            k
        } else {
            (k + SIDES - 1) % SIDES
        })
    }

    fn faces(&self) -> usize {
        SIDES
    }

    fn particle_fields(&self) -> (&'static [&'static str], &'static str) {
        (
            &[
                "tube.thickness_mm",
                "tube.side_mm",
                "tube.length_mm",
                "discretization.particles_through_thickness",
            ],
            "side_mm · length_mm · n² / thickness_mm²",
        )
    }
}

#[cfg(test)]
mod tests;
