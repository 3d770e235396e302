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

use super::case::{CaseSpec, LoadingMode, Model};
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
}

impl CrossSection {
    /// The wall thickness t, mm.
    pub fn thickness_mm(&self) -> Real {
        match *self {
            CrossSection::Round { thickness_mm, .. } => thickness_mm,
        }
    }

    /// The size across the section at the wall's mid-surface (a round tube's mean diameter d),
    /// mm: the scale a sideways drift of the tube is measured against.
    pub fn width_mm(&self) -> Real {
        match *self {
            CrossSection::Round {
                mean_diameter_mm, ..
            } => mean_diameter_mm,
        }
    }

    /// From the centre to the undeformed outer surface, mm: (d + t)/2 for a round tube.
    pub fn outer_mm(&self) -> Real {
        match *self {
            CrossSection::Round {
                thickness_mm: t,
                mean_diameter_mm: d,
            } => (d + t) / 2.0,
        }
    }

    /// The wall-line metric, around: where on the wall a point at (dx, dy) from the section's
    /// centre lies, as an angle in (−π, π] (its polar angle, for a round tube).
    #[inline]
    pub fn angle(&self, dx: Real, dy: Real) -> Real {
        match self {
            CrossSection::Round { .. } => dy.atan2(dx),
        }
    }

