//! `FABRICATION.md`: the human fabrication sheet, rendered from the manifest alone.

use crate::manifest::{Manifest, ManifestPart};
use std::fmt::Write as _;

/// Renders the sheet. Deterministic: only the manifest goes in.
pub(crate) fn render(m: &Manifest) -> String {
    let mut s = String::new();
    // `write!` into a String cannot fail; the results are ignored on purpose.
    let _ = writeln!(s, "# Fabrication sheet: {}\n", text(&m.design.name));
    s.push_str(
        "Written by fabkit with every export; regenerate it rather than edit it. \
         Lengths in mm, volumes in mm³ unless stated.\n\n",
    );

    provenance(&mut s, m);

    print_list(&mut s, m);
    groups(&mut s, m);
    print_settings(&mut s, m);

    layer_stack(&mut s, m);
    markers(&mut s, m);
    section_view(&mut s, m);

    cast_order(&mut s, m);

    shopping_list(&mut s, m);
    laser_cut(&mut s, m);
    pcb_outlines(&mut s, m);
    machined_parts(&mut s, m);
    procedure(&mut s, m);

    bought_items(&mut s, m);
    checking_the_prints(&mut s, m);
    s
}

/// `## Provenance`: the fabkit version, the design and its sha256, the chord tolerance, the
/// command line, the frame and the kit 3MF.
fn provenance(s: &mut String, m: &Manifest) {
    s.push_str("## Provenance\n\n");
    let _ = writeln!(s, "- fabkit version: {}", code(&m.fabkit_version));
    let _ = writeln!(
        s,
        "- design: {} from {}",
        code(&m.design.name),
        code(&m.design.source)
    );
    let _ = writeln!(s, "- design sha256: {}", code(&m.design.sha256));
    let _ = writeln!(
        s,
        "- chord tolerance: {} mm (largest facet-to-surface distance)",
        m.chord_tolerance_mm
    );
    let _ = writeln!(s, "- command line: {}", code(&shell_words(&m.command_line)));
    let _ = writeln!(s, "- frame: {}", text(&m.frame));
    if let Some(k) = &m.kit_3mf {
        let _ = writeln!(
            s,
            "- kit 3MF: {} ({} objects in one file, for viewing the whole kit; print from the plates below), sha256 {}",
            code(&k.file),
            k.objects.len(),
            code(&k.sha256)
        );
    }
    s.push_str("- file hashes and exact part numbers: `manifest.json`\n\n");
}

/// `## Print list`: every part with its file, technology, group, material, volume and size,
/// what it is, the plates and the part previews.
fn print_list(s: &mut String, m: &Manifest) {
    s.push_str("## Print list\n\n");
    s.push_str(
        "| # | Part | File | Technology | Group | Material | Volume (mm³) | \
         Size x × y × z (mm) |\n",
    );
    s.push_str(
        "|---|------|------|------------|-------|----------|-------------:|\
         ---------------------|\n",
    );
    for (i, p) in m.parts.iter().enumerate() {
        let [sx, sy, sz] = p.bbox_mm.size();
        let file = p
            .file
            .as_deref()
            .map_or_else(|| "(in the 3MF only)".to_owned(), code);
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.2} × {:.2} × {:.2} |",
            i + 1,
            code(&p.name),
            file,
            p.print_technology,
            p.group.as_deref().map_or_else(|| "–".to_owned(), code),
            text(&p.material_name),
            p.volume_mm3,
            sx,
            sy,
            sz
        );
    }
    s.push('\n');
    for p in &m.parts {
        let _ = writeln!(
            s,
            "- {} ({}): {}",
            code(&p.name),
            text(&p.role),
            text(&p.description)
        );
    }
    s.push('\n');
    if !m.plates.is_empty() {
        s.push_str("### Plates

One 3MF per printer plate, parts of one technology and material inside the printer's bed less its margin, already placed: open it in the slicer without arranging.

");
        s.push_str(
            "| Plate | Printer | Bed x × y × z (mm) | Margin (mm) | Parts |
",
        );
        s.push_str(
            "|-------|---------|--------------------|------------:|-------|
",
        );
        for p in &m.plates {
            let _ = writeln!(
                s,
                "| {} | {} ({}) | {} × {} × {} | {} | {} |",
                code(&p.file),
                code(&p.printer),
                p.print_technology,
                p.bed_mm[0],
                p.bed_mm[1],
                p.bed_mm[2],
                p.margin_mm,
                plate_parts(&p.objects)
            );
        }
        s.push('\n');
        for p in m.plates.iter().filter(|p| p.preview.is_some()) {
            let _ = writeln!(
                s,
                "![Plate {}]({})\n",
                text(&p.file),
                p.preview.as_deref().unwrap_or_default()
            );
        }
    }
    if m.parts.iter().any(|p| p.preview.is_some()) {
        s.push_str(
            "### Part previews

Each part in print orientation, from above-front-right and from below-back-left.

",
        );
        for p in m.parts.iter().filter(|p| p.preview.is_some()) {
            let _ = writeln!(
                s,
                "{}\n\n![{}]({})\n",
                code(&p.name),
                text(&p.name),
                p.preview.as_deref().unwrap_or_default()
            );
        }
    }
}

