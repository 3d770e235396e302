//! Sweeps: a base case plus lists of values for fields of the case → one checked case per
//! combination (the last field varies fastest), or every reason there is none. Pure: JSON text
//! in, cases out; the route stores them.
//!
//! Everything a sweep can cost is bounded before the first combination is built: the body is
//! one object with every key once (else 400); the base must read as a case (names and types,
//! else 422 naming where); each parameter must name a field of the case (so it is one or two
//! segments deep, and there are at most as many parameters as fields); its values must be a
//! non-empty list of plain values; and the combinations must number at most the server's
//! `--max-sweep-jobs`. Combinations are then built and checked one at a time, each a copy of
//! the base with its values set, and the check stops after [`MAX_ERRORS`] errors.

use crate::solver::model::case::{field_paths, spec_from_value};
use crate::solver::model::input::{
    clip, object, object_from_str, set_field, user_message, JsonError,
};
use crate::solver::model::spec::whole;
use crate::solver::{Case, CaseError, FieldError, Limits};
use crate::study::ensemble::SEED_FIELD;
use schemars::JsonSchema;
use serde::Deserialize;
use serde_json::{Map, Value};

/// The longest sweep label, characters: the case's own limit, since it becomes the label of
/// every case that names none.
const MAX_LABEL_CHARS: usize = 200;

/// The body of `POST /v1/sweeps`.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
#[schemars(
    description = "A base case and the values to vary: `parameters` (every combination), an `ensemble` over trigger seeds, or both (every combination over every seed); one of the two at least (422 on `parameters` otherwise).",
    example = serde_json::json!({"base": {"tube": {"length_mm": 8}, "discretization": {"particles_through_thickness": 1}, "loading": {"crush_distance_mm": 1, "plate_speed_m_s": 20}, "output": {"history_points": 20}}, "parameters": {"loading.plate_speed_m_s": [10, 20]}})
)]
pub struct SweepRequest {
    /// Label of every job whose base case has none.
    #[serde(default)]
    #[schemars(length(max = 200))]
    pub label: Option<String>,
    /// The case every job starts from (a Case). Only the whole case of each combination is
    /// held to the Case schema's bounds: a swept field's value here is replaced.
    #[serde(default = "empty_object")]
    #[schemars(with = "Map<String, Value>")]
    pub base: Value,
    /// Field of the case (as `GET /v1/case/fields` names it) → non-empty list of values, e.g.
    /// `"tube.thickness_mm": [1.27, 2.0, 3.2]`. Fields vary in name order, the last fastest.
    #[serde(default)]
    #[schemars(schema_with = "parameters_schema")]
    pub parameters: Map<String, Value>,
    /// Run every combination over this many trigger seeds, from the base's `trigger.seed` on
    /// (past 18446744073709551615 the seeds go on from 0): `trigger.seed` becomes the last
    /// (fastest) parameter, and the sweep's view reads the runs as a distribution.
    #[serde(default, deserialize_with = "present")]
    #[schemars(with = "EnsembleRequest")]
    pub ensemble: Option<EnsembleRequest>,
}

/// An ensemble over trigger seeds.
#[derive(Debug, Clone, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EnsembleRequest {
    /// A whole number; `5.0` reads as 5, as JSON Schema's `integer` has it.
    #[serde(deserialize_with = "whole::<_, u64>")]
    #[schemars(range(min = 2), extend("maximum" = u64::MAX))]
    pub seeds: u64,
}

/// `parameters`' schema: every field a case can set, each with a non-empty list of values.
fn parameters_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
    schemars::json_schema!({
        "type": "object",
        "propertyNames": { "enum": crate::solver::model::case::field_paths() },
        "additionalProperties": {
            "type": "array",
            "minItems": 1,
            "items": { "type": ["number", "string", "boolean", "null"] }
        }
    })
}

/// An optional object that, when given, must be one: `null` is a wrong type, not "absent",
/// and an array is not read by position.
fn present<'de, D: serde::Deserializer<'de>>(de: D) -> Result<Option<EnsembleRequest>, D::Error> {
    object::<_, EnsembleRequest>(de).map(Some)
}

