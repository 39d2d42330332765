//! Criterion benchmark of the pin-imprint detector (`fabkit_calibration::imprints`) on one
//! synthetic 640 x 480 capture and its reference (the R-Tac0 skin seen by the benchmark
//! fisheye, 5 pins pressed 1 mm, blur, vignetting, LED reflections, noise of 2 grey levels;
//! rendered once, outside the timing): `detect` with the mask given, and `reference_mask`
//! plus `detect` (what a capture costs when its reference is new). One thread: the detector
//! does not use rayon.
//!
//! And the whole 29-pin calibration from images (`calibrate_extrinsics` with capture images,
//! as `fabkit calibrate extrinsics --images ... --reference ...` less writing the output
//! folder): the R-Tac0 pin dome's point table and capture plan (`--pins-preset rtac0`), its
//! eight captures rendered (one pin per ring, pressed to the table's tips) and saved as 8-bit
//! PNG, the reference too; timed: reading the nine PNGs, detection, ids, the solve, the report
//! and the overlays. Figures: docs/src/benchmarks.md, "Extrinsics: accuracy and speed".

use criterion::{criterion_group, criterion_main, Criterion};
use fabkit_calibration::groundtruth::surface::ReferenceSurface;
use fabkit_calibration::imprints::synthetic::{render, render_through, ring_pins, Shading};
use fabkit_calibration::imprints::{detect, reference_mask, DetectParams};
use fabkit_calibration::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use fabkit_calibration::refraction::OpticalLayers;
use fabkit_calibration::synthetic::benchmark_camera;
use fabkit_calibration::{calibrate_extrinsics, ExtrinsicsJob};

fn bench(c: &mut Criterion) {
    let design = fabkit::designs::library::load("rtac0").unwrap();
    let surface = ReferenceSurface::of(&design.body).unwrap();
    let pose = Isometry3::from_parts(
        Translation3::new(0.3, -0.2, 10.4),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.02, -0.015, 0.4)),
    );
    let pins = ring_pins(0.0, 1.0);
    let r = render(
        &benchmark_camera(),
        &pose,
        &surface,
        &pins,
        &Shading::real_capture(),
        1,
    );
    let mask = reference_mask(&r.reference, 255.0, 4);
    let p = DetectParams::default();
    // the five pins, and the specks and the scratch of a real capture
    assert!(
        detect(&r.reference, &r.capture, Some(&mask), &p)
            .unwrap()
            .len()
            > 5
    );
    let mut g = c.benchmark_group("imprints_640x480");
    g.sample_size(50);
    g.bench_function("detect", |b| {
        b.iter(|| detect(&r.reference, &r.capture, Some(&mask), &p).unwrap())
    });
    g.bench_function("mask_and_detect", |b| {
        b.iter(|| {
            let m = reference_mask(&r.reference, 255.0, 4);
            detect(&r.reference, &r.capture, Some(&m), &p).unwrap()
        })
    });
    g.finish();
}

