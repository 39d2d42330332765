//! Which command may replace which output folder: every command's output written into
//! another command's folder, a forged marker naming a user's file, a same-size edit of an
//! exported file. Nothing is deleted or overwritten without --force, another command's output
//! never, and each refusal names the file or the other command.

use std::path::Path;

use crate::calibrate_cli::{intrinsics, observe, write_table};
use crate::common::{run, snapshot, text};
use crate::groundtruth_cli::setup;
use fabkit_calibration::{write_camera, CameraFileFormat};

/// The command lines of the four commands that write an output folder, writing into `out`
/// (the inputs are those [`prepare`] writes), with `extra` appended; and the name each
/// command has in a marker.
fn command(name: &str, out: &str, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<&str> = match name {
        "export" => vec!["export", "rtac0", "--format", "stl"],
        "fixtures" => vec![
            "fixtures",
            "rtac0",
            "--pins-preset",
            "rtac0",
            "--semidomes",
            "2",
            "--seed",
            "3",
            "--format",
            "stl",
        ],
        "groundtruth" => vec![
            "groundtruth",
            "rtac0",
            "--camera",
            "cam.yaml",
            "--extrinsics",
            "extrinsics.json",
            "--fixtures",
            "fx",
        ],
        "calibrate extrinsics" => vec![
            "calibrate",
            "extrinsics",
            "--camera",
            "calcam.yaml",
            "--points",
            "pins.csv",
            "--observations",
            "obs.csv",
        ],
        other => panic!("no command {other}"),
    };
    a.extend(["--out", out]);
    a.extend(extra);
    a.into_iter().map(String::from).collect()
}

fn fabkit(dir: &Path, args: &[String]) -> std::process::Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    run(dir, &args, &[])
}

/// The inputs of every command in `dir`, and `fx`, the output of `fabkit fixtures`.
fn prepare(dir: &Path) {
    setup(dir);
    std::fs::write(
        dir.join("calcam.yaml"),
        write_camera(&intrinsics(), CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    write_table(&dir.join("pins.csv"));
    std::fs::write(dir.join("obs.csv"), observe(false, 0..29)).unwrap();
}

const COMMANDS: [(&str, &str); 4] = [
    ("export", "kit"),
    ("fixtures", "fx"),
    ("groundtruth", "gt"),
    ("calibrate extrinsics", "calib"),
];

/// `calibrate extrinsics --out` into an export, `export --out` into a calibration, fixtures
/// and ground truth into each other's folders, and every other pair: refused with exit 2,
/// with and without --force, naming the command whose output it is; the folder is unchanged.
#[test]
fn no_command_replaces_another_commands_output() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    prepare(dir);
    for (name, out) in COMMANDS.iter().filter(|(n, _)| *n != "fixtures") {
        let o = fabkit(dir, &command(name, out, &[]));
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
    }
    for (owner, out) in COMMANDS {
        let before = snapshot(&dir.join(out));
        assert!(before.contains_key(".fabkit-output"), "{out}");
        for (name, _) in COMMANDS.iter().filter(|(n, _)| *n != owner) {
            for extra in [&[][..], &["--force"][..]] {
                let o = fabkit(dir, &command(name, out, extra));
                let e = text(&o.stderr);
                assert_eq!(o.status.code(), Some(2), "{name} {extra:?} into {out}: {e}");
                assert!(
                    e.contains(&format!("holds the output of `fabkit {owner}`"))
                        && e.contains(&format!("which `fabkit {name}` does not replace")),
                    "{name} {extra:?} into {out}: {e}"
                );
                assert_eq!(snapshot(&dir.join(out)), before, "{name} into {out}");
            }
        }
    }
    // The same command and job replaces its own output.
    let o = fabkit(
        dir,
        &command("calibrate extrinsics", "calib", &["--seed", "1"]),
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    // A calibration from other observations is another job: refused, then replaced with
    // --force.
    std::fs::write(dir.join("obs.csv"), observe(false, 0..25)).unwrap();
    let before = snapshot(&dir.join("calib"));
    let o = fabkit(dir, &command("calibrate extrinsics", "calib", &[]));
    let e = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("holds the output of `fabkit calibrate extrinsics` for extrinsics from 1 observation files")
            && e.contains("give --force"),
        "{e}"
    );
    assert_eq!(snapshot(&dir.join("calib")), before);
    let o = fabkit(dir, &command("calibrate extrinsics", "calib", &["--force"]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("calib/extrinsics.json")).unwrap()).unwrap();
    assert_eq!(j["residuals"]["observations"], 25, "{j}");
}

/// A folder of the user's own files with a forged marker naming them at their sizes (this
/// fabkit's format with made-up checksums, or the earlier format without any): every command
/// refuses it, with or without --force, naming the user's file, and touches nothing.
#[test]
fn a_forged_marker_does_not_give_a_users_folder_away() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    prepare(dir);
    let thesis = dir.join("thesis");
    std::fs::create_dir(&thesis).unwrap();
    std::fs::write(thesis.join("thesis.tex"), "\\chapter{Results}\n").unwrap();
    let n = std::fs::metadata(thesis.join("thesis.tex")).unwrap().len();
    for (owner, _) in COMMANDS {
        for marker in [
            serde_json::json!({"format": "fabkit-output/1",
                               "files": [{"path": "thesis.tex", "bytes": n}]}),
            serde_json::json!({"format": "fabkit-output/2", "command": owner,
                               "job": "kit 'rtac0' at chord tolerance 0.05 mm",
                               "files": [{"path": "thesis.tex", "bytes": n,
                                          "sha256": "ab".repeat(32)}]}),
        ] {
            std::fs::write(thesis.join(".fabkit-output"), marker.to_string()).unwrap();
            let before = snapshot(&thesis);
            for (name, _) in COMMANDS {
                for extra in [&[][..], &["--force"][..]] {
                    let o = fabkit(dir, &command(name, "thesis", extra));
                    let e = text(&o.stderr);
                    assert_eq!(o.status.code(), Some(2), "{name} {extra:?}: {e}");
                    assert!(
                        e.contains(
                            "output directory thesis is not a folder fabkit wrote: `thesis.tex`"
                        ),
                        "{name} {extra:?} ({marker}): {e}"
                    );
                    assert_eq!(snapshot(&thesis), before, "{name}");
                }
            }
        }
    }
}

/// An export whose FABRICATION.md was edited without changing its size is the user's now:
/// `fabkit export` refuses it, naming the file, with or without --force.
#[test]
fn a_same_size_edit_of_an_exported_file_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let o = fabkit(dir, &command("export", "kit", &[]));
    assert!(o.status.success(), "{}", text(&o.stderr));
    let sheet = dir.join("kit/FABRICATION.md");
    let mut edited = std::fs::read(&sheet).unwrap();
    let k = edited.iter().position(u8::is_ascii_lowercase).unwrap();
    edited[k] = edited[k].to_ascii_uppercase();
    std::fs::write(&sheet, &edited).unwrap();
    for extra in [&[][..], &["--force"][..]] {
        let o = fabkit(dir, &command("export", "kit", extra));
        let e = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{e}");
        assert!(
            e.contains(
                "`FABRICATION.md` was changed after fabkit wrote it (same size, other bytes"
            ),
            "{e}"
        );
        assert_eq!(std::fs::read(&sheet).unwrap(), edited);
    }
}
