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
    // an unknown key: the schema refuses it too
    write_design(&tmp.path().join("bad.yaml"), &yaml, SchemaVerdict::Rejects);
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
        .replace("draft_angle_deg: 2.0", "draft_angle_deg: 12.0")
        .replace("primer: pr_1200_rtv", "primer: ease_release_200");
    // the draft angle is past its bound [0, 10) in the schema too
    write_design(&tmp.path().join("bad.yaml"), &yaml, SchemaVerdict::Rejects);
    let o = run(tmp.path(), &["export", "bad.yaml", "--out", "out/bad"], &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(err.contains("layers[2].outer_radius_mm = 14.8"), "{err}");
    assert!(
        err.contains("mold.draft_angle_deg = 12: must be in [0, 10)"),
        "{err}"
    );
    assert!(
        err.contains(
            "core.primer = ease_release_200: is a Release material, expected one of [Primer]"
        ),
        "{err}"
    );
    assert!(!tmp.path().join("out").exists());
}

/// One fit broken at a time, through the CLI: a camera board taller than its bay overlaps the
/// LED PCB (the fit check), a tube whose light chamber keeps a ledge under the diffuser cannot
/// take the PCB from the top (here a validation rule, which the insertion check backs); each
/// is exit 2 with the error naming the parameter, its value, both parts and the overlap, and
/// nothing written.
#[test]
fn a_broken_fit_is_a_named_interference_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    for (from, to, expect) in [
        (
            "    bay_height_mm: 3.0 ",
            "    bay_height_mm: 3.5 ",
            "housing.camera.bay_height_mm = 3.5: fit check: `led_pcb_envelope` and `camera_board_envelope` overlap by 21.",
        ),
        (
            "  light_chamber_diameter_mm: 23.4 ",
            "  light_chamber_diameter_mm: 20.0 ",
            "housing.light_chamber_diameter_mm = 20: must pass the LED PCB",
        ),
    ] {
        let yaml = rtac0_yaml().replace(from, to);
        assert!(yaml.contains(to), "{to}");
        // a fit is a rule between parameters: the schema accepts the design
        write_design(&tmp.path().join("bad.yaml"), &yaml, SchemaVerdict::Accepts);
        let o = run(tmp.path(), &["export", "bad.yaml", "--out", "out/bad"], &[]);
        assert_eq!(o.status.code(), Some(2), "{to}");
        let err = text(&o.stderr);
        assert!(err.contains(expect), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert!(!tmp.path().join("out").exists());
    }
}

/// The TacTip's body, through the CLI: a lug 1 mm too wide for its pinned groove and an LED
/// ring seat 0.3 mm under the ring's diameter are each one named interference; a bayonet
/// profile of one lug on a 20 deg ramp is refused on both counts. Exit 2, the error naming the
/// parameter path, its value and the rule, nothing written.
#[test]
fn tactip_body_fits_and_bayonet_profile_are_checked_and_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml =
        std::fs::read_to_string(repo_root().join("designs/library/tactip_dualmodal.yaml")).unwrap();
    let profile = "printers:\n  fdm:\n    xy_resolution_mm: 0.4\n    layer_height_mm: 0.2\n    \
        min_wall_mm: 0.8\n    min_hole_diameter_mm: 1.0\n    min_feature_mm: 0.8\n    \
        bayonet: {lug_count: 1, ramp_deg: 20.0, clearance_mm: 0.2}\n";
    for (from, to, expect) in [
        (
            "    lug_width_mm: 3.0 ",
            "    groove_width_mm: 3.4\n    lug_width_mm: 4.0 ",
            vec!["shaft_body.bayonet.groove_width_mm = 3.4: fit check: `tip_fitting` and `shaft_body` overlap by 1."],
        ),
        (
            "    outer_diameter_mm: 18.0 ",
            "    seat_diameter_mm: 17.7\n    outer_diameter_mm: 18.0 ",
            vec!["shaft_body.led_ring.seat_diameter_mm = 17.7: fit check: `shaft_body` and `led_ring_envelope` overlap by 21."],
        ),
        (
            "shaft_body:\n",
            &format!("{profile}shaft_body:\n"),
            vec![
                "printers.fdm.bayonet.lug_count = 1: must be 2 to 8",
                "printers.fdm.bayonet.ramp_deg = 20: must be at least 0 and below 15",
            ],
        ),
    ] {
        // fits are rules between parameters, and the bayonet profile's bounds apply only to a
        // design with a shaft body: the schema accepts each
        refused_writing_nothing(tmp.path(), &yaml, (from, to), &expect, SchemaVerdict::Accepts);
    }
}

