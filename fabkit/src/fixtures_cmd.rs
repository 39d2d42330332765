//! `fabkit fixtures`: argument parsing and dispatch over fabkit-fixtures.

use crate::args::{DataFileArgs, MeshOutputArgs};
use crate::progress::Progress;
use fabkit_export::write_kit_reporting;
use fabkit_fixtures::params::{from_yaml, given_in, resolve, FixtureOptions, Given};
use fabkit_fixtures::FixtureProgress;
use std::error::Error;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Debug)]
pub struct FixturesArgs {
    /// A design YAML file or the name of a library design (default: rtac0).
    design: Option<String>,
    /// Output directory (default: out/<design>_fixtures). Replaced as a whole if it holds
    /// earlier fixtures of the same design and chord tolerance, as fabkit wrote them; refused if
    /// it holds anything else.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace earlier fixtures in --out of another design or chord tolerance. Another
    /// command's output (an export, ground truth, a calibration) is never replaced.
    #[arg(long)]
    force: bool,
    /// Fixture parameters (YAML: pin_dome, semidomes, grid_plate, semiplates, board, indenters);
    /// defaults where absent.
    #[arg(long)]
    params: Option<PathBuf>,
    /// Replace the pin dome with an embedded preset (rtac0: the published R-Tac0 fixture), or
    /// `default` for fabkit's own dome. Default: the dome of the paper the design reproduces
    /// (R-Tac0's for rtac0), unless --params has a pin_dome.
    #[arg(long)]
    pins_preset: Option<String>,
    /// Generate N protrusion semi-dome patterns (semi-plate patterns on a flat skin), in
    /// addition to those in --params; 0 for none. Default: the paper's count (100 for rtac0),
    /// unless --params sets `generate`.
    #[arg(long)]
    semidomes: Option<u32>,
    /// Seed of the pattern generator.
    #[arg(long)]
    seed: Option<u64>,
    /// Apply one of the design's presets.
    #[arg(long)]
    preset: Option<String>,
    #[command(flatten)]
    mesh: MeshOutputArgs,
    #[command(flatten)]
    data_files: DataFileArgs,
}

pub fn run(args: FixturesArgs) -> Result<(), Box<dyn Error>> {
    let tol = args.mesh.tolerance()?;
    let loaded = args.mesh.load(
        args.design.as_deref(),
        args.preset.as_deref(),
        &args.data_files,
    )?;
    let (base, given) = match &args.params {
        Some(path) => {
            // A regular file of bounded size, as a design file.
            let text = fabkit_designs::input_files::read_design_file(path)?;
            let params = from_yaml(&text, &path.display().to_string())?;
            (Some(params), given_in(&text))
        }
        None => (None, Given::default()),
    };
    // curved skins: semi-domes; flat skins: semi-plates; what neither sets, the design's paper's
    let resolved = resolve(
        &loaded.design,
        base,
        given,
        &FixtureOptions {
            pins_preset: args.pins_preset.as_deref(),
            patterns: args.semidomes,
            seed: args.seed,
        },
    )?;
    let params = resolved.params;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| Path::new("out").join(fabkit_fixtures::kit_name(&loaded.design.name)));
    let mut opts = args.mesh.options(&loaded, tol);
    if let Some(sim) = sim_format(&opts.formats) {
        return Err(format!("--format {sim}: the simulators' files are of the sensor (`fabkit export {} --format {sim}`), not of its fixtures; fixtures take stl, 3mf and step", loaded.design.name).into());
    }
    opts.command = fabkit_export::OutputCommand::Fixtures;
    opts.force = args.force;
    // The output folder is checked before anything is built, as `fabkit export` checks it.
    fabkit_export::check_out_dir(
        &out,
        &opts.claim(&fabkit_fixtures::kit_name(&loaded.design.name)),
    )?;
    let provenance =
        fabkit_fixtures::provenance(&loaded.design.name, &loaded.source, &loaded.sha256);
    args.mesh.check_csg()?;
    let t0 = std::time::Instant::now();
    let progress: std::sync::OnceLock<Progress> = std::sync::OnceLock::new();
    let set = fabkit_fixtures::build_fixtures_reporting(
        &loaded.design,
        &params,
        tol,
        args.mesh.max_triangles,
        &provenance,
        &|p| match p {
            FixtureProgress::Started { parts, triangles } => {
                progress.get_or_init(|| {
                    Progress::new(
                        "fixtures",
                        &format!(
                            "building the {parts} parts of {} (about {triangles} triangles)",
                            loaded.design.name
                        ),
                        parts as u64,
                    )
                });
            }
            FixtureProgress::Built { done, parts } => {
                if let Some(r) = progress.get() {
                    r.set(done as u64, parts as u64);
                }
            }
        },
    );
    let progress = progress.into_inner();
    let set = match set {
        Ok(s) => s,
        Err(e) => {
            if let Some(p) = progress {
                p.finish();
            }
            return Err(e.into());
        }
    };
    if let Some(p) = &progress {
        p.stage(&format!(
            "writing {} parts and {} data files to {}",
            set.kit.parts.len(),
            set.files.len(),
            out.display()
        ));
    }
    // STEP export takes seconds a part: each part as the CadQuery twin starts it
    let step_progress = |i: usize, n: usize, part: &str| {
        let what = format!("STEP {i}/{n}: {part}");
        match &progress {
            Some(p) => p.stage(&what),
            None => eprintln!("{what}"),
        }
    };
    let summary = write_kit_reporting(&set.kit, &set.files, &out, &opts, Some(&step_progress));
    if let Some(p) = progress {
        p.finish();
    }
    let summary = summary?;
    args.mesh.write_csg(&set.kit)?;
    for w in &summary.warnings {
        eprintln!("warning: {w}");
    }
    print_summary(&set, &params, &loaded.design, &out, t0.elapsed());
    for what in &resolved.from_paper {
        out!("  from the paper: {what}");
    }
    print_hints(&set, &args);
    crate::args::print_parts(&summary.manifest.parts);
    Ok(())
}

