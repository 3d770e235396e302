//! Folds counted from the deformed shape, as a person looking at the sections counts them: the
//! outward lobes along a wall line from one plate to the other. Units: mm.
//!
//! Method (axial loading; a lateral crush flattens, it does not fold): the wall is cut into
//! lines in *material* coordinates — slices one particle spacing thick by their position
//! before the crush, and [`SECTORS`] sectors around the axis by their angle before the crush.
//! Along each line, the wall's outermost reach per slice is the largest distance of a particle
//! of that slice and sector from the slice's current centroid (so a tube that drifted sideways
//! is measured about its own centre line), less the undeformed outer radius (d + t)/2. The
//! profile rises at each fold's outer hinge and falls at its inner hinge. A fold is a bump that
//! reaches at least [`FOLD_REACH_T`] wall thicknesses out, with a rise of at least
//! [`FOLD_PROMINENCE_T`] before it and a fall of as much after (hysteresis, as in the
//! load-drop counter); the plates count as the undeformed surface, so a fold flattened against
//! a plate counts too. A three-slice running median first removes single-particle outliers.
//! A section through the axis holds two opposite lines, and shows the folds of the one with
//! more (a tube that leans folds on one side only); the tube's count is the lower median over
//! its [`SECTORS`]/2 sections: what most sections show.
//!
//! Why material coordinates: once folds are pressed together, the lobes of neighbouring folds
//! lie at the same height, and a profile over the *current* height no longer falls between
//! them (the diamond runs at t 1.27 mm read 1 and 2 folds where their sections show about 3
//! and 4). Along the material the folds stay apart however tightly they are packed. Why lines
//! and not the whole ring: a slice's reach over all angles stays out wherever any lobe of an
//! inclined diamond hinge is, and the same runs then read 5 and 6.
//!
//! A polygonal tube (one with [`Outline::faces`]: a rectangle's four, a hexagon's six) folds
//! face by face: in a layer of lobes a square's two opposite faces go out and the other two in
//! (or all four out), and the next layer turns them over, so a face line shows every layer as a
//! lobe, out or in. Its folds are counted along the middle of each face ([`super::faces`]): the
//! bumps of the face's outward or inward displacement, with the same rise, fall and reach as a
//! round tube's, in which the wall runs back along the axis (a fold turns it back on itself; a
//! face that only waves, as the unfolded part of a square tube does by a wall thickness or two,
//! never does); the tube's count is the lower median over its faces.
//!
//! The load curve's drops are counted apart (`curve::count_load_drops`): in the diamond runs
//! each lobe's peak shows there, about twice the folds visible in the sections.

use super::faces::face_slices;
use super::peaks::Peaks;
use crate::solver::engine::Snapshot;
use crate::solver::model::case::{Case, CrossSection, LoadingMode, Model, Outline};
use crate::solver::Real;

/// The rise and fall of the outer profile that makes a fold, in wall thicknesses. Measured:
/// the notches between the three stacked folds of the axial example (t 3.2, n = 6, 50 mm) are
/// 2.5–4.5 mm deep, 0.78 t and more. Half a wall thickness keeps room below that.
pub const FOLD_PROMINENCE_T: Real = 0.5;

/// How far beyond the undeformed outer surface a fold's outer hinge must reach, in wall
/// thicknesses. A fold's hinge goes out by about half the fold length: 5.5–7.5 mm (1.7–2.3 t)
/// in the axial example; the smooth barrelling bulges of the n = 2 crush over 20 mm reach
/// 1.6–1.8 mm (0.5–0.56 t) beside its one fold of 7 mm. One wall thickness lies between.
pub const FOLD_REACH_T: Real = 1.0;

/// How many wall lines around the axis are counted (an even number: opposite lines make a
/// section): sectors of 22.5°, as narrow as a section and wide enough to hold particles at
/// n = 2 (44 around the axial example's ring).
pub const SECTORS: usize = 16;

