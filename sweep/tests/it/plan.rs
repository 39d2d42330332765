//! Planning large sweeps: the variant count comes first (a sweep of too many variants is
//! refused before any value is looked at), and the ids planned without resolving each design
//! are those of the resolved designs.

use fabkit_designs::library;
use fabkit_sweep::*;
use serde_json::Value;
use std::path::Path;
use std::sync::Mutex;

const SPACING: &str = "layers[0].markers[0].pattern.spacing_mm";
const HEIGHT: &str = "layers[0].markers[0].feature.height_mm";

fn parse(text: &str) -> Result<SweepSpec, SweepError> {
    SweepSpec::parse(text, "sweep.yaml", Path::new(""))
}

/// ShadowTac (preset `paper_text`) with `vary` (YAML lines, indented) and `rest`.
fn sweep(vary: &str, rest: &str) -> String {
    format!("base: shadowtac\npreset: paper_text\nvary:\n{vary}{rest}")
}

/// The ids of `plan`'s variants as resolving each variant's design gives them.
fn resolved_ids(s: &SweepSpec, plan: &Plan) -> Vec<String> {
    plan.variants
        .iter()
        .map(|v| variant_id(&s.resolve(&v.params).unwrap(), s.chord_tolerance.mm()))
        .collect()
}

fn ids(plan: &Plan) -> Vec<String> {
    plan.variants.iter().map(|v| v.id.clone()).collect()
}

/// `n` numbers of a paths' parameter from `paths` (numbers of the design), each with 1000
/// values: a grid of 1000^n variants.
fn grid_of_thousands(n: usize) -> String {
    let d = library::load("shadowtac")
        .unwrap()
        .with_preset("paper_text")
        .unwrap();
    let json = serde_json::to_value(&d).unwrap();
    let numbers: Vec<String> = parameter_paths(&d)
        .into_iter()
        .filter(|p| {
            let ptr = format!("/{}", p.replace(['.', '['], "/").replace(']', ""));
            json.pointer(&ptr).is_some_and(Value::is_f64)
        })
        .take(n)
        .collect();
    assert_eq!(numbers.len(), n);
    let vary: String = numbers
        .iter()
        .map(|p| format!("  {p}: {{range: [1, 1000, 1]}}\n"))
        .collect();
    sweep(&vary, "")
}

#[test]
fn a_grid_of_1e21_variants_is_refused_by_its_count_before_any_value_is_checked() {
    // seven parameters of 1000 values: 10^21 variants. Counted first, so the refusal does not
    // set 7000 values into the design nor build the probes of each parameter.
    let e = parse(&grid_of_thousands(7)).unwrap_err().to_string();
    assert!(
        e.contains("the sweep has 1000000000000000000000 variants")
            && e.contains("1000 x 1000 x 1000 x 1000 x 1000 x 1000 x 1000")
            && e.contains(&format!("more than the {MAX_VARIANTS} allowed")),
        "{e}"
    );
}

#[test]
fn a_grid_whose_count_overflows_is_refused_as_such() {
    // 1000^14 = 10^42 > 2^128
    let e = parse(&grid_of_thousands(14)).unwrap_err().to_string();
    assert!(
        e.contains("more than 2^128 variants (the product overflows)")
            && e.contains(&format!("more than the {MAX_VARIANTS} allowed")),
        "{e}"
    );
}

#[test]
fn the_variant_count_is_the_product_of_the_numbers_of_values() {
    let s = parse(&sweep(
        &format!(
            "  {SPACING}: [1.3, 1.4, 1.5]\n  {HEIGHT}: [0.3, 0.4, 0.5, 0.6]\n  name: [a, b, c, d, e]\n"
        ),
        "",
    ))
    .unwrap();
    let n = variant_count(&s.parameters, s.mode, s.count, "sweep.yaml").unwrap();
    assert_eq!(n, 3 * 4 * 5);
    let plan = s.plan().unwrap();
    assert_eq!(plan.variants.len() as u64, n);
    // zip: the length of the lists; random: count
    assert_eq!(
        variant_count(&s.parameters[..1], Mode::Zip, None, "sweep.yaml").unwrap(),
        3
    );
    assert_eq!(
        variant_count(&s.parameters, Mode::Random, Some(7), "sweep.yaml").unwrap(),
        7
    );
    // the grid's ids are those of the resolved designs, with a text parameter among numbers
    assert_eq!(ids(&plan), resolved_ids(&s, &plan));
}

#[test]
fn a_long_list_plans_every_value_in_order_with_the_ids_of_the_resolved_designs() {
    let n = 3000;
    let values: Vec<String> = (0..n)
        .map(|k| format!("{}", 1.3 + k as f64 * 1e-5))
        .collect();
    let s = parse(&sweep(
        &format!("  {SPACING}: [{}]\n", values.join(", ")),
        "",
    ))
    .unwrap();
    let calls = Mutex::new(Vec::new());
    let plan = s
        .plan_with_progress(&|done, total| calls.lock().unwrap().push((done, total)))
        .unwrap();
    assert_eq!(plan.variants.len(), n);
    for (k, v) in plan.variants.iter().enumerate() {
        assert_eq!(v.index, k);
        assert_eq!(
            v.params,
            vec![(SPACING.to_string(), s.parameters[0].values[k].clone())]
        );
    }
    assert_eq!(ids(&plan), resolved_ids(&s, &plan));
    // progress: the same total, counts that never decrease, ending with every variant
    let calls = calls.into_inner().unwrap();
    assert!(calls.len() >= 2, "{calls:?}");
    assert!(calls.iter().all(|&(_, t)| t == n));
    assert!(calls.windows(2).all(|w| w[0].0 <= w[1].0), "{calls:?}");
    assert_eq!(calls.last(), Some(&(n, n)));
}

