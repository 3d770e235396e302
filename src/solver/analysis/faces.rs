//! A polygonal tube's faces along its length (a rectangle's four, a hexagon's six: the section's
//! [`Outline::faces`]), from its final shape: per slice of the material (by position along the
//! axis before the crush), how far each face's middle moved out (+) or in (−) along its normal.
//! The folds ([`super::folds`]) and the collapse mode ([`super::mode`]) of such a tube are read
//! from these. Units: mm.
//!
//! A face's displacement in a slice is the mean, over the particles beside the middle half of
//! the face ([`Outline::face`]), of how much further out their wall-line reach is now than
//! before the crush, each measured from the slice's centroid of the time: a slice that moved
//! sideways reads as it would in place, and the faces' lobes (which the corners do not follow) are what
//! remains.

use crate::solver::engine::Snapshot;
use crate::solver::model::case::{CrossSection, Outline};
use crate::solver::Real;

/// One slice of the tube.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FaceSlice {
    /// Mean position along the axis before the crush, mm.
    pub axial: Real,
    /// Particles in the slice.
    pub count: usize,
    /// Each face's mean outward displacement, in face order; None where no particle lies
    /// beside its middle.
    pub w: Vec<Option<Real>>,
    /// Each face middle's mean position along the axis now (None as for `w`): where a fold
    /// turned the wall back on itself, it falls from one slice to the next.
    pub along: Vec<Option<Real>>,
    /// RMS of every particle's outward displacement in the slice.
    pub rms: Real,
}

/// The slices of `width` along the axis (component `ax` of a position; `la`, `lb` the
/// cross-section's axes), bottom to top, empty slices left out.
pub fn face_slices(
    snapshot: &Snapshot,
    section: &CrossSection,
    [ax, la, lb]: [usize; 3],
    width: Real,
) -> Vec<FaceSlice> {
    let pairs = || {
        snapshot
            .initial_mm
            .iter()
            .zip(&snapshot.position_mm)
            .filter(|(a, p)| a.iter().chain(p.iter()).all(|v| v.is_finite()))
    };
    let lo = pairs().map(|(a, _)| a[ax]).fold(Real::MAX, Real::min);
    let hi = pairs().map(|(a, _)| a[ax]).fold(Real::MIN, Real::max);
    if !(lo <= hi && width > 0.0) {
        return Vec::new();
    }
    let slices = ((hi - lo) / width).floor() as usize + 1;
    let slice = |a: &[Real; 3]| (((a[ax] - lo) / width) as usize).min(slices - 1);
    // (count, Σ axial, Σ lateral a and b now, Σ lateral a and b before the crush).
    let mut centroid = vec![(0usize, 0.0, [0.0; 4]); slices];
    for (a, p) in pairs() {
        let c = &mut centroid[slice(a)];
        c.0 += 1;
        c.1 += a[ax];
        for (sum, v) in c.2.iter_mut().zip([p[la], p[lb], a[la], a[lb]]) {
            *sum += v;
        }
    }
    // Per face (count, Σ w, Σ position along the axis now), and Σ w² over the slice.
    let mut faces = vec![(vec![(0usize, 0.0, 0.0); section.faces()], 0.0); slices];
    for (a, p) in pairs() {
        let k = slice(a);
        let (m, _, sums) = centroid[k];
        let [x, y, x0, y0] = sums.map(|v| v / m as Real);
        let w = section.reach(p[la] - x, p[lb] - y) - section.reach(a[la] - x0, a[lb] - y0);
        let (sums, squares) = &mut faces[k];
        *squares += w * w;
        if let Some(f) = section.face(a[la], a[lb]) {
            sums[f] = (sums[f].0 + 1, sums[f].1 + w, sums[f].2 + p[ax]);
        }
    }
    centroid
        .into_iter()
        .zip(faces)
        .filter(|((m, ..), _)| *m > 0)
        .map(|((m, axial, ..), (sums, squares))| FaceSlice {
            axial: axial / m as Real,
            count: m,
            w: sums
                .iter()
                .map(|&(n, s, _)| (n > 0).then(|| s / n as Real))
                .collect(),
            along: sums
                .iter()
                .map(|&(n, _, a)| (n > 0).then(|| a / n as Real))
                .collect(),
            rms: (squares / m as Real).sqrt(),
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::solver::{Case, Limits};

    /// A square tube (50 × 50, t 1.5, r 1.5, l 60, n 2) of the solver's own lattice, along z.
    pub(crate) fn square_case() -> Case {
        Case::from_json(
            r#"{"tube": {"section": "rectangular", "side_a_mm": 50, "thickness_mm": 1.5,
                         "corner_radius_mm": 1.5, "length_mm": 60},
                "loading": {"crush_distance_mm": 30},
                "discretization": {"particles_through_thickness": 2}}"#,
            &Limits::default(),
        )
        .unwrap()
    }

    /// The case's particles, each face's middle moved out along its normal by w(z, face)
    /// (in where negative) and the rest in proportion as it nears a corner, then all moved by
    /// `shift(z)`.
    pub(crate) fn deformed(
        case: &Case,
        w: impl Fn(Real, usize) -> Real,
        shift: impl Fn(Real) -> [Real; 2],
    ) -> Snapshot {
        let initial = case.geometry().positions();
        let CrossSection::Rectangular(r) = case.geometry().section else {
            panic!("a square case")
        };
        let half = 0.5 * r.side_a_mm;
        let position = initial
            .iter()
            .map(|p| {
                let (x, y, z) = (p[0], p[1], p[2]);
                // The face a point is on by its larger coordinate; its share of the face's
                // displacement falls from 1 at the middle to 0 at the corner.
                let (face, along) = if x.abs() >= y.abs() {
                    (if x >= 0.0 { 0 } else { 2 }, y)
                } else {
                    (if y >= 0.0 { 1 } else { 3 }, x)
                };
                let share = (1.0 - along.abs() / half).clamp(0.0, 1.0);
                let d = w(z, face) * share;
                let normal = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]][face];
                let s = shift(z);
                [x + d * normal[0] + s[0], y + d * normal[1] + s[1], z]
            })
            .collect();
        Snapshot {
            initial_mm: initial.clone(),
            position_mm: position,
            plastic_strain: vec![0.0; initial.len()],
        }
    }

    #[test]
    fn each_face_reads_its_own_displacement_wherever_the_slice_went() {
        let case = square_case();
        // ±y out by 2, ±x in by 1 at their middles, and the whole tube moved sideways.
        let snap = deformed(
            &case,
            |_, face| if face % 2 == 1 { 2.0 } else { -1.0 },
            |z| [0.1 * z, -3.0],
        );
        let slices = face_slices(&snap, &case.geometry().section, [2, 0, 1], 1.5);
        assert_eq!(slices.len(), 40);
        // The middle half of a face moves by 1 to 0.53 of its displacement, 0.765 of it on
        // average.
        for s in &slices {
            let w: Vec<Real> = s.w.iter().map(|w| w.unwrap()).collect();
            for (f, want) in [(0, -0.765), (1, 1.53), (2, -0.765), (3, 1.53)] {
                assert!((w[f] - want).abs() < 0.02, "face {f}: {s:?}");
            }
        }
        // A tube that only moved reads no displacement at all.
        let moved = deformed(&case, |_, _| 0.0, |_| [2.0, -3.0]);
        for s in face_slices(&moved, &case.geometry().section, [2, 0, 1], 1.5) {
            assert!(s.rms < 1e-9 && s.w.iter().all(|w| w.unwrap().abs() < 1e-9));
        }
    }
}
