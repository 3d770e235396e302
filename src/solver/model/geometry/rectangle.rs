//! A rectangular tube's cross-section: the wall's mid-line is a rectangle of sides a (along u)
//! and b (along v) whose corners are quarter circles of radius r, centred on the tube's axis;
//! the wall is t thick about it. Units: mm, mm².
//!
//! The curves the lattice lays particles on are the mid-line offset by e through the wall
//! (−t/2 < e < t/2): the same straight flats (a − 2r and b − 2r long) and corners of radius
//! r + e, so their length is P(e) = 2(a − 2r) + 2(b − 2r) + 2π(r + e). A band of the wall h
//! thick about such a curve has area h·P(e) exactly, and any piece of it h times the length
//! of the curve it holds (h·Δs on a flat, (r + e)·h·Δφ on a corner): particles spread evenly
//! along a curve have equal and exact volumes.
//!
//! The wall-line metric reads a point (u, v) by the nearest point of the undeformed mid-line:
//! where around the wall it lies (its arc length, as an angle) and which face it is on; and how
//! far out it is, by the signed distance from the undeformed outer surface. Its folds are read
//! face by face (four faces).

use super::outline::{OffsetCurves, Outline, Ring};
use crate::solver::model::checker::Checker;
use crate::solver::model::spec::Tube;
use crate::solver::Real;
use std::f64::consts::{FRAC_PI_2, PI};

/// The fields of a rectangular tube's own.
pub const FIELDS: &[&str] = &["tube.side_a_mm", "tube.side_b_mm", "tube.corner_radius_mm"];

/// The cross-section of a rectangular tube with rounded corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rectangle {
    /// Wall thickness t.
    pub thickness_mm: Real,
    /// Side a along u (x in an axial crush, y in a lateral one), at the wall's mid-line.
    pub side_a_mm: Real,
    /// Side b along v (y in an axial crush, z, between the plates, in a lateral one).
    pub side_b_mm: Real,
    /// Radius r of the mid-line's corners.
    pub corner_radius_mm: Real,
}

impl Rectangle {
    /// The rectangle a tube's spec describes, its omitted lengths filled in: side b (= a) and
    /// corner radius (= t). A missing side a reads NaN: the checks name it.
    pub fn of(tube: &Tube) -> Rectangle {
        let t = tube.thickness_mm;
        let a = tube.side_a_mm.unwrap_or(Real::NAN);
        Rectangle {
            thickness_mm: t,
            side_a_mm: a,
            side_b_mm: tube.side_b_mm.unwrap_or(a),
            corner_radius_mm: tube.corner_radius_mm.unwrap_or(t),
        }
    }

    /// A rectangular tube's own checks: side a given, the sides positive and more than twice
    /// the wall, the corner radius from t/2 (a sharp inner corner) to half the smaller side.
    pub(in crate::solver::model) fn check(c: &mut Checker, t: &Tube) {
        match t.side_a_mm {
            None => c.fail("tube.side_a_mm", "is required for a rectangular section"),
            Some(a) => c.positive("tube.side_a_mm", a),
        }
        if let Some(b) = t.side_b_mm {
            c.positive("tube.side_b_mm", b);
        }
        let r = Rectangle::of(t);
        let fine = |v: f64| v.is_finite() && v > 0.0;
        let smaller = r.side_a_mm.min(r.side_b_mm);
        if !(fine(r.thickness_mm) && fine(r.side_a_mm) && fine(r.side_b_mm)) {
            return;
        }
        if r.thickness_mm >= smaller / 2.0 {
            c.fail(
                "tube.thickness_mm",
                &format!(
                    "must be < half the smaller side, min(side_a_mm, side_b_mm) / 2 = \
                     {smaller_half} mm (the wall would close the bore)",
                    smaller_half = smaller / 2.0
                ),
            );
            return;
        }
        if let Some(radius) = t.corner_radius_mm {
            let field = "tube.corner_radius_mm";
            if !radius.is_finite() || radius < r.thickness_mm / 2.0 {
                c.fail(
                    field,
                    &format!(
                        "must be at least thickness_mm / 2 = {} mm (the radius of the wall's \
                         mid-line at a corner: below it the inner surface's corner would have a \
                         negative radius)",
                        r.thickness_mm / 2.0
                    ),
                );
            } else if radius > smaller / 2.0 {
                c.fail(
                    field,
                    &format!(
                        "must be at most half the smaller side, min(side_a_mm, side_b_mm) / 2 = \
                         {} mm (the corners would overlap)",
                        smaller / 2.0
                    ),
                );
            }
        }
    }