/// The number of folds of an axial crush from its final shape; 0 for lateral loading.
pub fn count_folds(case: &Case, snapshot: &Snapshot) -> u32 {
    let geometry = case.geometry();
    if geometry.mode == LoadingMode::Lateral {
        return 0;
    }
    let section = geometry.section;
    let t = section.thickness_mm();
    if geometry.model == Model::Axisymmetric {
        // The section is one wall line: its reach is the radius itself.
        let line = section_line(snapshot, case.spacing_mm(), section.outer_mm());
        return count_bumps(&median3(&line), FOLD_PROMINENCE_T * t, FOLD_REACH_T * t);
    }
    if section.faces() > 0 {
        return face_folds(snapshot, case.spacing_mm(), &section);
    }
    let lines = wall_lines(snapshot, case.spacing_mm(), &section);
    let count = |line: &Vec<Real>| match line.is_empty() {
        true => None,
        false => Some(count_bumps(
            &median3(line),
            FOLD_PROMINENCE_T * t,
            FOLD_REACH_T * t,
        )),
    };
    let (left, right) = lines.split_at(lines.len() / 2);
    let mut sections: Vec<u32> = left
        .iter()
        .zip(right)
        .filter_map(|(a, b)| count(a).max(count(b)))
        .collect();
    sections.sort_unstable();
    sections
        .get(sections.len().saturating_sub(1) / 2)
        .copied()
        .unwrap_or(0)
}

/// The folds of a polygonal tube along the middles of its faces, slices `h` thick: the lower
/// median over the faces of each face's folded bumps ([`face_line_folds`]).
fn face_folds(snapshot: &Snapshot, h: Real, section: &CrossSection) -> u32 {
    let t = section.thickness_mm();
    let slices = face_slices(snapshot, section, [2, 0, 1], h);
    let mut faces: Vec<u32> = (0..section.faces())
        .map(|f| {
            let line: Vec<(Real, Real)> = slices
                .iter()
                .filter_map(|s| s.w[f].zip(s.along[f]))
                .collect();
            face_line_folds(&line, t)
        })
        .collect();
    faces.sort_unstable();
    faces[(faces.len() - 1) / 2]
}

/// The folds along one face's middle, from its (displacement, position along the axis now)
/// per material slice, bottom to top: the bumps of |displacement| (rise, fall and reach as a
/// round tube's) in which the wall runs back along the axis somewhere between the troughs on
/// either side, as a fold turns it back on itself. A face of a square tube waves before it
/// folds: the unfolded lower part of the steel tubes of docs/materials.md waves by 2 t (out
/// and in) with its wall never past 45° from the axis, and read as two folds more than the
/// crush holds.
fn face_line_folds(line: &[(Real, Real)], t: Real) -> u32 {
    let reach: Vec<Real> = line.iter().map(|(w, _)| w.abs()).collect();
    let profile = median3(&reach);
    let last = line.len().saturating_sub(1);
    // The wall at slice k runs back when the face middle stands lower in the slice above than
    // in the slice below.
    let back: Vec<bool> = (0..line.len())
        .map(|k| line[(k + 1).min(last)].1 < line[k.saturating_sub(1)].1)
        .collect();
    let mut peaks = Peaks::from_trough(0.0);
    let troughs: Vec<usize> = profile
        .iter()
        .chain(std::iter::once(&0.0))
        .filter_map(|&v| peaks.push(v, FOLD_PROMINENCE_T * t, FOLD_REACH_T * t))
        .collect();
    // Each bump runs from its trough to the next one's (the last to the tube's end).
    let ends = troughs
        .iter()
        .skip(1)
        .copied()
        .chain(std::iter::once(line.len()));
    troughs
        .iter()
        .zip(ends)
        .filter(|&(&from, to)| back[(from + 1).min(to)..to].iter().any(|&b| b))
        .count() as u32
}

