//! The crush-case form as data (`GET /v1/case/fields`): every field of a case with its label,
//! unit, default (read off [`CaseSpec::default`]), the bounds that `Case::parse` enforces on it
//! alone, its choices and its help — all read off the case's JSON Schema, which the contract
//! serves too ([`crate::solver::model::schema`]: the titles are the labels, `x-unit` the units,
//! the descriptions the help). The web page builds its form from this and checks the bounds in
//! the browser; the checks that tie fields together (wall thinner than half the diameter,
//! crush shorter than the tube, plate slower than half the wave speed, the particle limit) it
//! leaves to the server, which it asks as the user types (`POST /v1/estimate`). A test below
//! holds every bound to what `Case::parse` accepts and refuses.

use crate::solver::model::material::preset::Preset;
use crate::solver::model::spec::full_case;
use crate::solver::CaseSpec;
use schemars::generate::SchemaSettings;
use schemars::JsonSchema;
use serde::Serialize;
use serde_json::{Map, Value};
use std::collections::BTreeMap;
use std::sync::LazyLock;

/// What kind of input a field takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[schemars(transform = crate::solver::model::schema::choices)]
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
#[derive(Debug, Clone, Serialize, JsonSchema)]
#[schemars(rename = "CaseField")]
pub struct Field {
    /// Dotted path in the case JSON.
    pub field: String,
    pub label: String,
    /// Unit, empty when the field has none.
    pub unit: String,
    pub kind: Kind,
    /// The server's default; null when the server picks (optional fields).
    pub default: Value,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The bound itself is refused (`> min` rather than `>= min`).
    pub min_exclusive: bool,
    pub max_exclusive: bool,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub choices: Vec<String>,
    /// May be left empty (the server then picks, as `help` says).
    pub optional: bool,
    pub help: String,
    /// For a material field: its value in each preset that sets it (preset name → value), so
    /// that the form can show what a preset fills in.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub presets: BTreeMap<&'static str, Value>,
}

/// Every field of the form, in the order the case's types declare them.
pub fn fields() -> Vec<Field> {
    static FIELDS: LazyLock<Vec<Field>> = LazyLock::new(derive_fields);
    FIELDS.clone()
}

/// The case's schemas by name, as the server reads a case.
fn case_schemas() -> Map<String, Value> {
    let mut generator = SchemaSettings::draft2020_12()
        .with(|s| s.definitions_path = "/$defs".into())
        .into_generator();
    generator.subschema_for::<CaseSpec>();
    generator.take_definitions(true)
}

/// A property's schema with `$ref`s followed and a nullable `anyOf [X, null]` read as X.
fn resolved<'a>(schema: &'a Value, schemas: &'a Map<String, Value>) -> &'a Value {
    if let Some(name) = schema
        .get("$ref")
        .and_then(Value::as_str)
        .and_then(|r| r.rsplit('/').next())
    {
        return schemas.get(name).map_or(schema, |s| resolved(s, schemas));
    }
    if let Some(Value::Array(any)) = schema.get("anyOf") {
        if let Some(s) = any.iter().find(|s| s.get("type") != Some(&"null".into())) {
            return resolved(s, schemas);
        }
    }
    schema
}

/// The schema's own type, `null` aside.
fn type_of(schema: &Value) -> &str {
    match schema.get("type") {
        Some(Value::String(t)) => t,
        Some(Value::Array(t)) => t
            .iter()
            .filter_map(Value::as_str)
            .find(|t| *t != "null")
            .unwrap_or(""),
        _ => "",
    }
}

fn text(schema: &Value, key: &str) -> String {
    schema
        .get(key)
        .and_then(Value::as_str)
        .unwrap_or("")
        .to_string()
}

/// The case's fields in declaration order: (section or `None` for a top-level field, name).
fn ordered_paths() -> Vec<(Option<String>, String)> {
    // A YAML mapping keeps its keys in the order the serializer wrote them, which is the
    // types' declaration order (a JSON object here is sorted).
    let Ok(serde_yaml_ng::Value::Mapping(sections)) = serde_yaml_ng::to_value(full_case()) else {
        return Vec::new();
    };
    let mut paths = Vec::new();
    for (section, value) in sections {
        let section = section.as_str().unwrap_or_default().to_string();
        match value {
            serde_yaml_ng::Value::Mapping(fields) => paths.extend(
                fields
                    .keys()
                    .filter_map(|k| k.as_str())
                    .map(|k| (Some(section.clone()), k.to_string())),
            ),
            _ => paths.push((None, section)),
        }
    }
    paths
}

