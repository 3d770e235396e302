//! Collapse-mode detection from the final shape of the tube. Units: mm.
//!
//! Assumptions about the scene (the scene builder follows them):
//! - **axial loading**: the tube axis is z, the bottom plate is at z = 0, the tube is centred on
//!   x = y = 0;
//! - **lateral loading**: the tube axis is x, the plates are normal to z, the tube is centred on
//!   y = z = 0.
//!
//! `Snapshot::initial_mm` and `Snapshot::position_mm` hold the same particles in the same order.
//!
//! Method: particles are binned by their *initial* axial coordinate into slices. Per slice we take
//! the centroid of the current positions (its lateral drift shows bowing of the centre line) and
//! the circumferential Fourier amplitudes, harmonics 0..=8, of the radial displacement
//! w = (current radius from the original axis) − (initial radius), as a function of the initial
//! angle. Harmonic m of w is an m-lobe shape; harmonic 1 is a sideways shift of the section and is
//! left to the drift test.
//!
//! Decision (axial loading), in this order:
//! 1. **global buckling** when the largest drift of a slice centroid — from the straight line
//!    through the end slices' centroids, or from the original axis, whichever is larger —
//!    exceeds [`DRIFT_FRACTION`] · d, whatever the folds did (a tube that tipped over and was
//!    flattened shows radial displacements larger than its drift; one that tipped over and lies
//!    across the plates moves both ends, so only the distance from the axis shows it: the
//!    t = 1.27, d = 10 example at n = 4 had 4.9 mm from the end line but 30 mm from the axis);
//! 2. **ring** when the mean harmonic-0 amplitude over the folded slices is at least the largest
//!    mean amplitude among harmonics 2..8;
//! 3. otherwise **diamond**, with lobes = the harmonic in 2..8 of largest mean amplitude.
//!
//! Folded slices are those whose RMS radial displacement is at least [`FOLDED_FRACTION`] of the
//! largest slice RMS and at least [`FOLDED_MIN_T`] · t; if none is, every slice is used (a tube
//! that did not fold reads as ring, and the detail says so). Lateral loading is always
//! [`CollapseMode::Flattening`]; its detail is computed the same way about the x axis.

use crate::solver::engine::Snapshot;
use crate::solver::model::case::{Case, CrossSection, LoadingMode, Model};
use crate::solver::Real;
use serde::{Deserialize, Serialize};

/// How the tube collapsed, judged from its final shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CollapseMode {
    /// Axisymmetric concertina folds.
    Ring,
    /// Non-axisymmetric folds with this many lobes around the circumference.
    Diamond { lobes: u32 },
    /// The whole column bowed sideways (Euler buckling).
    GlobalBuckling,
    /// Lateral loading: the tube was flattened across a diameter.
    Flattening,
}

impl CollapseMode {
    /// The mode's name as its JSON `kind` spells it (`ring`, `diamond`, …): the stored
    /// `mode` column and the sweep table's `mode`.
    pub fn kind(&self) -> &'static str {
        match self {
            CollapseMode::Ring => "ring",
            CollapseMode::Diamond { .. } => "diamond",
            CollapseMode::GlobalBuckling => "global_buckling",
            CollapseMode::Flattening => "flattening",
        }
    }
}

/// Highest circumferential harmonic analysed.
pub const MAX_HARMONIC: usize = 8;
/// Centre-line drift, as a fraction of the mean diameter, beyond which the column counts as bowed.
pub const DRIFT_FRACTION: Real = 0.5;
/// A slice is folded when its RMS radial displacement reaches this share of the largest slice's.
pub const FOLDED_FRACTION: Real = 0.25;
/// ... and at least this many wall thicknesses.
pub const FOLDED_MIN_T: Real = 0.25;
/// Fewest particles a slice needs to resolve harmonic 8 (Nyquist: 2·8 + 1).
const MIN_PER_SLICE: usize = 2 * MAX_HARMONIC + 1;
/// Most slices along the tube.
const MAX_SLICES: usize = 400;

/// Why the mode came out as it did.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct ModeDetail {
    /// Slices holding enough particles to analyse.
    pub slices: u32,
    /// Slices counted as folded (used for the ring/diamond decision).
    pub folded_slices: u32,
    /// Width of a slice in the initial axial coordinate, mm.
    pub slice_width_mm: Real,
    /// Amplitude of harmonics 0..=8 of the radial displacement, mean over the folded slices, mm.
    pub harmonic_amplitude_mm: Vec<Real>,
    /// Largest lateral drift of a slice centroid, from the end slices' line or from the original
    /// axis, whichever is larger, mm.
    pub max_drift_mm: Real,
    /// Drift beyond which the column counts as bowed (DRIFT_FRACTION · d), mm.
    pub drift_threshold_mm: Real,
    /// One sentence: which test decided.
    pub reason: String,
}