/// `yaml` with `from` replaced by `to` (once) is refused by `fabkit export`: exit 2, stderr
/// holding each of `expect` and no panic, no output folder; the design schema says of it what
/// `schema` says ([`write_design`]).
fn refused_writing_nothing(
    tmp: &std::path::Path,
    yaml: &str,
    (from, to): (&str, &str),
    expect: &[&str],
    schema: SchemaVerdict,
) {
    let bad = yaml.replacen(from, to, 1);
    assert!(bad.contains(to), "{to}");
    write_design(&tmp.join("bad.yaml"), &bad, schema);
    let o = run(tmp, &["export", "bad.yaml", "--out", "out/bad"], &[]);
    assert_eq!(o.status.code(), Some(2), "{to}");
    let err = text(&o.stderr);
    for e in expect {
        assert!(err.contains(e), "{e}: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!tmp.join("out").exists());
}

/// UVDtact's fingertip base (Sec. III-C) and acrylic shell (Sec. III): one fit broken at a time
/// (a camera holder wider than the PCB's bore, LEDs taller than the pocket leaves them, a
/// diffusion ring tight on the camera holder) is one named interference; a shell drawing
/// without a tolerance is refused by path. Exit 2, nothing written.
#[test]
fn uvdtact_fits_and_shell_drawing_are_checked_and_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = std::fs::read_to_string(repo_root().join("designs/library/uvdtact.yaml")).unwrap();
    for (from, to, expect, schema) in [
        (
            "    outer_diameter_mm: 2.6 ",
            "    outer_diameter_mm: 3.6 ",
            "fingertip_base.led_pcb.inner_diameter_mm = 3.2: fit check: `camera_holder` and `led_pcb_envelope` overlap by",
            SchemaVerdict::Accepts,
        ),
        (
            "    led_height_mm: 0.6 ",
            "    led_height_mm: 1.4 ",
            "fingertip_base.pocket_depth_mm = 3.0: fit check: `diffusion_ring` and `leds_envelope` overlap by",
            SchemaVerdict::Accepts,
        ),
        (
            "    inner_diameter_mm: 4.0 ",
            "    inner_diameter_mm: 2.0 ",
            "fingertip_base.diffusion_ring.inner_diameter_mm = 2.0: fit check: `camera_holder` and `diffusion_ring` overlap by",
            SchemaVerdict::Accepts,
        ),
        (
            "  general_tolerance_mm: 0.05 ",
            "  general_tolerance_mm: 0 ",
            "core.machining.general_tolerance_mm = 0: must be above 0",
            // a bound on the parameter alone: exclusiveMinimum 0 in the schema
            SchemaVerdict::Rejects,
        ),
    ] {
        refused_writing_nothing(tmp.path(), &yaml, (from, to), &[expect], schema);
    }
}

/// ShadowTac's casing (Sec. IV-B): a 30 mm camera board in the 29.4 mm bay is one named
/// interference; a 24 mm window that does not pass the camera's view of the skin's rim and a
/// gripper base narrower than its bolt pattern are refused by path. Exit 2, the error naming
/// the parameter path, its value and the rule, nothing written.
#[test]
fn shadowtac_casing_fits_and_rules_are_checked_and_write_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = std::fs::read_to_string(repo_root().join("designs/library/shadowtac.yaml")).unwrap();
    for (from, to, expect) in [
        (
            "    board_width_mm: 29.0 ",
            "    board_width_mm: 30.0 ",
            "casing.camera.board_width_mm = 30.0: fit check: `casing` and `camera_board_envelope` overlap by 213.8",
        ),
        (
            "  window_diameter_mm: 31.0 ",
            "  window_diameter_mm: 24.0 ",
            "casing.window_diameter_mm = 24: the camera's view of the skin's rim (radius 17.50 mm, the lens's front 4.00 mm under the plate) crosses the casing's top 14.95 mm from the axis: the window must pass it",
        ),
        (
            "    width_mm: 82.6 ",
            "    width_mm: 60.0 ",
            "casing.gripper_base.width_mm = 60: the bolts' counterbores (8.00 mm on a 70.00 mm spacing) must stay 0.80 mm inside the base",
        ),
    ] {
        // fits and rules between parameters: the schema accepts each
        refused_writing_nothing(
            tmp.path(),
            &yaml,
            (from, to),
            &[expect],
            SchemaVerdict::Accepts,
        );
    }
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
    // Below the floor (1e-9 mm once aborted on a 6 GB allocation): refused by every command that
    // meshes, and by validate and sweep files, before anything is built.
    for args in [
        &["export", "--chord-tolerance-mm", "1e-9"][..],
        &["fixtures", "--chord-tolerance-mm", "0.0001"],
        &["validate", "--chord-tolerance-mm", "1e-9"],
    ] {
        let o = run(tmp.path(), args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(
            text(&o.stderr).contains(&format!(
                "--chord-tolerance-mm: chord tolerance = {} mm: must be at least 0.001 mm",
                args[2].parse::<f64>().unwrap()
            )),
            "{args:?}: {}",
            text(&o.stderr)
        );
    }
    std::fs::write(
        tmp.path().join("sweep.yaml"),
        "base: rtac0\nchord_tolerance_mm: 1e-9\nvary:\n  layers[0].thickness_mm: [1.5, 2.0]\n",
    )
    .unwrap();
    let o = run(tmp.path(), &["sweep", "sweep.yaml", "--out", "out/s"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains(
            "sweep.yaml:2:21: chord tolerance = 0.000000001 mm: must be at least 0.001 mm"
        ),
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
    // a negative wall: below the schema's bound too
    write_design(&tmp.path().join("bad.yaml"), &yaml, SchemaVerdict::Rejects);
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

/// A design's data file (`pattern.csv_file`) is read only from the design's folder (or a folder
/// `--allow-data-dir` allows), only when it is a regular file within the size bound; a refused
/// file's lines are never quoted, and nothing is written.
#[test]
fn marker_csv_file_is_confined_to_the_design_folder_regular_and_bounded() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    std::fs::create_dir_all(root.join("designs/data")).unwrap();
    std::fs::create_dir_all(root.join("elsewhere")).unwrap();
    let pts = "polar_deg, azimuth_deg\n0, 0\n10, 0\n10, 90\n";
    // Outside the design's folder: a valid table whose comment must never be echoed.
    let secret = format!("{pts}# SECRET-LINE\n");
    std::fs::write(root.join("elsewhere/pts.csv"), &secret).unwrap();
    std::fs::write(root.join("designs/data/pts.csv"), pts).unwrap();
    std::os::unix::fs::symlink(
        root.join("elsewhere/pts.csv"),
        root.join("designs/link_out.csv"),
    )
    .unwrap();
    std::os::unix::fs::symlink("data/pts.csv", root.join("designs/link_in.csv")).unwrap();
    let fifo = std::process::Command::new("mkfifo")
        .arg(root.join("designs/pipe.csv"))
        .status()
        .unwrap();
    assert!(fifo.success());
    // the file name is refused by fabkit when it reads it, not by the schema (any text)
    let design = |csv: &str| {
        write_design(
            &root.join("designs/d.yaml"),
            &shadowtac_with_csv_list().replace("csv_file: pts.csv", &format!("csv_file: {csv:?}")),
            SchemaVerdict::Accepts,
        );
    };
    let param = "layers[0].markers[0].pattern.csv_file";
    let outside = root.join("elsewhere/pts.csv").display().to_string();
    let refused: Vec<(&str, String, Vec<&str>, &str)> = vec![
        (
            "absolute",
            outside.clone(),
            vec![],
            "outside the design's folder",
        ),
        (
            "dot-dot",
            "../elsewhere/pts.csv".into(),
            vec![],
            "outside the design's folder",
        ),
        (
            "symlink",
            "link_out.csv".into(),
            vec![],
            "outside the design's folder",
        ),
        (
            "device",
            "/dev/zero".into(),
            vec![],
            "outside the design's folder",
        ),
        (
            "device allowed",
            "/dev/zero".into(),
            vec!["--allow-data-dir", "/dev"],
            "is a character device; a data file must be a regular file",
        ),
        (
            "fifo",
            "pipe.csv".into(),
            vec![],
            "is a FIFO (named pipe); a data file must be a regular file",
        ),
        (
            "folder",
            "data".into(),
            vec![],
            "is a folder; a data file must be a regular file",
        ),
        (
            "size",
            "data/pts.csv".into(),
            vec!["--max-data-file-bytes", "20"],
            "over the data file limit of 20 bytes",
        ),
    ];
    for (what, csv, extra, rule) in refused {
        design(&csv);
        let mut args = vec!["export", "designs/d.yaml", "--out", "out/d"];
        args.extend(extra);
        let o = run(root, &args, &[]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(
            err.contains(&format!("{param} = {csv:?}: ")) && err.contains(rule),
            "{what}: {err}"
        );
        assert!(
            !err.contains("SECRET") && !err.contains("10, 90"),
            "{what} quotes the file: {err}"
        );
        assert!(!root.join("out").exists(), "{what}: output written");
    }
    // A sweep over such a design refuses it the same way.
    std::fs::write(
        root.join("sweep.yaml"),
        "base: designs/d.yaml\nvary:\n  layers[0].markers[0].feature.height_mm: [0.3, 0.4]\n",
    )
    .unwrap();
    design("../elsewhere/pts.csv");
    let o = run(root, &["sweep", "sweep.yaml", "--out", "out/sweep"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("outside the design's folder"),
        "{}",
        text(&o.stderr)
    );
    assert!(!root.join("out").exists());

    // Inside the folder (also through a symlink that stays inside), or in an allowed folder.
    let ok: Vec<(&str, Vec<&str>)> = vec![
        ("data/pts.csv", vec![]),
        ("link_in.csv", vec![]),
        (
            "../elsewhere/pts.csv",
            vec!["--allow-data-dir", "elsewhere"],
        ),
        (
            &outside,
            vec![
                "--allow-data-dir",
                "elsewhere",
                "--max-data-file-bytes",
                "4096",
            ],
        ),
    ];
    for (csv, extra) in ok {
        design(csv);
        let mut args = vec!["validate", "designs/d.yaml"];
        args.extend(extra.iter().copied());
        let o = run(root, &args, &[]);
        assert!(o.status.success(), "{csv} {extra:?}: {}", text(&o.stderr));
    }

    // Bad values of the new options: the option, the value and the rule; nothing written.
    design("data/pts.csv");
    std::fs::write(root.join("a_file"), "x").unwrap();
    let bad: &[(&[&str], &str, &str)] = &[
        (
            &["--max-data-file-bytes", "0"],
            "'0'",
            "must be a whole number of bytes from 1 to 67108864",
        ),
        (
            &["--max-data-file-bytes", "-5"],
            "'-5'",
            "must be a whole number of bytes from 1 to 67108864",
        ),
        (
            &["--max-data-file-bytes", "1e6"],
            "'1e6'",
            "must be a whole number of bytes from 1 to 67108864",
        ),
        (
            &["--max-data-file-bytes", "67108865"],
            "'67108865'",
            "must be a whole number of bytes from 1 to 67108864",
        ),
        (
            &["--allow-data-dir", "no_such_dir"],
            "'no_such_dir'",
            "must name an existing folder",
        ),
        (
            &["--allow-data-dir", "a_file"],
            "'a_file'",
            "must name an existing folder",
        ),
        (
            &["--allow-data-dir", ""],
            "''",
            "must name an existing folder",
        ),
    ];
    for (extra, value, rule) in bad {
        for cmd in [
            &["export", "designs/d.yaml", "--out", "out/d"][..],
            &["fixtures", "designs/d.yaml", "--out", "out/f"],
        ] {
            let mut args = cmd.to_vec();
            args.extend(extra.iter().copied());
            let o = run(root, &args, &[]);
            let err = text(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert!(
                err.contains(extra[0]) && err.contains(value) && err.contains(rule),
                "{args:?}: {err}"
            );
            assert!(!root.join("out").exists(), "{args:?}: output written");
        }
    }
}

/// The YAML files a user names (design, sweep file, fixture parameters) are read only when they
/// are regular files of at most 16 MiB: a FIFO or a device is refused at once, never read.
#[test]
fn yaml_inputs_must_be_regular_files_within_the_size_bound() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let fifo = std::process::Command::new("mkfifo")
        .arg(root.join("pipe.yaml"))
        .status()
        .unwrap();
    assert!(fifo.success());
    let big = std::fs::File::create(root.join("big.yaml")).unwrap();
    big.set_len((16 << 20) + 1).unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["export", "./pipe.yaml", "--out", "out/a"],
            "pipe.yaml: is a FIFO (named pipe); only regular files are read",
        ),
        (
            &["export", "/dev/zero", "--out", "out/a"],
            "/dev/zero: is a character device; only regular files are read",
        ),
        (
            &["validate", "big.yaml"],
            "big.yaml: is 16777217 bytes, over the limit of 16777216 bytes",
        ),
        (
            &["sweep", "pipe.yaml", "--out", "out/s"],
            "pipe.yaml: is a FIFO (named pipe)",
        ),
        (
            &["fixtures", "--params", "pipe.yaml", "--out", "out/f"],
            "pipe.yaml: is a FIFO (named pipe)",
        ),
    ];
    for (args, expect) in cases {
        let o = run(root, args, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(
            text(&o.stderr).contains(expect),
            "{args:?}: {}",
            text(&o.stderr)
        );
        assert!(!root.join("out").exists(), "{args:?}: output written");
    }
}

/// `--csg FILE` writes a new file or replaces an earlier CSG file of fabkit's; a user's file (here
/// the design itself) or a symbolic link is refused before anything is built or written.
#[test]
fn csg_never_overwrites_a_users_file() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    write_design(&root.join("d.yaml"), &rtac0_yaml(), SchemaVerdict::Accepts);
    std::fs::write(root.join("target.json"), "{}").unwrap();
    std::os::unix::fs::symlink("target.json", root.join("link.json")).unwrap();
    for (csg, why) in [
        ("d.yaml", "exists and is not a CSG file fabkit wrote"),
        ("link.json", "is a symbolic link"),
    ] {
        for cmd in ["export", "fixtures"] {
            let o = run(root, &[cmd, "d.yaml", "--out", "out", "--csg", csg], &[]);
            assert_eq!(o.status.code(), Some(2), "{cmd} {csg}");
            assert!(
                text(&o.stderr).contains(&format!("--csg {csg}: {why}")),
                "{cmd} {csg}: {}",
                text(&o.stderr)
            );
            assert!(!root.join("out").exists(), "{cmd} {csg}");
        }
    }
    assert_eq!(
        std::fs::read_to_string(root.join("d.yaml")).unwrap(),
        rtac0_yaml()
    );
    assert_eq!(
        std::fs::read_to_string(root.join("target.json")).unwrap(),
        "{}"
    );
    // A new file, then the same file again (fabkit's own): both written (the pin dome alone:
    // R-Tac0's paper default of 100 semi-domes took 5 of the command's 6 CPU-seconds).
    for _ in 0..2 {
        let o = run(
            root,
            &[
                "fixtures",
                "d.yaml",
                "--semidomes",
                "0",
                "--out",
                "out",
                "--csg",
                "fx.csg.json",
                "--format",
                "stl",
            ],
            &[],
        );
        assert!(o.status.success(), "{}", text(&o.stderr));
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(root.join("fx.csg.json")).unwrap()).unwrap();
        assert_eq!(j["format"], "fabkit-csg/1");
    }
}

/// The work of a build is estimated before anything is built: past `--max-triangles` an export
/// or a fixture set is refused (the estimate, the limit, how to raise it; nothing written) and a sweep variant
/// is recorded as an error while the sweep writes its table.
#[test]
fn work_past_max_triangles_is_refused_before_building() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let o = run(
        root,
        &[
            "export",
            "shadowtac",
            "--max-triangles",
            "100000",
            "--out",
            "out/s",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains("shadowtac: the kit would have about ")
            && err.contains("469 marker features), more than the limit of 100000")
            && err.contains("raise it with --max-triangles"),
        "{err}"
    );
    assert!(!root.join("out").exists());
    // fixtures: 100 semi-domes at the finest tolerance (once 9 GB and 80 s) are refused
    let o = run(
        root,
        &[
            "fixtures",
            "--semidomes",
            "100",
            "--chord-tolerance-mm",
            "0.001",
            "--out",
            "out/f",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains("rtac0: the fixtures would have about ")
            && err.contains("100 semi-dome patterns")
            && err.contains("more than the limit of 4000000")
            && err.contains("raise it with --max-triangles"),
        "{err}"
    );
    assert!(!root.join("out").exists());
    for bad in ["0", "-3", "100000001", "1e6"] {
        for cmd in ["export", "sweep", "fixtures"] {
            let args = match cmd {
                "export" => vec!["export", "--max-triangles", bad],
                "fixtures" => vec!["fixtures", "--max-triangles", bad],
                _ => vec!["sweep", "s.yaml", "--out", "out/w", "--max-triangles", bad],
            };
            let o = run(root, &args, &[]);
            assert_eq!(o.status.code(), Some(2), "{args:?}");
            assert!(
                text(&o.stderr).contains(&format!("invalid value '{bad}' for '--max-triangles"))
                    && text(&o.stderr)
                        .contains("must be a whole number of triangles from 1 to 100000000"),
                "{args:?}: {}",
                text(&o.stderr)
            );
        }
    }
    assert!(!root.join("out").exists());
    std::fs::write(
        root.join("s.yaml"),
        "base: shadowtac\nvary:\n  layers[0].markers[0].feature.height_mm: [0.4, 0.5]\n",
    )
    .unwrap();
    let o = run(
        root,
        &[
            "sweep",
            "s.yaml",
            "--out",
            "out/w",
            "--max-triangles",
            "100000",
        ],
        &[],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(root.join("out/w/results.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2, "{csv}");
    for r in rows {
        assert!(
            r.contains(",error,") && r.contains("more than the limit of 100000"),
            "{r}"
        );
    }
}

#[test]
fn marker_list_from_csv_is_placed_and_hashed() {
    let tmp = tempfile::tempdir().unwrap();
    write_design(
        &tmp.path().join("d.yaml"),
        &shadowtac_with_csv_list(),
        SchemaVerdict::Accepts,
    );
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
    // held once every file is in the temporary sibling, before the rename
    let mut child = crate::common::spawn_held(
        tmp.path(),
        &["export", "uvdtact", "--out", "out/u"],
        "export-written",
        1,
    );
    let prefix = format!(".u.tmp-{}-", child.id());
    let sibling = || {
        std::fs::read_dir(tmp.path().join("out"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .find(|n| n.starts_with(&prefix))
    };
    child.kill().unwrap(); // SIGKILL: no chance to clean up
    child.wait().unwrap();
    let stale = sibling().expect("the temporary sibling of the held export");
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

/// A file that does not exist is named with its cause once, by every command that reads one
/// (the calibration files said "No such file or directory" twice), and nothing is written.
#[test]
fn a_missing_file_states_its_cause_once() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [&[&str]; 5] = [
        &["export", "nope.yaml", "--out", "out/x"],
        &["fixtures", "--params", "nope.yaml", "--out", "out/x"],
        &["sweep", "nope.yaml", "--out", "out/x"],
        &[
            "calibrate",
            "extrinsics",
            "--camera",
            "nocam.yaml",
            "--points",
            "p.csv",
            "--observations",
            "o.csv",
            "--out",
            "out/x",
        ],
        &[
            "groundtruth",
            "--camera",
            "nocam.yaml",
            "--extrinsics",
            "e.json",
            "--fixtures",
            "fx",
            "--out",
            "out/x",
        ],
    ];
    for args in cases {
        let o = run(tmp.path(), args, &[]);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("nope.yaml") || err.contains("nocam.yaml"),
            "{args:?}: {err}"
        );
        assert_eq!(
            err.matches("No such file or directory").count(),
            1,
            "{args:?}: {err}"
        );
        assert!(!tmp.path().join("out").exists(), "{args:?}");
    }
}

/// `--mold-strategy direct` writes its own kit (`rtac0_mold_direct`, in its own default folder)
/// and never silently replaces the default kit: into the same `--out` it is refused, naming both
/// kits and `--force`, as is another chord tolerance; `--force` replaces. The design's own
/// strategy keeps the kit's name.
#[test]
fn a_mold_strategy_export_never_silently_replaces_the_default_kit() {
    let tmp = tempfile::tempdir().unwrap();
    let export = |extra: &[&str]| {
        let mut args = vec!["export", "rtac0", "--format", "stl"];
        args.extend_from_slice(extra);
        if !extra.contains(&"--chord-tolerance-mm") {
            args.extend_from_slice(&["--chord-tolerance-mm", "0.05"]);
        }
        run(tmp.path(), &args, &[])
    };
    let manifest = |dir: &str| std::fs::read(tmp.path().join(dir).join("manifest.json")).unwrap();
    let name = |dir: &str| {
        serde_json::from_slice::<serde_json::Value>(&manifest(dir)).unwrap()["design"]["name"]
            .as_str()
            .unwrap()
            .to_string()
    };
    assert!(export(&[]).status.success());
    let default_kit = manifest("out/rtac0");
    let o = export(&["--mold-strategy", "direct"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(name("out/rtac0_mold_direct"), "rtac0_mold_direct");
    assert!(tmp.path().join("out/rtac0_mold_direct/parts").is_dir());
    assert_eq!(manifest("out/rtac0"), default_kit);
    for (extra, words) in [
        (
            &["--mold-strategy", "direct", "--out", "out/rtac0"][..],
            "output directory out/rtac0 holds the output of `fabkit export` for kit 'rtac0' at chord tolerance 0.05 mm, made with other options or inputs than this one (kit 'rtac0_mold_direct' at chord tolerance 0.05 mm): refusing to replace it (hint: choose another directory, or give --force (Python: force=True) to replace it)",
        ),
        (
            &["--chord-tolerance-mm", "0.06"][..],
            "for kit 'rtac0' at chord tolerance 0.05 mm, made with other options or inputs than this one (kit 'rtac0' at chord tolerance 0.06 mm)",
        ),
    ] {
        let o = export(extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}");
        assert!(text(&o.stderr).contains(words), "{extra:?}: {}", text(&o.stderr));
        assert_eq!(manifest("out/rtac0"), default_kit, "{extra:?}");
    }
    // the design's own strategy is the same kit
    assert!(export(&["--mold-strategy", "master"]).status.success());
    assert_eq!(name("out/rtac0"), "rtac0");
    let o = export(&["--mold-strategy", "direct", "--out", "out/rtac0", "--force"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(name("out/rtac0"), "rtac0_mold_direct");
}

/// A value valid in its unit but likely typed in another is warned about by its
/// file:line:column, path, value and the likely unit, and the command still runs (issue 102): a
/// draft angle of 0.035 (radians in a degree field). A clearance of 0.0005 (metres in a
/// millimetre field) is refused (lengths are 0 or at least a micrometre), and the warning
/// beside the refusal says what it would be in metres. No library design draws a warning.
#[test]
fn values_plausible_in_another_unit_are_warned_about() {
    let tmp = tempfile::tempdir().unwrap();
    let yaml = rtac0_yaml().replace("  draft_angle_deg: 2.0", "  draft_angle_deg: 0.035");
    let line = |y: &str, prefix: &str| y.lines().position(|l| l.starts_with(prefix)).unwrap() + 1;
    write_design(
        &tmp.path().join("units.yaml"),
        &yaml,
        SchemaVerdict::Accepts,
    );
    let o = run(tmp.path(), &["validate", "units.yaml"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(
        err.contains(&format!(
            "warning: units.yaml:{}:20: mold.draft_angle_deg = 0.035: under a fifth of a degree; if it is in radians, that is 2.01 deg",
            line(&yaml, "  draft_angle_deg")
        )),
        "{err}"
    );
    let yaml = rtac0_yaml().replace(
        "  cavity_clearance_mm: 0.0",
        "  cavity_clearance_mm: 0.0005",
    );
    write_design(
        &tmp.path().join("metres.yaml"),
        &yaml,
        SchemaVerdict::Accepts,
    );
    let o = run(tmp.path(), &["validate", "metres.yaml"], &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains(&format!(
            "warning: metres.yaml:{}:24: mold.cavity_clearance_mm = 0.0005: under a micrometre; if it is in metres, that is 0.5 mm",
            line(&yaml, "  cavity_clearance_mm")
        )) && err.contains("mold.cavity_clearance_mm = 0.0005: must be 0 or a length of at least 0.001 mm"),
        "{err}"
    );
    for design in fabkit_designs::library::LIBRARY.iter().map(|(n, _)| *n) {
        let o = run(tmp.path(), &["validate", design], &[]);
        assert!(o.status.success(), "{design}");
        assert!(
            !text(&o.stderr).contains("warning"),
            "{design}: {}",
            text(&o.stderr)
        );
    }
}
