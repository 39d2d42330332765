//! A flat sensor's camera from a board press (calibration/src/board.rs) on the real 9DTact
//! captures (tests/data/9dtact_sensor1/camera_calibration: the 7 x 9 board at 2.5 mm pressed
//! in, its reference, and the authors' result).

use fabkit_calibration::board::*;
use fabkit_calibration::imprints::GrayImage;
use fabkit_calibration::tables::PointTable;

fn load(name: &str) -> GrayImage {
    load_turned(name, BoardTurn::Deg0)
}

/// The capture `name` turned as a camera turned by `turn` about its optical axis would see it:
/// the image crate's `rotate90` (clockwise as shown), `rotate180` or `rotate270`.
fn load_turned(name: &str, turn: BoardTurn) -> GrayImage {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/9dtact_sensor1/camera_calibration");
    let i = image::open(dir.join(name)).unwrap();
    let i = match turn {
        BoardTurn::Deg0 => i,
        BoardTurn::Deg90 => i.rotate90(),
        BoardTurn::Deg180 => i.rotate180(),
        BoardTurn::Deg270 => i.rotate270(),
    }
    .into_luma8();
    GrayImage {
        width: i.width() as usize,
        height: i.height() as usize,
        data: i.into_raw().into_iter().map(f32::from).collect(),
    }
}

/// The board's point table as `fabkit fixtures ninedtact` writes it: ids 1..63 row by row
/// from -y, the contact face at z = 2.8 mm.
fn ninedtact_board() -> PointTable {
    crate::common::grid_table("board_table.csv", 7, 9, 2.5, 2.8)
}

/// The authors' result for this sensor (position_scale.npy): the centre bump's row and
/// column, px, and mm per px.
const AUTHORS_CENTRE_ROW_COL_PX: (f64, f64) = (240.0, 327.0);
const AUTHORS_MM_PER_PX: f64 = 0.0510150969;

fn solved() -> (BoardGrid, GridFind, BoardCamera) {
    let grid = board_grid(&ninedtact_board()).unwrap();
    let (_, find) = find_bumps(&load("ref.png"), &load("sample.png"), &grid, "sample.png").unwrap();
    let bc = solve_board_camera(&grid, &find, (640, 480), 11.548).unwrap();
    (grid, find, bc)
}

/// The real board press: all 63 bumps found, none left over, each with its grid place: along
/// every row u grows with the column and along every column v with the row (the image's u
/// runs along x, v along y), and the authors' centre bump (row 240, column 327 px) is the
/// grid's middle one, id 32, within a pixel.
#[test]
fn the_real_board_press_gives_every_bump_its_id() {
    let (grid, find, _) = solved();
    assert_eq!(find.found.len(), 63, "missing {:?}", find.missing);
    assert!(find.missing.is_empty() && find.extra.is_empty(), "{find:?}");
    assert!(find.notes.is_empty(), "{:?}", find.notes);
    let at = |r: u32, c: u32| {
        find.found
            .iter()
            .find(|b| b.row == r && b.column == c)
            .unwrap()
    };
    for r in 0..grid.rows {
        for c in 0..grid.columns {
            let b = at(r, c);
            assert_eq!(b.id, (r * 9 + c + 1).to_string());
            if c > 0 {
                assert!(b.u_px > at(r, c - 1).u_px + 30.0, "{b:?}");
            }
            if r > 0 {
                assert!(b.v_px > at(r - 1, c).v_px + 30.0, "{b:?}");
            }
        }
    }
    let mid = at(3, 4);
    assert_eq!(mid.id, "32");
    let (row, col) = AUTHORS_CENTRE_ROW_COL_PX;
    assert!(
        (mid.v_px - row).abs() < 1.0 && (mid.u_px - col).abs() < 1.0,
        "{mid:?}"
    );
}

