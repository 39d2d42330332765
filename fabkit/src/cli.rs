//! The `fabkit` command line: argument parsing, dispatch, progress and error printing.
//! No geometry here.

use crate::args::{load_design, print_parts, tolerance, DataFileArgs, MeshOutputArgs};
use clap::{Parser, Subcommand, ValueEnum};
use fabkit_designs::schema::MoldStrategy;
use fabkit_designs::timings;
use fabkit_designs::{build_kit_bounded, library, ChordTolerance};
use fabkit_export::write_kit_reporting;
use std::error::Error;

use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "fabkit",
    version,
    about = "Parametric fabrication kits for vision-based tactile sensors"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Build a design's parts and write printer-ready STL + 3MF, manifest.json and FABRICATION.md.
    Export(ExportArgs),
    /// Build a design's calibration fixtures (pin-hole dome + point table, semi-domes, indenters).
    Fixtures(crate::fixtures_cmd::FixturesArgs),
    /// Camera calibration: extrinsics from pin-dome observations.
    #[command(subcommand)]
    Calibrate(crate::calibrate_cmd::CalibrateCommand),
    /// Ground-truth depth maps of the protrusion semi-domes (or the pin dome's captures, or a
    /// real press of a sphere fitted in its capture) through the calibrated camera.
    Groundtruth(crate::groundtruth_cmd::GroundTruthArgs),
    /// Build and measure many variants of a design over a parameter grid (results table).
    Sweep(crate::sweep_cmd::SweepArgs),
    /// List the designs embedded in fabkit.
    Designs,
    /// Print a library design's YAML (with its comments), a template to start a design from.
    /// Its first line points editors at `design.schema.json` beside the file (write it with
    /// `fabkit schema > design.schema.json`).
    Show {
        /// The name of a library design (`fabkit designs` lists them).
        design: String,
        /// Write the template to this file instead of printing it (an existing file is never
        /// replaced).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Check a design and print every parameter path with its resolved value (the paths a
    /// preset or a sweep can set) and the resolved layer stack, without writing anything.
    Validate {
        /// A design YAML file or the name of a library design (default: rtac0).
        design: Option<String>,
        #[arg(long, default_value_t = ChordTolerance::DEFAULT_MM)]
        chord_tolerance_mm: f64,
        /// Apply one of the design's presets.
        #[arg(long)]
        preset: Option<String>,
        #[command(flatten)]
        data_files: DataFileArgs,
    },
    /// Print the JSON Schema (draft 2020-12) of a design file as pretty JSON: every key with
    /// its type, unit and bounds (lengths in mm, angles in degrees), generated from the design
    /// types. Editors use it to complete and check design YAML (designs/design.schema.json is
    /// this output); rules between keys are checked by `fabkit validate` only.
    Schema,
}

#[derive(clap::Args, Debug)]
struct ExportArgs {
    /// A design YAML file or the name of a library design (default: rtac0).
    design: Option<String>,
    /// Output directory (default: out/<design name>). Replaced as a whole if it holds a
    /// previous export; refused if it holds anything else.
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    mesh: MeshOutputArgs,
    /// Apply one of the design's presets (see `fabkit designs`); the kit is named
    /// <design>_<preset>.
    #[arg(long)]
    preset: Option<String>,
    /// Override the design's mold strategy for every cast layer; when that changes the design,
    /// the kit is named <design>_mold_<strategy> (and so is its default output folder).
    #[arg(long)]
    mold_strategy: Option<Strategy>,
    /// Replace an earlier export in --out made with other options (another design, preset,
    /// mold strategy or chord tolerance); without it that export is kept and this one refused.
    /// Another command's output (fixtures, ground truth, calibration) is never replaced.
    #[arg(long)]
    force: bool,
    /// Print where the time went to stderr after the export: the wall and CPU time of each
    /// stage (reading, checks, parts, pours, assembly and fit check, meshes, pictures, plates,
    /// 3MF, manifest and sheet, writing) and of the whole command; CPU / wall is the number of
    /// cores a stage kept busy.
    #[arg(long)]
    timings: bool,
    /// With --format mjcf, urdf or usd: a calibrated camera's file (OpenCV or ROS YAML, as
    /// `calibrate extrinsics` reads it), whose intrinsics the simulators' camera takes in place
    /// of the design's nominal camera; with --extrinsics.
    #[arg(long, requires = "extrinsics", value_name = "camera.yaml")]
    camera: Option<PathBuf>,
    /// With --format mjcf, urdf or usd: the `extrinsics.json` of `fabkit calibrate extrinsics`
    /// (T_cam_sensor) that places the simulators' camera; with --camera.
    #[arg(long, requires = "camera", value_name = "extrinsics.json")]
    extrinsics: Option<PathBuf>,
    #[command(flatten)]
    data_files: DataFileArgs,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq)]
