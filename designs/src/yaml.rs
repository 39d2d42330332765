//! The YAML reading rules of every fabkit input file, and where a value sits in its text
//! (`file:line:column` for errors).

use crate::error::DesignError;
use serde::Deserialize;

/// The YAML reading rules of every fabkit input file (designs, sweeps, fixture parameters): a
/// scalar is taken as what it is written as, never converted. A number or a boolean where text
/// is expected (`name: 25`, `description: true`) is refused (quote it); so are YAML 1.1
/// booleans (`yes`, `on`) and tags fabkit does not know (`!!python/object/apply:...`).
pub fn yaml_options() -> serde_saphyr::Options {
    let mut o = budget_options();
    o.no_schema = true;
    o.strict_booleans = true;
    o.reject_unsupported_tags = true;
    o
}

/// Marker patterns of [`crate::markers::MAX_MARKERS_PER_PATTERN`] listed points each that one
/// input file may hold within [`MAX_YAML_NODES`].
pub const MAX_LISTED_PATTERNS: usize = 4;

/// Most YAML values (nodes: lists, mappings and scalars) one input file may hold: what the
/// design limits allow, [`MAX_LISTED_PATTERNS`] marker lists of
/// [`crate::markers::MAX_MARKERS_PER_PATTERN`] points (a list of two numbers, three nodes,
/// each) and 100,000 nodes for the rest of the design. Bounds the parser's memory before any
/// value is typed.
pub const MAX_YAML_NODES: usize =
    MAX_LISTED_PATTERNS * 3 * crate::markers::MAX_MARKERS_PER_PATTERN + 100_000;

/// The parser's budget for every fabkit input file: [`MAX_YAML_NODES`] nodes, twice as many
/// parser events (a list or mapping is two), the library's defaults otherwise (64 levels of
/// nesting, 64 MiB of scalars, 50,000 aliases).
pub fn yaml_budget() -> serde_saphyr::Budget {
    let mut b = serde_saphyr::Budget::default();
    b.max_nodes = MAX_YAML_NODES;
    b.max_events = 2 * MAX_YAML_NODES;
    b
}

/// The parser's default reading rules under [`yaml_budget`]: for the untyped passes that find
/// where a value sits ([`yaml_location`]) and which numbers were quoted.
pub fn budget_options() -> serde_saphyr::Options {
    let mut o = serde_saphyr::Options::default();
    o.budget = Some(yaml_budget());
    o
}

/// Parses YAML `text` into `T` under [`yaml_options`].
///
/// # Errors
/// The parser's error (with its location; see [`yaml_error`]).
pub fn yaml_from_str<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, serde_saphyr::Error> {
    serde_saphyr::from_str_with_options(text, yaml_options())
}

/// Refuses a number written quoted in `text` (`radius_mm: "15.0"`), which the parser would
/// convert ([`crate::values::quoted_numbers`]).
///
/// # Errors
/// [`DesignError::Yaml`] naming every such value at its `origin:line:column`
/// ([`yaml_location`]), with its parameter path and text.
pub fn refuse_quoted_numbers<T: serde::Serialize + ?Sized>(
    typed: &T,
    text: &str,
    origin: &str,
) -> Result<(), DesignError> {
    let quoted = crate::values::quoted_numbers(typed, text);
    if quoted.is_empty() {
        return Ok(());
    }
    Err(DesignError::Yaml(
        quoted
            .iter()
            .map(|(path, s)| {
                let at = yaml_location(text, path)
                    .map(|(l, c)| format!(":{l}:{c}"))
                    .unwrap_or_default();
                format!("{origin}{at}: {path} = \"{s}\": a number must be written without quotes")
            })
            .collect::<Vec<_>>()
            .join("\n"),
    ))
}

/// Line and column (from 1) where the YAML node at parameter path `path` (`a.b[2].c`: `.`
/// between keys, `[i]` for list items) starts in `text`; `None` when the text does not parse
/// or has no such node.
pub fn yaml_location(text: &str, path: &str) -> Option<(u64, u64)> {
    let root: serde_saphyr::Spanned<Node> =
        serde_saphyr::from_str_with_options(text, budget_options()).ok()?;
    let mut cur = &root;
    for step in path_steps(path)? {
        cur = match (&cur.value, step) {
            (Node::Map(entries), Step::Key(k)) => &entries.iter().find(|(name, _)| *name == k)?.1,
            (Node::Seq(items), Step::Index(i)) => items.get(i)?,
            _ => return None,
        };
    }
    Some((cur.referenced.line(), cur.referenced.column()))
}

/// The plain scalar that starts at `line`, `column` (from 1) of `text`, as written: up to the
/// end of the line or a comment; `None` for a quoted, flow or block value.
pub(crate) fn written_scalar(text: &str, line: u64, column: u64) -> Option<String> {
    let l = text
        .lines()
        .nth(usize::try_from(line).ok()?.checked_sub(1)?)?;
    let rest = l.get(usize::try_from(column).ok()?.checked_sub(1)?..)?;
    let scalar = rest.split(" #").next()?.trim_end();
    let plain = !scalar.is_empty()
        && !scalar.starts_with(['"', '\'', '[', '{', '|', '>', '&', '*', '!'])
        && !scalar.contains(": ");
    plain.then(|| scalar.to_string())
}

