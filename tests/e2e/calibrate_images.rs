//! `fabkit calibrate extrinsics --images ... --reference ...` end to end: the R-Tac0 pin dome's
//! point table and capture plan (`fabkit fixtures rtac0 --pins-preset rtac0 --semidomes 0`: 29
//! pins, eight captures of one pin per ring), each capture rendered with the ground-truth caster
//! (`imprints::synthetic`: imprint darkening, PSF, vignetting, flickering LED reflections,
//! noise) through the e2e fisheye at a known pose 8.4 mm under R-Tac0's filling gel surface
//! (the rays bent there, as the command bends them by default for a table of a design with a
//! filling gel), and written as the photos a user has: grey
//! 8-bit and 16-bit PNG, RGB PNG and JPEG. The pins are found, given the plan's ids (or the ids
//! their file names list), written to observations.csv with an overlay per capture, and the
//! pose solved from them is as good as the pose solved from the imprints' true centroids.

use std::collections::BTreeMap;
use std::path::Path;

use crate::calibrate_cli::{intrinsics, json, layers_of, pose_of, truth_under_gel};
use crate::common::{run, text};
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::imprints::synthetic::{Pin, Shading};
use fabkit_calibration::imprints::GrayImage;
use fabkit_calibration::nalgebra::{
    DMatrix, DVector, Isometry3, Translation3, UnitQuaternion, Vector2, Vector3,
};
use fabkit_calibration::tables::{read_capture_plan, read_point_table, PointsFrom};
use fabkit_calibration::{
    write_camera, CameraFileFormat, CameraModel, Distortion, Intrinsics, PnpOptions,
};

/// The tip radius of the fixtures' default pin, mm.
const TIP_RADIUS_MM: f64 = 0.8;

/// How a capture is saved.
#[derive(Clone, Copy)]
enum Kind {
    Gray8,
    Gray16,
    Rgb8,
    Jpeg,
}

fn save(img: &GrayImage, path: &Path, kind: Kind) {
    let (w, h) = (img.width as u32, img.height as u32);
    let g8: Vec<u8> = img
        .data
        .iter()
        .map(|g| g.round().clamp(0.0, 255.0) as u8)
        .collect();
    match kind {
        Kind::Gray8 => image::GrayImage::from_raw(w, h, g8)
            .unwrap()
            .save(path)
            .unwrap(),
        Kind::Gray16 => {
            let g16: Vec<u16> = img
                .data
                .iter()
                .map(|g| (g.clamp(0.0, 255.0) * 257.0).round() as u16)
                .collect();
            image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, g16)
                .unwrap()
                .save(path)
                .unwrap()
        }
        Kind::Rgb8 => {
            let rgb: Vec<u8> = g8.iter().flat_map(|&g| [g, g, g]).collect();
            image::RgbImage::from_raw(w, h, rgb)
                .unwrap()
                .save(path)
                .unwrap()
        }
        Kind::Jpeg => {
            let f = std::fs::File::create(path).unwrap();
            image::codecs::jpeg::JpegEncoder::new_with_quality(f, 95)
                .encode(&g8, w, h, image::ExtendedColorType::L8)
                .unwrap()
        }
    }
}

/// The fixtures' table and plan, and a renderer of captures of their pins.
struct Scene {
    dir: tempfile::TempDir,
    /// The camera the captures are rendered through, and its pose.
    camera: CameraModel,
    pose: Isometry3<f64>,
    surface: ReferenceSurface,
    tips: BTreeMap<String, Vector3<f64>>,
    plan: Vec<Vec<String>>,
    /// The optical path the captures are seen through (the gel's surface and the glass tube);
    /// `None`: straight rays.
    layers: Option<fabkit_calibration::refraction::OpticalLayers>,
}

impl Scene {
    /// The e2e fisheye 8.4 mm under R-Tac0's gel surface ([`truth_under_gel`]): the captures
    /// are seen through the table's design's filling gel.
    fn new() -> Scene {
        Self::with(intrinsics(), truth_under_gel())
    }

    /// The captures rendered through `camera` at `pose`, through R-Tac0's filling gel (the
    /// point table's design); cam.yaml holds `camera`.
    fn with(camera: Intrinsics, pose: Isometry3<f64>) -> Scene {
        let dir = tempfile::tempdir().unwrap();
        crate::common::published_pin_dome(dir.path(), "rtac0", "fx");
        std::fs::write(
            dir.path().join("cam.yaml"),
            write_camera(&camera, CameraFileFormat::OpenCvYaml),
        )
        .unwrap();
        let table = read_point_table(
            &dir.path().join("fx/points/point_table.csv"),
            PointsFrom::Tip,
        )
        .unwrap();
        let plan = read_capture_plan(&dir.path().join("fx/points/capture_plan.csv")).unwrap();
        let design = fabkit_designs::library::load("rtac0").unwrap();
        Scene {
            dir,
            camera: CameraModel::new(camera).unwrap(),
            pose,
            surface: ReferenceSurface::of(&design.body).unwrap(),
            tips: table.rows.into_iter().map(|(id, p, _)| (id, p)).collect(),
            plan: plan.captures,
            layers: layers_of("rtac0"),
        }
    }

    fn path(&self, rel: &str) -> std::path::PathBuf {
        self.dir.path().join(rel)
    }

    /// The reference and the capture of `ids` pressed (balls of the pin's tip radius, their
    /// lowest points at the table's tips), and each pin's true imprint centroid.
    fn render(&self, ids: &[String], seed: u64) -> (GrayImage, GrayImage, Vec<[f64; 2]>) {
        let shading = Shading {
            grey_per_mm: 60.0,
            ..Shading::default()
        };
        self.render_with(ids, seed, &shading)
    }

    /// [`Scene::render`] with `shading`.
    fn render_with(
        &self,
        ids: &[String],
        seed: u64,
        shading: &Shading,
    ) -> (GrayImage, GrayImage, Vec<[f64; 2]>) {
        self.render_seated(ids, seed, shading, &Vector3::zeros())
    }

    /// [`Scene::render_with`] with the dome seated `shift_mm` (sensor frame) off its place:
    /// every pin moved by it.
    fn render_seated(
        &self,
        ids: &[String],
        seed: u64,
        shading: &Shading,
        shift_mm: &Vector3<f64>,
    ) -> (GrayImage, GrayImage, Vec<[f64; 2]>) {
        let pins: Vec<Pin> = ids
            .iter()
            .map(|id| {
                let tip = self.tips[id];
                let c = tip + tip.normalize() * TIP_RADIUS_MM + shift_mm;
                Pin {
                    centre_mm: [c.x, c.y, c.z],
                    radius_mm: TIP_RADIUS_MM,
                }
            })
            .collect();
        let r = fabkit_calibration::imprints::synthetic::render_through(
            &self.camera,
            &self.pose,
            self.layers.as_ref(),
            &self.surface,
            &pins,
            shading,
            seed,
        );
        let centres = r.centres_px.iter().map(|c| c.unwrap()).collect();
        (r.reference, r.capture, centres)
    }
}

impl Scene {
    /// How far `pose` is from the scene's: rotation (deg) and translation (mm).
    fn pose_errors(&self, pose: &Isometry3<f64>) -> (f64, f64) {
        pose_errors_from(pose, &self.pose)
    }

    /// The scene's camera and optical path.
    fn imaging(&self) -> fabkit_calibration::refraction::Imaging<'_> {
        fabkit_calibration::refraction::Imaging::new(&self.camera, self.layers.as_ref())
    }
}

/// observations.csv rows: (capture, id) -> (u_px, v_px).
fn observations(path: &Path) -> BTreeMap<(String, String), [f64; 2]> {
    let t = std::fs::read_to_string(path).unwrap();
    let mut lines = t.lines().filter(|l| !l.starts_with('#'));
    assert_eq!(lines.next(), Some("capture,id,u_px,v_px,score"));
    lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            assert_eq!(c.len(), 5, "{l}");
            // measured 77 or more, 28 or more where an LED notch clips the imprint (the detector
            // keeps spots above its threshold_sigma, 8)
            assert!(c[4].parse::<f64>().unwrap() > 8.0, "score of {l}");
            (
                (c[0].to_string(), c[1].to_string()),
                [c[2].parse().unwrap(), c[3].parse().unwrap()],
            )
        })
        .collect()
}