/// Per-slice accumulators.
#[derive(Clone, Copy, Default)]
struct Slice {
    count: usize,
    axial_sum: Real,
    centroid_sum: [Real; 2],
    w_sq_sum: Real,
    /// Σ w cos(mθ), Σ w sin(mθ) for m = 0..=8.
    cos_sum: [Real; MAX_HARMONIC + 1],
    sin_sum: [Real; MAX_HARMONIC + 1],
}

impl Slice {
    fn amplitude(&self, m: usize) -> Real {
        let n = self.count as Real;
        if m == 0 {
            (self.cos_sum[0] / n).abs()
        } else {
            2.0 * self.cos_sum[m].hypot(self.sin_sum[m]) / n
        }
    }
    fn rms(&self) -> Real {
        (self.w_sq_sum / self.count as Real).sqrt()
    }
    fn centroid(&self) -> [Real; 2] {
        let n = self.count as Real;
        [self.centroid_sum[0] / n, self.centroid_sum[1] / n]
    }
    fn axial(&self) -> Real {
        self.axial_sum / self.count as Real
    }
    /// Largest ring or lobe amplitude (harmonics 0 and 2..8).
    fn fold_amplitude(&self) -> Real {
        (0..=MAX_HARMONIC)
            .filter(|&m| m != 1)
            .map(|m| self.amplitude(m))
            .fold(0.0, Real::max)
    }
}

/// The collapse mode of a finished run and the numbers behind it.
pub fn detect_mode(case: &Case, snapshot: &Snapshot) -> (CollapseMode, ModeDetail) {
    let geometry = case.geometry();
    let section = geometry.section;
    let d = section.width_mm();
    let t = section.thickness_mm();
    // (axial, lateral a, lateral b) component indices.
    let axes = match geometry.mode {
        LoadingMode::Axial => [2, 0, 1],
        LoadingMode::Lateral => [0, 1, 2],
    };
    let mut detail = ModeDetail {
        drift_threshold_mm: DRIFT_FRACTION * d,
        harmonic_amplitude_mm: vec![0.0; MAX_HARMONIC + 1],
        ..Default::default()
    };
    if geometry.model == Model::Axisymmetric {
        return (
            CollapseMode::Ring,
            axisymmetric_detail(case, snapshot, detail),
        );
    }
    let slices = slice_up(snapshot, &section, axes, case.spacing_mm(), &mut detail);
    detail.slices = slices.len() as u32;

    let max_rms = slices.iter().map(Slice::rms).fold(0.0, Real::max);
    let folded: Vec<&Slice> = slices
        .iter()
        .filter(|s| s.rms() >= (FOLDED_FRACTION * max_rms).max(FOLDED_MIN_T * t))
        .collect();
    let used: Vec<&Slice> = if folded.is_empty() {
        slices.iter().collect()
    } else {
        folded.clone()
    };
    detail.folded_slices = folded.len() as u32;
    if !used.is_empty() {
        for (m, a) in detail.harmonic_amplitude_mm.iter_mut().enumerate() {
            *a = used.iter().map(|s| s.amplitude(m)).sum::<Real>() / used.len() as Real;
        }
    }
    detail.max_drift_mm = max_drift(&slices).max(max_axis_offset(&slices));

    if geometry.mode == LoadingMode::Lateral {
        detail.reason = "lateral loading: the tube is flattened across a diameter".into();
        return (CollapseMode::Flattening, detail);
    }
    if slices.is_empty() {
        detail.reason = "no particles to analyse; reported as ring".into();
        return (CollapseMode::Ring, detail);
    }
    let max_fold = slices
        .iter()
        .map(Slice::fold_amplitude)
        .fold(0.0, Real::max);
    // A drift of half a diameter is a global collapse whatever the folds did: a tube that tipped
    // over and was flattened has radial displacements larger than its drift (seen on the
    // t = 1.27, d = 12 example, which was first misread as a ring).
    if detail.max_drift_mm > detail.drift_threshold_mm {
        detail.reason = format!(
            "centre line drifted {:.2} mm (> {:.2} mm; largest fold amplitude {:.2} mm)",
            detail.max_drift_mm, detail.drift_threshold_mm, max_fold
        );
        return (CollapseMode::GlobalBuckling, detail);
    }
    let amp = &detail.harmonic_amplitude_mm;
    let (lobes, lobe_amp) = (2..=MAX_HARMONIC)
        .map(|m| (m, amp[m]))
        .fold((2, Real::MIN), |b, c| if c.1 > b.1 { c } else { b });
    let unfolded = if folded.is_empty() {
        "; no slice folded, all slices used"
    } else {
        ""
    };
    if amp[0] >= lobe_amp {
        detail.reason = format!(
            "axisymmetric amplitude {:.3} mm >= harmonic {lobes} amplitude {:.3} mm{unfolded}",
            amp[0], lobe_amp
        );
        (CollapseMode::Ring, detail)
    } else {
        detail.reason = format!(
            "harmonic {lobes} amplitude {:.3} mm > axisymmetric amplitude {:.3} mm{unfolded}",
            lobe_amp, amp[0]
        );
        (
            CollapseMode::Diamond {
                lobes: lobes as u32,
            },
            detail,
        )
    }
}