/// Line and column (from 1) in `text` of the value that preset `preset` gives parameter `path`
/// (a key of `presets.<preset>`, dots and brackets included).
pub(crate) fn preset_value_location(text: &str, preset: &str, path: &str) -> Option<(u64, u64)> {
    let root: serde_saphyr::Spanned<Node> =
        serde_saphyr::from_str_with_options(text, budget_options()).ok()?;
    let mut cur = &root;
    for key in ["presets", preset, path] {
        let Node::Map(entries) = &cur.value else {
            return None;
        };
        cur = &entries.iter().find(|(name, _)| name == key)?.1;
    }
    Some((cur.referenced.line(), cur.referenced.column()))
}

/// The parameter path (`core.wall_thickness_mm`, `layers[1].name`) of the scalar value that
/// starts at `line`, `column` (from 1) of `text`; `None` when the text does not parse or no
/// scalar value starts there (a key, a mapping, a list).
pub fn yaml_scalar_path_at(text: &str, line: u64, column: u64) -> Option<String> {
    fn find(n: &serde_saphyr::Spanned<Node>, at: (u64, u64), path: &mut String) -> bool {
        match &n.value {
            Node::Scalar => (n.referenced.line(), n.referenced.column()) == at,
            Node::Map(entries) => entries.iter().any(|(k, v)| {
                let len = path.len();
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(k);
                let hit = find(v, at, path);
                if !hit {
                    path.truncate(len);
                }
                hit
            }),
            Node::Seq(items) => items.iter().enumerate().any(|(i, v)| {
                let len = path.len();
                path.push_str(&format!("[{i}]"));
                let hit = find(v, at, path);
                if !hit {
                    path.truncate(len);
                }
                hit
            }),
        }
    }
    let root: serde_saphyr::Spanned<Node> =
        serde_saphyr::from_str_with_options(text, budget_options()).ok()?;
    let mut path = String::new();
    (find(&root, (line, column), &mut path) && !path.is_empty()).then_some(path)
}

enum Step<'a> {
    Key(&'a str),
    Index(usize),
}

/// `a.b[2].c` as keys and indices; `None` for a malformed path.
fn path_steps(path: &str) -> Option<Vec<Step<'_>>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_once('[').map_or((part, ""), |(k, r)| (k, r));
        if key.is_empty() && out.is_empty() {
            return None;
        }
        if !key.is_empty() {
            out.push(Step::Key(key));
        }
        while !rest.is_empty() {
            let (i, r) = rest.split_once(']')?;
            out.push(Step::Index(i.parse().ok()?));
            rest = r.strip_prefix('[').unwrap_or(r);
            if !r.is_empty() && !r.starts_with('[') {
                return None;
            }
        }
    }
    Some(out)
}

/// A YAML document with the location of every node: maps keep their keys in order.
enum Node {
    Map(Vec<(String, serde_saphyr::Spanned<Node>)>),
    Seq(Vec<serde_saphyr::Spanned<Node>>),
    Scalar,
}

impl<'de> Deserialize<'de> for Node {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        macro_rules! scalar {
            ($($f:ident: $t:ty),*) => {
                $(fn $f<E: serde::de::Error>(self, _: $t) -> Result<Node, E> { Ok(Node::Scalar) })*
            };
        }
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Node;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("any YAML node")
            }
            scalar!(visit_bool: bool, visit_i64: i64, visit_u64: u64, visit_i128: i128,
                visit_u128: u128, visit_f64: f64, visit_str: &str, visit_bytes: &[u8]);
            fn visit_unit<E: serde::de::Error>(self) -> Result<Node, E> {
                Ok(Node::Scalar)
            }
            fn visit_none<E: serde::de::Error>(self) -> Result<Node, E> {
                Ok(Node::Scalar)
            }
            fn visit_some<D: serde::Deserializer<'de>>(self, d: D) -> Result<Node, D::Error> {
                Node::deserialize(d)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut a: A) -> Result<Node, A::Error> {
                let mut items = Vec::new();
                while let Some(x) = a.next_element()? {
                    items.push(x);
                }
                Ok(Node::Seq(items))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> Result<Node, A::Error> {
                let mut entries = Vec::new();
                while let Some(k) = m.next_key::<serde_json::Value>()? {
                    let key = match k {
                        serde_json::Value::String(s) => s,
                        other => other.to_string(),
                    };
                    entries.push((key, m.next_value()?));
                }
                Ok(Node::Map(entries))
            }
        }
        d.deserialize_any(V)
    }
}