#[test]
fn a_grid_plans_the_ids_of_the_resolved_designs_in_grid_order() {
    let spacing: Vec<String> = (0..30)
        .map(|k| format!("{}", 1.3 + k as f64 * 0.01))
        .collect();
    let height: Vec<String> = (0..40)
        .map(|k| format!("{}", 0.3 + k as f64 * 0.005))
        .collect();
    let s = parse(&sweep(
        &format!(
            "  {SPACING}: [{}]\n  {HEIGHT}: [{}]\n",
            spacing.join(", "),
            height.join(", ")
        ),
        "",
    ))
    .unwrap();
    let plan = s.plan().unwrap();
    assert_eq!(plan.variants.len(), 1200);
    for (k, v) in plan.variants.iter().enumerate() {
        assert_eq!(v.params[0].1, s.parameters[0].values[k / 40]);
        assert_eq!(v.params[1].1, s.parameters[1].values[k % 40]);
    }
    assert_eq!(ids(&plan), resolved_ids(&s, &plan));
    // zip and random give the ids of the same points
    let zip = parse(&sweep(
        &format!(
            "  {SPACING}: [{}]\n  {HEIGHT}: [{}]\n",
            spacing.join(", "),
            height[..30].join(", ")
        ),
        "mode: zip\n",
    ))
    .unwrap();
    let zplan = zip.plan().unwrap();
    assert_eq!(ids(&zplan), resolved_ids(&zip, &zplan));
    let random = parse(&sweep(
        &format!(
            "  {SPACING}: [{}]\n  {HEIGHT}: [{}]\n",
            spacing.join(", "),
            height.join(", ")
        ),
        "mode: random\ncount: 100\nseed: 3\n",
    ))
    .unwrap();
    let rplan = random.plan().unwrap();
    assert_eq!(ids(&rplan), resolved_ids(&random, &rplan));
}

#[test]
fn parameters_checked_as_a_whole_are_resolved_one_by_one_with_the_same_ids() {
    // two parameters of the body, whose YAML form is checked as a whole
    let s = parse(&sweep(
        "  body.base_diameter_mm: [34.0, 35.0]\n  body.height_mm: [7.5, 8.0]\n",
        "",
    ))
    .unwrap();
    let plan = s.plan().unwrap();
    assert_eq!(plan.variants.len(), 4);
    assert_eq!(ids(&plan), resolved_ids(&s, &plan));
}

#[test]
fn repeats_in_long_lists_are_found() {
    // the same number twice, and an integer and a float that resolve to the same design
    let mut values: Vec<String> = (0..2000)
        .map(|k| format!("{}", 1.3 + k as f64 * 1e-5))
        .collect();
    values[1500] = values[700].clone();
    let e = parse(&sweep(
        &format!("  {SPACING}: [{}]\n", values.join(", ")),
        "",
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains(&format!("the value {} is listed twice", values[700])),
        "{e}"
    );
    let e = parse(&sweep(&format!("  {HEIGHT}: [0.4, 1, 1.0]\n"), ""))
        .unwrap()
        .plan()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("variants 1 and 2 resolve to the same design"),
        "{e}"
    );
}

/// Issue 95: a non-finite number in a sweep file was refused as "non-finite float `.nan`
/// rejected by the configured policy". Each spelling of one is refused at its file:line:col
/// with the rule in words.
#[test]
fn a_non_finite_value_is_refused_in_words_at_its_place() {
    for bad in [".nan", ".inf", "-.inf", "1e999"] {
        let e = parse(&sweep(&format!("  {SPACING}: [1.4, {bad}]\n"), ""))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("sweep.yaml:4:")
                && e.contains(&format!(
                    "`{bad}` is not a finite number: every number in a fabkit input must be finite"
                ))
                && !e.contains("policy"),
            "{bad}: {e}"
        );
    }
}

/// The splice (ids without resolving each design) is what plans numbers and text; two
/// parameters of the body are resolved one by one.
#[test]
fn numbers_and_text_are_spliced_and_the_body_is_resolved() {
    let s = parse(&sweep(
        &format!("  {SPACING}: [1.3, 1.4]\n  {HEIGHT}: [0.4, 0.5]\n  name: [a, b]\n"),
        "",
    ))
    .unwrap();
    let json = serde_json::to_value(&s.base.design).unwrap();
    assert_eq!(splice_pieces(&s, &json), Some(4));
    assert!(takes_any_number(&json, SPACING));
    assert!(!takes_any_number(&json, "name"));
    let body = parse(&sweep(
        "  body.base_diameter_mm: [34.0, 35.0]\n  body.height_mm: [7.5, 8.0]\n",
        "",
    ))
    .unwrap();
    assert_eq!(splice_pieces(&body, &json), None);
}
