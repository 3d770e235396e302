//! The tube's geometry, owned in one place. Its cross-section ([`CrossSection`]: the wall's
//! shape and thickness, and the wall-line metric the analysis reads a deformed tube with) and,
//! with the length, the particles through the wall, the model and the loading direction, the
//! particle lattice ([`Geometry`]): every particle's centre and volume, the one exact particle
//! count, where the plates start and the box the particles must stay in. Everything after the
//! scene reads the geometry from here, never from raw t and d. Units: mm, mm³.
//!
//! Frames: axial loading puts the tube axis on z (bottom plate at z = 0); lateral loading puts
//! it on x over 0..l, centred on y = z = 0, with the plates normal to z. The reduced models lay
//! their section in the x–z plane (y is the direction the symmetry removes): axisymmetric, x is
//! the radius r and z the axis, each particle standing for its ring (volume 2π·r·area); plane
//! strain, x and z are the cross-section's y and z, each particle standing for the tube's length
//! (volume area·l).

mod rectangle;

pub use rectangle::Rectangle;

use super::spec::{CaseSpec, LoadingMode, Model, SectionShape, Tube, DEFAULT_MEAN_DIAMETER_MM};
use crate::solver::Real;
use nalgebra::Vector3;
use std::f64::consts::PI;

/// The tube's cross-section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CrossSection {
    /// A round tube of wall thickness t and mean diameter d (at the wall's mid-surface).
    Round {
        thickness_mm: Real,
        mean_diameter_mm: Real,
    },
    /// A rectangular tube with rounded corners ([`Rectangle`]).
    Rectangular(Rectangle),
}

impl CrossSection {
    /// The cross-section a tube's spec describes, its omitted lengths filled in: a round
    /// tube's diameter, a rectangular one's side b (= a) and corner radius (= t). A length
    /// that is required and missing reads NaN: the checks name it.
    pub fn of(tube: &Tube) -> CrossSection {
        let t = tube.thickness_mm;
        match tube.section {
            SectionShape::Round => CrossSection::Round {
                thickness_mm: t,
                mean_diameter_mm: tube.mean_diameter_mm.unwrap_or(DEFAULT_MEAN_DIAMETER_MM),
            },
            SectionShape::Rectangular => {
                let a = tube.side_a_mm.unwrap_or(Real::NAN);
                CrossSection::Rectangular(Rectangle {
                    thickness_mm: t,
                    side_a_mm: a,
                    side_b_mm: tube.side_b_mm.unwrap_or(a),
                    corner_radius_mm: tube.corner_radius_mm.unwrap_or(t),
                })
            }
        }
    }

    /// The wall thickness t, mm.
    pub fn thickness_mm(&self) -> Real {
        match *self {
            CrossSection::Round { thickness_mm, .. } => thickness_mm,
            CrossSection::Rectangular(r) => r.thickness_mm,
        }
    }

    /// The size across the section at the wall's mid-surface, mm: a round tube's mean diameter
    /// d, a rectangular one's larger side. The scale a sideways drift of the tube is measured
    /// against, and the wall's slenderness with t.
    pub fn width_mm(&self) -> Real {
        match *self {
            CrossSection::Round {
                mean_diameter_mm, ..
            } => mean_diameter_mm,
            CrossSection::Rectangular(r) => r.side_a_mm.max(r.side_b_mm),
        }
    }

