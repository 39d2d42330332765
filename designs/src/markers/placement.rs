//! Placing a pattern's markers on a surface ([`place`]): the patterned region between the
//! polar limits, one function per layout (`concentric_6k`, `concentric`, `hex_grid`,
//! `golden_spiral`, `list`), and the bound on their count.

use super::spec::{layout_name, Layout, Marker, Pattern, PatternError, RingAzimuthOffset};
use super::surface::Surface;
use std::f64::consts::PI;

/// Most markers one pattern may place. Counts are estimated from the parameters before any
/// marker is placed (a golden spiral of 1e8 markers once aborted on an 8.8 GB allocation);
/// the library's patterns have 85 to 627 markers.
pub const MAX_MARKERS_PER_PATTERN: usize = 100_000;

/// The arc lengths (mm, from the pole) between which `pattern` places its markers on
/// `surface`: its polar limits, else the pole and the rim less `rim_margin_mm`.
///
/// # Errors
/// A polar limit beyond the surface, or limits that leave no room.
fn patterned_arc(
    surface: &Surface,
    pattern: &Pattern,
    rim_margin_mm: f64,
) -> Result<(f64, f64), PatternError> {
    let err = |f: &str, v: String, rule: &str| Err((f.to_string(), v, rule.to_string()));
    let surface_max_deg = surface.polar_deg_at(surface.total_arc_mm());
    if let Some(p) = pattern.max_polar_deg.filter(|&p| p > surface_max_deg) {
        return err(
            "max_polar_deg",
            p.to_string(),
            &format!(
                "must be at most the surface's polar range, {surface_max_deg:.3} deg at its rim"
            ),
        );
    }
    let s_max = match pattern.max_polar_deg {
        Some(p) => surface.s_at_polar_deg(p),
        None => surface.total_arc_mm() - rim_margin_mm,
    };
    let s_min = pattern
        .min_polar_deg
        .map(|p| surface.s_at_polar_deg(p))
        .unwrap_or(0.0);
    if !(s_max > s_min) {
        // name the limit that was given: the minimum when only it is (the maximum is the rim)
        return match (pattern.max_polar_deg, pattern.min_polar_deg) {
            (Some(p), _) => err(
                "max_polar_deg",
                p.to_string(),
                "leaves no room for markers between the polar limits and the rim",
            ),
            (None, Some(p)) => err(
                "min_polar_deg",
                p.to_string(),
                &format!(
                    "leaves no room for markers between it and the rim margin ({rim_margin_mm:.3} mm of arc below {surface_max_deg:.3} deg)"
                ),
            ),
            (None, None) => err(
                "feature.diameter_mm",
                format!("{rim_margin_mm}"),
                "leaves no room for markers: the rim margin (one feature diameter) covers the surface",
            ),
        };
    }
    Ok((s_min, s_max))
}

/// Every point of a `list` pattern that cannot be placed on `surface`, as (`points[i]`, value,
/// rule), in list order; empty for other layouts or when the polar limits are themselves wrong
/// ([`place`] reports those).
pub fn point_errors(surface: &Surface, pattern: &Pattern, rim_margin_mm: f64) -> Vec<PatternError> {
    let (Some(pts), Ok((s_min, s_max))) = (
        pattern.points.as_ref(),
        patterned_arc(surface, pattern, rim_margin_mm),
    ) else {
        return Vec::new();
    };
    bad_points(surface, pts, s_min, s_max)
}

fn bad_points(surface: &Surface, pts: &[[f64; 2]], s_min: f64, s_max: f64) -> Vec<PatternError> {
    let mut out = Vec::new();
    for (i, p) in pts.iter().enumerate() {
        let rule = if !(p[0] >= 0.0 && p[0].is_finite() && p[1].is_finite()) {
            "polar angle must be >= 0 and both angles finite"
        } else {
            let s = surface.s_at_polar_deg(p[0]);
            if s > s_max + 1e-9 || s < s_min - 1e-9 {
                "lies outside the patterned region"
            } else {
                continue;
            }
        };
        out.push((format!("points[{i}]"), format!("{p:?}"), rule.to_string()));
    }
    out
}