    /// The straight flats' lengths, (a − 2r, b − 2r).
    fn flats(&self) -> (Real, Real) {
        let r = self.corner_radius_mm;
        (self.side_a_mm - 2.0 * r, self.side_b_mm - 2.0 * r)
    }

    /// The corner circles' centres, (±cu, ±cv).
    fn centres(&self) -> (Real, Real) {
        let (fa, fb) = self.flats();
        (0.5 * fa, 0.5 * fb)
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

    /// Length of the mid-line offset by `e` outward, P(e), mm.
    pub fn perimeter_at(&self, e: Real) -> Real {
        let (fa, fb) = self.flats();
        2.0 * (fa + fb) + 2.0 * PI * (self.corner_radius_mm + e)
    }

    /// The wall's cross-section area, t·P(0), mm².
    pub fn area_mm2(&self) -> Real {
        self.thickness_mm * self.perimeter_at(0.0)
    }

    /// Half the outer extents, ((a + t)/2, (b + t)/2), mm.
    pub fn outer_half(&self) -> (Real, Real) {
        let t = self.thickness_mm;
        (0.5 * (self.side_a_mm + t), 0.5 * (self.side_b_mm + t))
    }

    /// The wall's smaller second moment of area about an axis through the centre, mm⁴: the
    /// outer rounded rectangle's less the inner one's.
    pub fn least_second_moment_mm4(&self) -> Real {
        let (a, b, r, t) = (
            self.side_a_mm,
            self.side_b_mm,
            self.corner_radius_mm,
            self.thickness_mm,
        );
        let about_u = |a: Real, b: Real| {
            filled_second_moment(0.5 * (a + t), 0.5 * (b + t), r + 0.5 * t)
                - filled_second_moment(0.5 * (a - t), 0.5 * (b - t), r - 0.5 * t)
        };
        about_u(a, b).min(about_u(b, a))
    }

    /// The point at arc length `s` along the mid-line offset by `e`, counted anticlockwise from
    /// the middle of the +u face, as (u, v).
    pub fn point_at(&self, e: Real, s: Real) -> (Real, Real) {
        let (fa, fb) = self.flats();
        let radius = self.corner_radius_mm + e;
        let quarter = 0.5 * (fa + fb) + FRAC_PI_2 * radius;
        let s = s.rem_euclid(4.0 * quarter);
        let k = ((s / quarter) as usize).min(3);
        let local = s - k as Real * quarter;
        // The quarter from the +u face to the +v face, mirrored or turned into the others.
        let (u, v) = match k {
            0 => self.first_quarter(e, local),
            1 => {
                let (u, v) = self.first_quarter(e, quarter - local);
                (-u, v)
            }
            2 => {
                let (u, v) = self.first_quarter(e, local);
                (-u, -v)
            }
            _ => {
                let (u, v) = self.first_quarter(e, quarter - local);
                (u, -v)
            }
        };
        (u, v)
    }

    /// The first quarter of the curve offset by `e`: up the +u face from v = 0, round the
    /// corner, along the +v face to u = 0.
    fn first_quarter(&self, e: Real, s: Real) -> (Real, Real) {
        let (cu, cv) = self.centres();
        let radius = self.corner_radius_mm + e;
        let arc = FRAC_PI_2 * radius;
        if s < cv {
            (cu + radius, s)
        } else if s < cv + arc {
            let phi = (s - cv) / radius;
            (cu + radius * phi.cos(), cv + radius * phi.sin())
        } else {
            (cu - (s - cv - arc), cv + radius)
        }
    }

    /// Where the nearest point of the mid-line to (|u|, |v|) lies along the first quarter
    /// (arc length from the middle of the +u face), and on which part: Some(0) the +u face,
    /// Some(1) the +v face, None the corner.
    fn nearest_in_first_quarter(&self, x: Real, y: Real) -> (Real, Option<usize>) {
        let (cu, cv) = self.centres();
        let r = self.corner_radius_mm;
        let top = cv + FRAC_PI_2 * r;
        match (x >= cu, y >= cv) {
            (true, true) => (cv + r * (y - cv).atan2(x - cu), None),
            (true, false) => (y, Some(0)),
            (false, true) => (top + (cu - x), Some(1)),
            // Inside the corners' centres: the nearer face.
            (false, false) if 0.5 * self.side_a_mm - x <= 0.5 * self.side_b_mm - y => (y, Some(0)),
            (false, false) => (top + (cu - x), Some(1)),
        }
    }

    /// Where around the wall (u, v) lies: its nearest mid-line point's arc length from the
    /// middle of the +u face, as a share of the perimeter, as an angle in (−π, π] (the faces'
    /// middles at 0, π/2, π and −π/2, as the polar angle of a round tube's).
    pub fn angle(&self, u: Real, v: Real) -> Real {
        let (fa, fb) = self.flats();
        let quarter = 0.5 * (fa + fb) + FRAC_PI_2 * self.corner_radius_mm;
        let (s, _) = self.nearest_in_first_quarter(u.abs(), v.abs());
        let turn = FRAC_PI_2 * (s / quarter).clamp(0.0, 1.0);
        match (u >= 0.0, v >= 0.0) {
            (true, true) => turn,
            (false, true) => PI - turn,
            (false, false) => turn - PI,
            (true, false) => -turn,
        }
    }

    /// Which face's middle (u, v) lies beside: 0 (+u), 1 (+v), 2 (−u) or 3 (−v), numbered as
    /// their angles run, when its nearest mid-line point is on the middle half of that face's
    /// flat, where the lobes stand out most; None nearer a corner.
    pub fn face(&self, u: Real, v: Real) -> Option<usize> {
        let (fa, fb) = self.flats();
        let (x, y) = (u.abs(), v.abs());
        match self.nearest_in_first_quarter(x, y).1 {
            Some(0) if y <= 0.25 * fb => Some(if u >= 0.0 { 0 } else { 2 }),
            Some(1) if x <= 0.25 * fa => Some(if v >= 0.0 { 1 } else { 3 }),
            _ => None,
        }
    }

    /// The signed distance of (u, v) from the undeformed outer surface (positive outside), mm.
    pub fn beyond_outer(&self, u: Real, v: Real) -> Real {
        let (cu, cv) = self.centres();
        let (qx, qy) = (u.abs() - cu, v.abs() - cv);
        let outside = qx.max(0.0).hypot(qy.max(0.0));
        outside + qx.max(qy).min(0.0) - (self.corner_radius_mm + 0.5 * self.thickness_mm)
    }
}

impl Outline for Rectangle {
    fn name(&self) -> &'static str {
        "rectangular"
    }

