//! Plate layout of the kit 3MF: deterministic shelf (row) packing by bounding box, with the
//! parts of one multi-material group packed as one unit (one 3MF object).

use crate::ExportError;
use fabkit_designs::geometry::Aabb;
use fabkit_designs::kit::PrintTechnology;
use fabkit_designs::schema::{Bed, PrinterProfiles, Technology};
use std::collections::BTreeMap;

/// Clear distance between neighbouring parts on the plate, mm.
pub(crate) const GAP_MM: f64 = 5.0;

/// A row is closed when the next part would end beyond this x, mm. 200 mm fits the common
/// 220-250 mm beds; a part wider than this gets a row of its own.
pub(crate) const ROW_WIDTH_MM: f64 = 200.0;

/// Translations, mm, one per box in input order, that lay the boxes out in rows from the
/// origin towards +x then +y, `gap_mm` apart, each resting on z = 0 (translation z = -min z).
///
/// Rows are filled in input order; a box starts a new row when it would end beyond
/// `row_width_mm` and the row already holds a box. The xy footprints of the translated boxes
/// are pairwise at least `gap_mm` apart.
pub(crate) fn shelf_pack(boxes: &[Aabb], row_width_mm: f64, gap_mm: f64) -> Vec<[f64; 3]> {
    let (mut x, mut y, mut row_depth) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut row_len = 0usize;
    boxes
        .iter()
        .map(|b| {
            let [w, d, _] = b.size();
            if row_len > 0 && x + w > row_width_mm {
                y += row_depth + gap_mm;
                x = 0.0;
                row_depth = 0.0;
                row_len = 0;
            }
            let t = [x - b.min[0], y - b.min[1], -b.min[2]].map(|c| if c == 0.0 { 0.0 } else { c });
            x += w + gap_mm;
            row_depth = row_depth.max(d);
            row_len += 1;
            t
        })
        .collect()
}

/// The plate units of a kit, in order of first appearance: each unit lists part indices in
/// input order. A unit is either one ungrouped part (`None`) or all parts with the same
/// `Some(group)`; a group takes the place of its first member. Every index appears once.
///
/// ```text
/// groups [Some("t"), None, Some("t"), Some("o")]  ->  [[0, 2], [1], [3]]
/// ```
pub(crate) fn units(groups: &[Option<&str>]) -> Vec<Vec<usize>> {
    let mut units: Vec<Vec<usize>> = Vec::with_capacity(groups.len());
    let mut unit_of_group: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, g) in groups.iter().enumerate() {
        match g.and_then(|g| unit_of_group.get(g).copied()) {
            Some(u) => units[u].push(i),
            None => {
                if let Some(g) = g {
                    unit_of_group.insert(g, units.len());
                }
                units.push(vec![i]);
            }
        }
    }
    units
}

/// Translations, mm, one per unit: [`shelf_pack`] of the units' boxes, where a unit's box is
/// the union of its members' boxes (`boxes` has one entry per part, `units` as from
/// [`units`]).
///
/// One translation moves all members of a unit, so they keep their relative placement (they
/// were built in shared coordinates and must stay registered). Units are `gap_mm` apart;
/// members of one unit may touch or overlap.
pub(crate) fn pack_units(
    boxes: &[Aabb],
    units: &[Vec<usize>],
    row_width_mm: f64,
    gap_mm: f64,
) -> Vec<[f64; 3]> {
    let unit_boxes: Vec<Aabb> = units
        .iter()
        .map(|members| {
            members[1..]
                .iter()
                .fold(boxes[members[0]], |acc, &i| union(&acc, &boxes[i]))
        })
        .collect();
    shelf_pack(&unit_boxes, row_width_mm, gap_mm)
}

/// One unit on a plate.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PlateItem {
    /// Index into the units.
    pub unit: usize,
    /// Which copy of the unit (0, 1, ...; a unit of `n` copies is placed `n` times).
    pub copy: usize,
    /// Turned 90 deg about z (counter-clockwise seen from above) before the translation.
    pub turned: bool,
    /// Build-item translation, mm (after the turn).
    pub translation_mm: [f64; 3],
}

/// One print plate: units of one technology and material inside one printer's bed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Plate {
    pub technology: PrintTechnology,
    /// The material key, or a group's keys joined by `+`.
    pub material: String,
    pub bed: Bed,
    /// 1, 2, ... within its technology and material.
    pub number: usize,
    pub items: Vec<PlateItem>,
}

/// Packing resolution: footprints in units of 0.01 mm.
const PACK_UNITS_PER_MM: f64 = 100.0;

