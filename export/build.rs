//! Lists the CadQuery twin package for `src/step.rs` to embed (`$OUT_DIR/twins.rs`): every
//! family twin module `python/twins/cq_*.py` with the package's `__init__.py`, `families.py`
//! and `step_export.py`, in file-name order. A new family's twin is one new `cq_<family>.py`
//! (and its line in `cq_twin.TWINS`); the checking and benchmark scripts beside them are not
//! embedded.

use std::path::PathBuf;

/// The package's modules that are not family twins but are embedded.
const PACKAGE: [&str; 3] = ["__init__.py", "families.py", "step_export.py"];

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = PathBuf::from(manifest).join("python").join("twins");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| PACKAGE.contains(&n.as_str()) || (n.starts_with("cq_") && n.ends_with(".py")))
        .collect();
    names.sort();
    let mut out = String::from("&[\n");
    for n in &names {
        let path = dir.join(n);
        out.push_str(&format!(
            "    ({n:?}, include_str!({:?})),\n",
            path.to_str().expect("the twins' path is UTF-8")
        ));
    }
    out.push_str("]\n");
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    std::fs::write(out_dir.join("twins.rs"), out)
        .unwrap_or_else(|e| panic!("writing {}: {e}", out_dir.display()));
}
