use fabkit_designs::materials::*;

#[test]
fn embedded_table_parses_and_has_the_required_entries() {
    let t = MaterialsTable::embedded().unwrap();
    let s = t.get("sylgard_184").unwrap();
    assert_eq!(s.density_g_per_cm3, 1.03);
    assert_eq!(s.mix.as_ref().unwrap().ratio, vec![10.0, 1.0]);
    assert_eq!(t.get("ecoflex_00_30").unwrap().density_g_per_cm3, 1.07);
    let ms = t.get("mold_star_30").unwrap();
    assert_eq!(ms.density_g_per_cm3, 1.18);
    assert_eq!(ms.mix.as_ref().unwrap().by, MixBasis::Volume);
    for k in [
        "ecoflex_00_50",
        "ecoflex_00_10",
        "solaris",
        "solaris_thinner_40",
        "ptg_501_black",
    ] {
        assert!(t.get(k).is_some(), "{k}");
    }
}

#[test]
fn sylgard_pour_splits_ten_to_one() {
    let t = MaterialsTable::embedded().unwrap();
    let m = t.get("sylgard_184").unwrap();
    // 10 mL with 20 % waste: 10 x 1.03 x 1.2 = 12.36 g, A = 11.236..., B = 1.1236...
    let r = pour(1, "gel", "sylgard_184", m, vec![], 10_000.0, 0.2).unwrap();
    assert!((r.total_mass_g - 12.36).abs() < 1e-9);
    assert!((r.components[0].mass_g - 12.36 * 10.0 / 11.0).abs() < 1e-9);
    assert!((r.components[1].mass_g - 12.36 / 11.0).abs() < 1e-9);
    assert_eq!(r.mix_ratio, "10:1 by weight");
}

#[test]
fn uncastable_material_is_an_error() {
    let t = MaterialsTable::embedded().unwrap();
    let m = t.get("pla_black").unwrap();
    assert!(pour(1, "x", "pla_black", m, vec![], 1.0, 0.1).is_err());
}

/// A mix by volume (Mold Star 30, 1A:1B) gives each component in millilitres, the pour plus
/// the waste allowance split by the ratio, and the grams at the mixed density; a mix by weight
/// gives grams only. The material's product name goes with every pour.
#[test]
fn mixes_by_volume_are_measured_in_millilitres() {
    use fabkit_designs::materials::{pour, MaterialsTable};
    let t = MaterialsTable::embedded().unwrap();
    let ms = &t.materials["mold_star_30"];
    let r = pour(
        1,
        "silicone_mold:x",
        "mold_star_30",
        ms,
        vec![],
        10_000.0,
        0.2,
    )
    .unwrap();
    assert_eq!(r.material_name, "Smooth-On Mold Star 30");
    let ml: Vec<f64> = r.components.iter().map(|c| c.volume_ml.unwrap()).collect();
    assert!(
        (ml[0] - 6.0).abs() < 1e-12 && (ml[1] - 6.0).abs() < 1e-12,
        "{ml:?}"
    );
    for c in &r.components {
        assert!((c.mass_g - c.volume_ml.unwrap() * ms.density_g_per_cm3).abs() < 1e-9);
    }
    let s = pour(
        1,
        "x",
        "sylgard_184",
        &t.materials["sylgard_184"],
        vec![],
        10_000.0,
        0.2,
    )
    .unwrap();
    assert!(s.components.iter().all(|c| c.volume_ml.is_none()));
    assert!(s.layer_volume_ml.is_none());
}

