//! The manifest and `FABRICATION.md` of every library kit, read as a maker reads them at the
//! bench: product names rather than material keys, a shopping list with amounts, the procedure
//! in order, cast layer and pour volumes, mixes that can be weighed, screws and bolts by
//! standard size and length, and checks that fit the kit.

use fabkit_designs::kit::ProcedureAction as A;
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::schema::MoldStrategy;
use fabkit_designs::{build_kit, ChordTolerance};
use fabkit_export::{write_kit, ExportOptions, Formats};
use serde_json::Value;
use std::f64::consts::PI;

const TOL_MM: f64 = 0.05;

struct Exported {
    manifest: Value,
    sheet: String,
}

fn export(design: &str, strategy: Option<MoldStrategy>) -> Exported {
    export_as(design, strategy, false).0
}

/// The export, and the bytes of `assembly.3mf` (with `threemf`) and `section.png` when written.
fn export_as(
    design: &str,
    strategy: Option<MoldStrategy>,
    threemf: bool,
) -> (Exported, [Option<Vec<u8>>; 2]) {
    let mut d = fabkit_designs::library::load(design).unwrap();
    if let Some(s) = strategy {
        d.mold.strategy = s;
    }
    let kit = build_kit(&d, ChordTolerance::new(TOL_MM).unwrap()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join(design);
    let opts = ExportOptions {
        formats: Formats {
            stl: true,
            threemf,
            step: false,
            mjcf: false,
            urdf: false,
            usd: false,
        },
        command_line: vec!["fabkit".into(), "export".into(), design.into()],
        design_source: format!("library:{design}"),
        design_sha256: "0".repeat(64),
        chord_tolerance_mm: TOL_MM,
        fabkit_version: "test".into(),
        printers: Default::default(),
        command: fabkit_export::OutputCommand::Export,
        force: false,
        sim: Default::default(),
    };
    write_kit(&kit, &out, &opts).unwrap();
    let exported = Exported {
        manifest: serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap())
            .unwrap(),
        sheet: std::fs::read_to_string(out.join("FABRICATION.md")).unwrap(),
    };
    common_checks(design, &exported);
    let read = |f: &str| std::fs::read(out.join(f)).ok();
    (exported, [read("assembly.3mf"), read("section.png")])
}

/// The lines of the sheet's section `## title`, up to the next `## `.
fn section<'a>(sheet: &'a str, title: &str) -> Vec<&'a str> {
    let head = format!("## {title}");
    sheet
        .lines()
        .skip_while(|l| *l != head)
        .skip(1)
        .take_while(|l| !l.starts_with("## "))
        .collect()
}

fn arr<'a>(v: &'a Value, key: &str) -> &'a Vec<Value> {
    v[key]
        .as_array()
        .unwrap_or_else(|| panic!("{key} is not an array"))
}

fn actions(e: &Exported) -> Vec<A> {
    arr(&e.manifest, "procedure")
        .iter()
        .map(|s| serde_json::from_value(s["action"].clone()).unwrap())
        .collect()
}

fn cast<'a>(e: &'a Exported, name: &str) -> &'a Value {
    arr(&e.manifest, "casts")
        .iter()
        .find(|c| c["cast"] == name)
        .unwrap_or_else(|| panic!("no cast {name}"))
}

fn close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b}");
}

