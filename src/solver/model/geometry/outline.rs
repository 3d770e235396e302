//! What every cross-section of a tube answers, so that the rest of the solver asks its section
//! instead of matching its shape: its sizes, its wall's area, the layers of the particle lattice
//! through its wall, the wall-line metric the analysis reads a deformed tube with, and whether
//! its folds are read by harmonics around an axis (a round tube) or face by face (a polygon).
//! Each shape answers in its own file. Units: mm, mm², mm³.
//!
//! A leaf of the geometry: imports nothing of the model.

use crate::solver::Real;

/// One layer of the particle lattice through the wall: where it lies (a round tube's mid-radius,
/// a polygon's offset from its mid-line), mm; its particles around; the volume of each over an
/// axial length dz, mm³.
pub type Ring = (Real, usize, Real);

/// The questions a cross-section answers. Engine-facing answers (the lattice) keep each shape's
/// own arithmetic, so that a shape's particles do not depend on how it is asked.
pub trait Outline {
    /// The shape's name in a case (`tube.section`): "round", "rectangular", "hexagonal".
    fn name(&self) -> &'static str;

    /// The wall thickness t, mm.
    fn thickness_mm(&self) -> Real;

    /// The size across the section at the wall's mid-surface, mm: the scale a sideways drift
    /// of the tube is measured against, and the wall's slenderness with t.
    fn width_mm(&self) -> Real;

    /// The name of [`Outline::width_mm`] in a ratio: "d", "b", "w".
    fn width_symbol(&self) -> &'static str;

    /// The name of [`Outline::width_mm`] in a sentence: "mean diameter", "larger side".
    fn width_name(&self) -> &'static str;

    /// From the centre to the undeformed outer surface, mm, as far as it goes.
    fn outer_mm(&self) -> Real;

    /// From the centre to the outer surface along the plates' normal in a lateral crush, mm.
    fn half_height_mm(&self) -> Real;

    /// The bore between the plates in a lateral crush, mm.
    fn bore_mm(&self) -> Real;

    /// How a message names [`Outline::bore_mm`] by the case's fields.
    fn bore_formula(&self) -> &'static str;

    /// The wall's cross-section area, mm².
    fn area_mm2(&self) -> Real;

    /// The section's lengths for a reader: "t 3.2 mm, d 22.2 mm".
    fn describe(&self) -> String;

    /// Whether the section has an axis of symmetry for the axisymmetric model to revolve it
    /// about: a round tube's alone.
    fn revolves(&self) -> bool {
        false
    }

    /// t and d of the round tube the axisymmetric model revolves, mm. Another shape reads as the
    /// round tube of its mid-line's length: only the axisymmetric model asks, and the checks
    /// refuse it any section that does not [`Outline::revolves`].
    fn revolved(&self) -> (Real, Real);

    /// Particles around layer `j` of the wall at spacing h, exactly as [`Outline::ring`] lays
    /// them (at least 8).
    fn around(&self, j: u32, h: Real) -> u64;

    /// [`Outline::around`] in floating point, for any section whose fields are finite and
    /// positive: it cannot wrap or saturate.
    fn around_f64(&self, j: u32, h: Real) -> f64;

    /// Layer `j` of the wall at spacing h, its particles' volumes over an axial length dz. The
    /// volumes of every layer add up to the wall's area times dz.
    fn ring(&self, j: u32, h: Real, dz: Real) -> Ring;

    /// Particle `i` of a layer in the cross-section's own axes (u, v), mm.
    fn point(&self, ring: &Ring, i: usize) -> (Real, Real);

    /// The wall-line metric, around: where on the wall a point at (dx, dy) from the section's
    /// centre lies, as an angle in (−π, π].
    fn angle(&self, dx: Real, dy: Real) -> Real;

    /// The wall-line metric, out: how far from the centre a point at (dx, dy) lies along the
    /// wall's outward normal, mm; the undeformed outer surface reads [`Outline::outer_mm`].
    fn reach(&self, dx: Real, dy: Real) -> Real;

    /// The wall-line metric, faces: beside which face's middle a point at (dx, dy) lies,
    /// numbered anticlockwise as their angles run (None nearer a corner, and always for a
    /// section without faces).
    fn face(&self, dx: Real, dy: Real) -> Option<usize>;

    /// How many faces its folds are read on: 0 for a section read by its harmonics around the
    /// axis (rings and lobes), else its flat faces, each folding out or in.
    fn faces(&self) -> usize {
        0
    }

    /// The fields that set its particle count, and how the count grows with them.
    fn particle_fields(&self) -> (&'static [&'static str], &'static str);
}

/// The offset from the mid-line of layer `j` through a wall t thick at spacing h, mm.
pub(super) fn offset(t: Real, h: Real, j: u32) -> Real {
    -0.5 * t + (j as Real + 0.5) * h
}

/// Particles along a curve of this length at spacing h (at least 8).
pub(super) fn around_length(length: f64, h: f64) -> u64 {
    ((length / h).round() as u64).max(8)
}

/// The lattice of a section whose layers are its mid-line offset e through the wall (a polygon
/// with rounded corners), given the curve's length P(e) (`perimeter`) and the point at arc
/// length s along it (`point_at`): layer `j` of a wall t thick at spacing h is round(P(e)/h)
/// particles spread evenly along its curve, each h·P(e)/count times dz. A band h thick about
/// such a curve has area h·P(e) exactly, so the volumes are exact.
pub(super) struct OffsetCurves<P, Q> {
    pub thickness_mm: Real,
    pub perimeter: P,
    pub point_at: Q,
}

impl<P: Fn(Real) -> Real, Q: Fn(Real, Real) -> (Real, Real)> OffsetCurves<P, Q> {
    /// [`Outline::around`].
    pub fn around(&self, j: u32, h: Real) -> u64 {
        around_length((self.perimeter)(offset(self.thickness_mm, h, j)), h)
    }

    /// [`Outline::around_f64`].
    pub fn around_f64(&self, j: u32, h: Real) -> f64 {
        ((self.perimeter)(offset(self.thickness_mm, h, j)) / h)
            .round()
            .max(8.0)
    }

    /// [`Outline::ring`].
    pub fn ring(&self, j: u32, h: Real, dz: Real) -> Ring {
        let e = offset(self.thickness_mm, h, j);
        let length = (self.perimeter)(e);
        let count = around_length(length, h) as usize;
        (e, count, h * length / count as Real * dz)
    }

    /// [`Outline::point`].
    pub fn point(&self, &(e, count, _): &Ring, i: usize) -> (Real, Real) {
        let step = (self.perimeter)(e) / count as Real;
        (self.point_at)(e, (i as Real + 0.5) * step)
    }
}