    /// The name of [`CrossSection::width_mm`] in a slenderness ratio: `d` or `b`.
    pub fn width_symbol(&self) -> &'static str {
        match self {
            CrossSection::Round { .. } => "d",
            CrossSection::Rectangular(_) => "b",
        }
    }

    /// From the centre to the undeformed outer surface, mm, as far as it goes: (d + t)/2 for a
    /// round tube, half the larger outer side for a rectangular one.
    pub fn outer_mm(&self) -> Real {
        match *self {
            CrossSection::Round {
                thickness_mm: t,
                mean_diameter_mm: d,
            } => (d + t) / 2.0,
            CrossSection::Rectangular(r) => {
                let (a, b) = r.outer_half();
                a.max(b)
            }
        }
    }

    /// From the centre to the outer surface along the plates' normal in a lateral crush, mm:
    /// (d + t)/2, or (b + t)/2.
    pub fn half_height_mm(&self) -> Real {
        match *self {
            CrossSection::Round { .. } => self.outer_mm(),
            CrossSection::Rectangular(r) => r.outer_half().1,
        }
    }

    /// The bore between the plates in a lateral crush, mm: d − t, or b − t.
    pub fn bore_mm(&self) -> Real {
        match *self {
            CrossSection::Round {
                thickness_mm: t,
                mean_diameter_mm: d,
            } => d - t,
            CrossSection::Rectangular(r) => r.side_b_mm - r.thickness_mm,
        }
    }

    /// The wall's cross-section area, mm²: π d t, or t times the mid-line's length.
    pub fn area_mm2(&self) -> Real {
        match *self {
            CrossSection::Round {
                thickness_mm: t,
                mean_diameter_mm: d,
            } => PI * d * t,
            CrossSection::Rectangular(r) => r.area_mm2(),
        }
    }

    /// The wall-line metric, around: where on the wall a point at (dx, dy) from the section's
    /// centre lies, as an angle in (−π, π] (its polar angle, for a round tube; its nearest
    /// mid-line point's share of the perimeter from the middle of the +x face, for a
    /// rectangular one).
    #[inline]
    pub fn angle(&self, dx: Real, dy: Real) -> Real {
        match self {
            CrossSection::Round { .. } => dy.atan2(dx),
            CrossSection::Rectangular(r) => r.angle(dx, dy),
        }
    }

    /// The wall-line metric, out: how far from the section's centre a point at (dx, dy) lies,
    /// measured along the wall's outward normal, mm: its radius, for a round tube; for a
    /// rectangular one [`CrossSection::outer_mm`] plus its signed distance from the
    /// undeformed outer surface (the distance from the centre, on the faces of a square).
    /// Either way, the undeformed outer surface reads `outer_mm`.
    #[inline]
    pub fn reach(&self, dx: Real, dy: Real) -> Real {
        match self {
            CrossSection::Round { .. } => dx.hypot(dy),
            CrossSection::Rectangular(r) => self.outer_mm() + r.beyond_outer(dx, dy),
        }
    }

    /// The wall-line metric, faces: beside which face's middle half a point at (dx, dy) from
    /// a rectangular section's centre lies, 0 to 3 anticlockwise from +x (None nearer a corner,
    /// and always for a round section).
    #[inline]
    pub fn face(&self, dx: Real, dy: Real) -> Option<usize> {
        match self {
            CrossSection::Round { .. } => None,
            CrossSection::Rectangular(r) => r.face(dx, dy),
        }
    }
}

/// The whole tube as the solver lays it out: its cross-section, length and particles through
/// the wall, for a model and a loading direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    pub section: CrossSection,
    /// The tube's length l, mm.
    pub length_mm: Real,
    /// Particles through the wall, n.
    pub layers: u32,
    pub model: Model,
    pub mode: LoadingMode,
}

impl Geometry {
    /// The geometry a case's spec describes. Meaningful for a spec whose tube and
    /// discretization passed their checks (a stored case did, when it was submitted).
    pub fn of(spec: &CaseSpec) -> Geometry {
        Geometry {
            section: CrossSection::of(&spec.tube),
            length_mm: spec.tube.length_mm,
            layers: spec.discretization.particles_through_thickness,
            model: spec.discretization.model,
            mode: spec.loading.mode,
        }
    }

    /// Particle spacing h = t / n, mm.
    pub fn spacing_mm(&self) -> Real {
        self.section.thickness_mm() / self.layers as Real
    }

    /// The number of particles [`Geometry::each_point`] lays out, exactly. Only for a geometry
    /// whose [`Geometry::count_f64`] fits a u64.
    pub fn count(&self) -> u64 {
        let n = self.layers as u64;
        let axial = layers_along(self.length_mm, self.spacing_mm());
        match self.model {
            Model::ThreeD => self.around_all() * axial,
            // The (r, z) section: n layers by the layers along.
            Model::Axisymmetric => n * axial,
            // The cross-section: the rings of one layer along.
            Model::PlaneStrain => self.around_all(),
        }
    }

    /// Particles around the wall, summed over the layers through it.
    fn around_all(&self) -> u64 {
        let n = self.layers as u64;
        match self.section {
            CrossSection::Round {
                thickness_mm: t,
                mean_diameter_mm: d,
            } => {
                let h = t / n as f64;
                let inner = d / 2.0 - t / 2.0;
                (0..n)
                    .map(|j| around(inner + (j as f64 + 0.5) * h, h))
                    .sum::<u64>()
            }
            CrossSection::Rectangular(r) => {
                let h = self.spacing_mm();
                (0..self.layers)
                    .map(|j| around_length(r.perimeter_at(offset(r.thickness_mm, h, j)), h))
                    .sum::<u64>()
            }
        }
    }

