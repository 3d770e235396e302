//! JSON Schema of the case's types (schemars): the case's contract and the form's field table
//! are read off these schemas, so the bounds, titles (the form's labels), units (`x-unit`)
//! and help texts live on the types, beside the fields they describe. This file holds the
//! transform the choice enums use; it imports nothing of the model, so that every type's file
//! can name it. The defaults the server fills into the schemas are in `case_defaults.rs`.

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