/// The camera solved from the real press: the scale at the centre bump as the authors measure
/// it (the pitch over the mean distance to its four neighbours, whole-pixel centres) within
/// 1.5 % of theirs, 0.05102 mm per px (measured 0.0508, 0.4 % off); the local scale of the
/// solved model there is larger (0.0530: the distortion stretches the image outwards, by
/// k1 r^2 = 2.8 % at a neighbour's 49 px, so the neighbours' mean spacing exceeds the local
/// one). The RMS reprojection error is 1.16 px: the issue asks 0.5, which these centres do
/// not allow: a 5th-degree polynomial map of the plane to the image (42 coefficients, any
/// smooth lens) leaves 0.70 px, so the centres scatter by about 0.85 px about any smooth
/// model (the bumps' print, the imprints' shading; numpy, see the issue note). The bound
/// here is 1.3 px. The principal point trades against the plane's offset and is held at the
/// image's centre, the focal length against its distance (held where it puts the plane 11.548
/// mm away, as the design's housing gives it); k1 and k2 are determined (k1 = 0.55 +- 0.04).
#[test]
fn the_real_board_press_gives_the_authors_scale() {
    let (grid, find, bc) = solved();
    let mid = find.found.iter().find(|b| b.id == "32").unwrap();
    let near = |r: u32, c: u32| {
        let b = find
            .found
            .iter()
            .find(|b| b.row == r && b.column == c)
            .unwrap();
        (b.u_px.round() - mid.u_px.round()).hypot(b.v_px.round() - mid.v_px.round())
    };
    let mean = (near(2, 4) + near(4, 4) + near(3, 3) + near(3, 5)) / 4.0;
    let authors_way = grid.pitch_mm / mean;
    assert!(
        (authors_way / AUTHORS_MM_PER_PX - 1.0).abs() < 0.015,
        "{authors_way} mm per px"
    );
    let local = mm_per_px_at(
        &bc,
        grid.plane_z_mm,
        nalgebra::Vector2::new(mid.u_px, mid.v_px),
    )
    .unwrap();
    assert!(local > authors_way && local < 1.06 * authors_way, "{local}");
    assert!(bc.rms_px < 1.3, "RMS {} px", bc.rms_px);
    let k1 = bc.parameters.iter().find(|p| p.name == "k1").unwrap();
    assert!(
        k1.held.is_none() && k1.std.unwrap() < 0.2 && k1.value > 0.5,
        "{k1:?}"
    );
    for name in ["fx", "fy"] {
        let f = bc.parameters.iter().find(|p| p.name == name).unwrap();
        assert!(f.held.as_deref().unwrap().contains("distance"), "{f:?}");
    }
    // the map from pixels to the plane takes the centre bump's pixel to its point (0, 0), to
    // within its reprojection error and the pixel's rounding at the local scale
    let map = pixel_to_plane_mm(&bc, grid.plane_z_mm);
    let (u, v) = (mid.u_px.round() as usize, mid.v_px.round() as usize);
    let (x, y) = (map[(v * 640 + u) * 2], map[(v * 640 + u) * 2 + 1]);
    let k = find.found.iter().position(|b| b.id == "32").unwrap();
    let within = (bc.residuals_px[k].norm() + 0.71) * local;
    assert!(
        f64::from(x).hypot(f64::from(y)) < within,
        "({x}, {y}) against {within} mm"
    );
    assert!(map.iter().all(|m| m.is_finite()), "a pixel off the plane");
}

/// Where pixel `(u, v)` of a `w` x `h` image lands when the image is turned by `turn` (the
/// image crate's rotate90, rotate180, rotate270), px.
fn turned_px(turn: BoardTurn, (w, h): (u32, u32), (u, v): (f64, f64)) -> (f64, f64) {
    let (w, h) = (f64::from(w) - 1.0, f64::from(h) - 1.0);
    match turn {
        BoardTurn::Deg0 => (u, v),
        BoardTurn::Deg90 => (h - v, u),
        BoardTurn::Deg180 => (w - u, h - v),
        BoardTurn::Deg270 => (v, w - u),
    }
}