enum Strategy {
    Direct,
    Master,
    /// One-piece open mold for a solid skin.
    Open,
    /// Cavity block and reservoir top piece for a solid skin.
    #[value(name = "two_piece_open")]
    TwoPieceOpen,
}

/// The command line's definition (every command, argument and help text), for generated
/// documentation: the user guide's command reference is rendered from it.
pub fn command() -> clap::Command {
    <Cli as clap::CommandFactory>::command()
}

/// The first line of every library design: editors with a YAML language server check the
/// file against the schema in designs/.
const LIBRARY_MODELINE: &str = "# yaml-language-server: $schema=../design.schema.json\n";
/// The same line in a template written by `fabkit show`: the schema beside the file.
const TEMPLATE_MODELINE: &str = "# yaml-language-server: $schema=design.schema.json\n";

/// Runs the CLI; returns the process exit code (0 ok, 2 error).
pub fn main() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let _ = e.print();
            return if e.use_stderr() { 2 } else { 0 };
        }
    };
    match run(cli) {
        Ok(()) => 0,
        Err(e) => {
            eprint!("{}", error_report(e.as_ref()));
            2
        }
    }
}

/// `v` with every number that is not an integer rounded to 1e-9 (float noise such as
/// `-1.5999999999999996` or `1.1e-16` printed as `-1.6` and `0`).
fn rounded(v: &serde_json::Value) -> serde_json::Value {
    use serde_json::Value;
    match v {
        Value::Number(n) if !(n.is_i64() || n.is_u64()) => {
            let x = n.as_f64().unwrap_or(0.0);
            let r = (x * 1e9).round() / 1e9;
            let r = if r == 0.0 { 0.0 } else { r };
            serde_json::Number::from_f64(r).map_or(Value::Null, Value::Number)
        }
        Value::Array(a) => Value::Array(a.iter().map(rounded).collect()),
        Value::Object(o) => Value::Object(o.iter().map(|(k, x)| (k.clone(), rounded(x))).collect()),
        other => other.clone(),
    }
}

