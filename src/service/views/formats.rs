//! How the views read what the store keeps: unix ms as RFC 3339, a stored JSON text as a
//! value, and a job's swept values (all but one) as one key. Imports nothing of the views;
//! `views.rs`, `sweep.rs` and `time_step.rs` import it.

use serde_json::Value;

/// Unix ms → RFC 3339.
pub fn rfc3339(ms: i64) -> String {
    time::OffsetDateTime::from_unix_timestamp_nanos(ms as i128 * 1_000_000)
        .ok()
        .and_then(|t| {
            t.format(&time::format_description::well_known::Rfc3339)
                .ok()
        })
        .unwrap_or_default()
}

pub(super) fn json(text: Option<&str>) -> Option<Value> {
    text.and_then(|t| serde_json::from_str(t).ok())
}

/// The swept values other than `left_out`, sorted, as one string.
pub(super) fn key_without(fields: &[String], values: &Value, left_out: &str) -> String {
    let mut parts: Vec<String> = fields
        .iter()
        .filter(|f| *f != left_out)
        .map(|f| format!("{f}={}", values.get(f).unwrap_or(&Value::Null)))
        .collect();
    parts.sort();
    parts.join(", ")
}