/// What every kit's sheet must hold.
fn common_checks(design: &str, e: &Exported) {
    let s = &e.sheet;
    let m = &e.manifest;
    // Product names, not keys: no material key of the table appears anywhere in the sheet
    // (the keys with an underscore cannot be mistaken for words) but in the plates' file
    // names, which carry the key.
    let table = MaterialsTable::embedded().unwrap();
    let mut without_files = s.clone();
    for p in m["plates"].as_array().into_iter().flatten() {
        for k in ["file", "preview"] {
            if let Some(f) = p[k].as_str() {
                without_files = without_files.replace(f, "");
            }
        }
    }
    for key in table.materials.keys().filter(|k| k.contains('_')) {
        assert!(
            !without_files.contains(key.as_str()),
            "{design}: key {key} in the sheet\n{s}"
        );
    }
    // The shopping list: one row per product used, each with an amount in g or mL.
    let rows: Vec<(String, String)> = section(s, "Shopping list")
        .iter()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| Product"))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            (cells[1].to_string(), cells[2].to_string())
        })
        .collect();
    for (product, amount) in &rows {
        let number = amount
            .trim_start_matches("about ")
            .split(' ')
            .next()
            .and_then(|n| n.parse::<f64>().ok());
        assert!(
            number.is_some_and(|n| n > 0.0) && (amount.contains(" g") || amount.contains(" mL")),
            "{design}: {product}: amount {amount:?}"
        );
    }
    let listed = |name: &str| rows.iter().any(|(p, _)| p == name);
    for c in arr(m, "casts") {
        assert!(
            listed(c["material_name"].as_str().unwrap()),
            "{design}: {c}"
        );
        for k in c["coats"].as_array().into_iter().flatten() {
            assert!(listed(k["material_name"].as_str().unwrap()), "{design}");
        }
        for t in c["treatments"].as_array().into_iter().flatten() {
            assert!(listed(t["material_name"].as_str().unwrap()), "{design}");
        }
    }
    for p in arr(m, "parts") {
        assert!(
            listed(p["material_name"].as_str().unwrap()),
            "{design}: {p}"
        );
    }
    // The procedure: printing first, assembly last, and the sheet lists it numbered in order.
    let a = actions(e);
    assert_eq!(a.first(), Some(&A::Print), "{design}");
    assert_eq!(a.last(), Some(&A::Assemble), "{design}");
    let listed_steps: Vec<&str> = section(s, "Procedure")
        .into_iter()
        .filter(|l| l.chars().next().is_some_and(|c| c.is_ascii_digit()))
        .collect();
    assert_eq!(listed_steps.len(), a.len(), "{design}");
    for (i, (line, step)) in listed_steps.iter().zip(arr(m, "procedure")).enumerate() {
        assert_eq!(
            *line,
            format!("{}. {}", i + 1, step["text"].as_str().unwrap()),
            "{design}"
        );
    }
    // Each pour's layer volume and pour volume are stated.
    for c in arr(m, "casts") {
        let pour = c["cavity_volume_ml"].as_f64().unwrap();
        assert!(
            s.contains(&format!("- pour volume: {pour:.2} mL")),
            "{design}: {}",
            c["cast"]
        );
        if let Some(v) = c["layer_volume_ml"].as_f64() {
            assert!(
                s.contains(&format!("- layer volume: {v:.2} mL")),
                "{design}"
            );
        }
    }
    // The checks fit the kit: no registration keys or clamp bolts that the kit lacks.
    let checks = section(s, "Checking the prints").join("\n");
    let roles: Vec<&str> = arr(m, "parts")
        .iter()
        .map(|p| p["role"].as_str().unwrap())
        .collect();
    if checks.contains("registration keys") {
        assert!(roles.contains(&"mold_half"), "{design}: {checks}");
    }
    let bought = arr(m, "bought_items");
    if checks.contains("clamp bolts") {
        assert!(
            bought
                .iter()
                .any(|b| b.as_str().unwrap().contains("clamp bolts M3 x ")),
            "{design}: {bought:?}"
        );
    }
    // Print settings for the parts whose surface forms the skin, and for mold boxes.
    if roles
        .iter()
        .any(|r| ["master_pattern", "mold_half", "open_mold_piece", "mold_box"].contains(r))
    {
        assert!(s.contains("### Print settings that matter"), "{design}");
    }
}

