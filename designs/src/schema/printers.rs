//! Printer profiles: what each print technology can print (walls, holes, features, the
//! bayonet fit) and its bed; `printers` in a design.

use crate::error::ParamError;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Print technologies, as used in the design file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Technology {
    Fdm,
    Sla,
    Polyjet,
}

impl From<crate::parts::PrintTechnology> for Technology {
    fn from(t: crate::parts::PrintTechnology) -> Self {
        use crate::parts::PrintTechnology as P;
        match t {
            P::Fdm => Self::Fdm,
            P::Sla => Self::Sla,
            P::Polyjet => Self::Polyjet,
        }
    }
}

impl From<Technology> for crate::parts::PrintTechnology {
    fn from(t: Technology) -> Self {
        match t {
            Technology::Fdm => Self::Fdm,
            Technology::Sla => Self::Sla,
            Technology::Polyjet => Self::Polyjet,
        }
    }
}

/// Printer capabilities used to decide what can be printed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PrinterProfile {
    /// Nozzle diameter (FDM) or pixel size (SLA), mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub xy_resolution_mm: f64,
    /// Layer height the printer prints at, mm, > 0. Only that bound is checked: no rule or
    /// part uses it.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub layer_height_mm: f64,
    /// Thinnest wall that prints reliably, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub min_wall_mm: f64,
    /// Smallest hole that prints open, mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub min_hole_diameter_mm: f64,
    /// Smallest positive feature (pin, key), mm.
    #[schemars(extend("exclusiveMinimum" = 0))]
    pub min_feature_mm: f64,
    /// Lug count, ramp and clearance of a bayonet printed on this printer.
    #[serde(default)]
    pub bayonet: crate::parts::bayonet::BayonetProfile,
    /// The printer's build volume, which the plates are laid out in; not given: the bed of the
    /// printer the technology ships with.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bed: Option<Bed>,
}

/// A printer's build volume: what one plate holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Bed {
    /// The printer's name, in messages and the manifest (`[a-z0-9_]+`).
    #[schemars(extend("pattern" = "^[a-z0-9_]+$", "maxLength" = 64))]
    pub name: String,
    /// Build volume: x and y of the plate, z the height, mm.
    #[schemars(extend("items" = {"type": "number", "exclusiveMinimum": 0}))]
    pub size_mm: [f64; 3],
    /// Border kept clear on every side of the plate, mm: an FDM slicer's skirt (PrusaSlicer
    /// lays it 6 mm out, 6.4 mm with its line), an SLA support pad's rim.
    pub margin_mm: f64,
}

/// A user's own printer (`--printer FILE.yaml`): its technology and bed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PrinterFile {
    pub technology: Technology,
    pub name: String,
    pub size_mm: [f64; 3],
    pub margin_mm: f64,
}

impl Bed {
    /// The plate's usable x and y (the bed less its margin on both sides), mm.
    pub fn usable_xy_mm(&self) -> [f64; 2] {
        [
            self.size_mm[0] - 2.0 * self.margin_mm,
            self.size_mm[1] - 2.0 * self.margin_mm,
        ]
    }
}

/// The printers fabkit ships, each with its technology: a common FDM printer (Prusa MK4-class,
/// 250 x 210 x 220 mm; PrusaSlicer's skirt needs the 10 mm margin), a common SLA printer
/// (Formlabs Form 2-class, 145 x 145 x 175 mm) and a PolyJet printer (Stratasys J750-class
/// tray, 490 x 390 x 200 mm). The first of each technology is its default.
pub fn shipped_printers() -> Vec<(Technology, Bed)> {
    let bed = |name: &str, size_mm: [f64; 3], margin_mm: f64| Bed {
        name: name.into(),
        size_mm,
        margin_mm,
    };
    vec![
        (
            Technology::Fdm,
            bed("prusa_mk4", [250.0, 210.0, 220.0], 10.0),
        ),
        (
            Technology::Sla,
            bed("formlabs_form2", [145.0, 145.0, 175.0], 5.0),
        ),
        (
            Technology::Polyjet,
            bed("stratasys_j750", [490.0, 390.0, 200.0], 10.0),
        ),
    ]
}

impl Technology {
    /// The key of the technology in the design file (`fdm`, `sla`, `polyjet`).
    pub fn key(self) -> &'static str {
        match self {
            Technology::Fdm => "fdm",
            Technology::Sla => "sla",
            Technology::Polyjet => "polyjet",
        }
    }
}

