//! From a sweep file to its list of variants: grid, zip and random expansion, stable ids and
//! shards.

use super::file::{Mode, Parameter, SweepSpec};
use super::SweepError;
use fabkit_designs::schema::Design;
use fabkit_designs::variant::canonical_json;
use rand_chacha::rand_core::SeedableRng;
use rayon::prelude::*;
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

impl Variant {
    fn new(index: usize, id: String, params: Vec<(String, Value)>) -> Self {
        Self { index, id, params }
    }
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
    let mut h = id_hasher(chord_tolerance_mm);
    h.update(canonical_json(&v).as_bytes());
    hex(&h.finalize()[..ID_HEX_DIGITS / 2])
}

/// The hasher of a variant id before the design's canonical JSON.
fn id_hasher(chord_tolerance_mm: f64) -> Sha256 {
    let mut h = Sha256::new();
    h.update(b"fabkit-sweep-variant/1\n");
    h.update(format!("chord_tolerance_mm={chord_tolerance_mm}\n").as_bytes());
    h
}

pub(crate) fn hex(b: &[u8]) -> String {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    let mut s = String::with_capacity(2 * b.len());
    for x in b {
        s.push(DIGITS[usize::from(x >> 4)] as char);
        s.push(DIGITS[usize::from(x & 15)] as char);
    }
    s
}

/// Progress of [`SweepSpec::plan_with_progress`]: called with (variants planned, variants in
/// the sweep), the counts never decreasing and the last call with both equal.
pub type PlanProgress<'a> = &'a (dyn Fn(usize, usize) + Sync);

/// Variants planned per batch (and per progress report).
const BATCH: usize = 4096;

/// Parameter subtrees whose serde form is checked as a whole (`#[serde(try_from)]`): two
/// parameters inside the same one may be valid alone and not together, so their variants are
/// resolved one by one.
const CHECKED_AS_A_WHOLE: &[&str] = &["body"];

/// How many variants the sweep `parameters` give in `mode` (`count`: of mode random), from
/// the numbers of values alone, before any value is looked at.
///
/// In mode random the count is `count`, checked against the grid's size by
/// [`SweepSpec::plan`].
///
/// # Errors
/// [`SweepError::File`] at `origin` when the count is above [`MAX_VARIANTS`] (naming it, or
/// saying that the product overflows), or when a random draw's grid is too large to index.
pub fn variant_count(
    parameters: &[Parameter],
    mode: Mode,
    count: Option<u64>,
    origin: &str,
) -> Result<u64, SweepError> {
    let err = |message: String| SweepError::File {
        at: origin.to_string(),
        message,
    };
    let sizes: Vec<u128> = parameters.iter().map(|p| p.values.len() as u128).collect();
    let factors = sizes
        .iter()
        .map(u128::to_string)
        .collect::<Vec<_>>()
        .join(" x ");
    // u128 holds any product of up to 4 lists of 2^32 values; past it, say so
    let grid = sizes.iter().try_fold(1u128, |a, &b| a.checked_mul(b));
    let too_many = |n: u128| {
        err(format!(
            "the sweep has {n} variants ({factors}), more than the {MAX_VARIANTS} allowed"
        ))
    };
    let overflows = || {
        err(format!(
            "the sweep's grid of {factors} values has more than 2^128 variants (the product \
             overflows), more than the {MAX_VARIANTS} allowed"
        ))
    };
    match mode {
        Mode::Zip => {
            let n = parameters.first().map_or(0, |p| p.values.len()) as u64;
            if n > MAX_VARIANTS {
                return Err(err(format!(
                    "the sweep has {n} variants, more than the {MAX_VARIANTS} allowed"
                )));
            }
            Ok(n)
        }
        Mode::Grid => {
            let n = grid.ok_or_else(overflows)?;
            if n > u128::from(MAX_VARIANTS) {
                return Err(too_many(n));
            }
            Ok(n as u64)
        }
        Mode::Random => {
            let count = count.unwrap_or(0);
            let n = grid.ok_or_else(overflows)?;
            if u128::from(count) > n {
                // refused by the plan, which names the grid's size ([`SweepSpec::plan`])
                return Ok(count);
            }
            if count > MAX_VARIANTS {
                return Err(err(format!(
                    "the sweep has {count} variants (count), more than the {MAX_VARIANTS} allowed"
                )));
            }
            // drawing without replacement indexes the grid
            if n > (u64::MAX / 2) as u128 || n > usize::MAX as u128 {
                return Err(err(format!(
                    "the grid of {factors} values has {n} combinations, too many to draw \
                     `count` of them from (at most {})",
                    (u64::MAX / 2).min(usize::MAX as u64)
                )));
            }
            Ok(count)
        }
    }
}