    fn thickness_mm(&self) -> Real {
        self.thickness_mm
    }

    /// The larger side.
    fn width_mm(&self) -> Real {
        self.side_a_mm.max(self.side_b_mm)
    }

    fn width_symbol(&self) -> &'static str {
        "b"
    }

    fn width_name(&self) -> &'static str {
        "larger side"
    }

    /// Half the larger outer side.
    fn outer_mm(&self) -> Real {
        let (a, b) = self.outer_half();
        a.max(b)
    }

    /// (b + t)/2.
    fn half_height_mm(&self) -> Real {
        self.outer_half().1
    }

    /// b − t.
    fn bore_mm(&self) -> Real {
        self.side_b_mm - self.thickness_mm
    }

    fn bore_formula(&self) -> &'static str {
        "the bore between the plates (side_b_mm - thickness_mm)"
    }

    /// t·P(0).
    fn area_mm2(&self) -> Real {
        Rectangle::area_mm2(self)
    }

    fn describe(&self) -> String {
        format!(
            "t {} mm, {} x {} mm, corner r {} mm",
            self.thickness_mm, self.side_a_mm, self.side_b_mm, self.corner_radius_mm
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

    #[inline]
    fn angle(&self, dx: Real, dy: Real) -> Real {
        Rectangle::angle(self, dx, dy)
    }

    /// [`Outline::outer_mm`] plus the signed distance from the undeformed outer surface (the
    /// distance from the centre, on the faces of a square).
    #[inline]
    fn reach(&self, dx: Real, dy: Real) -> Real {
        Outline::outer_mm(self) + self.beyond_outer(dx, dy)
    }

    #[inline]
    fn face(&self, dx: Real, dy: Real) -> Option<usize> {
        Rectangle::face(self, dx, dy)
    }

    fn faces(&self) -> usize {
        4
    }

    fn particle_fields(&self) -> (&'static [&'static str], &'static str) {
        (
            &[
                "tube.thickness_mm",
                "tube.side_a_mm",
                "tube.side_b_mm",
                "tube.length_mm",
                "discretization.particles_through_thickness",
            ],
            "(side_a_mm + side_b_mm) · length_mm · n² / thickness_mm²",
        )
    }
}