/// The FDM, SLA and PolyJet profiles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PrinterProfiles {
    pub fdm: PrinterProfile,
    pub sla: PrinterProfile,
    pub polyjet: PrinterProfile,
}
defaults!(PrinterProfiles {
    // 0.4 mm nozzle, 0.2 mm layers; two perimeters; holes below 1 mm close up.
    fdm: PrinterProfile {
        xy_resolution_mm: 0.4,
        layer_height_mm: 0.2,
        min_wall_mm: 0.8,
        min_hole_diameter_mm: 1.0,
        min_feature_mm: 0.8,
        bayonet: crate::parts::bayonet::BayonetProfile::default(),
        bed: None,
    },
    // Form 3 class: 25-50 um pixels and layers.
    sla: PrinterProfile {
        xy_resolution_mm: 0.05,
        layer_height_mm: 0.05,
        min_wall_mm: 0.4,
        min_hole_diameter_mm: 0.4,
        min_feature_mm: 0.3,
        bayonet: crate::parts::bayonet::BayonetProfile {
            clearance_mm: 0.1,
            ..crate::parts::bayonet::BayonetProfile::default()
        },
        bed: None,
    },
    // Stratasys PolyJet (Connex): 42 um pixels, 16-30 um layers; Tango features below ~0.6 mm tear.
    polyjet: PrinterProfile {
        xy_resolution_mm: 0.042,
        layer_height_mm: 0.03,
        min_wall_mm: 0.6,
        min_hole_diameter_mm: 0.5,
        min_feature_mm: 0.5,
        bayonet: crate::parts::bayonet::BayonetProfile {
            clearance_mm: 0.1,
            ..crate::parts::bayonet::BayonetProfile::default()
        },
        bed: None,
    },
});

impl PrinterProfiles {
    pub fn get(&self, t: Technology) -> &PrinterProfile {
        match t {
            Technology::Fdm => &self.fdm,
            Technology::Sla => &self.sla,
            Technology::Polyjet => &self.polyjet,
        }
    }

    pub fn get_mut(&mut self, t: Technology) -> &mut PrinterProfile {
        match t {
            Technology::Fdm => &mut self.fdm,
            Technology::Sla => &mut self.sla,
            Technology::Polyjet => &mut self.polyjet,
        }
    }

    /// The bed of technology `t`: the profile's, else the shipped printer's.
    pub fn bed(&self, t: Technology) -> Bed {
        self.get(t).bed.clone().unwrap_or_else(|| {
            shipped_printers()
                .into_iter()
                .find(|(tech, _)| *tech == t)
                .map(|(_, b)| b)
                .expect("a shipped printer per technology")
        })
    }
}

/// The rules of the printer profiles, errors named under `printers.<technology>.`: every
/// capability above 0, and each bed's own rules ([`check_bed`]).
pub(crate) fn check_printers(printers: &PrinterProfiles, errs: &mut Vec<ParamError>) {
    for (name, p) in [
        ("fdm", &printers.fdm),
        ("sla", &printers.sla),
        ("polyjet", &printers.polyjet),
    ] {
        // The bed has its own rules (check_bed).
        crate::parts::check_above_zero(&format!("printers.{name}."), p, &["bed"], errs);
        if let Some(bed) = &p.bed {
            check_bed(bed, &format!("printers.{name}.bed"), errs);
        }
    }
}

/// Largest bed side accepted, mm (a 10 m printer is a typo).
pub const MAX_BED_MM: f64 = 10_000.0;

/// The rules of a printer's bed, errors named under `path` (`printers.fdm.bed`, or a
/// `--printer` file's own keys).
pub fn check_bed(bed: &Bed, path: &str, errs: &mut Vec<ParamError>) {
    let at = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    if !crate::values::is_file_stem(&bed.name) {
        errs.push(ParamError::new(
            at("name"),
            format!("'{}'", bed.name),
            "must be a name of a-z, 0-9 and _, at most 64 characters (it names the plates in the manifest)",
        ));
    }
    for (k, v) in bed.size_mm.iter().enumerate() {
        if !(v.is_finite() && *v > 0.0 && *v <= MAX_BED_MM) {
            errs.push(ParamError::new(
                format!("{}[{k}]", at("size_mm")),
                *v,
                "must be above 0 and at most 10000 mm",
            ));
        }
    }
    let m = bed.margin_mm;
    if !(m.is_finite() && m >= 0.0) {
        errs.push(ParamError::new(at("margin_mm"), m, "must be 0 or more"));
    } else if bed.size_mm[..2].iter().all(|v| v.is_finite() && *v > 0.0)
        && 2.0 * m >= bed.size_mm[0].min(bed.size_mm[1])
    {
        errs.push(ParamError::new(
            at("margin_mm"),
            m,
            format!(
                "must leave room on the plate: twice the margin is below its smaller side ({} mm)",
                bed.size_mm[0].min(bed.size_mm[1])
            ),
        ));
    }
}
