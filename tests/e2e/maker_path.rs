//! The maker's path on the command line: `validate` as the map of every settable parameter,
//! `show` as the template to start a design from.

use crate::common::*;

/// `validate` prints every parameter path of each library design (the paths presets and sweeps
/// set, the markers' included) with its value, and no float noise (`-1.5999999999999996`,
/// `1.1e-16`); `show` prints the design's own YAML, comments included, which loads as the
/// same design, and writes it to a new file only.
#[test]
fn validate_lists_every_path_without_noise_and_show_gives_a_template() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, yaml) in fabkit::designs::library::LIBRARY {
        let o = run(tmp.path(), &["validate", name], &[]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let out = text(&o.stdout);
        let design = fabkit::designs::library::load(name).unwrap();
        let paths = fabkit::designs::sweep::parameter_paths(&design);
        let has_markers = design.layers.iter().any(|l| !l.markers.is_empty());
        assert_eq!(
            paths.iter().any(|p| p.contains("markers[0].pattern.")),
            has_markers,
            "{name}"
        );
        for p in &paths {
            assert!(
                out.contains(&format!("\n  {p} = ")),
                "{name}: {p} not listed"
            );
        }
        // every number printed has at most 9 decimals and no exponent
        for token in out.split(|c: char| !(c.is_ascii_digit() || ".-+eE".contains(c))) {
            if token.parse::<f64>().is_ok() && token.contains('.') {
                let decimals = token.split('.').nth(1).unwrap();
                assert!(
                    decimals.len() <= 9 && !decimals.contains(['e', 'E']),
                    "{name}: float noise {token}"
                );
            }
        }
        let o = run(tmp.path(), &["show", name], &[]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        assert_eq!(text(&o.stdout), *yaml);
        let file = format!("{name}.yaml");
        let o = run(tmp.path(), &["show", name, "--out", &file], &[]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let copy = std::fs::read_to_string(tmp.path().join(&file)).unwrap();
        assert!(
            copy.lines().any(|l| l.contains(" # ")),
            "{name}: comments kept"
        );
        let loaded = fabkit::designs::Design::from_yaml(&copy, &file).unwrap();
        assert_eq!(loaded, design);
        let o = run(
            tmp.path(),
            &[
                "export",
                &file,
                "--out",
                "x",
                "--chord-tolerance-mm",
                "0.05",
                "--format",
                "stl",
            ],
            &[],
        );
        assert!(
            o.status.success(),
            "{name}: the template exports: {}",
            text(&o.stderr)
        );
        // an existing file is never replaced
        std::fs::write(tmp.path().join(&file), "mine").unwrap();
        let o = run(tmp.path(), &["show", name, "--out", &file], &[]);
        assert_eq!(o.status.code(), Some(2));
        assert!(
            text(&o.stderr).contains(&format!("--out {file}:")),
            "{}",
            text(&o.stderr)
        );
        assert_eq!(
            std::fs::read_to_string(tmp.path().join(&file)).unwrap(),
            "mine"
        );
        std::fs::remove_dir_all(tmp.path().join("x")).unwrap();
    }
    let o = run(tmp.path(), &["show", "nosuch"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr)
            .contains("show: 'nosuch' is not a library design (they are: rtac0, shadowtac"),
        "{}",
        text(&o.stderr)
    );
}