/// The real press with the camera turned about its optical axis: the reference and the
/// capture turned by a quarter, a half and three quarters (the image crate's rotate90,
/// rotate180, rotate270; 480 x 640 px at a quarter turn, the 7 x 9 board 9 tall and 7 wide),
/// calibrated with the matching `BoardTurn`: all 63 bumps found with no spot left over, each
/// id at the turned pixel of that id in the unturned press (within 0.01 px: the detector is
/// the same on the turned pixels); the RMS reprojection error within 0.05 px of the unturned
/// solve's (1.2338 px here, the turned ones within 1e-4 of it); and the solved T_cam_sensor is
/// the unturned one followed by the turn about the camera's z: the rotation between the two
/// poses is about z by the turn within 0.1 deg (1e-4 measured), with under 0.1 deg about x
/// and y (1e-4 measured), and the camera's centre in the sensor frame within 0.01 mm of the
/// unturned one's (3e-5 mm measured). The quarter turn calibrated as unturned is refused by
/// the image, naming the turns that fit.
#[test]
fn the_real_board_press_turned_in_the_image_gives_the_same_ids_and_camera() {
    use nalgebra::{UnitQuaternion, Vector3};
    let (grid, find0, bc0) = solved();
    for turn in [BoardTurn::Deg90, BoardTurn::Deg180, BoardTurn::Deg270] {
        let (reference, capture) = (
            load_turned("ref.png", turn),
            load_turned("sample.png", turn),
        );
        let size = (capture.width as u32, capture.height as u32);
        let found = find_bumps_in_captures_turned(
            &reference,
            &[("sample.png".into(), capture)],
            &grid,
            None,
            turn,
        )
        .unwrap();
        let find = &found.find;
        let t = turn.deg();
        assert_eq!(find.found.len(), 63, "{t} deg: missing {:?}", find.missing);
        assert!(
            find.missing.is_empty() && find.extra.is_empty(),
            "{t} deg: {find:?}"
        );
        for b0 in &find0.found {
            let b = find.found.iter().find(|b| b.id == b0.id).unwrap();
            let (u, v) = turned_px(turn, (640, 480), (b0.u_px, b0.v_px));
            assert!(
                (b.u_px - u).hypot(b.v_px - v) < 0.01 && (b.row, b.column) == (b0.row, b0.column),
                "{t} deg: {b:?} against {b0:?} turned to ({u}, {v})"
            );
        }
        let bc = solve_board_camera(&grid, find, size, 11.548).unwrap();
        assert!(
            (bc.rms_px - bc0.rms_px).abs() < 0.05,
            "{t} deg: RMS {} px against {} unturned",
            bc.rms_px,
            bc0.rms_px
        );
        let between: UnitQuaternion<f64> =
            bc.t_cam_sensor.rotation * bc0.t_cam_sensor.rotation.inverse();
        let m = between.to_rotation_matrix();
        let about_z = m[(1, 0)].atan2(m[(0, 0)]).to_degrees();
        let off = (f64::from(t) - about_z).rem_euclid(360.0);
        let off = off.min(360.0 - off);
        let tilt = m[(2, 2)].clamp(-1.0, 1.0).acos().to_degrees();
        assert!(
            off < 0.1 && tilt < 0.1,
            "{t} deg: turned {about_z} deg about z, {tilt} deg off it"
        );
        let centre = |p: &nalgebra::Isometry3<f64>| p.inverse().translation.vector;
        let moved: Vector3<f64> = centre(&bc.t_cam_sensor) - centre(&bc0.t_cam_sensor);
        assert!(
            moved.norm() < 0.01,
            "{t} deg: the camera's centre moved {moved:?} mm"
        );
        eprintln!(
            "{t} deg: RMS {:.4} px (unturned {:.4}), about z {about_z:.4} deg, tilt {tilt:.5} deg, centre moved {:.2e} mm",
            bc.rms_px,
            bc0.rms_px,
            moved.norm()
        );
    }
    // the quarter turn taken as unturned: 7 wide and 9 tall, larger than the board's 7 rows
    let err = find_bumps(
        &load_turned("ref.png", BoardTurn::Deg90),
        &load_turned("sample.png", BoardTurn::Deg90),
        &grid,
        "sample.png",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("7 wide")
            && err.contains("9 tall")
            && err.contains("--board-turn 90 or 270 fits"),
        "{err}"
    );
}

/// `--board-turn` takes 0, 90, 180 and 270 and refuses anything else naming the value and the
/// rule (a multiple of 90 outside them with its equivalent).
#[test]
fn board_turns_other_than_quarter_turns_are_refused() {
    for t in BoardTurn::ALL {
        assert_eq!(BoardTurn::from_deg(f64::from(t.deg())).unwrap(), t);
    }
    for (deg, told) in [
        (45.0, "--board-turn = 45: must be 0, 90, 180 or 270"),
        (-90.0, "(-90 is 270)"),
        (360.0, "(360 is 0)"),
        (90.5, "--board-turn = 90.5"),
        (f64::NAN, "--board-turn = NaN"),
    ] {
        let e = BoardTurn::from_deg(deg).unwrap_err().to_string();
        assert!(e.contains(told), "{deg}: {e}");
    }
}

