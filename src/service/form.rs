//! The crush-case form as data (`GET /v1/case/fields`): every field of a case with its label,
//! unit, default (read off [`CaseSpec::default`], so it cannot drift) and the bounds that
//! `Case::parse` enforces on it alone. The web page builds its form from this and checks the
//! bounds in the browser; the checks that tie fields together (wall thinner than half the
//! diameter, crush shorter than the tube, plate slower than half the wave speed, the particle
//! limit) it leaves to the server, which it asks as the user types (`POST /v1/estimate`).
//! A test below holds every bound here to what `Case::parse` accepts and refuses.

use crate::solver::model::material::preset::Preset;
use crate::solver::CaseSpec;
use serde::Serialize;
use serde_json::Value;
use std::collections::BTreeMap;

/// What kind of input a field takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Number,
    Integer,
    Choice,
    Boolean,
    Text,
    /// A list of [x, y] pairs (a hardening curve), typed as "x y" pairs separated by commas.
    Curve,
}

/// One field of the form.
#[derive(Debug, Clone, Serialize)]
pub struct Field {
    /// Dotted path in the case JSON.
    pub field: &'static str,
    pub label: &'static str,
    /// Unit, empty when the field has none.
    pub unit: &'static str,
    pub kind: Kind,
    pub default: Value,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The bound itself is refused (`> min` rather than `>= min`).
    pub min_exclusive: bool,
    pub max_exclusive: bool,
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    pub choices: &'static [&'static str],
    /// May be left empty (the server then picks, as `help` says).
    pub optional: bool,
    pub help: &'static str,
    /// For a material field: its value in each preset that sets it (preset name → value), so
    /// that the form can show what a preset fills in.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub presets: BTreeMap<&'static str, Value>,
}

struct Spec {
    field: &'static str,
    label: &'static str,
    unit: &'static str,
    kind: Kind,
    /// (min, exclusive)
    min: Option<(f64, bool)>,
    max: Option<(f64, bool)>,
    choices: &'static [&'static str],
    help: &'static str,
}

const fn num(
    field: &'static str,
    label: &'static str,
    unit: &'static str,
    min: Option<(f64, bool)>,
    max: Option<(f64, bool)>,
    help: &'static str,
) -> Spec {
    Spec {
        field,
        label,
        unit,
        kind: Kind::Number,
        min,
        max,
        choices: &[],
        help,
    }
}

const fn other(
    field: &'static str,
    label: &'static str,
    kind: Kind,
    choices: &'static [&'static str],
    help: &'static str,
) -> Spec {
    Spec {
        field,
        label,
        unit: "",
        kind,
        min: None,
        max: None,
        choices,
        help,
    }
}

const POSITIVE: Option<(f64, bool)> = Some((0.0, true));

