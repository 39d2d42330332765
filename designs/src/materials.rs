//! The materials table (`designs/materials.yaml`) and the pour calculator.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The materials table shipped with fabkit, embedded at build time.
pub const MATERIALS_YAML: &str = include_str!("../materials.yaml");

/// What a material is used for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MaterialKind {
    Cast,
    Coating,
    Print,
    Bought,
    /// Wiped or brushed onto a part so that silicone bonds to it (Dow PR-1200 on R-Tac0's
    /// glass tube, Sec. III-B1); needs `applied_ml_per_cm2`.
    Primer,
    /// Sprayed into a mold so that the cast skin comes out (Mann Ease Release 200, R-Tac0
    /// Sec. III-B1, ShadowTac Sec. III); needs `applied_ml_per_cm2`.
    Release,
}

/// Mixing by weight or by volume.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MixBasis {
    Weight,
    Volume,
}

/// A multi-component mix ratio.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mix {
    pub components: Vec<String>,
    pub ratio: Vec<f64>,
    pub by: MixBasis,
    /// Components that evaporate after spraying or brushing (a thinner): they are mixed but
    /// leave no material in the coat. Each must name a component, and one must stay.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub evaporates: Vec<String>,
}

/// One entry of the materials table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    pub kind: MaterialKind,
    /// Density of the mixed, uncured material, g/cm^3.
    pub density_g_per_cm3: f64,
    #[serde(default)]
    pub mix: Option<Mix>,
    #[serde(default)]
    pub notes: String,
    /// Amount used per cm^2 of treated surface, mL, losses included (primer and release only,
    /// where it is required), in (0, 0.1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub applied_ml_per_cm2: Option<f64>,
    /// Refractive index for visible light, where the camera looks through the material
    /// (clear gels, glass, acrylic); `None` for opaque materials.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refractive_index: Option<RefractiveIndex>,
    /// Where the numbers come from (datasheet, paper and section).
    pub source: String,
}

/// Refractive index of a clear material at the sodium D line (589 nm), with its source.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefractiveIndex {
    /// n_D, dimensionless, in [1, 3): 1.41 for the clear silicones, 1.47 for borosilicate
    /// glass, 1.49 for PMMA.
    pub n: f64,
    /// Where the value comes from (datasheet, paper); a value no maker publishes starts with
    /// `ASSUMPTION:` and says what it is taken from.
    pub source: String,
}

/// Largest refractive index the table accepts (exclusive): beyond any clear material a
/// tactile sensor is made of (diamond is 2.42).
pub const MAX_REFRACTIVE_INDEX: f64 = 3.0;

/// The whole table, keyed by material key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialsTable {
    pub materials: BTreeMap<String, Material>,
}

impl MaterialsTable {
    /// The embedded table.
    ///
    /// # Errors
    /// Only if the embedded file is malformed (a build defect, covered by a test).
    pub fn embedded() -> Result<Self, String> {
        Self::from_yaml(MATERIALS_YAML, "designs/materials.yaml")
    }

    /// Parses and checks a materials table (the form of `designs/materials.yaml`); `origin`
    /// names it in messages.
    ///
    /// # Errors
    /// The YAML error at `origin:line:column`, or the first rule broken, naming its path
    /// (`materials.<key>.mix.evaporates[0]`), value and rule.
    pub fn from_yaml(text: &str, origin: &str) -> Result<Self, String> {
        let t: Self =
            crate::yaml::yaml_from_str(text).map_err(|e| crate::yaml::yaml_error(origin, &e))?;
        t.check().map_err(|e| format!("{origin}: {e}"))?;
        Ok(t)
    }