fn derive_fields() -> Vec<Field> {
    let schemas = case_schemas();
    let case = schemas.get("Case").cloned().unwrap_or(Value::Null);
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
    let mut out = Vec::new();
    for (section, name) in ordered_paths() {
        let (field, raw) = match &section {
            Some(section) => {
                let section_schema = resolved(&case["properties"][section], &schemas);
                (
                    format!("{section}.{name}"),
                    section_schema["properties"][&name].clone(),
                )
            }
            None => (name.clone(), case["properties"][&name].clone()),
        };
        let schema = resolved(&raw, &schemas);
        let choices: Vec<String> = schema
            .get("enum")
            .and_then(Value::as_array)
            .map(|e| {
                e.iter()
                    .filter_map(|c| c.as_str().map(String::from))
                    .collect()
            })
            .unwrap_or_default();
        let kind = match (type_of(schema), choices.is_empty()) {
            (_, false) => Kind::Choice,
            ("number", _) => Kind::Number,
            ("integer", _) => Kind::Integer,
            ("boolean", _) => Kind::Boolean,
            ("array", _) => Kind::Curve,
            _ => Kind::Text,
        };
        let bound = |inclusive: &str, exclusive: &str| match (
            schema.get(inclusive).and_then(Value::as_f64),
            schema.get(exclusive).and_then(Value::as_f64),
        ) {
            (_, Some(b)) => (Some(b), true),
            (b, None) => (b, false),
        };
        let (min, min_exclusive) = bound("minimum", "exclusiveMinimum");
        let (max, max_exclusive) = bound("maximum", "exclusiveMaximum");
        // A bound past 2⁵³ (a u64 seed's) is the type's, not one the form can check exactly.
        let max = max.filter(|m| *m < 9_007_199_254_740_992.0);
        // Only the fields the server fills in itself (label, crush distance, start ramp,
        // shape functions, the material's preset and the laws a preset may fill) have no
        // default in the serialized case: those are the optional ones.
        let pointer = format!("/{}", field.replace('.', "/"));
        let default = defaults.pointer(&pointer).cloned().unwrap_or(Value::Null);
        out.push(Field {
            label: text(&raw, "title"),
            unit: text(&raw, "x-unit"),
            help: text(&raw, "description"),
            kind,
            optional: default.is_null(),
            default,
            min,
            max,
            min_exclusive,
            max_exclusive,
            choices,
            presets: match field.strip_prefix("material.") {
                Some(name) if name != "preset" => presets
                    .iter()
                    .filter_map(|(p, m)| m.get(name).map(|v| (*p, v.clone())))
                    .collect(),
                _ => BTreeMap::new(),
            },
            field,
        });
    }
    out
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
        // A rectangular section's lengths, tried on a rectangular tube (which has no diameter);
        // a hexagon's side, on a hexagonal one.
        let rectangular = matches!(
            field,
            "tube.side_a_mm" | "tube.side_b_mm" | "tube.corner_radius_mm"
        ) || (field == "tube.section" && value == "rectangular");
        let hexagonal =
            field == "tube.side_mm" || (field == "tube.section" && value == "hexagonal");
        for (shape, side, given) in [
            ("rectangular", "side_a_mm", rectangular),
            ("hexagonal", "side_mm", hexagonal),
        ] {
            if given {
                let tube = spec["tube"].as_object_mut().unwrap();
                tube.remove("mean_diameter_mm");
                tube.insert("section".into(), shape.into());
                tube.insert(side.into(), 30.0.into());
            }
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
        assert_eq!(
            fields.len(),
            crate::solver::model::case::field_paths().len()
        );
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
            .map(|f| f.field.as_str())
            .collect();
        assert_eq!(
            optional,
            [
                "label",
                "tube.side_a_mm",
                "tube.side_b_mm",
                "tube.corner_radius_mm",
                "tube.side_mm",
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
                "loading.test_speed_m_s",
                "discretization.cfl",
                "discretization.shape",
                "discretization.mass_scaling"
            ]
        );
    }

    #[test]
    fn the_shape_help_names_the_servers_thresholds() {
        use crate::solver::model::case::{HOLDING_FRICTION, THIN_WALL_D_OVER_T};
        let shape = fields()
            .into_iter()
            .find(|f| f.field == "discretization.shape")
            .unwrap();
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/api/openapi.yaml");
        let contract = std::fs::read_to_string(path).unwrap();
        for threshold in [
            format!("(d/t >= {THIN_WALL_D_OVER_T})"),
            format!("(μ < {HOLDING_FRICTION})"),
        ] {
            assert!(shape.help.contains(&threshold), "{}", shape.help);
            assert!(
                contract.contains(&threshold),
                "api/openapi.yaml: {threshold}"
            );
        }
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
                let name = f.field.as_str();
                assert_eq!(
                    refused_for(name, bound, integer),
                    exclusive,
                    "{name} at {bound}"
                );
                assert!(refused_for(name, outside, integer), "{name} at {outside}");
            }
        }
    }

    #[test]
    fn each_field_reads_its_label_unit_kind_and_bounds_off_the_types() {
        let all = fields();
        let field = |name: &str| all.iter().find(|f| f.field == name).unwrap().clone();
        for f in &all {
            assert!(!f.label.is_empty(), "{} has no title", f.field);
        }
        let t = field("tube.thickness_mm");
        assert_eq!(
            (t.label.as_str(), t.unit.as_str()),
            ("Wall thickness t", "mm")
        );
        assert_eq!(
            (t.kind, t.min, t.min_exclusive, t.max),
            (Kind::Number, Some(0.0), true, None)
        );
        let n = field("discretization.particles_through_thickness");
        assert_eq!(
            (n.kind, n.min, n.max),
            (Kind::Integer, Some(1.0), Some(64.0))
        );
        assert!(!n.min_exclusive && !n.max_exclusive);
        let nu = field("material.poisson_ratio");
        assert_eq!((nu.min, nu.max), (Some(-0.99), Some(0.4999)));
        let cfl = field("discretization.cfl");
        assert_eq!(
            (cfl.min_exclusive, cfl.max, cfl.max_exclusive),
            (true, Some(1.0), false)
        );
        assert_eq!(field("material.preset").choices.len(), Preset::ALL.len());
        assert_eq!(field("material.preset").kind, Kind::Choice);
        assert_eq!(field("material.hardening_curve").kind, Kind::Curve);
        assert_eq!(field("output.final_state").kind, Kind::Boolean);
        assert_eq!(field("label").kind, Kind::Text);
        assert_eq!(field("material.density_kg_m3").unit, "kg/m³");
        // In the types' order, the case's sections as the page groups them.
        assert_eq!(all[0].field, "label");
        assert_eq!(all[1].field, "tube.section");
        assert_eq!(
            field("tube.section").choices,
            ["round", "rectangular", "hexagonal"]
        );
        assert_eq!(all.last().unwrap().field, "output.frames");
    }

    #[test]
    fn every_choice_is_accepted_and_others_are_not() {
        for f in fields().into_iter().filter(|f| f.kind == Kind::Choice) {
            for c in &f.choices {
                assert!(
                    case_with(&f.field, Value::from(c.as_str())).is_ok(),
                    "{} = {c}",
                    f.field
                );
            }
            assert!(case_with(&f.field, Value::from("nonsense")).is_err());
        }
    }

    #[test]
    fn the_form_has_every_field_of_the_case_and_no_other() {
        // `field_paths` is also what a sweep may name.
        let mut paths = crate::solver::model::case::field_paths();
        let mut form: Vec<String> = fields().into_iter().map(|f| f.field).collect();
        paths.sort();
        form.sort();
        assert_eq!(form, paths);
        assert!(paths.contains(&"loading.crush_distance_mm".to_string()));
        assert!(paths.contains(&"label".to_string()));
    }
}