/// `## Cast order`: each pour with its material, volumes, what to weigh or measure out, its
/// coats and the smallest batch weighable by hand.
fn cast_order(s: &mut String, m: &Manifest) {
    s.push_str("## Cast order\n\n");
    if m.casts.is_empty() {
        s.push_str("No pours in this kit.\n\n");
    }
    for c in &m.casts {
        let _ = writeln!(s, "### Step {}: {}\n", c.step, text(&c.cast));
        let _ = writeln!(s, "- material: {}", text(&c.material_name));
        let _ = writeln!(s, "- mix ratio: {}", text(&c.mix_ratio));
        if !c.mold_parts.is_empty() {
            let parts: Vec<String> = c.mold_parts.iter().map(|p| code(p)).collect();
            let _ = writeln!(s, "- held by: {}", parts.join(", "));
        }
        if let Some(v) = c.layer_volume_ml {
            let _ = writeln!(
                s,
                "- layer volume: {v:.2} mL (the cast layer alone, from the exact profile)"
            );
        }
        let _ = writeln!(
            s,
            "- pour volume: {:.2} mL ({})",
            c.cavity_volume_ml,
            if c.cast == fabkit_designs::procedure::FILLING_GEL {
                // poured into the assembled shell: no mold, no reservoir
                "the space it fills in the assembled shell, from the exact surfaces"
            } else {
                "the cavity with its reservoir and sprue"
            }
        );
        let _ = writeln!(
            s,
            "- waste allowance: {:.0} % (included in the masses below)",
            c.waste_allowance * 100.0
        );
        let by_volume = c.components.iter().any(|x| x.volume_ml.is_some());
        s.push_str(if by_volume {
            "- measure out (mixed by volume):\n"
        } else {
            "- weigh out:\n"
        });
        for comp in &c.components {
            match comp.volume_ml {
                Some(v) => {
                    let _ = writeln!(
                        s,
                        "  - {}: {v:.2} mL ({:.2} g)",
                        text(&comp.name),
                        comp.mass_g
                    );
                }
                None => {
                    let _ = writeln!(s, "  - {}: {:.2} g", text(&comp.name), comp.mass_g);
                }
            }
        }
        if by_volume {
            let ml: f64 = c.components.iter().filter_map(|x| x.volume_ml).sum();
            let _ = writeln!(s, "  - total: {ml:.2} mL ({:.2} g)", c.total_mass_g);
        } else {
            let _ = writeln!(s, "  - total: {:.2} g", c.total_mass_g);
        }
        for k in &c.coats {
            let parts: Vec<String> = k
                .components
                .iter()
                .map(|x| format!("{} {:.2} g", text(&x.name), x.mass_g))
                .collect();
            let gone = if k.evaporates.is_empty() {
                String::new()
            } else {
                format!(", {} evaporating", k.evaporates.join(", "))
            };
            let _ = writeln!(
                s,
                "- coat {} first: {}, {:.2} mm, {:.3} mL on the mold's surface; mix {}{gone}: {} = {:.2} g for the coat itself (spraying loses more)",
                code(&k.layer),
                text(&k.material_name),
                k.thickness_mm,
                k.coat_volume_ml,
                text(&k.mix_ratio),
                parts.join(" + "),
                k.total_mass_g
            );
            if let Some(b) = &k.min_batch {
                let _ = writeln!(
                    s,
                    "  - smallest batch weighable by hand: {} = {:.1} g",
                    batch_parts(b),
                    b.total_mass_g
                );
            }
        }
        if let Some(b) = &c.min_batch {
            let _ = writeln!(
                s,
                "- too little to weigh by hand: mix at least {} = {:.1} g (the smallest component \
                 {:.1} g, about 10 % on a 0.1 g scale), pour what the step needs, {:.1} g is left over",
                batch_parts(b),
                b.total_mass_g,
                fabkit_designs::kit::MIN_WEIGHABLE_G,
                b.leftover_g
            );
        }
        if !c.notes.trim().is_empty() {
            let _ = writeln!(s, "- notes: {}", text(&c.notes));
        }
        s.push('\n');
    }
}

