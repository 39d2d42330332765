//! Whether a swept parameter changes what the sweep builds: a parameter the resolved design
//! ignores would give identical variants, and the sweep refuses it before anything runs.

use super::file::{Parameter, SweepSpec};
use super::SweepError;
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::variant::{evaluate, printability, Metrics, Outcome, Verdict};
use fabkit_designs::ChordTolerance;
use serde_json::Value;
use sha2::{Digest, Sha256};

/// Most values of one parameter that are built to look for an effect (the first, the last
/// and values spread evenly between them).
pub const MAX_PROBED_VALUES: usize = 5;

/// Most values of each other parameter under which a parameter is probed again when it has no
/// effect on the base design (a switch such as `housing.style` may turn it on).
pub const MAX_CONTEXT_VALUES: usize = 3;

/// The coarsest chord tolerance the probes are built at, mm: coarse enough to be quick, and a
/// changed parameter moves the vertices of the surfaces it shapes at any tolerance.
pub const PROBE_CHORD_TOLERANCE_MM: f64 = 0.05;

/// Everything a variant's results and files are made of, apart from the resolved parameters
/// the kit echoes (the summary and each part's `params`).
#[derive(PartialEq)]
struct Fingerprint {
    /// sha256 over every part's name, role, material, technology, group and written mesh.
    parts_sha256: Vec<u8>,
    /// The pours as the fabrication sheet gives them.
    casts: Value,
    bought_items: Vec<String>,
    metrics: Metrics,
    verdicts: Vec<Verdict>,
}

fn fingerprint(
    design: &fabkit_designs::schema::Design,
    materials: &MaterialsTable,
    tol: ChordTolerance,
) -> Option<Fingerprint> {
    let Outcome::Ok { metrics, kit } = evaluate(design, materials, tol) else {
        return None;
    };
    let mut h = Sha256::new();
    for p in &kit.parts {
        h.update(
            format!(
                "{}\n{}\n{}\n{}\n{:?}\n",
                p.name, p.role, p.material, p.print_technology, p.group
            )
            .as_bytes(),
        );
        let m = p.written_mesh();
        for v in &m.vertices {
            for c in v {
                h.update(c.to_le_bytes());
            }
        }
        for t in &m.triangles {
            for i in t {
                h.update(i.to_le_bytes());
            }
        }
        h.update(b"\n");
    }
    Some(Fingerprint {
        parts_sha256: h.finalize().to_vec(),
        casts: serde_json::to_value(&kit.casts).unwrap_or(Value::Null),
        bought_items: kit.bought_items.clone(),
        metrics,
        verdicts: printability(design, materials, tol),
    })
}

/// At most `n` of `values`: the first, the last and ones spread evenly between them.
fn spread(values: &[Value], n: usize) -> Vec<&Value> {
    if values.len() <= n {
        return values.iter().collect();
    }
    let mut idx: Vec<usize> = (0..n)
        .map(|k| k * (values.len() - 1) / (n - 1).max(1))
        .collect();
    idx.dedup();
    idx.into_iter().map(|i| &values[i]).collect()
}

/// Whether a value is free text (a name or a description for the fabrication sheet), not a
/// choice among the schema's keywords: the design takes any other text in its place.
fn is_free_text(spec: &SweepSpec, path: &str, value: &Value) -> bool {
    value.is_string()
        && spec
            .resolve(&[(path.to_string(), Value::String("fabkit probe text".into()))])
            .is_ok()
}

