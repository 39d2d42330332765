//! Helpers shared by the test modules.

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{library, stack, ChordTolerance, Design, ParamError};

/// Every library design and every preset of each.
pub fn library_designs_and_presets() -> Vec<Design> {
    let mut designs = Vec::new();
    for (name, _) in library::LIBRARY {
        let base = library::load(name).unwrap();
        for p in base.presets.keys() {
            designs.push(base.with_preset(p).unwrap());
        }
        designs.push(base);
    }
    designs
}

/// The errors of `validate` for `d` at the default tolerance (empty when valid).
pub fn validation_errors(d: &Design) -> Vec<ParamError> {
    let materials = MaterialsTable::embedded().unwrap();
    match stack::validate(d, &materials, ChordTolerance::default()) {
        Ok(_) => Vec::new(),
        Err(e) => e.0,
    }
}

/// The parameter errors that stop `build_kit` for `d` at 0.01 mm; panics when it builds or
/// fails otherwise.
pub fn build_error(d: &Design) -> fabkit_designs::ParamErrors {
    match fabkit_designs::build_kit(d, ChordTolerance::new(0.01).unwrap()) {
        Err(fabkit_designs::DesignError::Params(e)) => e,
        other => panic!("{:?}", other.map(|k| k.design)),
    }
}

/// The paths of the rules `d` breaks, as `build_kit` at 0.01 mm reports them; panics, naming
/// `what`, when it builds or fails otherwise.
pub fn refused_paths(d: &Design, what: &str) -> Vec<String> {
    match fabkit_designs::build_kit(d, ChordTolerance::new(0.01).unwrap()) {
        Err(fabkit_designs::DesignError::Params(e)) => e.0.iter().map(|x| x.path.clone()).collect(),
        other => panic!("{what}: {:?}", other.map(|k| k.design)),
    }
}

/// The overlap's volume in a fit-check error's rule ("overlap by V mm³").
pub fn overlap(rule: &str) -> f64 {
    rule.split("overlap by ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{rule}"))
}

/// `d` does not build: one error naming `path` = `value` and the interference of `pair`
/// ("`a` and `b`"), whose overlap is within `rel` of the analytic `want` mm³, its rule naming
/// each of `also`.
pub fn assert_one_interference(
    d: &Design,
    (path, value): (&str, &str),
    pair: &str,
    also: &[&str],
    want: f64,
    rel: f64,
) {
    let e = build_error(d);
    assert_eq!(e.0.len(), 1, "{e}");
    let got = overlap(&e.0[0].rule);
    assert!(
        e.0[0].path == path
            && e.0[0].value == value
            && e.0[0].rule.contains(&format!("{pair} overlap by"))
            && also.iter().all(|a| e.0[0].rule.contains(a))
            && (got - want).abs() <= rel * want,
        "{e} (analytic {want})"
    );
}

/// A bad value and the parameter path it must be refused by.
pub type RuleCase = (&'static str, fn(&mut Design));

/// For each case, `base()` mutated: validation names the case's path (among any others the
/// value breaks) with its value and a rule, and `build_kit` refuses it.
pub fn assert_each_rule_names_its_path(base: fn() -> Design, cases: &[RuleCase]) {
    let materials = MaterialsTable::embedded().unwrap();
    let tol = ChordTolerance::new(0.01).unwrap();
    for (path, mutate) in cases {
        let mut d = base();
        mutate(&mut d);
        let e = match stack::validate(&d, &materials, tol) {
            Err(e) => e,
            Ok(_) => panic!("{path}: validates"),
        };
        assert!(
            e.0.iter()
                .any(|x| x.path == *path && !x.rule.is_empty() && !x.value.is_empty()),
            "{path}: {e}"
        );
        assert!(
            matches!(
                fabkit_designs::build_kit(&d, tol),
                Err(fabkit_designs::DesignError::Params(_))
            ),
            "{path}"
        );
    }
}

/// The seed set of the seeded tests (`FABKIT_TEST_SEED_SET`, 0 unless set; `.ci/run` cycles
/// 0, 1 and 2): their seeds start at `1000 x set`, so a bound must hold on every set.
pub fn seed_set() -> u64 {
    let set = std::env::var("FABKIT_TEST_SEED_SET").ok();
    set.and_then(|s| s.parse().ok()).unwrap_or(0)
}