/// R-Tac0 (master strategy): the translucent layer's own volume and its pour volume; Mold Star
/// in mL; the black coat's mix and amount; the primer and release agent with their areas from
/// the exact profile; the Mold Star fill height from the master's own height; screws by
/// standard size and length; the procedure in order.
#[test]
fn rtac0_sheet_states_volumes_coats_treatments_and_the_procedure() {
    let e = export("rtac0", None);
    let s = &e.sheet;
    // layer volume 13.5 -> 14.9 mm: hemisphere shell plus the 6 mm cylinder
    let (r0, r1, l) = (13.5f64, 14.9f64, 6.0);
    let v = (2.0 / 3.0 * PI * (r1.powi(3) - r0.powi(3)) + PI * (r1 * r1 - r0 * r0) * l) / 1000.0;
    let t = cast(&e, "translucent_gel");
    close(
        t["layer_volume_ml"].as_f64().unwrap(),
        v,
        1e-9,
        "layer volume",
    );
    assert!(t["cavity_volume_ml"].as_f64().unwrap() > v, "{t}");
    // Mold Star 30 is measured out in mL
    let ms = cast(&e, "silicone_mold:transparent_gel");
    let part_a = ms["components"][0]["volume_ml"].as_f64().unwrap();
    assert!(s.contains(&format!("  - Part A: {part_a:.2} mL (")), "{s}");
    // the black coat: its mix and amount
    let k = &t["coats"][0];
    assert_eq!(k["mix_ratio"], "100:3:500 by weight");
    assert!(
        s.contains(&format!(
            "mix 100:3:500 by weight, Thinner evaporating: Silicone oil {:.2} g",
            k["components"][0]["mass_g"].as_f64().unwrap()
        )),
        "{s}"
    );
    // primer on the tube (r = 10, down to the base plane 6 mm under the equator) before the
    // first layer only; release on each cavity (r = 13.5, then the coat's r = 15)
    let area = |r: f64| (2.0 * PI * r * r + 2.0 * PI * r * l) / 100.0;
    let first = cast(&e, "transparent_gel");
    let tr = arr(first, "treatments");
    assert_eq!(tr.len(), 2, "{first}");
    assert_eq!(tr[0]["material"], "pr_1200_rtv");
    // The area comes from a 1 µm polyline: each chord's band is short of its sphere zone by
    // s / r (s its sagitta), so the hemisphere's 2 pi r^2 by 2 pi r x 1 µm at most: 6.3e-4,
    // 8.5e-4 and 9.4e-4 cm^2 for r = 10, 13.5 and 15 (the cylinder is exact); measured 4.3e-4,
    // 6.0e-4 and 6.6e-4 cm^2 short. The primer amount follows (x 0.002 mL/cm^2: 1.3e-6 mL at
    // most, measured 8.6e-7).
    close(
        tr[0]["area_cm2"].as_f64().unwrap(),
        area(10.0),
        1e-3,
        "primer area",
    );
    close(
        tr[0]["amount_ml"].as_f64().unwrap(),
        area(10.0) * 0.002,
        1e-5,
        "primer amount",
    );
    assert_eq!(tr[1]["material"], "ease_release_200");
    close(
        tr[1]["area_cm2"].as_f64().unwrap(),
        area(13.5),
        1e-3,
        "release area",
    );
    let tr = arr(t, "treatments");
    assert_eq!(tr.len(), 1, "{t}");
    close(
        tr[0]["area_cm2"].as_f64().unwrap(),
        area(15.0),
        1e-3,
        "release area",
    );
    let release_ml = (area(13.5) + area(15.0)) * 0.005;
    assert!(
        s.contains(&format!(
            "| Mann Ease Release 200 (aerosol) | about {release_ml:.2} mL |"
        )),
        "{s}"
    );
    assert!(
        s.contains("| Dow PR-1200 RTV Prime Coat (clear) | about 0.02 mL |"),
        "{s}"
    );
    // screws by standard size and length
    let bought = arr(&e.manifest, "bought_items");
    assert!(
        bought
            .iter()
            .any(|b| b.as_str().unwrap().starts_with("2 joint screws M2 x 6 ")),
        "{bought:?}"
    );
    // the procedure in order
    assert_eq!(
        actions(&e),
        [
            A::Print,
            A::SeatMaster,
            A::FillMoldStar,
            A::DemoldSiliconeMold,
            A::SeatMaster,
            A::FillMoldStar,
            A::DemoldSiliconeMold,
            A::PrimeCore,
            A::MountCore,
            A::SprayRelease,
            A::Pour,
            A::Demold,
            A::MoveCore,
            A::SprayRelease,
            A::SprayCoat,
            A::Pour,
            A::Demold,
            A::Assemble,
            A::Assemble,
            A::Assemble,
            A::Pour,
            A::Assemble,
            A::Assemble,
        ]
    );
    // the filling gel (R-Tac0 Sec. III-B1, `fills: core`), poured into the assembled shell:
    // the core's inside (radius 9 mm: hemisphere on 6 + 3 mm of cylinder) up to its open end;
    // Solaris 1.02 g/cm3, 1:1 by weight, 20 % waste
    let gel = cast(&e, "filling_gel");
    let v_ml = (2.0 / 3.0 * PI * 9.0f64.powi(3) + PI * 81.0 * 9.0) / 1000.0;
    close(
        gel["cavity_volume_ml"].as_f64().unwrap(),
        v_ml,
        1e-9,
        "filling gel",
    );
    assert!(gel.get("layer_volume_ml").is_none(), "not a layer: {gel}");
    close(
        gel["total_mass_g"].as_f64().unwrap(),
        v_ml * 1.02 * 1.2,
        1e-9,
        "filling gel mass",
    );
    assert_eq!(gel["material"], "solaris");
    assert!(
        e.sheet.contains(&format!(
            "- pour volume: {v_ml:.2} mL (the space it fills in the assembled shell"
        )),
        "{}",
        e.sheet
    );
    let pour = arr(&e.manifest, "procedure")
        .iter()
        .rfind(|p| p["action"] == "pour")
        .unwrap()["text"]
        .as_str()
        .unwrap();
    assert!(
        pour.contains(&format!("{v_ml:.2} mL to fill"))
            && pour.contains("before the camera goes on"),
        "{pour}"
    );
    // the assembly order, with the screws at each step
    let steps: Vec<&str> = arr(&e.manifest, "procedure")
        .iter()
        .filter(|p| p["action"] == "assemble")
        .map(|p| p["text"].as_str().unwrap())
        .collect();
    assert_eq!(steps.len(), 5, "{steps:?}");
    for (step, words) in steps.iter().zip::<[&[&str]; 5]>([
        &["LED ring PCB", "down the light chamber of `shell_tube`"],
        &[
            "diffuser disc onto the top face of `shell_tube`",
            "10.0 mm above the PCB",
            "then glue `shell_collar`",
        ],
        &[
            "contact module",
            "into `shell_collar`",
            "rests on the diffuser's inner edge",
        ],
        &[
            "camera board onto the spigot of `shell_base`",
            "4 self-tapping screws M2 (1.6 mm pilots)",
        ],
        &[
            "`shell_base` under `shell_tube`",
            "the 2 joint screws M2 x 6",
        ],
    ]) {
        assert!(words.iter().all(|w| step.contains(w)), "{step}");
    }
    // the fill height: the master's height over its plinth face (its 2 mm locating pin stands
    // in the floor's socket) plus the 5 mm Mold Star wall over its top
    let master = arr(&e.manifest, "parts")
        .iter()
        .find(|p| p["name"] == "transparent_gel_master_pattern")
        .unwrap();
    let (lo, hi) = (
        master["bbox_mm"]["min"][2].as_f64().unwrap(),
        master["bbox_mm"]["max"][2].as_f64().unwrap(),
    );
    let fill = hi - lo - 2.0 + 5.0;
    assert!(
        s.contains(&format!(
            "up to {fill:.1} mm above the box floor: 5.0 mm over the master's top"
        )),
        "{fill}\n{s}"
    );
    assert!(s.contains("pole-down"), "{s}");
}

