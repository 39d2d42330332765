use fabkit_designs::sweep::*;
use serde_json::Value;

#[test]
fn shadowtac_paths_include_set_and_optional_marker_fields() {
    let d = fabkit_designs::library::load("shadowtac").unwrap();
    let p = parameter_paths(&d);
    for want in [
        "layers[0].markers[0].pattern.spacing_mm",
        "layers[0].markers[0].feature.height_mm",
        "layers[0].markers[0].pattern.rings",
        "layers[0].markers[0].tip_material",
        "mold.wall_thickness_mm",
        "body.base_diameter_mm",
    ] {
        assert!(p.iter().any(|x| x == want), "{want} missing from {p:?}");
    }
    assert!(!p.iter().any(|x| x.starts_with("presets")));
    assert!(path_exists(&d, "layers[0].markers[0].feature"));
    assert!(!path_exists(&d, "layers[0].markers[0].feat"));
    assert!(!path_exists(&d, "layers[1].name"));
}

#[test]
fn nearest_paths_find_the_full_path_of_a_short_one() {
    let d = fabkit_designs::library::load("shadowtac").unwrap();
    assert_eq!(
        nearest_paths(&d, "markers.spacing_mm", 3)[0],
        "layers[0].markers[0].pattern.spacing_mm"
    );
    assert_eq!(
        nearest_paths(&d, "layers[0].markers[0].feature.hieght_mm", 3)[0],
        "layers[0].markers[0].feature.height_mm"
    );
    assert_eq!(
        nearest_paths(&d, "mold.wall_thicknes_mm", 1),
        vec!["mold.wall_thickness_mm".to_string()]
    );
}

#[test]
fn short_paths_expand_when_unambiguous() {
    let d = fabkit_designs::library::load("shadowtac").unwrap();
    assert_eq!(
        expand_short_path(&d, "markers.spacing_mm").as_deref(),
        Some("layers[0].markers[0].pattern.spacing_mm")
    );
    assert_eq!(
        expand_short_path(&d, "markers.feature.height_mm").as_deref(),
        Some("layers[0].markers[0].feature.height_mm")
    );
    // No such key, or keys out of order.
    assert_eq!(expand_short_path(&d, "markers.spacing"), None);
    assert_eq!(expand_short_path(&d, "pattern.markers.spacing_mm"), None);
    assert_eq!(expand_short_path(&d, "layers[1].markers.spacing_mm"), None);
    // Several fits (every layer has a name).
    let r = fabkit_designs::library::load("rtac0").unwrap();
    assert_eq!(expand_short_path(&r, "name"), None);
}

#[test]
fn canonical_json_sorts_keys() {
    let v: Value = serde_json::from_str(r#"{"b":[1,{"z":1,"a":2.5}],"a":"x"}"#).unwrap();
    assert_eq!(canonical_json(&v), r#"{"a":"x","b":[1,{"a":2.5,"z":1}]}"#);
}