/// The detail of an axisymmetric run's section (positions (r, 0, z)), which can fold only as a
/// ring: per material slice one spacing thick, the mean radial displacement is harmonic 0; the
/// other harmonics and the drift are zero by the model's symmetry.
fn axisymmetric_detail(case: &Case, snapshot: &Snapshot, mut detail: ModeDetail) -> ModeDetail {
    let h = case.spacing_mm();
    let t = case.geometry().section.thickness_mm();
    let mut slices: Vec<(usize, Real, Real)> = Vec::new();
    for (x0, x) in snapshot.initial_mm.iter().zip(&snapshot.position_mm) {
        let k = (x0[2] / h).floor().max(0.0) as usize;
        if slices.len() <= k {
            slices.resize(k + 1, (0, 0.0, 0.0));
        }
        let w = x[0] - x0[0];
        slices[k].0 += 1;
        slices[k].1 += w;
        slices[k].2 += w * w;
    }
    slices.retain(|s| s.0 > 0);
    let rms = |s: &(usize, Real, Real)| (s.2 / s.0 as Real).sqrt();
    let max_rms = slices.iter().map(rms).fold(0.0, Real::max);
    let folded: Vec<_> = slices
        .iter()
        .filter(|s| rms(s) >= (FOLDED_FRACTION * max_rms).max(FOLDED_MIN_T * t))
        .collect();
    let used = if folded.is_empty() {
        slices.iter().collect()
    } else {
        folded.clone()
    };
    detail.slices = slices.len() as u32;
    detail.folded_slices = folded.len() as u32;
    detail.slice_width_mm = h;
    if !used.is_empty() {
        detail.harmonic_amplitude_mm[0] =
            used.iter().map(|s| (s.1 / s.0 as Real).abs()).sum::<Real>() / used.len() as Real;
    }
    detail.reason = format!(
        "axisymmetric model: the section folds only as a ring (axisymmetric amplitude {:.3} mm; \
         lobes and drift are outside what the model can show)",
        detail.harmonic_amplitude_mm[0]
    );
    detail
}

/// Bins particles by initial axial coordinate; keeps slices with enough particles, in axial order.
fn slice_up(
    snapshot: &Snapshot,
    section: &CrossSection,
    [ax, la, lb]: [usize; 3],
    h: Real,
    detail: &mut ModeDetail,
) -> Vec<Slice> {
    let pairs = || snapshot.initial_mm.iter().zip(&snapshot.position_mm);
    let (lo, hi) = pairs().fold((Real::MAX, Real::MIN), |(lo, hi), (p, _)| {
        (lo.min(p[ax]), hi.max(p[ax]))
    });
    if snapshot.initial_mm.is_empty() || !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    // Two particle layers per slice at least, so that no slice falls between layers.
    let span = hi - lo;
    let width = (2.0 * h).max(span / MAX_SLICES as Real).max(Real::EPSILON);
    let count = ((span / width).floor() as usize + 1).min(MAX_SLICES + 1);
    detail.slice_width_mm = width;
    let mut slices = vec![Slice::default(); count];
    // A non-finite coordinate would poison its slice's sums; the solver should never store one.
    for (p0, p) in pairs().filter(|(p0, p)| p0.iter().chain(p.iter()).all(|v| v.is_finite())) {
        let k = (((p0[ax] - lo) / width) as usize).min(count - 1);
        let s = &mut slices[k];
        let r0 = section.reach(p0[la], p0[lb]);
        let w = section.reach(p[la], p[lb]) - r0;
        let theta = section.angle(p0[la], p0[lb]);
        s.count += 1;
        s.axial_sum += p0[ax];
        s.centroid_sum[0] += p[la];
        s.centroid_sum[1] += p[lb];
        s.w_sq_sum += w * w;
        for m in 0..=MAX_HARMONIC {
            let (sin, cos) = (m as Real * theta).sin_cos();
            s.cos_sum[m] += w * cos;
            s.sin_sum[m] += w * sin;
        }
    }
    slices.retain(|s| s.count >= MIN_PER_SLICE);
    slices
}