/// `## Bought items`.
fn bought_items(s: &mut String, m: &Manifest) {
    s.push_str("## Bought items\n\n");
    if m.bought_items.is_empty() {
        s.push_str("None.\n");
    }
    for b in &m.bought_items {
        let _ = writeln!(s, "- {}", text(b));
    }
    s.push('\n');
}

/// `## Checking the prints`: the files' hashes, the slicer's manifold check and volume, the
/// sizes, and the fit checks of this kit.
fn checking_the_prints(s: &mut String, m: &Manifest) {
    s.push_str("## Checking the prints\n\n");
    s.push_str(
        "1. Files: `sha256sum` of each file must equal its `sha256` in `manifest.json` \
         (`parts[].sha256`, `kit_3mf.sha256`).\n",
    );
    s.push_str(
        "2. Before slicing: the slicer must report every object as manifold with no repaired \
         errors (e.g. `prusa-slicer --info <file>`), and its volume must match the print list \
         to within 0.1 %.\n",
    );
    s.push_str(
        "3. After printing: measure the overall size with calipers against the print list \
         (typically within ±0.2 mm for FDM, ±0.1 mm for SLA).\n",
    );
    for check in fit_checks(m) {
        let _ = writeln!(s, "   - {check}");
    }
}

/// The consumables to buy, per product, with the amounts this kit uses: each cast material's
/// mix (grams, or millilitres and grams for a mix by volume; waste allowance included) and each
/// print material's grams (part volumes times density, before supports and purge).
fn shopping_list(s: &mut String, m: &Manifest) {
    // (product, grams, millilitres): grams for what is weighed, millilitres for a mix by
    // volume (with its grams) and for primer and release (millilitres only)
    let mut items: Vec<(String, Option<f64>, Option<f64>)> = Vec::new();
    let mut add = |name: &str, g: Option<f64>, ml: Option<f64>| {
        let sum = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(a), Some(b)) => Some(a + b),
            (a, b) => a.or(b),
        };
        match items.iter_mut().find(|(n, _, _)| n == name) {
            Some((_, tg, tml)) => {
                *tg = sum(*tg, g);
                *tml = sum(*tml, ml);
            }
            None => items.push((name.to_string(), g, ml)),
        }
    };
    // coats and treatments first: they are applied before their pour
    for c in &m.casts {
        for k in &c.coats {
            add(&k.material_name, Some(k.total_mass_g), None);
        }
        for t in &c.treatments {
            add(&t.material_name, None, Some(t.amount_ml));
        }
    }
    for c in &m.casts {
        let ml = c
            .components
            .iter()
            .all(|x| x.volume_ml.is_some())
            .then(|| c.components.iter().filter_map(|x| x.volume_ml).sum());
        add(&c.material_name, Some(c.total_mass_g), ml);
    }
    for p in &m.parts {
        if p.mass_g > 0.0 {
            add(&p.material_name, Some(p.mass_g), None);
        }
    }
    if items.is_empty() {
        return;
    }
    s.push_str("## Shopping list\n\n");
    s.push_str(
        "What this kit uses, per product: cast materials as mixed (waste allowance included), \
         prints as the parts' volume times the material's density (add supports, purge and \
         failed prints).\n\n",
    );
    s.push_str("| Product | Amount |\n|---------|-------:|\n");
    for (name, g, ml) in items {
        let amount = match (g, ml) {
            (None, Some(ml)) => format!("about {ml:.2} mL"),
            (Some(g), Some(ml)) => format!("{ml:.1} mL ({g:.1} g)"),
            // two decimals where a 0.01 g scale matters, one above 10 g
            (Some(g), None) if g < 10.0 => format!("{g:.2} g"),
            (Some(g), None) => format!("{g:.1} g"),
            (None, None) => continue,
        };
        let _ = writeln!(s, "| {} | {amount} |", text(&name));
    }
    s.push('\n');
}

