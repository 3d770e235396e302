//! The tube's geometry, owned in one place. Its cross-section ([`CrossSection`], which answers
//! every question of [`Outline`]: the wall's shape and thickness, the layers of its lattice, and
//! the wall-line metric the analysis reads a deformed tube with; one file per shape, [`round`],
//! [`rectangle`] and [`hexagon`]) and, with the length, the particles through the wall, the model and the
//! loading direction, the particle lattice ([`Geometry`]): every particle's centre and volume,
//! the one exact particle count, where the plates start and the box the particles must stay in.
//! Everything after the scene reads the geometry from here, never from raw t and d, and asks the
//! section rather than matching its shape. Units: mm, mm³.
//!
//! Frames: axial loading puts the tube axis on z (bottom plate at z = 0); lateral loading puts
//! it on x over 0..l, centred on y = z = 0, with the plates normal to z. The reduced models lay
//! their section in the x–z plane (y is the direction the symmetry removes): axisymmetric, x is
//! the radius r and z the axis, each particle standing for its ring (volume 2π·r·area); plane
//! strain, x and z are the cross-section's y and z, each particle standing for the tube's length
//! (volume area·l).

mod cross_section;
pub mod hexagon;
pub mod outline;
pub mod rectangle;
pub mod round;

pub use cross_section::CrossSection;
pub use hexagon::Hexagon;
pub use outline::Outline;
pub use rectangle::Rectangle;
pub use round::Circle;

use super::spec::{CaseSpec, LoadingMode, Model};
use crate::solver::Real;
use nalgebra::Vector3;
use std::f64::consts::PI;

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
        let h = self.spacing_mm();
        (0..self.layers)
            .map(|j| self.section.around(j, h))
            .sum::<u64>()
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
            (0..self.layers)
                .map(|j| self.section.around_f64(j, h))
                .sum()
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
                let (t, d) = self.section.revolved();
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
/// round(l/h) along; each layer as its cross-section lays it ([`Outline::ring`]: a round
/// tube's at mid-radius r holds round(2πr/h) particles around, each its exact annular sector; a
/// polygon's at offset e from the mid-line holds round(P(e)/h) spread evenly along it), so that
/// the volumes add up to the wall's area times l. Every layer holds at least 8.
struct Lattice {
    section: CrossSection,
    /// Per layer: mid-radius (round) or offset from the mid-line, mm; particles around; volume
    /// of each, mm³.
    rings: Vec<outline::Ring>,
    along: usize,
    dz: Real,
}

impl Lattice {
    fn new(section: &CrossSection, l: Real, n: u32) -> Lattice {
        let t = section.thickness_mm();
        let h = t / n as Real;
        let along = layers_along(l, h) as usize;
        let dz = l / along as Real;
        let rings = (0..n).map(|j| section.ring(j, h, dz)).collect();
        Lattice {
            section: *section,
            rings,
            along,
            dz,
        }
    }

    /// Particle `i` of a layer in the cross-section's own axes (u, v).
    fn at(&self, ring: &outline::Ring, i: usize) -> (Real, Real) {
        self.section.point(ring, i)
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
