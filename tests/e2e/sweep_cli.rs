//! End to end: `fabkit sweep` and `fabkit sweep merge` (issue 8).
//!
//! - shards 0..N-1 merged give the unsharded results table byte for byte;
//! - an infeasible variant in the middle of a sweep is reported and the others are built;
//! - a sweep killed mid-run completes only the missing variants when re-run;
//! - variant folders hold the files of `fabkit export`, measured like the results table;
//! - sweep file errors stop the run before anything is written;
//! - a sweep of too many variants is refused by its count (issue 70).
//!
//! The ShadowTac `paper_text` open mold at 0.05 mm chord tolerance keeps each variant near 0.3 s.

use crate::common::{run, snapshot, spawn_held, text};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;

/// 9 variants: spacing x feature diameter; the dimples are pins in the mold, and the 0.25 mm
/// diameter (the middle value) is below the SLA profile's 0.3 mm minimum feature, so variants
/// 1, 4 and 7 are infeasible.
const SWEEP: &str = "base: shadowtac
preset: paper_text
chord_tolerance_mm: 0.05
vary:
  layers[0].markers[0].pattern.spacing_mm: {range: [1.6, 2.0, 0.2]}
  layers[0].markers[0].feature.diameter_mm: [0.45, 0.25, 0.5]
mode: grid
outputs: [metrics]
";

fn write_sweep(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).unwrap();
    name.to_string()
}

fn ok(o: &std::process::Output) {
    assert!(
        o.status.success(),
        "fabkit failed: {}\n{}",
        text(&o.stdout),
        text(&o.stderr)
    );
}

