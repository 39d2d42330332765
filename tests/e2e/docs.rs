//! The user guide's generated page is current: the command reference
//! (docs/src/reference/cli.md) is rendered from the CLI's clap definition, so it lists every
//! command and flag with its help text and cannot drift from the binary.

use crate::common::repo_root;
use serde_json::Value;

const HEADER: &str = "<!-- Generated from the command line's definition (fabkit/src/cli.rs) by \
tests/e2e/docs.rs; regenerate with FABKIT_BLESS=1 cargo test -p fabkit --test e2e -- \
the_command_reference. -->\n\n";

fn reference() -> String {
    let options = clap_markdown::MarkdownOptions::new()
        .title("Commands".to_string())
        .show_footer(false)
        .show_table_of_contents(true);
    let body = clap_markdown::help_markdown_command_custom(&fabkit::cli::command(), &options);
    format!("{HEADER}{}", escape_angle_brackets(&body))
}

/// `<design>` in help text is a placeholder, not an HTML tag: escaped outside code spans.
fn escape_angle_brackets(markdown: &str) -> String {
    markdown
        .lines()
        .map(|line| {
            line.split('`')
                .enumerate()
                .map(|(i, part)| {
                    if i % 2 == 0 {
                        part.replace('<', "&lt;").replace('>', "&gt;")
                    } else {
                        part.to_string()
                    }
                })
                .collect::<Vec<_>>()
                .join("`")
        })
        .map(|line| line + "\n")
        .collect()
}

/// The committed generated page `file` (under docs/src/reference/) equals `want`; with
/// FABKIT_BLESS=1 it is written first. Returns the page.
fn committed_page(file: &str, want: &str, test: &str) -> String {
    let path = repo_root().join("docs/src/reference").join(file);
    if std::env::var("FABKIT_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, want).unwrap();
    }
    let got = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        got == want,
        "docs/src/reference/{file} is not what fabkit generates; regenerate it with \
         `FABKIT_BLESS=1 cargo test --profile quick -p fabkit --test e2e -- {test}`"
    );
    got
}

#[test]
fn the_command_reference_is_rendered_from_the_cli() {
    let got = committed_page("cli.md", &reference(), "the_command_reference");
    for command in [
        "export",
        "fixtures",
        "calibrate extrinsics",
        "groundtruth",
        "sweep",
        "schema",
        "validate",
    ] {
        assert!(
            got.contains(&format!("## `fabkit {command}`")),
            "{command} is in the reference"
        );
    }
}

/// One row of the design reference: a key's path, what it holds, its bounds, its default and
/// its description.
struct Field {
    path: String,
    kind: String,
    bounds: String,
    default: String,
    description: String,
}

/// The definition a `$ref` names, else the node itself.
fn resolve<'a>(root: &'a Value, node: &'a Value) -> &'a Value {
    match node.get("$ref").and_then(Value::as_str) {
        Some(r) => {
            let name = r.trim_start_matches("#/$defs/");
            &root["$defs"][name]
        }
        None => node,
    }
}

/// `X` of an optional `anyOf: [X, null]`.
fn non_null(node: &Value) -> &Value {
    if let Some(branches) = node.get("anyOf").and_then(Value::as_array) {
        let not_null: Vec<&Value> = branches.iter().filter(|b| b["type"] != "null").collect();
        if not_null.len() == 1 {
            return not_null[0];
        }
    }
    node
}

