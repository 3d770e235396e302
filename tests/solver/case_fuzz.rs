//! Property tests of the case and sweep parsers and the cost estimate: whatever a client sends,
//! an accepted case has a finite cost within the limits, an accepted sweep has at most the
//! server's number of combinations, each such a case, and no text makes a parser panic; every
//! refusal is small and names where. Numbers are drawn to hit the edges: subnormals, 1e±300,
//! ±MAX, zero, negatives, and values near the bounds, in every field at once; sweeps get deep
//! and wide paths, keys given twice, arrays where sections go, and values of every JSON type.

use crush::service::sweep::{plan, Refusal, MAX_ERRORS};
use crush::solver::model::case::field_paths;
use crush::solver::model::input::ECHO_CHARS;
use crush::solver::{estimate, Case, CaseError, Limits};
use proptest::prelude::*;
use serde_json::{json, Value};

/// Cases per property of the case parser: 60 000 in all, about 2 s in the test profile.
const CASES: u32 = 20_000;

/// Cases per property of the sweep parser and of case texts (each sweep may check up to 100
/// combinations): about 10 s in all in the test profile.
const SWEEPS: u32 = 3_000;

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
                    // A count that saturated a u64 (what broke once) would read 1844674407370955…
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

/// A section of a case written as an array of its values, or a key given twice: the text and
/// the field the refusal must name.
fn case_text() -> impl Strategy<Value = (String, String)> {
    let sections = [
        "tube",
        "material",
        "loading",
        "contact",
        "discretization",
        "trigger",
        "output",
    ];
    (case(), 0..sections.len(), any::<bool>()).prop_map(move |(mut c, i, twice)| {
        // Integers out of range and numbers past f64 (null) would be the first malformation
        // found: leave them out.
        c["discretization"]
            .as_object_mut()
            .unwrap()
            .remove("particles_through_thickness");
        c["trigger"].as_object_mut().unwrap().remove("seed");
        for section in c.as_object_mut().unwrap().values_mut() {
            section.as_object_mut().unwrap().retain(|_, v| !v.is_null());
        }
        let section = sections[i];
        let inner = c[section].as_object().cloned().unwrap_or_default();
        if twice {
            // The section, or its first field, once more at the end of its object.
            let text = c.to_string();
            match inner.iter().next() {
                Some((name, value)) => {
                    let open = format!("\"{section}\":{{");
                    let text = text.replacen(&open, &format!("{open}\"{name}\":{value},"), 1);
                    (text, format!("{section}.{name}"))
                }
                None => {
                    let text = format!("{},\"{section}\":{{}}}}", &text[..text.len() - 1]);
                    (text, section.to_string())
                }
            }
        } else {
            c[section] = Value::Array(inner.into_values().collect());
            (c.to_string(), section.to_string())
        }
    })
}

/// A value a sweep may list, of every JSON type.
fn sweep_value() -> impl Strategy<Value = Value> {
    prop_oneof![
        4 => extreme().prop_map(Value::from),
        2 => (1u64..20).prop_map(Value::from),
        1 => "[a-z_0-9]{0,12}".prop_map(Value::from),
        1 => Just(Value::from("x".repeat(300))),
        1 => any::<bool>().prop_map(Value::from),
        1 => Just(Value::Null),
        1 => Just(json!([1, 2])),
        1 => Just(json!({"a": 1})),
    ]
}

/// A parameter's name: a field of the case, mostly, or a path that is not one.
fn sweep_path() -> impl Strategy<Value = String> {
    let fields = field_paths();
    prop_oneof![
        6 => (0..fields.len()).prop_map(move |i| fields[i].clone()),
        1 => (1usize..20_000).prop_map(|n| vec!["a"; n].join(".")),
        1 => (1usize..5_000).prop_map(|n| "k".repeat(n)),
        1 => "[a-z.]{0,12}",
        1 => Just("tube.thickness_mm.x".to_string()),
    ]
}

/// A parameter that a sweep of the small base case can take, with values it accepts.
fn sensible_entry() -> impl Strategy<Value = (String, Value)> {
    let values = |field: &'static str, list: Vec<Value>| {
        let n = list.len();
        proptest::sample::subsequence(list, 1..=n)
            .prop_map(move |v| (field.to_string(), Value::Array(v)))
    };
    prop_oneof![
        values("tube.length_mm", vec![json!(8), json!(9.5), json!(12)]),
        values("tube.thickness_mm", vec![json!(1.27), json!(2), json!(3.2)]),
        values(
            "loading.plate_speed_m_s",
            vec![json!(5), json!(10), json!(20)]
        ),
        values(
            "discretization.shape",
            vec![json!("gimp"), json!("linear"), json!(null)]
        ),
        values("trigger.seed", vec![json!(1), json!(2), json!(3), json!(4)]),
        values(
            "output.history_points",
            vec![json!(10), json!(20.0), json!(50)]
        ),
        values("label", vec![json!("a"), json!("b")]),
    ]
}

