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
//! 1. a **global** collapse when the largest drift of a slice centroid — from the straight line
//!    through the end slices' centroids, or from the original axis, whichever is larger —
//!    exceeds [`DRIFT_FRACTION`] · d, whatever the folds did (a tube that tipped over and was
//!    flattened shows radial displacements larger than its drift; one that tipped over and lies
//!    across the plates moves both ends, so only the distance from the axis shows it: the
//!    t = 1.27, d = 10 example at n = 4 had 4.9 mm from the end line but 30 mm from the axis).
//!    It is **tipped over** when the tube turned as a whole: an end has left its plate — its
//!    ring stands on edge, its mean height above the tube's extreme point at that end more than
//!    [`END_LIFT_FRACTION`] · d (a ring turned 30° about its lowest point) — and the centre line
//!    is still straight (no slice centroid more than [`DRIFT_FRACTION`] · d from the line
//!    through the end slices' centroids: the drift is the ends' own, they slid across the
//!    plates). It is **global buckling** otherwise: the column bent, its ends on the plates or
//!    turned by the bend (a column bent far turns its end rings too, so the lift alone cannot
//!    tell a bend from a fall);
//! 2. **ring** when the mean harmonic-0 amplitude over the folded slices is at least the largest
//!    mean amplitude among harmonics 2..8;
//! 3. otherwise **diamond**, with lobes = the harmonic in 2..8 of largest mean amplitude.
//!
//! Folded slices are those whose wall has turned: in at least [`TURNED_SHARE`] of the
//! [`SECTORS`] sectors around the axis, the wall line through the slice (the sector's current
//! centroid in the slice below and the slice above, taken about the slices' own centroids) runs
//! more than 45° from the axis, or back on itself; and whose RMS radial displacement is at least
//! [`FOLDED_MIN_T`] · t. A fold turns its wall by up to 180°; a tube that is oval, or bowed, or
//! bulged but not folded keeps its wall lines near the axis, however large its radial
//! displacement, and its slices do not count (an oval unfolded part would otherwise outvote the
//! lobes of the folds). If no slice is folded, every slice is used (a tube that did not fold
//! reads as ring, and the detail says so). Lateral loading is always
//! [`CollapseMode::Flattening`]; its detail is computed the same way about the x axis.
//!
//! How round the wall not yet folded stayed (a round tube under axial loading, whatever its
//! mode): a slice holds a **hinge** when at least [`HINGE_SHARE`] of its particles passed the
//! plastic strain [`HINGE_STRAIN`] (a fold's hinge lines strain the wall far more; an oval or a
//! cone bent out of the wall does not); the slices with none, at least half a fold length
//! (`reference::fold_length_mm` / 2) from any slice with one, are the unfolded wall, and the
//! largest harmonic-2 amplitude among them of each particle's distance from its slice's own
//! current centroid, less its initial radius, is `unfolded_two_lobe_mm`: how far the unfolded
//! wall went oval. Not all of that is wrong: the hinged slices' own ovals reach along an
//! elastic tube, decaying as e^(−x/ℓ) with ℓ the shell's e-folding length for two lobes
//! (`reference::shell`; 39 mm on the d/t 14 PVC tube, where a fold is 23 mm long). What the
//! unfolded wall holds beyond the largest of those envelopes is `unfolded_excess_two_lobe_mm`,
//! the oval the folds do not explain (a cone splayed on the plate, a wall that yielded); the
//! verdict cautions when it passes half the wall thickness (docs/folding.md §6).
//!
//! How far each end ring spread on its plate (`end_spread`, a round tube under axial loading):
//! its particles' largest distance from its own centroid, over d/2. An end that folds stays
//! near 1; one flattened shut into a pouch, its two sides pressed together on the plate,
//! spreads to π/2, half its perimeter either side of its centre.
//!
//! A polygonal tube's (one with [`Outline::faces`]: a rectangle's, a hexagon's) harmonics are those of its
//! wall-line angle (its perimeter), and its drift is judged against its section's width; once
//! it has not bent over as a whole, its mode is read from how its faces fold ([`faceted`]):
//! symmetric, asymmetric mixed or extensional.