/// The canonical JSON of the base design cut where the varied parameters' values go, and each
/// value's canonical text as the resolved design writes it, so that a variant's id is hashed
/// from pieces without building its design ([`SweepSpec::splice`]).
struct Splice {
    /// The canonical JSON of the base design around the values: `pieces[0]`, the value of
    /// parameter `order[0]`, `pieces[1]`, ... ; `pieces.len() == order.len() + 1`.
    pieces: Vec<Vec<u8>>,
    /// Parameters in the order their values appear in the canonical JSON.
    order: Vec<usize>,
    /// Per parameter, per value: its canonical text in the resolved design.
    texts: Vec<Vec<Vec<u8>>>,
}

/// Whether path `a` is `b` or inside it (`layers[0].feature` is inside `layers[0]`).
fn within(a: &str, b: &str) -> bool {
    a.strip_prefix(b)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with('.') || rest.starts_with('['))
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
        self.plan_with_progress(&|_, _| {})
    }

    /// [`SweepSpec::plan`], calling `progress` with the variants planned so far.
    ///
    /// The count comes first (from the numbers of values, [`variant_count`]): a sweep of too
    /// many variants is refused before any value is looked at. Planning then takes time linear
    /// in the variants: each value is set into the base design once and read back as the
    /// resolved design writes it, and a variant's id is hashed from the base design's
    /// canonical JSON with its values spliced in. The splice is used when every value changes
    /// nothing outside its own path and no two parameters share a subtree that is checked as
    /// a whole; a sample of variants is resolved in full and must give the same ids.
    /// Otherwise every variant's design is resolved in full (the same ids, more slowly).
    ///
    /// # Errors
    /// As [`SweepSpec::plan`].
    pub fn plan_with_progress(&self, progress: PlanProgress<'_>) -> Result<Plan, SweepError> {
        let total = variant_count(&self.parameters, self.mode, self.count, &self.origin)?;
        let sizes: Vec<u64> = self
            .parameters
            .iter()
            .map(|p| p.values.len() as u64)
            .collect();
        if self.mode == Mode::Random {
            // the grid fits in u64 here (variant_count)
            let n = sizes.iter().product::<u64>();
            if total > n {
                return Err(SweepError::File {
                    at: self.origin.clone(),
                    message: format!("count = {total}: more than the {n} combinations of the grid"),
                });
            }
        }
        let total = total as usize;
        // grid points (random mode: the ones drawn), else None: grid index i, or zip index i
        let picked: Option<Vec<u64>> = (self.mode == Mode::Random).then(|| {
            let n = sizes.iter().product::<u64>();
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.seed);
            let mut picked: Vec<u64> = rand::seq::index::sample(&mut rng, n as usize, total)
                .into_iter()
                .map(|i| i as u64)
                .collect();
            picked.sort_unstable();
            picked
        });
        let m = self.parameters.len();
        let combo = |i: usize| -> Vec<usize> {
            match (&picked, self.mode) {
                (_, Mode::Zip) => vec![i; m],
                (Some(p), _) => decode(p[i], &sizes),
                (None, _) => decode(i as u64, &sizes),
            }
        };
        let params_of = |c: &[usize]| -> Vec<(String, Value)> {
            self.parameters
                .iter()
                .zip(c)
                .map(|(p, &k)| (p.path.clone(), p.values[k].clone()))
                .collect()
        };
        progress(0, total);
        let tol = self.chord_tolerance.mm();
        let base_json = serde_json::to_value(&self.base.design).map_err(|e| SweepError::File {
            at: self.origin.clone(),
            message: e.to_string(),
        })?;
        let exact = |i: usize| -> Result<(u64, Variant), SweepError> {
            let params = params_of(&combo(i));
            let design =
                super::variants::resolve_in(&base_json, &self.base.design, &self.origin, &params)?;
            let id = variant_id(&design, tol);
            let key = u64::from_str_radix(&id, 16).unwrap_or_default();
            Ok((key, Variant::new(i, id, params)))
        };
        let splice = self.splice(&base_json).filter(|s| {
            // a sample of variants resolved in full must give the spliced ids
            let n = total.max(1);
            let k = n.min(64);
            (0..k).all(|j| {
                let i = if k > 1 { j * (n - 1) / (k - 1) } else { 0 };
                i >= total || exact(i).is_ok_and(|(key, _)| key == s.id_of(&combo(i), tol, None).0)
            })
        });
        let done = std::sync::Mutex::new(0usize);
        let report = |n: usize| {
            if let Ok(mut d) = done.lock() {
                *d += n;
                progress(*d, total);
            }
        };
        let batches: Vec<(usize, usize)> = (0..total)
            .step_by(BATCH)
            .map(|lo| (lo, (lo + BATCH).min(total)))
            .collect();
        let planned: Vec<Vec<Result<(u64, Variant), SweepError>>> = batches
            .par_iter()
            .map(|&(lo, hi)| {
                let out: Vec<Result<(u64, Variant), SweepError>> = match &splice {
                    Some(s) => {
                        let mut states = Vec::new();
                        let mut prev: Vec<usize> = Vec::new();
                        (lo..hi)
                            .map(|i| {
                                let c = combo(i);
                                let (key, id) = s.id_of(&c, tol, Some((&mut states, &prev)));
                                let params = params_of(&c);
                                prev = c;
                                Ok((key, Variant::new(i, id, params)))
                            })
                            .collect()
                    }
                    None => (lo..hi).map(exact).collect(),
                };
                report(hi - lo);
                out
            })
            .collect();
        let mut variants = Vec::with_capacity(total);
        let mut seen: std::collections::HashMap<u64, usize, IdHash> =
            std::collections::HashMap::with_capacity_and_hasher(total, IdHash::default());
        for r in planned.into_iter().flatten() {
            let (key, v) = r?;
            if let Some(other) = seen.insert(key, v.index) {
                return Err(SweepError::File {
                    at: self.origin.clone(),
                    message: format!(
                        "variants {other} and {} resolve to the same design (id {}); remove the duplicate value",
                        v.index, v.id
                    ),
                });
            }
            variants.push(v);
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

    /// The pieces from which the ids of this sweep's variants are hashed without resolving
    /// their designs, or `None` when some value changes the design outside its own path (or is
    /// left out of it), two parameters overlap or share a subtree checked as a whole, or a
    /// value does not resolve: then every variant is resolved in full.
    fn splice(&self, base_json: &Value) -> Option<Splice> {
        use serde::Deserialize as _;
        let paths: Vec<&str> = self.parameters.iter().map(|p| p.path.as_str()).collect();
        for (i, a) in paths.iter().enumerate() {
            for b in &paths[i + 1..] {
                if within(a, b) || within(b, a) {
                    return None;
                }
                if CHECKED_AS_A_WHOLE
                    .iter()
                    .any(|w| within(a, w) && within(b, w))
                {
                    return None;
                }
            }
        }
        let base = Design::deserialize(base_json).ok()?;
        let text = serde_json::to_string(&base).ok()?;
        let canonical = canonical_json(&serde_json::to_value(&base).ok()?);
        let mut spans: Vec<(usize, usize, usize)> = Vec::with_capacity(paths.len());
        for (k, p) in paths.iter().enumerate() {
            let (a, b) = fabkit_designs::variant::span_of(&canonical, p)?;
            spans.push((a, b, k));
        }
        spans.sort_unstable();
        if spans.windows(2).any(|w| w[0].1 > w[1].0) {
            return None;
        }
        let mut pieces = Vec::with_capacity(spans.len() + 1);
        let mut at = 0;
        for &(a, b, _) in &spans {
            pieces.push(canonical.as_bytes()[at..a].to_vec());
            at = b;
        }
        pieces.push(canonical.as_bytes()[at..].to_vec());
        let mut texts = Vec::with_capacity(paths.len());
        for p in &self.parameters {
            let span = fabkit_designs::variant::span_of(&text, &p.path)?;
            let numbers = takes_any_number(base_json, &p.path);
            let t: Option<Vec<Vec<u8>>> = p
                .values
                .par_iter()
                .map_init(
                    || None,
                    |json: &mut Option<Value>, v| match v {
                        Value::Number(n) if numbers => number_text(n),
                        _ => value_text(
                            json.get_or_insert_with(|| base_json.clone()),
                            &p.path,
                            v,
                            &text,
                            span,
                        ),
                    },
                )
                .collect();
            texts.push(t?);
        }
        Some(Splice {
            pieces,
            order: spans.iter().map(|s| s.2).collect(),
            texts,
        })
    }
}