/// R-Tac0 with the direct strategy: the clamp bolts by size and length (4 per mold across
/// both halves: 2 x (cavity rim + plinth margin 5 + flange 8)), the sprue told from the vents,
/// the mold closed before the pour.
#[test]
fn rtac0_direct_sheet_names_the_clamp_bolts_and_the_sprue() {
    let e = export("rtac0", Some(MoldStrategy::Direct));
    let s = &e.sheet;
    let bought = arr(&e.manifest, "bought_items");
    for (layer, grip) in [
        ("transparent_gel", 2.0 * (13.5 + 13.0)),
        ("translucent_gel", 2.0 * (15.0 + 13.0)),
    ] {
        let want = format!(
            "4 clamp bolts M3 x 60 with nuts for the {layer} mold: 3.4 mm holes, {grip:.1} mm grip"
        );
        assert!(
            bought.iter().any(|b| b == &want),
            "{want} not in {bought:?}"
        );
    }
    assert!(
        s.contains("tighten the 4 clamp bolts (M3 x 60, with nuts)"),
        "{s}"
    );
    assert!(
        s.contains("pour it slowly through the sprue (the 3.0 mm hole ")
            && s.contains(
                "from the axis, the one nearest the axis; the 2 vents are the 1.2 mm holes"
            ),
        "{s}"
    );
    assert_eq!(
        actions(&e),
        [
            A::Print,
            A::PrimeCore,
            A::MountCore,
            A::SprayRelease,
            A::CloseMold,
            A::Pour,
            A::Demold,
            A::MoveCore,
            A::SprayRelease,
            A::SprayCoat,
            A::CloseMold,
            A::Pour,
            A::Demold,
            A::Assemble,
            A::Assemble,
            A::Assemble,
            A::Pour,
            A::Assemble,
            A::Assemble,
        ]
    );
    assert!(section(s, "Checking the prints")
        .join("\n")
        .contains("registration keys"));
}