/// The authors' file name of a capture of `ids`: `01_02_06_14_22.EXT`.
fn file_name(ids: &[String], ext: &str) -> String {
    ids.iter()
        .map(|id| format!("{:02}", id.parse::<u32>().unwrap()))
        .collect::<Vec<_>>()
        .join("_")
        + "."
        + ext
}

/// `calibrate extrinsics --images NAMES --reference REFERENCE --out out` with the scene's
/// camera and table, the ids from the file names.
fn calibrate_by_file_names(s: &Scene, reference: &str, names: &[String]) -> std::process::Output {
    calibrate_by_file_names_into(s, reference, names, "out")
}

/// [`calibrate_by_file_names`] into the folder `out`.
fn calibrate_by_file_names_into(
    s: &Scene,
    reference: &str,
    names: &[String],
    out: &str,
) -> std::process::Output {
    let mut args = vec![
        "calibrate",
        "extrinsics",
        "--camera",
        "cam.yaml",
        "--points",
        "fx/points/point_table.csv",
        "--reference",
        reference,
        "--out",
        out,
        "--images",
    ];
    args.extend(names.iter().map(String::as_str));
    run(s.dir.path(), &args, &[])
}

impl Scene {
    /// Each pin's tip and its observed centre ((capture, id) -> px), a pin seen in several
    /// captures averaged, as the command does; by id.
    fn tips_and_mean_centres(
        &self,
        centres: &BTreeMap<(String, String), [f64; 2]>,
    ) -> (Vec<Vector3<f64>>, Vec<Vector2<f64>>) {
        let mut by_id: BTreeMap<&String, (Vector2<f64>, f64)> = BTreeMap::new();
        for ((_, id), c) in centres {
            let e = by_id.entry(id).or_insert((Vector2::zeros(), 0.0));
            e.0 += Vector2::new(c[0], c[1]);
            e.1 += 1.0;
        }
        by_id
            .iter()
            .map(|(id, (sum, n))| (self.tips[*id], sum / *n))
            .unzip()
    }

    /// How far from the true pose the camera's noise may move a pose solved from these
    /// observations ((capture, id) -> px, a pin seen in several captures averaged) when each
    /// centre is off by `sigma_px` RMS: 6 standard deviations of the Cramer-Rao bound at the
    /// true pose (pnp::pose_uncertainty, Hartley & Zisserman Ch. 5), rotation (deg) and
    /// translation (mm), the root of the traces of their blocks. An error past it is not noise.
    fn noise_allowance(
        &self,
        centres: &BTreeMap<(String, String), [f64; 2]>,
        sigma_px: f64,
    ) -> (f64, f64) {
        let (pts, px) = self.tips_and_mean_centres(centres);
        let u = fabkit_calibration::pnp::pose_uncertainty_through(
            &self.imaging(),
            &pts,
            &px,
            &vec![true; pts.len()],
            &self.pose,
        )
        .unwrap();
        let (rot_deg, t_mm) = u.rms_errors(sigma_px);
        (6.0 * rot_deg, 6.0 * t_mm)
    }

    /// The pose solved from the imprints' true centroids ((capture, id) -> px; a pin seen in
    /// several captures averaged, as the command does).
    fn pose_from_true_centres(
        &self,
        true_centres: &BTreeMap<(String, String), [f64; 2]>,
    ) -> Isometry3<f64> {
        let (pts, px) = self.tips_and_mean_centres(true_centres);
        fabkit_calibration::pnp::solve_pnp_through(
            &self.imaging(),
            &pts,
            &px,
            &PnpOptions::default(),
        )
        .unwrap()
        .t_cam_sensor
    }
}

#[test]
fn pins_found_in_photos_get_the_plans_ids_and_give_the_pose() {
    let s = Scene::new();
    let kinds = [Kind::Rgb8, Kind::Gray16, Kind::Jpeg];
    let mut names = Vec::new();
    let mut true_centres: BTreeMap<(String, String), [f64; 2]> = BTreeMap::new();
    for (k, ids) in s.plan.iter().enumerate() {
        let seed = 1000 * crate::common::seed_set() + 100 + k as u64;
        let (reference, capture, centres) = s.render(ids, seed);
        if k == 0 {
            save(&reference, &s.path("reference.png"), Kind::Gray16);
        }
        let kind = kinds.get(k).copied().unwrap_or(Kind::Gray8);
        let name = format!(
            "capture_{}.{}",
            k + 1,
            if matches!(kind, Kind::Jpeg) {
                "jpg"
            } else {
                "png"
            }
        );
        save(&capture, &s.path(&name), kind);
        for (id, c) in ids.iter().zip(centres) {
            true_centres.insert((name.clone(), id.clone()), c);
        }
        names.push(name);
    }
    let calibrate = |out: &str, threads: &str| {
        let mut args = vec![
            "calibrate",
            "extrinsics",
            "--camera",
            "cam.yaml",
            "--points",
            "fx/points/point_table.csv",
            "--capture-plan",
            "fx/points/capture_plan.csv",
            "--reference",
            "reference.png",
            "--out",
            out,
            "--images",
        ];
        args.extend(names.iter().map(String::as_str));
        run(s.dir.path(), &args, &[("RAYON_NUM_THREADS", threads)])
    };
    let o = calibrate("out", "2");
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    assert!(!text(&o.stderr).contains("warning"), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("imprints: 40 pins found in 8 of 8 captures"),
        "{}",
        text(&o.stdout)
    );

    // observations.csv starts with its header row (its notes in observations.json) and opens
    // in pandas, csv and numpy with default arguments.
    let obs_csv = s.path("out/observations.csv");
    assert!(std::fs::read_to_string(&obs_csv)
        .unwrap()
        .starts_with("capture,id,u_px,v_px,score\n"));
    let side: serde_json::Value =
        serde_json::from_slice(&std::fs::read(s.path("out/observations.json")).unwrap()).unwrap();
    assert_eq!(side["file"], "observations.csv");
    crate::default_readers::default_readers_check(
        s.dir.path(),
        &serde_json::json!({"csv": [crate::default_readers::csv_spec(
            &obs_csv,
            &["capture", "id", "u_px", "v_px", "score"],
            Some(40),
        )]}),
    );

    // Every planned pin of every capture found, with its id, at its imprint's centroid.
    let found = observations(&s.path("out/observations.csv"));
    assert_eq!(
        found.keys().collect::<Vec<_>>(),
        true_centres.keys().collect::<Vec<_>>()
    );
    let (mut sq, mut worst) = (0.0, 0.0f64);
    for (key, t) in &true_centres {
        let f = found[key];
        let e = (f[0] - t[0]).hypot(f[1] - t[1]);
        sq += e * e;
        worst = worst.max(e);
    }
    let rms = (sq / true_centres.len() as f64).sqrt();
    // measured 0.059 to 0.062 px RMS, worst 0.114 to 0.161 px, on seed sets 0 to 2
    assert!(
        rms < 0.1 && worst < 0.3,
        "centroid error {rms:.4} px RMS, worst {worst:.4} px"
    );

    // The pose against the true pose (issue 96: not against another run of the solver). An
    // imprint's centroid is not the image of the pin's tip: that offset, the same for every
    // capture, moves the pose from the true centroids by (rot_true, t_true) from the truth;
    // the detection's noise (the centres' RMS error above) may move it by its Cramer-Rao
    // allowance more, no further.
    let (rot_true, t_true) = s.pose_errors(&s.pose_from_true_centres(&true_centres));
    let (rot_noise, t_noise) = s.noise_allowance(&true_centres, rms);
    let j = json(&s.path("out/extrinsics.json"));
    let (rot, t) = s.pose_errors(&pose_of(&j));
    // measured on seed sets 0 to 2: 0.024 to 0.036 deg and 0.556 to 0.557 mm from the truth;
    // the true centroids' pose 0.024 deg and 0.545 mm; allowances 0.21 to 0.22 deg and 0.022 to
    // 0.024 mm
    assert!(
        rot <= rot_true + rot_noise && t <= t_true + t_noise,
        "from the images: {rot:.4} deg, {t:.4} mm from the truth; the centroids' offset {rot_true:.4} deg, {t_true:.4} mm, the noise's allowance {rot_noise:.4} deg, {t_noise:.4} mm"
    );
    assert_eq!(j["residuals"]["observations"], 29);
    assert_eq!(j["provenance"]["reference_image"], "reference.png");
    assert_eq!(j["provenance"]["observation_files"][2], "capture_3.jpg");

    // The residual histogram: bars for the 29 inliers' errors.
    let hist = image::open(s.path("out/residuals.png"))
        .unwrap()
        .into_rgb8();
    assert_eq!(hist.dimensions(), (480, 260));
    // measured 20,938 to 26,239 pixels on seed sets 0 to 2
    assert!(hist.pixels().filter(|p| p.0 == [60, 110, 200]).count() > 29 * 10);

    // An overlay per capture, the camera's size, each spot circled in green.
    for (k, name) in names.iter().enumerate() {
        let stem = name.split('.').next().unwrap();
        let img = image::open(s.path(&format!("out/overlays/{stem}.png")))
            .unwrap()
            .into_rgb8();
        assert_eq!(img.dimensions(), (640, 480));
        let green = img.pixels().filter(|p| p.0 == [0, 220, 0]).count();
        // measured 420 to 438 pixels on seed sets 0 to 2
        assert!(green > 5 * 20, "capture {}: {green} green pixels", k + 1);
    }

    // Same input, same bytes, whatever the thread count.
    let o = calibrate("out1", "1");
    assert!(o.status.success(), "{}", text(&o.stderr));
    for f in ["observations.csv", "overlays/capture_2.png"] {
        assert_eq!(
            std::fs::read(s.path("out").join(f)).unwrap(),
            std::fs::read(s.path("out1").join(f)).unwrap(),
            "{f}"
        );
    }
    let j1 = json(&s.path("out1/extrinsics.json"));
    assert_eq!(
        (&j["rvec"], &j["tvec_mm"], &j["residuals"]),
        (&j1["rvec"], &j1["tvec_mm"], &j1["residuals"])
    );
}

