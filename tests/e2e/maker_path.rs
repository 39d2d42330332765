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
        let paths = fabkit::sweep::parameter_paths(&design);
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
        // the library text, but for the schema modeline: it names the schema beside the
        // template (`fabkit schema > design.schema.json`) rather than designs/'s
        let o = run(tmp.path(), &["show", name], &[]);
        assert!(o.status.success(), "{name}: {}", text(&o.stderr));
        let library_rest = yaml
            .strip_prefix("# yaml-language-server: $schema=../design.schema.json\n")
            .expect("the library design starts with its modeline");
        assert_eq!(
            text(&o.stdout),
            format!("# yaml-language-server: $schema=design.schema.json\n{library_rest}")
        );
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

/// The README's first command installs `fabkit` onto the PATH (`cargo install`, which builds
/// the same binary as this test's), and with `fabkit` on the PATH every `fabkit` command of the
/// README's first two command blocks runs as written, from a folder that holds the repository's
/// `designs/`.
#[test]
fn the_readmes_commands_run_as_written_after_its_install_step() {
    let readme = std::fs::read_to_string(repo_root().join("README.md")).unwrap();
    let blocks: Vec<&str> = readme
        .split("```sh\n")
        .skip(1)
        .map(|b| b.split("```").next().unwrap())
        .take(2)
        .collect();
    let first = blocks[0].lines().next().unwrap();
    assert!(
        first.starts_with("cargo install --locked --path fabkit && fabkit export "),
        "{first}"
    );
    let bin = std::path::PathBuf::from(env!("CARGO_BIN_EXE_fabkit"));
    assert_eq!(bin.file_name().unwrap(), "fabkit");
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let tmp = tempfile::tempdir().unwrap();
    std::os::unix::fs::symlink(repo_root().join("designs"), tmp.path().join("designs")).unwrap();
    let mut commands: Vec<String> = vec![first
        .split("&& ")
        .nth(1)
        .unwrap()
        .split('#')
        .next()
        .unwrap()
        .trim()
        .to_string()];
    commands.extend(
        blocks[1]
            .lines()
            .filter(|l| l.starts_with("fabkit "))
            .map(|l| l.split(" # ").next().unwrap().trim().to_string()),
    );
    assert!(commands.len() >= 6, "{commands:?}");
    for c in &commands {
        let o = std::process::Command::new("sh")
            .arg("-c")
            .arg(c)
            .current_dir(tmp.path())
            .env("PATH", &path)
            .output()
            .unwrap();
        assert!(o.status.success(), "`{c}`: {}", text(&o.stderr));
    }
    for dir in ["out/rtac0", "out/rtac0_mold_direct"] {
        assert!(
            tmp.path().join(dir).join("manifest.json").is_file(),
            "{dir}"
        );
    }
}