/// For tests (sweep/tests/it/plan.rs): the number of pieces of the splice that plans this
/// sweep's ids from the base design's JSON form `base_json` (one more than the varied
/// parameters), or `None` when every variant is resolved in full.
#[doc(hidden)]
pub fn splice_pieces(spec: &SweepSpec, base_json: &Value) -> Option<usize> {
    spec.splice(base_json).map(|s| s.pieces.len())
}

/// Numbers that a parameter must take, and write back as the same `f64`, for every number to
/// count as one of its values without setting each into the design ([`takes_any_number`]):
/// zero, integers, fractions, both signs, the extremes of `f64` and of the integer types,
/// and digits a rounding serializer would change.
fn number_probes() -> Vec<Value> {
    vec![
        Value::from(0),
        Value::from(1),
        Value::from(-1),
        Value::from(0.5),
        Value::from(-0.5),
        Value::from(0.1),
        Value::from(0.123_456_789_012_345_6),
        Value::from(1.000_000_000_000_000_2),
        Value::from(123_456_789),
        Value::from(1e300),
        Value::from(-1e300),
        Value::from(5e-324),
        Value::from(u64::MAX),
        Value::from(i64::MIN),
    ]
}

/// The canonical text of a number in a plain `f64` field of the resolved design.
pub(crate) fn number_text(n: &serde_json::Number) -> Option<Vec<u8>> {
    serde_json::to_vec(&n.as_f64()?).ok()
}