/// [`yaml_error`] followed by ` (at <parameter path>)` when the error points at a scalar of
/// `text` (the parsed YAML).
pub fn yaml_error_in(origin: &str, text: &str, e: &serde_saphyr::Error) -> String {
    let mut msg = yaml_error(origin, e);
    let path = e
        .location()
        .and_then(|loc| yaml_scalar_path_at(text, loc.line(), loc.column()));
    if let Some(path) = path {
        msg.push_str(&format!(" (at {path})"));
    }
    msg
}

/// Formats a serde-saphyr error as `file:line:column: message`.
pub fn yaml_error(origin: &str, e: &serde_saphyr::Error) -> String {
    let msg = plain_message(e).unwrap_or_else(|| e.to_string());
    let first = msg.lines().next().unwrap_or(&msg);
    let hint = nearest_name_hint(first).unwrap_or_default();
    match e.location() {
        Some(loc) => format!(
            "{origin}:{}:{}: {}{hint}",
            loc.line(),
            loc.column(),
            strip_location(first)
        ),
        None => format!("{origin}: {first}{hint}"),
    }
}

/// `; did you mean `strategy`?` for the parser's "unknown field `strategi`, expected one of
/// strategy, ..." (or "unknown variant"): the listed name nearest the mistyped one in edits
/// (optimal string alignment distance: insertions, deletions, substitutions and swaps of
/// neighbours; letter case ignored), the first in the listed order among equally near ones,
/// when it is at most max(2, a third of the mistyped name's length) edits away; `None`
/// otherwise.
fn nearest_name_hint(msg: &str) -> Option<String> {
    let rest = msg
        .split_once("unknown field `")
        .or_else(|| msg.split_once("unknown variant `"))?
        .1;
    let (typed, rest) = rest.split_once('`')?;
    let names = rest.split_once("expected one of ").map_or_else(
        || {
            rest.split_once("expected ")
                .map(|(_, n)| n.split(" or ").collect::<Vec<_>>())
        },
        |(_, n)| Some(n.split(", ").collect()),
    )?;
    let best = nearest_name(typed, names.iter().map(|n| n.trim().trim_matches('`')))?;
    Some(format!("; did you mean `{best}`?"))
}

/// The name of `names` nearest `typed` in edits, letter case ignored (optimal string alignment
/// distance), the first of equally near ones, when it is at most max(2, a third of `typed`'s
/// length in characters) edits away.
fn nearest_name<'a>(typed: &str, names: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let typed_lower = typed.to_lowercase();
    let limit = (typed.chars().count() / 3).max(2);
    // min_by_key keeps the first of equal keys: the listed order breaks ties
    let (d, best) = names
        .into_iter()
        .filter(|n| !n.is_empty())
        .map(|n| (strsim::osa_distance(&typed_lower, &n.to_lowercase()), n))
        .min_by_key(|(d, _)| *d)?;
    (d <= limit).then_some(best)
}

/// The rule and the limit in words for the parser's errors that name its internals (a budget
/// breached, its non-finite float policy); `None` for the others, whose text is the parser's.
fn plain_message(e: &serde_saphyr::Error) -> Option<String> {
    use serde_saphyr::budget::BudgetBreach;
    let budget = yaml_budget();
    Some(match e.without_snippet() {
        serde_saphyr::Error::NonFiniteFloat { value, .. } => format!(
            "`{value}` is not a finite number: every number in a fabkit input must be finite"
        ),
        serde_saphyr::Error::Budget { breach, .. } => match breach {
            BudgetBreach::Nodes { .. } | BudgetBreach::Events { .. } => format!(
                "the file holds more than {} YAML values (lists, mappings and numbers), the most an input file may hold: enough for {MAX_LISTED_PATTERNS} marker lists of {} points (hint: give a long point list as a csv_file)",
                budget.max_nodes,
                crate::markers::MAX_MARKERS_PER_PATTERN
            ),
            BudgetBreach::Depth { .. } => format!(
                "lists and mappings are nested more than {} levels deep, the most an input file may have",
                budget.max_depth
            ),
            BudgetBreach::Aliases { .. } | BudgetBreach::Anchors { .. } => format!(
                "more than {} YAML anchors or aliases (&name, *name), the most an input file may have",
                budget.max_aliases.min(budget.max_anchors)
            ),
            BudgetBreach::Documents { .. } => {
                "more than one YAML document (---): an input file is one document".to_string()
            }
            BudgetBreach::ScalarBytes { .. } => format!(
                "its values hold more than {} bytes of text, the most an input file may",
                budget.max_total_scalar_bytes
            ),
            other => format!("the file is beyond the YAML reader's limits ({other:?})"),
        },
        _ => return None,
    })
}

/// Drops serde-saphyr's own `error: line N column M: ` prefix (we print file:line:col).
fn strip_location(s: &str) -> &str {
    let s = s.strip_prefix("error: ").unwrap_or(s);
    if s.starts_with("line ") {
        if let Some(i) = s.find(": ") {
            if s[..i].contains("column") {
                return &s[i + 2..];
            }
        }
    }
    s
}