/// UVDtact's black gel (0.56 g, of which 0.05 g pigment) cannot be weighed by hand: the cast
/// gives the smallest batch whose every component is at least 1 g, in the mix ratio, and what
/// is left over; a pour whose amounts can be weighed gives none.
#[test]
fn a_pour_too_small_to_weigh_gives_the_smallest_weighable_batch() {
    use fabkit_designs::kit::MIN_WEIGHABLE_G;
    let d = fabkit_designs::library::load("uvdtact").unwrap();
    let kit =
        fabkit_designs::build_kit(&d, fabkit_designs::ChordTolerance::new(0.05).unwrap()).unwrap();
    let black = kit
        .casts
        .iter()
        .find(|c| c.material == "ecoflex_00_30_silc_pig_black")
        .unwrap();
    assert!(black.total_mass_g < 1.0, "{}", black.total_mass_g);
    let b = black.min_batch.as_ref().unwrap();
    let smallest = b
        .components
        .iter()
        .map(|c| c.mass_g)
        .fold(f64::INFINITY, f64::min);
    assert!((smallest - MIN_WEIGHABLE_G).abs() < 1e-12);
    let k = b.components[0].mass_g / black.components[0].mass_g;
    for (x, y) in b.components.iter().zip(&black.components) {
        assert!((x.mass_g - k * y.mass_g).abs() < 1e-9, "{}", x.name);
    }
    assert!((b.total_mass_g - b.components.iter().map(|c| c.mass_g).sum::<f64>()).abs() < 1e-9);
    assert!((b.leftover_g - (b.total_mass_g - black.total_mass_g)).abs() < 1e-9);
    // 11 g of the 5:5:1 mix: 1 g of pigment
    assert!((b.total_mass_g - 11.0).abs() < 1e-9, "{}", b.total_mass_g);
    // 10 mL of Sylgard 184 (10:1, 20 % waste): the curing agent is 1.12 g, weighable
    let t = fabkit_designs::materials::MaterialsTable::embedded().unwrap();
    let p = fabkit_designs::materials::pour(
        1,
        "x",
        "sylgard_184",
        &t.materials["sylgard_184"],
        vec![],
        10_000.0,
        0.2,
    )
    .unwrap();
    assert!(p.components[1].mass_g > MIN_WEIGHABLE_G && p.min_batch.is_none());
}

/// R-Tac0's black coating: the mix (100:3:500 by weight, the thinner evaporating) for the coat
/// itself is the coat's volume (0.1 mm from R14.9 to R15, analytic) of oil and catalyst plus
/// the thinner in ratio, with the smallest batch weighable by hand; an `evaporates` entry that
/// names no component, or all of them, is refused by path.
#[test]
fn the_black_coating_has_its_mix_and_amount() {
    use std::f64::consts::PI;
    let d = fabkit_designs::library::load("rtac0").unwrap();
    let kit =
        fabkit_designs::build_kit(&d, fabkit_designs::ChordTolerance::new(0.05).unwrap()).unwrap();
    let coats: Vec<_> = kit.casts.iter().flat_map(|c| c.coats.iter()).collect();
    assert_eq!(coats.len(), 1);
    let c = coats[0];
    assert_eq!(c.layer, "black_coating");
    let v = 2.0 / 3.0 * PI * (15f64.powi(3) - 14.9f64.powi(3))
        + PI * (15f64.powi(2) - 14.9f64.powi(2)) * 6.0;
    assert!(
        (c.coat_volume_ml * 1000.0 - v).abs() < 1e-9,
        "{}",
        c.coat_volume_ml
    );
    let m: Vec<f64> = c.components.iter().map(|x| x.mass_g).collect();
    // density 1.0 g/cm3 (materials table): the oil and the catalyst are the coat's mass
    assert!((m[0] + m[1] - v / 1000.0).abs() < 1e-12, "{m:?}");
    assert!((m[0] / m[1] - 100.0 / 3.0).abs() < 1e-9 && (m[2] / m[0] - 5.0).abs() < 1e-9);
    let b = c.min_batch.as_ref().unwrap();
    assert!((b.components[1].mass_g - 1.0).abs() < 1e-12);
    use fabkit_designs::materials::MaterialsTable;
    let text = |evaporates: &str| {
        format!(
            "materials:\n  c:\n    name: C\n    kind: coating\n    density_g_per_cm3: 1.0\n    mix: {{components: [A, B], ratio: [1, 2], by: weight, evaporates: {evaporates}}}\n    source: test\n"
        )
    };
    assert!(MaterialsTable::from_yaml(&text("[B]"), "m.yaml").is_ok());
    let e = MaterialsTable::from_yaml(&text("[Water]"), "m.yaml").unwrap_err();
    assert!(
        e.starts_with(
            "m.yaml: materials.c.mix.evaporates[0] = \"Water\": must name one of the components"
        ),
        "{e}"
    );
    let e = MaterialsTable::from_yaml(&text("[A, B]"), "m.yaml").unwrap_err();
    assert!(
        e.contains("materials.c.mix.evaporates: at least one component must stay"),
        "{e}"
    );
}