    /// The same count in floating point, for any geometry whose fields are finite and positive:
    /// it cannot wrap or saturate (it may be infinite). Exact below 2⁵³, as every term is an
    /// integer.
    pub fn count_f64(&self) -> f64 {
        let t = self.section.thickness_mm();
        let n = self.layers as f64;
        let h = t / n;
        let axial = (self.length_mm / h).round().max(1.0);
        let around_all = || -> f64 {
            match self.section {
                CrossSection::Round {
                    mean_diameter_mm: d,
                    ..
                } => {
                    let inner = d / 2.0 - t / 2.0;
                    (0..self.layers)
                        .map(|j| {
                            let r = inner + (j as f64 + 0.5) * h;
                            (2.0 * PI * r / h).round().max(8.0)
                        })
                        .sum()
                }
                CrossSection::Rectangular(r) => (0..self.layers)
                    .map(|j| (r.perimeter_at(offset(t, h, j)) / h).round().max(8.0))
                    .sum(),
            }
        };
        match self.model {
            Model::ThreeD => around_all() * axial,
            Model::Axisymmetric => n * axial,
            Model::PlaneStrain => around_all(),
        }
    }

    /// Every particle's centre (in the engine's frame: see the module's note) and volume, in the
    /// scene's order: axial position outermost, then angle, then radius for the 3D tube, so that
    /// neighbours in space stay near in memory. The volumes add up to the wall's.
    pub fn each_point(&self, mut f: impl FnMut(Vector3<Real>, Real)) {
        match self.model {
            Model::ThreeD => {
                let lattice = self.lattice();
                for (x, vol) in lattice.points(self.mode) {
                    f(x, vol);
                }
            }
            Model::Axisymmetric | Model::PlaneStrain => {
                for (x, vol) in self.section_points() {
                    f(x, vol);
                }
            }
        }
    }

    /// The particles' positions before the crush as the outputs report them ([`Geometry::reported`]),
    /// in the scene's order: what a snapshot's `initial_mm` holds.
    pub fn positions(&self) -> Vec<[Real; 3]> {
        let mut out = Vec::with_capacity(self.count() as usize);
        match self.model {
            // Only the positions: the full particle set is hundreds of bytes a particle, and this
            // is what every state download rebuilds.
            Model::ThreeD => out.extend(
                self.lattice()
                    .points(self.mode)
                    .map(|(x, _)| [x.x, x.y, x.z]),
            ),
            _ => out.extend(self.section_points().iter().map(|(x, _)| self.reported(x))),
        }
        out
    }

    /// Where outputs put an engine position: the 3D scene's coordinates. Axisymmetric:
    /// (r, 0, z), the section at angle 0. Plane strain: the cross-section at mid-length,
    /// (l/2, x, z).
    pub fn reported(&self, x: &Vector3<Real>) -> [Real; 3] {
        match self.model {
            Model::ThreeD | Model::Axisymmetric => [x.x, x.y, x.z],
            Model::PlaneStrain => [0.5 * self.length_mm, x.x, x.z],
        }
    }

    /// A vector of the engine (a velocity) in the frame of [`Geometry::reported`].
    pub fn reported_vector(&self, v: &Vector3<Real>) -> [Real; 3] {
        match self.model {
            Model::ThreeD | Model::Axisymmetric => [v.x, v.y, v.z],
            Model::PlaneStrain => [v.y, v.x, v.z],
        }
    }

    /// A stress of the engine (Voigt order xx, yy, zz, yz, xz, xy) in the frame of
    /// [`Geometry::reported`]: in plane strain the engine's x is the reported y and its removed
    /// y the reported x, so the two swap; axisymmetric, the engine's (r, θ, z) is (x, y, z) at
    /// angle 0.
    pub fn reported_stress(&self, s: &[Real; 6]) -> [Real; 6] {
        match self.model {
            Model::ThreeD | Model::Axisymmetric => *s,
            Model::PlaneStrain => [s[1], s[0], s[2], s[4], s[3], s[5]],
        }
    }