#[test]
fn ids_from_file_names_and_a_missing_pin_or_an_extra_spot_handled_per_spot() {
    let s = Scene::new();
    let mut names = Vec::new();
    let last = s.plan.len() - 1;
    for (k, ids) in s.plan.iter().enumerate() {
        let mut pressed = ids.clone();
        if k == last {
            pressed.pop(); // one pin fewer than its name says
        }
        if k == last - 1 {
            pressed.push(s.plan[0][2].clone()); // one more than its name says
        }
        let (reference, capture, _) = s.render(&pressed, 200 + k as u64);
        if k == 0 {
            save(&reference, &s.path("reference.png"), Kind::Gray8);
        }
        let name = file_name(ids, "png");
        save(&capture, &s.path(&name), Kind::Gray8);
        names.push(name);
    }
    let o = calibrate_by_file_names(&s, "reference.png", &names);
    let err = text(&o.stderr);
    assert!(o.status.success(), "{}{err}", text(&o.stdout));
    assert!(
        text(&o.stdout).contains(
            "imprints: 39 pins found in 8 of 8 captures (observations.csv; overlays/); 0 captures left out, 1 spot discarded, 1 pin missing: named below"
        ),
        "{}",
        text(&o.stdout)
    );
    let popped = s.plan[last].last().unwrap();
    let extra = &s.plan[0][2];
    assert!(
        err.contains(&format!(
            "warning: {}: 4 spots; kept pins {}; pin {popped} missing: no spot within",
            names[last],
            s.plan[last][..4]
                .iter()
                .map(|id| id.parse::<u32>().unwrap())
                .collect::<std::collections::BTreeSet<_>>()
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        )),
        "{err}"
    );
    assert!(
        err.contains(&format!(
            "warning: {}: 6 spots; kept pins ",
            names[last - 1]
        )) && err.contains("discarded: "),
        "{err}"
    );
    let found = observations(&s.path("out/observations.csv"));
    assert_eq!(found.len(), 5 * (s.plan.len() - 1) + 4);
    for (capture, id) in found.keys() {
        let k = names.iter().position(|n| n == capture).unwrap();
        assert!(s.plan[k].contains(id), "{capture} {id}");
        assert!(k != last || id != popped, "the missing pin has no spot");
    }
    // the report lists per capture what was found, kept, discarded and missing
    let j = json(&s.path("out/extrinsics.json"));
    let caps = j["captures"].as_array().unwrap();
    assert_eq!(caps.len(), s.plan.len());
    let c = &caps[last - 1];
    assert_eq!(c["spots_found"], 6);
    assert_eq!(c["kept"].as_array().unwrap().len(), 5);
    let d = &c["discarded"][0];
    assert!(d["reason"].as_str().unwrap().len() > 10, "{d}");
    // the discarded spot is the pin pressed but not named, not one of the capture's own pins
    let t = s.render(std::slice::from_ref(extra), 0).2[0];
    let (u, v) = (d["u_px"].as_f64().unwrap(), d["v_px"].as_f64().unwrap());
    // measured 0.071 px on seed sets 0 to 2
    assert!((u - t[0]).hypot(v - t[1]) < 1.0, "{d} vs {t:?}");
    let c = &caps[last];
    assert_eq!(c["missing"][0]["id"].as_str().unwrap(), popped);
    assert!(caps.iter().all(|c| c.get("left_out").is_none()));
    // a pin that no other capture holds is the only one unobserved
    let unobserved: Vec<&str> = j["provenance"]["unobserved_ids"]
        .as_array()
        .map(|a| a.iter().map(|v| v.as_str().unwrap()).collect())
        .unwrap_or_default();
    let elsewhere = s.plan[..last].iter().flatten().any(|i| i == popped);
    assert_eq!(
        unobserved,
        if elsewhere {
            vec![]
        } else {
            vec![popped.as_str()]
        }
    );
}