fn jsonl(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The CSV's lines with the `build_time_s` column removed, and that column's cells.
fn without_build_time(csv: &str) -> (Vec<String>, Vec<String>) {
    let lines: Vec<&str> = csv.lines().collect();
    let col = lines[0]
        .split(',')
        .position(|c| c == "build_time_s")
        .unwrap();
    let mut rest = Vec::new();
    let mut times = Vec::new();
    for l in &lines {
        // build_time_s comes before `errors`, the only column whose text may hold commas
        let mut cells: Vec<&str> = l.splitn(col + 2, ',').collect();
        times.push(cells.remove(col).to_string());
        rest.push(cells.join(","));
    }
    (rest, times[1..].to_vec())
}

#[test]
fn merged_shards_equal_the_unsharded_table_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let s = write_sweep(d, "sweep.yaml", SWEEP);
    ok(&run(
        d,
        &[
            "sweep",
            &s,
            "--out",
            "whole",
            "--no-build-time",
            "--jobs",
            "2",
        ],
        &[],
    ));
    for (i, jobs) in [(0, "1"), (1, "2"), (2, "1")] {
        let shard = format!("{i}/3");
        let out = format!("shard{i}");
        ok(&run(
            d,
            &[
                "sweep", &s, "--out", &out, "--shard", &shard, "--jobs", jobs,
            ],
            &[],
        ));
        let rows = jsonl(&d.join(&out).join("results.jsonl"));
        let idx: Vec<u64> = rows.iter().map(|r| r["index"].as_u64().unwrap()).collect();
        let want: Vec<u64> = (0..9).filter(|k| k % 3 == i).collect();
        assert_eq!(idx, want, "shard {shard} runs every third variant from {i}");
    }
    let shards = ["shard2", "shard0", "shard1"]; // any order
    let mut args = vec!["sweep", "merge"];
    args.extend(shards);
    ok(&run(
        d,
        &[&args[..], &["--out", "merged", "--no-build-time"]].concat(),
        &[],
    ));
    for f in ["results.csv", "results.jsonl"] {
        let a = std::fs::read(d.join("whole").join(f)).unwrap();
        let b = std::fs::read(d.join("merged").join(f)).unwrap();
        assert!(a == b, "{f} differs:\n{}\n---\n{}", text(&a), text(&b));
    }
    let csv = std::fs::read_to_string(d.join("whole/results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 10);
    assert!(csv.starts_with(
        "index,id,layers[0].markers[0].pattern.spacing_mm,layers[0].markers[0].feature.diameter_mm,status,part.skin_open_mold.volume_mm3,"
    ));

    // With build times: every other column is still the same, and the times are there.
    ok(&run(
        d,
        &[&args[..], &["--out", "merged_timed"]].concat(),
        &[],
    ));
    let timed = std::fs::read_to_string(d.join("merged_timed/results.csv")).unwrap();
    let (rest_timed, times) = without_build_time(&timed);
    let (rest_whole, blank) = without_build_time(&csv);
    assert_eq!(rest_timed, rest_whole);
    assert!(blank.iter().all(String::is_empty));
    assert!(
        times
            .iter()
            .all(|t| t.parse::<f64>().is_ok_and(|x| x > 0.0)),
        "{times:?}"
    );

    // A missing shard, a shard given twice, another split, an unfinished shard: refused with
    // exit code 2, nothing written.
    let refused: [(&[&str], &str, bool); 4] = [
        (&["shard0", "shard2"], "missing shard(s) 1/3", false),
        (&["shard0", "shard1", "shard1"], "shards overlap", false),
        (&["shard0", "whole"], "different splits", false),
        (&["shard0", "shard1", "shard2"], "did not finish", true),
    ];
    for (k, (dirs, want, unfinished)) in refused.into_iter().enumerate() {
        if unfinished {
            std::fs::remove_file(d.join("shard1/results.jsonl")).unwrap();
        }
        let out = format!("m{k}");
        let o = run(
            d,
            &[&["sweep", "merge"], dirs, &["--out", &out]].concat(),
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{dirs:?}");
        assert!(
            text(&o.stderr).contains(want),
            "{dirs:?}: {}",
            text(&o.stderr)
        );
        assert!(!d.join(&out).exists(), "{out} was written");
    }

    // Records edited by hand (a shard index past its count, a count of 0, counts that would
    // size a huge allocation): refused as records fabkit did not write, nothing written.
    let record = std::fs::read_to_string(d.join("shard0/sweep.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&record).unwrap();
    let tampered: [(&str, serde_json::Value, &str); 3] = [
        (
            "shard",
            serde_json::json!({"index": 5, "count": 3}),
            "shard = 5/3: needs 0 <= I < N",
        ),
        (
            "shard",
            serde_json::json!({"index": 0, "count": 0}),
            "shard = 0/0: needs 0 <= I < N",
        ),
        (
            "variant_count",
            serde_json::json!(u64::MAX / 2),
            "variant_count = 9223372036854775807: must be at most 10000000",
        ),
    ];
    for (k, (field, value, want)) in tampered.into_iter().enumerate() {
        let mut j = json.clone();
        j[field] = value;
        std::fs::write(d.join("shard0/sweep.json"), serde_json::to_vec(&j).unwrap()).unwrap();
        let out = format!("t{k}");
        let o = run(
            d,
            &["sweep", "merge", "shard0", "shard1", "--out", &out],
            &[],
        );
        assert_eq!(o.status.code(), Some(2), "{field}");
        assert!(
            text(&o.stderr).contains(want),
            "{field}: {}",
            text(&o.stderr)
        );
        assert!(!d.join(&out).exists(), "{out} was written");
    }
    std::fs::write(d.join("shard0/sweep.json"), record).unwrap();

    // --jobs past 4 x the CPUs (or 0), and a shard count past the most variants a sweep has.
    let cpus = std::thread::available_parallelism().map_or(1, usize::from);
    let many = (4 * cpus + 1).to_string();
    for (args, want) in [
        (
            vec!["--jobs", many.as_str()],
            format!("jobs = {many}: must be from 1 to {}", 4 * cpus),
        ),
        (
            vec!["--jobs", "0"],
            format!("jobs = 0: must be from 1 to {}", 4 * cpus),
        ),
        (
            vec!["--shard", "0/99999999999"],
            "N must be at most 10000000".to_string(),
        ),
    ] {
        let mut a = vec!["sweep", s.as_str(), "--out", "j"];
        a.extend(args.iter().copied());
        let o = run(d, &a, &[]);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(
            text(&o.stderr).contains(&want),
            "{args:?}: {}",
            text(&o.stderr)
        );
        assert!(!d.join("j").exists(), "{args:?}: output written");
    }
}

#[test]
fn an_infeasible_variant_is_recorded_and_the_sweep_goes_on() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let s = write_sweep(d, "sweep.yaml", SWEEP);
    let o = run(d, &["sweep", &s, "--out", "out"], &[]);
    ok(&o);
    assert!(
        text(&o.stdout)
            .contains("9 variants: 9 built, 0 skipped (complete); 6 ok, 3 infeasible, 0 errors"),
        "{}",
        text(&o.stdout)
    );
    // reported as it happens (plain lines when stderr is not a terminal)
    let err = text(&o.stderr);
    assert!(
        err.contains("variant 4 (") && err.contains("infeasible: layers[0].markers[0].feature.diameter_mm = 0.25: below the minimum feature 0.3 mm of printer profile 'sla'"),
        "{err}"
    );
    let rows = jsonl(&d.join("out/results.jsonl"));
    assert_eq!(rows.len(), 9);
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r["index"], k);
        let diameter = r["params"]["layers[0].markers[0].feature.diameter_mm"]
            .as_f64()
            .unwrap();
        if diameter == 0.25 {
            assert_eq!(r["status"], "infeasible");
            assert!(r["metrics"].is_null());
            assert_eq!(r["errors"].as_array().unwrap().len(), 1, "{r}");
        } else {
            assert_eq!(r["status"], "ok", "{r}");
            let m = &r["metrics"];
            // the measured spacing follows the varied spacing, the thinnest wall is at most the
            // wall between the features' bases (the spacing less the diameter; dimples also
            // converge inwards and near the base plane) and at least SLA's 0.4 mm, and only SLA
            // makes sub-0.5 mm pins
            let spacing = r["params"]["layers[0].markers[0].pattern.spacing_mm"]
                .as_f64()
                .unwrap();
            let mk = &m["markers"][0];
            let median = mk["median_spacing_mm"].as_f64().unwrap();
            // measured within 0.6 %
            assert!(
                (median - spacing).abs() < 0.07 * spacing,
                "{median} vs {spacing}"
            );
            let min = mk["min_spacing_mm"].as_f64().unwrap();
            let wall = m["min_wall_mm"].as_f64().unwrap();
            assert!(
                wall <= min - diameter + 1e-12 && wall >= 0.4,
                "{wall} vs {min} - {diameter}"
            );
            let verdict = |p: usize| r["printability"][p]["printable"].as_bool().unwrap();
            assert_eq!(
                (verdict(0), verdict(1), verdict(2)),
                (false, true, diameter >= 0.5)
            );
            // measured 14,406 to 14,420 mm3 and 4.89 to 4.90 g
            assert!(m["parts"][0]["volume_mm3"].as_f64().unwrap() > 1.0e4);
            assert!(m["casts"][0]["total_mass_g"].as_f64().unwrap() > 4.0);
        }
    }
}

/// Lists the ids with a result file in `variants/`.
fn complete_ids(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir.join("variants"))
        .unwrap()
        .filter_map(|e| {
            let n = e.unwrap().file_name().to_string_lossy().into_owned();
            n.strip_suffix(".json")
                .filter(|s| !s.starts_with('.'))
                .map(str::to_owned)
        })
        .collect()
}

#[test]
fn a_killed_sweep_completes_only_the_missing_variants() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // 12 feasible variants, built one at a time
    let s = write_sweep(
        d,
        "sweep.yaml",
        "base: shadowtac
preset: paper_text
chord_tolerance_mm: 0.05
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.6, 1.65, 1.7, 1.8, 1.9, 2.0]
  layers[0].markers[0].feature.height_mm: [0.25, 0.3]
",
    );
    // held once its third variant's result is written (one job: one variant at a time)
    let mut child = spawn_held(
        d,
        &["sweep", &s, "--out", "out", "--jobs", "1"],
        "sweep-variant-written",
        3,
    );
    child.kill().unwrap(); // SIGKILL: no chance to clean up
    child.wait().unwrap();
    let out = d.join("out");
    assert!(!out.join("results.csv").exists());
    let before = complete_ids(&out);
    assert_eq!(before.len(), 3, "{before:?}");
    let bytes: Vec<Vec<u8>> = before
        .iter()
        .map(|id| std::fs::read(out.join("variants").join(format!("{id}.json"))).unwrap())
        .collect();

    let o = run(d, &["sweep", &s, "--out", "out", "--jobs", "2"], &[]);
    ok(&o);
    let missing = 12 - before.len();
    assert!(
        text(&o.stdout).contains(&format!(
            "12 variants: {missing} built, {} skipped (complete); 12 ok",
            before.len()
        )),
        "{}",
        text(&o.stdout)
    );
    // the variants built now are exactly those without a result before
    let built: BTreeSet<String> = text(&o.stderr)
        .lines()
        .filter_map(|l| {
            let i = l.find(" (")?;
            let j = l[i..].find(')')?;
            l.contains("] variant ")
                .then(|| l[i + 2..i + j].to_string())
        })
        .collect();
    let all = complete_ids(&out);
    assert_eq!(all.len(), 12);
    let expected: BTreeSet<String> = all.difference(&before).cloned().collect();
    assert_eq!(built, expected);
    // the results of the first run were kept as they were (build times included)
    for (id, b) in before.iter().zip(&bytes) {
        let now = std::fs::read(out.join("variants").join(format!("{id}.json"))).unwrap();
        assert!(now == *b, "variant {id} was rewritten");
    }
    // no temporary file left behind, and a complete table
    let names: Vec<String> = std::fs::read_dir(out.join("variants"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "{names:?}");
    assert_eq!(jsonl(&out.join("results.jsonl")).len(), 12);

    // a third run has nothing left to do
    let o = run(d, &["sweep", &s, "--out", "out"], &[]);
    ok(&o);
    assert!(
        text(&o.stdout).contains("0 built, 12 skipped"),
        "{}",
        text(&o.stdout)
    );
}