/// ShadowTac: the two-piece mold's 20 bolts by size and length, no registration keys in the
/// checks (a boss and pocket register its pieces), release then pour into the reservoir, then
/// the reflective layer brushed on.
#[test]
fn shadowtac_sheet_names_its_bolts_and_pours_into_the_reservoir() {
    let e = export("shadowtac", None);
    let bought = arr(&e.manifest, "bought_items");
    assert!(
        bought.iter().any(|b| b
            .as_str()
            .unwrap()
            .starts_with("20 clamp bolts M3 x 30 with nuts for the skin mold")),
        "{bought:?}"
    );
    assert!(!section(&e.sheet, "Checking the prints")
        .join("\n")
        .contains("registration keys"));
    assert_eq!(
        actions(&e),
        [
            A::Print,
            A::SprayRelease,
            A::CloseMold,
            A::Pour,
            A::Demold,
            A::BrushCoat,
            A::Assemble,
            A::Assemble,
            A::Assemble,
            A::Assemble,
            A::Assemble
        ]
    );
    // Sec. IV: the skin onto its plate, the LEDs into the casing before the plate closes it,
    // the plate onto the casing, the camera from below, the casing onto the gripper base
    let steps: Vec<String> = arr(&e.manifest, "procedure")
        .iter()
        .filter(|s| s["action"] == "assemble")
        .map(|s| s["text"].as_str().unwrap().to_string())
        .collect();
    for (i, begins) in [
        "Assemble: Glue the skin's base to the backing plate with Smooth-On Sil-Poxy",
        "Assemble: Cut 3 single-LED segments from the strip",
        "Assemble: Glue the backing plate, the skin up, onto the top face of `casing` with cyanoacrylate",
        "Assemble: Set the camera board (Basler dart daA1920-160uc",
        "Assemble: Set `casing` into the socket of `gripper_base`",
    ]
    .into_iter()
    .enumerate()
    {
        assert!(steps[i].starts_with(begins), "{i}: {}", steps[i]);
    }
    assert!(
        steps[1].contains("at 90, 210, 330 deg from +x"),
        "{}",
        steps[1]
    );
    // the reflective layer (Sec. IV-A), brushed on after demolding, before the plate
    assert!(
        e.sheet.contains(
            "Step 1: brush a thin reflective layer onto `skin`: Smooth-On Psycho Paint, aluminium powder, Silc Pig white"
        ) && e.sheet.contains("silicone solvent"),
        "{}",
        e.sheet
    );
    assert!(bought.iter().any(|b| b
        .as_str()
        .unwrap()
        .starts_with("Reflective layer brushed onto `skin`: Smooth-On Psycho Paint")));
}