/// A synthetic press (calibration/src/board/synthetic.rs) of 9DTact's board seen by a camera
/// turned about its optical axis: 640 x 640 px (so that the board fits either way), f = 290
/// px, plumb_bob k1 = 0.9, k2 = -1.0, k3 = 0.5, the plane 15 mm away, the unturned pose
/// turned 1.5 deg about x, -1 deg about y and 0.5 deg about z (as board_synthetic.rs), then
/// by 0, 90, 180 or 270 deg about the camera's z. Calibrated with the matching turn: all 63
/// bumps found, each within 1 px of its own bump's true centre (its neighbours lie 40 px and
/// more away, so every id is right; 0.36 to 0.48 px measured over seed sets 0 to 2), the
/// solved rotation within 0.1 deg of the truth, the turn included (0.007 to 0.046 deg), and
/// the turned solves' RMS within 0.05 px of the unturned one's (0.12 to 0.14 px, each turn
/// its own noise). The seed follows the seed set.
#[test]
fn a_synthetic_press_seen_by_a_turned_camera_gets_its_ids_and_pose() {
    use fabkit_calibration::board::synthetic::{render_board, BoardPress, BoardShading};
    use fabkit_calibration::{CameraModel, Distortion, Intrinsics};
    use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
    let grid = board_grid(&ninedtact_board()).unwrap();
    let camera = CameraModel::new(Intrinsics {
        image_width_px: 640,
        image_height_px: 640,
        fx_px: 290.0,
        fy_px: 290.0,
        cx_px: 319.5,
        cy_px: 319.5,
        distortion: Distortion::PlumbBob([0.9, -1.0, 0.0, 0.0, 0.5]),
    })
    .unwrap();
    let unturned = Isometry3::from_parts(
        Translation3::new(0.3, 0.3, 2.8 - 15.0),
        UnitQuaternion::from_euler_angles(
            1.5f64.to_radians(),
            (-1.0f64).to_radians(),
            0.5f64.to_radians(),
        ),
    )
    .inverse();
    let press = BoardPress {
        bump_radius_mm: 0.6,
        depth_mm: 0.5,
        unpressed: Vec::new(),
        specks: Vec::new(),
    };
    let shading = BoardShading {
        seed: 1000 * crate::common::seed_set() + 7,
        ..BoardShading::default()
    };
    let mut rms0 = None;
    for turn in BoardTurn::ALL {
        let t = turn.deg();
        let about_z =
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), f64::from(t).to_radians());
        let pose = Isometry3::from_parts(Translation3::identity(), about_z) * unturned;
        let r = render_board(&camera, &pose, &grid, &press, &shading);
        let found = find_bumps_in_captures_turned(
            &r.reference_gray(),
            &[("capture.png".into(), r.capture_gray())],
            &grid,
            None,
            turn,
        )
        .unwrap();
        let find = &found.find;
        assert_eq!(find.found.len(), 63, "{t} deg: missing {:?}", find.missing);
        let worst = find
            .found
            .iter()
            .map(|b| {
                let [u, v] = r.centre_of(&b.id).unwrap();
                (b.u_px - u).hypot(b.v_px - v)
            })
            .fold(0.0, f64::max);
        assert!(
            worst < 0.5,
            "{t} deg: a bump {worst} px off its id's centre"
        );
        let bc = solve_board_camera(&grid, find, (640, 640), 15.0).unwrap();
        let error = (bc.t_cam_sensor.rotation * pose.rotation.inverse())
            .angle()
            .to_degrees();
        assert!(
            error < 0.1,
            "{t} deg: the rotation {error} deg off the truth"
        );
        let rms0 = *rms0.get_or_insert(bc.rms_px);
        assert!(
            (bc.rms_px - rms0).abs() < 0.05,
            "{t} deg: RMS {} px against {rms0} unturned",
            bc.rms_px
        );
        eprintln!(
            "synthetic {t} deg: worst {worst:.3} px off, rotation {error:.4} deg off, RMS {:.4} px",
            bc.rms_px
        );
    }
}
