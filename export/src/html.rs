//! `FABRICATION.html`: the fabrication sheet (`FABRICATION.md`) as one self-contained HTML page
//! to open in a browser: the Markdown rendered (CommonMark with tables, `pulldown-cmark`), every
//! picture of the export the sheet shows inlined as a `data:` URI, the CSS inline; no network
//! resource, no script.

use base64::Engine as _;
use pulldown_cmark::{html, Event, Options, Parser, Tag};

/// The page's style: readable text, tables with rules, pictures at most the page's width.
const CSS: &str = "body{font-family:system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;line-height:1.45;\
color:#1b1b1b;background:#fff;margin:0}main{max-width:1100px;margin:0 auto;padding:1.5em 2em 4em}\
h1,h2,h3{line-height:1.2}h2{border-bottom:1px solid #ccc;padding-bottom:.2em;margin-top:2em}\
table{border-collapse:collapse;margin:1em 0;font-size:.92em}th,td{border:1px solid #ccc;padding:.3em .6em;\
vertical-align:top}th{background:#f3f3f3;text-align:left}code{font-family:ui-monospace,Menlo,Consolas,monospace;\
font-size:.9em;background:#f5f5f5;padding:0 .2em;border-radius:3px}img{max-width:100%;height:auto;\
border:1px solid #ddd;background:#fafafa}.swatch{display:inline-block;width:1.6em;height:1em;\
vertical-align:-.15em;margin-right:.4em;border:1px solid #888;border-radius:2px}";

/// The HTML page of `markdown` titled `title`; an image whose path is one of `files` (export
/// relative paths and bytes, PNG) is inlined, any other is left as a relative link.
pub(crate) fn render(markdown: &str, title: &str, files: &[(String, Vec<u8>)]) -> String {
    let opts = Options::ENABLE_TABLES | Options::ENABLE_STRIKETHROUGH;
    let events = Parser::new_ext(markdown, opts).map(|ev| match ev {
        Event::Start(Tag::Image {
            link_type,
            dest_url,
            title,
            id,
        }) => {
            let inlined = files
                .iter()
                .find(|(f, _)| f.as_str() == dest_url.as_ref())
                .map(|(_, bytes)| {
                    format!(
                        "data:image/png;base64,{}",
                        base64::engine::general_purpose::STANDARD.encode(bytes)
                    )
                });
            Event::Start(Tag::Image {
                link_type,
                dest_url: inlined.map_or(dest_url, Into::into),
                title,
                id,
            })
        }
        // a colour written as code (the section view's legend) gets its swatch
        Event::Code(c) if is_hex_colour(&c) => Event::InlineHtml(
            format!("<span class=\"swatch\" style=\"background:{c}\"></span><code>{c}</code>")
                .into(),
        ),
        other => other,
    });
    let mut body = String::new();
    html::push_html(&mut body, events);
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{CSS}</style>\n</head>\n<body>\n<main>\n{body}</main>\n</body>\n</html>\n",
        escape(title)
    )
}

/// `#rrggbb`.
fn is_hex_colour(s: &str) -> bool {
    s.len() == 7 && s.starts_with('#') && s[1..].chars().all(|c| c.is_ascii_hexdigit())
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A colour in a code span (the section view's legend, `#6aa7e8`) is drawn as a swatch
    /// beside its code; other code is left as it is.
    #[test]
    fn colour_codes_get_swatches() {
        let h = render(
            "| `#6aa7e8` | `gel` |\n|---|---|\n| `#12345g` | x |\n",
            "t",
            &[],
        );
        assert!(
            h.contains(
                "<span class=\"swatch\" style=\"background:#6aa7e8\"></span><code>#6aa7e8</code>"
            ),
            "{h}"
        );
        assert!(
            h.contains("<code>gel</code>") && h.contains("<code>#12345g</code>"),
            "{h}"
        );
        assert_eq!(h.matches("class=\"swatch\"").count(), 1, "{h}");
    }

    #[test]
    fn pictures_of_the_export_are_inlined_and_tables_rendered() {
        let png = vec![0x89, b'P', b'N', b'G', 1, 2, 3];
        let md = "# Kit\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n![section](section.png)\n\n![elsewhere](other.png)\n";
        let h = render(md, "Kit <x>", &[("section.png".into(), png.clone())]);
        assert!(h.starts_with("<!DOCTYPE html>"));
        assert!(h.contains("<title>Kit &lt;x&gt;</title>"));
        assert!(h.contains("<table>") && h.contains("<td>1</td>"));
        let b64 = base64::engine::general_purpose::STANDARD.encode(&png);
        assert!(
            h.contains(&format!("src=\"data:image/png;base64,{b64}\"")),
            "{h}"
        );
        assert!(h.contains("src=\"other.png\""));
        assert!(!h.contains("http://") && !h.contains("https://") && !h.contains("<script"));
    }
}
