//! Bad input: clear errors naming file:line:column or the parameter path, exit code 2, no
//! panic, nothing half-written.

use crate::common::*;

fn rtac0_yaml() -> String {
    std::fs::read_to_string(repo_root().join("designs/library/rtac0.yaml")).unwrap()
}

#[test]
fn unknown_key_reports_file_line_column_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = rtac0_yaml().replace(
        "  cylinder_length_mm: 6.0",
        "  cylinder_length_mm: 6.0\n  colour: red",
    );
    let line = yaml
        .lines()
        .position(|l| l.starts_with("  colour: red"))
        .unwrap()
        + 1;
    std::fs::write(tmp.path().join("bad.yaml"), &yaml).unwrap();
    let o = run(tmp.path(), &["export", "bad.yaml", "--out", "out/bad"], &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.contains(&format!("bad.yaml:{line}:")), "{err}");
    assert!(err.contains("colour"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn impossible_parameters_are_all_reported_with_their_paths() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = rtac0_yaml()
        .replace("outer_radius_mm: 15.0 ", "outer_radius_mm: 14.8 ")
        .replace("draft_angle_deg: 2.0", "draft_angle_deg: 12.0");
    std::fs::write(tmp.path().join("bad.yaml"), &yaml).unwrap();
    let o = run(tmp.path(), &["export", "bad.yaml", "--out", "out/bad"], &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.contains("layers[2].outer_radius_mm = 14.8"), "{err}");
    assert!(
        err.contains("mold.draft_angle_deg = 12: must be in [0, 10)"),
        "{err}"
    );
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn bad_chord_tolerance_and_unknown_design_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(tmp.path(), &["export", "--chord-tolerance-mm", "0"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("chord tolerance = 0 mm"),
        "{}",
        text(&o.stderr)
    );
    let o = run(tmp.path(), &["export", "nosuchsensor"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("no library design named 'nosuchsensor'"));
    assert!(!tmp.path().join("out").exists());
}

#[test]
fn failed_export_leaves_the_previous_export_untouched() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(tmp.path(), &["export", "--format", "stl"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let manifest = std::fs::read(tmp.path().join("out/rtac0/manifest.json")).unwrap();
    let yaml = rtac0_yaml().replace("wall_thickness_mm: 1.0 ", "wall_thickness_mm: -1.0 ");
    std::fs::write(tmp.path().join("bad.yaml"), yaml).unwrap();
    let o = run(
        tmp.path(),
        &["export", "bad.yaml", "--out", "out/rtac0"],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("core.wall_thickness_mm = -1"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(
        std::fs::read(tmp.path().join("out/rtac0/manifest.json")).unwrap(),
        manifest
    );
    let leftovers: Vec<_> = std::fs::read_dir(tmp.path().join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 1, "{leftovers:?}");
}

#[test]
fn a_folder_fabkit_did_not_write_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("thesis")).unwrap();
    std::fs::write(tmp.path().join("thesis/chapter1.tex"), "keep me").unwrap();
    let o = run(tmp.path(), &["export", "--out", "thesis"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("thesis/chapter1.tex")).unwrap(),
        "keep me"
    );
    // A look-alike manifest.json (a string fabkit_version) does not make it fabkit's folder.
    let look_alike = "{\"fabkit_version\": \"0.1.0\"}\n";
    std::fs::write(tmp.path().join("thesis/manifest.json"), look_alike).unwrap();
    for cmd in [&["export"][..], &["fixtures", "rtac0"]] {
        let mut args = cmd.to_vec();
        args.extend(["--out", "thesis"]);
        let o = run(tmp.path(), &args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = text(&o.stderr);
        assert!(
            err.contains("chapter1.tex") && err.contains(".fabkit-output"),
            "{args:?}: {err}"
        );
    }
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("thesis/chapter1.tex")).unwrap(),
        "keep me"
    );
    assert_eq!(
        std::fs::read_to_string(tmp.path().join("thesis/manifest.json")).unwrap(),
        look_alike
    );
    let mut names: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    names.sort();
    assert_eq!(names, ["thesis"]);
}

#[test]
fn designs_lists_the_library() {
    let o = run(&repo_root(), &["designs"], &[]);
    assert!(o.status.success());
    assert!(
        text(&o.stdout).starts_with("rtac0 (default)"),
        "{}",
        text(&o.stdout)
    );
}

fn shadowtac_with_csv_list() -> String {
    let yaml = std::fs::read_to_string(repo_root().join("designs/library/shadowtac.yaml")).unwrap();
    let yaml = yaml[..yaml.find("presets:").unwrap()].to_string();
    assert!(yaml.contains("          layout: concentric_6k "));
    yaml.replace(
        "          layout: concentric_6k ",
        "          csv_file: pts.csv\n          layout: list ",
    )
    .lines()
    .filter(|l| !l.contains("rings: 12") && !l.contains("polar_step_deg: 3.9474"))
    .collect::<Vec<_>>()
    .join("\n")
}

#[test]
fn marker_list_from_csv_is_placed_and_hashed() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("d.yaml"), shadowtac_with_csv_list()).unwrap();
    let hash = |pts: &str| {
        std::fs::write(tmp.path().join("pts.csv"), pts).unwrap();
        let o = run(
            tmp.path(),
            &["export", "d.yaml", "--out", "out/d", "--format", "stl"],
            &[],
        );
        assert!(o.status.success(), "{}", text(&o.stderr));
        let m: serde_json::Value =
            serde_json::from_slice(&std::fs::read(tmp.path().join("out/d/manifest.json")).unwrap())
                .unwrap();
        (
            m["summary"]["markers"][0]["count"].as_u64().unwrap(),
            m["design"]["sha256"].as_str().unwrap().to_string(),
        )
    };
    let (n1, h1) = hash("polar_deg, azimuth_deg\n0, 0\n10, 0\n10, 90 # a comment\n");
    let (n2, h2) = hash("polar_deg, azimuth_deg\n0, 0\n10, 0\n12, 90\n");
    assert_eq!((n1, n2), (3, 3));
    assert_ne!(h1, h2, "the design hash covers the CSV");
    std::fs::write(
        tmp.path().join("pts.csv"),
        "polar_deg, azimuth_deg\n0, 0\n10, x\n",
    )
    .unwrap();
    let o = run(tmp.path(), &["export", "d.yaml", "--out", "out/e"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("pts.csv:3:"),
        "{}",
        text(&o.stderr)
    );
    assert!(!tmp.path().join("out/e").exists());
}

/// A run killed with SIGKILL while writing leaves its temporary sibling (`.<name>.tmp-<pid>-<n>`);
/// the next complete run into the same folder removes it and says so.
#[test]
fn a_run_after_a_sigkill_mid_write_removes_the_stale_sibling_and_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir(tmp.path().join("out")).unwrap();
    let mut child = crate::common::fabkit()
        .current_dir(tmp.path())
        .args(["export", "uvdtact", "--out", "out/u"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let prefix = format!(".u.tmp-{}-", child.id());
    let sibling = || {
        std::fs::read_dir(tmp.path().join("out"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .find(|n| n.starts_with(&prefix))
    };
    // the temporary sibling exists once the parts are being written
    let t0 = std::time::Instant::now();
    while sibling().is_none() && child.try_wait().unwrap().is_none() {
        assert!(
            t0.elapsed().as_secs() < 120,
            "no temporary sibling appeared"
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap(); // SIGKILL: no chance to clean up
    child.wait().unwrap();
    let Some(stale) = sibling() else {
        panic!("the export finished before it could be killed");
    };
    assert!(!tmp.path().join("out/u").exists());

    let o = run(tmp.path(), &["export", "rtac0", "--out", "out/u"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(
        err.contains("removed") && err.contains(&stale) && err.contains("interrupted"),
        "{err}"
    );
    let names: Vec<String> = std::fs::read_dir(tmp.path().join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["u"]);
}