/// UVDtact: the black gel (0.56 g) cannot be weighed by hand; the sheet gives the smallest
/// batch whose every component weighs at least 1 g, and what is left over. The layers are cast
/// inside out onto the first inner silicone mold, released once.
#[test]
fn uvdtact_sheet_gives_a_weighable_batch_and_casts_inside_out() {
    let e = export("uvdtact", None);
    let black = cast(&e, "black_gel");
    let total = black["total_mass_g"].as_f64().unwrap();
    assert!(total < 1.0, "{black}");
    let b = &black["min_batch"];
    let masses: Vec<f64> = arr(b, "components")
        .iter()
        .map(|c| c["mass_g"].as_f64().unwrap())
        .collect();
    close(
        masses.iter().copied().fold(f64::INFINITY, f64::min),
        1.0,
        1e-9,
        "smallest",
    );
    close(masses[0] / masses[2], 5.0, 1e-9, "ratio 5:5:1");
    let batch = b["total_mass_g"].as_f64().unwrap();
    close(
        b["leftover_g"].as_f64().unwrap(),
        batch - total,
        1e-9,
        "leftover",
    );
    assert!(
        e.sheet.contains(&format!(
            "- too little to weigh by hand: mix at least Ecoflex 00-30 Part A 5.0 g + Ecoflex 00-30 Part B 5.0 g + Silc Pig black 1.0 g = {batch:.1} g"
        )) && e.sheet.contains(&format!("{:.1} g is left over", batch - total)),
        "{}",
        e.sheet
    );
    let mold_star = [A::SeatMaster, A::FillMoldStar, A::DemoldSiliconeMold];
    let mut want = vec![A::Print];
    for _ in 0..6 {
        want.extend(mold_star);
    }
    want.extend([A::SprayRelease, A::SprayRelease, A::Pour, A::Demold]);
    for _ in 0..2 {
        want.extend([A::MoveCore, A::SprayRelease, A::Pour, A::Demold]);
    }
    // the core bonded into the skin, then the fingertip's base: camera into its holder and
    // onto the base, PCB and ring, the shell into its holder, the holder bolted to the base
    want.extend([A::Assemble; 5]);
    assert_eq!(actions(&e), want);
    let steps: Vec<&str> = arr(&e.manifest, "procedure")
        .iter()
        .filter(|s| s["action"] == "assemble")
        .map(|s| s["text"].as_str().unwrap())
        .collect();
    for (i, begins) in [
        "Assemble: Bond the core",
        "Assemble: Glue the camera (COMedia muC103P",
        "Assemble: Lead the lighting PCB's wires",
        "Assemble: Glue the acrylic shell's foot",
        "Assemble: Set `shell_holder` on `sensor_base` and fasten them with 3 bolts",
    ]
    .into_iter()
    .enumerate()
    {
        assert!(steps[i].starts_with(begins), "{i}: {}", steps[i]);
    }
}

/// The dual-modal TacTip is printed; its one pour is the filling gel, poured into the tip
/// among the assembly steps: LED ring and camera into the body, the gel and the window into
/// the tip, the body locked into the robot's mount, the tip twisted onto the body's bayonet.
#[test]
fn tactip_sheet_pours_the_gel_between_the_assembly_steps() {
    let e = export("tactip_dualmodal", None);
    let casts = arr(&e.manifest, "casts");
    assert_eq!(casts.len(), 1);
    assert_eq!(casts[0]["cast"], "filling_gel");
    assert_eq!(
        actions(&e),
        [
            A::Print,
            A::Assemble,
            A::Assemble,
            A::Pour,
            A::Assemble,
            A::Assemble
        ]
    );
    for text in [
        "Step 1: stand the tip pole-down",
        "lay the lens window into its seat in `tip_fitting`",
        "the 3 lugs of `tip_fitting` down the 3 entry grooves",
        "turn it 30 deg counter-clockwise",
        "Bolt `robot_mount` to the tool flange of the ABB IRB 120",
        "turn `shaft_body` 30 deg clockwise",
    ] {
        assert!(e.sheet.contains(text), "{text}: {}", e.sheet);
    }
}