/// Largest distance of a slice centroid from the line joining the end slices' centroids,
/// interpolated by initial axial position.
fn max_drift(slices: &[Slice]) -> Real {
    let (Some(first), Some(last)) = (slices.first(), slices.last()) else {
        return 0.0;
    };
    let (a, b) = (first.centroid(), last.centroid());
    let (z0, z1) = (first.axial(), last.axial());
    slices
        .iter()
        .map(|s| {
            let f = if z1 > z0 {
                (s.axial() - z0) / (z1 - z0)
            } else {
                0.0
            };
            let c = s.centroid();
            (c[0] - (a[0] + f * (b[0] - a[0]))).hypot(c[1] - (a[1] + f * (b[1] - a[1])))
        })
        .fold(0.0, Real::max)
}

/// Largest distance of a slice centroid from the original axis (x = y = 0).
fn max_axis_offset(slices: &[Slice]) -> Real {
    slices
        .iter()
        .map(|s| {
            let c = s.centroid();
            c[0].hypot(c[1])
        })
        .fold(0.0, Real::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::Limits;
    use std::f64::consts::PI;

    /// The default tube (t 3.2, d 22.2, l 76.2, n 4 → h 0.8) laid out as the scene does, along z.
    fn axial_case() -> Case {
        Case::from_json("{}", &Limits::default()).unwrap()
    }

    /// A lattice of the case's tube, each particle moved by `deform(z, θ, r) -> (x, y, z)`.
    fn tube(case: &Case, deform: impl Fn(Real, Real, Real) -> [Real; 3]) -> Snapshot {
        let spec = case.spec();
        let (t, d, l) = (
            spec.tube.thickness_mm,
            spec.tube.mean_diameter_mm,
            spec.tube.length_mm,
        );
        let h = case.spacing_mm();
        let n = spec.discretization.particles_through_thickness;
        let mut snap = Snapshot::default();
        for j in 0..n {
            let r = d / 2.0 - t / 2.0 + (j as Real + 0.5) * h;
            let around = (2.0 * PI * r / h).round() as usize;
            for k in 0..(l / h).round() as usize {
                let z = (k as Real + 0.5) * h;
                for i in 0..around {
                    let th = 2.0 * PI * i as Real / around as Real;
                    snap.initial_mm.push([r * th.cos(), r * th.sin(), z]);
                    snap.position_mm.push(deform(z, th, r));
                }
            }
        }
        snap.plastic_strain = vec![0.0; snap.initial_mm.len()];
        snap
    }

    /// Moves a particle radially by w.
    fn radial(z: Real, th: Real, r: Real, w: Real) -> [Real; 3] {
        [(r + w) * th.cos(), (r + w) * th.sin(), z]
    }

    #[test]
    fn axisymmetric_folds_are_ring() {
        let case = axial_case();
        // w = 2 sin(2πz/12): λ = 12 mm folds, no θ dependence.
        let snap = tube(&case, |z, th, r| {
            radial(z, th, r, 2.0 * (2.0 * PI * z / 12.0).sin())
        });
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Ring, "{detail:?}");
        assert!(detail.harmonic_amplitude_mm[0] > 1.0, "{detail:?}");
        assert!(
            detail.harmonic_amplitude_mm[2..].iter().all(|&a| a < 0.01),
            "{detail:?}"
        );
        assert!(detail.max_drift_mm < 1e-6, "{detail:?}");
        assert!(
            detail.folded_slices > 0 && detail.folded_slices < detail.slices,
            "{detail:?}"
        );
    }

    #[test]
    fn three_lobe_folds_are_diamond_3() {
        let case = axial_case();
        let snap = tube(&case, |z, th, r| {
            radial(
                z,
                th,
                r,
                2.0 * (3.0 * th).cos() * (2.0 * PI * z / 12.0).sin(),
            )
        });
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Diamond { lobes: 3 }, "{detail:?}");
        let a = &detail.harmonic_amplitude_mm;
        assert!(
            a[3] > 10.0 * a[0] && a[3] > 10.0 * a[2] && a[3] > 10.0 * a[4],
            "{detail:?}"
        );
    }

    #[test]
    fn four_lobes_with_some_ring_content_are_diamond_4() {
        let case = axial_case();
        let snap = tube(&case, |z, th, r| {
            let s = (2.0 * PI * z / 12.0).sin();
            radial(z, th, r, (0.5 + 2.0 * (4.0 * th).cos()) * s)
        });
        assert_eq!(
            detect_mode(&case, &snap).0,
            CollapseMode::Diamond { lobes: 4 }
        );
    }

    #[test]
    fn a_bowed_column_is_global_buckling() {
        let case = axial_case();
        let l = case.spec().tube.length_mm;
        // Centre line bowed by B = 15 mm (> 0.5 d = 11.1 mm) at mid-length, section unchanged.
        let snap = tube(&case, |z, th, r| {
            [r * th.cos() + 15.0 * (PI * z / l).sin(), r * th.sin(), z]
        });
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::GlobalBuckling, "{detail:?}");
        // The end slices sit 0.5 mm off the axis, so the drift from their line is about 14.5 mm.
        assert!((detail.max_drift_mm - 15.0).abs() < 1.0, "{detail:?}");
    }

    /// A tube that tipped over and lies across the plates (sections shifted along a straight
    /// tilted line, the ends 30 mm either side of the axis) has no drift from its end slices'
    /// line at all; the distance from the original axis shows the collapse. (The t = 1.27,
    /// d = 10 example at n = 4 did this.)
    #[test]
    fn a_tube_that_tipped_over_is_global_buckling() {
        let case = axial_case();
        let l = case.spec().tube.length_mm;
        let snap = tube(&case, |z, th, r| {
            let lean = 30.0 * (2.0 * z / l - 1.0);
            [r * th.cos() + lean, r * th.sin(), z]
        });
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::GlobalBuckling, "{detail:?}");
        assert!((detail.max_drift_mm - 30.0).abs() < 2.0, "{detail:?}");
    }

    #[test]
    fn a_small_bow_with_ring_folds_stays_ring() {
        let case = axial_case();
        let l = case.spec().tube.length_mm;
        let snap = tube(&case, |z, th, r| {
            let [x, y, z] = radial(z, th, r, 2.0 * (2.0 * PI * z / 12.0).sin());
            [x + 3.0 * (PI * z / l).sin(), y, z]
        });
        assert_eq!(detect_mode(&case, &snap).0, CollapseMode::Ring);
    }

    #[test]
    fn an_undeformed_tube_reads_ring_and_says_so() {
        let case = axial_case();
        let snap = tube(&case, |z, th, r| radial(z, th, r, 0.0));
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Ring);
        assert_eq!(detail.folded_slices, 0);
        assert!(
            detail.reason.contains("no slice folded"),
            "{}",
            detail.reason
        );
    }

    #[test]
    fn empty_snapshot_does_not_panic() {
        let (mode, detail) = detect_mode(&axial_case(), &Snapshot::default());
        assert_eq!(mode, CollapseMode::Ring);
        assert_eq!(detail.slices, 0);
    }

    #[test]
    fn lateral_loading_is_flattening_with_an_oval_section() {
        let case =
            Case::from_json(r#"{"loading": {"mode": "lateral"}}"#, &Limits::default()).unwrap();
        // Axis x; the section squashed in z and widened in y: w ≈ −2 cos(2θ) about x.
        let axial = tube(&case, |z, th, r| radial(z, th, r, -2.0 * (2.0 * th).cos()));
        let snap = Snapshot {
            initial_mm: axial
                .initial_mm
                .iter()
                .map(|p| [p[2], p[0], p[1]])
                .collect(),
            position_mm: axial
                .position_mm
                .iter()
                .map(|p| [p[2], p[0], p[1]])
                .collect(),
            plastic_strain: axial.plastic_strain,
        };
        let (mode, detail) = detect_mode(&case, &snap);
        assert_eq!(mode, CollapseMode::Flattening);
        assert!(
            (detail.harmonic_amplitude_mm[2] - 2.0).abs() < 1e-6,
            "{detail:?}"
        );
    }
}
