//! Errors name the parameter that produced them: each rule reports under the path of the value
//! it checks, and a list reports every bad entry.

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{library, stack, ChordTolerance, Design, ParamError};

fn errors(d: &Design) -> Vec<ParamError> {
    crate::common::validation_errors(d)
}

/// The camera's mount pilots and the joint screw's pilots are separate holes: a camera pilot
/// below the FDM profile's minimum hole is reported under its own path (it was reported under
/// the joint screw's).
#[test]
fn each_pilot_hole_is_reported_under_its_own_path() {
    let base = library::load("rtac0").unwrap();
    for preset in [None, Some("square_split")] {
        let mut d = match preset {
            Some(p) => base.with_preset(p).unwrap(),
            None => base.clone(),
        };
        d.housing.as_mut().unwrap().camera.mount_pilot_diameter_mm = 0.2;
        let errs = errors(&d);
        assert!(
            errs.iter()
                .any(|e| e.path == "housing.camera.mount_pilot_diameter_mm"
                    && e.value == "0.2"
                    && e.rule.contains("below the minimum hole")),
            "{preset:?}: {errs:?}"
        );
        assert!(
            errs.iter()
                .all(|e| e.path != "housing.joint_screw.pilot_diameter_mm"),
            "{preset:?}: {errs:?}"
        );
    }
}

/// A marker point list reports every malformed row with its line (it reported the first only),
/// and a byte order mark (spreadsheet "CSV UTF-8") reads as the same table without one.
#[test]
fn every_bad_row_of_a_point_list_is_reported() {
    use fabkit_designs::schema::parse_angle_csv;
    let text =
        "polar_deg, azimuth_deg\n0, 0\n10, x\n20\n# a comment\n30, 40, 50\nfoo, bar\n40, 90\n";
    let e = parse_angle_csv(text, "pts.csv").unwrap_err().to_string();
    for line in [3, 4, 6, 7] {
        assert!(
            e.contains(&format!("pts.csv:{line}: expected two numbers")),
            "line {line}: {e}"
        );
    }
    assert_eq!(e.lines().count(), 4, "{e}");
    let many: String = (0..30).map(|i| format!("{i}, x\n")).collect();
    let e = parse_angle_csv(&many, "m.csv").unwrap_err().to_string();
    assert!(
        e.lines().count() == 21 && e.ends_with("m.csv: and 10 more malformed rows"),
        "{e}"
    );
    let plain = "polar_deg, azimuth_deg\n0, 0\n10, 90\n";
    assert_eq!(
        parse_angle_csv(&format!("\u{feff}{plain}"), "bom.csv").unwrap(),
        parse_angle_csv(plain, "plain.csv").unwrap()
    );
}

/// A `list` pattern reports every point that cannot be placed, each under its own index (the
/// first was reported only).
#[test]
fn every_bad_point_of_a_list_pattern_is_reported() {
    let mut d = library::load("tactip_dualmodal").unwrap();
    let p = &mut d.layers[0].markers[0].pattern;
    p.layout = fabkit_designs::markers::Layout::List;
    p.spacing_mm = None;
    p.rings = None;
    p.polar_step_deg = None;
    p.points = Some(vec![
        [0.0, 0.0],
        [-5.0, 0.0],
        [20.0, 90.0],
        [170.0, 0.0],
        [-0.5, 10.0],
        [30.0, 180.0],
        [95.0, 0.0],
    ]);
    let errs = errors(&d);
    let bad: Vec<(&str, &str)> = errs
        .iter()
        .filter_map(|e| {
            e.path
                .strip_prefix("layers[0].markers[0].pattern.")
                .map(|f| (f, e.rule.as_str()))
        })
        .collect();
    assert_eq!(
        bad,
        [
            (
                "points[1]",
                "polar angle must be >= 0 and both angles finite"
            ),
            ("points[3]", "lies outside the patterned region"),
            (
                "points[4]",
                "polar angle must be >= 0 and both angles finite"
            ),
            ("points[6]", "lies outside the patterned region"),
        ],
        "{errs:?}"
    );
    // a NaN row is listed with the others, not alone (it was the only one listed)
    let mut with_nan = d.clone();
    let pts = with_nan.layers[0].markers[0]
        .pattern
        .points
        .as_mut()
        .unwrap();
    pts[2] = [f64::NAN, 90.0];
    let errs = errors(&with_nan);
    let rows: Vec<&str> = errs
        .iter()
        .filter_map(|e| e.path.strip_prefix("layers[0].markers[0].pattern."))
        .collect();
    assert_eq!(
        rows,
        [
            "points[1]",
            "points[2]",
            "points[3]",
            "points[4]",
            "points[6]"
        ],
        "{errs:?}"
    );
}