#[test]
fn variant_folders_hold_the_export_files() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let s = write_sweep(
        d,
        "sweep.yaml",
        "base: shadowtac
preset: paper_text
chord_tolerance_mm: 0.05
vary:
  layers[0].markers[0].pattern.spacing_mm: [1.8, 2.0]
outputs: [metrics, files]
",
    );
    ok(&run(d, &["sweep", &s, "--out", "out"], &[]));
    let out = d.join("out");
    let rows = jsonl(&out.join("results.jsonl"));
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let id = r["id"].as_str().unwrap();
        let v = out.join("variants").join(id);
        assert!(v.join("parts/skin_open_mold.stl").is_file());
        assert!(v.join("shadowtac_paper_text.3mf").is_file());
        let m: Value =
            serde_json::from_str(&std::fs::read_to_string(v.join("manifest.json")).unwrap())
                .unwrap();
        // the table's numbers are the manifest's: the same mesh, the same computation
        assert_eq!(
            m["parts"][0]["volume_mm3"],
            r["metrics"]["parts"][0]["volume_mm3"]
        );
        assert_eq!(
            m["parts"][0]["triangles"],
            r["metrics"]["parts"][0]["triangles"]
        );
        assert_eq!(
            m["casts"][0]["total_mass_g"],
            r["metrics"]["casts"][0]["total_mass_g"]
        );
        assert!(m["design"]["source"].as_str().unwrap().contains(id));
    }
    // a variant whose files went missing is built again, the other is not
    let gone = rows[1]["id"].as_str().unwrap();
    std::fs::remove_dir_all(out.join("variants").join(gone)).unwrap();
    let o = run(d, &["sweep", &s, "--out", "out"], &[]);
    ok(&o);
    assert!(
        text(&o.stdout).contains("1 built, 1 skipped"),
        "{}",
        text(&o.stdout)
    );
    assert!(
        text(&o.stderr).contains(&format!("({gone}) ok")),
        "{}",
        text(&o.stderr)
    );
    assert!(out
        .join("variants")
        .join(gone)
        .join("manifest.json")
        .is_file());
}