    /// Where the plates start, z of (the moving top plate, the fixed bottom plate), mm: on the
    /// tube's ends (axial) or on its outer surface (lateral).
    pub fn plates_z(&self) -> (Real, Real) {
        let half = self.section.half_height_mm();
        match self.mode {
            LoadingMode::Axial => (self.length_mm, 0.0),
            LoadingMode::Lateral => (half, -half),
        }
    }

    /// The box the particles must stay in, mm: three cells of `cell_mm` beyond the plates, and
    /// the tube's outer radius (its largest outer half-side) plus its length around it (any
    /// fold or tip-over stays inside).
    pub fn domain(&self, cell_mm: Real) -> [[Real; 3]; 2] {
        let (outer, l) = (self.section.outer_mm(), self.length_mm);
        let half = self.section.half_height_mm();
        let reach = outer + l;
        let margin = 3.0 * cell_mm;
        match (self.model, self.mode) {
            (Model::ThreeD, LoadingMode::Axial) => {
                [[-reach, -reach, -margin], [reach, reach, l + margin]]
            }
            (Model::ThreeD, LoadingMode::Lateral) => [
                [-reach, -reach, -half - margin],
                [l + reach, reach, half + margin],
            ],
            // A particle reaching the axis would divide by r = 0 in its hoop strain rate.
            (_, LoadingMode::Axial) => [[0.0, 0.0, -margin], [reach, 0.0, l + margin]],
            (_, LoadingMode::Lateral) => {
                [[-reach, 0.0, -half - margin], [reach, 0.0, half + margin]]
            }
        }
    }

    /// What the points of a reduced model's outputs are, for a reader of the files: None for
    /// 3D.
    pub fn symmetry_note(&self) -> Option<&'static str> {
        match self.model {
            Model::ThreeD => None,
            Model::Axisymmetric => Some(
                "axisymmetric model: the points are the (r, z) section at angle 0 (x = r, y = 0); \
                 each stands for its ring about the z axis, and the tube is this section revolved",
            ),
            Model::PlaneStrain => Some(
                "plane-strain model: the points are the cross-section at mid-length (x = l/2); each \
                 stands for a line of material along the tube axis x, and the tube is this section \
                 extruded over its length",
            ),
        }
    }

    /// t and d of the round tube. A rectangular section reads as the round tube of its
    /// mid-line's length: only the axisymmetric model, which the checks refuse it, asks.
    fn round(&self) -> (Real, Real) {
        match self.section {
            CrossSection::Round {
                thickness_mm,
                mean_diameter_mm,
            } => (thickness_mm, mean_diameter_mm),
            CrossSection::Rectangular(r) => (r.thickness_mm, r.perimeter_at(0.0) / PI),
        }
    }

    fn lattice(&self) -> Lattice {
        Lattice::new(&self.section, self.length_mm, self.layers)
    }

    /// The section a reduced model runs, as the engine holds it: per particle its centre in the
    /// x–z plane and the volume it stands for (see the module's note), mm and mm³.
    /// Axisymmetric: n layers through the wall by round(l/h) along, each the annulus
    /// π(r₁² − r₀²)·dz. Plane strain: the layers of [`Lattice`] in the y–z cross-section (y as
    /// x), each particle's piece times l, ordered around the wall.
    fn section_points(&self) -> Vec<(Vector3<Real>, Real)> {
        let (l, n) = (self.length_mm, self.layers);
        let lattice = self.lattice();
        match self.model {
            Model::Axisymmetric => {
                let (t, d) = self.round();
                let h = t / n as Real;
                let inner = d / 2.0 - t / 2.0;
                (0..lattice.along)
                    .flat_map(|k| {
                        let z = (k as Real + 0.5) * lattice.dz;
                        (0..n).map(move |j| {
                            let (r0, r1) = (inner + j as Real * h, inner + (j + 1) as Real * h);
                            let vol = PI * (r1 * r1 - r0 * r0) * lattice.dz;
                            (Vector3::new(0.5 * (r0 + r1), 0.0, z), vol)
                        })
                    })
                    .collect()
            }
            Model::PlaneStrain | Model::ThreeD => {
                let mut points: Vec<(Real, Vector3<Real>, Real)> = lattice
                    .rings
                    .iter()
                    .flat_map(|ring| {
                        let lattice = &lattice;
                        (0..ring.1).map(move |i| {
                            let th = (i as Real + 0.5) * 2.0 * PI / ring.1 as Real;
                            let (u, v) = lattice.at(ring, i);
                            (th, Vector3::new(u, 0.0, v), ring.2 / lattice.dz * l)
                        })
                    })
                    .collect();
                // Around the ring, then out through the wall: a run of particles is an arc,
                // and the scatter's patch over it small.
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
                points.into_iter().map(|(_, x, vol)| (x, vol)).collect()
            }
        }
    }
}