mod faceted;
mod kinds;

pub use kinds::{CollapseMode, FaceLayers};

use super::faces::face_slices;
use super::reference::fold_length_mm;
use super::reference::shell::lobe_decay_mm;
use crate::solver::engine::Snapshot;
use crate::solver::model::case::{Case, CrossSection, LoadingMode, Model, Outline};
use crate::solver::Real;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Highest circumferential harmonic analysed.
pub const MAX_HARMONIC: usize = 8;
/// Centre-line drift, as a fraction of the mean diameter, beyond which the column counts as bowed.
pub const DRIFT_FRACTION: Real = 0.5;
/// A slice is folded when its wall line has turned more than 45° from the axis (lateral change
/// over axial change above 1) in at least this share of its sectors ...
pub const TURNED_SHARE: Real = 0.25;
/// ... and its RMS radial displacement is at least this many wall thicknesses.
pub const FOLDED_MIN_T: Real = 0.25;
/// Sectors around the axis, by the initial angle, in which the wall lines are followed: 22.5°,
/// as in the fold counter.
pub const SECTORS: usize = 16;
/// An end has left its plate when its ring's mean height above the tube's extreme point at that
/// end exceeds this share of the width d: a ring turned by 30° about its lowest point.
pub const END_LIFT_FRACTION: Real = 0.25;
/// The plastic strain a fold's hinge lines pass (PVC and aluminium folds strain their hinges
/// to 0.4–0.8; the wall between folds, an oval or a cone bent out of the wall, 0.02–0.1) ...
pub const HINGE_STRAIN: Real = 0.2;
/// ... in at least this share of a slice's particles for the slice to hold a hinge (the
/// slices through a fold's hinges pass 0.3–1.0; a wall pressed on a plate with friction, or a
/// slice on a fold's edge, up to 0.1–0.25).
pub const HINGE_SHARE: Real = 0.25;
/// Fewest particles a slice needs to resolve harmonic 8 (Nyquist: 2·8 + 1).
const MIN_PER_SLICE: usize = 2 * MAX_HARMONIC + 1;
/// Most slices along the tube.
const MAX_SLICES: usize = 400;

