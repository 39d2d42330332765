//! Every library design renders a reference and an indented image from its own optics (the
//! lights of its housing, casing, shaft body or fingertip base, or its `optics.lights`): seen
//! from a camera on its axis under the base plane, with a 3 mm sphere tip pressed 1 mm into the
//! skin part-way to its rim.

use fabkit_calibration::groundtruth::exact::ExactPrimitives;
use fabkit_calibration::groundtruth::shading::{frame_radiance, Imaging};
use fabkit_calibration::groundtruth::{indented_hits, reference_hits, Scene};
use fabkit_calibration::synthetic::benchmark_intrinsics;
use fabkit_calibration::CameraModel;
use fabkit_designs::optics::of_design;
use fabkit_designs::primitives::Primitive;
use fabkit_designs::{library, ChordTolerance};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

#[test]
fn every_library_design_renders_a_reference_and_an_indented_image() {
    let cam = CameraModel::new(benchmark_intrinsics()).unwrap();
    for (name, _) in library::LIBRARY {
        let design = library::load(name).unwrap();
        let optics = of_design(&design, ChordTolerance::new(0.01).unwrap())
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(!optics.lights.is_empty(), "{name}");
        // on the axis, 8 mm under the base plane, looking along +z
        let base = design.body.base_z_mm();
        let pose = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, -(base - 8.0)),
            UnitQuaternion::identity(),
        );
        let scene = Scene::new(&design, &cam, &pose, "pose").unwrap_or_else(|e| panic!("{e}"));
        let reference = reference_hits(&scene.rays, &scene.surface);
        let seen = reference.valid_count();
        // measured 80,692 to 242,988 pixels over the library's designs
        assert!(seen > 20_000, "{name}: {seen} pixels see the skin");
        // the tip pressed 1 mm in along the skin's normal, 60 % of the way from the image
        // centre to the rim along the middle row (off the pole, where side lights graze)
        let row = 240 * 640;
        let rim = (320..640)
            .take_while(|&u| reference.t_mm[row + u].is_finite())
            .last()
            .unwrap();
        let k = row + 320 + (rim - 320) * 6 / 10;
        let (o, d, t) = (scene.rays.origin_mm, scene.rays.dirs[k], reference.t_mm[k]);
        let n = reference.normal[k];
        let tip = ExactPrimitives::new(&[Primitive::Sphere {
            centre_mm: std::array::from_fn(|c| o[c] + t * d[c] + 2.0 * n[c]),
            radius_mm: 3.0,
        }])
        .unwrap();
        let pressed = indented_hits(&scene.rays, &reference, &tip, scene.surface.base_z_mm());
        let imaging = Imaging::new(optics, [319.5, 239.5], &scene.rays, &reference);
        let a = imaging.image(&scene.rays, &reference, &reference, None, 0);
        let b = imaging.image(&scene.rays, &reference, &pressed, Some(&tip), 1);
        // the skin is lit: most of the pixels that see it are above the read noise
        let lit = (0..a.len())
            .filter(|&i| reference.t_mm[i].is_finite() && a[i].iter().any(|&c| c > 3))
            .count();
        let lit_pressed = (0..b.len())
            .filter(|&i| reference.t_mm[i].is_finite() && b[i].iter().any(|&c| c > 3))
            .count();
        // measured 0.65 to 1 of the seen pixels
        assert!(
            lit as f64 > 0.5 * seen as f64 && lit_pressed as f64 > 0.5 * seen as f64,
            "{name}: {lit} and {lit_pressed} of {seen} skin pixels lit"
        );
        // the imprint shows where the tip pushes the skin in, in the radiance before the
        // camera's noise: changed by more than 2 % on most contact pixels, unchanged on most
        // pixels away from it (bar the tip's shadow)
        let ra = frame_radiance(&scene.rays, None, &reference, &imaging.optics, None);
        let rb = frame_radiance(
            &scene.rays,
            Some(&reference),
            &pressed,
            &imaging.optics,
            Some(&tip),
        );
        let changed = |i: usize| (ra[i][1] - rb[i][1]).abs() > 0.02 * ra[i][1].abs();
        let (mut contact, mut on, mut away, mut off) = (0, 0, 0, 0);
        for i in 0..a.len() {
            if !reference.t_mm[i].is_finite() {
                continue;
            }
            if pressed.contact[i] {
                contact += 1;
                on += usize::from(changed(i));
            } else {
                away += 1;
                off += usize::from(changed(i));
            }
        }
        eprintln!("{name}: lit {lit} of {seen}; {on} of {contact} contact pixels change, {off} of {away} away");
        assert!(contact > 50, "{name}: {contact} contact pixels");
        assert!(
            2 * on > contact,
            "{name}: {on} of {contact} contact pixels change"
        );
        assert!(
            off * 10 < away,
            "{name}: {off} of {away} pixels change away from the tip"
        );
    }
}

/// A folder given where an image is read (a board press's `--images caps`, a reference) is
/// named as a folder with how to give its images, not as an undecodable file.
#[test]
fn a_folder_given_as_an_image_is_named_as_one() {
    let d = tempfile::tempdir().unwrap();
    let caps = d.path().join("caps");
    std::fs::create_dir(&caps).unwrap();
    let e =
        fabkit_calibration::capture_images::read_gray(&caps, "--images", (640, 480), "cam.yaml")
            .unwrap_err()
            .to_string();
    assert_eq!(
        e,
        format!(
            "--images = {}: is a folder, not an image: give the capture images themselves (as {}/*.png, which the shell expands in name order)",
            caps.display(),
            caps.display()
        )
    );
}