    /// The wall-line metric, out: how far from the section's centre a point at (dx, dy) lies,
    /// measured along the wall's outward normal (its radius, for a round tube), mm.
    #[inline]
    pub fn reach(&self, dx: Real, dy: Real) -> Real {
        match self {
            CrossSection::Round { .. } => dx.hypot(dy),
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
            section: CrossSection::Round {
                thickness_mm: spec.tube.thickness_mm,
                mean_diameter_mm: spec.tube.mean_diameter_mm,
            },
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
        let (t, d) = self.round();
        let n = self.layers as u64;
        let h = t / n as f64;
        let inner = d / 2.0 - t / 2.0;
        let axial = layers_along(self.length_mm, h);
        let around_all = || {
            (0..n)
                .map(|j| around(inner + (j as f64 + 0.5) * h, h))
                .sum::<u64>()
        };
        match self.model {
            Model::ThreeD => around_all() * axial,
            // The (r, z) section: n layers by the layers along.
            Model::Axisymmetric => n * axial,
            // The cross-section: the rings of one layer along.
            Model::PlaneStrain => around_all(),
        }
    }

    /// The same count in floating point, for any geometry whose fields are finite and positive:
    /// it cannot wrap or saturate (it may be infinite). Exact below 2⁵³, as every term is an
    /// integer.
    pub fn count_f64(&self) -> f64 {
        let (t, d) = self.round();
        let n = self.layers as f64;
        let h = t / n;
        let inner = d / 2.0 - t / 2.0;
        let axial = (self.length_mm / h).round().max(1.0);
        let around_all = || -> f64 {
            (0..self.layers)
                .map(|j| {
                    let r = inner + (j as f64 + 0.5) * h;
                    (2.0 * PI * r / h).round().max(8.0)
                })
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
        let outer = self.section.outer_mm();
        match self.mode {
            LoadingMode::Axial => (self.length_mm, 0.0),
            LoadingMode::Lateral => (outer, -outer),
        }
    }

    /// The box the particles must stay in, mm: three cells of `cell_mm` beyond the plates, and
    /// the tube's outer radius plus its length around it (any fold or tip-over stays inside).
    pub fn domain(&self, cell_mm: Real) -> [[Real; 3]; 2] {
        let (outer, l) = (self.section.outer_mm(), self.length_mm);
        let reach = outer + l;
        let margin = 3.0 * cell_mm;
        match (self.model, self.mode) {
            (Model::ThreeD, LoadingMode::Axial) => {
                [[-reach, -reach, -margin], [reach, reach, l + margin]]
            }
            (Model::ThreeD, LoadingMode::Lateral) => [
                [-reach, -reach, -outer - margin],
                [l + reach, reach, outer + margin],
            ],
            // A particle reaching the axis would divide by r = 0 in its hoop strain rate.
            (_, LoadingMode::Axial) => [[0.0, 0.0, -margin], [reach, 0.0, l + margin]],
            (_, LoadingMode::Lateral) => {
                [[-reach, 0.0, -outer - margin], [reach, 0.0, outer + margin]]
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

    /// t and d of the round tube.
    fn round(&self) -> (Real, Real) {
        match self.section {
            CrossSection::Round {
                thickness_mm,
                mean_diameter_mm,
            } => (thickness_mm, mean_diameter_mm),
        }
    }

    fn lattice(&self) -> Lattice {
        let (t, d) = self.round();
        Lattice::new(t, d, self.length_mm, self.layers)
    }

    /// The section a reduced model runs, as the engine holds it: per particle its centre in the
    /// x–z plane and the volume it stands for (see the module's note), mm and mm³.
    /// Axisymmetric: n layers through the wall by round(l/h) along, each the annulus
    /// π(r₁² − r₀²)·dz. Plane strain: the rings of [`Lattice`] in the y–z cross-section (y as
    /// x), each sector times l, ordered by angle.
    fn section_points(&self) -> Vec<(Vector3<Real>, Real)> {
        let (t, d) = self.round();
        let (l, n) = (self.length_mm, self.layers);
        let lattice = Lattice::new(t, d, l, n);
        let h = t / n as Real;
        let inner = d / 2.0 - t / 2.0;
        match self.model {
            Model::Axisymmetric => (0..lattice.along)
                .flat_map(|k| {
                    let z = (k as Real + 0.5) * lattice.dz;
                    (0..n).map(move |j| {
                        let (r0, r1) = (inner + j as Real * h, inner + (j + 1) as Real * h);
                        let vol = PI * (r1 * r1 - r0 * r0) * lattice.dz;
                        (Vector3::new(0.5 * (r0 + r1), 0.0, z), vol)
                    })
                })
                .collect(),
            Model::PlaneStrain | Model::ThreeD => {
                let mut points: Vec<(Real, Vector3<Real>, Real)> = lattice
                    .rings
                    .iter()
                    .flat_map(|&(r, count, vol)| {
                        (0..count).map(move |i| {
                            let th = (i as Real + 0.5) * 2.0 * PI / count as Real;
                            let x = Vector3::new(r * th.cos(), 0.0, r * th.sin());
                            (th, x, vol / lattice.dz * l)
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

/// The particle lattice of a round tube's wall: `n` layers through the thickness at spacing
/// h = t/n; each layer at mid-radius r holds round(2πr/h) particles around and round(l/h)
/// along. Each particle's volume is its exact annular sector, so the volumes add up to π d t l.
struct Lattice {
    /// Per layer: mid-radius (mm), particles around, volume of each (mm³).
    rings: Vec<(Real, usize, Real)>,
    along: usize,
    dz: Real,
}

impl Lattice {
    fn new(t: Real, d: Real, l: Real, n: u32) -> Lattice {
        let h = t / n as Real;
        let inner = d / 2.0 - t / 2.0;
        let along = layers_along(l, h) as usize;
        let dz = l / along as Real;
        let rings = (0..n)
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
            .collect();
        Lattice { rings, along, dz }
    }

    /// Each particle's centre and volume, axial position outermost, then angle, then radius.
    fn points(&self, mode: LoadingMode) -> impl Iterator<Item = (Vector3<Real>, Real)> + '_ {
        (0..self.along).flat_map(move |k| {
            let s = (k as Real + 0.5) * self.dz;
            self.rings.iter().flat_map(move |&(r, count, vol)| {
                (0..count).map(move |i| {
                    let th = (i as Real + 0.5) * 2.0 * PI / count as Real;
                    let (c, sn) = (r * th.cos(), r * th.sin());
                    let x = match mode {
                        LoadingMode::Axial => Vector3::new(c, sn, s),
                        LoadingMode::Lateral => Vector3::new(s, c, sn),
                    };
                    (x, vol)
                })
            })
        })
    }
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
}