/// The R-Tac0 fixtures' point table and plan, the camera file and the nine images in `dir`:
/// with `path`, seen through it (R-Tac0's gel and glass tube) from 17.4 mm under the dome's
/// centre, else with straight rays from 10.4 mm under it.
fn calibration_inputs(
    dir: &std::path::Path,
    path: Option<&fabkit::designs::optics::OpticalPath>,
) -> Vec<std::path::PathBuf> {
    use fabkit::calibration::overlay::encode_gray8;
    use fabkit::calibration::tables::{read_capture_plan, read_point_table, PointsFrom};
    use fabkit::calibration::{write_camera, CameraFileFormat};
    use fabkit::fixtures::params::{apply_pin_preset, FixtureParams};
    use fabkit_calibration::imprints::synthetic::Pin;
    let design = fabkit::designs::library::load("rtac0").unwrap();
    let mut params = FixtureParams::default();
    apply_pin_preset(&mut params, "rtac0").unwrap();
    let tol =
        fabkit::designs::ChordTolerance::new(fabkit::designs::ChordTolerance::DEFAULT_MM).unwrap();
    let set = fabkit::fixtures::build_fixtures(&design, &params, tol, u64::MAX, "bench").unwrap();
    for (name, bytes) in &set.files {
        if name.starts_with("points/") {
            std::fs::create_dir_all(dir.join("points")).unwrap();
            std::fs::write(dir.join(name), bytes).unwrap();
        }
    }
    let cam = benchmark_camera();
    std::fs::write(
        dir.join("cam.yaml"),
        write_camera(cam.intrinsics(), CameraFileFormat::OpenCvYaml),
    )
    .unwrap();
    let table = read_point_table(&dir.join("points/point_table.csv"), PointsFrom::Tip).unwrap();
    let plan = read_capture_plan(&dir.join("points/capture_plan.csv")).unwrap();
    let surface = ReferenceSurface::of(&design.body).unwrap();
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.02, -0.015, 0.4));
    let pose = match path {
        None => Isometry3::from_parts(Translation3::new(0.3, -0.2, 10.4), rot),
        Some(_) => Isometry3::from_parts(
            Translation3::from(-(rot * Vector3::new(0.3, -0.2, -17.4))),
            rot,
        ),
    };
    let layers = path.map(|p| OpticalLayers::from_optical_path(p).unwrap());
    let shading = Shading {
        grey_per_mm: 60.0,
        ..Shading::default()
    };
    let png = |img: &fabkit_calibration::imprints::GrayImage, path: &std::path::Path| {
        let g8: Vec<u8> = img
            .data
            .iter()
            .map(|g| g.round().clamp(0.0, 255.0) as u8)
            .collect();
        let bytes = encode_gray8(img.width as u32, img.height as u32, &g8).unwrap();
        std::fs::write(path, bytes).unwrap();
    };
    let mut captures = Vec::new();
    for (k, ids) in plan.captures.iter().enumerate() {
        let pins: Vec<Pin> = ids
            .iter()
            .map(|id| {
                let tip = table.rows.iter().find(|r| &r.0 == id).unwrap().1;
                let c = tip + tip.normalize() * 0.8;
                Pin {
                    centre_mm: [c.x, c.y, c.z],
                    radius_mm: 0.8,
                }
            })
            .collect();
        let r = render_through(
            &cam,
            &pose,
            layers.as_ref(),
            &surface,
            &pins,
            &shading,
            k as u64,
        );
        if k == 0 {
            png(&r.reference, &dir.join("reference.png"));
        }
        let path = dir.join(format!("capture_{}.png", k + 1));
        png(&r.capture, &path);
        captures.push(path);
    }
    captures
}

fn bench_calibration(c: &mut Criterion) {
    let mut g = c.benchmark_group("calibration_from_images");
    g.sample_size(20);
    let tol =
        fabkit::designs::ChordTolerance::new(fabkit::designs::ChordTolerance::DEFAULT_MM).unwrap();
    let design = fabkit::designs::library::load("rtac0").unwrap();
    let path = fabkit::designs::optics::optical_path_of_design(&design, tol).unwrap();
    for (name, path) in [
        ("rtac0_29_pins_8_captures", None),
        ("rtac0_29_pins_8_captures_through_the_tube", Some(&path)),
    ] {
        let d = tempfile::tempdir().unwrap();
        let job = calibration_job(d.path(), path);
        g.bench_function(name, |b| b.iter(|| calibrate_extrinsics(&job).unwrap()));
    }
    g.finish();
}

/// The job of [`bench_calibration`] on [`calibration_inputs`] in `dir`, checked once.
fn calibration_job(
    dir: &std::path::Path,
    path: Option<&fabkit::designs::optics::OpticalPath>,
) -> ExtrinsicsJob {
    use fabkit_calibration::capture_images::CaptureImages;
    use fabkit_calibration::{Observed, PointsFrom};
    let captures = calibration_inputs(dir, path);
    let job = ExtrinsicsJob {
        camera: dir.join("cam.yaml"),
        camera_model: None,
        points: dir.join("points/point_table.csv"),
        points_from: PointsFrom::Tip,
        observations: Observed::Images(CaptureImages {
            captures,
            reference: dir.join("reference.png"),
        }),
        capture_plan: Some(dir.join("points/capture_plan.csv")),
        image: None,
        ransac: Some(Default::default()),
        refine_intrinsics: None,
        optical_path: path.cloned(),
        optical_path_from: path.map(|_| "design rtac0".into()),
        refine_optical_path: false,
        command_line: "bench".into(),
    };
    let out = calibrate_extrinsics(&job).unwrap();
    assert_eq!(out.report.residuals.observations, 29);
    assert!(out.report.warnings.is_empty(), "{:?}", out.report.warnings);
    job
}

criterion_group!(benches, bench, bench_calibration);
criterion_main!(benches);