#[test]
fn sweep_file_errors_stop_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let s = write_sweep(
        d,
        "bad.yaml",
        "base: shadowtac\nvary:\n  markers.spacing: {range: [1.2, 2.0, 0.2]}\n",
    );
    let o = run(d, &["sweep", &s, "--out", "out"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("bad.yaml:3:3: vary: 'markers.spacing' is not a parameter path of design 'shadowtac'; nearest: layers[0].markers[0].pattern.spacing_mm"),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.join("out").exists());
    // a folder that is not a sweep is refused
    std::fs::create_dir(d.join("mine")).unwrap();
    std::fs::write(d.join("mine/notes.txt"), "keep").unwrap();
    let s = write_sweep(d, "ok.yaml", SWEEP);
    let o = run(d, &["sweep", &s, "--out", "mine"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("holds no fabkit sweep"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(std::fs::read_dir(d.join("mine")).unwrap().count(), 1);
    // A look-alike sweep.json does not make a folder a sweep's: nothing in it is touched.
    std::fs::write(d.join("mine/sweep.json"), "{\"mine\": 1}\n").unwrap();
    std::fs::write(d.join("mine/results.csv"), "my,data\n").unwrap();
    let o = run(d, &["sweep", &s, "--out", "mine"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("sweep.json is not a fabkit sweep record"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(d.join("mine/sweep.json")).unwrap(),
        "{\"mine\": 1}\n"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("mine/results.csv")).unwrap(),
        "my,data\n"
    );
    assert_eq!(std::fs::read_dir(d.join("mine")).unwrap().count(), 3);
    // A sweep folder a user added a file to is theirs too (also under variants/).
    let o = run(d, &["sweep", &s, "--out", "ours"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    for extra in ["ours/plot.png", "ours/variants/.notes"] {
        std::fs::write(d.join(extra), "keep").unwrap();
        let o = run(d, &["sweep", &s, "--out", "ours"], &[]);
        assert_eq!(o.status.code(), Some(2), "{extra}");
        assert!(
            text(&o.stderr).contains("is not a file a sweep writes"),
            "{extra}: {}",
            text(&o.stderr)
        );
        assert_eq!(std::fs::read_to_string(d.join(extra)).unwrap(), "keep");
        std::fs::remove_file(d.join(extra)).unwrap();
    }
    let o = run(d, &["sweep", &s, "--out", "ours"], &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// A grid of 10^21 variants (seven parameters of 1000 values) is refused by its count, before
/// any value is set into the design or any probe is built, and nothing is written.
#[test]
fn a_sweep_of_too_many_variants_is_refused_by_its_count() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let vary: String = [
        "layers[0].markers[0].pattern.spacing_mm",
        "layers[0].markers[0].feature.height_mm",
        "layers[0].markers[0].feature.diameter_mm",
        "body.base_diameter_mm",
        "body.height_mm",
        "backing.diameter_mm",
        "backing.thickness_mm",
    ]
    .iter()
    .map(|p| format!("  {p}: {{range: [1, 1000, 1]}}\n"))
    .collect();
    let s = write_sweep(
        d,
        "huge.yaml",
        &format!("base: shadowtac\npreset: paper_text\nvary:\n{vary}"),
    );
    let o = run(d, &["sweep", &s, "--out", "out"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains(
            "huge.yaml: the sweep has 1000000000000000000000 variants (1000 x 1000 x 1000 x 1000 \
             x 1000 x 1000 x 1000), more than the 10000000 allowed"
        ),
        "{}",
        text(&o.stderr)
    );
    assert!(!d.join("out").exists());
}

/// Issue 95, data loss: a sweep, a shard or a merge written into another sweep's folder (or
/// into another shard's) replaced its tables and left its variants beside the new table. Now
/// refused, naming both sweeps, and the folder is left as it was; with --force the folder is
/// replaced whole (none of the other sweep's variants stay); the same shard still resumes.
#[test]
fn another_sweeps_folder_is_refused_and_replaced_only_whole_with_force() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let a = write_sweep(d, "a.yaml", SWEEP);
    let b = write_sweep(
        d,
        "b.yaml",
        &SWEEP
            .replace("[0.45, 0.25, 0.5]", "[0.45]")
            .replace("2.0, 0.2", "1.8, 0.2"),
    );
    for (i, out) in [(0, "a0"), (1, "a1")] {
        let shard = format!("{i}/2");
        ok(&run(
            d,
            &["sweep", &a, "--out", out, "--shard", &shard],
            &[],
        ));
    }
    ok(&run(d, &["sweep", &b, "--out", "B"], &[]));
    let (b_before, a0_before) = (snapshot(&d.join("B")), snapshot(&d.join("a0")));
    assert!(b_before.keys().any(|p| p.contains("variants")));
    let refused =
        |args: &[&str], folder: &str, before: &std::collections::BTreeMap<String, Vec<u8>>| {
            let o = run(d, args, &[]);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o.stdout));
            let e = text(&o.stderr);
            assert!(
                e.contains("holds the output of another sweep"),
                "{args:?}: {e}"
            );
            assert!(e.contains("--force"), "{e}");
            assert_eq!(
                &snapshot(&d.join(folder)),
                before,
                "{args:?} changed {folder}"
            );
            e
        };
    // a merge and a whole run into sweep B's folder, a shard into another shard's folder
    let e = refused(
        &["sweep", "merge", "a0", "a1", "--out", "B"],
        "B",
        &b_before,
    );
    assert!(e.contains("b.yaml") && e.contains("a.yaml"), "{e}");
    refused(&["sweep", &a, "--out", "B"], "B", &b_before);
    refused(
        &["sweep", &a, "--out", "a0", "--shard", "1/2"],
        "a0",
        &a0_before,
    );
    // the same shard resumes in its own folder
    ok(&run(
        d,
        &["sweep", &a, "--out", "a0", "--shard", "0/2"],
        &[],
    ));
    // --force replaces B whole: A's merged table, none of B's variants
    ok(&run(
        d,
        &["sweep", "merge", "a0", "a1", "--out", "B", "--force"],
        &[],
    ));
    let after = snapshot(&d.join("B"));
    assert!(
        after.keys().all(|p| !p.contains("variants")),
        "{:?}",
        after.keys().collect::<Vec<_>>()
    );
    assert_eq!(jsonl(&d.join("B/results.jsonl")).len(), 9);
}
