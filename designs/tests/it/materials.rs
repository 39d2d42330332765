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
