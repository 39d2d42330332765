//! `--printer NAME|FILE.yaml`: the printers whose beds the plates are laid out in. A shipped
//! printer by name ([`fabkit_designs::schema::shipped_printers`]), or a user's own from a YAML
//! file:
//!
//! ```yaml
//! technology: fdm          # fdm, sla or polyjet
//! name: my_printer         # a-z, 0-9 and _
//! size_mm: [220, 220, 250] # build volume x, y, z
//! margin_mm: 8             # kept clear on every side of the plate
//! ```
//!
//! One printer per technology; it replaces the design's `printers.<technology>.bed`.

use std::error::Error;
use std::path::Path;

use fabkit_designs::schema::{shipped_printers, Bed, PrinterFile, PrinterProfiles, Technology};

#[derive(clap::Args, Debug, Clone, Default)]
pub struct PrinterArgs {
    /// Printer whose bed the plates are laid out in, one per technology: a shipped one
    /// (prusa_mk4: FDM 250 x 210 x 220 mm; formlabs_form2: SLA 145 x 145 x 175 mm;
    /// stratasys_j750: PolyJet 490 x 390 x 200 mm) or your own YAML file (technology, name,
    /// size_mm: [x, y, z], margin_mm). Default: the design's printers.<technology>.bed, else
    /// the shipped printer of the technology.
    #[arg(long = "printer", value_name = "NAME|FILE.yaml")]
    pub printers: Vec<String>,
}

fn shipped_list() -> String {
    shipped_printers()
        .iter()
        .map(|(t, b)| {
            format!(
                "{} ({}, {} x {} x {} mm)",
                b.name,
                fabkit_designs::kit::PrintTechnology::from(*t),
                b.size_mm[0],
                b.size_mm[1],
                b.size_mm[2]
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The printer an argument names.
fn printer(arg: &str) -> Result<(Technology, Bed), Box<dyn Error>> {
    if let Some(p) = shipped_printers().into_iter().find(|(_, b)| b.name == arg) {
        return Ok(p);
    }
    let path = Path::new(arg);
    if !path.exists() {
        return Err(format!(
            "--printer {arg}: no shipped printer has that name ({}) and there is no such file",
            shipped_list()
        )
        .into());
    }
    let text = fabkit_designs::input_files::read_design_file(path)
        .map_err(|e| format!("--printer {arg}: {e}"))?;
    let f: PrinterFile = fabkit_designs::schema::yaml_from_str(&text)
        .map_err(|e| format!("--printer {}", fabkit_designs::schema::yaml_error(arg, &e)))?;
    fabkit_designs::schema::refuse_quoted_numbers(&f, &text, arg)
        .map_err(|e| format!("--printer {e}"))?;
    let bed = Bed {
        name: f.name,
        size_mm: f.size_mm,
        margin_mm: f.margin_mm,
    };
    let mut errs = Vec::new();
    fabkit_designs::stack::check_bed(&bed, "", &mut errs);
    if !errs.is_empty() {
        return Err(errs
            .iter()
            .map(|e| {
                let at = fabkit_designs::schema::yaml_location(&text, &e.path)
                    .map(|(l, c)| format!(":{l}:{c}"))
                    .unwrap_or_default();
                format!("--printer {arg}{at}: {e}")
            })
            .collect::<Vec<_>>()
            .join("\n")
            .into());
    }
    Ok((f.technology, bed))
}

/// Applies the `--printer` arguments to `printers` (each replaces its technology's bed).
///
/// # Errors
/// An unknown name that is no file, a file that is not a printer (file:line:col, or the key,
/// its value and the rule), two printers of one technology.
pub fn apply(args: &PrinterArgs, printers: &mut PrinterProfiles) -> Result<(), Box<dyn Error>> {
    let mut seen: Vec<(Technology, &str)> = Vec::new();
    for arg in &args.printers {
        let (tech, bed) = printer(arg)?;
        if let Some((_, first)) = seen.iter().find(|(t, _)| *t == tech) {
            return Err(format!(
                "--printer {first} and --printer {arg}: both are {} printers; give one per technology",
                fabkit_designs::kit::PrintTechnology::from(tech)
            )
            .into());
        }
        seen.push((tech, arg));
        printers.get_mut(tech).bed = Some(bed);
    }
    Ok(())
}
