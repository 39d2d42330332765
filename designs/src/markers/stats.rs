//! Count and spacing of placed markers ([`stats`]): nearest neighbours by a bucket grid,
//! distances measured on the surface.

use super::spec::Marker;
use super::surface::Surface;
use serde::Serialize;

/// Count and spacing of a placed pattern, distances measured on the surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PatternStats {
    pub count: usize,
    /// Smallest nearest-neighbour distance on the surface, mm (0 for fewer than 2 markers).
    pub min_spacing_mm: f64,
    pub median_spacing_mm: f64,
    /// The pair with the smallest distance.
    pub closest_pair: Option<(usize, usize)>,
}

/// For each point, (index, chord distance) of its nearest other point, by a bucket grid.
/// Needs at least two points.
pub fn nearest_neighbours(points: &[[f64; 3]]) -> Vec<(usize, f64)> {
    let n = points.len();
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    let cell = (diag / (n as f64).sqrt()).max(1e-6);
    let key = |p: [f64; 3]| {
        [
            (p[0] / cell).floor() as i64,
            (p[1] / cell).floor() as i64,
            (p[2] / cell).floor() as i64,
        ]
    };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<usize>> =
        std::collections::HashMap::new();
    for (i, p) in points.iter().enumerate() {
        grid.entry(key(*p)).or_default().push(i);
    }
    let dist = |a: [f64; 3], b: [f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let k = key(p);
            let mut best = (usize::MAX, f64::INFINITY);
            let mut radius = 1;
            loop {
                for dx in -radius..=radius {
                    for dy in -radius..=radius {
                        for dz in -radius..=radius {
                            if let Some(v) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                                for &j in v {
                                    if j != i {
                                        let d = dist(p, points[j]);
                                        if d < best.1 || (d == best.1 && j < best.0) {
                                            best = (j, d);
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
                // a neighbour found within `radius` cells is the nearest if its distance is
                // below radius x cell
                if best.1 <= radius as f64 * cell || radius > 1 << 20 {
                    break;
                }
                radius *= 2;
            }
            best
        })
        .collect()
}

/// Count and nearest-neighbour spacing on the surface.
///
/// A pure function of its inputs, kept for the last few inputs of each thread: one design's
/// validation, printability checks and parts place the same pattern on the same surface up
/// to a dozen times, and a nearest-neighbour distance on the surface costs a geodesic walk
/// (10 ms for 600 markers). A repeat is recognised by the inputs' bits and gets a copy of the
/// same answer.
pub fn stats(surface: &Surface, markers: &[Marker]) -> PatternStats {
    let key = StatsKey::of(surface, markers);
    let found = STATS_SEEN.with(|seen| {
        seen.borrow()
            .iter()
            .find(|(k, _)| *k == key)
            .map(|(_, s)| s.clone())
    });
    if let Some(s) = found {
        return s;
    }
    let s = stats_of(surface, markers);
    STATS_SEEN.with(|seen| {
        let mut seen = seen.borrow_mut();
        seen.insert(0, (key, s.clone()));
        seen.truncate(STATS_KEPT);
    });
    s
}

/// How many of a thread's latest [`stats`] are kept.
const STATS_KEPT: usize = 4;

thread_local! {
    /// Each thread's latest [`stats`], newest first.
    static STATS_SEEN: std::cell::RefCell<Vec<(StatsKey, PatternStats)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// The inputs of [`stats`] by their bits: the body profile as its `Debug` text (every number
/// printed so that it reads back to the same bits, -0.0 apart from 0.0), the surface's offset,
/// and every field of every marker.
#[derive(PartialEq)]
struct StatsKey {
    body: String,
    bits: Vec<u64>,
}

impl StatsKey {
    fn of(surface: &Surface, markers: &[Marker]) -> StatsKey {
        let mut bits = Vec::with_capacity(1 + 13 * markers.len());
        bits.push(surface.offset_mm.to_bits());
        for m in markers {
            bits.extend([m.id as u64, u64::from(m.ring)]);
            bits.extend(
                [m.arc_mm, m.azimuth_deg, m.polar_deg]
                    .iter()
                    .chain(&m.position_mm)
                    .chain(&m.normal)
                    .map(|x| x.to_bits()),
            );
        }
        StatsKey {
            body: format!("{:?}", surface.body),
            bits,
        }
    }
}

/// [`stats`], computed.
fn stats_of(surface: &Surface, markers: &[Marker]) -> PatternStats {
    let n = markers.len();
    if n < 2 {
        return PatternStats {
            count: n,
            min_spacing_mm: 0.0,
            median_spacing_mm: 0.0,
            closest_pair: None,
        };
    }
    let points: Vec<[f64; 3]> = markers.iter().map(|m| m.position_mm).collect();
    let neighbours = nearest_neighbours(&points);
    let mut nn = Vec::with_capacity(n);
    let mut best_pair = (0, 1, f64::INFINITY);
    for (i, m) in markers.iter().enumerate() {
        let best = neighbours[i];
        let d = surface.surface_distance(m, &markers[best.0]);
        if d < best_pair.2 {
            best_pair = (i.min(best.0), i.max(best.0), d);
        }
        nn.push(d);
    }
    nn.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    let median = if n % 2 == 1 {
        nn[n / 2]
    } else {
        0.5 * (nn[n / 2 - 1] + nn[n / 2])
    };
    PatternStats {
        count: n,
        min_spacing_mm: nn[0],
        median_spacing_mm: median,
        closest_pair: Some((best_pair.0, best_pair.1)),
    }
}