/// Places the markers of `pattern` on `surface`.
///
/// `rim_margin_mm` keeps marker centres that far (in arc length) from the base plane when no
/// polar limit is given.
///
/// # Errors
/// The first violation as (field below `pattern`, value, rule); the caller adds the path.
/// [`Pattern::field_errors`] lists every violation of the fields themselves.
pub fn place(
    surface: &Surface,
    pattern: &Pattern,
    rim_margin_mm: f64,
) -> Result<Vec<Marker>, PatternError> {
    if let Some(e) = pattern.field_errors().into_iter().next() {
        return Err(e);
    }
    let (s_min, s_max) = patterned_arc(surface, pattern, rim_margin_mm)?;
    let region = Region {
        surface,
        pattern,
        rim_margin_mm,
        s_min,
        s_max,
        polar_max: surface.polar_deg_at(s_max),
        centre: pattern.center_marker && s_min == 0.0,
    };
    let raw = match pattern.layout {
        Layout::Concentric6k => concentric_6k_raw(&region)?,
        Layout::Concentric => concentric_raw(&region)?,
        Layout::HexGrid => hex_grid_raw(&region)?,
        Layout::GoldenSpiral => golden_spiral_raw(&region)?,
        Layout::List => list_raw(&region)?,
    };
    Ok(raw
        .into_iter()
        .enumerate()
        .map(|(id, (s, az, ring))| {
            let (position_mm, normal) = surface.point(s, az);
            Marker {
                id,
                ring,
                arc_mm: s,
                azimuth_deg: az.to_degrees(),
                polar_deg: surface.polar_deg_at(s),
                position_mm,
                normal,
            }
        })
        .collect())
}

/// What every layout places its markers in: the pattern on its surface, and the patterned
/// region between `s_min` and `s_max` mm of arc from the pole (`polar_max` deg at its outer
/// edge); `centre`: a marker goes on the pole.
struct Region<'a> {
    surface: &'a Surface,
    pattern: &'a Pattern,
    rim_margin_mm: f64,
    s_min: f64,
    s_max: f64,
    polar_max: f64,
    centre: bool,
}

impl Region<'_> {
    /// The rule that bounds the region, for messages: `max_polar_deg` when given, else the rim
    /// less `rim_margin_mm` mm of arc.
    fn limit(&self) -> String {
        match self.pattern.max_polar_deg {
            Some(p) => format!("max_polar_deg {p}"),
            None => format!(
                "the rim at {:.3} deg less a margin of {:.3} mm of arc",
                self.surface.polar_deg_at(self.surface.total_arc_mm()),
                self.rim_margin_mm
            ),
        }
    }
}

/// A marker before it is placed: (arc length mm, azimuth radians, ring).
type RawMarker = (f64, f64, u32);

/// A pattern error as an `Err`: (field below `pattern`, value, rule).
fn pattern_err<T>(f: &str, v: String, rule: &str) -> Result<T, PatternError> {
    Err((f.to_string(), v, rule.to_string()))
}

/// The value `v` of field `f` of `pattern` when it is finite and above 0; the violation
/// otherwise (a missing value is required by the pattern's layout).
fn positive(pattern: &Pattern, f: &str, v: Option<f64>) -> Result<f64, PatternError> {
    match v {
        Some(x) if x > 0.0 && x.is_finite() => Ok(x),
        Some(x) => Err((f.to_string(), x.to_string(), "must be above 0".into())),
        None => Err((
            f.to_string(),
            "missing".into(),
            format!("is required for layout {}", layout_name(pattern.layout)),
        )),
    }
}

/// The violation of a pattern whose `field` (of `value`) places about `n` markers, more than
/// [`MAX_MARKERS_PER_PATTERN`].
fn too_many(field: &str, value: String, n: f64) -> PatternError {
    // Counts are bounded before anything is placed.
    (
        field.to_string(),
        value,
        format!(
            "places about {n:.0} markers, more than the {MAX_MARKERS_PER_PATTERN} one pattern may have"
        ),
    )
}

/// Pushes onto `raw` ring `k` of `n` markers at arc length `s` mm, evenly spaced in azimuth
/// from the ring's offset (`ring_azimuth_offset` of `pattern`).
fn push_ring(pattern: &Pattern, raw: &mut Vec<RawMarker>, s: f64, k: u32, n: usize) {
    let off = pattern.ring_offset_rad(k, n);
    for j in 0..n {
        raw.push((s, off + 2.0 * PI * j as f64 / n as f64, k));
    }
}