/// Splits the units into plates: by technology and material (a multi-material group is one
/// unit, its materials joined by `+`), each set packed first-fit-decreasing into as many of its
/// technology's beds as it needs (`rectangle_pack`), every footprint inside the bed less its
/// margin and `gap_mm` from its neighbours, resting on z = 0. A unit that fits only turned by
/// 90 deg is turned.
///
/// `parts`: (technology, material, box) per part; `units` as from [`units`] (the first
/// member's technology counts), `copies[u]` of unit `u` placed (each its own footprint).
///
/// # Errors
/// [`ExportError::TooLargeForBed`] naming the unit's first part, its size and the bed.
pub(crate) fn plates(
    parts: &[(PrintTechnology, &str, Aabb)],
    names: &[&str],
    units: &[Vec<usize>],
    copies: &[usize],
    printers: &PrinterProfiles,
    gap_mm: f64,
) -> Result<Vec<Plate>, ExportError> {
    use rectangle_pack::{
        contains_smallest_box, pack_rects, volume_heuristic, GroupedRectsToPlace, RectToInsert,
        TargetBin,
    };
    // units by (technology, material), in order of first appearance
    let mut sets: Vec<(PrintTechnology, String, Vec<usize>)> = Vec::new();
    for (u, members) in units.iter().enumerate() {
        let tech = parts[members[0]].0;
        let mut materials: Vec<&str> = Vec::new();
        for &i in members {
            if !materials.contains(&parts[i].1) {
                materials.push(parts[i].1);
            }
        }
        let material = materials.join("+");
        match sets.iter_mut().find(|s| s.0 == tech && s.1 == material) {
            Some(s) => s.2.push(u),
            None => sets.push((tech, material, vec![u])),
        }
    }
    let to_units = |mm: f64| (mm * PACK_UNITS_PER_MM).ceil().max(1.0) as u32;
    let mut plates = Vec::new();
    for (tech, material, members) in sets {
        let bed = printers.bed(Technology::from(tech));
        let [ux, uy] = bed.usable_xy_mm();
        // each unit's box, turned when it fits only so
        let mut boxes: Vec<(usize, usize, bool, Aabb)> = Vec::with_capacity(members.len());
        for &u in &members {
            let b = units[u][1..]
                .iter()
                .fold(parts[units[u][0]].2, |acc, &i| union(&acc, &parts[i].2));
            let [w, d, h] = b.size();
            let turned = if w <= ux && d <= uy && h <= bed.size_mm[2] {
                false
            } else if d <= ux && w <= uy && h <= bed.size_mm[2] {
                true
            } else {
                return Err(ExportError::TooLargeForBed {
                    part: names[units[u][0]].to_string(),
                    technology: tech,
                    size_mm: [w, d, h],
                    printer: bed.name.clone(),
                    bed_mm: bed.size_mm,
                    margin: bed.margin_mm,
                });
            };
            let b = if turned {
                // (x, y) -> (-y, x)
                Aabb {
                    min: [-b.max[1], b.min[0], b.min[2]],
                    max: [-b.min[1], b.max[0], b.max[2]],
                }
            } else {
                b
            };
            for copy in 0..copies.get(u).copied().unwrap_or(1).max(1) {
                boxes.push((u, copy, turned, b));
            }
        }
        let mut rects: GroupedRectsToPlace<usize, ()> = GroupedRectsToPlace::new();
        for (k, (_, _, _, b)) in boxes.iter().enumerate() {
            let [w, d, _] = b.size();
            rects.push_rect(
                k,
                None,
                RectToInsert::new(to_units(w + gap_mm), to_units(d + gap_mm), 1),
            );
        }
        // as many beds as units: the packer fills them in order and leaves the rest empty
        let bin_x = ((ux + gap_mm) * PACK_UNITS_PER_MM).floor() as u32;
        let bin_y = ((uy + gap_mm) * PACK_UNITS_PER_MM).floor() as u32;
        let mut bins: BTreeMap<usize, TargetBin> = (0..boxes.len())
            .map(|k| (k, TargetBin::new(bin_x, bin_y, 1)))
            .collect();
        let packed = pack_rects(&rects, &mut bins, &volume_heuristic, &contains_smallest_box)
            .expect("every unit fits a bed of its own (checked above)");
        let mut by_bin: BTreeMap<usize, Vec<PlateItem>> = BTreeMap::new();
        for (k, (u, copy, turned, b)) in boxes.iter().enumerate() {
            let (bin, loc) = &packed.packed_locations()[&k];
            let x = bed.margin_mm + loc.x() as f64 / PACK_UNITS_PER_MM;
            let y = bed.margin_mm + loc.y() as f64 / PACK_UNITS_PER_MM;
            by_bin.entry(*bin).or_default().push(PlateItem {
                unit: *u,
                copy: *copy,
                turned: *turned,
                translation_mm: [x - b.min[0], y - b.min[1], -b.min[2]].map(|c| {
                    if c == 0.0 {
                        0.0
                    } else {
                        c
                    }
                }),
            });
        }
        for (number, (_, mut items)) in by_bin.into_iter().enumerate() {
            items.sort_by_key(|i| (i.unit, i.copy));
            plates.push(Plate {
                technology: tech,
                material: material.clone(),
                bed: bed.clone(),
                number: number + 1,
                items,
            });
        }
    }
    Ok(plates)
}

