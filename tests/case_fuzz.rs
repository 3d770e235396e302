//! Property tests of the case parser and the cost estimate: whatever numbers a client sends,
//! an accepted case has a finite cost within the limits, and no text makes the parser panic.
//! Numbers are drawn to hit the edges: subnormals, 1e±300, ±MAX, zero, negatives, and values
//! near the bounds, in every field at once.

use crush::solver::{estimate, Case, CaseError, Limits};
use proptest::prelude::*;
use serde_json::{json, Value};

/// Cases per property: 60 000 in all, about 2 s in the test profile.
const CASES: u32 = 20_000;

/// Any f64 a JSON number can carry, weighted towards the extremes.
fn extreme() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-0.0),
        Just(f64::MIN_POSITIVE),
        Just(5e-324),
        Just(f64::MAX),
        Just(-f64::MAX),
        Just(1e-300),
        Just(1e300),
        Just(4294967296.0),
        Just(18446744073709551616.0),
        (-308i32..=308).prop_map(|e| 10f64.powi(e)),
        (-308i32..=308, 1.0f64..10.0).prop_map(|(e, m)| m * 10f64.powi(e)),
        -1e3f64..1e3,
        0.0f64..2.0,
        any::<f64>().prop_filter("JSON has no NaN or infinity", |v| v.is_finite()),
    ]
}

/// A number for a field, usually near its default so that other fields' checks pass too.
fn field(default: f64) -> impl Strategy<Value = Option<f64>> {
    prop_oneof![
        3 => Just(None),
        1 => Just(Some(default)),
        1 => (0.01f64..100.0).prop_map(move |k| Some(default * k)),
        2 => extreme().prop_map(Some),
    ]
}

fn integer() -> impl Strategy<Value = Option<Value>> {
    prop_oneof![
        2 => Just(None),
        2 => (0u64..=20).prop_map(|n| Some(json!(n))),
        1 => any::<u64>().prop_map(|n| Some(json!(n))),
        1 => any::<i64>().prop_map(|n| Some(json!(n))),
    ]
}

/// Sets `value` at the dotted `path` when it is `Some`.
fn put(case: &mut Value, path: &str, value: Option<Value>) {
    let Some(value) = value else { return };
    let (section, name) = path.split_once('.').unwrap();
    case[section][name] = value;
}

fn case() -> impl Strategy<Value = Value> {
    let tube = (field(3.2), field(22.2), field(76.2));
    let material = (field(3378.4), field(0.42), field(65.5), field(1380.0));
    let loading = (field(10.0), field(50.0), any::<bool>());
    let disc = (integer(), field(2.0), field(0.5));
    let rest = (field(0.02), field(0.003), field(0.01), integer());
    (tube, material, loading, disc, rest).prop_map(|(t, m, l, d, r)| {
        let mut c = json!({
            "tube": {}, "material": {}, "loading": {}, "contact": {},
            "discretization": {}, "trigger": {}, "output": {"history_points": 20}
        });
        let f = |v: Option<f64>| v.map(Value::from);
        put(&mut c, "tube.thickness_mm", f(t.0));
        put(&mut c, "tube.mean_diameter_mm", f(t.1));
        put(&mut c, "tube.length_mm", f(t.2));
        put(&mut c, "material.youngs_modulus_mpa", f(m.0));
        put(&mut c, "material.poisson_ratio", f(m.1));
        put(&mut c, "material.yield_stress_mpa", f(m.2));
        put(&mut c, "material.density_kg_m3", f(m.3));
        put(&mut c, "loading.plate_speed_m_s", f(l.0));
        put(&mut c, "loading.crush_distance_mm", f(l.1));
        if l.2 {
            put(&mut c, "loading.mode", Some(json!("lateral")));
        }
        put(&mut c, "discretization.particles_through_thickness", d.0);
        put(&mut c, "discretization.cell_to_particle_ratio", f(d.1));
        put(&mut c, "discretization.cfl", f(d.2));
        put(&mut c, "contact.friction", f(r.0));
        put(&mut c, "trigger.weak_fraction", f(r.1));
        put(&mut c, "trigger.strength_ratio", f(r.2));
        put(&mut c, "trigger.seed", r.3);
        c
    })
}

/// Small limits, so that the property also covers cases just under and over them.
fn limits() -> impl Strategy<Value = Limits> {
    prop_oneof![
        Just(Limits::default()),
        Just(Limits::unbounded()),
        (1u64..100_000, 1u64..100_000, 1u64..10_000_000_000).prop_map(|(p, s, w)| Limits {
            max_particles: p,
            max_steps: s,
            max_particle_steps: w,
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: CASES,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Every accepted case has a finite cost within the limits; every refusal names a field.
    #[test]
    fn every_accepted_case_has_a_finite_bounded_cost(c in case(), limits in limits()) {
        let text = c.to_string();
        match Case::from_json(&text, &limits) {
            Ok(case) => {
                let e = estimate(&case, 2);
                prop_assert!(e.particles >= 8 && e.particles <= limits.max_particles, "{text}: {e:?}");
                prop_assert!(e.steps >= 1 && e.steps <= limits.max_steps, "{text}: {e:?}");
                prop_assert!(e.particles as f64 * e.steps as f64 <= limits.max_particle_steps as f64, "{text}: {e:?}");
                prop_assert!(e.particles.checked_mul(500).is_some_and(|m| m == e.memory_bytes), "{text}: {e:?}");
                prop_assert!(e.wall_time_s.is_finite() && e.wall_time_s > 0.0, "{text}: {e:?}");
                prop_assert!(e.cells >= 1 && e.cells <= e.particles, "{text}: {e:?}");
                prop_assert!(case.spacing_mm().is_finite() && case.spacing_mm() > 0.0);
                prop_assert!(case.wave_speed_m_s().is_finite() && case.wave_speed_m_s() > 0.0);
            }
            Err(CaseError::Invalid(errors)) => {
                prop_assert!(!errors.is_empty());
                for e in &errors {
                    prop_assert!(!e.field.is_empty() && !e.reason.is_empty(), "{text}: {e:?}");
                    // A count that saturated a u64 (issue 10) would read 1844674407370955…
                    prop_assert!(!e.reason.contains("gives 18446744073709551"), "{text}: {e:?}");
                }
            }
            Err(CaseError::Malformed { .. }) => {}
        }
    }

    /// Any bytes, as text, are a case or an error: never a panic.
    #[test]
    fn arbitrary_text_never_panics_the_parser(bytes in proptest::collection::vec(any::<u8>(), 0..256)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = Case::from_json(&text, &Limits::default());
    }

    /// JSON-shaped text (braces, keys of the case, numbers with huge exponents) never panics.
    #[test]
    fn json_shaped_text_never_panics_the_parser(
        parts in proptest::collection::vec(prop_oneof![
            Just("{".to_string()), Just("}".to_string()), Just("[".to_string()), Just("]".to_string()),
            Just(",".to_string()), Just(":".to_string()), Just("\"tube\"".to_string()),
            Just("\"thickness_mm\"".to_string()), Just("\"discretization\"".to_string()),
            Just("\"particles_through_thickness\"".to_string()), Just("null".to_string()),
            (any::<i64>(), -400i32..400).prop_map(|(m, e)| format!("{m}e{e}")),
            any::<u64>().prop_map(|n| n.to_string()),
            "[a-z_\"]{0,8}",
        ], 0..40)
    ) {
        let text = parts.concat();
        let _ = Case::from_json(&text, &Limits::default());
    }
}