/// The default command (ids from the file names, no flags) on JPEG photos with every artifact
/// of a real capture (`Shading::real_capture`: a ring of saturated LED highlights that move
/// 1.5 px, gain drift, imprints side-lit from the rim, three specks and a scratch off the
/// pins per capture): every capture is used with all its pins, each speck and scratch is
/// discarded and reported with why (none of them a pin), the centres are within 0.2 px RMS of
/// the true centroids and the pose, against the true pose, within the true centroids' error
/// plus 6 sd of the Cramer-Rao spread at the centres' measured noise.
#[test]
fn the_default_command_on_photos_with_every_artifact_of_a_real_capture_uses_every_capture() {
    let s = Scene::new();
    let shading = Shading {
        grey_per_mm: 60.0,
        jpeg_quality: None, // the files are JPEG
        ..Shading::real_capture()
    };
    let mut names = Vec::new();
    let mut true_centres: BTreeMap<(String, String), [f64; 2]> = BTreeMap::new();
    for (k, ids) in s.plan.iter().enumerate() {
        let (reference, capture, centres) = s.render_with(ids, 400 + k as u64, &shading);
        if k == 0 {
            save(&reference, &s.path("reference.jpg"), Kind::Jpeg);
        }
        let name = file_name(ids, "jpg");
        save(&capture, &s.path(&name), Kind::Jpeg);
        for (id, c) in ids.iter().zip(centres) {
            true_centres.insert((name.clone(), id.clone()), c);
        }
        names.push(name);
    }
    let o = calibrate_by_file_names(&s, "reference.jpg", &names);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{out}{err}");
    assert!(
        out.contains("imprints: 40 pins found in 8 of 8 captures")
            && out.contains("0 captures left out")
            && out.contains("0 pins missing"),
        "{out}"
    );
    // every discarded spot reported with why, and none of them a pin
    let j = json(&s.path("out/extrinsics.json"));
    let caps = j["captures"].as_array().unwrap();
    let mut by_shape = 0;
    for (c, name) in caps.iter().zip(&names) {
        assert_eq!(c["kept"].as_array().unwrap().len(), 5, "{c}");
        for d in c["discarded"].as_array().into_iter().flatten() {
            let (u, v) = (d["u_px"].as_f64().unwrap(), d["v_px"].as_f64().unwrap());
            let why = d["reason"].as_str().unwrap();
            assert!(
                err.contains(&format!("discarded: {why}")),
                "{why} not in the warnings:\n{err}"
            );
            let nearest = true_centres
                .iter()
                .filter(|((n, _), _)| n == name)
                .map(|(_, t)| (u - t[0]).hypot(v - t[1]))
                .fold(f64::INFINITY, f64::min);
            // measured 30 px or more on seed sets 0 to 2
            assert!(nearest > 10.0, "{name}: a pin discarded: {d}");
            by_shape += usize::from(why.contains("a speck") || why.contains("a scratch"));
        }
    }
    // measured 30 on seed sets 0 to 2
    assert!(
        by_shape >= 8,
        "{by_shape} spots discarded for their shape\n{err}"
    );
    let found = observations(&s.path("out/observations.csv"));
    assert_eq!(
        found.keys().collect::<Vec<_>>(),
        true_centres.keys().collect::<Vec<_>>()
    );
    let sq: f64 = true_centres
        .iter()
        .map(|(key, t)| (found[key][0] - t[0]).powi(2) + (found[key][1] - t[1]).powi(2))
        .sum();
    let rms = (sq / true_centres.len() as f64).sqrt();
    // measured 0.038 px on seed sets 0 to 2
    assert!(rms < 0.2, "centroid error {rms:.4} px RMS");
    // the pose against the true pose: the centroids' own offset from the tips' images, and
    // the detection noise's Cramer-Rao allowance (issue 96)
    let (rot_true, t_true) = s.pose_errors(&s.pose_from_true_centres(&true_centres));
    let (rot_noise, t_noise) = s.noise_allowance(&true_centres, rms);
    let (rot, t) = s.pose_errors(&pose_of(&j));
    // measured on seed sets 0 to 2: within 0.003 deg and 0.002 mm of the true centroids' pose
    // (0.024 deg, 0.545 mm from the truth), against allowances of 0.133 deg and 0.015 mm
    assert!(
        rot <= rot_true + rot_noise && t <= t_true + t_noise,
        "from the images: {rot:.4} deg, {t:.4} mm from the truth; the centroids' offset {rot_true:.4} deg, {t_true:.4} mm, the noise's allowance {rot_noise:.4} deg, {t_noise:.4} mm"
    );
    // The same captures in the reverse order and in another interleaving: the same pose, to
    // rounding (issue 97: on real captures the order moved it 0.83 deg). The per-pin averages
    // sum the captures in another order, which moves them by about 1e-14 px.
    let n = names.len();
    for (k, order) in [
        names.iter().rev().cloned().collect::<Vec<_>>(),
        (0..n).map(|i| names[(3 * i + 1) % n].clone()).collect(),
    ]
    .iter()
    .enumerate()
    {
        let out = format!("reordered_{k}");
        let o = calibrate_by_file_names_into(&s, "reference.jpg", order, &out);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let j2 = json(&s.path(&format!("{out}/extrinsics.json")));
        let (r, t) = pose_errors_from(&pose_of(&j2), &pose_of(&j));
        assert!(
            r < 1e-9 && t < 1e-9,
            "order {order:?}: {r} deg, {t} mm apart"
        );
        assert_eq!(j2["residuals"]["inliers"], j["residuals"]["inliers"]);
    }
}

#[test]
fn bad_images_and_reference_exit_2_naming_the_option_and_write_nothing() {
    let s = Scene::new();
    let blank = GrayImage::filled(640, 480, 120.0);
    save(&blank, &s.path("ref.png"), Kind::Gray8);
    save(&blank, &s.path("01_02_06_14_22.png"), Kind::Gray8);
    save(&blank, &s.path("capture.png"), Kind::Gray8);
    save(
        &GrayImage::filled(320, 240, 120.0),
        &s.path("01_05_09_17_25.png"),
        Kind::Gray8,
    );
    std::fs::copy(s.path("01_05_09_17_25.png"), s.path("small.png")).unwrap();
    std::fs::write(s.path("01_04_08_16_24.png"), "not an image\n").unwrap();
    std::fs::write(s.path("obs.csv"), "id,u_px,v_px\n").unwrap();
    std::fs::create_dir(s.path("caps")).unwrap();
    save(&blank, &s.path("01_01_01_01_01.png"), Kind::Gray8);
    // issue 95: a JPEG cut to half its bytes was accepted (the decoder fills the rest)
    save(&blank, &s.path("01_06_10_18_26.jpg"), Kind::Jpeg);
    let jpeg = std::fs::read(s.path("01_06_10_18_26.jpg")).unwrap();
    std::fs::write(s.path("01_06_10_18_26.jpg"), &jpeg[..jpeg.len() / 2]).unwrap();
    let base = [
        "calibrate",
        "extrinsics",
        "--camera",
        "cam.yaml",
        "--points",
        "fx/points/point_table.csv",
        "--out",
        "out",
    ];
    let cases: &[(&[&str], &str)] = &[
        (
            &["--reference", "ref.png", "--images", "01_03_07_15_23.png"],
            "--images = 01_03_07_15_23.png: cannot read",
        ),
        (
            &["--reference", "ref.png", "--images", "01_04_08_16_24.png"],
            "--images = 01_04_08_16_24.png: not a readable PNG or JPEG image",
        ),
        (
            &["--reference", "ref.png", "--images", "01_05_09_17_25.png"],
            "--images = 01_05_09_17_25.png: the image is 320 x 240 px but the camera file cam.yaml says 640 x 480 px",
        ),
        (
            &["--reference", "small.png", "--images", "01_02_06_14_22.png"],
            "--reference = small.png: the image is 320 x 240 px",
        ),
        (
            &["--reference", "missing.png", "--images", "01_02_06_14_22.png"],
            "--reference = missing.png: cannot read",
        ),
        (
            &["--reference", "ref.png", "--images", "capture.png"],
            "--images = capture.png: the file name does not list the capture's pin ids",
        ),
        // issue 102: a folder of captures was told its name lists no pin ids
        (
            &["--reference", "ref.png", "--images", "caps"],
            "--images = caps: is a folder, not an image: give the capture images themselves (as caps/*.png",
        ),
        (
            &[
                "--reference",
                "ref.png",
                "--capture-plan",
                "fx/points/capture_plan.csv",
                "--images",
                "capture.png",
            ],
            "--images: 1 images but the capture plan fx/points/capture_plan.csv has 8 captures",
        ),
        (
            &[
                "--reference",
                "ref.png",
                "--images",
                "01_02_06_14_22.png",
                "01_02_06_14_22.png",
            ],
            "--images = 01_02_06_14_22.png: given twice",
        ),
        (
            &["--reference", "ref.png", "--images", "01_06_10_18_26.jpg"],
            "--images = 01_06_10_18_26.jpg: not a readable PNG or JPEG image: the JPEG is incomplete",
        ),
        // issue 95: a name that lists a pin five times was accepted with five warnings
        (
            &["--reference", "ref.png", "--images", "01_01_01_01_01.png"],
            "--images = 01_01_01_01_01.png: pin 1 listed 5 times",
        ),
        (&["--reference", "ref.png"], "--images"),
        (&["--images", "01_02_06_14_22.png"], "--reference"),
        (
            &[
                "--reference",
                "ref.png",
                "--images",
                "01_02_06_14_22.png",
                "--observations",
                "obs.csv",
            ],
            "cannot be used with",
        ),
    ];
    for (extra, message) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let o = run(s.dir.path(), &args, &[]);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains(message),
            "{extra:?}: wanted {message:?} in {}",
            text(&o.stderr)
        );
        assert!(!s.path("out").exists(), "{extra:?}");
    }
}