/// `error: <e>` and each cause on its own `  caused by:` line, except a cause whose text the
/// lines above already state ([`fabkit_designs::error_report`]).
pub fn error_report(e: &(dyn std::error::Error + 'static)) -> String {
    format!("error: {}\n", fabkit_designs::error_report(e))
}

/// A ticking spinner on stderr for a build step (hidden when stderr is not a terminal).
pub(crate) fn spinner(message: String) -> indicatif::ProgressBar {
    let s = indicatif::ProgressBar::new_spinner();
    s.set_message(message);
    s.enable_steady_tick(std::time::Duration::from_millis(120));
    s
}

fn run(cli: Cli) -> Result<(), Box<dyn Error>> {
    match cli.command {
        Command::Designs => {
            for (name, _) in library::LIBRARY {
                let d = library::load(name)?;
                let default = if *name == library::DEFAULT_DESIGN {
                    " (default)"
                } else {
                    ""
                };
                let presets = if d.presets.is_empty() {
                    String::new()
                } else {
                    let names: Vec<&str> = d.presets.keys().map(String::as_str).collect();
                    format!("\tpresets: {}", names.join(", "))
                };
                out!(
                    "{name}{default}\t{}\t[{}]{presets}",
                    d.description,
                    d.source
                );
            }
            Ok(())
        }
        Command::Validate {
            design,
            chord_tolerance_mm,
            preset,
            data_files,
        } => {
            let tol = tolerance(chord_tolerance_mm)?;
            let mut loaded = load_design(design.as_deref(), &data_files)?;
            if let Some(p) = &preset {
                loaded.apply_preset(p)?;
            }
            let stack = fabkit_designs::validate_design(&loaded.design, tol)?;
            out!("{}: valid", loaded.source);
            out!(
                "\nparameters of {} (each path can be set by a preset or varied by `fabkit sweep`; numbers rounded to 1e-9):",
                loaded.design.name
            );
            // one copy for every lookup: value_at adds a null for an unset optional key,
            // which only reads as unset
            let mut json = serde_json::to_value(&loaded.design)?;
            for path in fabkit_sweep::parameter_paths(&loaded.design) {
                let value = fabkit_designs::schema::value_at(&mut json, &path)
                    .map(|x| rounded(x))
                    .unwrap_or(serde_json::Value::Null);
                let shown = if value.is_null() {
                    "(not set)".to_string()
                } else {
                    serde_json::to_string(&value)?
                };
                out!("  {path} = {shown}");
            }
            out!("\nresolved layer stack (mm, inner to outer):");
            out!("{}", serde_json::to_string_pretty(&rounded(&stack))?);
            Ok(())
        }
        Command::Show { design, out } => {
            let library_text = library::yaml(&design).ok_or_else(|| {
                let names: Vec<&str> = library::LIBRARY.iter().map(|(n, _)| *n).collect();
                format!(
                    "show: '{design}' is not a library design (they are: {})",
                    names.join(", ")
                )
            })?;
            // The library's modeline names the schema relative to designs/library/; a
            // template lives wherever the user saves it, with the schema beside it.
            let text = match library_text.strip_prefix(LIBRARY_MODELINE) {
                Some(rest) => format!("{TEMPLATE_MODELINE}{rest}"),
                None => library_text.to_string(),
            };
            match out {
                None => {
                    use std::io::Write as _;
                    std::io::stdout().write_all(text.as_bytes())?;
                }
                Some(path) => {
                    // create_new: a file of the user's is never replaced
                    let mut f = std::fs::OpenOptions::new()
                        .write(true)
                        .create_new(true)
                        .open(&path)
                        .map_err(|e| {
                            format!(
                                "--out {}: {e} (the template is written to a new file only; choose another name)",
                                path.display()
                            )
                        })?;
                    use std::io::Write as _;
                    if let Err(e) = f.write_all(text.as_bytes()).and_then(|()| f.sync_all()) {
                        drop(f);
                        let _ = std::fs::remove_file(&path);
                        return Err(format!("--out {}: {e}", path.display()).into());
                    }
                    out!(
                        "{design}: template written to {} (rename `name:` before exporting; \
                         `fabkit schema > design.schema.json` beside it lets an editor complete \
                         and check it)",
                        path.display()
                    );
                }
            }
            Ok(())
        }
        Command::Schema => {
            use std::io::Write as _;
            let text = fabkit_designs::schema::design_json_schema_text();
            std::io::stdout().write_all(text.as_bytes())?;
            Ok(())
        }
        Command::Export(args) => export(args),
        Command::Fixtures(args) => crate::fixtures_cmd::run(args),
        Command::Calibrate(cmd) => crate::calibrate_cmd::run(cmd),
        Command::Groundtruth(args) => crate::groundtruth_cmd::run(args),
        Command::Sweep(args) => crate::sweep_cmd::run(args),
    }
}

fn export(args: ExportArgs) -> Result<(), Box<dyn Error>> {
    let (wall0, cpu0) = (std::time::Instant::now(), timings::cpu_seconds());
    if args.timings {
        timings::enable();
    }
    let tol = args.mesh.tolerance()?;
    let mut loaded = args.mesh.load(
        args.design.as_deref(),
        args.preset.as_deref(),
        &args.data_files,
    )?;
    if let Some(s) = args.mold_strategy {
        let s = match s {
            Strategy::Direct => MoldStrategy::Direct,
            Strategy::Master => MoldStrategy::Master,
            Strategy::Open => MoldStrategy::Open,
            Strategy::TwoPieceOpen => MoldStrategy::TwoPieceOpen,
        };
        let before = loaded.design.clone();
        loaded.design.mold.strategy = s;
        for l in &mut loaded.design.layers {
            l.mold_strategy = None;
        }
        if loaded.design != before {
            let key = serde_json::to_value(s)?;
            loaded.design.name = format!(
                "{}_mold_{}",
                loaded.design.name,
                key.as_str().unwrap_or("other")
            );
        }
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(&loaded.design.name));
    let mut opts = args.mesh.options(&loaded, tol);
    opts.force = args.force;
    if let (Some(camera), Some(extrinsics)) = (&args.camera, &args.extrinsics) {
        let f = &opts.formats;
        if !(f.mjcf || f.urdf || f.usd) {
            return Err(
                "--camera and --extrinsics place the simulators' camera: give --format mjcf, urdf or usd"
                    .into(),
            );
        }
        opts.sim.camera = Some(crate::args::calibrated_sim_camera(
            &loaded.design.name,
            camera,
            extrinsics,
        )?);
        opts.sim.notes.retain(|n| !n.starts_with("no camera: "));
    }
    // The output folder is checked before anything is built.
    fabkit_export::check_out_dir(&out, &opts.claim(&loaded.design.name))?;
    args.mesh.check_csg()?;
    let building = format!(
        "building {} at {} mm chord tolerance",
        loaded.design.name,
        tol.mm()
    );
    // a spinner on a terminal, plain lines in a log or a pipe (issue 102)
    let plain = !std::io::IsTerminal::is_terminal(&std::io::stderr());
    if plain {
        eprintln!("export: {building}");
    }
    let spinner = spinner(building);
    let t0 = std::time::Instant::now();
    // The work is estimated and bounded before anything is built.
    let kit = build_kit_bounded(&loaded.design, tol, args.mesh.max_triangles);
    spinner.finish_and_clear();
    let kit = kit?;
    if plain {
        let (p, c) = (kit.parts.len(), kit.casts.len());
        eprintln!(
            "export: built {p} part{} and {c} cast{} in {:.1} s; writing them to {}",
            if p == 1 { "" } else { "s" },
            if c == 1 { "" } else { "s" },
            t0.elapsed().as_secs_f64(),
            out.display()
        );
    }
    // STEP export takes seconds a part: one plain line per part (a terminal, a log or a pipe)
    let step_progress = |i: usize, n: usize, part: &str| eprintln!("STEP {i}/{n}: {part}");
    let summary = write_kit_reporting(&kit, &[], &out, &opts, Some(&step_progress))?;
    if args.mesh.csg.is_some() {
        let _t = timings::stage("CSG tree");
        args.mesh.write_csg(&kit)?;
    }
    for w in &summary.warnings {
        eprintln!("warning: {w}");
    }
    out!(
        "{}: {} parts, {} casts -> {} ({} files, {:.2} s)",
        loaded.design.name,
        kit.parts.len(),
        kit.casts.len(),
        out.display(),
        summary.files.len(),
        t0.elapsed().as_secs_f64()
    );
    print_parts(&summary.manifest.parts);
    if let Some(markers) = kit.summary.get("markers").and_then(|m| m.as_array()) {
        for m in markers {
            out!(
                "  markers on {} ({}): {} features ({}), nearest-neighbour spacing on the surface min {:.3} mm, median {:.3} mm; printable with {}; formed by {}",
                m["layer"].as_str().unwrap_or("?"),
                m["surface"].as_str().unwrap_or("?"),
                m["count"],
                fabkit_export::marker_feature_words(m),
                m["min_spacing_mm"].as_f64().unwrap_or(0.0),
                m["median_spacing_mm"].as_f64().unwrap_or(0.0),
                m["printable_with"].as_array().map(|a| a.iter().filter_map(|x| x.as_str()).collect::<Vec<_>>().join(", ")).unwrap_or_default(),
                fabkit_export::marker_formers(m)
            );
        }
    }
    for c in &kit.casts {
        let comps: Vec<String> = c
            .components
            .iter()
            .map(|x| format!("{} {:.2} g", x.name, x.mass_g))
            .collect();
        out!(
            "  cast {}: {} {:.2} mL -> {}",
            c.step,
            c.cast,
            c.cavity_volume_ml,
            comps.join(", ")
        );
    }
    if args.timings {
        eprint!(
            "{}",
            timings::table(
                &timings::take(),
                wall0.elapsed().as_secs_f64(),
                timings::cpu_seconds() - cpu0
            )
        );
    }
    Ok(())
}