/// `fixtures` reports its work on stderr as it goes, also when stderr is not a terminal (a log
/// or CI): the parts and the estimated triangles first, then parts built, then the writing.
#[test]
fn fixtures_show_progress_off_a_terminal() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(
        tmp.path(),
        &[
            "fixtures",
            "rtac0",
            "--semidomes",
            "3",
            "--chord-tolerance-mm",
            "0.05",
            "--format",
            "stl",
            "--out",
            "fx",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    let at = |prefix: &str| line_starting(&err, prefix);
    // the paper's dome (and its holder ring), the pin, the holder, the empty half, three
    // patterns and the indenter
    let start = at("fixtures: building the 9 parts of rtac0 (about ");
    let built = at("fixtures: 9/9");
    let writing = at("fixtures: writing 9 parts and ");
    assert!(start < built && built < writing, "{err}");
}

/// `export` says what it does on stderr when stderr is not a terminal (a log, CI, a pipe):
/// what it builds, then how long that took and where it writes (issue 102: no silent wait).
#[test]
fn export_shows_its_stages_off_a_terminal() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run(tmp.path(), &["export", "ninedtact", "--out", "kit"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    let at = |prefix: &str| line_starting(&err, prefix);
    let building = at("export: building ninedtact at 0.01 mm chord tolerance");
    let writing = at("export: built ");
    assert!(building < writing, "{err}");
    assert!(
        err.lines()
            .nth(writing)
            .unwrap()
            .ends_with("; writing them to kit"),
        "{err}"
    );
}

/// `fixtures rtac0` with its defaults builds R-Tac0's paper's kit and says so (issue 102): the
/// published 29-hole dome (`--pins-preset rtac0`) and the paper's 100 semi-domes; each default
/// taken from the paper is named with the option that changes it. `--pins-preset default`
/// and `--semidomes 0` give fabkit's own 13-hole dome and no pattern; a `--params` file's
/// `pin_dome:` and `semidomes.generate` win over the paper's; a design of one's own started
/// from R-Tac0 gets fabkit's dome.
#[test]
fn fixtures_default_to_the_papers_kit() {
    let tmp = tempfile::tempdir().unwrap();
    let built = |out: &str, extra: &[&str]| {
        let mut args = vec!["fixtures", "rtac0", "--format", "stl", "--out", out];
        args.extend(extra);
        let o = run(tmp.path(), &args, &[]);
        assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
        let table =
            std::fs::read_to_string(tmp.path().join(out).join("points/point_table.csv")).unwrap();
        let patterns = std::fs::read_dir(tmp.path().join(out).join("parts"))
            .unwrap()
            .filter(|e| {
                let name = e
                    .as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .into_owned();
                name.starts_with("semidome_")
                    && !["semidome_holder.stl", "semidome_empty.stl"].contains(&name.as_str())
            })
            .count();
        (text(&o.stdout), table.lines().count() - 1, patterns)
    };
    let (said, holes, patterns) = built("a", &[]);
    assert_eq!((holes, patterns), (29, 100), "{said}");
    for line in [
        "  pin dome: 29 holes in 8 captures;",
        "  semi-domes: 100 patterns + the empty half -> 10000 stitched pairs",
        "  from the paper: the pin dome of the R-Tac0 paper (--pins-preset rtac0; fabkit's own: --pins-preset default)",
        "  from the paper: 100 semi-dome patterns, the R-Tac0 paper's count (--semidomes N for another, 0 for none)",
    ] {
        assert!(said.contains(line), "{line}\n{said}");
    }
    assert!(!said.contains("hint:"), "{said}");
    // fabkit's own dome and no pattern, asked for: nothing from the paper, no hint
    let (said, holes, patterns) = built("b", &["--pins-preset", "default", "--semidomes", "0"]);
    assert_eq!((holes, patterns), (13, 0), "{said}");
    assert!(
        !said.contains("from the paper") && !said.contains("hint:"),
        "{said}"
    );
    // a parameter file's own dome and count win over the paper's
    std::fs::write(
        tmp.path().join("p.yaml"),
        "pin_dome:\n  engrave_numbers: true\nsemidomes:\n  generate: 2\n",
    )
    .unwrap();
    let (said, holes, patterns) = built("c", &["--params", "p.yaml"]);
    assert_eq!((holes, patterns), (13, 2), "{said}");
    assert!(!said.contains("from the paper"), "{said}");
    // listed patterns are the file's count too (100 more would pass the 100-part cap)
    std::fs::write(
        tmp.path().join("q.yaml"),
        "semidomes:\n  patterns:\n    - name: one\n      protrusions:\n        - {polar_angle_deg: 20, azimuth_deg: 30, indentation_depth_mm: 1, shape: {type: sphere, radius_mm: 2}}\n",
    )
    .unwrap();
    let (said, holes, patterns) = built("d", &["--params", "q.yaml"]);
    assert_eq!((holes, patterns), (29, 1), "{said}");
    assert!(
        said.contains("from the paper: the pin dome") && !said.contains("semi-dome patterns, the"),
        "{said}"
    );
    // a design of one's own that starts from R-Tac0 (its source still cites the paper) gets
    // fabkit's dome, sized to its skin and camera
    let o = run(tmp.path(), &["show", "rtac0", "--out", "mine.yaml"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let yaml = std::fs::read_to_string(tmp.path().join("mine.yaml")).unwrap();
    assert!(yaml.contains("\nname: rtac0\n"), "{yaml}");
    let mine = yaml.replace("\nname: rtac0\n", "\nname: mine\n");
    std::fs::write(tmp.path().join("mine.yaml"), mine).unwrap();
    let o = run(
        tmp.path(),
        &[
            "fixtures",
            "mine.yaml",
            "--semidomes",
            "0",
            "--format",
            "stl",
            "--out",
            "f",
        ],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("  pin dome: 13 holes")
            && !text(&o.stdout).contains("from the paper"),
        "{}",
        text(&o.stdout)
    );
    // a design that reproduces no paper with a kit keeps fabkit's dome and says how to get
    // patterns
    let o = run(
        tmp.path(),
        &["fixtures", "shadowtac", "--format", "stl", "--out", "e"],
        &[],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        !text(&o.stdout).contains("from the paper")
            && text(&o.stdout).contains("hint: no semi-dome pattern was asked for"),
        "{}",
        text(&o.stdout)
    );
}