const SPECS: &[Spec] = &[
    other("label", "Label", Kind::Text, &[], "Free text, at most 200 characters; kept with the job."),
    num("tube.thickness_mm", "Wall thickness t", "mm", POSITIVE, None, "Less than half the mean diameter."),
    num("tube.mean_diameter_mm", "Mean diameter d", "mm", POSITIVE, None, "Measured at the wall's mid-surface."),
    num("tube.length_mm", "Length l", "mm", POSITIVE, None, "Along the tube axis."),
    other("material.preset", "Material preset", Kind::Choice, &["pvc", "aa6060_t5", "aa6061_t6", "mild_steel"], "Fills every material field left as it is; empty: the paper's PVC. Sources: docs/materials.md."),
    other("material.model", "Material model", Kind::Choice, &["j2", "elastic"], "j2: von Mises plasticity, perfectly plastic unless a hardening or rate law is set; elastic never yields."),
    num("material.youngs_modulus_mpa", "Young's modulus E", "MPa", POSITIVE, None, ""),
    num("material.poisson_ratio", "Poisson's ratio ν", "", Some((-0.99, false)), Some((0.4999, false)), ""),
    num("material.yield_stress_mpa", "Yield stress σy", "MPa", POSITIVE, None, "The flow stress at zero plastic strain and a static rate; with a curve, its first stress."),
    num("material.density_kg_m3", "Density ρ", "kg/m³", POSITIVE, None, ""),
    other("material.hardening", "Hardening", Kind::Choice, &["none", "table", "swift", "ludwik"], "Empty: the preset's (none for PVC). table: the curve below; swift: K (ε₀ + εp)ⁿ from σy; ludwik: σy + K εpⁿ."),
    other("material.hardening_curve", "Hardening curve", Kind::Curve, &[], "True stress against equivalent plastic strain, \"εp σ\" pairs separated by commas, from εp = 0 (at σy); strains increasing, stresses not decreasing; at most 100 points."),
    other("material.hardening_extrapolation", "Past the curve's end", Kind::Choice, &["flat", "last_slope"], "Empty: flat (the last stress)."),
    num("material.hardening_k_mpa", "Hardening K", "MPa", POSITIVE, None, "Swift or Ludwik."),
    num("material.hardening_n", "Hardening exponent n", "", POSITIVE, Some((1.0, false)), "Swift or Ludwik."),
    other("material.rate", "Strain-rate law", Kind::Choice, &["none", "cowper_symonds", "johnson_cook"], "Empty: the preset's (none for PVC). cowper_symonds: σ × (1 + (ε̇p/D)^(1/q)); johnson_cook: σ × (1 + C ln(ε̇p/ε̇₀)), 1 below ε̇₀."),
    num("material.cowper_symonds_d_per_s", "Cowper–Symonds D", "1/s", POSITIVE, None, ""),
    num("material.cowper_symonds_q", "Cowper–Symonds q", "", Some((1.0, false)), Some((100.0, false)), ""),
    num("material.johnson_cook_c", "Johnson–Cook C", "", Some((0.0, false)), Some((1.0, false)), ""),
    num("material.johnson_cook_reference_rate_per_s", "Johnson–Cook ε̇₀", "1/s", POSITIVE, None, "The reference (quasi-static) rate."),
    other("loading.mode", "Loading", Kind::Choice, &["axial", "lateral"], "Axial: plates normal to the axis. Lateral: the tube lies between the plates."),
    num("loading.plate_speed_m_s", "Plate speed", "m/s", POSITIVE, None, "Below half the material's wave speed."),
    num("loading.crush_distance_mm", "Crush distance", "mm", POSITIVE, None, "Empty: 50 mm axial, 12.5 mm lateral. Less than 95 % of the length (axial) or of the bore (lateral); at least the plate's travel while a stress wave crosses one grid cell."),
    num("loading.ramp_mm", "Start ramp", "mm", Some((0.0, false)), None, "Travel over which the plate comes up to speed (velocity rising linearly in time); 0 starts it at full speed, an impact. Empty: 0.5 mm, or half the crush distance if less. At most the crush distance."),
    num("contact.friction", "Plate friction μ", "", Some((0.0, false)), Some((2.0, false)), "Coulomb friction between tube and plates."),
    Spec { kind: Kind::Integer, ..num("discretization.particles_through_thickness", "Particles through the wall n", "", Some((1.0, false)), Some((64.0, false)), "Spacing h = t / n. At most 16 in 3D (cost about n⁴), 64 in the reduced models (cost about n³).") },
    num("discretization.cell_to_particle_ratio", "Cell size / spacing k", "", Some((1.0, false)), Some((4.0, false)), ""),
    num("discretization.cfl", "CFL number α", "", POSITIVE, Some((1.0, false)), "Δt = α · cell / max(c + |v|)."),
    other("discretization.shape", "Shape functions", Kind::Choice, &["gimp", "linear"], "gimp: uniform GIMP; linear: trilinear hats. Empty (auto): linear for a thin wall (d/t >= 8) in 3D, else gimp; the estimate says which."),
    other("discretization.model", "Model", Kind::Choice, &["3d", "axisymmetric", "plane_strain"], "3d: the whole tube. axisymmetric (axial, no trigger): the (r, z) section, ring folding only, seconds instead of minutes. plane_strain (lateral, no trigger): the cross-section, no end effects."),
    other("discretization.volumetric_averaging", "Volumetric averaging", Kind::Boolean, &[], "One volumetric strain rate per cell, against locking."),
    num("trigger.weak_fraction", "Weak-particle fraction", "", Some((0.0, false)), Some((0.1, false)), "0 disables the trigger."),
    num("trigger.strength_ratio", "Weak-particle strength ratio", "", POSITIVE, Some((1.0, false)), "Yield stress of a weak particle over σy."),
    Spec { kind: Kind::Integer, ..num("trigger.seed", "Trigger seed", "", Some((0.0, false)), None, "Seed of the random choice of weak particles.") },
    Spec { kind: Kind::Integer, ..num("output.history_points", "History points", "", Some((10.0, false)), Some((100000.0, false)), "Rows of the load history, at equal plate travel.") },
    other("output.final_state", "Keep the final state", Kind::Boolean, &[], "Needed for the deformed-tube picture and the VTU file; 16 bytes a particle."),
    Spec { kind: Kind::Integer, ..num("output.frames", "Time-series frames", "", Some((0.0, false)), Some((50.0, false)), "0: none. 2 to 50: particle states for ParaView (series.pvd, series.tar) at equal plate travel, start to end, with stress, velocity and volume; 56 bytes a particle a frame, frames × particles at most 10 million.") },
    other("output.error_bar", "Error bar", Kind::Boolean, &[], "After the run, price the mean load's discretization error with the tube's section at three resolutions (n or 8, 1.5x, 2x). Uniform GIMP and ring or flattening collapses only; costs 2.5x a 3D run at n = 4, 1/7 at n = 8."),
];

