//! Folds counted from the deformed shape, as a person looking at the sections counts them: the
//! outward lobes of the wall along the crushed tube. Units: mm.
//!
//! Method (axial loading; a lateral crush flattens, it does not fold): the final particle
//! positions are binned by their *current* axial coordinate into slices one particle spacing
//! thick. Per slice, the wall's outermost reach is the largest distance of a particle from the
//! slice's centroid (so a tube that drifted sideways is measured about its own centre line),
//! less the undeformed outer radius (d + t)/2. Along the axis this profile rises at each fold's
//! outer hinge and falls between folds; a ring fold and a layer of diamond lobes both reach
//! out, at every angle or at the lobes' corners. A fold is a bump that reaches at least
//! [`FOLD_REACH_T`] wall thicknesses out, with a rise of at least [`FOLD_PROMINENCE_T`] before
//! it and a fall of as much after (hysteresis, as in the load-drop counter); the plates count
//! as the undeformed surface, so a fold flattened against a plate counts too. A three-slice running median first removes single-particle outliers.
//!
//! The load curve's drops are counted apart (`summary::count_load_drops`): in the diamond runs
//! each lobe's peak shows there, about twice the folds visible in the sections.

use super::case::LoadingMode;
use super::{Case, Real, Snapshot};

/// The rise and fall of the outer profile that makes a fold, in wall thicknesses. Measured:
/// the notches between the three stacked folds of the axial example (t 3.2, n = 6, 50 mm) are
/// 2.5–4.5 mm deep, 0.78 t and more. Half a wall thickness keeps room below that.
pub const FOLD_PROMINENCE_T: Real = 0.5;

/// How far beyond the undeformed outer surface a fold's outer hinge must reach, in wall
/// thicknesses. A fold's hinge goes out by about half the fold length: 5.5–7.5 mm (1.7–2.3 t)
/// in the axial example; the smooth barrelling bulges of the n = 2 crush over 20 mm reach
/// 1.6–1.8 mm (0.5–0.56 t) beside its one fold of 7 mm. One wall thickness lies between.
pub const FOLD_REACH_T: Real = 1.0;

/// The number of folds of an axial crush from its final shape; 0 for lateral loading.
pub fn count_folds(case: &Case, snapshot: &Snapshot) -> u32 {
    let spec = case.spec();
    if spec.loading.mode == LoadingMode::Lateral {
        return 0;
    }
    let (t, d) = (spec.tube.thickness_mm, spec.tube.mean_diameter_mm);
    let profile = outer_profile(&snapshot.position_mm, case.spacing_mm(), 0.5 * (d + t));
    count_bumps(&median3(&profile), FOLD_PROMINENCE_T * t, FOLD_REACH_T * t)
}

/// Per slice of width `h` along z (bottom to top, empty slices left out): the largest distance
/// of a particle from the slice's centroid in x–y, less `outer`.
fn outer_profile(position: &[[Real; 3]], h: Real, outer: Real) -> Vec<Real> {
    let finite = || position.iter().filter(|p| p.iter().all(|v| v.is_finite()));
    let (lo, hi) = finite().fold((Real::MAX, Real::MIN), |(lo, hi), p| {
        (lo.min(p[2]), hi.max(p[2]))
    });
    if !(lo <= hi && h > 0.0) {
        return Vec::new();
    }
    let count = ((hi - lo) / h) as usize + 1;
    let slice = |p: &[Real; 3]| (((p[2] - lo) / h) as usize).min(count - 1);
    let mut sums = vec![(0usize, 0.0, 0.0); count];
    for p in finite() {
        let s = &mut sums[slice(p)];
        *s = (s.0 + 1, s.1 + p[0], s.2 + p[1]);
    }
    let mut reach = vec![Real::MIN; count];
    for p in finite() {
        let k = slice(p);
        let (n, x, y) = sums[k];
        let r = (p[0] - x / n as Real).hypot(p[1] - y / n as Real);
        reach[k] = reach[k].max(r);
    }
    reach
        .into_iter()
        .zip(&sums)
        .filter(|(_, s)| s.0 > 0)
        .map(|(r, _)| r - outer)
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
    let (mut rising, mut trough, mut peak, mut bumps) = (true, 0.0, Real::MIN, 0);
    for &v in profile.iter().chain(std::iter::once(&0.0)) {
        if rising {
            if v > peak {
                peak = v;
            } else if peak - v >= margin && peak - trough >= margin && peak >= reach {
                bumps += 1;
                (rising, trough) = (false, v);
            }
            if v < trough {
                (trough, peak) = (v, v);
            }
        } else if v < trough {
            trough = v;
        } else if v - trough >= margin {
            (rising, peak) = (true, v);
        }
    }
    bumps
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

    /// Diamond layers: two lobes per layer, each layer turned by 90° from the last. At a fixed
    /// angle only every other layer reaches out; the outermost reach shows every layer.
    #[test]
    fn diamond_layers_are_counted_once_each() {
        let snap = wall(48.0, |z, th| {
            let layer = (z / 12.0) as usize;
            let turn = if layer.is_multiple_of(2) {
                0.0
            } else {
                PI / 2.0
            };
            4.0 * (2.0 * (th - turn)).cos() * (PI * (z % 12.0) / 12.0).sin()
        });
        assert_eq!(count_folds(&case(), &snap), 4);
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

    #[test]
    fn lateral_crush_and_empty_snapshot_have_no_folds() {
        let lateral =
            Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
        assert_eq!(count_folds(&lateral, &wall(36.0, |z, _| lobes(z, 4.0))), 0);
        assert_eq!(count_folds(&case(), &Snapshot::default()), 0);
    }
}
