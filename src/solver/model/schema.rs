//! JSON Schema of the case's types (schemars): the case's contract and the form's field table
//! are read off these schemas, so the bounds, titles (the form's labels), units (`x-unit`)
//! and help texts live on the types, beside the fields they describe.

use super::spec::CaseSpec;
use schemars::Schema;
use serde_json::Value;

/// A choice enum as a plain string enumeration: schemars writes an enum whose variants carry
/// doc comments as `oneOf` of `const`s (one per variant); clients, the form and schemathesis
/// read `enum` more simply. The variants' doc comments stay in the code.
pub fn choices(schema: &mut Schema) {
    if let Some(Value::Array(variants)) = schema.remove("oneOf") {
        let names: Vec<Value> = variants
            .iter()
            .flat_map(|v| match (v.get("const"), v.get("enum")) {
                (Some(c), _) => vec![c.clone()],
                (None, Some(Value::Array(e))) => e.clone(),
                _ => vec![],
            })
            .collect();
        schema.insert("type".into(), "string".into());
        schema.insert("enum".into(), Value::Array(names));
    }
}

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
