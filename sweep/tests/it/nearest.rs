use fabkit_sweep::nearest_paths;

#[test]
fn nearest_paths_find_the_full_path_of_a_short_one() {
    let d = fabkit_designs::library::load("shadowtac").unwrap();
    assert_eq!(
        nearest_paths(&d, "markers.spacing_mm", 3)[0],
        "layers[0].markers[0].pattern.spacing_mm"
    );
    assert_eq!(
        nearest_paths(&d, "layers[0].markers[0].feature.hieght_mm", 3)[0],
        "layers[0].markers[0].feature.height_mm"
    );
    assert_eq!(
        nearest_paths(&d, "mold.wall_thicknes_mm", 1),
        vec!["mold.wall_thickness_mm".to_string()]
    );
}
