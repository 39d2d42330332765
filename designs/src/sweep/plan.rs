//! From a sweep file to its list of variants: grid, zip and random expansion, stable ids and
//! shards.

use super::file::{Mode, SweepSpec};
use super::paths::canonical_json;
use super::SweepError;
use crate::schema::Design;
use rand_chacha::rand_core::SeedableRng;
use serde_json::Value;
use sha2::{Digest, Sha256};

/// Most variants one sweep may have.
pub const MAX_VARIANTS: u64 = 10_000_000;

/// Hex digits of a variant id (64 bits of its sha256).
pub const ID_HEX_DIGITS: usize = 16;

/// One point of the sweep.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Position in the sweep, from 0, in the order of [`Plan::variants`].
    pub index: usize,
    /// The first [`ID_HEX_DIGITS`] hex digits of the sha256 of the resolved design (every
    /// parameter, after the variant's values are set; canonical JSON, keys sorted) and the
    /// chord tolerance ([`variant_id`]). The same parameters give the same id in any sweep,
    /// mode or order of the `vary` keys.
    pub id: String,
    /// The varied parameters' values, in the order of [`SweepSpec::parameters`].
    pub params: Vec<(String, Value)>,
}

/// Every variant of a sweep, in order.
#[derive(Debug, Clone)]
pub struct Plan {
    pub variants: Vec<Variant>,
    /// sha256 of the ids in order, one per line: shards of one sweep share it.
    pub plan_sha256: String,
}

/// The id of `design` built at `chord_tolerance_mm`; see [`Variant::id`].
pub fn variant_id(design: &Design, chord_tolerance_mm: f64) -> String {
    let v = serde_json::to_value(design).unwrap_or(Value::Null);
    let mut h = Sha256::new();
    h.update(b"fabkit-sweep-variant/1\n");
    h.update(format!("chord_tolerance_mm={chord_tolerance_mm}\n").as_bytes());
    h.update(canonical_json(&v).as_bytes());
    hex(&h.finalize())[..ID_HEX_DIGITS].to_string()
}

pub(crate) fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

impl SweepSpec {
    /// The base design with the values of `params` set.
    ///
    /// # Errors
    /// [`SweepError::WrongValue`] if a value does not fit the schema (checked per value when
    /// the file was parsed, so only a defect reaches this).
    pub fn resolve(&self, params: &[(String, Value)]) -> Result<Design, SweepError> {
        super::variants::resolve_variant(&self.base.design, &self.origin, params)
    }

    /// Expands the sweep into its variants.
    ///
    /// Grid: every combination, the first parameter of the file varying slowest. Zip: the
    /// k-th value of every parameter. Random: `count` distinct grid combinations drawn
    /// without replacement by a ChaCha8 generator seeded with `seed`
    /// (`rand::seq::index::sample`), listed in grid order.
    ///
    /// # Errors
    /// [`SweepError::File`] when the sweep has more than [`MAX_VARIANTS`] variants, when
    /// `count` exceeds the grid, or when two variants resolve to the same design.
    pub fn plan(&self) -> Result<Plan, SweepError> {
        let sizes: Vec<u64> = self
            .parameters
            .iter()
            .map(|p| p.values.len() as u64)
            .collect();
        let grid = sizes
            .iter()
            .try_fold(1u64, |a, &b| a.checked_mul(b))
            .filter(|&n| n <= u64::MAX / 2);
        let too_many = |n: String| SweepError::File {
            at: self.origin.clone(),
            message: format!("the sweep has {n} variants, more than the {MAX_VARIANTS} allowed"),
        };
        let combos: Vec<Vec<usize>> = match self.mode {
            Mode::Zip => (0..self.parameters[0].values.len())
                .map(|k| vec![k; self.parameters.len()])
                .collect(),
            Mode::Grid => {
                let n = grid.ok_or_else(|| too_many("too many".into()))?;
                if n > MAX_VARIANTS {
                    return Err(too_many(n.to_string()));
                }
                (0..n).map(|i| decode(i, &sizes)).collect()
            }
            Mode::Random => {
                let count = self.count.unwrap_or(0);
                let n = grid.ok_or_else(|| too_many("too many".into()))?;
                if count > n {
                    return Err(SweepError::File {
                        at: self.origin.clone(),
                        message: format!(
                            "count = {count}: more than the {n} combinations of the grid"
                        ),
                    });
                }
                if count > MAX_VARIANTS || n > usize::MAX as u64 {
                    return Err(too_many(count.to_string()));
                }
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.seed);
                let mut picked: Vec<u64> =
                    rand::seq::index::sample(&mut rng, n as usize, count as usize)
                        .into_iter()
                        .map(|i| i as u64)
                        .collect();
                picked.sort_unstable();
                picked.into_iter().map(|i| decode(i, &sizes)).collect()
            }
        };
        let tol = self.chord_tolerance.mm();
        let mut variants = Vec::with_capacity(combos.len());
        let mut seen: std::collections::HashMap<String, usize> = Default::default();
        for (index, combo) in combos.into_iter().enumerate() {
            let params: Vec<(String, Value)> = self
                .parameters
                .iter()
                .zip(&combo)
                .map(|(p, &k)| (p.path.clone(), p.values[k].clone()))
                .collect();
            let design = self.resolve(&params)?;
            let id = variant_id(&design, tol);
            if let Some(other) = seen.insert(id.clone(), index) {
                return Err(SweepError::File {
                    at: self.origin.clone(),
                    message: format!(
                        "variants {other} and {index} resolve to the same design (id {id}); remove the duplicate value"
                    ),
                });
            }
            variants.push(Variant { index, id, params });
        }
        let mut h = Sha256::new();
        for v in &variants {
            h.update(v.id.as_bytes());
            h.update(b"\n");
        }
        Ok(Plan {
            variants,
            plan_sha256: hex(&h.finalize()),
        })
    }
}

/// Grid index `i` as one value index per parameter, the first parameter varying slowest.
fn decode(mut i: u64, sizes: &[u64]) -> Vec<usize> {
    let mut out = vec![0; sizes.len()];
    for (k, &n) in sizes.iter().enumerate().rev() {
        out[k] = (i % n) as usize;
        i /= n;
    }
    out
}

/// `--shard I/N`: the variants whose index is I modulo N (every N-th variant from I).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Shard {
    /// I, from 0.
    pub index: usize,
    /// N, at least 1.
    pub count: usize,
}

impl Shard {
    /// Whether variant `index` belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.count == self.index
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    /// Parses `I/N` with 0 <= I < N.
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("shard `{s}`: expected I/N, e.g. 0/4"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| format!("shard `{s}`: I must be a whole number"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("shard `{s}`: N must be a whole number"))?;
        if count == 0 || index >= count {
            return Err(format!("shard `{s}`: needs 0 <= I < N"));
        }
        if count as u64 > MAX_VARIANTS {
            return Err(format!(
                "shard `{s}`: N must be at most {MAX_VARIANTS} (the most variants a sweep has)"
            ));
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}
