use super::*;
use crate::solver::model::case::{spec_from_json, HOLDING_FRICTION};

fn option(model: Model, n: u32, error: Option<f64>, wall_time_s: f64) -> PlanOption {
    PlanOption {
        model,
        shape: ShapeKind::Gimp,
        n,
        particles: 1,
        steps: 1,
        expected_error_percent: error,
        error_guide: String::new(),
        wall_time_s,
        wall_time_basis: RateBasis::Assumed,
        shows: String::new(),
    }
}

fn options() -> Vec<PlanOption> {
    vec![
        option(Model::ThreeD, 4, Some(11.6), 40.0),
        option(Model::ThreeD, 6, Some(6.3), 200.0),
        option(Model::ThreeD, 8, Some(2.1), 650.0),
        option(Model::ThreeD, 10, Some(1.1), 1600.0),
        option(Model::ThreeD, 12, None, 10.0),
        option(Model::Axisymmetric, 16, Some(0.4), 60.0),
    ]
}

#[test]
fn a_target_is_met_by_the_cheapest_option_of_the_cases_own_model() {
    let options = options();
    let (p, why) = pick(&options, Model::ThreeD, Goal::TargetErrorPercent(5.0));
    let p = p.unwrap();
    // n = 10 meets it too, and the section meets it for less: neither is the pick.
    assert_eq!((p.model, p.n), (Model::ThreeD, 8), "{why}");
    assert!(why.contains("n = 8"), "{why}");
    let (p, _) = pick(&options, Model::ThreeD, Goal::TargetErrorPercent(10.0));
    assert_eq!(p.unwrap().n, 6);
}

#[test]
fn a_budget_is_met_by_the_most_accurate_option_that_fits() {
    let options = options();
    let (p, why) = pick(&options, Model::ThreeD, Goal::BudgetS(700.0));
    assert_eq!(p.unwrap().n, 8, "{why}");
    // The option with no known error is never picked, however cheap.
    let (p, _) = pick(&options, Model::ThreeD, Goal::BudgetS(45.0));
    assert_eq!(p.unwrap().n, 4);
}

#[test]
fn when_no_option_meets_the_goal_the_plan_says_so() {
    let options = options();
    let (p, why) = pick(&options, Model::ThreeD, Goal::TargetErrorPercent(0.5));
    assert!(p.is_none());
    assert!(why.contains("±0.5 %") && why.contains("n = 10"), "{why}");
    let (p, why) = pick(&options, Model::ThreeD, Goal::BudgetS(5.0));
    assert!(p.is_none());
    assert!(why.contains("5 s") && why.contains("n = 4"), "{why}");
    let (p, why) = pick(&options, Model::PlaneStrain, Goal::BudgetS(5.0));
    assert!(p.is_none() && why.contains("plane strain"), "{why}");
}

#[test]
fn expected_errors_are_the_tables_and_in_between_interpolated() {
    let e = |n| expected_error_percent(LoadingMode::Axial, Model::ThreeD, ShapeKind::Gimp, n);
    assert_eq!(e(8), Some(2.1));
    assert_eq!(e(16), Some(1.1));
    let seven = e(7).unwrap();
    assert!(seven < 6.3 && seven > 2.1, "{seven}");
    assert_eq!(
        expected_error_percent(LoadingMode::Axial, Model::ThreeD, ShapeKind::Linear, 8),
        None
    );
}

/// The plan on two threads at the assumed rates, without limits, of the case `text`.
fn plan_of(text: &str, goal: Goal) -> Plan {
    let case = Case::parse(spec_from_json(text).unwrap(), &Limits::unbounded()).unwrap();
    plan(&case, goal, 2, &Rates::assumed(), &Limits::unbounded())
}

fn paper_case(model: &str) -> Case {
    let text = format!(
        r#"{{"loading": {{"crush_distance_mm": 50}}, "discretization": {{"model": "{model}"}}}}"#
    );
    Case::parse(spec_from_json(&text).unwrap(), &Limits::unbounded()).unwrap()
}

#[test]
fn the_paper_case_at_five_percent_runs_3d_at_n_8_and_lists_its_section() {
    let case = paper_case("3d");
    let p = plan(
        &case,
        Goal::TargetErrorPercent(5.0),
        2,
        &Rates::assumed(),
        &Limits::unbounded(),
    );
    let pick = p.pick.as_ref().unwrap();
    assert_eq!(
        (pick.model, pick.shape, pick.n),
        (Model::ThreeD, ShapeKind::Gimp, 8)
    );
    assert_eq!(p.target_error_percent, Some(5.0));
    assert!(p
        .options
        .iter()
        .any(|o| o.model == Model::Axisymmetric && o.shows.starts_with("rings only")));
    assert!(p
        .options
        .iter()
        .any(|o| o.shape == ShapeKind::Linear && o.expected_error_percent.is_none()));
    assert_eq!(p.refused, 0);
    // Wall times grow with n within a model and shape.
    let walls: Vec<f64> = p
        .options
        .iter()
        .filter(|o| o.model == Model::ThreeD && o.shape == ShapeKind::Gimp)
        .map(|o| o.wall_time_s)
        .collect();
    assert!(walls.windows(2).all(|w| w[0] < w[1]), "{walls:?}");
}