    fn check(&self) -> Result<(), String> {
        for (k, m) in &self.materials {
            if !(m.density_g_per_cm3 > 0.0) {
                return Err(format!("materials.{k}.density_g_per_cm3 must be above 0"));
            }
            if m.source.trim().is_empty() {
                return Err(format!("materials.{k}.source must name a source"));
            }
            if let Some(r) = &m.refractive_index {
                if !(r.n >= 1.0 && r.n < MAX_REFRACTIVE_INDEX) {
                    return Err(format!(
                        "materials.{k}.refractive_index.n = {}: must be from 1 to below 3 (n_D of a clear material)",
                        r.n
                    ));
                }
                if r.source.trim().is_empty() {
                    return Err(format!(
                        "materials.{k}.refractive_index.source must name a source (or start with ASSUMPTION:)"
                    ));
                }
            }
            let treatment = matches!(m.kind, MaterialKind::Primer | MaterialKind::Release);
            match m.applied_ml_per_cm2 {
                None if treatment => {
                    return Err(format!(
                        "materials.{k}.applied_ml_per_cm2 is required for a {:?} material (mL per cm² of treated surface)",
                        m.kind
                    ))
                }
                Some(a) if !treatment => {
                    return Err(format!(
                        "materials.{k}.applied_ml_per_cm2 = {a}: only primer and release materials take it"
                    ))
                }
                Some(a) if !(a > 0.0 && a <= 0.1) => {
                    return Err(format!(
                        "materials.{k}.applied_ml_per_cm2 = {a}: must be above 0 and at most 0.1 mL per cm² (a 1 mm film)"
                    ))
                }
                _ => {}
            }
            if let Some(mix) = &m.mix {
                if mix.components.len() != mix.ratio.len() || mix.ratio.iter().any(|r| !(*r > 0.0))
                {
                    return Err(format!(
                        "materials.{k}.mix: one positive ratio per component is required"
                    ));
                }
                for (i, e) in mix.evaporates.iter().enumerate() {
                    if !mix.components.contains(e) {
                        return Err(format!(
                            "materials.{k}.mix.evaporates[{i}] = {e:?}: must name one of the components {:?}",
                            mix.components
                        ));
                    }
                }
                if mix.components.iter().all(|c| mix.evaporates.contains(c)) {
                    return Err(format!(
                        "materials.{k}.mix.evaporates: at least one component must stay in the material"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Looks up a material by key.
    pub fn get(&self, key: &str) -> Option<&Material> {
        self.materials.get(key)
    }
}

/// Pour numbers for one cast: `cavity_volume_mm3` of `material`, plus `waste_allowance`
/// (fraction, e.g. 0.2).
///
/// Total mass = volume x density x (1 + waste). For a mix by weight each component gets its
/// share of the total mass; for a mix by volume each component gets its share of the volume at
/// the mixed density.
///
/// # Errors
/// When the material has no mix (it is not castable).
pub fn pour(
    step: u32,
    cast: &str,
    material_key: &str,
    material: &Material,
    mold_parts: Vec<String>,
    cavity_volume_mm3: f64,
    waste_allowance: f64,
) -> Result<CastReport, String> {
    let mix = mix_of(material_key, material).map_err(|e| format!("{e}: it cannot be cast"))?;
    let volume_ml = cavity_volume_mm3 / 1000.0;
    let total = volume_ml * material.density_g_per_cm3 * (1.0 + waste_allowance);
    let by_volume = matches!(mix.by, MixBasis::Volume);
    let total_ml = volume_ml * (1.0 + waste_allowance);
    let components = split(mix, total, by_volume.then_some(total_ml));

    Ok(CastReport {
        step,
        cast: cast.to_string(),
        material: material_key.to_string(),
        material_name: material.name.clone(),
        mold_parts,
        cavity_volume_ml: volume_ml,
        layer_volume_ml: None,
        waste_allowance,
        mix_ratio: ratio_text(mix),
        min_batch: min_batch(&components, total),
        components,
        total_mass_g: total,
        notes: material.notes.clone(),
        coats: Vec::new(),
        treatments: Vec::new(),
    })
}

/// The smallest weighable batch of a mix whose smallest component is below
/// [`MIN_WEIGHABLE_G`] ([`MinBatch`]); `None` otherwise.
fn min_batch(components: &[CastComponent], total_g: f64) -> Option<MinBatch> {
    let smallest = components
        .iter()
        .map(|c| c.mass_g)
        .fold(f64::INFINITY, f64::min);
    if !(smallest > 0.0 && smallest < MIN_WEIGHABLE_G) {
        return None;
    }
    let k = MIN_WEIGHABLE_G / smallest;
    let scaled: Vec<CastComponent> = components
        .iter()
        .map(|c| CastComponent {
            name: c.name.clone(),
            mass_g: c.mass_g * k,
            volume_ml: c.volume_ml.map(|v| v * k),
        })
        .collect();
    let total = total_g * k;
    Some(MinBatch {
        components: scaled,
        total_mass_g: total,
        leftover_g: total - total_g,
    })
}

/// The mix for a sprayed or brushed coat of `coat_volume_mm3` (the layer's own volume) of
/// `material`: the components that stay in the coat make up its mass (volume x density), the
/// evaporating ones ([`Mix::evaporates`]) are added in the mix ratio; no spray loss is
/// included. With the smallest batch weighable by hand ([`MinBatch`]).
///
/// # Errors
/// When the material has no mix.
pub fn coat(
    layer: &str,
    material_key: &str,
    material: &Material,
    thickness_mm: f64,
    coat_volume_mm3: f64,
) -> Result<CoatReport, String> {
    let mix = mix_of(material_key, material)?;
    let coat_g = coat_volume_mm3 / 1000.0 * material.density_g_per_cm3;
    let sum: f64 = mix.ratio.iter().sum();
    let staying: f64 = mix
        .components
        .iter()
        .zip(&mix.ratio)
        .filter(|(c, _)| !mix.evaporates.contains(c))
        .map(|(_, r)| r)
        .sum();
    let total = coat_g * sum / staying;
    let components = split(mix, total, None);

    Ok(CoatReport {
        layer: layer.to_string(),
        material: material_key.to_string(),
        material_name: material.name.clone(),
        thickness_mm,
        coat_volume_ml: coat_volume_mm3 / 1000.0,
        mix_ratio: ratio_text(mix),
        evaporates: mix.evaporates.clone(),
        min_batch: min_batch(&components, total),
        components,
        total_mass_g: total,
    })
}

/// The mix of `material` (key `material_key`), or the error that it has none.
fn mix_of<'m>(material_key: &str, material: &'m Material) -> Result<&'m Mix, String> {
    material
        .mix
        .as_ref()
        .ok_or_else(|| format!("material '{material_key}' has no mix ratio"))
}

/// `total_g` (and `total_ml`, for a mix by volume) split over the components of `mix` in its
/// ratio.
fn split(mix: &Mix, total_g: f64, total_ml: Option<f64>) -> Vec<CastComponent> {
    let sum: f64 = mix.ratio.iter().sum();
    mix.components
        .iter()
        .zip(&mix.ratio)
        .map(|(name, r)| CastComponent {
            name: name.clone(),
            mass_g: total_g * r / sum,
            volume_ml: total_ml.map(|v| v * r / sum),
        })
        .collect()
}

/// The ratio as written, e.g. `10:1 by weight`.
fn ratio_text(mix: &Mix) -> String {
    let ratio = mix
        .ratio
        .iter()
        .map(|r| format!("{r}"))
        .collect::<Vec<_>>()
        .join(":");
    let by = match mix.by {
        MixBasis::Weight => "weight",
        MixBasis::Volume => "volume",
    };
    format!("{ratio} by {by}")
}

/// Casting numbers for one pour.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CastReport {
    /// Order in which the pours are made, from 1.
    pub step: u32,
    /// What is cast: a layer name (`transparent_gel`) or `silicone_mold:<layer>` for a
    /// Mold Star mold made from a master pattern.
    pub cast: String,
    /// Material key in the materials table.
    pub material: String,
    /// The material's product name (the table's `name`), for the fabrication sheet.
    pub material_name: String,
    /// Names of the parts that hold this pour.
    pub mold_parts: Vec<String>,
    /// Volume to fill, mL (= cm^3): the cavity with its reservoir and sprue (the pour).
    pub cavity_volume_ml: f64,
    /// Volume of the cast layer itself, mL: the solid between its inner and outer surfaces
    /// down to the base plane, from the exact profile (marker features not counted); `None`
    /// for a silicone mold.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer_volume_ml: Option<f64>,
    /// Fraction added for losses in cups, sprue and vents (0.2 = 20 %).
    pub waste_allowance: f64,
    /// Mix ratio as written on the datasheet, e.g. `10:1 by weight`.
    pub mix_ratio: String,
    /// Mass of each component to weigh out, g, in datasheet order (Part A, Part B, ...).
    pub components: Vec<CastComponent>,
    /// Total mass to mix, g.
    pub total_mass_g: f64,
    /// Pot life, cure time and handling notes from the materials table.
    pub notes: String,
    /// The smallest batch that can be weighed by hand when a component of `components` is
    /// below [`MIN_WEIGHABLE_G`]: every component scaled up until the smallest is that much;
    /// `None` when the pour's own amounts can be weighed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_batch: Option<MinBatch>,
    /// Coats sprayed into the mold before this pour (R-Tac0's black coating), in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub coats: Vec<CoatReport>,
    /// Primer and release agent applied before this pour, in order (the core primed before
    /// the first layer cast on it, the mold's surfaces released).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub treatments: Vec<TreatmentReport>,
}

/// A primer or release agent applied to a surface before a pour, with its amount.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TreatmentReport {
    /// Material key in the materials table (kind `primer` or `release`), and its product name.
    pub material: String,
    pub material_name: String,
    /// `primer` or `release`.
    pub kind: MaterialKind,
    /// What is treated, e.g. `the core's outer surface`, `the cavity of transparent_gel`.
    pub surface: String,
    /// Area treated, cm^2 (the exact profile's surface, features not counted).
    pub area_cm2: f64,
    /// Amount used, mL: `area_cm2` x the material's `applied_ml_per_cm2`.
    pub amount_ml: f64,
}

/// A layer sprayed or brushed into a mold before a pour: its mix and amount.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CoatReport {
    /// The sprayed layer's name.
    pub layer: String,
    /// Material key in the materials table, and its product name.
    pub material: String,
    pub material_name: String,
    pub thickness_mm: f64,
    /// Volume of the coat itself, mL (the layer's own volume from the exact profile).
    pub coat_volume_ml: f64,
    /// Mix ratio as on the datasheet or in the paper, e.g. `100:3:500 by weight`.
    pub mix_ratio: String,
    /// Components that evaporate (a thinner).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub evaporates: Vec<String>,
    /// The mix that leaves the coat's mass once the thinner is gone, g, per component (no
    /// spray loss included).
    pub components: Vec<CastComponent>,
    pub total_mass_g: f64,
    /// The smallest batch weighable by hand, when a component is below [`MIN_WEIGHABLE_G`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_batch: Option<MinBatch>,
}

/// Least mass of one component that a kitchen scale weighs to about 10 % (0.1 g resolution), g.
pub const MIN_WEIGHABLE_G: f64 = 1.0;

/// A batch larger than the pour needs, so that every component can be weighed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MinBatch {
    /// Each component, in datasheet order; the smallest is [`MIN_WEIGHABLE_G`].
    pub components: Vec<CastComponent>,
    /// Total mass to mix, g.
    pub total_mass_g: f64,
    /// What is left over after the pour (waste allowance included), g.
    pub leftover_g: f64,
}