/// Screws are named by standard size and length: a 2.2 mm clearance hole takes M2, a 3.4 mm one
/// M3; the joint screws get the longest standard length within clamp + pilot (R-Tac0's round
/// tube: M2 x 6; the square halves: M2 x 10); a 1.6 mm pilot takes an M2 self-tapping screw.
#[test]
fn screws_are_named_by_standard_size_and_length() {
    use fabkit_designs::parts::fasteners::{metric_from_clearance, metric_from_pilot, screw_name};
    assert_eq!(metric_from_clearance(2.2), Some(2.0));
    assert_eq!(metric_from_clearance(3.4), Some(3.0));
    assert_eq!(metric_from_clearance(3.5), Some(3.0));
    assert_eq!(metric_from_clearance(1.0), None);
    assert_eq!(metric_from_pilot(1.6), Some(2.0));
    assert_eq!(metric_from_pilot(2.5), Some(3.0));
    assert_eq!(screw_name(2.2, 7.0).as_deref(), Some("M2 x 6"));
    assert_eq!(screw_name(3.4, 25.0).as_deref(), Some("M3 x 25"));
    assert_eq!(screw_name(2.2, 2.0), None);
    let tol = fabkit_designs::ChordTolerance::new(0.05).unwrap();
    let d = fabkit_designs::library::load("rtac0").unwrap();
    for (design, want) in [
        (d.clone(), "2 joint screws M2 x 6 (pan head)"),
        (
            d.with_preset("square_split").unwrap(),
            "2 joint screws M2 x 10 across",
        ),
    ] {
        let kit = fabkit_designs::build_kit(&design, tol).unwrap();
        assert!(
            kit.bought_items.iter().any(|b| b.starts_with(want)),
            "{:?}",
            kit.bought_items
        );
        assert!(
            kit.bought_items
                .iter()
                .any(|b| b.contains("4 self-tapping screws M2 (1.6 mm pilots")),
            "{:?}",
            kit.bought_items
        );
    }
}

/// Primer and release agents carry the amount one coat uses per cm²; the table refuses one
/// without it, a non-positive or film-thick amount, and the amount on any other kind.
#[test]
fn treatments_carry_a_checked_amount_per_area() {
    let t = MaterialsTable::embedded().unwrap();
    for (key, kind) in [
        ("pr_1200_rtv", MaterialKind::Primer),
        ("ease_release_200", MaterialKind::Release),
    ] {
        let m = t.get(key).unwrap();
        assert_eq!(m.kind, kind, "{key}");
        assert!(m.applied_ml_per_cm2.unwrap() > 0.0, "{key}");
    }
    let text = |kind: &str, amount: &str| {
        format!(
            "materials:\n  r:\n    name: R\n    kind: {kind}\n    density_g_per_cm3: 0.7\n{amount}    source: test\n"
        )
    };
    assert!(MaterialsTable::from_yaml(
        &text("release", "    applied_ml_per_cm2: 0.005\n"),
        "m.yaml"
    )
    .is_ok());
    for (kind, amount, want) in [
        (
            "release",
            "",
            "m.yaml: materials.r.applied_ml_per_cm2 is required for a Release material",
        ),
        (
            "primer",
            "    applied_ml_per_cm2: 0\n",
            "m.yaml: materials.r.applied_ml_per_cm2 = 0: must be above 0 and at most 0.1",
        ),
        (
            "release",
            "    applied_ml_per_cm2: 0.5\n",
            "m.yaml: materials.r.applied_ml_per_cm2 = 0.5: must be above 0 and at most 0.1",
        ),
        (
            "print",
            "    applied_ml_per_cm2: 0.005\n",
            "m.yaml: materials.r.applied_ml_per_cm2 = 0.005: only primer and release materials take it",
        ),
    ] {
        let e = MaterialsTable::from_yaml(&text(kind, amount), "m.yaml").unwrap_err();
        assert!(e.starts_with(want), "{kind} {amount:?}: {e}");
    }
}

