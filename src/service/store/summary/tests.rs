use super::*;
use crate::service::store::{sample_summary, temp_store, NewJob, Succeeded};
use uuid::Uuid;

/// The crash measures an older row lacks, and the first peak's of them (null when read).
const MEASURES: [&str; 7] = [
    "tube_mass_g",
    "specific_energy_absorption_j_per_g",
    "first_peak_load_n",
    "first_peak_displacement_mm",
    "mean_load_after_first_peak_n",
    "crush_force_efficiency",
    "energy_dissipated_mj",
];

/// The sample summary's JSON as the current solver stores it, read back as a JSON value (so
/// that its numbers went through the same float parser as the store's reads).
fn current() -> Value {
    let text = serde_json::to_string(&sample_summary()).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The JSON of `row` as the API serves it once the store read it.
fn served(row: &Value) -> Value {
    serde_json::to_value(StoredSummary::read(&row.to_string()).unwrap()).unwrap()
}

#[test]
fn a_current_summary_is_served_as_the_solver_wrote_it() {
    let text = serde_json::to_string(&sample_summary()).unwrap();
    let solver: Summary = serde_json::from_str(&text).unwrap();
    let stored = StoredSummary::read(&text).unwrap();
    assert_eq!(
        serde_json::to_string(&stored).unwrap(),
        serde_json::to_string(&solver).unwrap()
    );
    assert_eq!(stored, StoredSummary::from(solver));
}

/// A round tube's summary as the versions before verdicts stored it: no shape choice, verdict,
/// error bar or expected error, no load drops, energy books, unloaded stretch, crash measures
/// or metal closed forms. The API served those at zero (the first peak's figures null) and
/// left out the rest; it still does.
#[test]
fn a_summary_stored_before_verdicts_is_served_as_it_always_was() {
    let mut row = current();
    let fields = row.as_object_mut().unwrap();
    let lacks = ["shape", "verdict", "error_bar", "expected_error"];
    let zeroed = ["load_drops", "energy", "longest_unloaded_mm"];
    for key in lacks.iter().chain(&zeroed).chain(&MEASURES) {
        assert!(fields.remove(*key).is_some(), "the sample has {key}");
    }
    let references = fields["references"].as_object_mut().unwrap();
    assert!(references.remove("metal").is_some());

    let mut want = row.clone();
    let fields = want.as_object_mut().unwrap();
    fields.insert("load_drops".into(), json!(0));
    fields.insert(
        "energy".into(),
        json!({
            "work_top_mj": 0.0, "work_bottom_mj": 0.0, "kinetic_mj": 0.0, "elastic_mj": 0.0,
            "plastic_mj": 0.0, "friction_mj": 0.0, "contact_mj": 0.0, "residual_mj": 0.0
        }),
    );
    fields.insert("longest_unloaded_mm".into(), json!(0.0));
    for key in MEASURES {
        let zero = if key.contains("first_peak") || key == "crush_force_efficiency" {
            Value::Null
        } else {
            json!(0.0)
        };
        fields.insert(key.into(), zero);
    }
    fields["references"]["metal"] = json!({
        "flow_stress_mpa": 0.0, "yield_stress_mpa": 0.0, "ultimate_stress_mpa": 0.0,
        "abramowicz_jones_n": 0.0, "abramowicz_jones_dynamic_n": null, "guillow_n": 0.0,
        "guillow_dynamic_n": null, "guillow_in_range": false, "fold_wavelength_mm": 0.0,
        "strain_rate_per_s": 0.0, "rate_factor": 0.0
    });
    assert_eq!(served(&row), want);

    let read = StoredSummary::read(&row.to_string()).unwrap();
    assert_eq!(
        (read.shape, read.verdict, read.expected_error),
        (None, None, None)
    );
}

/// A round tube's metal closed forms as stored before they named the yield and ultimate
/// stresses: served with those at 0 and the rest as stored.
#[test]
fn metal_closed_forms_stored_before_the_stresses_serve_them_at_zero() {
    let mut row = current();
    let metal = row["references"]["metal"].as_object_mut().unwrap();
    metal.remove("yield_stress_mpa").unwrap();
    metal.remove("ultimate_stress_mpa").unwrap();
    let mut want = row.clone();
    want["references"]["metal"]["yield_stress_mpa"] = json!(0.0);
    want["references"]["metal"]["ultimate_stress_mpa"] = json!(0.0);
    assert_eq!(served(&row), want);
    assert_ne!(served(&row), current(), "the sample's stresses are not 0");
}

#[test]
fn a_summary_that_lacks_a_field_every_version_stored_does_not_read() {
    let mut row = current();
    row.as_object_mut().unwrap().remove("folds");
    let why = StoredSummary::read(&row.to_string()).unwrap_err();
    assert!(why.contains("folds"), "{why}");
    assert!(StoredSummary::read("{").unwrap_err().contains("not JSON"));
}

/// The whole read path: a row stored before verdicts, read back by the store, shows its
/// summary without a verdict.
#[tokio::test]
async fn the_store_reads_a_row_stored_before_verdicts() {
    let (_dir, store) = temp_store().await;
    let id = Uuid::new_v4();
    let job = NewJob {
        id,
        case_json: "{}".into(),
        label: None,
        particles: 10,
        idempotency_key: None,
    };
    store.submit(job, 10).await.unwrap();
    let claim = store.claim("a").await.unwrap().unwrap();
    let summary = sample_summary();
    let result = Succeeded {
        history: &[],
        summary: &summary,
        final_state: None,
        progress_json: None,
        frames: 0,
        particles: 0,
    };
    store
        .finish_succeeded(id, claim.lease, result)
        .await
        .unwrap();
    let mut row = current();
    for key in ["shape", "verdict", "expected_error"] {
        row.as_object_mut().unwrap().remove(key);
    }
    sqlx::query("UPDATE summaries SET summary_json = $1 WHERE job_id = $2")
        .bind(row.to_string())
        .bind(id.to_string())
        .execute(&store.pool)
        .await
        .unwrap();
    let back = store.job(id).await.unwrap().unwrap().summary.unwrap();
    assert_eq!(back.verdict, None);
    assert_eq!(serde_json::to_value(&back).unwrap(), row);
}