/// Says how to make semi-dome patterns when none were asked for and the design's paper gave
/// none (issue 102: a ground truth of such fixtures renders only the reference frame).
fn print_hints(set: &fabkit_fixtures::FixtureSet, args: &FixturesArgs) {
    let none = |n: Option<usize>| n == Some(0);
    if none(set.semidomes.as_ref().map(|s| s.halves.len())) && args.semidomes.is_none() {
        out!("  hint: no semi-dome pattern was asked for: --semidomes N generates N (the protrusions a ground truth is rendered for)");
    }
}

/// Prints what was written: the counts and time, then each fixture's figures and notes, and
/// where the indenters come from.
fn print_summary(
    set: &fabkit_fixtures::FixtureSet,
    params: &fabkit_fixtures::params::FixtureParams,
    design: &fabkit_designs::Design,
    out: &Path,
    elapsed: std::time::Duration,
) {
    out!(
        "{}: {} parts, {} data files -> {} ({:.2} s)",
        set.kit.design,
        set.kit.parts.len(),
        set.files.len(),
        out.display(),
        elapsed.as_secs_f64()
    );
    if let Some(d) = &set.pin_dome {
        out!(
            "  pin dome: {} holes in {} captures; pins {:.3} mm (head to tip), seated with {}, indentation {:.3} mm",
            d.table.len(),
            d.capture_plan.len(),
            d.pin_length_mm,
            d.seat.words(),
            d.table.first().map(|r| r.indentation_depth_mm).unwrap_or(0.0)
        );
        for n in &d.notes {
            out!("  note: {n}");
        }
    }
    if let Some(s) = &set.semidomes {
        let n = s.halves.len();
        out!(
            "  semi-domes: {n} patterns + the empty half -> {} stitched pairs",
            n * n
        );
    }
    if let Some(g) = &set.grid_plate {
        out!(
            "  grid plate: {} holes in {} captures; pins {:.3} mm (head to tip), indentation {:.3} mm",
            g.table.len(),
            g.capture_plan.len(),
            g.pin_length_mm,
            g.table.first().map(|r| r.indentation_depth_mm).unwrap_or(0.0)
        );
    }
    if let Some(s) = &set.semiplates {
        let n = s.halves.len();
        out!(
            "  semi-plates: {n} patterns + the empty half -> {} stitched pairs",
            n * n
        );
    } else if let Some(why) = set.kit.summary["semiplates"]["skipped"].as_str() {
        out!("  semi-plates: none: {why}");
    }
    if let Some(b) = &set.board {
        out!(
            "  calibration board: {} bumps, {:.3} mm into the skin with its floor on the contact face; pocket {:.3} x {:.3} mm; point table points/board_table.csv",
            b.table.len(),
            b.table.first().map(|r| r.indentation_depth_mm).unwrap_or(0.0),
            b.pocket.width_mm,
            b.pocket.length_mm
        );
    }
    if params.indenters.is_none() {
        let names: Vec<String> = params
            .indenters_for(design)
            .iter()
            .map(|p| p.name.clone())
            .collect();
        let paper = fabkit_fixtures::indenters::paper_of(design).and_then(|d| {
            fabkit_fixtures::indenters::PAPER_INDENTERS
                .iter()
                .find(|p| p.0 == d)
                .map(|p| p.1)
        });
        match paper {
            Some(paper) => out!(
                "  indenters: those of the {paper} paper ({}); list others under `indenters:` in --params",
                names.join(", ")
            ),
            None => out!(
                "  indenters: none (the design reproduces none of the library's papers); list them under `indenters:` in --params"
            ),
        }
    }
}

/// The first simulator format of `formats` (mjcf, urdf, usd), which fixtures do not write.
pub(crate) fn sim_format(formats: &fabkit_export::Formats) -> Option<&'static str> {
    [
        (formats.mjcf, "mjcf"),
        (formats.urdf, "urdf"),
        (formats.usd, "usd"),
    ]
    .into_iter()
    .find_map(|(on, name)| on.then_some(name))
}