#[test]
fn options_past_the_runners_limits_are_left_out_and_counted() {
    let case = paper_case("3d");
    let limits = Limits {
        max_particles: 120_000,
        ..Limits::unbounded()
    };
    let p = plan(&case, Goal::BudgetS(1e6), 1, &Rates::assumed(), &limits);
    assert!(p.options.iter().all(|o| o.particles <= 120_000));
    // 3D n = 8 and 10, each with both shape functions.
    assert_eq!(p.refused, 4);
    assert_eq!(p.pick.unwrap().n, 6);
}

#[test]
fn a_case_with_a_trigger_has_no_section_options() {
    let text = r#"{"trigger": {"weak_fraction": 0.1}}"#;
    let p = plan_of(text, Goal::BudgetS(60.0));
    assert!(p.options.iter().all(|o| o.model == Model::ThreeD));
}

#[test]
fn a_thin_walls_3d_ugimp_options_warn_of_tipping_over_on_slippery_plates_only() {
    let tip = |friction: f64| {
        let text = format!(
            r#"{{"tube": {{"thickness_mm": 1.27, "mean_diameter_mm": 20.32}},
                "contact": {{"friction": {friction}}}}}"#
        );
        let p = plan_of(&text, Goal::BudgetS(60.0));
        p.options
            .iter()
            .filter(|o| o.model == Model::ThreeD && o.shape == ShapeKind::Gimp)
            .map(|o| o.shows.contains("tip over"))
            .collect::<Vec<_>>()
    };
    let slippery = tip(0.02);
    assert!(!slippery.is_empty() && slippery.iter().all(|&t| t));
    // From HOLDING_FRICTION on the plates hold the ends: no warning.
    assert!(tip(HOLDING_FRICTION).iter().all(|&t| !t));
    assert!(tip(0.3).iter().all(|&t| !t));
}

/// The d/t 14 tube on a platen: its uGIMP and linear options have no guide (uGIMP's load
/// alternates with the parity of n), its B-spline options read their own study, and a 5 %
/// target picks B-splines at n = 4, the first n the study puts within it.
#[test]
fn a_thin_wall_s_plan_offers_b_splines_and_picks_them_for_a_five_percent_target() {
    let text = r#"{"tube": {"thickness_mm": 3.2, "mean_diameter_mm": 44.8, "length_mm": 125.4},
        "loading": {"crush_distance_mm": 60}, "contact": {"friction": 0.3},
        "trigger": {"weak_fraction": 0.003}}"#;
    let p = plan_of(text, Goal::TargetErrorPercent(5.0));
    for o in &p.options {
        match o.shape {
            ShapeKind::Bspline => assert!(o.expected_error_percent.is_some(), "{o:?}"),
            _ => assert_eq!(o.expected_error_percent, None, "{o:?}"),
        }
    }
    let pick = p.pick.expect("a pick");
    assert_eq!(
        (pick.shape, pick.n),
        (ShapeKind::Bspline, 4),
        "{}",
        p.reason
    );
}

/// An aluminium tube of d/t 29 is far from the studied PVC tube: no option quotes an expected
/// error, each says why in itself, and the plan picks none rather than borrow the PVC figure.
#[test]
fn a_case_far_from_the_studies_has_no_measured_guide_in_each_option() {
    let text = r#"{"material": {"preset": "aa6060_t5"},
        "tube": {"thickness_mm": 1.67, "mean_diameter_mm": 48.33, "length_mm": 100}}"#;
    let p = plan_of(text, Goal::TargetErrorPercent(5.0));
    assert!(!p.options.is_empty());
    for o in &p.options {
        assert_eq!(o.expected_error_percent, None, "{o:?}");
        assert!(o.error_guide.starts_with("no measured guide: "), "{o:?}");
    }
    assert!(p.pick.is_none(), "{}", p.reason);
    // The paper's tube keeps its guide.
    let paper = plan(
        &paper_case("3d"),
        Goal::TargetErrorPercent(5.0),
        2,
        &Rates::assumed(),
        &Limits::unbounded(),
    );
    assert!(paper
        .options
        .iter()
        .any(|o| o.expected_error_percent.is_some() && o.error_guide.starts_with("expected")));
}