/// One component of a mix.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CastComponent {
    pub name: String,
    pub mass_g: f64,
    /// Volume to measure out, mL, for a mix by volume (Mold Star 30 is mixed 1A:1B by volume);
    /// `None` for a mix by weight.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume_ml: Option<f64>,
}

impl CastReport {
    /// How the mix of this pour is measured: `12.36 g of Dow SYLGARD 184 (10:1 by weight)`.
    pub fn mix_text(&self) -> String {
        let by_volume = self.components.iter().all(|x| x.volume_ml.is_some());
        if by_volume {
            let ml: f64 = self.components.iter().filter_map(|x| x.volume_ml).sum();
            format!("{ml:.1} mL of {} ({})", self.material_name, self.mix_ratio)
        } else {
            format!(
                "{:.2} g of {} ({})",
                self.total_mass_g, self.material_name, self.mix_ratio
            )
        }
    }
}

/// The cure time from a material's notes (`cure 4 h at 23 C`), or the notes' pointer.
pub fn cure_text(notes: &str) -> String {
    let lower = notes.to_lowercase();
    lower
        .find("cure")
        .and_then(|i| {
            let rest = &notes[i..];
            let end = rest.find(['.', ';', '(']).unwrap_or(rest.len());
            let t = rest[..end].trim();
            (t.len() > "cure".len()).then(|| t.to_string())
        })
        .unwrap_or_else(|| "see the step's notes".into())
}
