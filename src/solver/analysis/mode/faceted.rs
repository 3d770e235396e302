//! The collapse mode of a polygonal tube crushed axially (a rectangle's four faces, a
//! hexagon's six), from how its faces fold ([`crate::solver::analysis::faces`]). Units: mm.
//!
//! Abramowicz & Jones (1984) name the progressive modes of square tubes by their layers of
//! lobes: in the **symmetric** mode (Wierzbicki & Abramowicz's) every layer folds two opposite
//! faces out and the other two in; in the **asymmetric mixed** modes some layers fold three
//! faces out and one in (or the like) among symmetric ones, and the column leans; in the
//! **extensional** mode, of thick walls, every face folds out together. A polygon of an even
//! number of faces reads the same way: a symmetric layer folds neighbouring faces opposite ways
//! and faces two apart alike (a hexagon's alternate faces out, the others in). Each folded
//! slice is read by the signs of its faces' displacements: a face that moved less than
//! [`FLAT_SHARE`] of the slice's largest counts as flat; every face out (or in) together is
//! extensional, neighbours unlike and faces two apart alike symmetric, anything else
//! asymmetric. The tube is extensional when at least [`EXTENSIONAL_SHARE`] of its folded
//! slices are, asymmetric mixed when at least [`ASYMMETRIC_SHARE`] are asymmetric, and
//! symmetric otherwise. Global bending is the round tube's global buckling, judged by the
//! same drift of the slices' centroids before this.

use super::kinds::{CollapseMode, FaceLayers};
use crate::solver::analysis::faces::FaceSlice;
use crate::solver::Real;

/// A slice is folded when its RMS displacement reaches this share of the largest slice's
/// (and the least a fold moves the wall, `super::FOLDED_MIN_T` · t).
pub const FOLDED_FRACTION: Real = 0.25;

/// A face whose displacement is below this share of the slice's largest counts as flat.
pub const FLAT_SHARE: Real = 0.25;

/// The share of folded slices with every face out (or in) together that makes the mode
/// extensional.
pub const EXTENSIONAL_SHARE: Real = 0.5;

/// The share of folded slices with an asymmetric pattern that makes the mode asymmetric mixed:
/// one layer in four.
pub const ASYMMETRIC_SHARE: Real = 0.25;

/// What a folded slice's faces show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layer {
    Symmetric,
    Asymmetric,
    Extensional,
}

/// The pattern of one slice's faces (in face order around the tube; at least two).
fn layer(w: &[Real]) -> Layer {
    let largest = w.iter().fold(0.0, |m: Real, v| m.max(v.abs()));
    let sign: Vec<i8> = w
        .iter()
        .map(|&v| match v {
            v if v >= FLAT_SHARE * largest => 1,
            v if v <= -FLAT_SHARE * largest => -1,
            _ => 0,
        })
        .collect();
    let k = sign.len();
    if sign.iter().all(|&s| s == sign[0] && s != 0) {
        Layer::Extensional
    } else if (0..k).all(|i| sign[i] == sign[(i + 2) % k]) && sign[0] != sign[1] {
        Layer::Symmetric
    } else {
        Layer::Asymmetric
    }
}

