//! The defaults of the case's JSON Schema: each field's `default`, read off
//! [`CaseSpec::default`] (units as in the field names). Imports the spec; the service's
//! contract calls it.

use super::spec::CaseSpec;
use serde_json::Value;

/// Sets each case field's `default` in the schemas (`definitions`: name → schema, as a
/// generator leaves them) to the value the server fills in, read off [`CaseSpec::default`]: the
/// material section is read through an input type whose fields are all optional, so its
/// schema alone knows no defaults. A field the server leaves empty (a preset, a law's
/// constants) gets none.
pub fn fill_case_defaults(definitions: &mut serde_json::Map<String, Value>) {
    let Ok(Value::Object(defaults)) = serde_json::to_value(CaseSpec::default()) else {
        return;
    };
    let sections: Vec<(String, String)> = definitions
        .get("Case")
        .and_then(|c| c.get("properties"))
        .and_then(Value::as_object)
        .map(|p| {
            p.iter()
                .filter_map(|(name, s)| Some((name.clone(), reference_name(s)?)))
                .collect()
        })
        .unwrap_or_default();
    for (section, schema_name) in sections {
        let Some(Value::Object(values)) = defaults.get(&section) else {
            continue;
        };
        let Some(Value::Object(properties)) = definitions
            .get_mut(&schema_name)
            .and_then(|s| s.get_mut("properties"))
        else {
            continue;
        };
        for (field, schema) in properties.iter_mut() {
            if let (Some(value), Value::Object(schema)) = (values.get(field), schema) {
                schema.insert("default".into(), value.clone());
            }
        }
    }
}

/// The schema name a `$ref` (or a one-element `allOf` of it) points to.
fn reference_name(schema: &Value) -> Option<String> {
    let r = schema.get("$ref").or_else(|| {
        schema
            .get("allOf")
            .and_then(|a| a.get(0))
            .and_then(|s| s.get("$ref"))
    })?;
    r.as_str()?.rsplit('/').next().map(String::from)
}
