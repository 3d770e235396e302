//! The checks of a case, field by field, and its cost against the limits.

use super::*;
use crate::solver::model::cost::STEP_FIELDS;
use crate::solver::model::geometry::round::PARTICLE_FIELDS;

/// A tube of wall t and diameter d with the given discretization JSON, checked.
fn tube_case(t: f64, d: f64, discretization: &str) -> Case {
    tube_case_on(t, d, 0.02, discretization)
}

/// [`tube_case`] between plates of friction μ.
fn tube_case_on(t: f64, d: f64, friction: f64, discretization: &str) -> Case {
    let text = format!(
        r#"{{"tube": {{"thickness_mm": {t}, "mean_diameter_mm": {d}, "length_mm": 10}},
            "loading": {{"crush_distance_mm": 5}},
            "contact": {{"friction": {friction}}},
            "discretization": {discretization}}}"#
    );
    Case::from_json(&text, &Limits::default()).unwrap()
}

#[test]
fn the_default_shape_follows_the_wall_and_the_plates_in_3d_and_is_gimp_in_the_sections() {
    // The paper's thick tube (d/t 6.9) and the t 1.27, d 10 tube (d/t 7.9): uGIMP.
    for (t, d) in [(3.2, 22.2), (1.27, 10.0)] {
        let case = tube_case(t, d, "{}");
        assert_eq!(case.shape(), ShapeKind::Gimp, "t {t} d {d}");
        let why = case.shape_choice().default_reason.clone().unwrap();
        let d_over_t = format!("{:.1}", d / t);
        assert_eq!(
            why,
            format!("gimp: the default for a wall of d/t = {d_over_t} < 8")
        );
    }
    // The thin tubes (d/t 9.4–26.1) and the threshold itself on the source's near-frictionless
    // plates: linear, with d/t and μ in the reason.
    for (t, d) in [(1.27, 12.0), (1.27, 20.32)] {
        assert_eq!(
            tube_case(t, d, "{}").shape(),
            ShapeKind::Linear,
            "t {t} d {d}"
        );
    }
    let thin = tube_case(0.76, 19.81, "{}");
    assert_eq!(thin.shape(), ShapeKind::Linear);
    assert_eq!(
        thin.shape_choice().default_reason.as_deref(),
        Some(
            "linear: the default for a thin wall (d/t = 26.1 >= 8) on near-frictionless \
             plates (μ 0.02 < 0.2), between which uGIMP lets such a tube tip over; where \
             linear shapes fold it first follows the wall's motion through the grid \
             (docs/folding.md §4)"
        )
    );
    let at = tube_case(1.0, THIN_WALL_D_OVER_T, "{}");
    assert_eq!(at.shape(), ShapeKind::Linear);
    let below = tube_case(1.0, THIN_WALL_D_OVER_T - 0.01, "{}");
    assert_eq!(below.shape(), ShapeKind::Gimp);
    // On plates that hold the ends (from μ 0.2 on) a thin wall gets B-splines, whose mean load
    // settles with n on the d/t 14 tube where uGIMP's alternates with the parity of n.
    let held = tube_case_on(0.76, 19.81, 0.3, "{}");
    assert_eq!(held.shape(), ShapeKind::Bspline);
    assert_eq!(
        held.shape_choice().default_reason.as_deref(),
        Some(
            "bspline: the default for a thin wall (d/t = 26.1 >= 8) on plates that hold its \
             ends (μ 0.3 >= 0.2): on the d/t 14 tube their mean load settles from n = 4, where \
             uGIMP's alternates with the parity of n (docs/studies.md §9)"
        )
    );
    let at = tube_case_on(1.27, 20.32, HOLDING_FRICTION, "{}");
    assert_eq!(at.shape(), ShapeKind::Bspline);
    let below = tube_case_on(1.27, 20.32, HOLDING_FRICTION - 1e-3, "{}");
    assert_eq!(below.shape(), ShapeKind::Linear);
    // A wall below the thin threshold keeps uGIMP on any plates.
    let thick_held = tube_case_on(3.2, 22.2, 0.3, "{}");
    assert_eq!(thick_held.shape(), ShapeKind::Gimp);
    // A reduced model has no global buckling to lose: uGIMP, which converges there.
    let section = tube_case(0.76, 19.81, r#"{"model": "axisymmetric"}"#);
    assert_eq!(section.shape(), ShapeKind::Gimp);
    // A named shape (or null, which is the default) is kept; only the default has a reason.
    for named in [ShapeKind::Gimp, ShapeKind::Linear] {
        let text = format!(r#"{{"shape": "{}"}}"#, named.name());
        for (t, d) in [(3.2, 22.2), (0.76, 19.81)] {
            let case = tube_case(t, d, &text);
            assert_eq!(case.shape(), named);
            assert_eq!(case.shape_choice().default_reason, None);
        }
    }
    assert_eq!(
        tube_case(0.76, 19.81, r#"{"shape": null}"#).shape(),
        ShapeKind::Linear
    );
    // The spec keeps what the user wrote: no shape stays no shape.
    assert!(serde_json::to_value(thin.spec()).unwrap()["discretization"]
        .get("shape")
        .is_none());
}

#[test]
fn empty_object_is_the_pvc_default() {
    let case = Case::from_json("{}", &Limits::default()).unwrap();
    assert_eq!(case.spec().tube.thickness_mm, 3.2);
    assert_eq!(case.crush_distance_mm(), 50.0);
    // 2π·11.1/0.8 etc.: the n = 4 lattice of the design page holds about 35 k particles.
    let n = case.particle_count();
    assert!((33_000..37_000).contains(&n), "{n}");
}

#[test]
fn an_empty_array_is_not_read_as_the_default_case() {
    for value in [
        serde_json::json!([]),
        serde_json::json!([{}]),
        serde_json::Value::Null,
    ] {
        match spec_from_value(&value) {
            Err(CaseError::Malformed {
                field: None,
                message,
            }) => {
                assert!(message.contains("object"), "{value}: {message}")
            }
            other => panic!("{value}: {other:?}"),
        }
    }
}

#[test]
fn n6_lattice_matches_the_source_particle_count() {
    let mut spec = CaseSpec::default();
    spec.discretization.particles_through_thickness = 6;
    let n = Case::parse(spec, &Limits::default())
        .unwrap()
        .particle_count();
    // The source reports about 113 k particles at n = 6; within 3 %.
    assert!((n as f64 / 113_000.0 - 1.0).abs() < 0.03, "{n}");
}

#[test]
fn every_bad_field_is_named() {
    let text = r#"{"tube": {"thickness_mm": 12, "mean_diameter_mm": 22.2},
        "material": {"poisson_ratio": 0.5, "density_kg_m3": -1},
        "loading": {"plate_speed_m_s": -3},
        "discretization": {"cfl": 0, "particles_through_thickness": 0},
        "trigger": {"weak_fraction": 0.5},
        "output": {"history_points": 1}}"#;
    let Err(CaseError::Invalid(errors)) = Case::from_json(text, &Limits::default()) else {
        panic!("accepted a bad case")
    };
    let fields: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    for f in [
        "tube.thickness_mm",
        "material.poisson_ratio",
        "material.density_kg_m3",
        "loading.plate_speed_m_s",
        "discretization.cfl",
        "discretization.particles_through_thickness",
        "trigger.weak_fraction",
        "output.history_points",
    ] {
        assert!(fields.contains(&f), "{f} not named in {fields:?}");
    }
}

#[test]
fn too_many_particles_is_rejected_with_the_count() {
    let text = r#"{"discretization": {"particles_through_thickness": 10}}"#;
    let err = Case::from_json(
        text,
        &Limits {
            max_particles: 100_000,
            ..Limits::default()
        },
    )
    .unwrap_err();
    assert!(
        err.to_string().contains("particles_through_thickness"),
        "{err}"
    );
    assert!(err.to_string().contains("limit of 100000"), "{err}");
}

/// The fields a rejection names, or a panic if the case was accepted.
fn rejected_fields(text: &str, limits: &Limits) -> Vec<FieldError> {
    match Case::from_json(text, limits) {
        Err(CaseError::Invalid(errors)) => errors,
        Err(e) => panic!("{text}: malformed? {e}"),
        Ok(case) => panic!(
            "{text}: accepted with {} particles, {} steps",
            case.particle_count(),
            case.step_count()
        ),
    }
}

#[test]
fn a_wall_of_1e_300_mm_is_refused_not_counted_as_4_particles() {
    // What broke: the u64 count saturated and wrapped to 4, the case was accepted and the
    // scene tried to build ~2⁶⁴ particles.
    let errors = rejected_fields(r#"{"tube":{"thickness_mm":1e-300}}"#, &Limits::default());
    let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    assert!(named.contains(&"tube.thickness_mm"), "{errors:?}");
    let reason = &errors[0].reason;
    assert!(
        reason.contains("particles") && reason.contains("5000000"),
        "{reason}"
    );
}

#[test]
fn a_kilometre_tube_is_refused_not_counted_as_0_particles() {
    // What broke: 2⁶⁴ particles exactly wrapped to 0.
    let text = r#"{"tube":{"thickness_mm":1,"mean_diameter_mm":1367130551.2,"length_mm":4294967296},"discretization":{"particles_through_thickness":1}}"#;
    let errors = rejected_fields(text, &Limits::unbounded());
    assert!(
        errors
            .iter()
            .any(|e| e.field == "tube.mean_diameter_mm"
                && e.reason.contains("gives 1.84e19 particles")),
        "{errors:?}"
    );
}

#[test]
fn a_1e300_mm_tube_reports_its_count_without_saturating() {
    // What broke: the 422 said "gives 18446744073709551267 particles" (a saturated u64).
    let errors = rejected_fields(r#"{"tube":{"length_mm":1e300}}"#, &Limits::default());
    let reason = &errors
        .iter()
        .find(|e| e.field == "tube.length_mm")
        .unwrap()
        .reason;
    assert!(reason.contains("e30"), "{reason}");
    assert!(!reason.contains("18446744073709551"), "{reason}");
}

#[test]
fn no_limit_admits_more_particles_than_their_u32_ids() {
    // Even unbounded, n = 16 through a 1e-3 mm wall of a 1 m tube is refused.
    let text = r#"{"tube":{"thickness_mm":0.001,"length_mm":1000},"discretization":{"particles_through_thickness":16}}"#;
    let errors = rejected_fields(text, &Limits::unbounded());
    assert!(
        errors[0].reason.contains(&PARTICLE_ID_LIMIT.to_string()),
        "{errors:?}"
    );
}

#[test]
fn a_plate_speed_of_1e_300_is_refused_for_its_steps() {
    // What broke: accepted with an estimate of 1.8e19 steps (a saturated u64).
    let errors = rejected_fields(
        r#"{"loading":{"plate_speed_m_s":1e-300}}"#,
        &Limits::default(),
    );
    let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    for f in [
        "loading.plate_speed_m_s",
        "discretization.cfl",
        "loading.crush_distance_mm",
    ] {
        assert!(named.contains(&f), "{f} not in {named:?}");
    }
    assert!(errors[0].reason.contains("time steps"), "{errors:?}");
    // Unbounded steps still refuses what no u64 can count.
    rejected_fields(
        r#"{"loading":{"plate_speed_m_s":1e-300}}"#,
        &Limits::unbounded(),
    );
}

#[test]
fn extreme_material_values_are_refused_for_their_steps() {
    // What broke: each of these exceeded 1e8 steps and was accepted.
    for text in [
        r#"{"loading":{"plate_speed_m_s":1e-9}}"#,
        r#"{"discretization":{"cfl":5e-324}}"#,
        r#"{"material":{"youngs_modulus_mpa":1e308}}"#,
        r#"{"material":{"density_kg_m3":1e-308}}"#,
    ] {
        let errors = rejected_fields(text, &Limits::default());
        assert!(
            errors
                .iter()
                .all(|e| STEP_FIELDS.contains(&e.field.as_str())),
            "{text}: {errors:?}"
        );
    }
}

#[test]
fn an_infinite_wave_speed_is_refused_not_run_with_a_zero_time_step() {
    // Found by tests/solver/case_fuzz.rs: ρ = 1e-300 gave c = ∞, Δt = 0, and with a crush of
    // 5e-324 mm, 0 / 0 steps, which counted as one: the run would never advance.
    let text = r#"{"material":{"density_kg_m3":1e-300},"loading":{"crush_distance_mm":5e-324}}"#;
    let errors = rejected_fields(text, &Limits::unbounded());
    assert!(
        errors.iter().any(|e| e.field == "material.density_kg_m3"),
        "{errors:?}"
    );
}

#[test]
fn a_crush_shorter_than_a_waves_transit_of_one_cell_is_refused_with_the_bound() {
    // The README's 8 mm tube at 20 m/s, n = 1 (cell 6.4 mm, bar wave 1565 m/s): 0.0818 mm.
    let tiny = |crush: &str| {
        format!(
            r#"{{"tube": {{"thickness_mm": 3.2, "mean_diameter_mm": 22.2, "length_mm": 8}},
                "discretization": {{"particles_through_thickness": 1}},
                "loading": {{"crush_distance_mm": {crush}, "plate_speed_m_s": 20}},
                "output": {{"history_points": 20}}}}"#
        )
    };
    // Run anyway: 650 kN, 6.5e102 N and a non-finite load; 5e-324 underflows the steps.
    for crush in ["1e-3", "1e-100", "1e-200", "5e-324", "0.08"] {
        let errors = rejected_fields(&tiny(crush), &Limits::default());
        assert_eq!(errors.len(), 1, "{crush}: {errors:?}");
        assert_eq!(errors[0].field, "loading.crush_distance_mm");
        assert!(
            errors[0].reason.contains("at least 0.0818 mm"),
            "{errors:?}"
        );
    }
    assert!(Case::from_json(&tiny("0.082"), &Limits::default()).is_ok());
    assert!(Case::from_json(&tiny("1"), &Limits::default()).is_ok());
    // The bound follows the cell and the wave speed: n = 4 quarters it, and so does a
    // material with 16 times the stiffness.
    let finer = tiny("0.03").replace(
        r#""particles_through_thickness": 1"#,
        r#""particles_through_thickness": 4"#,
    );
    assert!(Case::from_json(&finer, &Limits::default()).is_ok());
    let stiff = tiny("0.03").replace(
        r#""output""#,
        r#""material": {"youngs_modulus_mpa": 54054.4}, "output""#,
    );
    assert!(Case::from_json(&stiff, &Limits::default()).is_ok());
    // With a field it needs out of range, that field is named alone.
    let errors = rejected_fields(
        r#"{"loading": {"crush_distance_mm": 1e-9}, "material": {"density_kg_m3": -1}}"#,
        &Limits::default(),
    );
    let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    assert_eq!(named, ["material.density_kg_m3"]);
}

#[test]
fn too_much_work_names_every_field_that_drives_it() {
    let limits = Limits {
        max_particle_steps: 1_000_000,
        ..Limits::default()
    };
    let errors = rejected_fields("{}", &limits);
    let named: Vec<&str> = errors.iter().map(|e| e.field.as_str()).collect();
    for f in PARTICLE_FIELDS.iter().chain(STEP_FIELDS) {
        assert!(named.contains(f), "{f} not in {named:?}");
    }
    assert!(errors[0].reason.contains("particle-steps"), "{errors:?}");
}

/// A reduced model that does not fit the scene is refused with the field and the reason.
#[test]
fn a_reduced_model_must_fit_the_scene() {
    let fields = |text: &str| match Case::from_json(text, &Limits::default()) {
        Err(CaseError::Invalid(errors)) => errors
            .into_iter()
            .map(|e| (e.field, e.reason))
            .collect::<Vec<_>>(),
        other => panic!("{text}: {other:?}"),
    };
    let e =
        fields(r#"{"loading": {"mode": "lateral"}, "discretization": {"model": "axisymmetric"}}"#);
    assert_eq!(e.len(), 1);
    assert_eq!(e[0].0, "discretization.model");
    assert!(e[0].1.contains("not axisymmetric"), "{e:?}");
    let e = fields(r#"{"discretization": {"model": "plane_strain"}}"#);
    assert!(
        e[0].0 == "discretization.model" && e[0].1.contains("lateral"),
        "{e:?}"
    );
    let e = fields(
        r#"{"discretization": {"model": "axisymmetric"}, "trigger": {"weak_fraction": 0.003}}"#,
    );
    let named: Vec<&str> = e.iter().map(|e| e.0.as_str()).collect();
    assert_eq!(named, ["discretization.model", "trigger.weak_fraction"]);
    // 3D stops at n = 16; a section at 64.
    let e = fields(r#"{"discretization": {"particles_through_thickness": 17}}"#);
    assert!(e[0].1.contains("[1, 16]"), "{e:?}");
    let fine =
        r#"{"discretization": {"particles_through_thickness": 64, "model": "axisymmetric"}}"#;
    assert!(Case::from_json(fine, &Limits::default()).is_ok());
    let e = fields(&fine.replace("64", "65"));
    assert!(e[0].1.contains("[1, 64]"), "{e:?}");
}

/// A section's particle count: n layers by the layers along (axisymmetric), the rings of
/// one layer along (plane strain); the scene lays out exactly that many.
#[test]
fn a_section_counts_what_its_scene_lays_out() {
    for (text, want) in [
        (
            r#"{"discretization": {"particles_through_thickness": 6, "model": "axisymmetric"}}"#,
            6 * 143,
        ),
        (
            r#"{"loading": {"mode": "lateral"}, "discretization": {"model": "plane_strain"}}"#,
            0,
        ),
    ] {
        let case = Case::from_json(text, &Limits::default()).unwrap();
        let scene = crate::solver::engine::scene::Scene::from_case(&case);
        assert_eq!(
            scene.particles.len() as u64,
            case.particle_count(),
            "{text}"
        );
        if want > 0 {
            assert_eq!(case.particle_count(), want);
        }
        // The section's volumes add up to the tube's, π·d·t·l.
        let vol: f64 = scene.particles.vol.iter().sum();
        let exact = std::f64::consts::PI * 22.2 * 3.2 * 76.2;
        assert!(
            (vol / exact - 1.0).abs() < 1e-12,
            "{text}: {vol} vs {exact}"
        );
    }
}

#[test]
fn every_example_case_fits_the_default_limits_with_room() {
    // The margins stated on `Limits::default`: an example that needs more than a fifth
    // of a limit fails this, so the default cannot drift down to where examples no longer
    // run at their own resolution.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let limits = Limits::default();
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let case =
            Case::from_json(&text, &limits).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let (p, s) = (case.particle_count(), case.step_count());
        let name = path.display();
        assert!(p * 5 <= limits.max_particles, "{name}: {p} particles");
        assert!(s * 5 <= limits.max_steps, "{name}: {s} steps");
        assert!(p * s * 5 <= limits.max_particle_steps, "{name}: {p} × {s}");
        seen += 1;
    }
    assert!(seen >= 7);
}

#[test]
fn type_errors_and_unknown_fields_name_the_field() {
    let Err(CaseError::Malformed { field, .. }) =
        Case::from_json(r#"{"tube": {"thickness_mm": "thick"}}"#, &Limits::default())
    else {
        panic!()
    };
    assert_eq!(field.as_deref(), Some("tube.thickness_mm"));
    let err = Case::from_json(r#"{"tube": {"wall": 1}}"#, &Limits::default()).unwrap_err();
    assert!(err.to_string().contains("wall"), "{err}");
    assert!(Case::from_json("{", &Limits::default()).is_err());
}

#[test]
fn an_array_or_trailing_text_is_not_a_case() {
    // What broke: `[]` was read as the default case, and `/v1/estimate` took `{} x` and `{}{}`.
    for text in [
        "[]", "[1]", "3", "\"{}\"", "null", "{} x", "{}{}", "{} {}", "{},",
    ] {
        match Case::from_json(text, &Limits::default()) {
            Err(CaseError::Malformed { .. }) => {}
            other => panic!("{text}: {other:?}"),
        }
    }
    assert!(Case::from_json(" {}\n ", &Limits::default()).is_ok());
}

#[test]
fn whole_numbers_written_with_a_point_are_integers() {
    // schemathesis: `"seed": 7163146938.0` is an integer to JSON Schema, and was a 400.
    let text = r#"{"trigger":{"seed":7163146938.0},"output":{"history_points":1000.0},
        "discretization":{"particles_through_thickness":2.0}}"#;
    let case = Case::from_json(text, &Limits::default()).unwrap();
    assert_eq!(case.spec().trigger.seed, 7_163_146_938);
    assert_eq!(case.spec().output.history_points, 1000);
    for bad in [
        r#"{"output":{"history_points":10.5}}"#,
        r#"{"output":{"history_points":-10}}"#,
        r#"{"output":{"history_points":4294967296}}"#,
        r#"{"trigger":{"seed":1e30}}"#,
        r#"{"output":{"history_points":"10"}}"#,
    ] {
        let Err(CaseError::Malformed { field, .. }) = Case::from_json(bad, &Limits::default())
        else {
            panic!("{bad} accepted")
        };
        assert!(field.is_some(), "{bad}");
    }
}

#[test]
fn the_start_ramp_defaults_within_the_crush_and_goes_no_further() {
    let ramp = |text: &str| Case::from_json(text, &Limits::default()).map(|c| c.ramp_mm());
    assert_eq!(ramp("{}").unwrap(), DEFAULT_RAMP_MM);
    assert_eq!(
        ramp(r#"{"loading": {"crush_distance_mm": 0.4}}"#).unwrap(),
        0.2
    );
    assert_eq!(ramp(r#"{"loading": {"ramp_mm": 0}}"#).unwrap(), 0.0);
    for bad in [
        r#"{"loading": {"crush_distance_mm": 2, "ramp_mm": 3}}"#,
        r#"{"loading": {"ramp_mm": -1}}"#,
    ] {
        let err = ramp(bad).unwrap_err();
        assert!(err.to_string().contains("loading.ramp_mm"), "{err}");
    }
}

#[test]
fn lateral_crush_must_fit_in_the_bore() {
    let text = r#"{"loading": {"mode": "lateral", "crush_distance_mm": 30}}"#;
    let err = Case::from_json(text, &Limits::default()).unwrap_err();
    assert!(
        err.to_string().contains("loading.crush_distance_mm"),
        "{err}"
    );
}

#[test]
fn an_error_bar_is_held_with_its_ladder_to_the_limits_and_refused_where_no_ladder_prices_it() {
    let asked = |json: &str, limits: &Limits| {
        Case::from_json(json, limits).map_err(|e| match e {
            CaseError::Invalid(errors) => errors,
            other => panic!("{other:?}"),
        })
    };
    // The paper's tube at n = 1: a cheap run, but its ladder runs the section at n = 1, 8, 12
    // and 16 over the whole crush.
    let tiny = r#"{"discretization": {"particles_through_thickness": 1},
                   "output": {"error_bar": true}}"#;
    let run_alone = Case::from_json(
        r#"{"discretization": {"particles_through_thickness": 1}}"#,
        &Limits::default(),
    )
    .unwrap();
    let own = run_alone.particle_count() * run_alone.step_count();
    let tight = Limits {
        max_particle_steps: 2 * own,
        ..Limits::default()
    };
    assert!(Case::from_json(
        r#"{"discretization": {"particles_through_thickness": 1}}"#,
        &tight
    )
    .is_ok());
    let errors = asked(tiny, &tight).unwrap_err();
    assert_eq!(errors[0].field, "output.error_bar", "{errors:?}");
    assert!(errors[0].reason.contains("particle-steps"), "{errors:?}");
    assert!(asked(tiny, &Limits::default()).is_ok());
    let linear = r#"{"discretization": {"shape": "linear"}, "output": {"error_bar": true}}"#;
    let errors = asked(linear, &Limits::default()).unwrap_err();
    assert!(
        errors[0].reason.contains("linear shape functions"),
        "{errors:?}"
    );
}

#[test]
fn a_series_of_one_frame_or_of_more_than_fifty_is_refused_naming_output_frames() {
    for frames in [1, 51, 1000] {
        let text = format!(r#"{{"output": {{"frames": {frames}}}}}"#);
        let Err(CaseError::Invalid(errors)) = Case::from_json(&text, &Limits::default()) else {
            panic!("accepted {frames} frames")
        };
        assert_eq!(errors.len(), 1, "{errors:?}");
        assert_eq!(errors[0].field, "output.frames");
        assert!(errors[0].reason.contains("[2, 50]"), "{}", errors[0].reason);
    }
    for frames in [0, 2, 50] {
        let text = format!(r#"{{"output": {{"frames": {frames}}}}}"#);
        let case = Case::from_json(&text, &Limits::default()).unwrap();
        assert_eq!(case.spec().output.frames, frames);
    }
}

#[test]
fn a_series_over_ten_million_particle_states_is_refused_with_the_frames_the_case_may_keep() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/axial_t0.76_d19.81.json"
    );
    let mut spec: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let with_frames = |spec: &mut serde_json::Value, frames: u32| {
        spec["output"]["frames"] = frames.into();
        Case::from_json(&spec.to_string(), &Limits::default())
    };
    let case = with_frames(&mut spec, 19).unwrap();
    assert_eq!(case.particle_count(), 525_310);
    let Err(CaseError::Invalid(errors)) = with_frames(&mut spec, 20) else {
        panic!("accepted 20 frames of 525 310 particles")
    };
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].field, "output.frames");
    assert!(
        errors[0].reason.contains("at most 19 frames"),
        "{}",
        errors[0].reason
    );
}

#[test]
fn a_case_without_a_series_serializes_without_the_frames_field() {
    let case = Case::from_json("{}", &Limits::default()).unwrap();
    let json = serde_json::to_value(case.spec()).unwrap();
    assert!(json["output"].get("frames").is_none(), "{json}");
    assert!(crate::solver::model::spec::field_paths().contains(&"output.frames".to_string()));
}

/// A field the default case leaves out of its JSON (mass scaling at 1, an empty test speed or
/// CFL number) is still a field of the case: the form shows it and a sweep may vary it.
#[test]
fn fields_a_default_case_omits_are_still_fields_a_sweep_may_name() {
    let json = serde_json::to_value(CaseSpec::default()).unwrap();
    let paths = crate::solver::model::spec::field_paths();
    for (section, field) in [
        ("discretization", "mass_scaling"),
        ("discretization", "cfl"),
        ("loading", "test_speed_m_s"),
    ] {
        assert!(json[section].get(field).is_none(), "{section}.{field}");
        assert!(
            paths.contains(&format!("{section}.{field}")),
            "{section}.{field}"
        );
    }
}

/// The fields a rectangular tube's case is refused for, in the order the checks name them.
fn rectangular_refusals(tube: &str, rest: &str) -> Vec<(String, String)> {
    let text = format!(r#"{{"tube": {{"section": "rectangular", {tube}}}{rest}}}"#);
    rejected_fields(&text, &Limits::default())
        .into_iter()
        .map(|e| (e.field, e.reason))
        .collect()
}

#[test]
fn a_rectangular_tube_names_each_length_it_lacks_or_cannot_have() {
    let fields = |tube: &str, rest: &str| -> Vec<String> {
        rectangular_refusals(tube, rest)
            .into_iter()
            .map(|(f, _)| f)
            .collect()
    };
    // No side a; a diameter that belongs to a round tube.
    assert_eq!(
        fields(r#""mean_diameter_mm": 20"#, ""),
        ["tube.mean_diameter_mm", "tube.side_a_mm"]
    );
    // A wall as thick as half the smaller side.
    assert_eq!(
        fields(r#""side_a_mm": 40, "side_b_mm": 6, "thickness_mm": 3"#, ""),
        ["tube.thickness_mm"]
    );
    // Corners sharper than t/2 inside, or wider than the smaller side.
    for r in [0.5, 21.0] {
        let refused = rectangular_refusals(
            &format!(r#""side_a_mm": 40, "thickness_mm": 2, "corner_radius_mm": {r}"#),
            "",
        );
        assert_eq!(refused.len(), 1, "r {r}: {refused:?}");
        assert_eq!(refused[0].0, "tube.corner_radius_mm");
    }
    // Negative and non-finite sides.
    assert_eq!(
        fields(r#""side_a_mm": -1, "side_b_mm": 0"#, ""),
        ["tube.side_a_mm", "tube.side_b_mm"]
    );
    // A round tube with a rectangle's lengths.
    let round = rejected_fields(
        r#"{"tube": {"side_a_mm": 40, "corner_radius_mm": 2}}"#,
        &Limits::default(),
    );
    let named: Vec<&str> = round.iter().map(|e| e.field.as_str()).collect();
    assert_eq!(named, ["tube.side_a_mm", "tube.corner_radius_mm"]);
    // The axisymmetric model has no rectangle to revolve; a lateral crush past the bore
    // between the plates (b − t = 28 mm).
    let refused = fields(
        r#""side_a_mm": 40, "side_b_mm": 30, "thickness_mm": 2"#,
        r#", "discretization": {"model": "axisymmetric"}"#,
    );
    assert!(
        refused.contains(&"discretization.model".to_string())
            && refused.contains(&"tube.section".to_string()),
        "{refused:?}"
    );
    let past = rectangular_refusals(
        r#""side_a_mm": 40, "side_b_mm": 30, "thickness_mm": 2"#,
        r#", "loading": {"mode": "lateral", "crush_distance_mm": 27}"#,
    );
    assert_eq!(past.len(), 1, "{past:?}");
    assert_eq!(past[0].0, "loading.crush_distance_mm");
    assert!(
        past[0].1.contains("side_b_mm - thickness_mm"),
        "{}",
        past[0].1
    );
}

#[test]
fn a_square_tube_prices_its_particles_by_its_sides() {
    let limits = Limits {
        max_particles: 1000,
        ..Limits::default()
    };
    let refused = rejected_fields(
        r#"{"tube": {"section": "rectangular", "side_a_mm": 40, "thickness_mm": 1.5}}"#,
        &limits,
    );
    let named: Vec<&str> = refused.iter().map(|e| e.field.as_str()).collect();
    assert!(named.contains(&"tube.side_a_mm") && named.contains(&"tube.side_b_mm"));
    assert!(!named.contains(&"tube.mean_diameter_mm"));
    assert!(
        refused[0].reason.contains("side_a_mm + side_b_mm"),
        "{}",
        refused[0].reason
    );
}

/// What broke: a thickness in metres typed as millimetres (0.0032) was refused for its steps
/// with `loading.plate_speed_m_s` named first, the same reason on nine fields.
#[test]
fn a_cost_over_its_limit_names_the_field_that_drives_it_first_with_its_value() {
    let thin = r#"{"tube": {"thickness_mm": 0.0032}, "discretization": {"model": "axisymmetric"}}"#;
    let errors = rejected_fields(thin, &Limits::default());
    assert_eq!(errors[0].field, "tube.thickness_mm", "{errors:?}");
    let lead = &errors[0].reason;
    assert!(
        lead.starts_with("0.0032 mm gives 15843860 time steps, more than this runner's limit"),
        "{lead}"
    );
    assert!(
        lead.contains("at its default, 3.2 mm, they would be 15844"),
        "{lead}"
    );
    // The other fields that set the steps are named once each, briefly.
    for e in &errors[1..] {
        assert!(STEP_FIELDS.contains(&e.field.as_str()), "{errors:?}");
        assert!(
            e.reason.starts_with("also sets the time steps"),
            "{errors:?}"
        );
    }
    assert_eq!(errors.len(), STEP_FIELDS.len(), "{errors:?}");
    // Within the steps, the particle-steps: the thickness again.
    let limits = Limits {
        max_steps: u64::MAX,
        ..Limits::default()
    };
    let errors = rejected_fields(thin, &limits);
    assert_eq!(errors[0].field, "tube.thickness_mm", "{errors:?}");
    assert!(
        errors[0]
            .reason
            .contains("particle-steps (381000 particles × 15843860 time steps)"),
        "{errors:?}"
    );
    // A crawling plate leads the steps, a long tube the particles.
    let slow = rejected_fields(
        r#"{"loading": {"plate_speed_m_s": 0.001}}"#,
        &Limits::default(),
    );
    assert_eq!(slow[0].field, "loading.plate_speed_m_s", "{slow:?}");
    let long = rejected_fields(
        r#"{"tube": {"length_mm": 20000}, "loading": {"crush_distance_mm": 10}}"#,
        &Limits::default(),
    );
    assert_eq!(long[0].field, "tube.length_mm", "{long:?}");
    assert!(long[0].reason.contains("particles"), "{long:?}");
}

#[test]
fn mass_scaling_outside_1_to_100_is_refused_and_within_it_cuts_the_steps_by_its_root() {
    for bad in ["0.5", "101", "-4", "0"] {
        let text = format!(r#"{{"discretization": {{"mass_scaling": {bad}}}}}"#);
        let Err(CaseError::Invalid(errors)) = Case::from_json(&text, &Limits::default()) else {
            panic!("accepted mass scaling {bad}")
        };
        assert!(
            errors
                .iter()
                .any(|e| e.field == "discretization.mass_scaling"),
            "{bad}: {errors:?}"
        );
    }
    let steps = |f: f64| {
        let text = format!(r#"{{"discretization": {{"mass_scaling": {f}}}}}"#);
        Case::from_json(&text, &Limits::default())
            .unwrap()
            .step_count() as f64
    };
    for f in [4.0, 16.0, 100.0] {
        let ratio = steps(1.0) / steps(f);
        // Δt = α·cell / (c/√f + v): the plate's 10 m/s beside c/√f keeps the gain a little
        // under √f (c is 2 400 m/s for the paper's PVC, so under 1 % at f = 16, 4 % at 100).
        assert!(
            ratio <= f.sqrt() && ratio > 0.95 * f.sqrt(),
            "f {f}: steps fell {ratio:.3} times"
        );
    }
}

#[test]
fn a_plate_over_half_the_mass_scaled_wave_speed_is_refused_naming_the_scaling() {
    // The paper's PVC: c ≈ 2 400 m/s, so half of it under f = 100 is about 120 m/s.
    let text = r#"{"discretization": {"mass_scaling": 100}, "loading": {"plate_speed_m_s": 200}}"#;
    let Err(CaseError::Invalid(errors)) = Case::from_json(text, &Limits::default()) else {
        panic!("accepted a plate faster than half the scaled wave speed")
    };
    let e = errors
        .iter()
        .find(|e| e.field == "loading.plate_speed_m_s")
        .expect("the plate speed named");
    assert!(e.reason.contains("mass scaling 100"), "{}", e.reason);
}