/// The fewest seeds an ensemble takes: one seed is a single run.
pub const MIN_ENSEMBLE_SEEDS: u64 = 2;

fn empty_object() -> Value {
    Value::Object(Map::new())
}

/// The body's text → a request, or where and why not (a 400).
pub fn read(text: &str) -> Result<SweepRequest, JsonError> {
    let body = object_from_str(text)?;
    let req: SweepRequest = serde_path_to_error::deserialize(Value::Object(body)).map_err(|e| {
        let path = e.path().to_string();
        JsonError {
            field: (path != "." && !path.is_empty()).then(|| clip(&path).into_owned()),
            message: user_message(&e.inner().to_string()),
        }
    })?;
    if !req.base.is_object() {
        return Err(JsonError {
            field: Some("base".into()),
            message: "must be a case object".into(),
        });
    }
    Ok(req)
}

/// Most errors a refused sweep lists: past them the check stops, and says so.
pub const MAX_ERRORS: usize = 100;

/// A sweep that passed every check, ready to store.
#[derive(Debug, Clone)]
pub struct Plan {
    pub label: Option<String>,
    /// The base as sent.
    pub base: Value,
    /// `(field, values)` in column order.
    pub parameters: Vec<(String, Vec<Value>)>,
    /// One per combination, in order.
    pub jobs: Vec<PlannedJob>,
}

/// One combination's case, checked.
#[derive(Debug, Clone)]
pub struct PlannedJob {
    /// The case to store: the base with the sweep's label and this combination's values.
    pub case: Value,
    pub label: Option<String>,
    pub particles: u64,
    /// The values this combination takes from the sweep, by field.
    pub values: Map<String, Value>,
}

/// Why a sweep was refused: its body does not read as one (400), or what it asks for makes
/// no sense (422), with every field named.
#[derive(Debug, Clone, PartialEq)]
pub enum Refusal {
    Malformed(JsonError),
    Invalid(Vec<FieldError>),
}

