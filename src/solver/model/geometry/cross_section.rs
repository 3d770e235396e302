//! The tube's cross-section as the solver stores it ([`CrossSection`]: one variant per shape,
//! `Copy`, so that a geometry stays a value), and the one place that turns a shape's name into
//! its room: the section a spec describes, the checks of its own fields, and every
//! [`Outline`] question passed on to the shape that answers it. A new shape is a file beside
//! this one and an arm in each match here. Units: mm.

use super::hexagon::{self, Hexagon};
use super::outline::{Outline, Ring};
use super::rectangle::{self, Rectangle};
use super::round::{self, Circle};
use crate::solver::model::checker::Checker;
use crate::solver::model::spec::{SectionShape, Tube};
use crate::solver::Real;

/// The tube's cross-section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CrossSection {
    /// A round tube ([`Circle`]).
    Round(Circle),
    /// A rectangular tube with rounded corners ([`Rectangle`]).
    Rectangular(Rectangle),
    /// A regular hexagonal tube with rounded corners ([`Hexagon`]).
    Hexagonal(Hexagon),
}

/// Passes a question on to the shape's room.
macro_rules! each {
    ($section:expr, $shape:ident => $answer:expr) => {
        match $section {
            CrossSection::Round($shape) => $answer,
            CrossSection::Rectangular($shape) => $answer,
            CrossSection::Hexagonal($shape) => $answer,
        }
    };
}

/// Each shape's own fields, by its name in a case.
fn own_fields(shape: SectionShape) -> &'static [&'static str] {
    match shape {
        SectionShape::Round => round::FIELDS,
        SectionShape::Rectangular => rectangle::FIELDS,
        SectionShape::Hexagonal => hexagon::FIELDS,
    }
}

impl CrossSection {
    /// The cross-section a tube's spec describes, its omitted lengths filled in (each shape
    /// says how). A length that is required and missing reads NaN: the checks name it.
    pub fn of(tube: &Tube) -> CrossSection {
        match tube.section {
            SectionShape::Round => CrossSection::Round(Circle::of(tube)),
            SectionShape::Rectangular => CrossSection::Rectangular(Rectangle::of(tube)),
            SectionShape::Hexagonal => CrossSection::Hexagonal(Hexagon::of(tube)),
        }
    }

    /// The checks of a tube's section: no length of another shape's, then the shape's own.
    pub(in crate::solver::model) fn check(c: &mut Checker, t: &Tube) {
        let own = own_fields(t.section);
        for (field, given) in t.section_lengths() {
            if given.is_none() || own.contains(&field) {
                continue;
            }
            let owners: Vec<&str> = SectionShape::ALL
                .iter()
                .filter(|s| own_fields(**s).contains(&field))
                .map(|s| s.name())
                .collect();
            let lengths: Vec<&str> = own.iter().map(|f| &f["tube.".len()..]).collect();
            c.fail(
                field,
                &format!(
                    "applies to a {} section only (tube.section is {}; its lengths are {})",
                    owners.join(" or "),
                    t.section.name(),
                    lengths.join(", ")
                ),
            );
        }
        match t.section {
            SectionShape::Round => Circle::check(c, t),
            SectionShape::Rectangular => Rectangle::check(c, t),
            SectionShape::Hexagonal => Hexagon::check(c, t),
        }
    }
}

impl Outline for CrossSection {
    fn name(&self) -> &'static str {
        each!(self, s => s.name())
    }
    fn thickness_mm(&self) -> Real {
        each!(self, s => s.thickness_mm())
    }
    fn width_mm(&self) -> Real {
        each!(self, s => s.width_mm())
    }
    fn width_symbol(&self) -> &'static str {
        each!(self, s => s.width_symbol())
    }
    fn width_name(&self) -> &'static str {
        each!(self, s => s.width_name())
    }
    fn outer_mm(&self) -> Real {
        each!(self, s => s.outer_mm())
    }
    fn half_height_mm(&self) -> Real {
        each!(self, s => s.half_height_mm())
    }
    fn bore_mm(&self) -> Real {
        each!(self, s => s.bore_mm())
    }
    fn bore_formula(&self) -> &'static str {
        each!(self, s => s.bore_formula())
    }
    fn area_mm2(&self) -> Real {
        each!(self, s => Outline::area_mm2(s))
    }
    fn describe(&self) -> String {
        each!(self, s => s.describe())
    }
    fn revolves(&self) -> bool {
        each!(self, s => s.revolves())
    }
    fn revolved(&self) -> (Real, Real) {
        each!(self, s => s.revolved())
    }
    fn around(&self, j: u32, h: Real) -> u64 {
        each!(self, s => s.around(j, h))
    }
    fn around_f64(&self, j: u32, h: Real) -> f64 {
        each!(self, s => s.around_f64(j, h))
    }
    fn ring(&self, j: u32, h: Real, dz: Real) -> Ring {
        each!(self, s => s.ring(j, h, dz))
    }
    #[inline]
    fn point(&self, ring: &Ring, i: usize) -> (Real, Real) {
        each!(self, s => s.point(ring, i))
    }
    #[inline]
    fn angle(&self, dx: Real, dy: Real) -> Real {
        each!(self, s => Outline::angle(s, dx, dy))
    }
    #[inline]
    fn reach(&self, dx: Real, dy: Real) -> Real {
        each!(self, s => s.reach(dx, dy))
    }
    #[inline]
    fn face(&self, dx: Real, dy: Real) -> Option<usize> {
        each!(self, s => Outline::face(s, dx, dy))
    }
    fn faces(&self) -> usize {
        each!(self, s => s.faces())
    }
    fn particle_fields(&self) -> (&'static [&'static str], &'static str) {
        each!(self, s => s.particle_fields())
    }
}