#[test]
fn refine_intrinsics_from_photos_writes_the_camera_file_in_the_form_read() {
    use fabkit_calibration::{read_camera_file, Distortion};
    // The camera 10.4 mm under the dome's centre looking through air (--straight-rays): from
    // there the pins span enough of the field to fix the principal point. (From 8.4 mm under
    // R-Tac0's gel surface, 17.4 mm from the centre, cx and cy trade against the camera's
    // offset, condition numbers 1.8e3 and 5.4e2, and are held; measured.)
    let mut s = Scene::with(intrinsics(), crate::calibrate_cli::truth());
    s.layers = None;
    let mut names = Vec::new();
    for (k, ids) in s.plan.iter().enumerate() {
        let (reference, capture, _) = s.render(ids, 300 + k as u64);
        if k == 0 {
            save(&reference, &s.path("reference.png"), Kind::Gray8);
        }
        let name = format!("capture_{}.png", k + 1);
        save(&capture, &s.path(&name), Kind::Gray8);
        names.push(name);
    }
    // the camera file: the principal point 3 and 2 px off, k1 half the true value
    let mut off = intrinsics();
    off.cx_px += 3.0;
    off.cy_px -= 2.0;
    off.distortion = Distortion::Fisheye([-0.01, 0.004, -0.0015, 0.0002]);
    std::fs::write(
        s.path("cam_off.json"),
        write_camera(&off, CameraFileFormat::Json),
    )
    .unwrap();
    std::fs::write(
        s.path("cam_off.yaml"),
        write_camera(&off, CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    let calibrate = |camera: &str, refine: &str, out: &str| {
        let mut args = vec![
            "calibrate",
            "extrinsics",
            "--camera",
            camera,
            "--points",
            "fx/points/point_table.csv",
            "--capture-plan",
            "fx/points/capture_plan.csv",
            "--reference",
            "reference.png",
            "--straight-rays",
            "--out",
            out,
        ];
        if refine.is_empty() {
            args.push("--refine-intrinsics");
        } else {
            args.extend(["--refine-intrinsics", refine]);
        }
        args.push("--images");
        args.extend(names.iter().map(String::as_str));
        run(s.dir.path(), &args, &[])
    };
    let o = calibrate("cam_off.json", "", "out");
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    let j = json(&s.path("out/extrinsics.json"));
    let ir = &j["intrinsics_refinement"];
    assert_eq!(ir["camera_file"], "camera_refined.json");
    assert!(ir["rms_after_px"].as_f64().unwrap() < ir["rms_before_px"].as_f64().unwrap());
    let truth = intrinsics();
    let true_values = [
        ("fx", truth.fx_px),
        ("fy", truth.fy_px),
        ("cx", truth.cx_px),
        ("cy", truth.cy_px),
        ("k1", -0.02),
    ];
    let params = ir["parameters"].as_array().unwrap();
    let param = |n: &str| params.iter().find(|p| p["name"] == n).unwrap();
    for n in ["fx", "fy"] {
        assert!(
            param(n)["held"]
                .as_str()
                .unwrap()
                .contains("the focal length (fx and fy together)"),
            "{}",
            param(n)
        );
    }
    for (n, tv) in &true_values[2..] {
        let p = param(n);
        let (v, sd) = (p["value"].as_f64().unwrap(), p["std"].as_f64().unwrap());
        // within 4 sd: each parameter's error leaves it with a probability of 6.3e-5, any of
        // the three with 1.9e-4 (3 sd, 0.8 %, failed about one run in five of the refine
        // tests' 30 seeds); measured z = -0.77, 0.14 and -0.98 for cx, cy and k1
        assert!(
            (v - tv).abs() < 4.0 * sd
                && (v - tv).abs() < (p["initial"].as_f64().unwrap() - tv).abs(),
            "{n} = {v} +- {sd}, true {tv}"
        );
    }
    // the refined camera file, in the form read, holds the reported values
    let refined = read_camera_file(&s.path("out/camera_refined.json")).unwrap();
    let r = refined.intrinsics();
    let got = [
        r.fx_px,
        r.fy_px,
        r.cx_px,
        r.cy_px,
        r.distortion.coefficients()[0],
    ];
    for ((n, _), g) in true_values.iter().zip(got) {
        assert!(
            (param(n)["value"].as_f64().unwrap() - g).abs() < 1e-9,
            "{n}: {g} in the file"
        );
    }
    let o = calibrate("cam_off.yaml", "cx,cy,k1,k2", "out_yaml");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let y = std::fs::read_to_string(s.path("out_yaml/camera_refined.yaml")).unwrap();
    assert!(y.starts_with("%YAML:1.0"), "{y}");
    assert!(read_camera_file(&s.path("out_yaml/camera_refined.yaml")).is_ok());
    std::fs::write(
        s.path("cam_off.xml"),
        write_camera(&off, CameraFileFormat::OpenCvXml),
    )
    .unwrap();
    let o = calibrate("cam_off.xml", "cx,cy,k1,k2", "out_xml");
    assert!(o.status.success(), "{}", text(&o.stderr));
    let from_xml = read_camera_file(&s.path("out_xml/camera_refined.xml")).unwrap();
    let from_yaml = read_camera_file(&s.path("out_yaml/camera_refined.yaml")).unwrap();
    assert_eq!(from_xml.intrinsics(), from_yaml.intrinsics());

    // parameters the model lacks, or the captures do not constrain: exit 2, nothing written
    for (refine, message) in [
        (
            "cx,k9",
            "--refine-intrinsics cx,k9: 'k9' is not a parameter of the fisheye model (its parameters: fx, fy, cx, cy, k1, k2, k3, k4)",
        ),
        (
            "fx,fy,cx,cy,k1",
            "--refine-intrinsics fx,fy,cx,cy,k1: the captures do not constrain f",
        ),
        ("cx,cx", "--refine-intrinsics cx,cx: 'cx' is named twice"),
    ] {
        let o = calibrate("cam_off.json", refine, "bad");
        assert_eq!(o.status.code(), Some(2), "{refine}: {}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains(message),
            "{refine}: wanted {message:?} in {}",
            text(&o.stderr)
        );
        assert!(!s.path("bad").exists(), "{refine}");
    }
}

/// A 160 deg lens close under the dome, as on the R-Tac0 (an equidistant fisheye, f = 172 px:
/// 80 deg off the axis at 240 px; the camera 2 mm below the dome's centre, so that the outer
/// ring is seen 67 deg off the axis), described by a 5-coefficient pinhole camera file
/// (plumb_bob) fitted to the lens over the pins' field by least squares and then 20 px off at
/// the outer ring: the default command (no --ransac-threshold-px, no --refine-intrinsics)
/// gives a pose from the inner rings, and the report gives the RMS per ring and says that the
/// errors grow with the polar angle, suggesting --refine-intrinsics.
#[test]
fn straight_rays_give_a_pose_through_a_rough_pinhole_file_of_a_160_deg_lens() {
    let lens = Intrinsics {
        image_width_px: 640,
        image_height_px: 480,
        fx_px: 172.0,
        fy_px: 172.0,
        cx_px: 320.0,
        cy_px: 240.0,
        distortion: Distortion::Fisheye([0.0; 4]),
    };
    let pose = Isometry3::from_parts(
        Translation3::new(0.2, -0.1, 2.0),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.015, -0.01, 0.3)),
    );
    // the camera 2 mm under the dome's centre, in the gel above its surface: nothing bends
    // between the lens and the pins, the rays are straight (--straight-rays)
    let mut s = Scene::with(lens, pose);
    s.layers = None;
    // the pins' angles off the optical axis, and the outermost
    let theta: Vec<f64> = s
        .tips
        .values()
        .map(|p| {
            let c = pose * fabkit_calibration::nalgebra::Point3::from(*p);
            c.coords.xy().norm().atan2(c.z)
        })
        .collect();
    let outer = theta.iter().copied().fold(0.0, f64::max);
    assert!(outer.to_degrees() > 55.0, "{}", outer.to_degrees());
    // plumb_bob: r_d = t (1 + k1 t^2 + k2 t^4 + k3 t^6), t = tan(theta), fitted to the
    // equidistant r_d = theta over 0..outer
    let samples: Vec<f64> = (1..=200).map(|i| outer * i as f64 / 200.0).collect();
    let a = DMatrix::from_fn(samples.len(), 3, |i, j| {
        let t = samples[i].tan();
        t.powi(2 * j as i32 + 3)
    });
    let b = DVector::from_fn(samples.len(), |i, _| samples[i] - samples[i].tan());
    let k = a.clone().svd(true, true).solve(&b, 1e-12).unwrap();
    let to = outer.tan();
    let fit_err_px =
        172.0 * (to * (1.0 + k[0] * to.powi(2) + k[1] * to.powi(4) + k[2] * to.powi(6)) - outer);
    // then 20 px off at the outer ring by k1, which moves the inner rings too (by t^3)
    let k1 = k[0] + (20.0 - fit_err_px) / (172.0 * to.powi(3));
    let file = Intrinsics {
        distortion: Distortion::PlumbBob([k1, k[1], 0.0, 0.0, k[2]]),
        ..lens
    };
    std::fs::write(
        s.path("cam.yaml"),
        write_camera(&file, CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    let off = CameraModel::new(file).unwrap();
    let true_cam = CameraModel::new(lens).unwrap();
    let off_at = |p: &Vector3<f64>| {
        let c = (pose * fabkit_calibration::nalgebra::Point3::from(*p)).coords;
        (off.project(&c).unwrap() - true_cam.project(&c).unwrap()).norm()
    };
    let worst = s.tips.values().map(off_at).fold(0.0, f64::max);
    // measured 20.76 px (the file was fitted to be about 20 px off there)
    assert!(
        (worst - 20.0).abs() < 1.0,
        "the file is {worst:.2} px off at the outer ring"
    );
    let mut names = Vec::new();
    for (k, ids) in s.plan.iter().enumerate() {
        let (reference, capture, _) = s.render(ids, 700 + k as u64);
        if k == 0 {
            save(&reference, &s.path("reference.png"), Kind::Gray8);
        }
        let name = format!("capture_{}.png", k + 1);
        save(&capture, &s.path(&name), Kind::Gray8);
        names.push(name);
    }
    let calibrate = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "calibrate",
            "extrinsics",
            "--camera",
            "cam.yaml",
            "--points",
            "fx/points/point_table.csv",
            "--capture-plan",
            "fx/points/capture_plan.csv",
            "--reference",
            "reference.png",
            "--straight-rays",
            "--out",
            out,
        ];
        args.extend_from_slice(extra);
        args.push("--images");
        args.extend(names.iter().map(String::as_str));
        run(s.dir.path(), &args, &[])
    };
    let o = calibrate("out", &[]);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{out}{err}");
    assert!(out.contains("RMS by polar angle: 0 deg "), "{out}");
    let j = json(&s.path("out/extrinsics.json"));
    let rings = j["residuals"]["by_polar_angle"].as_array().unwrap();
    assert_eq!(rings.len(), 5, "{rings:?}");
    let rms: Vec<f64> = rings
        .iter()
        .map(|r| r["rms_px"].as_f64().unwrap())
        .collect();
    assert!(
        rms[4] > 10.0 && rms[..3].iter().all(|&r| r < 2.0),
        "{rms:?}"
    );
    let warning = j["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .find(|w| w.contains("grow with the polar angle"))
        .unwrap_or_else(|| panic!("{}", j["warnings"]));
    assert!(warning.contains("--refine-intrinsics"), "{warning}");
    assert!(err.contains("grow with the polar angle"), "{err}");
    // before the outer ring is rejected the models fitted to every pin are compared: refined
    // k1 and k2 explain every pin (measured RMS 0.93 px, worst 1.37 px, BIC -16.4, against
    // the file's 4.29 px RMS, BIC 153.0) and are suggested, not taken (a change of the camera
    // file is the user's call)
    let c = &j["model_comparison"];
    assert_eq!(c["chosen"], "RANSAC", "{c}");
    let models = c["models"].as_array().unwrap();
    let (given, radial) = (&models[0], &models[1]);
    assert_eq!(
        (given["model"].as_str(), radial["model"].as_str()),
        (Some("as given"), Some("radial terms refined"))
    );
    assert!(
        radial["explains_every_pin"] == true
            && given["explains_every_pin"] == false
            && radial["bic"].as_f64() < given["bic"].as_f64(),
        "{c}"
    );
    assert!(
        err.contains("are explained by refining the lens's k1 and k2"),
        "{err}"
    );
    let inliers = j["residuals"]["inliers"].as_u64().unwrap();
    let threshold = j["residuals"]["ransac_threshold_px"].as_f64().unwrap();
    let (rot, tr) = pose_errors_from(&pose_of(&j), &pose);
    eprintln!("default: {inliers} inliers within {threshold:.2} px; pose off by {rot:.3} deg, {tr:.4} mm; rings {rms:?}");
    assert!(inliers >= 19, "{inliers} inliers within {threshold} px");
    // the wrong distortion trades against the camera's distance along its axis: 0.22 mm
    assert!(rot < 0.5 && tr < 0.4, "pose off by {rot} deg and {tr} mm");
    // refining the intrinsics over the pins kept, as the warning suggests, brings the pose
    // back (0.02 mm); the outer ring stays out, and the report says why
    let o = calibrate("refined", &["--refine-intrinsics"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let j = json(&s.path("refined/extrinsics.json"));
    let (rot2, tr2) = pose_errors_from(&pose_of(&j), &pose);
    eprintln!("refined: pose off by {rot2:.3} deg, {tr2:.4} mm");
    assert!(rot2 < 0.2 && tr2 < 0.25 * tr, "{rot2} deg, {tr2} mm");
    let warning = j["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .find(|w| w.contains("grow with the polar angle"))
        .unwrap_or_else(|| panic!("{}", j["warnings"]));
    assert!(
        warning.contains("the refined model still does not follow"),
        "{warning}"
    );
    // every pin still projects through the refined model (issue 97: refined over the inner
    // rings, the outer ring no longer projected and its RMS printed as 0)
    for ring in j["residuals"]["by_polar_angle"].as_array().unwrap() {
        assert_eq!(ring["projected"], ring["points"], "{ring}");
    }
}

fn pose_errors_from(pose: &Isometry3<f64>, truth: &Isometry3<f64>) -> (f64, f64) {
    (
        pose.rotation.angle_to(&truth.rotation).to_degrees(),
        (pose.translation.vector - truth.translation.vector).norm(),
    )
}

/// The pin dome's eight captures seen through R-Tac0's filling gel (its flat free surface at
/// the tube's mouth, z = -9 mm, n = 1.41), the camera 8.4 mm under it as issue 97 measured
/// the authors' (the skin then covers under half of the frame: the reference mask takes the
/// skin's level above Otsu's threshold): with `--design rtac0` every pin is found with its id
/// and kept, and the pose is as good as the pose solved through the gel from the imprints'
/// true centroids; with straight rays the camera comes out millimetres off at a low RMS
/// (issue 97's drifting camera).
#[test]
fn captures_through_the_gel_give_the_pose_with_the_design() {
    use fabkit_calibration::pnp::{pose_uncertainty_through, solve_pnp_through};
    use fabkit_calibration::refraction::Imaging;
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.02, -0.015, 0.4));
    let centre = Vector3::new(0.3, -0.2, -17.4);
    let pose = Isometry3::from_parts(Translation3::from(-(rot * centre)), rot);
    let mut s = Scene::with(intrinsics(), pose);
    s.layers = crate::calibrate_cli::layers_of("rtac0");
    let mut names = Vec::new();
    let mut true_centres: BTreeMap<(String, String), [f64; 2]> = BTreeMap::new();
    for (k, ids) in s.plan.iter().enumerate() {
        let seed = 1000 * crate::common::seed_set() + 700 + k as u64;
        let (reference, capture, centres) = s.render(ids, seed);
        if k == 0 {
            save(&reference, &s.path("reference.png"), Kind::Gray8);
        }
        let name = format!("capture_{}.png", k + 1);
        save(&capture, &s.path(&name), Kind::Gray8);
        for (id, c) in ids.iter().zip(centres) {
            true_centres.insert((name.clone(), id.clone()), c);
        }
        names.push(name);
    }
    let calibrate = |out: &str, extra: &[&str]| {
        let mut args = vec![
            "calibrate",
            "extrinsics",
            "--camera",
            "cam.yaml",
            "--points",
            "fx/points/point_table.csv",
            "--capture-plan",
            "fx/points/capture_plan.csv",
            "--reference",
            "reference.png",
            "--out",
            out,
        ];
        args.extend(extra);
        args.push("--images");
        args.extend(names.iter().map(String::as_str));
        run(s.dir.path(), &args, &[])
    };
    let o = calibrate("bent", &["--design", "rtac0"]);
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    assert!(
        text(&o.stdout).contains("imprints: 40 pins found in 8 of 8 captures"),
        "{}",
        text(&o.stdout)
    );
    let j = json(&s.path("bent/extrinsics.json"));
    assert_eq!(j["residuals"]["inliers"], 29);
    let found = observations(&s.path("bent/observations.csv"));
    assert_eq!(
        found.keys().collect::<Vec<_>>(),
        true_centres.keys().collect::<Vec<_>>()
    );
    let (mut sq, mut n) = (0.0, 0.0);
    for (key, t) in &true_centres {
        let f = found[key];
        sq += (f[0] - t[0]).powi(2) + (f[1] - t[1]).powi(2);
        n += 1.0;
    }
    let rms = (sq / n).sqrt();
    // the pose against the truth: the true centroids' pose through the gel, plus the
    // detection noise's Cramer-Rao allowance (6 sd at the centres' RMS error)
    let layers = s.layers.clone().unwrap();
    let through = Imaging::new(&s.camera, Some(&layers));
    let (pts, px) = s.tips_and_mean_centres(&true_centres);
    let from_true = solve_pnp_through(&through, &pts, &px, &PnpOptions::default())
        .unwrap()
        .t_cam_sensor;
    let u = pose_uncertainty_through(&through, &pts, &px, &vec![true; pts.len()], &pose).unwrap();
    let (rot_noise, t_noise) = u.rms_errors(rms);
    let err = |p: &Isometry3<f64>| {
        (
            p.rotation.angle_to(&pose.rotation).to_degrees(),
            (p.translation.vector - pose.translation.vector).norm(),
        )
    };
    let ((rot, t), (rot_true, t_true)) = (err(&pose_of(&j)), err(&from_true));
    eprintln!(
        "through the gel: centroids {rms:.3} px RMS; pose {rot:.4} deg, {t:.4} mm; true centroids' {rot_true:.4} deg, {t_true:.4} mm; allowance {:.4} deg, {:.4} mm",
        6.0 * rot_noise,
        6.0 * t_noise
    );
    // measured on seed sets 0 to 2: centroids 0.056 to 0.061 px RMS; 0.010 to 0.016 deg and
    // 0.538 to 0.539 mm from the truth, the true centroids' pose 0.005 deg and 0.527 mm (the
    // imprint's centroid is not the tip's image), the allowance 0.20 to 0.22 deg and 0.021 to
    // 0.023 mm
    assert!(
        rot <= rot_true + 6.0 * rot_noise && t <= t_true + 6.0 * t_noise,
        "{rot} deg, {t} mm"
    );

    assert!(!text(&o.stderr).contains("note: "), "{}", text(&o.stderr));
    assert_eq!(j["optical_path_from"], "--design rtac0");
    // the default command: the point table's design (its point_table.json) gives the same
    // optical path, the same pose, and a note says so
    let o = calibrate("default", &[]);
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    assert!(
        text(&o.stderr).contains("note: the rays bend at the interfaces of design rtac0, the point table's (fx/points/point_table.json): the gel's free surface at the core's open end; the core's inner face; the core's outer face; the outer face of transparent_gel (--straight-rays for straight rays)"),
        "{}",
        text(&o.stderr)
    );
    let d = json(&s.path("default/extrinsics.json"));
    assert_eq!(d["optical_path"], j["optical_path"]);
    assert_eq!(d["T_cam_sensor"], j["T_cam_sensor"]);
    // straight rays: the camera pulled towards the dome
    let o = calibrate("straight", &["--straight-rays"]);
    assert!(o.status.success(), "{}{}", text(&o.stdout), text(&o.stderr));
    assert!(!text(&o.stderr).contains("note: "), "{}", text(&o.stderr));
    let j = json(&s.path("straight/extrinsics.json"));
    assert!(j.get("optical_path").is_none());
    let c = &j["residuals"]["camera_centre_in_sensor_mm"];
    let closer = c[2].as_f64().unwrap() - centre.z;
    eprintln!(
        "straight rays: camera {closer:.2} mm closer, RMS {} px",
        j["rms_reprojection_error_px"]
    );
    // measured 5.74 mm closer at an RMS of 2.2 px on seed sets 0 to 2
    assert!(closer > 3.0, "{closer}");
}

/// The shading of [`every_artifact_through_the_gel_keeps_every_pin_with_its_id`] for the scene
/// `s`: `Shading::real_capture`, the Hertz halo and four dark notches beside the outer pins 22,
/// 24, 26 and 28.
fn every_artifact(s: &Scene) -> Shading {
    // the outer pins' azimuths and radii in the image (about its centre) at the true pose
    let through = s.imaging();
    let (r, t) = (
        *s.pose.rotation.to_rotation_matrix().matrix(),
        s.pose.translation.vector,
    );
    let polar = |id: &str| {
        let p = through.project(&r, &t, &s.tips[id]).unwrap();
        (
            (p.y - 239.5).atan2(p.x - 319.5),
            (p.y - 239.5).hypot(p.x - 319.5),
        )
    };
    let (a22, r22) = polar("22");
    // the skin's edge along pin 22's azimuth, from a render without notches (the tube's mouth
    // bounds the view there)
    let (reference, _, _) = s.render_with(&["22".to_string()], 1, &Shading::default());
    let edge = (0..400)
        .map(|k| 0.5 * k as f64)
        .filter(|rr| {
            let (u, v) = (319.5 + rr * a22.cos(), 239.5 + rr * a22.sin());
            u >= 0.0
                && v >= 0.0
                && u < 640.0
                && v < 480.0
                && reference.data[v.round() as usize * 640 + u.round() as usize] > 60.0
        })
        .fold(0.0, f64::max);
    // four slots 8 px wide, their middles 6 px beside pins 22, 24, 26 and 28, reaching as far
    // in as their centres (seen through the tube, the outer ring sits near the mouth's edge,
    // where a slot reaching past a pin's centre hides most of its imprint)
    Shading {
        grey_per_mm: 60.0,
        jpeg_quality: None, // the files are JPEG
        halo: 0.065,
        notches: 4,
        notch_phase_deg: (a22 + 6.0 / r22).to_degrees(),
        notch_width_px: 8.0,
        notch_depth_px: edge - r22,
        ..Shading::real_capture()
    }
}

/// Issue 97's synthetic done-when: the eight captures seen through R-Tac0's gel with every
/// artifact of the real ones: `Shading::real_capture` (saturated moving LED ring, gain drift,
/// side light, specks, a scratch, JPEG), a faint Hertz halo around each imprint that joins
/// neighbouring imprints of a capture into one spot (ring 3 and 4 share an azimuth, as on the
/// real dome; 0.065 of Hertz's skirt: four to five captures join two or three imprints), dark LED
/// notches at the rim that clip four of the outer imprints, and the dome re-seated by up to
/// 0.1 mm per capture. The default command keeps every capture's five pins with the right ids
/// and the pose is within 1.2 times the true centroids' error from the truth; `--seed` 0 to 11
/// and the captures in reverse order give the same pose.
#[test]
fn every_artifact_through_the_gel_keeps_every_pin_with_its_id() {
    let s = Scene::new();
    let shading = every_artifact(&s);
    let mut names = Vec::new();
    let mut true_centres: BTreeMap<(String, String), [f64; 2]> = BTreeMap::new();
    for (k, ids) in s.plan.iter().enumerate() {
        // re-seated: 0, 0.05 or 0.1 mm off, in a direction that turns from capture to capture
        let a = (137.5 * k as f64).to_radians();
        let shift = Vector3::new(a.cos(), a.sin(), 0.0) * (0.05 * (k % 3) as f64);
        let seed = 1000 * crate::common::seed_set() + 900 + k as u64;
        let (reference, capture, centres) = s.render_seated(ids, seed, &shading, &shift);
        if k == 0 {
            save(&reference, &s.path("reference.jpg"), Kind::Jpeg);
        }
        let name = file_name(ids, "jpg");
        save(&capture, &s.path(&name), Kind::Jpeg);
        for (id, c) in ids.iter().zip(centres) {
            true_centres.insert((name.clone(), id.clone()), c);
        }
        names.push(name);
    }
    let o = calibrate_by_file_names(&s, "reference.jpg", &names);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{out}{err}");
    assert!(
        out.contains("imprints: 40 pins found in 8 of 8 captures")
            && out.contains("0 captures left out")
            && out.contains("0 pins missing"),
        "{out}"
    );
    let j = json(&s.path("out/extrinsics.json"));
    assert_eq!(j["residuals"]["inliers"], 29, "{out}");
    // the joined imprints were cut in two for the plan's pins (measured 4 to 5 captures on seed
    // sets 0 to 2)
    let splits: Vec<&serde_json::Value> = j["captures"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|c| c["split"].as_array().into_iter().flatten())
        .collect();
    assert!(splits.len() >= 3, "{splits:?}\n{err}");
    // every pin with its id, at its imprint: the clipped ones within 2.5 px (measured worst
    // 1.62 to 1.73 px on seed sets 0 to 2: the part the notch hides is a disc's, the outer
    // imprints are ellipses), the others within 0.5 px (measured 0.24 px or less); each nearer
    // its own true centre than
    // any other pin's of the capture
    let found = observations(&s.path("out/observations.csv"));
    assert_eq!(
        found.keys().collect::<Vec<_>>(),
        true_centres.keys().collect::<Vec<_>>()
    );
    let mut worst = [0.0f64; 2];
    for ((name, id), t) in &true_centres {
        let f = found[&(name.clone(), id.clone())];
        let e = (f[0] - t[0]).hypot(f[1] - t[1]);
        let clipped = ["22", "24", "26", "28"].contains(&id.as_str());
        worst[usize::from(clipped)] = worst[usize::from(clipped)].max(e);
        assert!(
            e < if clipped { 2.5 } else { 0.5 },
            "{name} pin {id}: {e:.2} px off"
        );
        let nearest_other = true_centres
            .iter()
            .filter(|((n, i), _)| n == name && i != id)
            .map(|(_, o)| (f[0] - o[0]).hypot(f[1] - o[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(
            e < nearest_other,
            "{name} pin {id}: {e:.2} px against {nearest_other:.2}"
        );
    }
    // the pose: within 1.2 times the true centroids' pose's error (measured on seed sets 0 to
    // 2: 0.218 to 0.261 deg and 0.525 to 0.532 mm against 0.276 deg and 0.519 mm; the true
    // centroids are off the table's tips by the re-seating and by the imprint's core centroid
    // against the tip's image)
    let (rot_true, t_true) = s.pose_errors(&s.pose_from_true_centres(&true_centres));
    let (rot, t) = s.pose_errors(&pose_of(&j));
    eprintln!(
        "every artifact: {} splits; worst pin {:.2} px (clipped {:.2} px); pose {rot:.3} deg {t:.3} mm, the true centroids' {rot_true:.3} deg {t_true:.3} mm",
        splits.len(),
        worst[0],
        worst[1]
    );
    assert!(
        rot <= 1.2 * rot_true && t <= 1.2 * t_true,
        "pose {rot:.4} deg {t:.4} mm from the truth; the true centroids' {rot_true:.4} deg {t_true:.4} mm"
    );
    // the same pose for --seed 0 to 11 and for the captures in reverse order (issue 97's
    // done-when: within 1e-9; the per-pin averages sum in another order, about 1e-14 px)
    let reversed: Vec<String> = names.iter().rev().cloned().collect();
    for (k, (extra, order)) in (0..12)
        .map(|seed| (vec!["--seed".to_string(), seed.to_string()], &names))
        .chain([(Vec::new(), &reversed)])
        .enumerate()
    {
        let out = format!("again_{k}");
        let mut args = vec![
            "calibrate",
            "extrinsics",
            "--camera",
            "cam.yaml",
            "--points",
            "fx/points/point_table.csv",
            "--reference",
            "reference.jpg",
            "--out",
            &out,
        ];
        args.extend(extra.iter().map(String::as_str));
        args.push("--images");
        args.extend(order.iter().map(String::as_str));
        let o = run(s.dir.path(), &args, &[]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let j2 = json(&s.path(&format!("{out}/extrinsics.json")));
        let (r, t) = pose_errors_from(&pose_of(&j2), &pose_of(&j));
        assert!(r < 1e-9 && t < 1e-9, "{extra:?}: {r} deg, {t} mm apart");
    }
}

/// Issue 97's done-when on subsets, synthetic: 30 captures through R-Tac0's gel and tube with
/// every artifact of [`every_artifact_through_the_gel_keeps_every_pin_with_its_id`] but the
/// re-seating (the plan's eight captures cycled, each with its own noise, specks, gain and
/// LED ring); the default command on eight subsets of 20 of them (a fixed schedule) gives
/// poses within 0.05 deg of the one from all 30. Re-seating the dome by up to 0.1 mm per
/// capture moves it by about 0.3 deg: per-capture seating is another issue's.
#[test]
fn subsets_of_20_captures_give_the_pose_of_all_30_within_005_deg() {
    let s = Scene::new();
    let shading = every_artifact(&s);
    let mut names = Vec::new();
    for k in 0..30 {
        let ids = &s.plan[k % s.plan.len()];
        let seed = 1000 * crate::common::seed_set() + 300 + k as u64;
        let (reference, capture, _) = s.render_seated(ids, seed, &shading, &Vector3::zeros());
        if k == 0 {
            save(&reference, &s.path("reference.jpg"), Kind::Jpeg);
        }
        let name = format!("capture_{k:02}.jpg");
        save(&capture, &s.path(&name), Kind::Jpeg);
        names.push(name);
    }
    let solve = |idx: &[usize], out: &str| -> Isometry3<f64> {
        let mut plan = String::from("capture,id,ring\n");
        for (j, &k) in idx.iter().enumerate() {
            for id in &s.plan[k % s.plan.len()] {
                plan.push_str(&format!("{},{id},0\n", j + 1));
            }
        }
        let plan_file = format!("{out}_plan.csv");
        std::fs::write(s.path(&plan_file), plan).unwrap();
        let mut args = vec![
            "calibrate",
            "extrinsics",
            "--camera",
            "cam.yaml",
            "--points",
            "fx/points/point_table.csv",
            "--capture-plan",
            &plan_file,
            "--reference",
            "reference.jpg",
            "--out",
            out,
            "--images",
        ];
        args.extend(idx.iter().map(|&k| names[k].as_str()));
        let o = run(s.dir.path(), &args, &[]);
        assert!(o.status.success(), "{out}: {}", text(&o.stderr));
        pose_of(&json(&s.path(&format!("{out}/extrinsics.json"))))
    };
    let all = solve(&(0..30).collect::<Vec<_>>(), "all");
    let mut worst = 0.0f64;
    for k in 0..8 {
        // leaves out ten captures spread over the thirty, a different ten each time
        let idx: Vec<usize> = (0..30).filter(|i| (i * 7 + k * 3) % 30 >= 10).collect();
        assert_eq!(idx.len(), 20);
        let p = solve(&idx, &format!("subset_{k}"));
        worst = worst.max(p.rotation.angle_to(&all.rotation).to_degrees());
    }
    eprintln!("subsets of 20: up to {worst:.4} deg from the pose of all 30");
    // measured on seed sets 0 to 2: 0.027, 0.044 and 0.019 deg (the goal: 0.05 deg)
    assert!(worst < 0.05, "{worst} deg");
}