fn union(a: &Aabb, b: &Aabb) -> Aabb {
    Aabb {
        min: [0, 1, 2].map(|k| a.min[k].min(b.min[k])),
        max: [0, 1, 2].map(|k| a.max[k].max(b.max[k])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(min: [f64; 3], max: [f64; 3]) -> Aabb {
        Aabb { min, max }
    }

    /// Plates: one technology and material each, every unit as many times as its copies,
    /// footprints inside the bed less its margin and a gap apart, a unit too long for the bed
    /// turned, one too large for either way round an error naming it.
    #[test]
    fn plates_split_by_technology_and_material_and_fit_their_beds() {
        use fabkit_designs::schema::PrinterProfiles;
        let printers = PrinterProfiles::default(); // prusa_mk4 230 x 190 usable, form2 135 x 135
        let fdm = PrintTechnology::Fdm;
        let sla = PrintTechnology::Sla;
        let mut parts = Vec::new();
        for k in 0..12 {
            parts.push((
                fdm,
                "pla",
                b([0.0, 0.0, 0.0], [60.0, 50.0, 20.0 + k as f64]),
            ));
        }
        parts.push((sla, "resin", b([-10.0, -10.0, 0.0], [10.0, 10.0, 5.0])));
        parts.push((fdm, "tpu", b([0.0, 0.0, 0.0], [20.0, 20.0, 5.0])));
        // 200 mm long in y: fits the 190 mm only along x
        parts.push((fdm, "pla", b([0.0, -100.0, 0.0], [30.0, 100.0, 10.0])));
        let names: Vec<String> = (0..parts.len()).map(|k| format!("p{k}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let units: Vec<Vec<usize>> = (0..parts.len()).map(|k| vec![k]).collect();
        // 29 of the 20 mm resin part (a pin dome's pins): 25 x 25 with the gap, 5 x 5 per
        // 135 x 135 plate, so two resin plates
        let copies: Vec<usize> = (0..parts.len())
            .map(|k| if k == 12 { 29 } else { 1 })
            .collect();
        let laid = plates(&parts, &names, &units, &copies, &printers, GAP_MM).unwrap();
        let mut copies_seen: Vec<usize> = Vec::new();
        let mut seen = vec![0; parts.len()];
        for p in &laid {
            let [ux, uy] = p.bed.usable_xy_mm();
            let m = p.bed.margin_mm;
            let mut placed: Vec<Aabb> = Vec::new();
            for it in &p.items {
                seen[it.unit] += 1;
                if it.unit == 12 {
                    copies_seen.push(it.copy);
                }
                let (tech, mat, bx) = parts[it.unit];
                assert_eq!((tech, mat), (p.technology, p.material.as_str()));
                let bx = if it.turned {
                    Aabb {
                        min: [-bx.max[1], bx.min[0], bx.min[2]],
                        max: [-bx.min[1], bx.max[0], bx.max[2]],
                    }
                } else {
                    bx
                };
                let t = it.translation_mm;
                let q = Aabb {
                    min: [bx.min[0] + t[0], bx.min[1] + t[1], bx.min[2] + t[2]],
                    max: [bx.max[0] + t[0], bx.max[1] + t[1], bx.max[2] + t[2]],
                };
                assert!(q.min[0] >= m - 1e-9 && q.min[1] >= m - 1e-9, "{q:?}");
                assert!(
                    q.max[0] <= m + ux + 1e-9 && q.max[1] <= m + uy + 1e-9,
                    "{q:?}"
                );
                assert_eq!(q.min[2], 0.0);
                for o in &placed {
                    let apart = q.max[0] + GAP_MM <= o.min[0] + 1e-6
                        || o.max[0] + GAP_MM <= q.min[0] + 1e-6
                        || q.max[1] + GAP_MM <= o.min[1] + 1e-6
                        || o.max[1] + GAP_MM <= q.min[1] + 1e-6;
                    assert!(apart, "{q:?} {o:?}");
                }
                placed.push(q);
            }
        }
        assert!(
            seen.iter().enumerate().all(|(k, &n)| n == copies[k]),
            "{seen:?}"
        );
        copies_seen.sort_unstable();
        assert_eq!(copies_seen, (0..29).collect::<Vec<_>>());
        let resin: Vec<&Plate> = laid.iter().filter(|p| p.material == "resin").collect();
        assert_eq!(
            resin.iter().map(|p| p.items.len()).collect::<Vec<_>>(),
            [25, 4]
        );
        // 12 boxes of 60 x 50 (65 x 55 with the gap) and the long one: 3 x 3 per 230 x 190
        // plate, so two PLA plates
        let pla: Vec<&Plate> = laid.iter().filter(|p| p.material == "pla").collect();
        assert_eq!(pla.len(), 2);
        assert_eq!(pla.iter().map(|p| p.number).collect::<Vec<_>>(), [1, 2]);
        let long = laid
            .iter()
            .flat_map(|p| &p.items)
            .find(|it| it.unit == 14)
            .unwrap();
        assert!(long.turned);
        assert_eq!(laid.len(), 5);

        // too large either way round
        parts.push((sla, "resin", b([0.0, 0.0, 0.0], [150.0, 20.0, 5.0])));
        let names: Vec<String> = (0..parts.len()).map(|k| format!("p{k}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let units: Vec<Vec<usize>> = (0..parts.len()).map(|k| vec![k]).collect();
        let e = plates(&parts, &names, &units, &[], &printers, GAP_MM).unwrap_err();
        assert!(
            e.to_string().starts_with(
                "part `p15` (SLA, 150.0 x 20.0 x 5.0 mm) does not fit the formlabs_form2 bed"
            ),
            "{e}"
        );
    }

    #[test]
    fn footprints_do_not_overlap_and_rest_on_z0() {
        let boxes = vec![
            b([-20.0, -20.0, 0.0], [20.0, 20.0, 10.0]),
            b([0.0, 0.0, 1.0], [160.0, 30.0, 5.0]),
            b([-5.0, -5.0, 0.0], [5.0, 5.0, 3.0]),
            b([0.0, 0.0, 0.0], [260.0, 10.0, 3.0]),
            b([-1.0, -1.0, -2.0], [1.0, 1.0, 3.0]),
        ];
        let t = shelf_pack(&boxes, ROW_WIDTH_MM, GAP_MM);
        let placed: Vec<Aabb> = boxes
            .iter()
            .zip(&t)
            .map(|(b, t)| Aabb {
                min: [b.min[0] + t[0], b.min[1] + t[1], b.min[2] + t[2]],
                max: [b.max[0] + t[0], b.max[1] + t[1], b.max[2] + t[2]],
            })
            .collect();
        for (i, p) in placed.iter().enumerate() {
            assert_eq!(p.min[2], 0.0);
            for q in &placed[i + 1..] {
                let apart_x =
                    p.max[0] + GAP_MM <= q.min[0] + 1e-9 || q.max[0] + GAP_MM <= p.min[0] + 1e-9;
                let apart_y =
                    p.max[1] + GAP_MM <= q.min[1] + 1e-9 || q.max[1] + GAP_MM <= p.min[1] + 1e-9;
                assert!(apart_x || apart_y, "{p:?} {q:?}");
            }
        }
        // the 160 mm box does not fit after the 40 mm one: second row
        assert!(placed[1].min[1] > placed[0].max[1]);
    }

    #[test]
    fn groups_form_one_unit_packed_by_its_union_box() {
        // A skin and its dots (touching, the dots above the skin's top), a plate between them
        // in input order, and a second group of one part.
        let boxes = vec![
            b([-15.0, -15.0, 0.0], [15.0, 15.0, 10.0]),
            b([0.0, 0.0, 0.0], [150.0, 30.0, 4.0]),
            b([-5.0, -5.0, 10.0], [20.0, 5.0, 12.0]),
            b([0.0, 0.0, 0.0], [10.0, 10.0, 10.0]),
        ];
        let groups = [Some("tactip"), None, Some("tactip"), Some("other")];
        let u = units(&groups);
        assert_eq!(u, vec![vec![0, 2], vec![1], vec![3]]);
        let t = pack_units(&boxes, &u, ROW_WIDTH_MM, GAP_MM);
        // the group is packed first, as its union box [-15, 20] x [-15, 15] x [0, 12]
        let unit_boxes = [
            b([-15.0, -15.0, 0.0], [20.0, 15.0, 12.0]),
            boxes[1],
            boxes[3],
        ];
        assert_eq!(t, shelf_pack(&unit_boxes, ROW_WIDTH_MM, GAP_MM));
        assert_eq!(t[0], [15.0, 15.0, 0.0]);
        // no groups: one unit per part, the plain shelf packing
        let plain = units(&[None; 4]);
        assert_eq!(plain, vec![vec![0], vec![1], vec![2], vec![3]]);
        assert_eq!(
            pack_units(&boxes, &plain, ROW_WIDTH_MM, GAP_MM),
            shelf_pack(&boxes, ROW_WIDTH_MM, GAP_MM)
        );
        // members need not be adjacent; the unit sits where its first member is
        assert_eq!(
            units(&[Some("a"), Some("b"), Some("a")]),
            vec![vec![0, 2], vec![1]]
        );
        assert!(units(&[]).is_empty());
    }
}