/// The laser-cut parts and their files; nothing when the kit has none.
fn laser_cut(s: &mut String, m: &Manifest) {
    if m.cut_parts.is_empty() {
        return;
    }
    s.push_str("## Laser cutting\n\n");
    s.push_str(
        "DXF (R2000, mm, layer `cut`) and SVG (mm, cut lines red, hairline) of each part, \
         centred on the sensor axis, for the laser; `cut/preview/` holds each part's SVG to look \
         at (visible lines, its name and a scale bar), not to cut. Where a kerf is given, the \
         paths are offset by half of it away from the part: set the cutter's kerf compensation \
         to 0.\n\n",
    );
    for c in &m.cut_parts {
        let _ = writeln!(
            s,
            "- {}{} and {}{}: {} from {}, {:.1} mm sheet, {:.1} mm² of face{}",
            if c.quantity > 1 {
                format!("{} x ", c.quantity)
            } else {
                String::new()
            },
            code(&c.dxf),
            code(&c.svg),
            c.stl
                .as_ref()
                .map_or(String::new(), |f| format!(" (solid: {})", code(f))),
            text(&c.description),
            text(&c.material_name),
            c.thickness_mm,
            c.nominal_area_mm2,
            if c.kerf_mm > 0.0 {
                format!("; paths for a {:.2} mm kerf", c.kerf_mm)
            } else {
                String::new()
            }
        );
    }
    s.push('\n');
}

/// The parts made to order by a machine shop, their drawings and files; nothing when the kit
/// has none.
fn machined_parts(s: &mut String, m: &Manifest) {
    if m.machined_parts.is_empty() {
        return;
    }
    s.push_str("## Machined parts (order from a shop)\n\n");
    s.push_str(
        "Send the shop the drawing (SVG: a section through the axis with the dimensions, \
         material, finish and tolerance) and the STEP file (`--format step`; the STL is the \
         same solid meshed), in the sensor frame, mm.\n\n",
    );
    for p in &m.machined_parts {
        let files: Vec<String> = [Some(&p.drawing), p.step_file.as_ref(), p.file.as_ref()]
            .into_iter()
            .flatten()
            .map(|f| code(f))
            .collect();
        let least = p.params["least_wall_mm"].as_f64();
        let _ = writeln!(
            s,
            "- {}: {} ({}), {}; {:.2} g{}",
            files.join(", "),
            text(&p.description),
            text(&p.material_name),
            text(&p.finish),
            p.mass_g,
            least.map_or(String::new(), |w| format!("; least wall {w:.2} mm"))
        );
    }
    s.push('\n');
}

/// The PCB outlines and their files; nothing when the kit has none.
fn pcb_outlines(s: &mut String, m: &Manifest) {
    if m.pcb_outlines.is_empty() {
        return;
    }
    s.push_str("## PCB outlines\n\n");
    s.push_str(
        "DXF (R2000, mm) of each board, centred on the sensor axis: import layer `cut` as the \
         board's edge and holes in the PCB tool; `engrave` marks the components' places.\n\n",
    );
    for c in &m.pcb_outlines {
        let _ = writeln!(
            s,
            "- {}: {}, {:.1} mm board, {:.1} mm² of face",
            code(&c.dxf),
            text(&c.description),
            c.thickness_mm,
            c.area_mm2
        );
    }
    s.push('\n');
}

/// The section view with its legend; nothing for a kit that is not a sensor.
fn section_view(s: &mut String, m: &Manifest) {
    let Some(v) = &m.section_view else {
        return;
    };
    s.push_str("## Section view\n\n");
    let _ = writeln!(
        s,
        "![The assembled sensor cut through its axis]({})\n\nThe sensor cut by the plane y = 0 \
         through its axis (x to the right, z up, {:.0} px per mm; the black bar under it is \
         {} mm long); bought parts are envelopes. Check it first: the layers on the core, the \
         seats in the shell.\n",
        v.file, v.px_per_mm, v.scale_bar_mm
    );
    s.push_str("| Colour | Part | Kind | Section area (mm²) |\n|--------|------|------|-------------------:|\n");
    for l in &v.legend {
        let kind = match l.kind {
            fabkit_designs::assembly::MemberKind::Printed => "printed",
            fabkit_designs::assembly::MemberKind::Cast => "cast",
            fabkit_designs::assembly::MemberKind::Bought => "bought (envelope)",
        };
        let _ = writeln!(
            s,
            "| `{}` | {} | {kind} | {:.1} |",
            l.colour,
            code(&l.name),
            l.area_mm2
        );
    }
    s.push('\n');
}

