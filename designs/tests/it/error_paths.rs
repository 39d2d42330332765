//! Errors name the parameter that produced them: each rule reports under the path of the value
//! it checks, and a list reports every bad entry.

use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{library, stack, ChordTolerance, Design, ParamError};

fn errors(d: &Design) -> Vec<ParamError> {
    let materials = MaterialsTable::embedded().unwrap();
    match stack::validate(d, &materials, ChordTolerance::default()) {
        Ok(_) => Vec::new(),
        Err(e) => e.0,
    }
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
