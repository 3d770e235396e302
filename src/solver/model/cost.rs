//! What a case costs — its particles and its explicit steps — and the check of both against
//! the caller's [`Limits`], each over-limit cost naming every field that drives it, the one
//! that drives it most first, with its value and the cost it would have at its default.

use super::checker::Checker;
use super::geometry::{Geometry, Outline};
use super::limits::{Limits, PARTICLE_ID_LIMIT};
use super::spec::{run_wave_speed_m_s, CaseSpec};
use super::step_policy::cfl_of;

/// Explicit steps at the initial time step, Δt = α · cell / (c + v), in floating point; at
/// least one per history row. The plate takes (crush + ramp) / v to crush: over the start
/// ramp its speed rises linearly from 0, so the ramp's travel takes twice as long as at full
/// speed.
fn steps_f64(spec: &CaseSpec, crush_mm: f64) -> f64 {
    let d = &spec.discretization;
    let cell =
        spec.tube.thickness_mm / d.particles_through_thickness as f64 * d.cell_to_particle_ratio;
    let speed = spec.loading.plate_speed_m_s;
    let dt_ms = cfl_of(spec) * cell / (run_wave_speed_m_s(spec) + speed);
    // A ramp the checks refuse (negative, past the crush, not a number) is held to [0, crush]
    // here: its own error names it.
    let ramp = spec
        .loading
        .ramp_or_default_mm(crush_mm)
        .min(crush_mm)
        .max(0.0);
    let steps = (crush_mm + ramp) / speed / dt_ms;
    // At least one: a crush of 5e-324 mm underflows to no steps at all; and 0 / 0 (the same
    // underflow over a Δt of 0) is too many, not one (both found by tests/solver/case_fuzz.rs).
    if steps.is_nan() {
        f64::INFINITY
    } else {
        // The run ends each history interval on a step of its own.
        steps.ceil().max(spec.output.history_points as f64).max(1.0)
    }
}

/// Fields that set the step count: the duration crush / v over Δt = α · k · t / n / (c + v),
/// with the wave speed c from E, ν and ρ.
pub(super) const STEP_FIELDS: &[&str] = &[
    "loading.plate_speed_m_s",
    "loading.crush_distance_mm",
    "discretization.cfl",
    "discretization.cell_to_particle_ratio",
    "discretization.particles_through_thickness",
    "tube.thickness_mm",
    "material.youngs_modulus_mpa",
    "material.poisson_ratio",
    "material.density_kg_m3",
];

/// A count for a message: whole below a billion, else in scientific notation.
fn count(x: f64) -> String {
    if !x.is_finite() {
        "more than 1.8e308".into()
    } else if x < 1e9 {
        format!("{x:.0}")
    } else {
        format!("{x:.2e}")
    }
}

/// A cost of a case and its crush distance, mm.
type CostOf = dyn Fn(&CaseSpec, f64) -> f64;

/// The case with one field at its default (the crush distance: the loading mode's), and the
/// crush distance it then has; none for a field without a default (a rectangle's sides).
fn with_default(spec: &CaseSpec, crush: f64, field: &str) -> Option<(CaseSpec, f64)> {
    let d = CaseSpec::default();
    let mut s = spec.clone();
    let mut crush = crush;
    match field {
        "tube.thickness_mm" => s.tube.thickness_mm = d.tube.thickness_mm,
        "tube.mean_diameter_mm" => s.tube.mean_diameter_mm = d.tube.mean_diameter_mm,
        "tube.length_mm" => s.tube.length_mm = d.tube.length_mm,
        "discretization.particles_through_thickness" => {
            s.discretization.particles_through_thickness =
                d.discretization.particles_through_thickness
        }
        "discretization.cfl" => s.discretization.cfl = d.discretization.cfl,
        "discretization.cell_to_particle_ratio" => {
            s.discretization.cell_to_particle_ratio = d.discretization.cell_to_particle_ratio
        }
        "loading.plate_speed_m_s" => s.loading.plate_speed_m_s = d.loading.plate_speed_m_s,
        "loading.crush_distance_mm" => {
            s.loading.crush_distance_mm = None;
            crush = s.loading.crush_distance_or_default();
        }
        "material.youngs_modulus_mpa" => {
            s.material.youngs_modulus_mpa = d.material.youngs_modulus_mpa
        }
        "material.poisson_ratio" => s.material.poisson_ratio = d.material.poisson_ratio,
        "material.density_kg_m3" => s.material.density_kg_m3 = d.material.density_kg_m3,
        _ => return None,
    }
    Some((s, crush))
}