/// The particle lattice of a tube's wall: `n` layers through the thickness at spacing h = t/n,
/// round(l/h) along. A round tube's layer at mid-radius r holds round(2πr/h) particles around,
/// each its exact annular sector, so the volumes add up to π d t l; a rectangular tube's layer
/// at offset e from the mid-line holds round(P(e)/h) spread evenly along it, each h·P(e)/count
/// times dz ([`Rectangle`]), so they add up to t·P(0)·l. Every layer holds at least 8.
struct Lattice {
    section: CrossSection,
    /// Per layer: mid-radius (round) or offset from the mid-line (rectangular), mm; particles
    /// around; volume of each, mm³.
    rings: Vec<(Real, usize, Real)>,
    along: usize,
    dz: Real,
}

impl Lattice {
    fn new(section: &CrossSection, l: Real, n: u32) -> Lattice {
        let t = section.thickness_mm();
        let h = t / n as Real;
        let along = layers_along(l, h) as usize;
        let dz = l / along as Real;
        let rings = match *section {
            CrossSection::Round {
                mean_diameter_mm: d,
                ..
            } => {
                let inner = d / 2.0 - t / 2.0;
                (0..n)
                    .map(|j| {
                        let (r0, r1) = (inner + j as Real * h, inner + (j + 1) as Real * h);
                        let r = 0.5 * (r0 + r1);
                        let count = around(r, h) as usize;
                        (
                            r,
                            count,
                            0.5 * (r1 * r1 - r0 * r0) * (2.0 * PI / count as Real) * dz,
                        )
                    })
                    .collect()
            }
            CrossSection::Rectangular(rect) => (0..n)
                .map(|j| {
                    let e = offset(t, h, j);
                    let length = rect.perimeter_at(e);
                    let count = around_length(length, h) as usize;
                    (e, count, h * length / count as Real * dz)
                })
                .collect(),
        };
        Lattice {
            section: *section,
            rings,
            along,
            dz,
        }
    }

    /// Particle `i` of a layer in the cross-section's own axes (u, v).
    fn at(&self, &(place, count, _): &(Real, usize, Real), i: usize) -> (Real, Real) {
        match self.section {
            CrossSection::Round { .. } => {
                let th = (i as Real + 0.5) * 2.0 * PI / count as Real;
                (place * th.cos(), place * th.sin())
            }
            CrossSection::Rectangular(rect) => {
                let step = rect.perimeter_at(place) / count as Real;
                rect.point_at(place, (i as Real + 0.5) * step)
            }
        }
    }

    /// Each particle's centre and volume, axial position outermost, then layer, then around.
    fn points(&self, mode: LoadingMode) -> impl Iterator<Item = (Vector3<Real>, Real)> + '_ {
        (0..self.along).flat_map(move |k| {
            let s = (k as Real + 0.5) * self.dz;
            self.rings.iter().flat_map(move |ring| {
                (0..ring.1).map(move |i| {
                    let (c, sn) = self.at(ring, i);
                    let x = match mode {
                        LoadingMode::Axial => Vector3::new(c, sn, s),
                        LoadingMode::Lateral => Vector3::new(s, c, sn),
                    };
                    (x, ring.2)
                })
            })
        })
    }
}

/// The offset from the mid-line of layer `j` through a wall t thick at spacing h, mm.
fn offset(t: Real, h: Real, j: u32) -> Real {
    -0.5 * t + (j as Real + 0.5) * h
}

/// Particles along a curve of this length at spacing h (at least 8).
fn around_length(length: f64, h: f64) -> u64 {
    ((length / h).round() as u64).max(8)
}

/// Particles around a ring of radius r at spacing h (at least 8).
fn around(r: f64, h: f64) -> u64 {
    ((2.0 * PI * r / h).round() as u64).max(8)
}

