//! The user guide's generated page is current: the command reference
//! (docs/src/reference/cli.md) is rendered from the CLI's clap definition, so it lists every
//! command and flag with its help text and cannot drift from the binary.

use crate::common::repo_root;

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

#[test]
fn the_command_reference_is_rendered_from_the_cli() {
    let path = repo_root().join("docs/src/reference/cli.md");
    let want = reference();
    if std::env::var("FABKIT_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, &want).unwrap();
    }
    let got = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        got == want,
        "docs/src/reference/cli.md is not the reference of this CLI; regenerate it with \
         `FABKIT_BLESS=1 cargo test --profile quick -p fabkit --test e2e -- the_command_reference`"
    );
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
