use fabkit_designs::variant::*;
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

/// The canonical JSON that ids hash, written node by node through strings as it was first
/// written: the faster writer must give the same bytes.
fn canonical_by_strings(v: &Value) -> String {
    match v {
        Value::Object(o) => {
            let mut keys: Vec<&String> = o.keys().collect();
            keys.sort();
            let items: Vec<String> = keys
                .into_iter()
                .map(|k| {
                    format!(
                        "{}:{}",
                        Value::String(k.clone()),
                        canonical_by_strings(&o[k])
                    )
                })
                .collect();
            format!("{{{}}}", items.join(","))
        }
        Value::Array(a) => format!(
            "[{}]",
            a.iter()
                .map(canonical_by_strings)
                .collect::<Vec<_>>()
                .join(",")
        ),
        other => other.to_string(),
    }
}

#[test]
fn the_canonical_json_is_unchanged() {
    for name in [
        "shadowtac",
        "rtac0",
        "uvdtact",
        "tactip_dualmodal",
        "soter_channels",
    ] {
        let d = fabkit_designs::library::load(name).unwrap();
        let mut v = serde_json::to_value(&d).unwrap();
        v["name"] = Value::String("a \"quoted\" \\ name\n\u{1}é".into());
        v["extra"] = serde_json::json!({"z": [1, -2, 0.5, -0.0, 1e300, null, true], "a": {}});
        assert_eq!(canonical_json(&v), canonical_by_strings(&v), "{name}");
    }
}

#[test]
fn spans_are_found_in_compact_json() {
    let text = r#"{"a":{"b":[1,{"c":"x]}"},[2,3]],"d":-1.5e3},"e\"":null}"#;
    let at = |p: &str| span_of(text, p).map(|(a, b)| &text[a..b]);
    assert_eq!(at("a.b[1].c"), Some(r#""x]}""#));
    assert_eq!(at("a.b[2]"), Some("[2,3]"));
    assert_eq!(at("a.d"), Some("-1.5e3"));
    assert_eq!(at("e\""), Some("null"));
    assert_eq!(at("a.b[3]"), None);
    assert_eq!(at("a.x"), None);
}