/// Scalars are taken as written: a number or a boolean where text is expected, a quoted number
/// where a number is expected, a YAML 1.1 boolean and an unknown tag are refused by location or
/// by path (an integer layer name, a boolean description and a quoted "25" were converted, and
/// a `!!python/object/apply` tag was ignored).
#[test]
fn lenient_scalars_and_unknown_tags_are_refused() {
    let text = library::yaml("rtac0").unwrap();
    let first = |from: &str, to: &str| {
        assert!(text.contains(from), "{from}");
        text.replacen(from, to, 1)
    };
    let layer = text
        .lines()
        .find(|l| l.trim_start().starts_with("- name: "))
        .unwrap();
    let description = text
        .lines()
        .find(|l| l.starts_with("description: "))
        .unwrap();
    let radius = text
        .lines()
        .find(|l| l.trim_start().starts_with("radius_mm: "))
        .unwrap();
    let value = radius.split_whitespace().nth(1).unwrap();
    for (case, yaml, words) in [
        (
            "an integer layer name",
            first(layer, "  - name: 25"),
            "The string value [25] must be quoted".to_string(),
        ),
        (
            "a boolean description",
            first(description, "description: true"),
            "x.yaml:7:14: The string value [true] must be quoted".into(),
        ),
        (
            "a quoted number",
            first(radius, &radius.replacen(value, "\"25\"", 1)),
            "x.yaml:12:14: body.radius_mm = \"25\": a number must be written without quotes".into(),
        ),
        (
            "an unknown tag",
            first(
                description,
                "description: !!python/object/apply:os.system [\"ls\"]",
            ),
            "unsupported tag `!!python/object/apply:os.system`".into(),
        ),
    ] {
        let e = Design::from_yaml(&yaml, "x.yaml").unwrap_err().to_string();
        assert!(
            e.starts_with("x.yaml:") && e.contains(&words),
            "{case}: {e}"
        );
    }
    // quoted, the same texts are text
    let quoted = first(layer, "  - name: \"gel25\"");
    assert!(Design::from_yaml(&quoted, "x.yaml").is_ok());
}

/// A quoted number is refused at its own file:line:column wherever it is written: the same key
/// with the same quoted value on several lines (each layer's `thickness_mm: "1.5"`), and in a
/// flow mapping.
#[test]
fn each_quoted_number_is_refused_at_its_own_location() {
    let text = library::yaml("uvdtact").unwrap();
    // the layers' lines, before the fingertip's base (whose PCB and ring have a thickness too)
    let layers_end = text.find("\nfingertip_base:").unwrap();
    let yaml = text[..layers_end]
        .lines()
        .map(|l| match l.find("  thickness_mm: ") {
            Some(i) if l.starts_with("    ") => format!("{}thickness_mm: \"1.5\"", &l[..i + 2]),
            _ => l.to_string(),
        })
        .chain(text[layers_end..].lines().map(str::to_string))
        .collect::<Vec<_>>()
        .join("\n")
        .replace(
            "  silicone_wall_mm: 4.0",
            "  silicone_wall_mm: 4.0\n  sprue: {diameter_mm: \"3\"}",
        );
    let e = Design::from_yaml(&yaml, "x.yaml").unwrap_err().to_string();
    let lines: Vec<&str> = e.lines().collect();
    assert_eq!(
        lines,
        [
            "x.yaml:28:19: layers[0].thickness_mm = \"1.5\": a number must be written without quotes",
            "x.yaml:42:19: layers[1].thickness_mm = \"1.5\": a number must be written without quotes",
            "x.yaml:55:19: layers[2].thickness_mm = \"1.5\": a number must be written without quotes",
            "x.yaml:70:24: mold.sprue.diameter_mm = \"3\": a number must be written without quotes",
        ],
        "{e}"
    );
}

