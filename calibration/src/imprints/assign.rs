//! Ids for the spots of each capture (R-Tac0 Sec. IV-A: each capture holds a few pins of the
//! dome, one per ring, listed by the capture plan or the file name). Extra spots (a speck, a
//! highlight's edge) and missing ones (a pin that barely marks the skin) are handled per spot:
//! a capture is kept with the spots that fit its pins at the pose solved from all captures,
//! the others are reported by pixel with why, and a capture is left out only when it cannot be
//! matched at all or when two spots fit one pin equally well.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Vector2, Vector3};

use super::Spot;
use crate::refraction::Imaging;
use crate::CameraModel;

/// One capture's detected spots and the pins planned for it (the capture plan's row, or the
/// ids its file name lists).
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureSpots {
    pub name: String,
    pub planned_ids: Vec<u32>,
    pub spots: Vec<Spot>,
}

/// A pin's pixel in a capture.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    pub capture: String,
    pub id: u32,
    pub u_px: f64,
    pub v_px: f64,
    pub score: f64,
}

/// What became of one capture's spots.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureOutcome {
    pub name: String,
    /// Spots the detector found.
    pub spots_found: usize,
    /// The spots kept, each with its pin's id, in id order.
    pub kept: Vec<(u32, Spot)>,
    /// Spots not taken for a pin, each with why.
    pub discarded: Vec<(Spot, String)>,
    /// Planned pins without a spot, each with why.
    pub missing: Vec<(u32, String)>,
    /// Spots cut in two ([`Spot::halves`]) because two of the capture's pins project onto
    /// their halves (two imprints that touch): the spot and the two pins' ids.
    pub split: Vec<(Spot, [u32; 2])>,
    /// Why the whole capture is left out (nothing is kept then).
    pub left_out: Option<String>,
}

impl CaptureOutcome {
    fn new(c: &CaptureSpots) -> Self {
        Self {
            name: c.name.clone(),
            spots_found: c.spots.len(),
            kept: Vec::new(),
            discarded: Vec::new(),
            missing: Vec::new(),
            split: Vec::new(),
            left_out: None,
        }
    }

    /// One line for the report when the capture is left out, a spot was discarded or a pin
    /// missed; `None` when every planned pin got a spot and every spot a pin.
    pub fn summary(&self) -> Option<String> {
        if let Some(why) = &self.left_out {
            return Some(format!("{}: {why}; left out", self.name));
        }
        if self.discarded.is_empty() && self.missing.is_empty() && self.split.is_empty() {
            return None;
        }
        let mut s = format!(
            "{}: {} spots; kept pins {}",
            self.name,
            self.spots_found,
            self.kept
                .iter()
                .map(|(id, _)| id.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        for (spot, [a, b]) in &self.split {
            s.push_str(&format!(
                "; spot at ({:.1}, {:.1}) split in two for pins {a} and {b} (two imprints that touch)",
                spot.u_px, spot.v_px
            ));
        }
        for (id, why) in &self.missing {
            s.push_str(&format!("; pin {id} missing: {why}"));
        }
        for (spot, why) in &self.discarded {
            s.push_str(&format!(
                "; spot at ({:.1}, {:.1}) discarded: {why}",
                spot.u_px, spot.v_px
            ));
        }
        Some(s)
    }
}

/// The ids given to the spots of every capture.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    /// Every kept spot, capture by capture (input order), ids in order.
    pub observations: Vec<Observation>,
    /// Per capture, in input order: spots kept, discarded and missing, or why it is left out.
    pub captures: Vec<CaptureOutcome>,
    /// The pose the final assignment was made with (`None` with fewer than 4 pins).
    pub t_cam_sensor: Option<Isometry3<f64>>,
}

impl Assignment {
    /// The captures left out, each with why and what was found.
    pub fn left_out(&self) -> Vec<String> {
        self.captures
            .iter()
            .filter(|c| c.left_out.is_some())
            .filter_map(CaptureOutcome::summary)
            .collect()
    }

