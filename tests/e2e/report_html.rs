//! `FABRICATION.html` opened in headless Chromium (Debian package `chromium`): every picture
//! the page holds is inlined (no network resource, no relative link left), decodes in the
//! browser (each image's `naturalWidth` > 0, read from the page Chromium rendered), and the
//! screenshot shows them (the page is not blank; the section view's colours are on it).

use std::path::Path;
use std::process::Command;

use crate::common::{missing, run, text};

fn chromium() -> bool {
    if Command::new("chromium").arg("--version").output().is_ok() {
        return true;
    }
    missing("chromium (scripts/setup-system)");
    false
}

/// The images' natural sizes as Chromium decoded them: a copy of the page with a script that
/// writes them into the title once the page has loaded, dumped after rendering.
fn natural_sizes(page: &Path, tmp: &Path) -> Vec<(u32, u32)> {
    let html = std::fs::read_to_string(page).unwrap();
    let probe = html.replace(
        "</body>",
        "<script>window.addEventListener('load',()=>{document.title='sizes:'+Array.from(document.images).map(i=>i.naturalWidth+'x'+i.naturalHeight).join(',')})</script></body>",
    );
    let copy = tmp.join("probe.html");
    std::fs::write(&copy, probe).unwrap();
    let o = Command::new("chromium")
        .args([
            "--headless",
            "--disable-gpu",
            "--no-sandbox",
            "--virtual-time-budget=10000",
            "--dump-dom",
        ])
        .arg(format!("file://{}", copy.display()))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o.stderr));
    let dom = text(&o.stdout);
    let title = dom
        .split("<title>sizes:")
        .nth(1)
        .and_then(|t| t.split("</title>").next())
        .unwrap_or_else(|| panic!("no sizes in the title: {}", &dom[..dom.len().min(400)]));
    title
        .split(',')
        .filter(|s| !s.is_empty())
        .map(|s| {
            let (w, h) = s.split_once('x').unwrap();
            (w.parse().unwrap(), h.parse().unwrap())
        })
        .collect()
}

/// Pixels of the screenshot that are strongly coloured (max - min channel above 60): the page's
/// text and rules are greys, so these come from pictures.
fn coloured_pixels(png: &Path) -> usize {
    let img = image::open(png).unwrap().into_rgb8();
    img.pixels()
        .filter(|p| {
            let [r, g, b] = p.0;
            r.max(g).max(b) - r.min(g).min(b) > 60
        })
        .count()
}

#[test]
fn fabrication_html_renders_its_pictures_in_chromium() {
    if !chromium() {
        return;
    }
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    for args in [
        &["export", "rtac0", "--out", "kit"][..],
        &["fixtures", "rtac0", "--out", "fx"][..],
    ] {
        let o = run(dir, args, &[]);
        assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
    }
    for (out, has_section) in [("kit", true), ("fx", false)] {
        let page = dir.join(out).join("FABRICATION.html");
        let html = std::fs::read_to_string(&page).unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"));
        assert!(
            !html.contains("http://") && !html.contains("https://") && !html.contains("<link"),
            "{out}: the page loads nothing from elsewhere"
        );
        let images = html.matches("<img ").count();
        let inlined = html.matches("<img src=\"data:image/png;base64,").count();
        assert_eq!(images, inlined, "{out}: every picture is inlined");
        assert!(images >= 1, "{out}: no picture");
        let sizes = natural_sizes(&page, dir);
        assert_eq!(sizes.len(), images, "{out}: {sizes:?}");
        assert!(
            sizes.iter().all(|&(w, h)| w > 0 && h > 0),
            "{out}: an image did not decode: {sizes:?}"
        );
        let shot = dir.join(format!("{out}.png"));
        let o = Command::new("chromium")
            .args([
                "--headless",
                "--disable-gpu",
                "--no-sandbox",
                "--hide-scrollbars",
                "--window-size=1200,12000",
                "--virtual-time-budget=10000",
            ])
            .arg(format!("--screenshot={}", shot.display()))
            .arg(format!("file://{}", page.display()))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
        let coloured = coloured_pixels(&shot);
        if has_section {
            // the section view alone is tens of thousands of coloured pixels
            // measured 639,251
            assert!(coloured > 20_000, "{out}: {coloured} coloured pixels");
        }
        let img = image::open(&shot).unwrap().into_rgb8();
        let non_white = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
        // measured 2.0 and 4.2 million
        assert!(non_white > 50_000, "{out}: {non_white} non-white pixels");
    }
}
