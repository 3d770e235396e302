//! Sweep expansion: a base case plus lists of values for dotted fields → one case per
//! combination (the last field varies fastest). Pure: JSON in, JSON out.

use crate::solver::FieldError;
use serde::Deserialize;
use serde_json::{Map, Value};

/// The body of `POST /v1/sweeps`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepRequest {
    #[serde(default)]
    pub label: Option<String>,
    #[serde(default = "empty_object")]
    pub base: Value,
    /// Dotted field path → values, e.g. `"tube.thickness_mm": [1.27, 2.0, 3.2]`.
    pub parameters: Map<String, Value>,
}

fn empty_object() -> Value {
    Value::Object(Map::new())
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
    let mut errors = Vec::new();
    let mut out = Vec::new();
    if req.parameters.is_empty() {
        errors.push(fail(
            "parameters",
            "must name at least one field with a list of values",
        ));
    }
    for (field, values) in &req.parameters {
        let name = format!("parameters.{field}");
        if field.is_empty() || field.split('.').any(str::is_empty) {
            errors.push(fail(
                &name,
                "must be a dotted path such as tube.thickness_mm",
            ));
            continue;
        }
        match values.as_array() {
            Some(list) if !list.is_empty() => out.push((field.clone(), list.clone())),
            _ => errors.push(fail(&name, "must be a non-empty list of values")),
        }
    }
    if !req.base.is_object() {
        errors.push(fail("base", "must be a case object"));
    }
    let count = out
        .iter()
        .fold(1usize, |n, (_, v)| n.saturating_mul(v.len()));
    if count > max_jobs {
        errors.push(fail(
            "parameters",
            &format!("gives {count} combinations, more than this server's limit of {max_jobs}"),
        ));
    }
    if errors.is_empty() {
        Ok(out)
    } else {
        Err(errors)
    }
}

/// Every combination of the parameters applied to `base`.
pub fn expand(
    base: &Value,
    params: &[(String, Vec<Value>)],
) -> Result<Vec<Combination>, Vec<FieldError>> {
    let mut combos = vec![Combination {
        case: base.clone(),
        values: Map::new(),
    }];
    for (field, values) in params {
        let mut next = Vec::with_capacity(combos.len() * values.len());
        for combo in &combos {
            for value in values {
                let mut c = combo.clone();
                set(&mut c.case, field, value.clone())
                    .map_err(|reason| vec![fail(&format!("parameters.{field}"), &reason)])?;
                c.values.insert(field.clone(), value.clone());
                next.push(c);
            }
        }
        combos = next;
    }
    Ok(combos)
}

/// Sets the dotted `path` in `case`, making intermediate objects as needed.
fn set(case: &mut Value, path: &str, value: Value) -> Result<(), String> {
    let mut node = case;
    let mut walked = Vec::new();
    let segments: Vec<&str> = path.split('.').collect();
    for (i, segment) in segments.iter().enumerate() {
        let Some(object) = node.as_object_mut() else {
            return Err(format!(
                "cannot be set: base.{} is not an object",
                walked.join(".")
            ));
        };
        if i + 1 == segments.len() {
            object.insert(segment.to_string(), value);
            return Ok(());
        }
        walked.push(*segment);
        node = object
            .entry(segment.to_string())
            .or_insert_with(empty_object);
    }
    Ok(())
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
        serde_json::from_value(v).unwrap()
    }

    #[test]
    fn two_fields_give_the_product_with_the_last_varying_fastest() {
        let req = request(json!({
            "base": {"tube": {"length_mm": 8}},
            "parameters": {"tube.thickness_mm": [1, 2], "output.history_points": [10, 20, 30]}
        }));
        let params = parameters(&req, 100).unwrap();
        let combos = expand(&req.base, &params).unwrap();
        assert_eq!(combos.len(), 6);
        // Fields in name order: output.history_points, then tube.thickness_mm (fastest).
        assert_eq!(params[0].0, "output.history_points");
        assert_eq!(
            combos[1].case,
            json!({"tube": {"length_mm": 8, "thickness_mm": 2}, "output": {"history_points": 10}})
        );
        assert_eq!(combos[3].values["tube.thickness_mm"], json!(2));
    }

    #[test]
    fn too_many_combinations_and_empty_lists_are_named() {
        let req = request(json!({"parameters": {"a.b": [1, 2, 3], "c": []}}));
        let errors = parameters(&req, 2).unwrap_err();
        let fields: Vec<_> = errors.iter().map(|e| e.field.as_str()).collect();
        assert!(fields.contains(&"parameters.c"), "{fields:?}");
        assert!(fields.contains(&"parameters"), "{fields:?}");
    }

    #[test]
    fn a_path_through_a_number_is_rejected() {
        let req = request(json!({"base": {"tube": 3}, "parameters": {"tube.thickness_mm": [1]}}));
        let params = parameters(&req, 10).unwrap();
        let errors = expand(&req.base, &params).unwrap_err();
        assert_eq!(errors[0].field, "parameters.tube.thickness_mm");
    }
}