/// The text of a sweep body: a label, a base (a small case, a section as an array, or not a
/// case), and parameters written out one by one, so that a key may come twice, or many
/// thousands of fields; and whether a parameter's key comes twice.
fn sweep_text() -> impl Strategy<Value = (String, bool)> {
    let label = prop_oneof![
        3 => Just(None),
        3 => "[a-z ]{0,20}".prop_map(Some),
        1 => Just(Some("l".repeat(201))),
    ];
    let base = prop_oneof![
        8 => Just(Some(json!({"tube": {"length_mm": 8}, "discretization":
            {"particles_through_thickness": 1}, "loading": {"crush_distance_mm": 1,
            "plate_speed_m_s": 20}, "output": {"history_points": 20, "final_state": false}}))),
        2 => Just(None),
        1 => Just(Some(json!({"discretization": [1, 2]}))),
        1 => Just(Some(json!({"tube": 3}))),
        1 => Just(Some(json!([]))),
        1 => (1usize..200).prop_map(|d| Some(serde_json::from_str(&format!(
            "{{\"tube\":{}{}}}", "[".repeat(d), "]".repeat(d))).unwrap_or(Value::Null))),
    ];
    let entry = (
        sweep_path(),
        prop_oneof![
            6 => proptest::collection::vec(sweep_value(), 0..6).prop_map(Value::Array),
            1 => sweep_value(),
        ],
    );
    let entries = prop_oneof![
        8 => proptest::collection::vec(entry, 0..5),
        8 => proptest::collection::vec(sensible_entry(), 1..4),
        1 => (0usize..30_000).prop_map(|n| (0..n).map(|i| (format!("f{i}.x"), json!([1]))).collect()),
    ];
    let twice = proptest::bool::weighted(0.2);
    (label, base, entries, twice).prop_map(|(label, base, mut entries, twice)| {
        // Each key once, unless the draw says twice.
        let mut seen = std::collections::HashSet::new();
        entries.retain(|(k, _)| seen.insert(k.clone()));
        let repeated = twice && !entries.is_empty();
        if repeated {
            entries.push(entries[0].clone());
        }
        let mut parts = Vec::new();
        if let Some(label) = label {
            parts.push(format!("\"label\":{}", Value::from(label)));
        }
        if let Some(base) = base {
            parts.push(format!("\"base\":{base}"));
        }
        let params: Vec<String> = entries
            .iter()
            .map(|(k, v)| format!("{}:{v}", Value::from(k.as_str())))
            .collect();
        parts.push(format!("\"parameters\":{{{}}}", params.join(",")));
        (format!("{{{}}}", parts.join(",")), repeated)
    })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: SWEEPS,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// A section written as an array, or a key given twice, is malformed, named where.
    #[test]
    fn a_section_as_an_array_or_a_key_twice_is_malformed_and_named((text, field) in case_text()) {
        match Case::from_json(&text, &Limits::default()) {
            Err(CaseError::Malformed { field: Some(named), .. }) => {
                prop_assert_eq!(named, field, "{}", text)
            }
            other => prop_assert!(false, "{text}: {other:?}"),
        }
    }

    /// Every sweep body is a plan within the limits or a small refusal that says where: never
    /// a panic, never more combinations than allowed, never a long quote of the client's text.
    #[test]
    fn every_sweep_is_a_bounded_plan_or_a_small_refusal(
        (text, repeated) in sweep_text(),
        max_jobs in prop_oneof![Just(1usize), Just(10), Just(100)],
        limits in prop_oneof![3 => Just(Limits::default()), 1 => limits()],
    ) {
        let short = |t: &str| t.chars().take(300).collect::<String>();
        match plan(&text, &limits, max_jobs) {
            Ok(p) => {
                prop_assert!(!repeated, "{}", short(&text));
                prop_assert!(!p.jobs.is_empty() && p.jobs.len() <= max_jobs);
                let fields = field_paths();
                prop_assert!(p.parameters.iter().all(|(f, _)| fields.contains(f)));
                let total: usize = p.parameters.iter().map(|(_, v)| v.len()).product();
                prop_assert_eq!(total, p.jobs.len());
                for job in &p.jobs {
                    let case = Case::from_json(&job.case.to_string(), &limits);
                    prop_assert!(case.is_ok(), "{}: {:?}", job.case, case);
                    let case = case.unwrap();
                    prop_assert!(case.particle_count() <= limits.max_particles);
                    prop_assert_eq!(case.particle_count(), job.particles);
                }
            }
            Err(Refusal::Malformed(e)) => {
                prop_assert!(!e.message.is_empty());
                prop_assert!(e.message.chars().count() < 1_000, "{}", short(&e.message));
                let field = e.field.unwrap_or_default();
                prop_assert!(field.chars().count() <= ECHO_CHARS + 10, "{}", short(&field));
            }
            Err(Refusal::Invalid(errors)) => {
                prop_assert!(!repeated, "{}", short(&text));
                prop_assert!(!errors.is_empty() && errors.len() <= MAX_ERRORS + 1);
                for e in &errors {
                    prop_assert!(!e.field.is_empty() && !e.reason.is_empty());
                    prop_assert!(e.field.chars().count() <= ECHO_CHARS + 20, "{}", short(&e.field));
                    prop_assert!(e.reason.chars().count() < 10_000, "{}", short(&e.reason));
                }
            }
        }
    }
}
