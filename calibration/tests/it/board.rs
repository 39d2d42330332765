//! A flat sensor's camera from a board press (calibration/src/board.rs) on the real 9DTact
//! captures (tests/data/9dtact_sensor1/camera_calibration: the 7 x 9 board at 2.5 mm pressed
//! in, its reference, and the authors' result).

use fabkit_calibration::board::*;
use fabkit_calibration::imprints::GrayImage;
use fabkit_calibration::tables::PointTable;

fn load(name: &str) -> GrayImage {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/9dtact_sensor1/camera_calibration");
    let i = image::open(dir.join(name)).unwrap().into_luma8();
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