/// The body of `POST /v1/sweeps` → every combination's case, checked against `limits`, or
/// why not. At most `max_jobs` combinations.
pub fn plan(text: &str, limits: &Limits, max_jobs: usize) -> Result<Plan, Refusal> {
    let req = read(text).map_err(Refusal::Malformed)?;
    // The base's names and types, once: every combination is a copy of it. (The contract
    // takes any object as a base, so what is wrong with it is a 422, as for a combination.)
    let trigger = match spec_from_value(&req.base) {
        Ok(spec) => spec.trigger,
        Err(CaseError::Malformed { field, message }) => {
            let field = field.map_or_else(|| "base".into(), |f| format!("base.{f}"));
            return Err(Refusal::Invalid(vec![fail(&field, &message)]));
        }
        Err(CaseError::Invalid(found)) => return Err(Refusal::Invalid(found)),
    };
    let mut params = parameters(&req, max_jobs).map_err(Refusal::Invalid)?;
    if let Some(e) = &req.ensemble {
        // Without weak particles every seed gives the same run; with a swept weak fraction,
        // each combination is checked on its own below.
        let swept = params.iter().any(|(f, _)| f == "trigger.weak_fraction");
        if trigger.weak_fraction <= 0.0 && !swept {
            return Err(Refusal::Invalid(vec![fail(
                "ensemble",
                "needs a trigger: base.trigger.weak_fraction must be > 0, or every seed gives \
                the same run",
            )]));
        }
        // Seeds only name a random draw, so one past the largest is 0: an ensemble from any
        // base seed gets as many distinct seeds as it asks for (at most `max_jobs`), where
        // refusing the base seed would turn away a valid case.
        let seeds = (0..e.seeds).map(|k| Value::from(trigger.seed.wrapping_add(k)));
        params.push((SEED_FIELD.to_string(), seeds.collect()));
    }
    let mut base = req.base.clone();
    if let (Some(label), Some(object)) = (&req.label, base.as_object_mut()) {
        object
            .entry("label")
            .or_insert_with(|| Value::String(label.clone()));
    }
    let total: usize = params.iter().map(|(_, v)| v.len()).product();
    let mut jobs = Vec::with_capacity(total);
    let mut errors: Vec<FieldError> = Vec::new();
    let mut checked = 0;
    for combo in combinations(&base, &params) {
        if errors.len() >= MAX_ERRORS {
            break;
        }
        checked += 1;
        let combo = combo.map_err(|e| Refusal::Invalid(vec![e]))?;
        let at = combo
            .values
            .iter()
            .map(|(f, v)| format!("{f} = {}", clip(&v.to_string())))
            .collect::<Vec<_>>()
            .join(", ");
        let checked = spec_from_value(&combo.case).and_then(|spec| Case::parse(spec, limits));
        match checked {
            Ok(case) => jobs.push(PlannedJob {
                label: case.spec().label.clone(),
                particles: case.particle_count(),
                case: combo.case,
                values: combo.values,
            }),
            Err(CaseError::Invalid(found)) => {
                for e in found {
                    let e = fail(&e.field, &format!("{} (with {at})", e.reason));
                    if !errors.contains(&e) {
                        errors.push(e);
                    }
                }
            }
            // The base read as a case and the values are plain: a value of the wrong type.
            Err(CaseError::Malformed { field, message }) => errors.push(fail(
                &field.unwrap_or_else(|| "base".into()),
                &format!("{message} (with {at})"),
            )),
        }
    }
    if errors.len() > MAX_ERRORS || (errors.len() == MAX_ERRORS && checked < total) {
        errors.truncate(MAX_ERRORS);
        errors.push(fail(
            "parameters",
            &format!(
                "has more errors than the {MAX_ERRORS} listed: the check stopped after \
                 {checked} of {total} combinations"
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(Refusal::Invalid(errors));
    }
    Ok(Plan {
        label: req.label,
        base: req.base,
        parameters: params,
        jobs,
    })
}

/// One combination: the case and the values it takes from the sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Combination {
    pub case: Value,
    pub values: Map<String, Value>,
}

/// The parameters as `(field, values)` in column order, checked; or every problem found.
pub fn parameters(
    req: &SweepRequest,
    max_jobs: usize,
) -> Result<Vec<(String, Vec<Value>)>, Vec<FieldError>> {
    let fields = field_paths();
    let mut errors = Vec::new();
    if req.parameters.is_empty() && req.ensemble.is_none() {
        errors.push(fail(
            "parameters",
            "must name at least one field with a list of values (or give an ensemble)",
        ));
    }
    // The seeds count as one more parameter's values; bounded here, before any is built.
    let seeds = req.ensemble.as_ref().map_or(1, |e| e.seeds);
    if let Some(e) = &req.ensemble {
        if e.seeds < MIN_ENSEMBLE_SEEDS {
            errors.push(fail(
                "ensemble.seeds",
                &format!("must be at least {MIN_ENSEMBLE_SEEDS}"),
            ));
        } else if e.seeds > max_jobs as u64 {
            errors.push(fail(
                "ensemble.seeds",
                &format!("must be at most this server's limit of {max_jobs} jobs a sweep"),
            ));
        }
        if req.parameters.contains_key(SEED_FIELD) {
            errors.push(fail(
                &format!("parameters.{SEED_FIELD}"),
                "cannot be swept with an ensemble, which sets the seeds",
            ));
        }
    }
    if req.parameters.len() > fields.len() {
        // Not one error per name: their number is bounded only by the body's size.
        return Err(vec![fail(
            "parameters",
            &format!(
                "names {} fields; a case has {} (GET /v1/case/fields lists them)",
                req.parameters.len(),
                fields.len()
            ),
        )]);
    }
    if req
        .label
        .as_ref()
        .is_some_and(|l| l.chars().count() > MAX_LABEL_CHARS)
    {
        errors.push(fail(
            "label",
            &format!("must be at most {MAX_LABEL_CHARS} characters"),
        ));
    }
    let mut out = Vec::new();
    for (field, values) in &req.parameters {
        let name = format!("parameters.{}", clip(field));
        if !fields.contains(field) {
            errors.push(fail(
                &name,
                "is not a field of the case (GET /v1/case/fields lists them, \
                 e.g. tube.thickness_mm)",
            ));
            continue;
        }
        match values.as_array() {
            Some(list) if list.is_empty() => {
                errors.push(fail(&name, "must be a non-empty list of values"))
            }
            Some(list) if list.iter().any(|v| v.is_array() || v.is_object()) => errors.push(fail(
                &name,
                "must list numbers, strings, true, false or null",
            )),
            Some(list) => out.push((field.clone(), list.clone())),
            None => errors.push(fail(&name, "must be a non-empty list of values")),
        }
    }
    // The true count when it fits in a u128; past that only "more than the limit" is known.
    let count = out.iter().try_fold(u128::from(seeds.max(1)), |n, (_, v)| {
        n.checked_mul(v.len() as u128)
    });
    match count {
        Some(count) if count <= max_jobs as u128 => {}
        Some(count) => errors.push(fail(
            "parameters",
            &format!("gives {count} combinations, more than this server's limit of {max_jobs}"),
        )),
        None => errors.push(fail(
            "parameters",
            &format!("gives more than {max_jobs} combinations, this server's limit"),
        )),
    }
    if errors.is_empty() {
        Ok(out)
    } else {
        Err(errors)
    }
}

/// Every combination of the parameters applied to `base`, built one at a time as the iterator
/// is read (the last parameter varies fastest).
pub fn combinations<'a>(
    base: &'a Value,
    params: &'a [(String, Vec<Value>)],
) -> impl Iterator<Item = Result<Combination, FieldError>> + 'a {
    let count = params.iter().map(|(_, v)| v.len()).product::<usize>();
    (0..count).map(move |mut index| {
        let mut picks = vec![0; params.len()];
        for (pick, (_, values)) in picks.iter_mut().zip(params).rev() {
            *pick = index % values.len();
            index /= values.len();
        }
        let mut combo = Combination {
            case: base.clone(),
            values: Map::new(),
        };
        for ((field, values), pick) in params.iter().zip(picks) {
            let value = &values[pick];
            set_field(&mut combo.case, field, value.clone()).map_err(|walked| {
                let reason = format!("cannot be set: base.{walked} is not an object");
                fail(&format!("parameters.{field}"), &reason)
            })?;
            combo.values.insert(field.clone(), value.clone());
        }
        Ok(combo)
    })
}

