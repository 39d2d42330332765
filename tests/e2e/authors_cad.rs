//! End to end: fabkit's seed presets against the authors' published CAD, measured on
//! the exported files by an independent oracle (`tests/oracles/authors_cad.py`, numpy + trimesh):
//! the ShadowTac two-piece mold (cavity R22.500 cut to a 35.000 mm rim, 469 pins 0.500 mm tall
//! on the authors' axes, 45 mm reservoir 14 mm tall, 60 x 65 x 2 mm boss, 20 bolts), the R-Tac0
//! mold cavities (R15.000, R13.500), round shell tube (30.000 x 21.650 mm) and layer
//! thicknesses, the R-Tac0 pin dome and pin (R16.650 / R19.100, 0.350 mm counterbores, the
//! orientation groove, 43 mm tabs, 8.8 mm pin with a 3.0 x 3.2 mm head, the published hole
//! ids), TacTipGenerator's 217-pin layout, and the DIGIT Pinki gel, its mold's cavity block and
//! insert against the published B-rep faces (every vertex and facet centre within 10 um of a
//! sphere, cylinder, cone, torus or plane of `Pinki Gel.step` / `Pinki Gel Mold.step`) with
//! their volumes (2,132.3 and 8,835.4 mm3 within 0.1 %). The same script prints the validation chapter's table (docs/src/validation.md).

use crate::common::*;

#[test]
fn presets_match_the_authors_cad_on_the_exported_files() {
    let Some(py) = oracle_python() else {
        return missing("the oracle python (numpy + trimesh)");
    };
    let tmp = tempfile::tempdir().unwrap();
    let o = std::process::Command::new(py)
        .arg(repo_root().join("tests/oracles/authors_cad.py"))
        .arg(env!("CARGO_BIN_EXE_fabkit"))
        .arg(tmp.path())
        .output()
        .expect("python runs");
    let out = text(&o.stdout);
    assert!(
        o.status.success() && out.contains(" 0 failed") && !out.contains("FAIL"),
        "authors_cad.py:\n{out}\n{}",
        text(&o.stderr)
    );
    // every asserted row ran: 13 on ShadowTac, 4 on R-Tac0, 10 on the pin dome and pin, 1 TacTip,
    // 6 on DIGIT Pinki
    let ok = out.lines().filter(|l| l.starts_with("ok ")).count();
    assert!(ok >= 31, "only {ok} rows asserted:\n{out}");
    assert!(
        out.lines()
            .filter(|l| l.starts_with("ok   DIGIT Pinki"))
            .count()
            == 6,
        "the DIGIT Pinki rows:\n{out}"
    );
}