/// The markers of a `concentric_6k` pattern as (arc length mm, azimuth radians, ring): the
/// centre marker when `centre`, then ring k of 6k markers at k pitches (`pitch_arc_mm` of arc
/// or `polar_step_deg`), each ring within the patterned region (up to `s_max` mm of arc,
/// `polar_max` deg).
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn concentric_6k_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_max, polar_max, centre) =
        (r.surface, r.pattern, r.s_max, r.polar_max, r.centre);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    let rings = pattern.rings.ok_or_else(|| {
        (
            "rings".to_string(),
            "missing".to_string(),
            "is required for concentric_6k".to_string(),
        )
    })?;
    let n = 1.0 + 3.0 * f64::from(rings) * (f64::from(rings) + 1.0);
    if n > cap {
        return Err(too_many("rings", rings.to_string(), n));
    }
    if centre {
        raw.push((0.0, 0.0, 0));
    }
    if let Some(step) = pattern.polar_step_deg {
        let last = rings as f64 * step;
        if last > polar_max + 1e-9 {
            return pattern_err(
                "polar_step_deg",
                step.to_string(),
                &format!(
                    "puts ring {rings} at {rings} x {step} = {last:.4} deg, beyond the patterned region (up to {polar_max:.4} deg: {})",
                    r.limit()
                ),
            );
        }
        for k in 1..=rings {
            let s = surface.s_at_polar_deg(k as f64 * step);
            push_ring(pattern, &mut raw, s, k, 6 * k as usize);
        }
    } else {
        let pitch = positive(pattern, "pitch_arc_mm", pattern.pitch_arc_mm)?;
        for k in 1..=rings {
            let s = k as f64 * pitch;
            if s > s_max + 1e-9 {
                return pattern_err("rings", rings.to_string(), &format!("ring {k} at {s:.3} mm of arc lies beyond the patterned region ({s_max:.3} mm: {})", r.limit()));
            }
            push_ring(pattern, &mut raw, s, k, 6 * k as usize);
        }
    }
    Ok(raw)
}

/// The markers of a `concentric` pattern as (arc length mm, azimuth radians, ring): the
/// centre marker when `centre`, then rings one `polar_step_deg` (or else one `spacing_mm` of
/// arc) apart, the first at the inner limit (`min_polar_deg`, `s_min` mm of arc) when there is
/// one and one step from the pole otherwise, up to `s_max` mm of arc (`polar_max` deg); each
/// ring holds markers about `spacing_mm` apart.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn concentric_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_min, s_max) = (r.surface, r.pattern, r.s_min, r.s_max);
    let (polar_max, centre) = (r.polar_max, r.centre);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    let sp = positive(pattern, "spacing_mm", pattern.spacing_mm)?;
    if centre {
        raw.push((0.0, 0.0, 0));
    }
    // Ring k's arc length, or None beyond the region.
    let ring_s = |k: u32| -> Option<f64> {
        match pattern.polar_step_deg {
            Some(step) => {
                let p0 = pattern.min_polar_deg.filter(|_| s_min > 0.0);
                let polar = match p0 {
                    Some(p0) => p0 + (k - 1) as f64 * step,
                    None => k as f64 * step,
                };
                (polar <= polar_max + 1e-9).then(|| surface.s_at_polar_deg(polar))
            }
            None => {
                let s = if s_min > 0.0 {
                    s_min + (k - 1) as f64 * sp
                } else {
                    k as f64 * sp
                };
                (s <= s_max + 1e-9).then_some(s)
            }
        }
    };
    // Each ring is counted before it is placed.
    let mut total = usize::from(centre);
    let mut k = 1;
    while let Some(s) = ring_s(k) {
        // counted in f64 and compared before the cast: a spacing of 1e-300 mm makes
        // a ratio past usize::MAX
        let n_f = (2.0 * PI * surface.radius_at(s) / sp).round().max(1.0);
        let count_f = total as f64 + n_f;
        if count_f > cap {
            // The parameter that drives the count: the ring pitch when there are more
            // rings than markers on a ring, else the spacing along the rings.
            let (field, value) = match pattern.polar_step_deg {
                Some(step) if f64::from(k) * f64::from(k) > count_f => {
                    ("polar_step_deg", step.to_string())
                }
                _ => ("spacing_mm", sp.to_string()),
            };
            return Err((
                field.to_string(),
                value,
                format!(
                    "places more than {MAX_MARKERS_PER_PATTERN} markers (by ring {k}), the most one pattern may have"
                ),
            ));
        }
        let n = n_f as usize;
        total += n;
        push_ring(pattern, &mut raw, s, k, n);
        k += 1;
    }
    if let Some(RingAzimuthOffset::PerRingDeg(v)) = &pattern.ring_azimuth_offset {
        if v.len() != (k - 1) as usize {
            return pattern_err(
                "ring_azimuth_offset.per_ring_deg",
                format!("{} entries", v.len()),
                &format!("needs one entry per ring (the pattern has {} rings)", k - 1),
            );
        }
    }
    Ok(raw)
}

