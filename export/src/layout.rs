//! Plate layout of the kit 3MF: deterministic shelf (row) packing by bounding box, with the
//! parts of one multi-material group packed as one unit (one 3MF object).

use fabkit_designs::geometry::Aabb;
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
