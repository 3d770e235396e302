//! A round tube's cross-section: a circle of mean diameter d (at the wall's mid-surface), the
//! wall t thick about it. Units: mm, mm², mm³.
//!
//! Its lattice lays layer j of the wall at mid-radius r = d/2 − t/2 + (j + ½)h with round(2πr/h)
//! particles around, each its exact annular sector, so that the volumes add up to π d t per unit
//! length. Its wall-line metric is polar: the angle about the axis and the radius. Its folds are
//! read by their harmonics around the axis (rings and lobes), not by faces.

use super::outline::{Outline, Ring};
use crate::solver::model::checker::Checker;
use crate::solver::model::spec::{Tube, DEFAULT_MEAN_DIAMETER_MM};
use crate::solver::Real;
use std::f64::consts::PI;

/// The fields of a round tube's own.
pub const FIELDS: &[&str] = &["tube.mean_diameter_mm"];

/// The fields that set a round tube's particle count.
pub const PARTICLE_FIELDS: &[&str] = &[
    "tube.thickness_mm",
    "tube.mean_diameter_mm",
    "tube.length_mm",
    "discretization.particles_through_thickness",
];

/// The cross-section of a round tube.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Wall thickness t.
    pub thickness_mm: Real,
    /// Mean diameter d, at the wall's mid-surface.
    pub mean_diameter_mm: Real,
}

impl Circle {
    /// The circle a tube's spec describes, its omitted diameter filled in.
    pub fn of(tube: &Tube) -> Circle {
        Circle {
            thickness_mm: tube.thickness_mm,
            mean_diameter_mm: tube.mean_diameter_mm.unwrap_or(DEFAULT_MEAN_DIAMETER_MM),
        }
    }

    /// A round tube's own checks: a positive diameter more than twice the wall.
    pub(in crate::solver::model) fn check(c: &mut Checker, t: &Tube) {
        let d = t.mean_diameter_mm.unwrap_or(DEFAULT_MEAN_DIAMETER_MM);
        c.positive("tube.mean_diameter_mm", d);
        if t.thickness_mm.is_finite() && d.is_finite() && t.thickness_mm >= d / 2.0 {
            c.fail(
                "tube.thickness_mm",
                "must be < mean_diameter_mm / 2 (the wall would close the bore)",
            );
        }
    }

    /// The radius inside the wall, d/2 − t/2.
    fn inner(&self) -> Real {
        self.mean_diameter_mm / 2.0 - self.thickness_mm / 2.0
    }
}

impl Outline for Circle {
    fn name(&self) -> &'static str {
        "round"
    }

    fn thickness_mm(&self) -> Real {
        self.thickness_mm
    }

    /// The mean diameter d.
    fn width_mm(&self) -> Real {
        self.mean_diameter_mm
    }

    fn width_symbol(&self) -> &'static str {
        "d"
    }

    fn width_name(&self) -> &'static str {
        "mean diameter"
    }

    /// (d + t)/2.
    fn outer_mm(&self) -> Real {
        (self.mean_diameter_mm + self.thickness_mm) / 2.0
    }

    fn half_height_mm(&self) -> Real {
        self.outer_mm()
    }

    /// d − t.
    fn bore_mm(&self) -> Real {
        self.mean_diameter_mm - self.thickness_mm
    }

    fn bore_formula(&self) -> &'static str {
        "the bore (mean_diameter_mm - thickness_mm)"
    }

    /// π d t.
    fn area_mm2(&self) -> Real {
        PI * self.mean_diameter_mm * self.thickness_mm
    }

    fn describe(&self) -> String {
        format!("t {} mm, d {} mm", self.thickness_mm, self.mean_diameter_mm)
    }

    fn revolves(&self) -> bool {
        true
    }

    fn revolved(&self) -> (Real, Real) {
        (self.thickness_mm, self.mean_diameter_mm)
    }

    fn around(&self, j: u32, h: Real) -> u64 {
        around(self.inner() + (j as f64 + 0.5) * h, h)
    }

    fn around_f64(&self, j: u32, h: Real) -> f64 {
        let r = self.inner() + (j as f64 + 0.5) * h;
        (2.0 * PI * r / h).round().max(8.0)
    }

    /// The layer at mid-radius r, each particle its annular sector ½(r₁² − r₀²)·(2π/count)·dz.
    fn ring(&self, j: u32, h: Real, dz: Real) -> Ring {
        let inner = self.inner();
        let (r0, r1) = (inner + j as Real * h, inner + (j + 1) as Real * h);
        let r = 0.5 * (r0 + r1);
        let count = around(r, h) as usize;
        (
            r,
            count,
            0.5 * (r1 * r1 - r0 * r0) * (2.0 * PI / count as Real) * dz,
        )
    }

    fn point(&self, &(r, count, _): &Ring, i: usize) -> (Real, Real) {
        let th = (i as Real + 0.5) * 2.0 * PI / count as Real;
        (r * th.cos(), r * th.sin())
    }

    /// The polar angle.
    #[inline]
    fn angle(&self, dx: Real, dy: Real) -> Real {
        dy.atan2(dx)
    }

    /// The radius.
    #[inline]
    fn reach(&self, dx: Real, dy: Real) -> Real {
        dx.hypot(dy)
    }

    fn face(&self, _dx: Real, _dy: Real) -> Option<usize> {
        None
    }

    fn particle_fields(&self) -> (&'static [&'static str], &'static str) {
        (
            PARTICLE_FIELDS,
            "mean_diameter_mm · length_mm · n² / thickness_mm²",
        )
    }
}

/// Particles around a ring of radius r at spacing h (at least 8).
fn around(r: f64, h: f64) -> u64 {
    ((2.0 * PI * r / h).round() as u64).max(8)
}