/// ∫ v² dA over a filled rectangle of half-sides (A, B) with corners of radius R, mm⁴: the
/// whole rectangle, less its four R × R corner squares, plus four quarter discs centred
/// (B − R) off the axis (each πR²/4 · (B − R)² + 2(B − R)·R³/3 + πR⁴/16).
fn filled_second_moment(half_a: Real, half_b: Real, radius: Real) -> Real {
    let (a, b, r) = (half_a, half_b, radius);
    let c = b - r;
    let square = r * (b.powi(3) - c.powi(3)) / 3.0;
    let quarter = PI * r * r / 4.0 * c * c + 2.0 * c * r.powi(3) / 3.0 + PI * r.powi(4) / 16.0;
    (2.0 * a) * (2.0 * b).powi(3) / 12.0 - 4.0 * square + 4.0 * quarter
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Real, b: Real) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }

    const BOX: Rectangle = Rectangle {
        thickness_mm: 2.0,
        side_a_mm: 40.0,
        side_b_mm: 30.0,
        corner_radius_mm: 3.0,
    };

    #[test]
    fn the_curve_walks_the_perimeter_once_and_ends_where_it_began() {
        for e in [-0.75, 0.0, 0.75] {
            let p = BOX.perimeter_at(e);
            let n = 4000;
            let mut length = 0.0;
            let mut last = BOX.point_at(e, 0.0);
            for i in 1..=n {
                let next = BOX.point_at(e, p * i as Real / n as Real);
                length += (next.0 - last.0).hypot(next.1 - last.1);
                // Every point of the curve lies e beyond the mid-line: e − t/2 from the outer
                // surface.
                close(BOX.beyond_outer(next.0, next.1), e - 1.0);
                last = next;
            }
            assert!((length / p - 1.0).abs() < 1e-6, "{length} vs {p}");
            close(last.0, 20.0 + e);
            close(last.1, 0.0);
        }
    }

    #[test]
    fn the_angle_runs_with_the_arc_length_and_the_faces_follow_it() {
        let p = BOX.perimeter_at(0.0);
        for i in 0..400 {
            let s = p * (i as Real + 0.5) / 400.0;
            let (u, v) = BOX.point_at(0.0, s);
            let want = 2.0 * PI * s / p;
            let want = if want > PI { want - 2.0 * PI } else { want };
            close(BOX.angle(u, v), want);
            // The same angle from points out and in along the normal.
            let (u1, v1) = BOX.point_at(0.0, s + 1e-6);
            let (tu, tv) = ((u1 - u) / 1e-6, (v1 - v) / 1e-6);
            for e in [-0.9, 0.9] {
                let angle = BOX.angle(u + e * tv, v - e * tu);
                assert!((angle - want).abs() < 1e-5, "{angle} vs {want} at {e}");
            }
        }
        assert_eq!(BOX.face(20.0, 1.0), Some(0));
        assert_eq!(BOX.face(-5.0, 15.0), Some(1));
        assert_eq!(BOX.face(-20.0, -1.0), Some(2));
        assert_eq!(BOX.face(5.0, -15.0), Some(3));
        assert_eq!(BOX.face(19.0, 14.0), None);
        // Beyond the middle half of a face's flat (24 mm on the ±u faces).
        assert_eq!(BOX.face(20.0, 7.0), None);
        close(BOX.angle(0.0, 15.0), FRAC_PI_2);
        close(BOX.angle(-20.0, 0.0), PI);
    }

    #[test]
    fn the_second_moment_is_a_rectangles_with_sharp_corners_and_a_rings_with_round_ones() {
        // R = 0: the rectangle's (2A)(2B)³/12; R = A = B: the disc's πR⁴/4.
        close(
            filled_second_moment(21.0, 16.0, 0.0),
            42.0 * 32f64.powi(3) / 12.0,
        );
        close(filled_second_moment(5.0, 5.0, 5.0), PI * 625.0 / 4.0);
        // a = b = 2r: a round tube of mean diameter 2r, I = π(d_o⁴ − d_i⁴)/64.
        let ring = Rectangle {
            thickness_mm: 2.0,
            side_a_mm: 30.0,
            side_b_mm: 30.0,
            corner_radius_mm: 15.0,
        };
        let i = PI * (32f64.powi(4) - 28f64.powi(4)) / 64.0;
        assert!((ring.least_second_moment_mm4() / i - 1.0).abs() < 1e-12);
        // The weaker axis of a wide box is across its short side.
        let wide = BOX.least_second_moment_mm4();
        let turned = Rectangle {
            side_a_mm: 30.0,
            side_b_mm: 40.0,
            ..BOX
        };
        close(wide, turned.least_second_moment_mm4());
        assert!(wide < filled_second_moment(21.0, 16.0, 4.0));
    }

    #[test]
    fn the_outer_surface_is_at_zero_and_the_axis_inside() {
        close(BOX.beyond_outer(21.0, 0.0), 0.0);
        close(BOX.beyond_outer(0.0, -16.0), 0.0);
        close(BOX.beyond_outer(25.0, 3.0), 4.0);
        close(BOX.beyond_outer(0.0, 0.0), -16.0);
        close(BOX.area_mm2(), 2.0 * (2.0 * (34.0 + 24.0) + 6.0 * PI));
    }
}