/// The markers of a `hex_grid` pattern as (arc length mm, azimuth radians, 0): the points of a
/// hexagonal lattice of pitch `spacing_mm`, laid out in arc length (mm) and azimuth about the
/// pole, from `s_min` to `s_max` mm of arc; ordered by arc length, then azimuth.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn hex_grid_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (pattern, s_min, s_max) = (r.pattern, r.s_min, r.s_max);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    let a = positive(pattern, "spacing_mm", pattern.spacing_mm)?;
    // Lattice points in the disc of radius s_max (the loop visits its bounding square).
    let n = PI * s_max * s_max / (a * a * 3f64.sqrt() / 2.0);
    if n > cap {
        return Err(too_many("spacing_mm", a.to_string(), n));
    }
    let m = (s_max / a).ceil() as i64 + 1;
    // rows are (sqrt 3 / 2) a apart, and row j is shifted by j/2 pitches
    let rows = (s_max / (a * 3f64.sqrt() / 2.0)).ceil() as i64 + 1;
    for j in -rows..=rows {
        let w = m + (j.abs() + 1) / 2;
        for i in -w..=w {
            let x = a * (i as f64 + 0.5 * j as f64);
            let y = a * (3f64.sqrt() / 2.0) * j as f64;
            let s = (x * x + y * y).sqrt();
            if s >= s_min - 1e-12 && s <= s_max + 1e-12 {
                raw.push((s, y.atan2(x), 0));
            }
        }
    }
    // deterministic order: by arc length, then azimuth
    raw.sort_by(|p, q| {
        (p.0, p.1)
            .partial_cmp(&(q.0, q.1))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(raw)
}

/// The markers of a `golden_spiral` pattern as (arc length mm, azimuth radians, 0): `count`
/// markers (or as many as `spacing_mm` gives) at equal steps of surface area from `s_min` to
/// `s_max` mm of arc, turned by the golden angle one to the next.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn golden_spiral_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_min, s_max) = (r.surface, r.pattern, r.s_min, r.s_max);
    let cap = MAX_MARKERS_PER_PATTERN as f64;
    let mut raw = Vec::new();
    // cumulative area table from s_min to s_max, inverted by interpolation
    let k = 4096;
    let ss: Vec<f64> = (0..=k)
        .map(|i| s_min + (s_max - s_min) * i as f64 / k as f64)
        .collect();
    let rs: Vec<f64> = ss.iter().map(|&x| surface.radius_at(x)).collect();
    let mut area = vec![0.0; k + 1];
    for i in 1..=k {
        area[i] = area[i - 1] + PI * (rs[i - 1] + rs[i]) * (ss[i] - ss[i - 1]);
    }
    let a_total = area[k];
    let n = match (pattern.count, pattern.spacing_mm) {
        (Some(c), _) if c as usize > MAX_MARKERS_PER_PATTERN => {
            return Err(too_many("count", c.to_string(), f64::from(c)))
        }
        (Some(c), _) if c > 0 => c as usize,
        (Some(c), _) => return pattern_err("count", c.to_string(), "must be above 0"),
        (None, sp) => {
            let sp = positive(pattern, "spacing_mm", sp)?;
            let n = (a_total / (sp * sp * 3f64.sqrt() / 2.0)).round();
            if n > cap {
                return Err(too_many("spacing_mm", sp.to_string(), n));
            }
            (n as usize).max(1)
        }
    };
    let golden = PI * (3.0 - 5f64.sqrt());
    for i in 0..n {
        let target = (i as f64 + 0.5) / n as f64 * a_total;
        let j = area.partition_point(|&a| a < target).clamp(1, k);
        let f = (target - area[j - 1]) / (area[j] - area[j - 1]).max(f64::MIN_POSITIVE);
        let s = ss[j - 1] + f * (ss[j] - ss[j - 1]);
        raw.push((s, (i as f64 * golden).rem_euclid(2.0 * PI), 0));
    }
    Ok(raw)
}

/// The markers of a `list` pattern as (arc length mm, azimuth radians, 0), in list order, each
/// point within `s_min` to `s_max` mm of arc.
///
/// # Errors
/// The first violation, as [`place`] reports it.
fn list_raw(r: &Region<'_>) -> Result<Vec<RawMarker>, PatternError> {
    let (surface, pattern, s_min, s_max) = (r.surface, r.pattern, r.s_min, r.s_max);
    let mut raw = Vec::new();
    let pts = pattern.points.as_ref().ok_or_else(|| {
        (
            "points".to_string(),
            "missing".to_string(),
            "is required for layout list (or csv_file)".to_string(),
        )
    })?;
    if pts.len() > MAX_MARKERS_PER_PATTERN {
        return Err(too_many(
            "points",
            format!("{} points", pts.len()),
            pts.len() as f64,
        ));
    }
    if let Some(e) = bad_points(surface, pts, s_min, s_max).into_iter().next() {
        return Err(e);
    }
    for p in pts {
        raw.push((surface.s_at_polar_deg(p[0]), p[1].to_radians(), 0));
    }
    Ok(raw)
}