/// Whether the parameter at `path` of the design whose JSON form is `base_json` is a plain
/// number (an `f64`, optional or not): the design takes each of [`number_probes`] there and
/// writes it back as that `f64`, changing nothing else. Then any number is a value of the
/// parameter, and its text in the resolved design is [`number_text`], without building the
/// design per value.
#[doc(hidden)]
pub fn takes_any_number(base_json: &Value, path: &str) -> bool {
    use serde::Deserialize as _;
    let Ok(base) = Design::deserialize(base_json) else {
        return false;
    };
    let Ok(text) = serde_json::to_string(&base) else {
        return false;
    };
    let Some(span) = fabkit_designs::variant::span_of(&text, path) else {
        return false;
    };
    let mut json = base_json.clone();
    number_probes().iter().all(|v| {
        let expected = v.as_number().and_then(number_text);
        expected.is_some() && value_text(&mut json, path, v, &text, span) == expected
    })
}

/// The canonical text of `value` at `path` as the design resolved from `base_json` with it
/// writes it; `None` unless the design it resolves to writes `base_text` (the base design's
/// JSON) everywhere but at `path` (its span `base_span` there).
fn value_text(
    base_json: &mut Value,
    path: &str,
    value: &Value,
    base_text: &str,
    base_span: (usize, usize),
) -> Option<Vec<u8>> {
    let design = super::variants::design_with(base_json, path, value)?.ok()?;
    let text = serde_json::to_string(&design).ok()?;
    let (a, b) = fabkit_designs::variant::span_of(&text, path)?;
    if text[..a] != base_text[..base_span.0] || text[b..] != base_text[base_span.1..] {
        return None;
    }
    let sub = &text[a..b];
    if sub.starts_with(['{', '[']) {
        // a list or an object: its canonical form from the design's tree (keys sorted;
        // numbers as serde_json writes them, not parsed back)
        let mut tree = serde_json::to_value(&design).ok()?;
        let at = fabkit_designs::schema::value_at(&mut tree, path)?;
        return Some(canonical_json(at).into_bytes());
    }
    // a scalar: written by the same serializer as the canonical form
    Some(sub.as_bytes().to_vec())
}

impl Splice {
    /// The id of the variant with value indices `combo` (per parameter) as a number and as
    /// text. `cache`: hasher states before each value and the previous combination, so that
    /// only the text from the first changed value on is hashed again.
    fn id_of(
        &self,
        combo: &[usize],
        tol: f64,
        cache: Option<(&mut Vec<Sha256>, &Vec<usize>)>,
    ) -> (u64, String) {
        let m = self.order.len();
        let mut local = Vec::new();
        let (states, prev) = match cache {
            Some((s, p)) => (s, p.as_slice()),
            None => (&mut local, &[][..]),
        };
        if states.is_empty() {
            let mut h = id_hasher(tol);
            h.update(&self.pieces[0]);
            states.resize(m.max(1), h);
        }
        let start = if prev.len() == combo.len() {
            (0..m)
                .find(|&k| prev[self.order[k]] != combo[self.order[k]])
                .unwrap_or(0)
        } else {
            0
        };
        let mut h = states[start].clone();
        for (k, &p) in self.order.iter().enumerate().skip(start) {
            if k > start {
                states[k] = h.clone();
            }
            h.update(&self.texts[p][combo[p]]);
            h.update(&self.pieces[k + 1]);
        }
        let d = h.finalize();
        let mut first = [0u8; 8];
        first.copy_from_slice(&d[..8]);
        (u64::from_be_bytes(first), hex(&first))
    }
}

/// Hashes the first 64 bits of a variant id (already a sha256) as they are.
type IdHash = std::hash::BuildHasherDefault<IdHasher>;

#[derive(Default)]
struct IdHasher(u64);

impl std::hash::Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(*b);
        }
    }
    fn write_u64(&mut self, n: u64) {
        self.0 = n;
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