/// The procedure in order, numbered, from `manifest.procedure`; nothing when it is empty.
fn procedure(s: &mut String, m: &Manifest) {
    if m.procedure.is_empty() {
        return;
    }
    s.push_str("## Procedure\n\n");
    s.push_str(
        "In this order; \"Step N\" is the pour of the cast order with its amounts and notes.\n\n",
    );
    for (i, p) in m.procedure.iter().enumerate() {
        let _ = writeln!(s, "{}. {}", i + 1, text(&p.text));
    }
    s.push('\n');
}

/// The print settings that matter for the kit's own parts, by role: no supports on surfaces
/// that form the skin, leak-tight mold boxes; nothing for a kit without such parts.
fn print_settings(s: &mut String, m: &Manifest) {
    let named = |roles: &[&str]| -> Vec<String> {
        m.parts
            .iter()
            .filter(|p| roles.contains(&p.role.as_str()))
            .map(|p| code(&p.name))
            .collect()
    };
    let forming = named(&[
        "master_pattern",
        "mold_half",
        "open_mold_piece",
        "negative_mold",
    ]);
    let boxes = named(&["mold_box"]);
    if forming.is_empty() && boxes.is_empty() {
        return;
    }
    s.push_str("### Print settings that matter\n\n");
    if !forming.is_empty() {
        let _ = writeln!(
            s,
            "- Surfaces that form the skin ({}): print each part as it is placed in its file, with \
             no supports touching the cavity or pattern surface (a support mark is cast into the \
             skin); put supports, where the slicer needs them, only under flanges, plinths and \
             outer walls. Finest layer height of the profile.",
            forming.join(", ")
        );
    }
    if !boxes.is_empty() {
        let _ = writeln!(
            s,
            "- Mold boxes ({}): they hold liquid Mold Star, so the walls must be leak-tight: at \
             least 3 perimeters and 4 top and bottom layers, no gaps at the seam; seal a leak with \
             tape or hot glue on the outside before pouring.",
            boxes.join(", ")
        );
    }
    s.push('\n');
}

/// A batch's components: `Part A 10.0 g + Part B 10.0 g + ...`.
fn batch_parts(b: &fabkit_designs::kit::MinBatch) -> String {
    b.components
        .iter()
        .map(|x| format!("{} {:.1} g", text(&x.name), x.mass_g))
        .collect::<Vec<_>>()
        .join(" + ")
}

/// The fit checks of the kit's own parts, by role, before any pour: only what the kit has.
fn fit_checks(m: &Manifest) -> Vec<&'static str> {
    let count = |role: &str| m.parts.iter().filter(|p| p.role == role).count();
    let mut out = Vec::new();
    if count("mold_half") > 0 {
        out.push(
            "mold halves: they close without a gap and their registration keys engage; the \
             clamp bolts pass through both halves",
        );
    }
    if count("open_mold_piece") > 1 {
        out.push(
            "two-piece mold: the top piece's boss seats in the cavity block's pocket without a \
             gap and the clamp bolts pass through both pieces",
        );
    }
    if count("mold_box") > 0 {
        out.push(
            "master patterns: each seats in its mold box, plinth in the recess, with no gap the \
             Mold Star could run under",
        );
    }
    if count("core_holder") + count("casting_jig") > 0 {
        out.push(
            "core holders and casting jigs: the core slides onto the centring pin without play",
        );
    }
    if count("shell_collar") + count("shell_tube") + count("shell_base") + count("shell_half") > 0 {
        out.push("shell: the parts fit together and their screw holes line up");
    }
    out
}