    /// A line per capture that is left out or lost a spot or a pin ([`CaptureOutcome::summary`]).
    pub fn notes(&self) -> Vec<String> {
        self.captures
            .iter()
            .filter_map(CaptureOutcome::summary)
            .collect()
    }
}

/// Most pins of one capture.
pub const MAX_PINS_PER_CAPTURE: usize = 8;

/// Each pin considers at most this many spots, the nearest to its projection.
const CANDIDATES_PER_PIN: usize = 4;

/// Two spots fit one pin equally well when the farther one's squared distance to the pin's
/// projection is within this factor of the nearer one's (plus 1 px^2).
const AMBIGUOUS_RATIO: f64 = 2.0;

/// A pin's spot is at least this round ([`Spot::roundness`]): a scratch, a fibre or the edge
/// of a highlight is a thin line.
pub const MIN_ROUNDNESS: f64 = 0.5;

/// A spot less round than [`MIN_ROUNDNESS`] may still be a pin's when it is as wide as one
/// (its minor axis's standard deviation at least this fraction of a disc of the pins' typical
/// area's, r / 2; a scratch or a highlight's edge is a line of 1 to 3 px) and either clipped
/// by the mask ([`Spot::clipped`]: a half disc's minor sd is 0.53 of the disc's) ...
pub const MIN_WIDTH_FRACTION: f64 = 0.4;
/// ... and no longer than a pin's spot (its major sd at most this multiple of the disc's; a
/// disc cut by a straight edge keeps at most the disc's r / 2, but the pins' spots differ in
/// size from ring to ring and the outer ring's are ellipses, long across the radius: an
/// outer imprint cut by a notch measured 1.6) ...
pub const CLIPPED_MAX_LENGTH_FACTOR: f64 = 2.0;
/// ... or two imprints joined into one spot (their halos or their edges touch: a spot whose
/// halves, [`Spot::halves`], each hold at least this fraction of the pins' typical core; a
/// scratch cut in two leaves two thin lines of a few pixels).
pub const PAIR_MIN_HALF_FRACTION: f64 = 0.5;

/// A spot of at most this roundness is cut in two when two of the capture's pins project onto
/// its halves, each nearer its half than the whole spot's centre (two touching equal discs:
/// 0.45; overlapping by 40 % of their radius: 0.64; a single imprint measured 0.83 or more).
pub const SPLIT_MAX_ROUNDNESS: f64 = 0.75;

/// A pin's spot covers at least this fraction of the pins' typical spot ([`spot_shape`]) ...
pub const MIN_AREA_FRACTION: f64 = 0.15;
/// ... and at most this multiple of it.
pub const MAX_AREA_FACTOR: f64 = 5.0;

/// The pins' typical spot area, px: over the captures, the median core ([`Spot::core_px`],
/// the imprint without the halo a spot grows into) of each capture's largest round spots, as
/// many as half the pins it plans, rounded up (specks are small, and two joined imprints are
/// not round: a capture of five pins may show three round ones beside three specks); `None`
/// without a round spot.
fn typical_area_px(captures: &[CaptureSpots]) -> Option<f64> {
    let mut areas: Vec<usize> = captures
        .iter()
        .flat_map(|c| {
            let mut a: Vec<usize> = c
                .spots
                .iter()
                .filter(|s| s.roundness >= MIN_ROUNDNESS)
                .map(|s| s.core_px)
                .collect();
            a.sort_unstable_by(|x, y| y.cmp(x));
            a.truncate(c.planned_ids.len().div_ceil(2));
            a
        })
        .collect();
    if areas.is_empty() {
        return None;
    }
    let m = areas.len() / 2;
    Some(*areas.select_nth_unstable(m).1 as f64)
}

/// Why `spot` is not a pin's by its shape, `None` when it may be one: round
/// ([`MIN_ROUNDNESS`]) and of a core ([`Spot::core_px`]) within [[`MIN_AREA_FRACTION`],
/// [`MAX_AREA_FACTOR`]] times the pins' typical one (`typical_px`, from all captures: a barely pressed pin's spot
/// is about a quarter of a fully pressed one's, a speck of dust a tenth or less).
///
/// A spot less round than that is kept when it is as wide as a pin's spot
/// ([`MIN_WIDTH_FRACTION`]) and either clipped by the mask and no longer than a pin's
/// ([`CLIPPED_MAX_LENGTH_FACTOR`]: what shows of an imprint at a dark LED notch) or cut in two
/// halves that each hold a good part of a pin's core ([`PAIR_MIN_HALF_FRACTION`]: two imprints
/// joined).
pub fn spot_shape(spot: &Spot, typical_px: f64) -> Option<String> {
    let (lo, hi) = (MIN_AREA_FRACTION * typical_px, MAX_AREA_FACTOR * typical_px);
    let disc_sd = 0.5 * (typical_px / std::f64::consts::PI).sqrt();
    let wide = spot.roundness * spot.major_sd_px >= MIN_WIDTH_FRACTION * disc_sd;
    let clipped_pin = spot.clipped && spot.major_sd_px <= CLIPPED_MAX_LENGTH_FACTOR * disc_sd;
    let pair = spot.halves.is_some_and(|hs| {
        hs.iter()
            .all(|h| h.area_px as f64 >= PAIR_MIN_HALF_FRACTION * typical_px)
    });
    if spot.roundness < MIN_ROUNDNESS && !(wide && (clipped_pin || pair)) {
        Some(format!(
            "not round (minor over major axis {:.2}, a pin's spot at least {MIN_ROUNDNESS:.2}): a scratch or an edge",
            // rounded down: 0.499 is not "0.50"
            (spot.roundness * 100.0).floor() / 100.0
        ))
    } else if (spot.core_px as f64) < lo {
        Some(format!(
            "a core of {} px, smaller than a pin's spot's may be ({lo:.0} px: {MIN_AREA_FRACTION} x the pins' typical {typical_px:.0} px): a speck",
            spot.core_px
        ))
    } else if spot.core_px as f64 > hi {
        Some(format!(
            "a core of {} px, larger than a pin's spot's may be ({hi:.0} px: {MAX_AREA_FACTOR} x the pins' typical {typical_px:.0} px)",
            spot.core_px
        ))
    } else {
        None
    }
}

/// Gives each capture's spots the ids of its planned pins (`points`: id to sensor-frame point,
/// mm).
///
/// 0. Spots not shaped as a pin's ([`spot_shape`]: thin, or much smaller or larger than the
///    pins' typical spot) are discarded, with why.
/// 1. A first pose: in each capture with at least as many spots as pins, its strongest spots,
///    as many as it plans pins, ordered by their distance from the principal point, get the
///    pins ordered by their polar angle about the sensor axis (spots from the centre outwards,
///    pins from the pole outwards); the pose is solved from all of them with RANSAC, so that a
///    capture whose strongest spots include a speck does not spoil it.
/// 2. At that pose each capture's spots are matched to its pins' projections: each pin takes
///    the spot that, over the capture, moves the spots least, within half the distance to the
///    nearest other pin's projection of the capture (a tenth of the image's diagonal at most).
///    A spot no pin takes is discarded, a pin no spot fits is missing; both are reported with
///    why, and the capture's other pins are kept. The pose is solved again from what was kept,
///    and the matching repeated until it does not change (three times at most).
///
/// A capture is left out, with why and what was found, when it plans a pin the table lacks,
/// holds more than [`MAX_PINS_PER_CAPTURE`] pins, shows no spot, or has two spots that fit one
/// pin equally well ([`AMBIGUOUS_RATIO`]). Without a first pose (fewer than 4 spots in all)
/// only the captures with as many spots as pins are kept, by ring order.
pub fn assign_ids(
    camera: &CameraModel,
    points: &BTreeMap<u32, Vector3<f64>>,
    all: &[CaptureSpots],
) -> Assignment {
    assign_ids_through(&Imaging::straight(camera), points, all)
}

/// [`assign_ids`] through an optical path: the pose solved and the pins projected through
/// `camera`'s layers ([`crate::refraction`]).
pub fn assign_ids_through(
    camera: &Imaging<'_>,
    points: &BTreeMap<u32, Vector3<f64>>,
    all: &[CaptureSpots],
) -> Assignment {
    // the spots shaped as a pin's go on; the others are discarded with why
    let typical = typical_area_px(all);
    let (captures, shape_discards): (Vec<CaptureSpots>, Vec<Vec<(Spot, String)>>) = all
        .iter()
        .map(|c| {
            let (mut keep, mut out) = (Vec::new(), Vec::new());
            for s in &c.spots {
                // without a round spot anywhere only the roundness counts
                match spot_shape(s, typical.unwrap_or(s.core_px as f64)) {
                    Some(why) => out.push((*s, why)),
                    None => keep.push(*s),
                }
            }
            (
                CaptureSpots {
                    spots: keep,
                    ..c.clone()
                },
                out,
            )
        })
        .unzip();
    // a capture that shows fewer spots than it plans pins: its largest joined spots cut in two
    let (captures, cut): (Vec<CaptureSpots>, Vec<Vec<Spot>>) = captures
        .into_iter()
        .map(|mut c| {
            let cut = typical.map_or_else(Vec::new, |t| split_by_plan(&mut c, t));
            (c, cut)
        })
        .unzip();
    let mut a = assign_shaped(camera, points, &captures);
    for (o, cut) in a.captures.iter_mut().zip(cut) {
        for whole in cut {
            let Some(hs) = whole.halves else { continue };
            let id_of = |h: &super::Half| {
                o.kept
                    .iter()
                    .find(|(_, k)| k.u_px == h.u_px && k.v_px == h.v_px)
                    .map(|(id, _)| *id)
            };
            if let (Some(x), Some(y)) = (id_of(&hs[0]), id_of(&hs[1])) {
                o.split.push((whole, [x.min(y), x.max(y)]));
            }
        }
    }
    for (k, (o, out)) in a.captures.iter_mut().zip(shape_discards).enumerate() {
        o.spots_found = all[k].spots.len();
        if o.left_out.is_none() {
            o.discarded.extend(out);
        } else if captures[k].spots.is_empty()
            && !out.is_empty()
            && all[k].planned_ids.iter().all(|id| points.contains_key(id))
            && all[k].planned_ids.len() <= MAX_PINS_PER_CAPTURE
        {
            // left out for having no spot (not for its plan): say that the spots were not
            // shaped as pins'
            o.left_out = Some(format!(
                "no spot shaped as a pin's for the {} planned pins {:?} ({})",
                all[k].planned_ids.len(),
                all[k].planned_ids,
                out.iter()
                    .map(|(s, why)| format!("({:.1}, {:.1}): {why}", s.u_px, s.v_px))
                    .collect::<Vec<_>>()
                    .join("; ")
            ));
        }
    }
    a
}

/// [`assign_ids`] after the spots' shapes were checked: steps 1 and 2.
fn assign_shaped(
    camera: &Imaging<'_>,
    points: &BTreeMap<u32, Vector3<f64>>,
    captures: &[CaptureSpots],
) -> Assignment {
    let mut outcomes: Vec<CaptureOutcome> = captures.iter().map(CaptureOutcome::new).collect();
    for (c, o) in captures.iter().zip(&mut outcomes) {
        o.left_out = if let Some(id) = c.planned_ids.iter().find(|id| !points.contains_key(id)) {
            Some(format!("pin {id} is planned but not in the point table"))
        } else if c.planned_ids.len() > MAX_PINS_PER_CAPTURE {
            Some(format!(
                "{} pins in one capture, more than the {MAX_PINS_PER_CAPTURE} told apart",
                c.planned_ids.len()
            ))
        } else if c.spots.is_empty() {
            Some(format!(
                "no spot found for the {} planned pins {:?}",
                c.planned_ids.len(),
                c.planned_ids
            ))
        } else {
            None
        };
    }
    let usable: Vec<usize> = (0..captures.len())
        .filter(|&k| outcomes[k].left_out.is_none())
        .collect();
    let first: Vec<(u32, Spot)> = usable
        .iter()
        .map(|&k| &captures[k])
        .filter(|c| c.spots.len() >= c.planned_ids.len())
        .flat_map(|c| by_ring(camera, points, c))
        .collect();
    let Some(mut pose) = solve(camera, points, &first) else {
        for &k in &usable {
            let (c, o) = (&captures[k], &mut outcomes[k]);
            if c.spots.len() == c.planned_ids.len() {
                o.kept = by_ring(camera, points, c);
                o.kept.sort_by_key(|(id, _)| *id);
            } else {
                o.left_out = Some(format!(
                    "{} spots for the {} planned pins {:?} ({}), and too few pins in all captures for a pose to choose by",
                    c.spots.len(),
                    c.planned_ids.len(),
                    c.planned_ids,
                    found_at(&c.spots)
                ));
            }
        }
        return finish(captures, outcomes, None);
    };
    let mut last: Option<Vec<Vec<(u32, Spot)>>> = None;
    for _ in 0..3 {
        for &k in &usable {
            outcomes[k] = match_at(camera, points, &captures[k], &pose);
        }
        let kept: Vec<Vec<(u32, Spot)>> =
            usable.iter().map(|&k| outcomes[k].kept.clone()).collect();
        if last.as_ref() == Some(&kept) {
            break;
        }
        let all: Vec<(u32, Spot)> = kept.iter().flatten().copied().collect();
        match solve(camera, points, &all) {
            Some(t) => pose = t,
            None => break,
        }
        last = Some(kept);
    }
    finish(captures, outcomes, Some(pose))
}

fn finish(
    captures: &[CaptureSpots],
    outcomes: Vec<CaptureOutcome>,
    pose: Option<Isometry3<f64>>,
) -> Assignment {
    let observations = captures
        .iter()
        .zip(&outcomes)
        .flat_map(|(c, o)| {
            o.kept.iter().map(|(id, s)| Observation {
                capture: c.name.clone(),
                id: *id,
                u_px: s.u_px,
                v_px: s.v_px,
                score: s.score,
            })
        })
        .collect();
    Assignment {
        observations,
        captures: outcomes,
        t_cam_sensor: pose,
    }
}

/// "found at (u, v), ..." or "none found".
fn found_at(spots: &[Spot]) -> String {
    if spots.is_empty() {
        return "none found".into();
    }
    format!(
        "found at {}",
        spots
            .iter()
            .map(|s| format!("({:.1}, {:.1})", s.u_px, s.v_px))
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The capture's strongest spots (peak times area), as many as it plans pins, given the pins
/// by ring: spots ordered by their distance from the principal point against pins by their
/// polar angle.
fn by_ring(
    camera: &Imaging<'_>,
    points: &BTreeMap<u32, Vector3<f64>>,
    c: &CaptureSpots,
) -> Vec<(u32, Spot)> {
    let i = camera.camera.intrinsics();
    let polar = |id: &u32| {
        let p = points[id];
        p.xy().norm().atan2(p.z)
    };
    let mut ids = c.planned_ids.clone();
    ids.sort_by(|a, b| polar(a).total_cmp(&polar(b)));
    // strongest: the most darkening in all (peak times area), so that a small dark speck
    // does not beat a lightly pressed pin
    let mass = |s: &Spot| s.score * s.area_px as f64;
    let mut spots = c.spots.clone();
    spots.sort_by(|a, b| mass(b).total_cmp(&mass(a)));
    spots.truncate(ids.len());
    spots.sort_by(|a, b| {
        (a.u_px - i.cx_px)
            .hypot(a.v_px - i.cy_px)
            .total_cmp(&(b.u_px - i.cx_px).hypot(b.v_px - i.cy_px))
    });
    ids.into_iter().zip(spots).collect()
}

/// The pose from `pairs` (RANSAC with the solver's defaults; without it if that fails).
fn solve(
    camera: &Imaging<'_>,
    points: &BTreeMap<u32, Vector3<f64>>,
    pairs: &[(u32, Spot)],
) -> Option<Isometry3<f64>> {
    let (pts, px): (Vec<Vector3<f64>>, Vec<Vector2<f64>>) = pairs
        .iter()
        .map(|(id, s)| (points[id], Vector2::new(s.u_px, s.v_px)))
        .unzip();
    let with = crate::PnpOptions::default();
    let without = crate::PnpOptions {
        ransac: None,
        ..with
    };
    crate::pnp::solve_pnp_through(camera, &pts, &px, &with)
        .or_else(|_| crate::pnp::solve_pnp_through(camera, &pts, &px, &without))
        .ok()
        .map(|s| s.t_cam_sensor)
}

/// Matches the capture's spots to its pins' projections at `pose` ([`assign_ids`], step 2).
fn match_at(
    camera: &Imaging<'_>,
    points: &BTreeMap<u32, Vector3<f64>>,
    c: &CaptureSpots,
    pose: &Isometry3<f64>,
) -> CaptureOutcome {
    let mut o = CaptureOutcome::new(c);
    let intr = camera.camera.intrinsics();
    let max_gate = 0.1 * f64::from(intr.image_width_px).hypot(f64::from(intr.image_height_px));
    let proj: Vec<Option<Vector2<f64>>> = c
        .planned_ids
        .iter()
        .map(|id| {
            camera.project(
                pose.rotation.to_rotation_matrix().matrix(),
                &pose.translation.vector,
                &points[id],
            )
        })
        .collect();
    let (split_spots, splits) = split_touching(c, &proj);
    o.split = splits;
    let c = &CaptureSpots {
        spots: split_spots,
        ..c.clone()
    };
    let gate: Vec<f64> = proj
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let Some(p) = p else { return 0.0 };
            proj.iter()
                .enumerate()
                .filter(|(j, _)| *j != k)
                .filter_map(|(_, q)| q.map(|q| 0.5 * (q - p).norm()))
                .fold(max_gate, f64::min)
        })
        .collect();
    let dist = |k: usize, j: usize| {
        proj[k].map_or(f64::INFINITY, |p| {
            (p - Vector2::new(c.spots[j].u_px, c.spots[j].v_px)).norm()
        })
    };
    // each pin's candidates: the nearest spots within its gate
    let candidates: Vec<Vec<usize>> = (0..proj.len())
        .map(|k| {
            let mut js: Vec<usize> = (0..c.spots.len())
                .filter(|&j| dist(k, j) < gate[k])
                .collect();
            js.sort_by(|&a, &b| dist(k, a).total_cmp(&dist(k, b)));
            js.truncate(CANDIDATES_PER_PIN);
            js
        })
        .collect();
    // the choice of at most one spot per pin, each spot to one pin, that costs least: a taken
    // spot its squared distance, a pin left without one its gate squared
    let mut best: (f64, Vec<Option<usize>>) = (f64::INFINITY, Vec::new());
    let mut choice = Vec::with_capacity(proj.len());
    search(
        &candidates,
        &|k, j| match j {
            Some(j) => dist(k, j).powi(2),
            None => gate[k].powi(2),
        },
        &mut choice,
        0.0,
        &mut best,
    );
    let taken = best.1;
    for (k, j) in taken.iter().enumerate() {
        let Some(j) = *j else { continue };
        let d1 = dist(k, j);
        // another spot, taken by no pin, that fits this pin about as well
        if let Some(&j2) = candidates[k]
            .iter()
            .find(|&&j2| j2 != j && !taken.contains(&Some(j2)))
        {
            let d2 = dist(k, j2);
            if d2 * d2 <= AMBIGUOUS_RATIO * d1 * d1 + 1.0 {
                let (a, b) = (c.spots[j], c.spots[j2]);
                o.left_out = Some(format!(
                    "pin {}: two spots fit it equally well, ({:.1}, {:.1}) at {d1:.1} px and ({:.1}, {:.1}) at {d2:.1} px from its projection",
                    c.planned_ids[k], a.u_px, a.v_px, b.u_px, b.v_px
                ));
                return o;
            }
        }
    }
    for (k, j) in taken.iter().enumerate() {
        let id = c.planned_ids[k];
        match (j, proj[k]) {
            (Some(j), _) => o.kept.push((id, c.spots[*j])),
            (None, None) => o
                .missing
                .push((id, "it does not project into the image at the pose".into())),
            (None, Some(p)) => o.missing.push((
                id,
                format!(
                    "no spot within {:.0} px of its projection ({:.1}, {:.1})",
                    gate[k], p.x, p.y
                ),
            )),
        }
    }
    o.kept.sort_by_key(|(id, _)| *id);
    for (j, s) in c.spots.iter().enumerate() {
        if taken.contains(&Some(j)) {
            continue;
        }
        // the nearest projection, and whether the spot lost a pin to a nearer one
        let near = (0..proj.len())
            .filter(|&k| proj[k].is_some())
            .min_by(|&a, &b| dist(a, j).total_cmp(&dist(b, j)));
        let why = match near {
            None => "no planned pin projects into the image".to_string(),
            Some(k) => {
                let d = dist(k, j);
                match taken[k] {
                    Some(jk) if d < gate[k] => format!(
                        "pin {} took a nearer spot ({:.1} px from its projection against {d:.1} px)",
                        c.planned_ids[k],
                        dist(k, jk)
                    ),
                    _ => format!(
                        "{d:.1} px from the nearest planned pin's projection (pin {}), more than the {:.0} px a spot of it may be",
                        c.planned_ids[k], gate[k]
                    ),
                }
            }
        };
        o.discarded.push((*s, why));
    }
    o
}

/// A spot is cut in two by the capture plan ([`split_by_plan`]) when its core holds at least
/// this multiple of the pins' typical one (two joined imprints: about 2).
pub const SPLIT_MIN_CORE_FACTOR: f64 = 1.5;

/// Cuts in two ([`Spot::halves`]) the spots of a capture that shows fewer spots than it plans
/// pins, the largest core first, while it does and a spot has halves and a core of at least
/// [`SPLIT_MIN_CORE_FACTOR`] times the pins' typical one (`typical_px`): two imprints that
/// touch or whose halos join make one spot. Returns the spots cut; each half becomes a spot
/// of its own ([`half_spot`]).
fn split_by_plan(c: &mut CaptureSpots, typical_px: f64) -> Vec<Spot> {
    let mut cut = Vec::new();
    while c.spots.len() < c.planned_ids.len() {
        let Some(j) = c
            .spots
            .iter()
            .enumerate()
            .filter(|(_, s)| {
                s.halves.is_some() && s.core_px as f64 >= SPLIT_MIN_CORE_FACTOR * typical_px
            })
            .max_by(|a, b| a.1.core_px.cmp(&b.1.core_px).then(b.0.cmp(&a.0)))
            .map(|(j, _)| j)
        else {
            break;
        };
        let whole = c.spots.remove(j);
        if let Some(hs) = whole.halves {
            c.spots.extend(hs.iter().map(|h| half_spot(&whole, h)));
        }
        cut.push(whole);
    }
    cut
}

/// A half of `whole` ([`Spot::halves`]) as a spot of its own: its centre and core, the whole's
/// score, round, its own halves its parts ([`super::Half::parts`]).
fn half_spot(whole: &Spot, h: &super::Half) -> Spot {
    Spot {
        u_px: h.u_px,
        v_px: h.v_px,
        area_px: h.area_px,
        core_px: h.area_px,
        roundness: 1.0,
        major_sd_px: 0.5 * (h.area_px as f64 / std::f64::consts::PI).sqrt(),
        halves: h.parts.map(|ps| {
            ps.map(|q| super::Half {
                u_px: q.u_px,
                v_px: q.v_px,
                area_px: q.area_px,
                parts: None,
            })
        }),
        ..*whole
    }
}

/// The capture's spots with each spot that two of its pins share cut in two: a spot of at
/// most [`SPLIT_MAX_ROUNDNESS`] with halves ([`Spot::halves`]) whose halves are nearest two
/// different pins' projections (`proj`, in plan order), each pin nearer its half than the
/// whole spot's centre. Each half becomes a spot of its own (the whole's score, its own
/// centre and pixel count, round). Returns the spots and the spots split with their pins' ids.
fn split_touching(
    c: &CaptureSpots,
    proj: &[Option<Vector2<f64>>],
) -> (Vec<Spot>, Vec<(Spot, [u32; 2])>) {
    let nearest = |u: f64, v: f64| {
        proj.iter()
            .enumerate()
            .filter_map(|(k, p)| p.map(|p| (k, (p - Vector2::new(u, v)).norm())))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    };
    let (mut spots, mut splits) = (Vec::with_capacity(c.spots.len() + 1), Vec::new());
    for s in &c.spots {
        let halves = s.halves.filter(|_| s.roundness <= SPLIT_MAX_ROUNDNESS);
        let pins = halves.and_then(|[a, b]| {
            let (ka, da) = nearest(a.u_px, a.v_px)?;
            let (kb, db) = nearest(b.u_px, b.v_px)?;
            let whole = |k: usize| {
                proj[k].map_or(f64::INFINITY, |p| (p - Vector2::new(s.u_px, s.v_px)).norm())
            };
            (ka != kb && da < whole(ka) && db < whole(kb)).then_some([ka, kb])
        });
        match (halves, pins) {
            (Some(hs), Some([ka, kb])) => {
                spots.extend(hs.iter().map(|h| half_spot(s, h)));
                splits.push((*s, [c.planned_ids[ka], c.planned_ids[kb]]));
            }
            _ => spots.push(*s),
        }
    }
    (spots, splits)
}

/// Depth-first search over the pins' candidates for the cheapest choice (`cost(k, spot)`);
/// `best` holds the cheapest so far.
fn search(
    candidates: &[Vec<usize>],
    cost: &dyn Fn(usize, Option<usize>) -> f64,
    choice: &mut Vec<Option<usize>>,
    so_far: f64,
    best: &mut (f64, Vec<Option<usize>>),
) {
    if so_far >= best.0 {
        return;
    }
    let k = choice.len();
    if k == candidates.len() {
        *best = (so_far, choice.clone());
        return;
    }
    for &j in &candidates[k] {
        if choice.contains(&Some(j)) {
            continue;
        }
        choice.push(Some(j));
        search(candidates, cost, choice, so_far + cost(k, Some(j)), best);
        choice.pop();
    }
    choice.push(None);
    search(candidates, cost, choice, so_far + cost(k, None), best);
    choice.pop();
}