/// `assembly.3mf` holds every member of the assembled sensor as one named object in the sensor
/// frame (no build-item translation), each as the manifest describes it (volume, box), the
/// bought parts as envelopes: read back with the `threemf` crate.
#[test]
fn rtac0_assembly_3mf_holds_every_member_in_the_sensor_frame() {
    let (e, [bytes, _]) = export_as("rtac0", None, true);
    let bytes = bytes.unwrap();
    let a = &e.manifest["assembly_3mf"];
    assert_eq!(a["file"], "assembly.3mf");
    use sha2::Digest;
    let sha: String = sha2::Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(a["sha256"], sha.as_str());
    let models = threemf::read(std::io::Cursor::new(&bytes)).unwrap();
    let model = &models[0];
    let members = arr(a, "members");
    let names: Vec<&str> = model
        .resources
        .object
        .iter()
        .map(|o| o.name.as_deref().unwrap())
        .collect();
    let listed: Vec<&str> = members
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, listed);
    for name in [
        "shell_collar",
        "shell_tube",
        "shell_base",
        "transparent_gel",
        "core_envelope",
        "camera_board_envelope",
    ] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
    for (o, m) in model.resources.object.iter().zip(members) {
        let mesh = o.mesh.as_ref().unwrap();
        let v = crate::export_kit::vertices_of(mesh);
        let vol = crate::export_kit::signed_volume(
            &v,
            mesh.triangles.triangle.iter().map(|t| [t.v1, t.v2, t.v3]),
        );
        let want = m["volume_mm3"].as_f64().unwrap();
        close(vol, want, 1e-6 * want, m["name"].as_str().unwrap());
        let zmax = v.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
        close(zmax, m["bbox_mm"]["max"][2].as_f64().unwrap(), 1e-9, "box");
        let item = model
            .build
            .item
            .iter()
            .find(|i| i.objectid == o.id)
            .unwrap();
        if let Some(t) = item.transform {
            assert_eq!(
                t,
                [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
            );
        }
    }
    // the shell's top face (the collar's) is the base plane, z = -6 mm, in the sensor frame;
    // the tube's top face is 5 mm under it (3 mm collar, 2 mm diffuser disc)
    for (name, top) in [("shell_collar", -6.0), ("shell_tube", -11.0)] {
        let p = members.iter().find(|m| m["name"] == name).unwrap();
        close(p["bbox_mm"]["max"][2].as_f64().unwrap(), top, 1e-6, name);
    }
    assert!(members
        .iter()
        .filter(|m| m["kind"] == "bought")
        .all(|m| m["name"].as_str().unwrap().ends_with("_envelope")));
}

/// `section.png` cuts the assembled sensor through its axis: each member's colour covers its
/// section's area (R-Tac0's transparent gel: two quarter annuli of radii 10 and 13.5 mm on
/// 3.5 x 6 mm rectangles; the tube's envelope likewise with radii 9 and 10 mm, 9 mm down; the
/// camera board 15 x 3 mm; the diffuser disc, two 5.2 x 2 mm rectangles), both in the legend (from the outline) and in the pixels.
#[test]
fn rtac0_section_view_shows_each_member_with_its_section_area() {
    let (e, [_, png_bytes]) = export_as("rtac0", None, false);
    let png_bytes = png_bytes.unwrap();
    let v = &e.manifest["section_view"];
    assert_eq!(v["file"], "section.png");
    let px = v["px_per_mm"].as_f64().unwrap();
    let quarter = |ri: f64, ro: f64, below: f64| {
        2.0 * (PI / 4.0 * (ro * ro - ri * ri) + (ro - ri) * (6.0 + below))
    };
    let decoder = png::Decoder::new(std::io::Cursor::new(&png_bytes));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.width as u64, v["width_px"].as_u64().unwrap());
    let rgb = &buf[..info.buffer_size()];
    let count = |hex: &str| {
        let c: Vec<u8> = (0..3)
            .map(|i| u8::from_str_radix(&hex[1 + 2 * i..3 + 2 * i], 16).unwrap())
            .collect();
        rgb.chunks_exact(3).filter(|p| *p == &c[..]).count() as f64
    };
    for (name, area) in [
        ("transparent_gel", quarter(10.0, 13.5, 0.0)),
        ("core_envelope", quarter(9.0, 10.0, 3.0)),
        ("camera_board_envelope", 15.0 * 3.0),
        ("diffuser_envelope", 2.0 * (15.0 - 9.8) * 2.0),
    ] {
        let l = arr(v, "legend").iter().find(|l| l["name"] == name).unwrap();
        // measured -0.076 % (gel) and -0.042 % (core), the rectangles exact: the profiles are
        // drawn at half the 0.05 mm tolerance, and a quarter arc's chords (sagitta s) take
        // (pi / 3) r s, net (2 pi / 3)(r_o - r_i) s for the two quarter annuli: 0.11 % of either
        // at s = 0.025 mm
        close(l["area_mm2"].as_f64().unwrap(), area, 0.002 * area, name);
        let pixels = count(l["colour"].as_str().unwrap()) / (px * px);
        // measured -0.092 % (gel) and -0.053 % (core), the rectangles exact: each row counts the
        // columns whose centres lie inside, up to half a pixel (0.025 mm at 20 px/mm) off at
        // each crossing; off by as much all down a vertical edge, the core's four (9 mm, 180
        // rows each) would take 0.9 mm^2, 1.9 %
        close(pixels, area, 0.03 * area, name);
    }
    assert!(e
        .sheet
        .contains("![The assembled sensor cut through its axis](section.png)"));
}