/// The skin's layers, inner to outer, with their thicknesses, from `summary.layers` (nothing
/// when the summary has no layers). Outer surfaces are radii when the body has a
/// `radius_mm`, offsets from the reference surface otherwise.
fn layer_stack(s: &mut String, m: &Manifest) {
    let Some(layers) = m.summary["layers"].as_array().filter(|l| !l.is_empty()) else {
        return;
    };
    let radius = m.summary["body"]["radius_mm"].as_f64();
    s.push_str("## Layer stack\n\n");
    s.push_str(
        "Inner to outer. The reference surface (`body` in `manifest.json`) is the cavity of \
         the outermost mold; a sprayed layer lies inside it, so its thickness comes out of the \
         cast layer under it.\n\n",
    );
    s.push_str("| Layer | Material | Process | Thickness (mm) | Outer surface (mm) |\n");
    s.push_str("|-------|----------|---------|---------------:|-------------------:|\n");
    for l in layers {
        let name = l["name"].as_str().unwrap_or("?");
        let material = l["material"].as_str().unwrap_or("?");
        let process = l["process"].as_str().unwrap_or("?");
        let thickness = l["thickness_mm"].as_f64().unwrap_or(f64::NAN);
        let offset = l["outer_offset_mm"].as_f64().unwrap_or(f64::NAN);
        let outer = match radius {
            Some(r) => format!("R{:.3}", r + offset),
            None => format!("offset {offset:+.3}"),
        };
        // the product name where a cast or a coat of this material gives it
        let material = m
            .casts
            .iter()
            .map(|c| (&c.material, &c.material_name))
            .chain(
                m.casts
                    .iter()
                    .flat_map(|c| c.coats.iter().map(|k| (&k.material, &k.material_name))),
            )
            .chain(m.parts.iter().map(|p| (&p.material, &p.material_name)))
            .find(|(key, _)| *key == material)
            .map_or_else(|| code(material), |(_, name)| text(name));
        let _ = writeln!(
            s,
            "| {} | {material} | {} | {thickness:.3} | {outer} |",
            code(name),
            text(process)
        );
    }
    s.push('\n');
}

/// The marker patterns, layer by layer, with the parts that carry their features, from
/// `summary.markers` (nothing when the kit has none): a maker checks them on the printed mold
/// before casting.
fn markers(s: &mut String, m: &Manifest) {
    let Some(sets) = m.summary["markers"].as_array().filter(|l| !l.is_empty()) else {
        return;
    };
    s.push_str(
        "## Markers

",
    );
    s.push_str(
        "The features of each marker pattern and the printed parts that form them: check that \
         each of these parts shows them before you cast. Under a sprayed coat the formers are \
         smaller (dimples) or larger (bumps) by the coat's thickness all round: the coat, \
         sprayed into the mold, follows them.\n\n",
    );
    s.push_str("| Layer | Surface | Markers | Feature | Formed by |\n");
    s.push_str("|-------|---------|--------:|---------|-----------|\n");
    for k in sets {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} |",
            code(k["layer"].as_str().unwrap_or("?")),
            text(k["surface"].as_str().unwrap_or("?")),
            k["count"],
            text(&marker_feature_words(k)),
            text(&marker_formers(k))
        );
    }
    s.push('\n');
}

/// A marker set's feature in a maker's words: "0.6 mm dimples, 0.4 mm deep".
pub fn marker_feature_words(k: &serde_json::Value) -> String {
    let f = &k["feature"];
    let d = f["diameter_mm"].as_f64().unwrap_or(f64::NAN);
    let h = f["height_mm"].as_f64().unwrap_or(f64::NAN);
    let recessed = matches!(f["on_skin"].as_str(), Some("dimple"))
        || matches!(f["polarity"].as_str(), Some("recessed"));
    if recessed {
        format!("{d} mm dimples, {h} mm deep")
    } else {
        format!("{d} mm bumps, {h} mm tall")
    }
}

/// The parts that carry a marker set's features and the formers' size:
/// "translucent_gel_master_pattern: 127 dimple formers, 0.400 mm (under 0.100 mm of coat)".
pub fn marker_formers(k: &serde_json::Value) -> String {
    let parts: Vec<&str> = k["formed_by"]
        .as_array()
        .map(|a| a.iter().filter_map(|x| x.as_str()).collect())
        .unwrap_or_default();
    let recessed = marker_feature_words(k).contains("dimples");
    let coat = k["coat_mm"].as_f64().unwrap_or(0.0);
    format!(
        "{}: {} {} formers, {:.3} mm{}",
        parts.join(", "),
        k["count"],
        if recessed { "dimple" } else { "bump" },
        k["former_diameter_mm"].as_f64().unwrap_or(f64::NAN),
        if coat > 0.0 {
            format!(" (under {coat:.3} mm of coat)")
        } else {
            String::new()
        }
    )
}