/// Every field of the form, in display order.
pub fn fields() -> Vec<Field> {
    let mut defaults = serde_json::to_value(CaseSpec::default()).unwrap_or(Value::Null);
    // A case's JSON leaves `output.frames` out at its default (no series): the form shows it.
    if let Some(output) = defaults
        .pointer_mut("/output")
        .and_then(Value::as_object_mut)
    {
        output.insert("frames".into(), CaseSpec::default().output.frames.into());
    }
    let presets: Vec<(&'static str, Value)> = Preset::ALL
        .iter()
        .map(|p| {
            (
                p.name(),
                serde_json::to_value(p.material()).unwrap_or(Value::Null),
            )
        })
        .collect();
    SPECS
        .iter()
        .map(|s| {
            let pointer = format!("/{}", s.field.replace('.', "/"));
            // Only the fields the server fills in itself (label, crush distance, start ramp,
            // shape functions, the material's preset and the laws a preset may fill) have no
            // default in the serialized case: those are the optional ones.
            let default = defaults.pointer(&pointer).cloned().unwrap_or(Value::Null);
            Field {
                field: s.field,
                label: s.label,
                unit: s.unit,
                kind: s.kind,
                optional: default.is_null(),
                default,
                min: s.min.map(|m| m.0),
                max: s.max.map(|m| m.0),
                min_exclusive: s.min.is_some_and(|m| m.1),
                max_exclusive: s.max.is_some_and(|m| m.1),
                choices: s.choices,
                help: s.help,
                presets: match s.field.strip_prefix("material.") {
                    Some(name) if name != "preset" => presets
                        .iter()
                        .filter_map(|(p, m)| m.get(name).map(|v| (*p, v.clone())))
                        .collect(),
                    _ => BTreeMap::new(),
                },
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{Case, CaseError, Limits};

    /// The default case with `field` set to `value` (a small tube, so that the particle limit
    /// never speaks).
    fn case_with(field: &str, value: Value) -> Result<Case, CaseError> {
        let mut spec = serde_json::to_value(CaseSpec::default()).unwrap();
        let parts: Vec<&str> = field.split('.').collect();
        // The bounds and choices that depend on the model, tried where they apply: n past 3D's
        // 16 on the axisymmetric model, plane strain on a lateral crush.
        let fine_n = value.as_f64().is_some_and(|n| n > 16.0);
        if field == "discretization.particles_through_thickness" && fine_n {
            spec["discretization"]["model"] = "axisymmetric".into();
        }
        if field == "discretization.model" && value == "plane_strain" {
            spec["loading"]["mode"] = "lateral".into();
        }
        // A law's constants, tried with the law that reads them (and its other constants).
        let material = &mut spec["material"];
        let law = match field.strip_prefix("material.") {
            Some("hardening_k_mpa" | "hardening_n") => Some(("hardening", "swift".into())),
            Some("hardening_extrapolation") => Some(("hardening", "table".into())),
            Some("cowper_symonds_d_per_s" | "cowper_symonds_q") => {
                Some(("rate", "cowper_symonds".into()))
            }
            Some("johnson_cook_c" | "johnson_cook_reference_rate_per_s") => {
                Some(("rate", "johnson_cook".into()))
            }
            Some(kind @ ("hardening" | "rate")) => Some((kind, value.clone())),
            _ => None,
        };
        if let Some((kind, name)) = law {
            let constants: &[(&str, Value)] = match name.as_str().unwrap_or("") {
                "table" => &[(
                    "hardening_curve",
                    serde_json::json!([[0.0, 65.5], [0.1, 80.0]]),
                )],
                "swift" | "ludwik" => &[
                    ("hardening_k_mpa", Value::from(200.0)),
                    ("hardening_n", Value::from(0.2)),
                ],
                "cowper_symonds" => &[
                    ("cowper_symonds_d_per_s", Value::from(40.4)),
                    ("cowper_symonds_q", Value::from(5.0)),
                ],
                "johnson_cook" => &[
                    ("johnson_cook_c", Value::from(0.01)),
                    ("johnson_cook_reference_rate_per_s", Value::from(1.0)),
                ],
                _ => &[],
            };
            material[kind] = name;
            for (k, v) in constants {
                material[*k] = v.clone();
            }
        }
        let mut at = &mut spec;
        for p in &parts[..parts.len() - 1] {
            at = at.get_mut(*p).unwrap();
        }
        at[parts[parts.len() - 1]] = value;
        Case::parse(
            serde_json::from_value(spec).map_err(|e| CaseError::Malformed {
                field: None,
                message: e.to_string(),
            })?,
            &Limits::default(),
        )
    }

    fn refused_for(field: &str, value: f64, integer: bool) -> bool {
        let v = if integer {
            Value::from(value as i64)
        } else {
            Value::from(value)
        };
        match case_with(field, v) {
            Ok(_) => false,
            Err(CaseError::Invalid(errors)) => errors.iter().any(|e| e.field == field),
            Err(CaseError::Malformed { .. }) => true,
        }
    }

    #[test]
    fn every_default_is_the_case_default_and_is_accepted() {
        let fields = fields();
        assert_eq!(fields.len(), SPECS.len());
        for f in &fields {
            if f.optional {
                continue;
            }
            assert!(!f.default.is_null(), "{} has no default", f.field);
        }
        assert!(Case::parse(CaseSpec::default(), &Limits::default()).is_ok());
        let optional: Vec<&str> = fields
            .iter()
            .filter(|f| f.optional)
            .map(|f| f.field)
            .collect();
        assert_eq!(
            optional,
            [
                "label",
                "material.preset",
                "material.hardening",
                "material.hardening_curve",
                "material.hardening_extrapolation",
                "material.hardening_k_mpa",
                "material.hardening_n",
                "material.rate",
                "material.cowper_symonds_d_per_s",
                "material.cowper_symonds_q",
                "material.johnson_cook_c",
                "material.johnson_cook_reference_rate_per_s",
                "loading.crush_distance_mm",
                "loading.ramp_mm",
                "discretization.shape"
            ]
        );
    }

    #[test]
    fn the_shape_help_names_the_servers_threshold() {
        let threshold = format!(
            "(d/t >= {})",
            crate::solver::model::case::LINEAR_FROM_D_OVER_T
        );
        let shape = fields()
            .into_iter()
            .find(|f| f.field == "discretization.shape")
            .unwrap();
        assert!(shape.help.contains(&threshold), "{}", shape.help);
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/api/openapi.yaml");
        let contract = std::fs::read_to_string(path).unwrap();
        assert!(
            contract.contains(&threshold),
            "api/openapi.yaml: {threshold}"
        );
    }

    #[test]
    fn every_bound_is_the_one_the_server_enforces() {
        for f in fields() {
            let integer = f.kind == Kind::Integer;
            let step = if integer { 1.0 } else { 1e-6 };
            // (bound, whether the bound itself is refused, a value just outside)
            let bounds = [
                f.min.map(|m| (m, f.min_exclusive, m - step)),
                f.max.map(|m| (m, f.max_exclusive, m + step)),
            ];
            for (bound, exclusive, outside) in bounds.into_iter().flatten() {
                let name = f.field;
                assert_eq!(
                    refused_for(name, bound, integer),
                    exclusive,
                    "{name} at {bound}"
                );
                assert!(refused_for(name, outside, integer), "{name} at {outside}");
            }
        }
    }

    /// `api/openapi.yaml`'s schema of the field at a dotted path.
    fn contract_schema(doc: &serde_yaml_ng::Value, field: &str) -> serde_yaml_ng::Value {
        let mut at = &doc["components"]["schemas"]["Case"];
        for part in field.split('.') {
            at = &at["properties"][part];
        }
        at.clone()
    }

    #[test]
    fn the_contract_carries_every_bound_of_this_table() {
        // One source for both: the schema's bounds, types, choices and defaults are the ones
        // this table serves (and the test above holds to the server).
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/api/openapi.yaml");
        let doc: serde_yaml_ng::Value =
            serde_yaml_ng::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let num = |v: &serde_yaml_ng::Value| v.as_f64();
        for f in fields() {
            let s = contract_schema(&doc, f.field);
            let name = f.field;
            assert!(!s.is_null(), "{name} is not in the contract");
            let kind = match f.kind {
                Kind::Number => "number",
                Kind::Integer => "integer",
                Kind::Choice | Kind::Text => "string",
                Kind::Boolean => "boolean",
                Kind::Curve => "array",
            };
            let types: Vec<&str> = match &s["type"] {
                serde_yaml_ng::Value::Sequence(t) => t.iter().filter_map(|t| t.as_str()).collect(),
                t => t.as_str().into_iter().collect(),
            };
            assert_eq!(types[0], kind, "{name}: type");
            let (min_key, other_min) = match f.min_exclusive {
                true => ("exclusiveMinimum", "minimum"),
                false => ("minimum", "exclusiveMinimum"),
            };
            assert_eq!(num(&s[min_key]), f.min, "{name}: {min_key}");
            assert!(s[other_min].is_null(), "{name}: {other_min}");
            let (max_key, other_max) = match f.max_exclusive {
                true => ("exclusiveMaximum", "maximum"),
                false => ("maximum", "exclusiveMaximum"),
            };
            assert!(s[other_max].is_null(), "{name}: {other_max}");
            match (f.max, name) {
                // u64: the schema's maximum is the type's, which this table leaves open.
                (None, "trigger.seed") => {
                    assert_eq!(s["maximum"].as_u64(), Some(u64::MAX), "{name}")
                }
                (max, _) => assert_eq!(num(&s[max_key]), max, "{name}: {max_key}"),
            }
            let choices: Vec<&str> = s["enum"]
                .as_sequence()
                .map_or(vec![], |e| e.iter().filter_map(|c| c.as_str()).collect());
            assert_eq!(choices, f.choices, "{name}: enum");
            let default: Value = serde_yaml_ng::from_value(s["default"].clone()).unwrap();
            let same = match (default.as_f64(), f.default.as_f64()) {
                (Some(a), Some(b)) => a == b,
                _ => default == f.default,
            };
            assert!(
                same,
                "{name}: default {default} in the contract, {} here",
                f.default
            );
        }
        // Each section and the case itself reject unknown fields, as serde does.
        let case = &doc["components"]["schemas"]["Case"];
        assert_eq!(case["additionalProperties"].as_bool(), Some(false));
        for (section, schema) in case["properties"].as_mapping().unwrap() {
            if schema["type"].as_str() == Some("object") {
                assert_eq!(
                    schema["additionalProperties"].as_bool(),
                    Some(false),
                    "{section:?}"
                );
            }
        }
        assert_eq!(
            contract_schema(&doc, "label")["maxLength"].as_u64(),
            Some(200)
        );
    }

    #[test]
    fn every_choice_is_accepted_and_others_are_not() {
        for f in fields().into_iter().filter(|f| f.kind == Kind::Choice) {
            for c in f.choices {
                assert!(
                    case_with(f.field, Value::from(*c)).is_ok(),
                    "{} = {c}",
                    f.field
                );
            }
            assert!(case_with(f.field, Value::from("nonsense")).is_err());
        }
    }

    #[test]
    fn the_form_has_every_field_of_the_case_and_no_other() {
        // `field_paths` is also what a sweep may name.
        let mut paths = crate::solver::model::case::field_paths();
        let mut form: Vec<String> = SPECS.iter().map(|s| s.field.to_string()).collect();
        paths.sort();
        form.sort();
        assert_eq!(form, paths);
        assert!(paths.contains(&"loading.crush_distance_mm".to_string()));
        assert!(paths.contains(&"label".to_string()));
    }
}