impl SweepSpec {
    /// Refuses a swept parameter that the resolved design ignores: one whose values all give
    /// the same parts (meshes as written), pours, bought items, metrics and printability
    /// verdicts ([`super::Metrics`], [`super::Verdict`]), so that every variant would repeat
    /// the same result.
    ///
    /// Up to [`MAX_PROBED_VALUES`] values of the parameter are built at the coarser of the
    /// sweep's chord tolerance and [`PROBE_CHORD_TOLERANCE_MM`] (at the sweep's own when a
    /// probe is infeasible at the coarser one), first on the base design, then with each other
    /// parameter set to each of up to [`MAX_CONTEXT_VALUES`] of its values. Free text (a
    /// description, a material or module name) is not probed, nor a parameter with one value,
    /// nor one whose probes do not all build: an infeasible value is itself a result.
    ///
    /// # Errors
    /// [`SweepError::File`] at the parameter's `file:line:column`, naming the path, the values
    /// built and the rule.
    pub fn refuse_ignored_parameters(&self, materials: &MaterialsTable) -> Result<(), SweepError> {
        for p in &self.parameters {
            if p.values.len() < 2 || is_free_text(self, &p.path, &p.values[0]) {
                continue;
            }
            let probed = spread(&p.values, MAX_PROBED_VALUES);
            let mut contexts: Vec<Option<(&str, &Value)>> = vec![None];
            for q in self.parameters.iter().filter(|q| q.path != p.path) {
                for v in spread(&q.values, MAX_CONTEXT_VALUES) {
                    contexts.push(Some((q.path.as_str(), v)));
                }
            }
            let mut ignored = true;
            for ctx in contexts {
                if self.changes_anything(p, &probed, ctx, materials) {
                    ignored = false;
                    break;
                }
            }
            if ignored {
                let list = probed
                    .iter()
                    .map(|v| v.to_string())
                    .collect::<Vec<_>>()
                    .join(", ");
                let hint = why_ignored(&self.base.design, &p.path)
                    .map(|h| format!(" ({h})"))
                    .unwrap_or_default();
                return Err(SweepError::File {
                    at: p.at.clone(),
                    message: format!(
                        "vary.{}: has no effect on design '{}'{hint}: the values {list} give the \
                         same parts, pours, markers and printability verdicts, so every variant \
                         would be the same design; remove it, or vary a parameter the design uses",
                        p.path, self.base.design.name
                    ),
                });
            }
        }
        Ok(())
    }

    /// Whether the `probed` values of `p` give different results with `ctx` (another
    /// parameter's value) set; `true` when a probe does not build, since then it cannot tell.
    fn changes_anything(
        &self,
        p: &Parameter,
        probed: &[&Value],
        ctx: Option<(&str, &Value)>,
        materials: &MaterialsTable,
    ) -> bool {
        let coarse = ChordTolerance::new(self.chord_tolerance.mm().max(PROBE_CHORD_TOLERANCE_MM))
            .unwrap_or(self.chord_tolerance);
        let at = |tol: ChordTolerance| -> Option<bool> {
            let build = |v: &Value| -> Option<Fingerprint> {
                let mut params = vec![(p.path.clone(), v.clone())];
                if let Some((q, qv)) = ctx {
                    params.push((q.to_string(), qv.clone()));
                }
                let design = self.resolve(&params).ok()?;
                fingerprint(&design, materials, tol)
            };
            // the first two at once (most parameters differ there), then one by one
            let (reference, second) = match probed {
                [a, b, ..] => rayon::join(|| build(a), || build(b)),
                [a] => (build(a), None),
                [] => return Some(false),
            };
            let reference = reference?;
            if probed.len() < 2 {
                return Some(false);
            }
            if second? != reference {
                return Some(true);
            }
            for v in &probed[2..] {
                if build(v)? != reference {
                    return Some(true);
                }
            }
            Some(false)
        };
        at(coarse)
            .or_else(|| {
                (coarse != self.chord_tolerance)
                    .then(|| at(self.chord_tolerance))
                    .flatten()
            })
            .unwrap_or(true)
    }
}

/// Why the design ignores `path`, for the common switches: a housing part of the other style,
/// mold fields no cast layer's strategy uses, the technology of a layer that is not printed.
fn why_ignored(design: &fabkit_designs::schema::Design, path: &str) -> Option<String> {
    use fabkit_designs::schema::{HousingStyle, LayerProcess, MoldStrategy};
    let cast: Vec<MoldStrategy> = design
        .layers
        .iter()
        .filter(|l| l.process == LayerProcess::Cast)
        .map(|l| l.mold_strategy.unwrap_or(design.mold.strategy))
        .collect();
    if let Some(h) = &design.housing {
        if path.starts_with("housing.round_tube.") && h.style != HousingStyle::RoundTube {
            return Some("it applies only with housing.style: round_tube".into());
        }
    }
    if path.starts_with("mold.") && cast.is_empty() {
        return Some("no layer is cast, so no mold is built".into());
    }
    if path.starts_with("mold.two_piece.") && !cast.contains(&MoldStrategy::TwoPieceOpen) {
        return Some("it applies only to layers cast with mold strategy two_piece_open".into());
    }
    if let Some(rest) = path.strip_prefix("layers[") {
        let (i, field) = rest.split_once("].")?;
        let layer = design.layers.get(i.parse::<usize>().ok()?)?;
        if field == "print_technology" && layer.process != LayerProcess::Printed {
            return Some("it applies only to printed layers".into());
        }
        if field == "mold_strategy" && layer.process != LayerProcess::Cast {
            return Some("it applies only to cast layers".into());
        }
    }
    None
}