/// A clamp bolt is the shortest standard length that passes the grip and an ISO 4032 nut
/// (0.8 d) by 1 mm: M3 through 53 mm needs 56.4 mm, so M3 x 60; through 25.4 mm, M3 x 30.
/// R-Tac0's direct mold halves take 4 such bolts each, across both halves (grip 2 x (plinth
/// radius + flange width)).
#[test]
fn clamp_bolts_are_named_by_standard_size_and_length() {
    use fabkit_designs::parts::fasteners::bolt_name;
    assert_eq!(bolt_name(3.4, 53.0).as_deref(), Some("M3 x 60"));
    assert_eq!(bolt_name(3.4, 25.4).as_deref(), Some("M3 x 30"));
    assert_eq!(bolt_name(3.4, 26.6).as_deref(), Some("M3 x 30"));
    assert_eq!(bolt_name(3.4, 26.61).as_deref(), Some("M3 x 35"));
    assert_eq!(bolt_name(1.0, 10.0), None);
    assert_eq!(bolt_name(3.4, 200.0), None);
    let tol = fabkit_designs::ChordTolerance::new(0.05).unwrap();
    let mut d = fabkit_designs::library::load("rtac0").unwrap();
    d.mold.strategy = fabkit_designs::schema::MoldStrategy::Direct;
    let kit = fabkit_designs::build_kit(&d, tol).unwrap();
    // transparent_gel: cavity rim 13.5 mm + plinth margin 5 + flange 8 = 26.5 mm half width
    let want =
        "4 clamp bolts M3 x 60 with nuts for the transparent_gel mold: 3.4 mm holes, 53.0 mm grip";
    assert!(
        kit.bought_items.iter().any(|b| b == want),
        "{:?}",
        kit.bought_items
    );
}

/// Every clear material the camera looks through in a library sensor has a refractive index
/// with a source; values no maker publishes say ASSUMPTION. A bad index or a missing source is
/// an error naming its path, value and rule.
#[test]
fn clear_materials_carry_a_sourced_refractive_index() {
    let t = MaterialsTable::embedded().unwrap();
    // the clear silicones, the R-Tac0 core's glass and ShadowTac's plate
    for (k, n) in [
        ("sylgard_184", 1.41),
        ("solaris", 1.41),
        ("ecoflex_00_30", 1.41),
        ("borosilicate_glass", 1.473),
        ("pmma", 1.491),
    ] {
        let r = t.get(k).unwrap().refractive_index.as_ref().unwrap();
        assert_eq!(r.n, n, "{k}");
        assert!(!r.source.trim().is_empty(), "{k}");
    }
    assert!(t
        .get("solaris")
        .unwrap()
        .refractive_index
        .as_ref()
        .unwrap()
        .source
        .starts_with("ASSUMPTION:"));
    assert!(t.get("pla_black").unwrap().refractive_index.is_none());
    let base = "materials:\n  gel:\n    name: g\n    kind: bought\n    density_g_per_cm3: 1.0\n    source: s\n";
    let with = |r: &str| format!("{base}    refractive_index: {r}\n");
    assert!(MaterialsTable::from_yaml(&with("{n: 1.41, source: x}"), "m.yaml").is_ok());
    let e = MaterialsTable::from_yaml(&with("{n: 0.9, source: x}"), "m.yaml").unwrap_err();
    assert!(
        e.contains("materials.gel.refractive_index.n = 0.9") && e.contains("from 1 to below 3"),
        "{e}"
    );
    let e = MaterialsTable::from_yaml(&with("{n: 1.4, source: ' '}"), "m.yaml").unwrap_err();
    assert!(e.contains("materials.gel.refractive_index.source"), "{e}");
}
