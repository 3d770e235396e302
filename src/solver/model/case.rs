//! A checked case ([`Case`]): a spec ([`super::spec`]) whose every section passed its checks
//! ([`super::checks`]) and whose cost is within the caller's limits ([`super::cost`]), with its
//! defaults resolved (the crush, the ramp, the shape functions: [`super::shape_policy`]) and its
//! geometry ([`super::geometry`]). The rest of the solver trusts it.

pub use super::geometry::{Circle, CrossSection, Geometry, Outline, Rectangle};
pub use super::limits::{CaseError, FieldError, Limits, PARTICLE_ID_LIMIT};
pub use super::shape_policy::{
    is_thin, may_tip_over, slenderness, ShapeChoice, HOLDING_FRICTION, THIN_WALL_D_OVER_T,
};
pub use super::spec::*;

use super::checker::Checker;
use super::checks;
use super::spec::wave_speed_m_s;

/// A case that has been checked: every number finite and in range, the particle count within
/// the caller's limit. Only [`Case::parse`] makes one.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    spec: CaseSpec,
    geometry: Geometry,
    crush_distance_mm: f64,
    /// Exact, and within the limits `parse` was given.
    particles: u64,
    /// Estimated at the initial time step, within the limits `parse` was given.
    steps: u64,
    ramp_mm: f64,
    shape: ShapeChoice,
}

impl Case {
    /// JSON text → valid case, or every reason it is not.
    pub fn from_json(text: &str, limits: &Limits) -> Result<Case, CaseError> {
        let spec = spec_from_json(text)?;
        Case::parse(spec, limits)
    }

    /// Checks every field, section by section, and collects every failure.
    pub fn parse(spec: CaseSpec, limits: &Limits) -> Result<Case, CaseError> {
        let mut c = Checker::default();
        checks::tube(&mut c, &spec.tube);
        checks::material(&mut c, &spec.material);
        let (crush, ramp) = checks::loading(&mut c, &spec);
        checks::contact(&mut c, &spec.contact);
        checks::discretization(&mut c, &spec);
        checks::trigger(&mut c, &spec.trigger);
        checks::output(&mut c, &spec.output);
        checks::crush_resolved(&mut c, &spec, crush);
        checks::label(&mut c, spec.label.as_deref());
        if !c.errors.is_empty() {
            return Err(CaseError::Invalid(c.errors));
        }
        let geometry = Geometry::of(&spec);
        let (particles, steps) = c.costs(&spec, &geometry, crush, limits);
        if let Some(particles) = particles {
            checks::series_size(&mut c, &spec.output, particles);
        }
        let case = match (particles, steps) {
            (Some(particles), Some(steps)) if c.errors.is_empty() => Case {
                shape: match spec.discretization.shape {
                    Some(kind) => ShapeChoice {
                        kind,
                        default_reason: None,
                    },
                    None => ShapeKind::default_for(
                        &geometry.section,
                        spec.discretization.model,
                        spec.contact.friction,
                    ),
                },
                geometry,
                spec,
                crush_distance_mm: crush,
                particles,
                steps,
                ramp_mm: ramp,
            },
            _ => return Err(CaseError::Invalid(c.errors)),
        };
        if case.spec.output.error_bar {
            case.ladder_within(limits).map_err(|reason| {
                CaseError::Invalid(vec![FieldError {
                    field: "output.error_bar".into(),
                    reason,
                }])
            })?;
        }
        Ok(case)
    }

    /// The error bar's rungs ([`super::ladder`]) with the run itself, held to `limits`: each
    /// rung's steps, and the particle-steps of all of them and the run together. A 3D case is
    /// held to both ladders it may climb (its section's, and its own at n − 2 and n − 1 for a
    /// collapse the section cannot fold), as its mode is known only once it has run.
    fn ladder_within(&self, limits: &Limits) -> Result<(), String> {
        let section = super::ladder::rungs(&self.spec, self.shape());
        let three_d = super::ladder::three_d_rungs(&self.spec, self.shape());
        if let (Err(why), Err(why_3d)) = (&section, &three_d) {
            let also = match self.spec.discretization.model {
                Model::ThreeD if why_3d != why => format!("; {why_3d}"),
                _ => String::new(),
            };
            return Err(format!("cannot be priced for this case: {why}{also}"));
        }
        let ladders = [(section, "section"), (three_d, "3D run")];
        for (rungs, what) in ladders {
            let Ok(rungs) = rungs else { continue };
            let mut work = self.particles as f64 * self.steps as f64;
            for (n, twin) in rungs {
                let Some(twin) = twin else { continue };
                let twin = Case::parse(twin, &Limits::unbounded())
                    .map_err(|e| format!("its {what} at n = {n} cannot be run: {e}"))?;
                if twin.steps > limits.max_steps {
                    return Err(format!(
                        "its {what} at n = {n} takes {} time steps, more than this runner's \
                         limit of {}",
                        twin.steps, limits.max_steps
                    ));
                }
                work += twin.particles as f64 * twin.steps as f64;
            }
            if work > limits.max_particle_steps as f64 {
                return Err(format!(
                    "the run with its error bar's ladder of the {what} comes to {work:.3e} \
                     particle-steps, more than this runner's limit of {}",
                    limits.max_particle_steps
                ));
            }
        }
        Ok(())
    }

    pub fn spec(&self) -> &CaseSpec {
        &self.spec
    }

    /// The tube's geometry: cross-section, lattice, particle count, domain.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// Particle spacing h = t / n, mm.
    pub fn spacing_mm(&self) -> f64 {
        self.geometry.spacing_mm()
    }

    /// Background cell size k · h, mm.
    pub fn cell_mm(&self) -> f64 {
        self.spacing_mm() * self.spec.discretization.cell_to_particle_ratio
    }

    /// The shape functions the case runs with: its own, or the default for its wall.
    pub fn shape(&self) -> ShapeKind {
        self.shape.kind
    }

    /// The CFL number the case runs with: its own, or the default for its wall and shape
    /// functions ([`super::step_policy::default_cfl`]).
    pub fn cfl(&self) -> f64 {
        self.spec
            .discretization
            .cfl
            .unwrap_or_else(|| super::step_policy::default_cfl(&self.geometry, self.shape()).0)
    }

    /// Why the case runs with [`Case::cfl`]: none when the case named it.
    pub fn cfl_default_reason(&self) -> Option<&'static str> {
        match self.spec.discretization.cfl {
            Some(_) => None,
            None => Some(super::step_policy::default_cfl(&self.geometry, self.shape()).1),
        }
    }

    /// [`Case::shape`] with whether, and why, it was chosen for the case.
    pub fn shape_choice(&self) -> &ShapeChoice {
        &self.shape
    }

    /// Crush distance with the mode's default filled in, mm.
    pub fn crush_distance_mm(&self) -> f64 {
        self.crush_distance_mm
    }

    /// Start ramp with its default filled in, mm.
    pub fn ramp_mm(&self) -> f64 {
        self.ramp_mm
    }

    /// Number of tube particles the scene will hold.
    pub fn particle_count(&self) -> u64 {
        self.particles
    }

    /// Explicit steps to the end of the crush at the initial time step (the estimate the
    /// limits were checked against; the run takes more where the material stiffens).
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// Dilatational wave speed of the undeformed material, m/s (= mm/ms).
    pub fn wave_speed_m_s(&self) -> f64 {
        wave_speed_m_s(&self.spec.material)
    }
}

#[cfg(test)]
mod tests;