/// Per sector of the material angle, per material slice of width `h` along z (bottom to top,
/// empty slices left out): the largest reach of the slice's particles in that sector from the
/// slice's current centroid, beyond the section's undeformed outer surface (its wall-line
/// metric).
fn wall_lines(snapshot: &Snapshot, h: Real, section: &CrossSection) -> Vec<Vec<Real>> {
    let outer = section.outer_mm();
    let pairs = || {
        snapshot
            .initial_mm
            .iter()
            .zip(&snapshot.position_mm)
            .filter(|(a, b)| a.iter().chain(b.iter()).all(|v| v.is_finite()))
    };
    let (mut lo, mut hi, mut ax, mut ay, mut n) = (Real::MAX, Real::MIN, 0.0, 0.0, 0usize);
    for (a, _) in pairs() {
        (lo, hi, ax, ay, n) = (lo.min(a[2]), hi.max(a[2]), ax + a[0], ay + a[1], n + 1);
    }
    if !(lo <= hi && h > 0.0) {
        return Vec::new();
    }
    let (ax, ay) = (ax / n as Real, ay / n as Real);
    let slices = ((hi - lo) / h).round() as usize + 1;
    let slice = |a: &[Real; 3]| (((a[2] - lo) / h).round() as usize).min(slices - 1);
    let sector = |a: &[Real; 3]| {
        let turn = section.angle(a[0] - ax, a[1] - ay) / std::f64::consts::TAU + 0.5;
        ((turn * SECTORS as Real) as usize).min(SECTORS - 1)
    };
    let mut centroid = vec![(0usize, 0.0, 0.0); slices];
    for (a, p) in pairs() {
        let c = &mut centroid[slice(a)];
        *c = (c.0 + 1, c.1 + p[0], c.2 + p[1]);
    }
    let mut reach = vec![vec![Real::MIN; slices]; SECTORS];
    for (a, p) in pairs() {
        let k = slice(a);
        let (m, x, y) = centroid[k];
        let r = section.reach(p[0] - x / m as Real, p[1] - y / m as Real);
        let cell = &mut reach[sector(a)][k];
        *cell = cell.max(r);
    }
    reach
        .into_iter()
        .map(|line| {
            line.into_iter()
                .filter(|&r| r > Real::MIN)
                .map(|r| r - outer)
                .collect()
        })
        .collect()
}

/// An axisymmetric section's outer profile: per material slice of width `h` along z (bottom to
/// top, empty slices left out), the largest radius of its particles less `outer`.
fn section_line(snapshot: &Snapshot, h: Real, outer: Real) -> Vec<Real> {
    let mut reach: Vec<Real> = Vec::new();
    for (a, p) in snapshot.initial_mm.iter().zip(&snapshot.position_mm) {
        if !(a[2].is_finite() && p[0].is_finite()) {
            continue;
        }
        let k = (a[2] / h).floor().max(0.0) as usize;
        if reach.len() <= k {
            reach.resize(k + 1, Real::MIN);
        }
        reach[k] = reach[k].max(p[0]);
    }
    reach
        .into_iter()
        .filter(|&r| r > Real::MIN)
        .map(|r| r - outer)
        .collect()
}

/// Running median over three values (the ends kept).
fn median3(v: &[Real]) -> Vec<Real> {
    (0..v.len())
        .map(|i| {
            if i == 0 || i + 1 == v.len() {
                v[i]
            } else {
                let mut w = [v[i - 1], v[i], v[i + 1]];
                w.sort_by(Real::total_cmp);
                w[1]
            }
        })
        .collect()
}