fn fail(field: &str, reason: &str) -> FieldError {
    FieldError {
        field: field.into(),
        reason: reason.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn request(v: Value) -> SweepRequest {
        read(&v.to_string()).unwrap()
    }

    fn all(base: &Value, params: &[(String, Vec<Value>)]) -> Vec<Combination> {
        combinations(base, params).map(Result::unwrap).collect()
    }

    #[test]
    fn two_fields_give_the_product_with_the_last_varying_fastest() {
        let req = request(json!({
            "base": {"tube": {"length_mm": 8}},
            "parameters": {"tube.thickness_mm": [1, 2], "output.history_points": [10, 20, 30]}
        }));
        let params = parameters(&req, 100).unwrap();
        let combos = all(&req.base, &params);
        assert_eq!(combos.len(), 6);
        // Fields in name order: output.history_points, then tube.thickness_mm (fastest).
        assert_eq!(params[0].0, "output.history_points");
        assert_eq!(
            combos[1].case,
            json!({"tube": {"length_mm": 8, "thickness_mm": 2}, "output": {"history_points": 10}})
        );
        assert_eq!(combos[3].values["tube.thickness_mm"], json!(2));
        assert_eq!(combos[5].values["output.history_points"], json!(30));
    }

    #[test]
    fn too_many_combinations_and_empty_lists_are_named() {
        let req = request(json!({"parameters": {
            "tube.length_mm": [1, 2, 3], "tube.thickness_mm": []
        }}));
        let errors = parameters(&req, 2).unwrap_err();
        let fields: Vec<_> = errors.iter().map(|e| e.field.as_str()).collect();
        assert!(
            fields.contains(&"parameters.tube.thickness_mm"),
            "{fields:?}"
        );
        assert!(fields.contains(&"parameters"), "{fields:?}");
    }

    #[test]
    fn a_path_that_is_not_a_field_of_the_case_is_named_clipped() {
        let deep = vec!["a"; 14_000].join(".");
        let req = request(json!({"parameters": {
            deep.clone(): [1], "tube": [1], "tube.wall": [1], "tube.thickness_mm.x": [1],
            "label": ["a", "b"]
        }}));
        let errors = parameters(&req, 100).unwrap_err();
        let fields: Vec<_> = errors.iter().map(|e| e.field.as_str()).collect();
        for f in [
            "parameters.tube",
            "parameters.tube.wall",
            "parameters.tube.thickness_mm.x",
        ] {
            assert!(fields.contains(&f), "{f} not in {fields:?}");
        }
        let clipped = format!("parameters.{}", clip(&deep));
        assert!(fields.contains(&clipped.as_str()), "{fields:?}");
        assert!(errors.iter().all(|e| e.field.chars().count() < 120));
        // label is a field of the case: not named.
        assert_eq!(errors.len(), 4, "{errors:?}");
    }

    #[test]
    fn more_parameters_than_fields_is_one_error() {
        let many: Map<String, Value> = (0..50_000)
            .map(|i| (format!("f{i}.x"), json!([1])))
            .collect();
        let req = request(json!({ "parameters": many }));
        let errors = parameters(&req, 100).unwrap_err();
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert!(
            errors[0].reason.contains("names 50000 fields"),
            "{errors:?}"
        );
    }

    #[test]
    fn values_must_be_plain_values() {
        for values in [json!([[1]]), json!([{"a": 1}]), json!(3), json!({})] {
            let req = request(json!({"parameters": {"tube.length_mm": values}}));
            let errors = parameters(&req, 100).unwrap_err();
            assert_eq!(errors[0].field, "parameters.tube.length_mm", "{values}");
        }
        let req = request(json!({"parameters": {"tube.length_mm": [1, 2.5, "x", true, null]}}));
        assert_eq!(parameters(&req, 100).unwrap()[0].1.len(), 5);
    }

    #[test]
    fn a_key_given_twice_in_parameters_or_base_is_refused() {
        for (text, field) in [
            (
                r#"{"parameters": {"tube.length_mm": [1], "tube.length_mm": [2]}}"#,
                "parameters.tube.length_mm",
            ),
            (
                r#"{"base": {"tube": {"length_mm": 8, "length_mm": 9}}, "parameters": {}}"#,
                "base.tube.length_mm",
            ),
            (r#"{"parameters": {}, "parameters": {}}"#, "parameters"),
        ] {
            let e = read(text).unwrap_err();
            assert_eq!(e.field.as_deref(), Some(field), "{text}");
        }
    }

    #[test]
    fn a_base_that_does_not_read_as_a_case_is_refused_at_once() {
        for (base, field) in [
            (json!({"tube": 3}), "base.tube"),
            (json!({"discretization": [1, 2]}), "base.discretization"),
            (json!({"tube": {"wall": 1}}), "base.tube.wall"),
            (
                json!({"tube": {"thickness_mm": "x"}}),
                "base.tube.thickness_mm",
            ),
        ] {
            let text = json!({"base": base, "parameters": {"tube.length_mm": [1]}});
            match plan(&text.to_string(), &Limits::default(), 100) {
                Err(Refusal::Invalid(errors)) => {
                    assert_eq!(errors.len(), 1, "{errors:?}");
                    assert_eq!(errors[0].field, field, "{base}");
                }
                other => panic!("{base}: {other:?}"),
            }
        }
        let text = json!({"base": [], "parameters": {"tube.length_mm": [1]}});
        let e = read(&text.to_string()).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("base"));
    }

    #[test]
    fn a_sweep_whose_every_combination_fails_lists_at_most_max_errors() {
        // Each combination is over the particle limit, which names four fields or more.
        let lengths: Vec<f64> = (0..100).map(|i| 8.0 + i as f64 / 10.0).collect();
        let base = json!({"loading": {"crush_distance_mm": 1}, "output": {"history_points": 20}});
        let text = json!({"base": base, "parameters": {"tube.length_mm": lengths}});
        let limits = Limits {
            max_particles: 10,
            ..Limits::default()
        };
        let Err(Refusal::Invalid(errors)) = plan(&text.to_string(), &limits, 100) else {
            panic!("accepted")
        };
        assert_eq!(errors.len(), MAX_ERRORS + 1);
        let last = errors.last().unwrap();
        assert_eq!(last.field, "parameters");
        assert!(last.reason.contains("of 100 combinations"), "{last:?}");
        // A sweep with fewer errors lists them all, with no note.
        let text = json!({"base": base, "parameters": {"tube.length_mm": [8, 9]}});
        let Err(Refusal::Invalid(errors)) = plan(&text.to_string(), &limits, 100) else {
            panic!("accepted")
        };
        assert!(errors.len() < MAX_ERRORS && errors.iter().all(|e| e.field != "parameters"));
    }

    #[test]
    fn the_contract_names_exactly_the_fields_a_sweep_may_vary() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/api/openapi.yaml");
        let doc: serde_yaml_ng::Value =
            serde_yaml_ng::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let names = &doc["components"]["schemas"]["SweepRequest"]["properties"]["parameters"]
            ["propertyNames"]["enum"];
        let mut contract: Vec<String> = names
            .as_sequence()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap().to_string())
            .collect();
        let mut fields = field_paths();
        contract.sort();
        fields.sort();
        assert_eq!(contract, fields);
    }

    #[test]
    fn a_sweep_label_longer_than_a_case_label_is_named() {
        let req = request(json!({"label": "x".repeat(201), "parameters": {"label": ["a"]}}));
        let errors = parameters(&req, 100).unwrap_err();
        assert_eq!(errors[0].field, "label");
    }

    fn refusal(body: Value, max_jobs: usize) -> Vec<FieldError> {
        match plan(&body.to_string(), &Limits::default(), max_jobs) {
            Err(Refusal::Invalid(errors)) => errors,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_ensemble_runs_each_combination_over_seeds_from_the_base_seed_on() {
        let body = json!({
            "base": {"trigger": {"weak_fraction": 0.003, "seed": 7},
                     "discretization": {"particles_through_thickness": 2}},
            "parameters": {"tube.length_mm": [60, 70]},
            "ensemble": {"seeds": 3}
        });
        let p = plan(&body.to_string(), &Limits::default(), 100).unwrap();
        assert_eq!(p.parameters.last().unwrap().0, SEED_FIELD);
        let seeds: Vec<u64> = p
            .jobs
            .iter()
            .map(|j| j.values[SEED_FIELD].as_u64().unwrap())
            .collect();
        assert_eq!(seeds, [7, 8, 9, 7, 8, 9]);
        assert_eq!(p.jobs[4].case["trigger"]["seed"], 8);
        assert_eq!(p.jobs[4].case["tube"]["length_mm"], 70);
    }

    #[test]
    fn an_ensemble_without_a_trigger_or_with_too_few_or_too_many_seeds_is_refused() {
        let untriggered = json!({"base": {}, "ensemble": {"seeds": 3}});
        let errors = refusal(untriggered, 100);
        assert_eq!(errors[0].field, "ensemble");
        // One sentence, its words one space apart (a line break in the source once carried
        // its indentation into the reason).
        assert!(!errors[0].reason.contains("  "), "{errors:?}");
        let triggered = json!({"trigger": {"weak_fraction": 0.003}});
        let one = json!({"base": triggered, "ensemble": {"seeds": 1}});
        assert_eq!(refusal(one, 100)[0].field, "ensemble.seeds");
        // Refused before a single seed is built, however many are asked for.
        let huge = json!({"base": triggered, "ensemble": {"seeds": u64::MAX}});
        let errors = refusal(huge, 100);
        assert_eq!(errors[0].field, "ensemble.seeds");
        assert!(errors[0].reason.contains("100"), "{errors:?}");
        let product = json!({"base": triggered, "ensemble": {"seeds": 30},
                             "parameters": {"tube.length_mm": [40, 50, 60, 70]}});
        let errors = refusal(product, 100);
        assert!(
            errors
                .iter()
                .any(|e| e.field == "parameters" && e.reason.contains("120")),
            "{errors:?}"
        );
        let both = json!({"base": triggered, "ensemble": {"seeds": 3},
                          "parameters": {"trigger.seed": [1, 2]}});
        assert_eq!(refusal(both, 100)[0].field, "parameters.trigger.seed");
        let whole = json!({"base": triggered, "ensemble": {"seeds": 3.0}});
        assert_eq!(
            plan(&whole.to_string(), &Limits::default(), 100)
                .unwrap()
                .jobs
                .len(),
            3
        );
        let null = json!({"base": triggered, "ensemble": null, "parameters": {"label": ["a"]}});
        assert!(matches!(
            plan(&null.to_string(), &Limits::default(), 100),
            Err(Refusal::Malformed(_))
        ));
        let unknown = json!({"base": triggered, "ensemble": {"seeds": 3, "from": 2}});
        assert!(matches!(
            plan(&unknown.to_string(), &Limits::default(), 100),
            Err(Refusal::Malformed(_))
        ));
    }

    #[test]
    fn an_ensemble_from_the_largest_seed_gives_distinct_seeds() {
        let body = json!({
            "base": {"trigger": {"weak_fraction": 0.003, "seed": u64::MAX}},
            "ensemble": {"seeds": 3}
        });
        let p = plan(&body.to_string(), &Limits::default(), 100).unwrap();
        let seeds: Vec<u64> = p
            .jobs
            .iter()
            .map(|j| j.case["trigger"]["seed"].as_u64().unwrap())
            .collect();
        assert_eq!(seeds, [u64::MAX, 0, 1]);
    }

    #[test]
    fn an_ensemble_given_as_an_array_is_refused_naming_ensemble() {
        for ensemble in [json!([2]), json!([]), json!(2)] {
            let text = json!({"base": {"trigger": {"weak_fraction": 0.003}}, "ensemble": ensemble});
            let e = read(&text.to_string()).unwrap_err();
            assert_eq!(e.field.as_deref(), Some("ensemble"), "{ensemble}");
            assert!(e.message.contains("expected an object"), "{e:?}");
        }
    }

    #[test]
    fn an_oversized_sweep_gives_its_true_count_or_more_than_the_limit_never_a_saturated_one() {
        let triggered = json!({"trigger": {"weak_fraction": 0.003}});
        // u64::MAX seeds × 2 lengths: past u64, within u128.
        let body = json!({"base": triggered, "ensemble": {"seeds": u64::MAX},
                          "parameters": {"tube.length_mm": [40, 50]}});
        let errors = refusal(body, 100);
        let count = errors.iter().find(|e| e.field == "parameters").unwrap();
        assert!(
            count
                .reason
                .contains("gives 36893488147419103230 combinations"),
            "{count:?}"
        );
        // Past u128: 2^64 seeds × (2^16)^5 values.
        let values: Vec<u32> = (0..1 << 16).collect();
        let parameters: Map<String, Value> = [
            "tube.length_mm",
            "tube.thickness_mm",
            "tube.mean_diameter_mm",
            "loading.plate_speed_m_s",
            "loading.crush_distance_mm",
        ]
        .iter()
        .map(|f| (f.to_string(), json!(values)))
        .collect();
        let body = json!({"base": triggered, "ensemble": {"seeds": u64::MAX},
                          "parameters": parameters});
        let errors = refusal(body, 100);
        let count = errors.iter().find(|e| e.field == "parameters").unwrap();
        assert!(
            count.reason.contains("more than 100 combinations"),
            "{count:?}"
        );
        assert!(
            errors
                .iter()
                .all(|e| !e.reason.contains(&u64::MAX.to_string())
                    && !e.reason.contains(&u128::MAX.to_string())),
            "{errors:?}"
        );
    }
}