/// Terminal escape sequences (and any control character but line breaks and tabs) in a text
/// field are refused by path before anything is built, so they never reach FABRICATION.md.
#[test]
fn control_characters_in_text_are_refused_by_path() {
    let text = library::yaml("rtac0").unwrap();
    let description = text
        .lines()
        .find(|l| l.starts_with("description: "))
        .unwrap();
    let yaml = text.replacen(description, "description: \"\\e[2J\\e[31mred\"", 1);
    let d = Design::from_yaml(&yaml, "x.yaml").unwrap();
    assert_eq!(d.description, "\u{1b}[2J\u{1b}[31mred");
    let errs = errors(&d);
    assert!(
        errs.len() == 1
            && errs[0].path == "description"
            && errs[0].value == "\"\\u{1b}[2J\\u{1b}[31mred\""
            && errs[0].rule.contains("control characters"),
        "{errs:?}"
    );
    // in a layer's material name too; line breaks are text
    let mut d = library::load("rtac0").unwrap();
    d.layers[1].name = "gel\u{7}".into();
    assert!(
        errors(&d).iter().any(|e| e.path == "layers[1].name"),
        "{:?}",
        errors(&d)
    );
    let mut d = library::load("rtac0").unwrap();
    d.description = "two\nlines\tand a tab".into();
    assert!(errors(&d).is_empty(), "{:?}", errors(&d));
}

/// A kernel error names the parameters its solid was built from. Built from designs changed
/// after validation (the one way to reach the kernel with values it refuses): a printed
/// layer's features of diameter 0 (spheres of radius 0) and molds with walls drafted 90 deg
/// (no cavity block left).
#[test]
fn kernel_errors_name_the_parameters_of_the_failing_solid() {
    use fabkit_designs::{build, molds, DesignError};
    let tol = ChordTolerance::default();
    let materials = MaterialsTable::embedded().unwrap();
    let mut d = library::load("tactip_dualmodal").unwrap();
    let st = stack::validate(&d, &materials, tol).unwrap();
    d.layers[0].markers[0].feature.diameter_mm = 0.0;
    match build::build_layer(&d, &st, 0, tol) {
        Err(e @ DesignError::Geometry { .. }) => {
            let DesignError::Geometry { params, .. } = &e else {
                unreachable!()
            };
            assert_eq!(params, &["layers[0]"]);
            assert!(
                e.to_string().contains("(from the parameters layers[0]): "),
                "{e}"
            );
        }
        other => panic!("{:?}", other.map(|o| o.parts.len())),
    }
    let mut d = library::load("rtac0").unwrap();
    let st = stack::validate(&d, &materials, tol).unwrap();
    d.mold.draft_angle_deg = 90.0;
    let plans = molds::cast_plans(&d.stack_input(), &st);
    let errs: Vec<DesignError> = plans
        .iter()
        .filter_map(|p| molds::build_mold(&d.stack_input(), &st, p, tol).err())
        .collect();
    assert!(!errs.is_empty());
    for e in errs {
        match &e {
            DesignError::Geometry { params, .. } => {
                assert!(params.iter().any(|p| p == "mold"), "{e}");
                assert!(params.iter().any(|p| p.starts_with("layers[")), "{e}");
            }
            other => panic!("{other}"),
        }
    }
}

/// The error text of the CLI and of Python: a cause the message already quotes is said once,
/// another gets its own `caused by:` line.
#[test]
fn error_report_states_each_cause_once() {
    #[derive(Debug)]
    struct Wrap(&'static str, std::io::Error);
    impl std::fmt::Display for Wrap {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str(self.0)
        }
    }
    impl std::error::Error for Wrap {
        fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
            Some(&self.1)
        }
    }
    let gone = || std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
    let quoted = Wrap("reading a.yaml: no such file", gone());
    assert_eq!(
        fabkit_designs::error_report(&quoted),
        "reading a.yaml: no such file"
    );
    let plain = Wrap("reading a.yaml", gone());
    assert_eq!(
        fabkit_designs::error_report(&plain),
        "reading a.yaml\n  caused by: no such file"
    );
}