/// Why the mode came out as it did.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct ModeDetail {
    /// Slices holding enough particles to analyse.
    pub slices: u32,
    /// Slices counted as folded: a round tube's where the wall turned back along the axis (the
    /// ring/diamond decision reads these), a polygonal tube's where its faces moved enough to
    /// be read (the faces' patterns in `faces` count these).
    pub folded_slices: u32,
    /// Width of a slice in the initial axial coordinate, mm.
    pub slice_width_mm: Real,
    /// Amplitude of harmonics 0..=8 of the radial displacement, mean over the folded slices, mm.
    pub harmonic_amplitude_mm: Vec<Real>,
    /// Largest lateral drift of a slice centroid, from the end slices' line or from the original
    /// axis, whichever is larger, mm.
    pub max_drift_mm: Real,
    /// Largest distance of a slice centroid from the line through the end slices' centroids,
    /// mm: how far the column bent (a tube that turned as a whole has little).
    #[serde(default)]
    pub bend_mm: Real,
    /// Drift beyond which the column counts as bowed (DRIFT_FRACTION · d), mm.
    pub drift_threshold_mm: Real,
    /// How far each end's ring (bottom, top: the particle layer at the end before the crush)
    /// stands, on average, above the tube's extreme point at that end (below it, at the top),
    /// mm: about 0 for an end flat on its plate.
    #[serde(default)]
    pub end_lift_mm: [Real; 2],
    /// Lift beyond which an end has left its plate (END_LIFT_FRACTION · d), mm.
    #[serde(default)]
    pub end_lift_threshold_mm: Real,
    /// How far each end ring (bottom, top) of a round tube under axial loading spread on its
    /// plate: the largest distance of its particles from its own centroid over d/2. About 1
    /// for an end that folded or stayed round; π/2 for a ring flattened shut (half its
    /// perimeter either side of its centre).
    #[serde(default)]
    pub end_spread: [Real; 2],
    /// The unfolded wall of a round tube under axial loading (slices with no hinge, half a
    /// fold length or more from any with one): how many slices, ...
    #[serde(default)]
    pub unfolded_slices: u32,
    /// ... their largest two-lobe (harmonic 2) amplitude about their own centroid, mm (0 with
    /// none) ...
    #[serde(default)]
    pub unfolded_two_lobe_mm: Real,
    /// ... and where that slice lay before the crush (its initial axial coordinate), mm.
    #[serde(default)]
    pub unfolded_two_lobe_at_mm: Real,
    /// The largest two-lobe amplitude of the slices that hold a fold's hinge, mm: the oval
    /// the folds themselves impose on the wall next to them.
    #[serde(default)]
    pub folds_two_lobe_mm: Real,
    /// The e-folding length over which an elastic tube of this section carries an oval along
    /// its axis (`reference::shell::lobe_decay_mm`, two lobes), mm.
    #[serde(default)]
    pub two_lobe_decay_mm: Real,
    /// The unfolded wall's largest two-lobe amplitude beyond what the folds' ovals carry to
    /// it on an elastic shell (each hinged slice's amplitude times e^(−distance / e-folding
    /// length), the largest of them), mm: 0 where the wall is no more oval than the folds
    /// make it ...
    #[serde(default)]
    pub unfolded_excess_two_lobe_mm: Real,
    /// ... and where that slice lay before the crush, mm.
    #[serde(default)]
    pub unfolded_excess_two_lobe_at_mm: Real,
    /// One sentence: which test decided.
    pub reason: String,
    /// A polygonal tube's folded slices by the pattern of their faces (axial loading).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub faces: Option<FaceLayers>,
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
    /// Per sector of the initial angle: particles, and the sum of their current (axial,
    /// lateral a, lateral b) coordinates.
    sector_count: [u32; SECTORS],
    sector_sum: [[Real; 3]; SECTORS],
    /// Particles past [`HINGE_STRAIN`].
    hinged: usize,
    /// Σ w_c cos 2θ, Σ w_c sin 2θ, w_c the distance from the slice's current centroid less
    /// the initial reach.
    oval_sum: [Real; 2],
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
    /// Sector `s`'s current centroid (axial, lateral a, lateral b), if it holds particles.
    fn sector(&self, s: usize) -> Option<[Real; 3]> {
        let n = self.sector_count[s] as Real;
        let c = &self.sector_sum[s];
        (n > 0.0).then(|| [c[0] / n, c[1] / n, c[2] / n])
    }
    /// Harmonic 2 of the distance from the slice's own centroid, mm.
    fn oval_amplitude(&self) -> Real {
        2.0 * self.oval_sum[0].hypot(self.oval_sum[1]) / self.count as Real
    }
    /// Whether a fold's hinge runs through the slice.
    fn holds_hinge(&self) -> bool {
        self.hinged as Real >= HINGE_SHARE * self.count as Real
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
    // Read face by face, or by harmonics around the axis.
    let faceted = section.faces() > 0;
    // The unfolded wall's oval is read on a round tube under axial loading only.
    let oval = geometry.mode == LoadingMode::Axial && !faceted;
    let slices = slice_up(
        snapshot,
        &section,
        axes,
        case.spacing_mm(),
        oval,
        &mut detail,
    );
    detail.slices = slices.len() as u32;

    let any_folded = fold_harmonics(&slices, t, &mut detail);
    detail.bend_mm = max_drift(&slices);
    detail.max_drift_mm = detail.bend_mm.max(max_axis_offset(&slices));
    detail.end_lift_mm = end_lifts(snapshot, axes, case.spacing_mm());
    detail.end_lift_threshold_mm = END_LIFT_FRACTION * d;

    if geometry.mode == LoadingMode::Lateral {
        detail.reason = "lateral loading: the tube is flattened across a diameter".into();
        return (CollapseMode::Flattening, detail);
    }
    if slices.is_empty() {
        let (mode, name) = match faceted {
            true => (CollapseMode::Symmetric, "symmetric"),
            false => (CollapseMode::Ring, "ring"),
        };
        detail.reason = format!("no particles to analyse; reported as {name}");
        return (mode, detail);
    }
    if oval {
        detail.end_spread = end_spreads(snapshot, axes, case.spacing_mm()).map(|r| r / (0.5 * d));
        let nu = case.spec().material.poisson_ratio;
        let decay = lobe_decay_mm(0.5 * d, t, nu, 2);
        unfolded_wall(&slices, 0.5 * fold_length_mm(case), decay, &mut detail);
    }
    let max_fold = slices
        .iter()
        .map(Slice::fold_amplitude)
        .fold(0.0, Real::max);
    // A drift of half a diameter is a global collapse whatever the folds did: a tube that tipped
    // over and was flattened has radial displacements larger than its drift (seen on the
    // t = 1.27, d = 12 example, which was first misread as a ring).
    if let Some(mode) = global_collapse(&mut detail, max_fold) {
        return (mode, detail);
    }
    if faceted {
        let faces = face_slices(snapshot, &section, axes, detail.slice_width_mm);
        let (mode, counts, reason) = faceted::decide(&faces, FOLDED_MIN_T * t);
        detail.faces = Some(counts);
        detail.folded_slices = counts.total();
        detail.reason = reason;
        return (mode, detail);
    }
    let mode = ring_or_diamond(&mut detail, any_folded);
    (mode, detail)
}