/// One note per multi-material group, in order of first appearance; nothing without groups.
fn groups(s: &mut String, m: &Manifest) {
    let mut groups: Vec<(&str, Vec<&ManifestPart>)> = Vec::new();
    for p in &m.parts {
        let Some(g) = p.group.as_deref() else {
            continue;
        };
        match groups.iter_mut().find(|(name, _)| *name == g) {
            Some((_, members)) => members.push(p),
            None => groups.push((g, vec![p])),
        }
    }
    if groups.is_empty() {
        return;
    }
    s.push_str("### Multi-material groups\n\n");
    s.push_str(
        "The parts of a group were built in shared coordinates and touch where their \
         materials meet: print them together as one multi-material job and never move one \
         without the others.\n\n",
    );
    for (g, members) in groups {
        let mut techs: Vec<String> = Vec::new();
        for p in &members {
            let t = p.print_technology.to_string();
            if !techs.contains(&t) {
                techs.push(t);
            }
        }
        // The 3MF object holding the group, if a 3MF was written.
        let object = m.kit_3mf.as_ref().and_then(|k| {
            k.objects
                .iter()
                .find(|o| o.group.as_deref() == Some(g))
                .map(|o| (k, o))
        });
        let load = match object {
            Some((k, o)) => format!(
                "object {} of {} holds them in place as its parts (one volume each)",
                code(&o.name),
                code(&k.file)
            ),
            None => {
                let files: Vec<String> = members
                    .iter()
                    .map(|p| p.file.as_deref().map_or_else(|| code(&p.name), code))
                    .collect();
                format!(
                    "load {} as parts of one object without moving them (shared coordinates)",
                    files.join(", ")
                )
            }
        };
        let materials: Vec<String> = members
            .iter()
            .map(|p| {
                let extruder = object
                    .and_then(|(_, o)| o.volumes.iter().find(|v| v.part == p.name))
                    .map_or_else(String::new, |v| format!(" (extruder {})", v.extruder));
                format!("{} {}{extruder}", code(&p.name), text(&p.material_name))
            })
            .collect();
        let _ = writeln!(
            s,
            "- group {} ({}): print together as one multi-material job: {}, assign materials: {}.",
            code(g),
            techs.join(", "),
            load,
            materials.join(", ")
        );
    }
    s.push('\n');
}

/// Inline code span; falls back to plain text when `s` holds a backtick or a `|` (which a
/// table would take for a cell border even inside a code span).
fn code(s: &str) -> String {
    if s.contains(['`', '|']) {
        text(s)
    } else {
        format!("`{}`", one_line(s))
    }
}

/// Plain text, safe inside a table cell: one line, `|` escaped.
fn text(s: &str) -> String {
    one_line(s).replace('|', "\\|")
}

fn one_line(s: &str) -> String {
    s.split(['\n', '\r'])
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Arguments joined by spaces, each quoted when it holds a space or quote (POSIX shell).
pub(crate) fn shell_words(args: &[String]) -> String {
    args.iter()
        .map(|a| {
            if !a.is_empty() && !a.contains([' ', '\'', '"', '\t']) {
                a.clone()
            } else {
                format!("'{}'", a.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// A plate's objects in words: each name once, in order, with its count when the plate holds
/// several (`` `pin` × 29 ``).
fn plate_parts(objects: &[crate::manifest::ManifestPlateObject]) -> String {
    let mut names: Vec<(&str, usize)> = Vec::new();
    for o in objects {
        match names.iter_mut().find(|(n, _)| *n == o.name) {
            Some((_, k)) => *k += 1,
            None => names.push((&o.name, 1)),
        }
    }
    names
        .iter()
        .map(|(n, k)| {
            if *k > 1 {
                format!("{} × {k}", code(n))
            } else {
                code(n)
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_cells_stay_in_their_column() {
        assert_eq!(text("a|b\nc"), "a\\|b c");
        assert_eq!(code("x`y"), "x`y");
        assert_eq!(code("x|y"), "x\\|y");
        assert_eq!(
            shell_words(&["fabkit".into(), "a b".into()]),
            "fabkit 'a b'"
        );
    }
}