/// Bumps of `profile` that reach `reach` and rise at least `margin` above the trough before
/// them and fall as much after; both ends stand on a trough at 0 (the plates hold the
/// undeformed surface).
fn count_bumps(profile: &[Real], margin: Real, reach: Real) -> u32 {
    let mut peaks = Peaks::from_trough(0.0);
    for &v in profile.iter().chain(std::iter::once(&0.0)) {
        peaks.push(v, margin, reach);
    }
    peaks.count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Limits;
    use std::f64::consts::PI;

    /// A tube wall (t 3.2, d 22.2) along z over `length`, each particle at radius r + w(z, θ).
    fn wall(length: Real, w: impl Fn(Real, Real) -> Real) -> Snapshot {
        let (t, d, h) = (3.2, 22.2, 0.8);
        let mut snap = Snapshot::default();
        for j in 0..4 {
            let r = d / 2.0 - t / 2.0 + (j as Real + 0.5) * h;
            let around = (2.0 * PI * r / h).round() as usize;
            for k in 0..(length / h).round() as usize {
                let z = (k as Real + 0.5) * h;
                for i in 0..around {
                    let th = 2.0 * PI * i as Real / around as Real;
                    let rr = r + w(z, th);
                    snap.initial_mm.push([r * th.cos(), r * th.sin(), z]);
                    snap.position_mm.push([rr * th.cos(), rr * th.sin(), z]);
                }
            }
        }
        snap
    }

    fn case() -> Case {
        Case::from_json("{}", &Limits::default()).unwrap()
    }

    /// Outward lobes only where sin > 0: `n` half-waves of 12 mm, each a fold.
    fn lobes(z: Real, amplitude: Real) -> Real {
        amplitude * (2.0 * PI * z / 12.0).sin().max(0.0)
    }

    #[test]
    fn three_ring_folds_are_three() {
        let snap = wall(36.0, |z, _| lobes(z, 4.0));
        assert_eq!(count_folds(&case(), &snap), 3);
        // Stacked folds whose outer hinges touch: notches of 2.5 mm (0.78 t) between them.
        let stacked = wall(36.0, |z, _| 5.0 - 2.5 * (2.0 * PI * z / 12.0).cos());
        assert_eq!(count_folds(&case(), &stacked), 3);
    }

    #[test]
    fn barrelling_waves_are_no_folds() {
        // 1.8 mm, 0.56 t: the bulges of the n = 2 crush over 20 mm.
        let snap = wall(36.0, |z, _| lobes(z, 1.8));
        assert_eq!(count_folds(&case(), &snap), 0);
        assert_eq!(count_folds(&case(), &wall(36.0, |_, _| 0.0)), 0);
    }

    /// Diamond layers: every layer folds out all round, furthest at its two lobe corners, each
    /// layer's corners turned by 90° from the last (12 mm of wall a layer).
    fn diamond(z: Real, th: Real) -> Real {
        let layer = (z / 12.0) as usize;
        let turn = if layer.is_multiple_of(2) {
            0.0
        } else {
            PI / 2.0
        };
        (5.0 + 1.5 * (2.0 * (th - turn)).cos()) * (PI * (z % 12.0) / 12.0).sin()
    }

    #[test]
    fn diamond_layers_are_counted_once_each() {
        assert_eq!(count_folds(&case(), &wall(48.0, diamond)), 4);
    }

    /// The same four layers pressed together: each layer's 12 mm of wall spans 6 mm of height
    /// and starts 3 mm above the last, so at every height two layers' lobes overlap and the
    /// outer reach over the current height no longer falls between them. Counted along the
    /// material, they stay four.
    #[test]
    fn packed_diamond_layers_still_count_once_each() {
        let snap = wall(48.0, diamond);
        let packed = Snapshot {
            position_mm: snap
                .position_mm
                .iter()
                .zip(&snap.initial_mm)
                .map(|(p, a)| {
                    [
                        p[0],
                        p[1],
                        3.0 * (a[2] / 12.0).floor() + 0.5 * (a[2] % 12.0),
                    ]
                })
                .collect(),
            ..snap
        };
        assert_eq!(count_folds(&case(), &packed), 4);
    }

    /// A fold pressed flat against a plate at the end of the tube counts: the plate stands for
    /// the undeformed surface.
    #[test]
    fn a_fold_at_a_plate_counts() {
        let snap = wall(30.0, |z, _| if z > 26.0 { 5.0 } else { 0.0 });
        assert_eq!(count_folds(&case(), &snap), 1);
    }

    #[test]
    fn a_tube_that_moved_sideways_is_measured_about_its_own_centre() {
        let snap = wall(36.0, |z, _| lobes(z, 4.0));
        let moved = Snapshot {
            position_mm: snap
                .position_mm
                .iter()
                .map(|p| [p[0] + 7.0, p[1] - 3.0, p[2]])
                .collect(),
            ..snap
        };
        assert_eq!(count_folds(&case(), &moved), 3);
    }

    /// Symmetric layers of a square tube, each `layer` mm of wall: two opposite faces out and
    /// the other two in, turned over from one layer to the next.
    fn symmetric(z: Real, face: usize, layer: Real, amplitude: Real) -> Real {
        let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
        sign * amplitude * (PI * z / layer).sin()
    }

    /// Where a fold puts the material at `z` (mm before the crush) along the axis: each
    /// `layer` of wall rises over its first three quarters and runs back over its last, so that
    /// it ends half a layer above where it began.
    fn run_back(z: Real, layer: Real) -> Real {
        let (k, u) = ((z / layer).floor(), z.rem_euclid(layer));
        let base = 0.5 * layer * k;
        match u < 0.75 * layer {
            true => base + u,
            false => base + 1.5 * layer - u,
        }
    }

    /// The snapshot with every particle's position along the axis set by `axial` of its
    /// position before the crush.
    fn along(snap: Snapshot, axial: impl Fn(Real) -> Real) -> Snapshot {
        let position_mm = snap
            .position_mm
            .iter()
            .zip(&snap.initial_mm)
            .map(|(p, a)| [p[0], p[1], axial(a[2])])
            .collect();
        Snapshot {
            position_mm,
            ..snap
        }
    }

    #[test]
    fn a_square_tubes_folds_are_its_layers_out_or_in() {
        use crate::solver::analysis::faces::tests::{deformed, square_case};
        let case = square_case();
        // Four folded layers of 15 mm over the 60 mm tube, lobes of 6 mm (4 t).
        let lobes = deformed(&case, |z, f| symmetric(z, f, 15.0, 6.0), |_| [0.0; 2]);
        let folded = along(lobes, |z| run_back(z, 15.0));
        assert_eq!(count_folds(&case, &folded), 4);
        // All faces out together (extensional) over 0–20 and 40–60 mm, folded, the wall
        // between unmoved, the tube leaning sideways.
        let out = deformed(
            &case,
            |z, _| 6.0 * (PI * z / 20.0).sin().max(0.0),
            |z| [0.2 * z, 0.0],
        );
        assert_eq!(count_folds(&case, &along(out, |z| run_back(z, 20.0))), 2);
        // Lobes of 1 mm (0.67 t) are ripples, not folds, even folded.
        let ripples = deformed(&case, |z, f| symmetric(z, f, 15.0, 1.0), |_| [0.0; 2]);
        assert_eq!(
            count_folds(&case, &along(ripples, |z| run_back(z, 15.0))),
            0
        );
    }

    /// What broke: the square steel tubes of docs/materials.md read 4 folds where the crush
    /// holds 2, their unfolded lower faces waving out and in by 2 t without turning back.
    #[test]
    fn a_square_faces_waves_that_never_turn_back_are_no_folds() {
        use crate::solver::analysis::faces::tests::{deformed, square_case};
        let case = square_case();
        // Lobes of 3 mm (2 t) in four layers of 15 mm, the wall never past 45° from the axis.
        let waves = deformed(&case, |z, f| symmetric(z, f, 15.0, 3.0), |_| [0.0; 2]);
        assert_eq!(count_folds(&case, &waves), 0);
        // The top two layers folded back on themselves, the bottom two only waving.
        let top_folded = along(waves, |z| match z < 30.0 {
            true => z,
            false => 30.0 + run_back(z - 30.0, 15.0),
        });
        assert_eq!(count_folds(&case, &top_folded), 2);
    }

    #[test]
    fn lateral_crush_and_empty_snapshot_have_no_folds() {
        let lateral =
            Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
        assert_eq!(count_folds(&lateral, &wall(36.0, |z, _| lobes(z, 4.0))), 0);
        assert_eq!(count_folds(&case(), &Snapshot::default()), 0);
    }
}