/// Reads the harmonics of the folded slices (of every slice where none folded) into
/// `detail`, with the count of folded slices; whether any slice folded. A slice is folded when
/// at least [`TURNED_SHARE`] of its wall turned and its RMS radial displacement reaches
/// [`FOLDED_MIN_T`] · t.
fn fold_harmonics(slices: &[Slice], t: Real, detail: &mut ModeDetail) -> bool {
    let folded: Vec<&Slice> = slices
        .iter()
        .zip(turned_shares(slices))
        .filter(|(s, turned)| *turned >= TURNED_SHARE && s.rms() >= FOLDED_MIN_T * t)
        .map(|(s, _)| s)
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
    !folded.is_empty()
}

/// Global buckling or tipping over, when the centre line drifted past its threshold: tipped
/// over where an end left its plate and the line stayed straight, else buckled. Writes the
/// reason into `detail`; `max_fold`: the largest fold amplitude, mm, for the reason.
fn global_collapse(detail: &mut ModeDetail, max_fold: Real) -> Option<CollapseMode> {
    if detail.max_drift_mm > detail.drift_threshold_mm {
        let [bottom, top] = detail.end_lift_mm;
        let left = bottom.max(top) > detail.end_lift_threshold_mm;
        let bent = detail.bend_mm > detail.drift_threshold_mm;
        detail.reason = format!(
            "centre line drifted {:.2} mm (> {:.2} mm; largest fold amplitude {:.2} mm), \
             {:.2} mm from the line through its ends ({}); the ends' rings stand {bottom:.2} \
             and {top:.2} mm off their plates ({} {:.2} mm)",
            detail.max_drift_mm,
            detail.drift_threshold_mm,
            max_fold,
            detail.bend_mm,
            if bent { "bent" } else { "straight" },
            if left {
                "an end left its plate: >"
            } else {
                "both on them: <="
            },
            detail.end_lift_threshold_mm
        );
        let mode = match left && !bent {
            true => CollapseMode::TippedOver,
            false => CollapseMode::GlobalBuckling,
        };
        return Some(mode);
    }
    None
}