/// Particle layers along a length at spacing h (at least 1).
fn layers_along(length: f64, h: f64) -> u64 {
    ((length / h).round() as u64).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::model::case::{Case, Limits};

    #[test]
    fn lattice_volumes_add_up_to_the_wall() {
        let (t, d, l) = (3.2, 22.2, 76.2);
        for mode in ["axial", "lateral"] {
            let text = format!(r#"{{"loading": {{"mode": "{mode}"}}}}"#);
            let case = Case::from_json(&text, &Limits::default()).unwrap();
            let (mut vol, mut count) = (0.0, 0);
            case.geometry()
                .each_point(|_, v| (vol, count) = (vol + v, count + 1));
            let exact = PI * d * t * l;
            assert!((vol / exact - 1.0).abs() < 1e-12, "{vol} vs {exact}");
            assert_eq!(count, case.particle_count());
            assert_eq!(case.geometry().count_f64(), count as f64);
        }
    }

    /// A rectangular tube 40 × 30, t 2, corner r 3, l 50 at n = 3, in 3D (axial and lateral)
    /// and in plane strain.
    fn box_case(mode: &str, model: &str) -> Case {
        let text = format!(
            r#"{{"tube": {{"section": "rectangular", "side_a_mm": 40, "side_b_mm": 30,
                          "thickness_mm": 2, "corner_radius_mm": 3, "length_mm": 50}},
                "loading": {{"mode": "{mode}", "crush_distance_mm": 10}},
                "discretization": {{"model": "{model}", "particles_through_thickness": 3}}}}"#
        );
        Case::from_json(&text, &Limits::default()).unwrap()
    }

    /// The wall's area is t times the mid-line's length, 2(a − 2r) + 2(b − 2r) + 2πr, exactly
    /// (each layer's band h · P(e) sums to t · P(0) since the offsets e average to 0); the
    /// particles' volumes add up to it times l, their count is the one the checks price, and
    /// every particle lies in the wall.
    #[test]
    fn a_rectangular_tubes_volumes_add_up_to_its_wall_and_its_count_is_exact() {
        let (t, a, b, r, l) = (2.0, 40.0, 30.0, 3.0, 50.0);
        let area = t * (2.0 * (a - 2.0 * r) + 2.0 * (b - 2.0 * r) + 2.0 * PI * r);
        for (mode, model) in [
            ("axial", "3d"),
            ("lateral", "3d"),
            ("lateral", "plane_strain"),
        ] {
            let case = box_case(mode, model);
            let geometry = case.geometry();
            let CrossSection::Rectangular(rect) = geometry.section else {
                panic!("a rectangular case has a rectangular section")
            };
            assert!((geometry.section.area_mm2() / area - 1.0).abs() < 1e-12);
            let (mut vol, mut count) = (0.0, 0u64);
            let mut outside = 0;
            geometry.each_point(|x, v| {
                (vol, count) = (vol + v, count + 1);
                // The cross-section's (u, v): (x, y) axial, (y, z) lateral, (x, z) in the
                // plane-strain section.
                let (u, w) = match (mode, model) {
                    ("axial", _) => (x.x, x.y),
                    (_, "3d") => (x.y, x.z),
                    _ => (x.x, x.z),
                };
                let beyond = rect.beyond_outer(u, w);
                if !(-t - 1e-9..=1e-9).contains(&beyond) {
                    outside += 1;
                }
            });
            let exact = area * l;
            assert!(
                (vol / exact - 1.0).abs() < 1e-12,
                "{mode} {model}: {vol} vs {exact}"
            );
            assert_eq!(outside, 0, "{mode} {model}: particles outside the wall");
            assert_eq!(count, case.particle_count(), "{mode} {model}");
            assert_eq!(geometry.count_f64(), count as f64, "{mode} {model}");
            // Per layer round(P(e)/h) around; 3D: round(l/h) layers along.
            let h = t / 3.0;
            let around: u64 = (0..3)
                .map(|j| (rect.perimeter_at(-t / 2.0 + (j as f64 + 0.5) * h) / h).round() as u64)
                .sum();
            let along = if model == "3d" {
                (l / h).round() as u64
            } else {
                1
            };
            assert_eq!(count, around * along, "{mode} {model}");
        }
    }

    /// A square tube's plates start on its ends (axial) or its outer faces (lateral), and the
    /// lateral bore is b − t.
    #[test]
    fn a_rectangular_tubes_plates_start_on_it() {
        let axial = box_case("axial", "3d");
        assert_eq!(axial.geometry().plates_z(), (50.0, 0.0));
        let lateral = box_case("lateral", "3d");
        assert_eq!(lateral.geometry().plates_z(), (16.0, -16.0));
        assert_eq!(lateral.geometry().section.bore_mm(), 28.0);
    }
}
