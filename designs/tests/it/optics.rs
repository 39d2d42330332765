//! The `optics` section (designs/src/optics.rs): the lights each library sensor gets from the
//! part that carries its LEDs, a design's own lights in their place, and each rule refused by
//! its path.

use crate::common::{assert_each_rule_names_its_path, RuleCase};
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::optics::{of_design, resolve, Light, OpticsParams};
use fabkit_designs::parts::Stack;
use fabkit_designs::{library, stack, ChordTolerance, Design};

fn resolved(d: &Design) -> fabkit_designs::optics::ResolvedOptics {
    let s = stack::validate(
        d,
        &MaterialsTable::embedded().unwrap(),
        ChordTolerance::new(0.01).unwrap(),
    )
    .unwrap();
    resolve(d, &s).unwrap()
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// R-Tac0: eight white LEDs on the ring PCB's top face, 15 mm under the skin's base plane
/// (z = -6 - 1 (core below it) - 2 (diffuser) - 10 (gap) - ... = -21 mm), on the PCB's
/// mid-width circle, (23 + 15) / 4 = 9.5 mm, 45 deg apart from +x, facing the skin.
#[test]
fn rtac0_is_lit_by_its_led_ring_under_the_diffuser() {
    let o = resolved(&library::load("rtac0").unwrap());
    assert_eq!(o.lights.len(), 8);
    assert!(o.light_sources.iter().all(|s| s == "housing"));
    for (k, l) in o.lights.iter().enumerate() {
        let a = (45.0 * k as f64).to_radians();
        let [x, y, z] = l.position_mm;
        assert!(near(x, 9.5 * a.cos()) && near(y, 9.5 * a.sin()), "{l:?}");
        assert!(near(z, -21.0), "{l:?}");
        assert_eq!(l.direction, [0.0, 0.0, 1.0]);
        assert_eq!(l.colour_rgb, [1.0, 1.0, 1.0]);
    }
}

/// ShadowTac: red, green and blue LEDs at 90, 210 and 330 deg on the light chamber's wall
/// (15.5 mm from the axis), half-way down their 7 mm segments from the casing's top under the
/// 3 mm plate (the skin's base plane at z = 14.142: z = 11.142 - 3.5), each facing the axis.
#[test]
fn shadowtac_is_lit_by_three_coloured_leds_facing_the_axis() {
    let o = resolved(&library::load("shadowtac").unwrap());
    let colours: Vec<[f64; 3]> = o.lights.iter().map(|l| l.colour_rgb).collect();
    assert_eq!(colours, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    for (l, az) in o.lights.iter().zip([90.0f64, 210.0, 330.0]) {
        let a = az.to_radians();
        let [x, y, z] = l.position_mm;
        assert!(near(x, 15.5 * a.cos()) && near(y, 15.5 * a.sin()), "{l:?}");
        assert!((z - (11.142 - 3.5)).abs() < 1e-3, "{l:?}");
        let d = l.direction;
        assert!(near(d[0], -a.cos()) && near(d[1], -a.sin()) && d[2] == 0.0);
    }
}

/// The TacTip's six LEDs sit under the window, the dual-modal fingertip's four white and four
/// UV LEDs alternate from +x; a design's own `optics.lights` replace the families' lights.
#[test]
fn the_other_sensors_get_their_leds_and_given_lights_replace_them() {
    let tactip = resolved(&library::load("tactip_dualmodal").unwrap());
    assert_eq!(tactip.lights.len(), 6);
    assert!(tactip.light_sources.iter().all(|s| s == "shaft_body"));
    let uvd = resolved(&library::load("uvdtact").unwrap());
    assert_eq!(uvd.lights.len(), 8);
    let white: Vec<bool> = uvd
        .lights
        .iter()
        .map(|l| l.colour_rgb == [1.0, 1.0, 1.0])
        .collect();
    assert_eq!(white, [true, false, true, false, true, false, true, false]);

    let mut d = library::load("rtac0").unwrap();
    let own = Light {
        position_mm: [0.0, 0.0, -20.0],
        direction: [0.0, 0.0, 2.0],
        cone_half_angle_deg: 60.0,
        colour_rgb: [1.0, 0.5, 0.0],
        intensity: 50.0,
    };
    d.optics = Some(OpticsParams {
        lights: Some(vec![own.clone()]),
        ..OpticsParams::default()
    });
    let o = resolved(&d);
    assert_eq!(o.lights, vec![own]);
    assert_eq!(o.light_sources, ["optics.lights[0]"]);
}

/// A flat skin carries no lights: rendering it needs `optics.lights`, said by that path
/// (the library's flat skin gives four; without them it is refused).
#[test]
fn a_design_without_lights_must_give_them() {
    let mut d = library::load("soter_channels").unwrap();
    let given = of_design(&d, ChordTolerance::new(0.01).unwrap()).unwrap();
    assert_eq!(given.lights.len(), 4);
    assert_eq!(given.light_sources[3], "optics.lights[3]");
    d.optics.as_mut().unwrap().lights = None;
    let e = resolve(
        &d,
        &Stack {
            core: None,
            layers: Vec::new(),
        },
    )
    .unwrap_err();
    assert_eq!(e.len(), 1);
    assert_eq!(e[0].path, "optics.lights");
}

fn rtac0_with_optics() -> Design {
    let mut d = library::load("rtac0").unwrap();
    d.optics = Some(OpticsParams {
        lights: Some(vec![Light {
            position_mm: [0.0, 0.0, -20.0],
            direction: [0.0, 0.0, 1.0],
            cone_half_angle_deg: 60.0,
            colour_rgb: [1.0, 1.0, 1.0],
            intensity: 50.0,
        }]),
        ..OpticsParams::default()
    });
    d
}

fn optics(d: &mut Design) -> &mut OpticsParams {
    d.optics.as_mut().unwrap()
}

fn light(d: &mut Design) -> &mut Light {
    &mut optics(d).lights.as_mut().unwrap()[0]
}

/// One bad value per rule, each refused by its path (with nothing built).
#[test]
fn each_optics_rule_names_its_path() {
    let cases: &[RuleCase] = &[
        ("optics.lights", |d| optics(d).lights = Some(Vec::new())),
        // issue 95: 20,000 lights passed and would take hours to render
        ("optics.lights", |d| {
            let one = light(d).clone();
            optics(d).lights = Some(vec![one; fabkit_designs::optics::MAX_LIGHTS + 1])
        }),
        ("optics.lights[0].direction", |d| {
            light(d).direction = [0.0, 0.0, 0.0]
        }),
        ("optics.lights[0].cone_half_angle_deg", |d| {
            light(d).cone_half_angle_deg = 95.0
        }),
        ("optics.lights[0].colour_rgb", |d| {
            light(d).colour_rgb = [0.0, 0.0, 0.0]
        }),
        ("optics.lights[0].colour_rgb[1]", |d| {
            light(d).colour_rgb = [1.0, 1.5, 1.0]
        }),
        ("optics.lights[0].intensity", |d| light(d).intensity = 0.0),
        ("optics.surface.albedo_rgb[2]", |d| {
            optics(d).surface.albedo_rgb = [0.5, 0.5, 1.2]
        }),
        ("optics.surface.specular", |d| {
            optics(d).surface.specular = 1.5
        }),
        ("optics.surface.roughness", |d| {
            optics(d).surface.roughness = 0.0
        }),
        ("optics.surface.darkness_per_mm", |d| {
            optics(d).surface.darkness_per_mm = Some(0.0)
        }),
        ("optics.surface.darkness_per_mm", |d| {
            optics(d).surface.darkness_per_mm = Some(f64::NAN)
        }),
        ("optics.marker_albedo_rgb[0]", |d| {
            optics(d).marker_albedo_rgb = [2.0, 0.9, 0.9]
        }),
        ("optics.camera.gain", |d| optics(d).camera.gain = Some(0.0)),
        ("optics.camera.vignetting", |d| {
            optics(d).camera.vignetting = 1.0
        }),
        ("optics.camera.full_well_electrons", |d| {
            optics(d).camera.full_well_electrons = 0.5
        }),
        ("optics.camera.bit_depth", |d| {
            optics(d).camera.bit_depth = 12
        }),
    ];
    assert_each_rule_names_its_path(rtac0_with_optics, cases);
}

/// The section in YAML: lights below the base plane (negative z) are accepted, an unknown key
/// is refused at its line.
#[test]
fn the_section_reads_from_yaml_with_signed_positions() {
    let text = library::yaml("rtac0").unwrap();
    // the lights joined to R-Tac0's own optics section (its skin's darkness mapping)
    let with = |extra: &str| {
        text.replacen("\noptics:\n", &format!("\noptics:\n  lights:\n    - position_mm: [0, 0, -20]\n      direction: [0, 0, 1]\n      cone_half_angle_deg: 60\n      colour_rgb: [1, 1, 1]\n      intensity: 50\n{extra}"), 1)
    };
    let d = Design::from_yaml(&with(""), "rtac0.yaml").unwrap();
    assert_eq!(resolved(&d).lights[0].position_mm, [0.0, 0.0, -20.0]);
    assert_eq!(resolved(&d).surface.darkness_per_mm, Some(0.22));
    let e = Design::from_yaml(&with("      colour: red\n"), "rtac0.yaml").unwrap_err();
    assert!(e.to_string().contains("colour"), "{e}");
}

/// The features the renderer draws: ShadowTac's 469 dimples (recessed into the outer skin
/// surface, the authors' CAD), the TacTip's pin tips and Soter's 100 painted markers (raised),
/// UVDtact's 85 ink-filled protrusions (the raised twin of its slots, drawn once); each spot or
/// dimple on the reference surface (offset 0) of its design.
#[test]
fn markers_and_dimples_come_from_the_layers_features() {
    let tol = ChordTolerance::new(0.01).unwrap();
    let of = |n: &str| of_design(&library::load(n).unwrap(), tol).unwrap();
    let s = of("shadowtac");
    assert_eq!(s.dimples.len(), 469);
    assert_eq!(s.markers.len(), 0);
    assert_eq!(
        s.dimple_sources,
        [("layers[0].markers[0]".to_string(), 469)]
    );
    let d = &s.dimples[0];
    assert!(near(d.radius_mm, 0.225) && near(d.height_mm, 0.5));
    let u = of("uvdtact");
    assert_eq!((u.markers.len(), u.dimples.len()), (85, 0));
    let t = of("tactip_dualmodal");
    // the concentric 3 mm layout within 85 deg (Sec. III-D): 107 pins, pinned as the other
    // designs' counts are (a floor of 100 sat 7 % under it)
    assert_eq!(t.markers.len(), 107);
    assert_eq!(of("soter_channels").markers.len(), 100);
    // on the reference sphere of R = 13.5 mm (the TacTip's skin), at the pins' normals
    for m in &t.markers {
        let r = m.centre_mm.iter().map(|x| x * x).sum::<f64>().sqrt();
        let z = m.centre_mm[2];
        if z > 0.0 {
            assert!((r - 13.5).abs() < 1e-6, "{m:?}");
        }
        assert!(near(m.radius_mm, 0.5));
    }
}

/// R-Tac0 with its gel filling the light chamber down to the LED PCB's face (z = -21) and the
/// lens's front under it, 4 mm over the spigot's top (z = -25.65).
fn chamber_fill(rtac0_yaml: &str) -> String {
    rtac0_yaml
        .replace("fills: core ", "fills: chamber ")
        .replace("lens_height_mm: 8.25 ", "lens_height_mm: 4.0 ")
}

fn path_of(d: &Design) -> Result<fabkit_designs::optics::OpticalPath, fabkit_designs::ParamError> {
    let m = MaterialsTable::embedded().unwrap();
    let s = stack::validate(d, &m, ChordTolerance::new(0.01).unwrap()).unwrap();
    fabkit_designs::optics::optical_path(d, &s, &m)
}

/// Each library sensor's flat optical path from the camera up (calibration::refraction):
/// R-Tac0's gel surface at the tube's mouth (z = -6 - 3 = -9 mm, Solaris 1.41, assumed); the
/// TacTip's 2 mm acrylic window (PMMA 1.491) under its RTV27905 gel; ShadowTac's 3 mm PMMA
/// plate under its solid Solaris skin, whose base plane is 22.5 - 8.358 = 14.142 mm above the
/// sphere's centre. `fills: chamber` moves R-Tac0's surface to the LED PCB's face (-21 mm).
#[test]
fn each_sensor_gives_its_flat_optical_path() {
    let planes = |name: &str| {
        path_of(&library::load(name).unwrap())
            .unwrap()
            .planes
            .into_iter()
            .map(|p| (p.z_mm, p.above, p.index_above))
            .collect::<Vec<_>>()
    };
    let r = planes("rtac0");
    assert_eq!(r.len(), 1);
    assert!(
        near(r[0].0, -9.0) && r[0].1 == "solaris" && r[0].2 == 1.41,
        "{r:?}"
    );
    let t = planes("tactip_dualmodal");
    assert_eq!(t.len(), 2, "{t:?}");
    assert!(near(t[1].0 - t[0].0, 2.0), "{t:?}");
    assert_eq!((t[0].1.as_str(), t[0].2), ("pmma", 1.491));
    assert_eq!((t[1].1.as_str(), t[1].2), ("rtv27905", 1.41));
    let s = planes("shadowtac");
    let base = 22.5 - (22.5f64.powi(2) - 17.5f64.powi(2)).sqrt();
    assert_eq!(s.len(), 2, "{s:?}");
    assert!(
        (s[1].0 - (22.5 - base)).abs() < 1e-3 && near(s[1].0 - s[0].0, 3.0),
        "{s:?}"
    );
    assert_eq!(
        (s[0].1.as_str(), s[1].1.as_str()),
        ("pmma", "solaris_thinner_40")
    );
    let yaml = library::LIBRARY
        .iter()
        .find(|(n, _)| *n == "rtac0")
        .unwrap()
        .1;
    let chamber = Design::from_yaml(&chamber_fill(yaml), "r.yaml").unwrap();
    let p = path_of(&chamber).unwrap();
    assert!(near(p.planes[0].z_mm, -21.0), "{p:?}");
    // a gel without a refractive index in the table is an error naming the gel's path
    let moldstar = Design::from_yaml(
        &yaml.replace("material: solaris\n", "material: mold_star_30\n"),
        "r.yaml",
    )
    .unwrap();
    let e = path_of(&moldstar).unwrap_err().to_string();
    assert!(
        e.starts_with("housing.filling_gel = mold_star_30") && e.contains("refractive_index"),
        "{e}"
    );
}

/// R-Tac0's curved faces from the camera's side (rtac0.yaml): the tube's inner face R9 (glass,
/// 1.473) and outer face R10 (Sylgard, 1.41) down to its open end at -6 - 3 = -9 mm, the
/// Sylgard's outer face R13.5 (Ecoflex, 1.41, assumed) down to the base plane at -6 mm, all
/// a hemisphere on the axis at z = 0 on a cylinder; the Ecoflex's outer face is not one (the
/// black coat outside it has no index: it is what the camera images). No other library sensor
/// has a spherical core; a core without an index (opaque) gives none.
#[test]
fn a_spherical_core_gives_its_curved_faces_up_to_the_imaged_coat() {
    let d = library::load("rtac0").unwrap();
    let shells = path_of(&d).unwrap().shells;
    let got: Vec<_> = shells
        .iter()
        .map(|s| {
            (
                s.radius_mm,
                s.bottom_z_mm,
                s.outside.as_str(),
                s.index_outside,
            )
        })
        .collect();
    let want = [
        (9.0, -9.0, "borosilicate_glass", 1.473),
        (10.0, -9.0, "sylgard_184", 1.41),
        (13.5, -6.0, "ecoflex_00_30", 1.41),
    ];
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            near(g.0, w.0) && near(g.1, w.1) && g.2 == w.2 && g.3 == w.3,
            "{g:?}"
        );
    }
    assert!(shells
        .iter()
        .all(|s| s.centre_z_mm == 0.0 && s.join_z_mm == 0.0));
    assert!(shells[0].what.starts_with("core"), "{}", shells[0].what);
    for name in ["tactip_dualmodal", "shadowtac", "digit_pinki", "uvdtact"] {
        assert!(
            path_of(&library::load(name).unwrap())
                .unwrap()
                .shells
                .is_empty(),
            "{name}"
        );
    }
    let yaml = library::LIBRARY
        .iter()
        .find(|(n, _)| *n == "rtac0")
        .unwrap()
        .1;
    let opaque = Design::from_yaml(
        &yaml.replace("material: borosilicate_glass", "material: pla_black"),
        "r.yaml",
    )
    .unwrap();
    assert!(path_of(&opaque).unwrap().shells.is_empty());
}