/// The mode of an axially crushed polygonal tube that did not bend over as a whole, from its
/// face slices, of which those whose RMS displacement is below `folded_min_mm` are not folded;
/// the counts behind it; and why.
pub(super) fn decide(
    slices: &[FaceSlice],
    folded_min_mm: Real,
) -> (CollapseMode, FaceLayers, String) {
    let whole: Vec<(&FaceSlice, Vec<Real>)> = slices
        .iter()
        .filter_map(|s| Some((s, s.w.iter().copied().collect::<Option<Vec<Real>>>()?)))
        .filter(|(_, w)| w.len() >= 2)
        .collect();
    let max_rms = whole.iter().map(|(s, _)| s.rms).fold(0.0, Real::max);
    let mut counts = FaceLayers::default();
    for (_, w) in whole
        .iter()
        .filter(|(s, _)| s.rms >= (FOLDED_FRACTION * max_rms).max(folded_min_mm))
    {
        match layer(w) {
            Layer::Symmetric => counts.symmetric += 1,
            Layer::Asymmetric => counts.asymmetric += 1,
            Layer::Extensional => counts.extensional += 1,
        }
    }
    let folded = counts.total();
    let tally = format!(
        "of {folded} folded slices, {} symmetric, {} asymmetric, {} extensional",
        counts.symmetric, counts.asymmetric, counts.extensional
    );
    let share = |n: u32| n as Real / folded.max(1) as Real;
    let (mode, why) = if folded == 0 {
        (
            CollapseMode::Symmetric,
            "no slice folded; reported as symmetric".to_string(),
        )
    } else if share(counts.extensional) >= EXTENSIONAL_SHARE {
        (
            CollapseMode::Extensional,
            format!("{tally}: extensional (at least {EXTENSIONAL_SHARE} of them)"),
        )
    } else if share(counts.asymmetric) >= ASYMMETRIC_SHARE {
        (
            CollapseMode::AsymmetricMixed,
            format!("{tally}: asymmetric mixed (at least {ASYMMETRIC_SHARE} asymmetric)"),
        )
    } else {
        (CollapseMode::Symmetric, format!("{tally}: symmetric"))
    };
    (mode, counts, why)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::analysis::faces::tests::{deformed, square_case};
    use crate::solver::analysis::mode::detect_mode;
    use std::f64::consts::PI;

    #[test]
    fn a_slices_faces_give_its_pattern() {
        assert_eq!(layer(&[3.0, -2.0, 2.5, -3.0]), Layer::Symmetric);
        // A neighbour pair barely moving still reads symmetric.
        assert_eq!(layer(&[3.0, 0.2, 2.5, -0.1]), Layer::Symmetric);
        assert_eq!(layer(&[3.0, 2.0, 2.5, 1.0]), Layer::Extensional);
        assert_eq!(layer(&[-3.0, -2.0, -2.5, -1.0]), Layer::Extensional);
        assert_eq!(layer(&[3.0, 2.0, 2.5, -3.0]), Layer::Asymmetric);
        assert_eq!(layer(&[3.0, 0.0, -2.5, 0.0]), Layer::Asymmetric);
        // Six faces: alternate faces out and in is symmetric; two neighbours alike is not.
        assert_eq!(layer(&[2.0, -2.0, 2.5, -1.5, 2.0, -2.0]), Layer::Symmetric);
        assert_eq!(layer(&[2.0, 2.0, -2.5, 1.5, -2.0, -2.0]), Layer::Asymmetric);
        assert_eq!(layer(&[2.0; 6]), Layer::Extensional);
    }

    /// Layers of lobes 15 mm of wall each over the 60 mm tube, 6 mm deep; `pattern(layer)`
    /// gives each face's sign in that layer.
    fn layers(pattern: impl Fn(usize) -> [Real; 4]) -> impl Fn(Real, usize) -> Real {
        move |z, face| {
            let k = ((z / 15.0) as usize).min(3);
            6.0 * pattern(k)[face] * (PI * (z % 15.0) / 15.0).sin()
        }
    }

    /// Symmetric layers and, between them, three faces out and one in.
    fn mixed(k: usize) -> [Real; 4] {
        match k % 2 {
            0 => [1.0, -1.0, 1.0, -1.0],
            _ => [1.0, 1.0, 1.0, -1.0],
        }
    }

    #[test]
    fn symmetric_layers_are_the_symmetric_mode() {
        let case = square_case();
        let alternate = |k: usize| {
            let s = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
            [s, -s, s, -s]
        };
        let snap = deformed(&case, layers(alternate), |_| [0.0; 2]);
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Symmetric, "{detail:?}");
        let faces = detail.faces.unwrap();
        assert!(faces.symmetric > 0 && faces.asymmetric == 0, "{detail:?}");
        assert_eq!(mode.kind(), "symmetric");
    }

    #[test]
    fn every_face_out_is_the_extensional_mode() {
        let case = square_case();
        let snap = deformed(&case, layers(|_| [1.0; 4]), |_| [0.0; 2]);
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Extensional, "{detail:?}");
    }

    #[test]
    fn layers_of_three_out_and_one_in_make_the_mode_asymmetric_mixed() {
        let case = square_case();
        let snap = deformed(&case, layers(mixed), |_| [0.0; 2]);
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::AsymmetricMixed, "{detail:?}");
        assert_eq!(mode.kind(), "asymmetric_mixed");
    }

    /// What broke: a square tube's summary gave one count of folded slices (the round tubes'
    /// rule, wall turned back) and its reason another (the faces'), 57 against 75 on the same run.
    #[test]
    fn a_square_tube_s_folded_slices_are_those_its_faces_were_read_on() {
        let case = square_case();
        let snap = deformed(&case, layers(mixed), |_| [0.0; 2]);
        let (_, detail) = detect_mode(&case, &snap);
        let faces = detail.faces.unwrap();
        assert!(faces.total() > 0, "{detail:?}");
        assert_eq!(detail.folded_slices, faces.total(), "{detail:?}");
        assert!(
            detail
                .reason
                .contains(&format!("of {} folded slices", detail.folded_slices)),
            "{detail:?}"
        );
    }

    #[test]
    fn a_square_column_bent_over_is_global_buckling() {
        let case = square_case();
        // Bowed by 30 mm at mid-length (> 0.5 · 50 mm), the faces unfolded.
        let snap = deformed(&case, |_, _| 0.0, |z| [30.0 * (PI * z / 60.0).sin(), 0.0]);
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::GlobalBuckling, "{detail:?}");
    }

    #[test]
    fn an_undeformed_square_tube_reads_symmetric_and_says_so() {
        let case = square_case();
        let snap = deformed(&case, |_, _| 0.0, |_| [0.0; 2]);
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Symmetric);
        assert!(detail.reason.contains("no slice folded"), "{detail:?}");
    }
}