/// A field's value as the case gives it, with its unit: "0.0032 mm".
fn value(spec: &serde_json::Value, field: &str) -> String {
    let v = field.split('.').fold(spec, |v, key| &v[key]);
    let unit = [
        ("_mm", " mm"),
        ("_m_s", " m/s"),
        ("_mpa", " MPa"),
        ("_kg_m3", " kg/m³"),
    ]
    .iter()
    .find(|(suffix, _)| field.ends_with(suffix))
    .map_or("", |(_, unit)| unit);
    format!("{v}{unit}")
}

impl Checker {
    /// An over-limit cost: the field that drives it most named first — the one whose default
    /// would lower it most, with its value and the cost at its default — then each other field
    /// that sets it, briefly. Where no field lowers it at its default (a default case over
    /// tight limits), every field carries the whole reason.
    fn fail_driven(
        &mut self,
        spec: &CaseSpec,
        crush: f64,
        fields: &[&str],
        cost: &CostOf,
        what: &str,
        over: &str,
    ) {
        let now = cost(spec, crush);
        // A cost infinite both ways is none the less at the default: its NaN gain is no lead.
        let driver = fields
            .iter()
            .filter_map(|&f| {
                let (s, crush) = with_default(spec, crush, f)?;
                let at_default = cost(&s, crush);
                Some((f, now / at_default, at_default, crush))
            })
            .filter(|&(_, gain, _, _)| gain > 1.01)
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((lead, _, at_default, default_crush)) = driver else {
            self.fail_all(fields, &format!("gives {} {what}{over}", count(now)));
            return;
        };
        let default = match lead {
            "loading.crush_distance_mm" => format!("{default_crush} mm"),
            _ => value(
                &serde_json::to_value(CaseSpec::default()).unwrap_or_default(),
                lead,
            ),
        };
        self.fail(
            lead,
            &format!(
                "{} gives {} {what}{over}; it drives them most: at its default, {default}, \
                 they would be {}",
                value(&serde_json::to_value(spec).unwrap_or_default(), lead),
                count(now),
                count(at_default)
            ),
        );
        for f in fields.iter().filter(|&&f| f != lead) {
            self.fail(
                f,
                &format!("also sets the {what} over this runner's limit (less than {lead})"),
            );
        }
    }

    /// Particles and steps of a case whose fields each passed, or the fields that drive
    /// whichever cost is over its limit, each named with the estimate.
    pub(super) fn costs(
        &mut self,
        spec: &CaseSpec,
        geometry: &Geometry,
        crush: f64,
        limits: &Limits,
    ) -> (Option<u64>, Option<u64>) {
        let max_particles = limits.max_particles.min(PARTICLE_ID_LIMIT);
        let (particle_fields, grows) = geometry.section.particle_fields();
        let particles = geometry.count_f64();
        let particles = if particles.is_finite() && particles <= max_particles as f64 {
            Some(geometry.count())
        } else {
            self.fail_driven(
                spec,
                crush,
                particle_fields,
                &|s, _| Geometry::of(s).count_f64(),
                "particles",
                &format!(
                    ", more than this runner's limit of {max_particles} (the count grows as \
                     {grows})"
                ),
            );
            None
        };
        let steps = steps_f64(spec, crush);
        let steps = if steps.is_finite() && steps <= limits.max_steps as f64 {
            Some(steps as u64)
        } else {
            self.fail_driven(
                spec,
                crush,
                STEP_FIELDS,
                &steps_f64,
                "time steps",
                &format!(
                    ", more than this runner's limit of {} (steps = (crush distance + start \
                     ramp) / plate speed / Δt, Δt = cfl · cell / (wave speed + plate speed), \
                     cell = k · thickness / n)",
                    limits.max_steps
                ),
            );
            None
        };
        if let (Some(p), Some(s)) = (particles, steps) {
            let work = p as f64 * s as f64;
            if work > limits.max_particle_steps as f64 {
                let mut fields: Vec<&str> = particle_fields.to_vec();
                fields.extend(STEP_FIELDS.iter().filter(|f| !particle_fields.contains(f)));
                self.fail_driven(
                    spec,
                    crush,
                    &fields,
                    &|s, crush| Geometry::of(s).count_f64() * steps_f64(s, crush),
                    "particle-steps",
                    &format!(
                        " ({p} particles × {s} time steps), more than this runner's limit of {}",
                        limits.max_particle_steps
                    ),
                );
            }
        }
        (particles, steps)
    }
}