fn one_line(text: &str) -> String {
    // the first paragraph; rustdoc's [`item`] links as plain code
    let text = text.split("\n\n").next().unwrap_or("").replace('\n', " ");
    let text = text.replace("[`", "`").replace("`]", "`");
    text.replace('|', "\\|")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn scalar_kind(node: &Value) -> String {
    let names: Vec<String> = match &node["type"] {
        Value::String(t) => vec![t.clone()],
        Value::Array(ts) => ts
            .iter()
            .filter_map(Value::as_str)
            .filter(|t| *t != "null")
            .map(str::to_string)
            .collect(),
        _ => vec![],
    };
    names.join(" or ")
}

fn bounds(node: &Value) -> String {
    let mut b = Vec::new();
    for (key, op) in [
        ("exclusiveMinimum", ">"),
        ("minimum", ">="),
        ("exclusiveMaximum", "<"),
        ("maximum", "<="),
    ] {
        if let Some(v) = node.get(key) {
            b.push(format!("{op} {v}"));
        }
    }
    if let Some(p) = node.get("pattern").and_then(Value::as_str) {
        b.push(format!("`{p}`"));
    }
    b.join(", ")
}

/// A key's default: its own, else its part of the default of the mapping it is in.
fn default_of(default: Option<&Value>) -> String {
    match default {
        Some(Value::Null) | None => String::new(),
        Some(v @ (Value::Bool(_) | Value::Number(_))) => format!("`{v}`"),
        Some(Value::String(s)) if s.is_empty() => "empty".to_string(),
        Some(Value::String(s)) => format!("`{s}`"),
        Some(Value::Array(a)) if a.is_empty() => "none".to_string(),
        Some(Value::Object(o)) if o.is_empty() => "none".to_string(),
        Some(_) => "as below".to_string(),
    }
}

/// The values of a string enum (`enum` or `oneOf` of `const`s), if the node is one.
fn enum_values(node: &Value) -> Option<Vec<String>> {
    if let Some(values) = node.get("enum").and_then(Value::as_array) {
        return Some(
            values
                .iter()
                .map(|v| {
                    format!(
                        "`{}`",
                        v.as_str().map_or_else(|| v.to_string(), String::from)
                    )
                })
                .collect(),
        );
    }
    let branches = node.get("oneOf")?.as_array()?;
    branches
        .iter()
        .map(|b| {
            b.get("const")
                .and_then(Value::as_str)
                .map(|c| format!("`{c}`"))
        })
        .collect()
}

/// Appends the rows of `node` (a key's schema, at `path`) and of every key below it.
fn walk(
    root: &Value,
    path: &str,
    node: &Value,
    inherited: Option<&Value>,
    description: &str,
    rows: &mut Vec<Field>,
) {
    let default = node.get("default").or(inherited);
    let inner = non_null(node);
    let def = resolve(root, inner);
    let description = if description.is_empty() {
        def.get("description").and_then(Value::as_str).unwrap_or("")
    } else {
        description
    };
    let row = |kind: String, rows: &mut Vec<Field>| {
        rows.push(Field {
            path: path.to_string(),
            kind,
            bounds: bounds(def),
            default: default_of(default),
            description: one_line(description),
        })
    };
    if let Some(values) = enum_values(def) {
        return row(format!("one of {}", values.join(", ")), rows);
    }
    if let Some(branches) = def.get("oneOf").and_then(Value::as_array) {
        let mut forms: Vec<String> = branches
            .iter()
            .filter_map(|b| b["properties"]["profile"]["const"].as_str())
            .map(|c| format!("`{c}`"))
            .collect();
        forms.dedup();
        if forms.is_empty() {
            // a mapping of exactly one of its keys (an enum of forms): each form's key
            row(
                "mapping with exactly one of the keys below".to_string(),
                rows,
            );
            for b in branches {
                let note = one_line(b["description"].as_str().unwrap_or(""));
                walk_properties(root, path, b, None, &format!(" ({note})"), rows);
            }
            return;
        }
        // a mapping in one of several forms named by `profile` (the body): each form's keys
        row("mapping, one of the forms below".to_string(), rows);
        rows.push(Field {
            path: format!("{path}.profile"),
            kind: format!("one of {}", forms.join(", ")),
            bounds: String::new(),
            default: String::new(),
            description: "The form, which decides the other keys.".to_string(),
        });
        for b in branches {
            let form = b["properties"]["profile"]["const"].as_str().unwrap_or("?");
            let note = one_line(b["description"].as_str().unwrap_or(""));
            let note = format!(" (`profile: {form}`: {note})");
            walk_properties(root, path, b, None, &note, rows);
        }
        return;
    }
    if def.get("properties").is_some() {
        row("mapping".to_string(), rows);
        return walk_properties(root, path, def, default, "", rows);
    }
    match scalar_kind(def).as_str() {
        "array" => {
            let items = resolve(root, non_null(&def["items"]));
            if items.get("properties").is_some() || items.get("oneOf").is_some() {
                row("list".to_string(), rows);
                walk(root, &format!("{path}[i]"), &def["items"], None, "", rows);
            } else {
                let item = enum_values(items)
                    .map(|v| v.join(", "))
                    .unwrap_or_else(|| scalar_kind(items));
                row(format!("list of {item}"), rows);
            }
        }
        "object" => {
            let values = def.get("additionalProperties").map(|v| resolve(root, v));
            match values {
                Some(v) if v.get("properties").is_some() => {
                    row("map of name to mapping".to_string(), rows);
                    let values = &def["additionalProperties"];
                    walk(root, &format!("{path}.<name>"), values, None, "", rows);
                }
                _ => row("map of name to values".to_string(), rows),
            }
        }
        kind => row(kind.to_string(), rows),
    }
}

fn walk_properties(
    root: &Value,
    path: &str,
    def: &Value,
    default: Option<&Value>,
    note: &str,
    rows: &mut Vec<Field>,
) {
    let Some(properties) = def["properties"].as_object() else {
        return;
    };
    for (key, child) in properties {
        if key == "profile" && !note.is_empty() {
            continue;
        }
        let child_path = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        let start = rows.len();
        let inherited = default.and_then(|d| d.get(key));
        let description = child["description"].as_str().unwrap_or("");
        walk(root, &child_path, child, inherited, description, rows);
        if !note.is_empty() {
            rows[start].description = format!("{}{note}", rows[start].description);
        }
    }
}

fn design_reference() -> String {
    let root = fabkit::designs::schema::design_json_schema();
    let mut rows = Vec::new();
    walk_properties(&root, "", &root, None, "", &mut rows);
    let mut out = String::from(
        "<!-- Generated from the design schema (fabkit schema) by tests/e2e/docs.rs; regenerate \
with FABKIT_BLESS=1 cargo test -p fabkit --test e2e -- the_design_reference. -->\n\n\
# Design fields\n\n\
Every key of a design file, generated from the design schema ([Design schema](schema.md)): \
its path (as presets and sweeps write it; `[i]` a list item, `<name>` a key of your choice), \
what it holds, the bounds the key must keep on its own, its default when it may be left out, \
and its description. Rules between keys are checked by `fabkit validate`. Lengths are mm \
and angles degrees.\n",
    );
    let mut section = String::new();
    for r in &rows {
        let top = r.path.split(['.', '[']).next().unwrap_or("").to_string();
        if top != section {
            section = top;
            out.push_str(&format!(
                "\n## `{section}`\n\n| key | holds | bounds | default | description |\n|---|---|---|---|---|\n"
            ));
        }
        out.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            r.path, r.kind, r.bounds, r.default, r.description
        ));
    }
    out
}

#[test]
fn the_design_reference_is_rendered_from_the_schema() {
    let got = committed_page(
        "design-fields.md",
        &design_reference(),
        "the_design_reference",
    );
    // every parameter path `fabkit validate` lists for the default design is in the reference
    let o = crate::common::run(&repo_root(), &["validate", "rtac0"], &[]);
    let listing = crate::common::text(&o.stdout);
    let generic = |p: &str| {
        let mut out = String::new();
        let mut rest = p;
        while let Some(i) = rest.find('[') {
            let j = rest[i..].find(']').map_or(rest.len(), |j| i + j + 1);
            out.push_str(&rest[..i]);
            out.push_str("[i]");
            rest = &rest[j..];
        }
        out + rest
    };
    let mut checked = 0;
    for line in listing.lines().filter_map(|l| l.strip_prefix("  ")) {
        let Some((p, _)) = line.split_once(" = ") else {
            continue;
        };
        let p = generic(p);
        assert!(
            got.contains(&format!("| `{p}` |")),
            "{p} is not in the design reference"
        );
        checked += 1;
    }
    assert!(checked > 50, "{checked} paths checked");
}