/// A round tube that folded in place: rings where the axisymmetric amplitude is at least the
/// largest lobed harmonic's, else a diamond with that harmonic's lobes. Writes the reason.
fn ring_or_diamond(detail: &mut ModeDetail, any_folded: bool) -> CollapseMode {
    let amp = &detail.harmonic_amplitude_mm;
    let (lobes, lobe_amp) = (2..=MAX_HARMONIC)
        .map(|m| (m, amp[m]))
        .fold((2, Real::MIN), |b, c| if c.1 > b.1 { c } else { b });
    let unfolded = if !any_folded {
        "; no slice folded, all slices used"
    } else {
        ""
    };
    if amp[0] >= lobe_amp {
        detail.reason = format!(
            "axisymmetric amplitude {:.3} mm >= harmonic {lobes} amplitude {:.3} mm{unfolded}",
            amp[0], lobe_amp
        );
        CollapseMode::Ring
    } else {
        detail.reason = format!(
            "harmonic {lobes} amplitude {:.3} mm > axisymmetric amplitude {:.3} mm{unfolded}",
            lobe_amp, amp[0]
        );
        CollapseMode::Diamond {
            lobes: lobes as u32,
        }
    }
}

/// The detail of an axisymmetric run's section (positions (r, 0, z)), which can fold only as a
/// ring: per material slice one spacing thick, the mean radial displacement is harmonic 0; the
/// other harmonics and the drift are zero by the model's symmetry. A slice is folded as in 3D:
/// its wall line (the mean (r, z) of the slice below to that of the slice above) runs more than
/// 45° from the axis, and its RMS radial displacement reaches [`FOLDED_MIN_T`] · t.
fn axisymmetric_detail(case: &Case, snapshot: &Snapshot, mut detail: ModeDetail) -> ModeDetail {
    let h = case.spacing_mm();
    let t = case.geometry().section.thickness_mm();
    /// Particles, Σ w, Σ w², Σ r, Σ z of one material slice.
    #[derive(Clone, Copy, Default)]
    struct Ring(usize, Real, Real, Real, Real);
    let mut slices: Vec<Ring> = Vec::new();
    for (x0, x) in snapshot.initial_mm.iter().zip(&snapshot.position_mm) {
        let k = (x0[2] / h).floor().max(0.0) as usize;
        if slices.len() <= k {
            slices.resize(k + 1, Ring::default());
        }
        let w = x[0] - x0[0];
        let s = &mut slices[k];
        *s = Ring(s.0 + 1, s.1 + w, s.2 + w * w, s.3 + x[0], s.4 + x[2]);
    }
    slices.retain(|s| s.0 > 0);
    let mean = |s: &Ring| [s.3 / s.0 as Real, s.4 / s.0 as Real];
    let last = slices.len().saturating_sub(1);
    let folded: Vec<&Ring> = (0..slices.len())
        .filter(|&k| {
            let (a, b) = (
                mean(&slices[k.saturating_sub(1)]),
                mean(&slices[(k + 1).min(last)]),
            );
            let s = &slices[k];
            (b[0] - a[0]).abs() > b[1] - a[1] && (s.2 / s.0 as Real).sqrt() >= FOLDED_MIN_T * t
        })
        .map(|k| &slices[k])
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
/// With `oval`, also sums each slice's two-lobe shape about its own centroid.
fn slice_up(
    snapshot: &Snapshot,
    section: &CrossSection,
    [ax, la, lb]: [usize; 3],
    h: Real,
    oval: bool,
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
    let finite = |(_, (p0, p)): &(usize, (&[Real; 3], &[Real; 3]))| {
        p0.iter().chain(p.iter()).all(|v| v.is_finite())
    };
    let slice_of = |p0: &[Real; 3]| (((p0[ax] - lo) / width) as usize).min(count - 1);
    let strain = |i: usize| snapshot.plastic_strain.get(i).copied().unwrap_or(0.0);
    for (i, (p0, p)) in pairs().enumerate().filter(finite) {
        let s = &mut slices[slice_of(p0)];
        s.hinged += usize::from(strain(i) > HINGE_STRAIN);
        let r0 = section.reach(p0[la], p0[lb]);
        let w = section.reach(p[la], p[lb]) - r0;
        let theta = section.angle(p0[la], p0[lb]);
        s.count += 1;
        s.axial_sum += p0[ax];
        s.centroid_sum[0] += p[la];
        s.centroid_sum[1] += p[lb];
        s.w_sq_sum += w * w;
        let turn = theta / std::f64::consts::TAU + 0.5;
        let sector = ((turn * SECTORS as Real) as usize).min(SECTORS - 1);
        s.sector_count[sector] += 1;
        for (sum, v) in s.sector_sum[sector].iter_mut().zip([p[ax], p[la], p[lb]]) {
            *sum += v;
        }
        for m in 0..=MAX_HARMONIC {
            let (sin, cos) = (m as Real * theta).sin_cos();
            s.cos_sum[m] += w * cos;
            s.sin_sum[m] += w * sin;
        }
    }
    // The distance from each slice's own centroid needs the centroids: a second pass, made
    // only where the oval is read.
    if oval {
        for (_, (p0, p)) in pairs().enumerate().filter(finite) {
            let s = &mut slices[slice_of(p0)];
            let c = s.centroid();
            let w_c = section.reach(p[la] - c[0], p[lb] - c[1]) - section.reach(p0[la], p0[lb]);
            let (sin, cos) = (2.0 * section.angle(p0[la], p0[lb])).sin_cos();
            s.oval_sum[0] += w_c * cos;
            s.oval_sum[1] += w_c * sin;
        }
    }
    slices.retain(|s| s.count >= MIN_PER_SLICE);
    slices
}

/// The unfolded wall's slices and their largest two-lobe amplitude (module doc), into `detail`:
/// the slices without a hinge whose initial axial coordinate lies at least `clear` mm from
/// every slice with one; and how much more oval they are than the hinged slices' ovals leave
/// on an elastic shell that carries an oval over `decay` mm (e-folding).
fn unfolded_wall(slices: &[Slice], clear: Real, decay: Real, detail: &mut ModeDetail) {
    let hinges: Vec<(Real, Real)> = slices
        .iter()
        .filter(|s| s.holds_hinge())
        .map(|s| (s.axial(), s.oval_amplitude()))
        .collect();
    detail.two_lobe_decay_mm = decay;
    detail.folds_two_lobe_mm = hinges.iter().map(|h| h.1).fold(0.0, Real::max);
    let unfolded = slices.iter().filter(|s| {
        !s.holds_hinge() && hinges.iter().all(|&(z, _)| (s.axial() - z).abs() >= clear)
    });
    for s in unfolded {
        detail.unfolded_slices += 1;
        let a = s.oval_amplitude();
        if a > detail.unfolded_two_lobe_mm {
            detail.unfolded_two_lobe_mm = a;
            detail.unfolded_two_lobe_at_mm = s.axial();
        }
        let carried = hinges
            .iter()
            .map(|&(z, oval)| oval * (-(s.axial() - z).abs() / decay).exp())
            .fold(0.0, Real::max);
        if a - carried > detail.unfolded_excess_two_lobe_mm {
            detail.unfolded_excess_two_lobe_mm = a - carried;
            detail.unfolded_excess_two_lobe_at_mm = s.axial();
        }
    }
}

/// Per slice, the share of its sectors whose wall line has turned more than 45° from the tube's
/// axis: the line from the sector's centroid in the slice below to the one in the slice above
/// (the slice itself at the ends), each taken about its slice's centroid so that a bowed or
/// shifted centre line does not count, changes more sideways than along the axis, or runs back.
fn turned_shares(slices: &[Slice]) -> Vec<Real> {
    let last = slices.len().saturating_sub(1);
    (0..slices.len())
        .map(|k| {
            let (a, b) = (&slices[k.saturating_sub(1)], &slices[(k + 1).min(last)]);
            let (ca, cb) = (a.centroid(), b.centroid());
            let (mut seen, mut turned) = (0u32, 0u32);
            for s in 0..SECTORS {
                let (Some(pa), Some(pb)) = (a.sector(s), b.sector(s)) else {
                    continue;
                };
                let along = pb[0] - pa[0];
                let across =
                    ((pb[1] - cb[0]) - (pa[1] - ca[0])).hypot((pb[2] - cb[1]) - (pa[2] - ca[1]));
                seen += 1;
                turned += u32::from(across > along);
            }
            match seen {
                0 => 0.0,
                _ => turned as Real / seen as Real,
            }
        })
        .collect()
}

/// How far each end's ring — the particles of the layer at that end before the crush, found
/// by their initial axial coordinate within half a spacing `h` of the end — stands on average
/// from the tube's extreme point at that end (its lowest point for the bottom end, its highest
/// for the top), mm, as (bottom, top). An end flat on its plate lifts about 0; a ring turned
/// by α about its lowest point lifts (d/2)·sin α; the end of a tube lying on its side, more.
fn end_lifts(snapshot: &Snapshot, [ax, ..]: [usize; 3], h: Real) -> [Real; 2] {
    let pairs = || {
        snapshot
            .initial_mm
            .iter()
            .zip(&snapshot.position_mm)
            .filter(|(p0, p)| p0[ax].is_finite() && p[ax].is_finite())
    };
    let (mut lo0, mut hi0, mut lo, mut hi) = (Real::MAX, Real::MIN, Real::MAX, Real::MIN);
    for (p0, p) in pairs() {
        (lo0, hi0) = (lo0.min(p0[ax]), hi0.max(p0[ax]));
        (lo, hi) = (lo.min(p[ax]), hi.max(p[ax]));
    }
    let mut sums = [(0.0, 0usize); 2];
    for (p0, p) in pairs() {
        if p0[ax] <= lo0 + 0.5 * h {
            sums[0] = (sums[0].0 + p[ax] - lo, sums[0].1 + 1);
        }
        if p0[ax] >= hi0 - 0.5 * h {
            sums[1] = (sums[1].0 + hi - p[ax], sums[1].1 + 1);
        }
    }
    sums.map(|(sum, n)| if n > 0 { sum / n as Real } else { 0.0 })
}

/// Per end ring (the particles within h/2 of the tube's initial bottom, top), the largest
/// distance of a particle from the ring's own current centroid across the axis, mm.
fn end_spreads(snapshot: &Snapshot, [ax, a, b]: [usize; 3], h: Real) -> [Real; 2] {
    let pairs: Vec<(&[Real; 3], &[Real; 3])> = snapshot
        .initial_mm
        .iter()
        .zip(&snapshot.position_mm)
        .filter(|(p0, p)| p0[ax].is_finite() && p.iter().all(|x| x.is_finite()))
        .collect();
    let (lo0, hi0) = pairs
        .iter()
        .fold((Real::MAX, Real::MIN), |(lo, hi), (p0, _)| {
            (lo.min(p0[ax]), hi.max(p0[ax]))
        });
    let mut rings: [Vec<[Real; 2]>; 2] = Default::default();
    for (p0, p) in &pairs {
        if p0[ax] <= lo0 + 0.5 * h {
            rings[0].push([p[a], p[b]]);
        }
        if p0[ax] >= hi0 - 0.5 * h {
            rings[1].push([p[a], p[b]]);
        }
    }
    rings.map(|ring| {
        let n = ring.len().max(1) as Real;
        let c = ring
            .iter()
            .fold([0.0; 2], |c, q| [c[0] + q[0] / n, c[1] + q[1] / n]);
        ring.iter()
            .map(|q| (q[0] - c[0]).hypot(q[1] - c[1]))
            .fold(0.0, Real::max)
    })
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
mod tests;
