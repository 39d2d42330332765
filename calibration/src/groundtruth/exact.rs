//! Rays against the exact protrusion primitives (`fabkit_designs::primitives`): the first
//! crossing of the union of the primitives, in closed form.
//!
//! The camera is outside every protrusion, so the first boundary crossing of any primitive is
//! an entry, and the first entry into the union is the smallest of the primitives' first
//! crossings. Shapes and conventions (flat-capped cylinders, solid cones with a base disc,
//! capsules, boxes with orthonormal axes, prisms over a simple counter-clockwise polygon) are
//! those of the JSON form written by `fabkit fixtures`.

use fabkit_designs::primitives::{add, cross, dot, norm, scale, sub, Primitive};

/// Why a primitive cannot be intersected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("primitives[{index}] ({kind}): {rule}")]
pub struct PrimitiveError {
    pub index: usize,
    pub kind: &'static str,
    pub rule: String,
}

/// A shape about a segment: from `a` along the unit axis `w` for length `h` (mm), radius `r`
/// (mm).
#[derive(Debug, Clone, Copy)]
struct Axial {
    a: [f64; 3],
    w: [f64; 3],
    h: f64,
    r: f64,
}

#[derive(Debug, Clone)]
enum Shape {
    Sphere {
        c: [f64; 3],
        r: f64,
    },
    /// Flat-capped cylinder of radius `r` round the segment.
    Cylinder(Axial),
    /// Solid cone: its apex at `a`, its base disc of radius `r` at the segment's end.
    Cone(Axial),
    /// The points within `r` of the segment.
    Capsule(Axial),
    /// Box: centre, orthonormal axes (rows), half extents.
    Box {
        c: [f64; 3],
        ax: [[f64; 3]; 3],
        e: [f64; 3],
    },
    /// Prism: origin, in-plane axes x, y, extrusion axis z, polygon, height.
    Prism {
        o: [f64; 3],
        ax: [[f64; 3]; 3],
        poly: Vec<[f64; 2]>,
        h: f64,
    },
}

/// A set of primitives ready for ray queries, each with a bounding sphere.
#[derive(Debug, Clone, Default)]
pub struct ExactPrimitives {
    shapes: Vec<(Shape, [f64; 3], f64)>,
}

/// First crossing: distance (mm), outward unit normal of the primitive, primitive index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    pub t_mm: f64,
    pub normal: [f64; 3],
    pub primitive: usize,
}

fn check_unit(v: [f64; 3]) -> bool {
    (norm(v) - 1.0).abs() < 1e-6
}

impl ExactPrimitives {
    /// Validates and prepares the primitives.
    ///
    /// # Errors
    /// [`PrimitiveError`] naming the first primitive with a non-finite number, a size that is
    /// not above 0, coincident end points, box or prism axes that are not orthonormal, or a
    /// polygon with fewer than 3 points or no positive area.
    pub fn new(prims: &[Primitive]) -> Result<ExactPrimitives, PrimitiveError> {
        let mut shapes = Vec::with_capacity(prims.len());
        for (index, p) in prims.iter().enumerate() {
            let err = |kind: &'static str, rule: String| PrimitiveError { index, kind, rule };
            let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
            let s = match p {
                Primitive::Sphere {
                    centre_mm,
                    radius_mm,
                } => {
                    if !(finite(centre_mm) && *radius_mm > 0.0 && radius_mm.is_finite()) {
                        return Err(err("sphere", format!("radius_mm = {radius_mm}: needs a finite centre and a radius above 0")));
                    }
                    Shape::Sphere {
                        c: *centre_mm,
                        r: *radius_mm,
                    }
                }
                Primitive::Cylinder {
                    base_mm,
                    top_mm,
                    radius_mm,
                }
                | Primitive::Capsule {
                    p0_mm: base_mm,
                    p1_mm: top_mm,
                    radius_mm,
                } => {
                    let kind = if matches!(p, Primitive::Cylinder { .. }) {
                        "cylinder"
                    } else {
                        "capsule"
                    };
                    let axis = sub(*top_mm, *base_mm);
                    let h = norm(axis);
                    if !(finite(base_mm)
                        && finite(top_mm)
                        && h > 0.0
                        && *radius_mm > 0.0
                        && radius_mm.is_finite())
                    {
                        return Err(err(kind, format!("length {h} mm, radius_mm = {radius_mm}: needs distinct finite end points and a radius above 0")));
                    }
                    let (a, w, r) = (*base_mm, scale(axis, 1.0 / h), *radius_mm);
                    if kind == "cylinder" {
                        Shape::Cylinder(Axial { a, w, h, r })
                    } else {
                        Shape::Capsule(Axial { a, w, h, r })
                    }
                }
                Primitive::Cone {
                    apex_mm,
                    base_mm,
                    base_radius_mm,
                } => {
                    let axis = sub(*base_mm, *apex_mm);
                    let h = norm(axis);
                    if !(finite(apex_mm)
                        && finite(base_mm)
                        && h > 0.0
                        && *base_radius_mm > 0.0
                        && base_radius_mm.is_finite())
                    {
                        return Err(err("cone", format!("height {h} mm, base_radius_mm = {base_radius_mm}: needs distinct finite apex and base and a radius above 0")));
                    }
                    Shape::Cone(Axial {
                        a: *apex_mm,
                        w: scale(axis, 1.0 / h),
                        h,
                        r: *base_radius_mm,
                    })
                }
                Primitive::Box {
                    centre_mm,
                    axes,
                    half_extents_mm,
                } => {
                    let ortho = axes.iter().all(|a| check_unit(*a))
                        && dot(axes[0], axes[1]).abs() < 1e-6
                        && dot(axes[0], axes[2]).abs() < 1e-6
                        && dot(axes[1], axes[2]).abs() < 1e-6;
                    if !(finite(centre_mm)
                        && ortho
                        && half_extents_mm.iter().all(|e| *e > 0.0 && e.is_finite()))
                    {
                        return Err(err("box", format!("half_extents_mm = {half_extents_mm:?}, axes = {axes:?}: needs orthonormal axes and half extents above 0")));
                    }
                    Shape::Box {
                        c: *centre_mm,
                        ax: *axes,
                        e: *half_extents_mm,
                    }
                }
                Primitive::Prism {
                    origin_mm,
                    x_axis,
                    y_axis,
                    polygon_mm,
                    height_mm,
                } => {
                    let n = polygon_mm.len();
                    let area2: f64 = (0..n)
                        .map(|i| {
                            let (a, b) = (polygon_mm[i], polygon_mm[(i + 1) % n]);
                            a[0] * b[1] - b[0] * a[1]
                        })
                        .sum();
                    let ortho = check_unit(*x_axis)
                        && check_unit(*y_axis)
                        && dot(*x_axis, *y_axis).abs() < 1e-6;
                    if !(finite(origin_mm)
                        && ortho
                        && n >= 3
                        && area2 > 0.0
                        && *height_mm > 0.0
                        && height_mm.is_finite())
                    {
                        return Err(err("prism", format!("{n} points, signed area {} mm2, height_mm = {height_mm}: needs orthonormal x_axis, y_axis, a counter-clockwise polygon and a height above 0", area2 / 2.0)));
                    }
                    Shape::Prism {
                        o: *origin_mm,
                        ax: [*x_axis, *y_axis, cross(*x_axis, *y_axis)],
                        poly: polygon_mm.clone(),
                        h: *height_mm,
                    }
                }
            };
            let (bc, br) = bounding_sphere(&s);
            shapes.push((s, bc, br));
        }
        Ok(ExactPrimitives { shapes })
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// Whether there is no primitive.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// Whether the point is inside (or on) any primitive's bounding sphere.
    pub fn near(&self, p: [f64; 3]) -> bool {
        self.shapes.iter().any(|(_, c, r)| norm(sub(p, *c)) <= *r)
    }

    /// Whether `p` is inside any primitive (sensor frame, mm).
    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.shapes.iter().any(|(s, _, _)| inside(s, p))
    }

    /// The first crossing of the union along `o + t d` with `0 < t < t_max_mm` (d a unit
    /// vector), or `None`.
    #[inline]
    pub fn first_crossing(&self, o: [f64; 3], d: [f64; 3], t_max_mm: f64) -> Option<Crossing> {
        self.first_crossing_among(o, d, t_max_mm, 0..self.shapes.len())
    }

    /// The bounding sphere of primitive `k`: (centre, radius), mm.
    pub fn bounding_sphere_of(&self, k: usize) -> ([f64; 3], f64) {
        let (_, c, r) = &self.shapes[k];
        (*c, *r)
    }

    /// [`Self::first_crossing`] of the primitives numbered `candidates` only (each index below
    /// [`Self::len`]; a repeated index is tested again).
    #[inline]
    pub fn first_crossing_among(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        t_max_mm: f64,
        candidates: impl IntoIterator<Item = usize>,
    ) -> Option<Crossing> {
        let mut best: Option<Crossing> = None;
        let mut tmax = t_max_mm;
        for k in candidates {
            let (s, c, r) = &self.shapes[k];
            // Bounding sphere: skip when the ray misses it or reaches it beyond tmax.
            let oc = sub(o, *c);
            let b = dot(oc, d);
            let cc = dot(oc, oc) - r * r;
            let disc = b * b - cc;
            if !(disc >= 0.0) || -b + disc.sqrt() <= 0.0 || -b - disc.sqrt() >= tmax {
                continue;
            }
            if let Some((t, n)) = crossing(s, o, d, tmax) {
                tmax = t;
                best = Some(Crossing {
                    t_mm: t,
                    normal: n,
                    primitive: k,
                });
            }
        }
        best
    }
}

fn bounding_sphere(s: &Shape) -> ([f64; 3], f64) {
    let slack = 1.0 + 1e-9;
    match s {
        Shape::Sphere { c, r } => (*c, r * slack + 1e-9),
        Shape::Cylinder(Axial { a, w, h, r }) | Shape::Capsule(Axial { a, w, h, r }) => {
            let cap = if matches!(s, Shape::Capsule(_)) {
                *r
            } else {
                0.0
            };
            (
                add(*a, scale(*w, h / 2.0)),
                ((h / 2.0 + cap).hypot(*r) + cap) * slack + 1e-9,
            )
        }
        Shape::Cone(Axial { a: apex, w, h, r }) => (
            add(*apex, scale(*w, h / 2.0)),
            (h / 2.0).hypot(*r) * slack + 1e-9,
        ),
        Shape::Box { c, e, .. } => (*c, norm(*e) * slack + 1e-9),
        Shape::Prism { o, ax, poly, h } => {
            let pts: Vec<[f64; 3]> = poly
                .iter()
                .flat_map(|q| {
                    let base = add(*o, add(scale(ax[0], q[0]), scale(ax[1], q[1])));
                    [base, add(base, scale(ax[2], *h))]
                })
                .collect();
            let n = pts.len() as f64;
            let c = pts
                .iter()
                .fold([0.0; 3], |acc, p| add(acc, scale(*p, 1.0 / n)));
            let r = pts.iter().map(|p| norm(sub(*p, c))).fold(0.0, f64::max);
            (c, r * slack + 1e-9)
        }
    }
}

/// Roots of `a t^2 + 2 b t + c = 0`, ascending.
#[inline]
fn roots(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    if a == 0.0 {
        if b == 0.0 {
            return None;
        }
        let t = -c / (2.0 * b);
        return Some((t, t));
    }
    let disc = b * b - a * c;
    if !(disc >= 0.0) {
        return None;
    }
    let s = disc.sqrt();
    let q = -(b + b.signum() * s);
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

fn unit_or(v: [f64; 3], fallback: [f64; 3]) -> [f64; 3] {
    let l = norm(v);
    if l > 0.0 {
        scale(v, 1.0 / l)
    } else {
        fallback
    }
}

/// Candidate crossing: keep it if 0 < t < best.
struct Best {
    t: f64,
    n: [f64; 3],
    found: bool,
}

impl Best {
    fn new(tmax: f64) -> Best {
        Best {
            t: tmax,
            n: [0.0; 3],
            found: false,
        }
    }
    #[inline]
    fn offer(&mut self, t: f64, n: impl FnOnce() -> [f64; 3]) {
        if t > 0.0 && t < self.t {
            self.t = t;
            self.n = n();
            self.found = true;
        }
    }
    fn get(self) -> Option<(f64, [f64; 3])> {
        self.found.then_some((self.t, self.n))
    }
}

/// Sphere crossings.
fn sphere_hits(c: [f64; 3], r: f64, o: [f64; 3], d: [f64; 3], best: &mut Best) {
    let oc = sub(o, c);
    if let Some((t0, t1)) = roots(1.0, dot(oc, d), dot(oc, oc) - r * r) {
        for t in [t0, t1] {
            best.offer(t, || {
                let p = add(o, scale(d, t));
                scale(sub(p, c), 1.0 / r)
            });
        }
    }
}

/// Crossings of the lateral surface of the cylinder of radius r about the line a + s w,
/// restricted to 0 <= s <= h.
fn tube_hits(a: [f64; 3], w: [f64; 3], h: f64, r: f64, o: [f64; 3], d: [f64; 3], best: &mut Best) {
    let oa = sub(o, a);
    let (dw, ow) = (dot(d, w), dot(oa, w));
    let dp = sub(d, scale(w, dw));
    let op = sub(oa, scale(w, ow));
    if let Some((t0, t1)) = roots(dot(dp, dp), dot(op, dp), dot(op, op) - r * r) {
        for t in [t0, t1] {
            let s = ow + t * dw;
            if (0.0..=h).contains(&s) {
                best.offer(t, || unit_or(add(op, scale(dp, t)), [0.0; 3]));
            }
        }
    }
}

/// Crossing of the disc of radius r centred at c with unit normal n (outward).
fn disc_hit(c: [f64; 3], n: [f64; 3], r: f64, o: [f64; 3], d: [f64; 3], best: &mut Best) {
    let den = dot(d, n);
    if den == 0.0 {
        return;
    }
    let t = dot(sub(c, o), n) / den;
    if t > 0.0 && t < best.t {
        let p = add(o, scale(d, t));
        if norm(sub(p, c)) <= r {
            best.offer(t, || n);
        }
    }
}

fn crossing(s: &Shape, o: [f64; 3], d: [f64; 3], tmax: f64) -> Option<(f64, [f64; 3])> {
    let mut best = Best::new(tmax);
    match s {
        Shape::Sphere { c, r } => sphere_hits(*c, *r, o, d, &mut best),
        Shape::Capsule(Axial { a, w, h, r }) => {
            tube_hits(*a, *w, *h, *r, o, d, &mut best);
            sphere_hits(*a, *r, o, d, &mut best);
            sphere_hits(add(*a, scale(*w, *h)), *r, o, d, &mut best);
        }
        Shape::Cylinder(Axial { a, w, h, r }) => {
            tube_hits(*a, *w, *h, *r, o, d, &mut best);
            disc_hit(*a, scale(*w, -1.0), *r, o, d, &mut best);
            disc_hit(add(*a, scale(*w, *h)), *w, *r, o, d, &mut best);
        }
        Shape::Cone(Axial { a: apex, w, h, r }) => {
            // Lateral surface: |q - (q.w) w|^2 = k^2 (q.w)^2 with q = p - apex, k = r / h,
            // on the nappe 0 <= q.w <= h.
            let k2 = (r / h) * (r / h);
            let q0 = sub(o, *apex);
            let (dw, qw) = (dot(d, *w), dot(q0, *w));
            let a = dot(d, d) - (1.0 + k2) * dw * dw;
            let b = dot(q0, d) - (1.0 + k2) * qw * dw;
            let c = dot(q0, q0) - (1.0 + k2) * qw * qw;
            if let Some((t0, t1)) = roots(a, b, c) {
                for t in [t0, t1] {
                    let s = qw + t * dw;
                    if (0.0..=*h).contains(&s) {
                        best.offer(t, || {
                            let q = add(q0, scale(d, t));
                            let radial = sub(q, scale(*w, s));
                            let rl = norm(radial);
                            // Outward normal: radial direction tilted back towards the apex.
                            if rl > 0.0 {
                                unit_or(sub(scale(radial, 1.0 / rl), scale(*w, r / h)), *w)
                            } else {
                                scale(*w, -1.0)
                            }
                        });
                    }
                }
            }
            disc_hit(add(*apex, scale(*w, *h)), *w, *r, o, d, &mut best);
        }
        Shape::Box { c, ax, e } => {
            // Slabs in the box frame.
            let oc = sub(o, *c);
            let (mut t_in, mut t_out) = (f64::NEG_INFINITY, f64::INFINITY);
            let mut n_in = [0.0; 3];
            for k in 0..3 {
                let (ok, dk) = (dot(oc, ax[k]), dot(d, ax[k]));
                if dk == 0.0 {
                    if ok.abs() > e[k] {
                        return None;
                    }
                    continue;
                }
                let (mut t0, mut t1) = ((-e[k] - ok) / dk, (e[k] - ok) / dk);
                let mut sgn = -1.0;
                if t0 > t1 {
                    std::mem::swap(&mut t0, &mut t1);
                    sgn = 1.0;
                }
                if t0 > t_in {
                    t_in = t0;
                    n_in = scale(ax[k], sgn);
                }
                t_out = t_out.min(t1);
            }
            if t_in <= t_out {
                best.offer(t_in, || n_in);
            }
        }
        Shape::Prism { o: po, ax, poly, h } => {
            let q = sub(o, *po);
            let lo = [dot(q, ax[0]), dot(q, ax[1]), dot(q, ax[2])];
            let ld = [dot(d, ax[0]), dot(d, ax[1]), dot(d, ax[2])];
            // Caps z = 0 and z = h.
            if ld[2] != 0.0 {
                for (z, n) in [(0.0, scale(ax[2], -1.0)), (*h, ax[2])] {
                    let t = (z - lo[2]) / ld[2];
                    if t > 0.0 && t < best.t {
                        let p = [lo[0] + t * ld[0], lo[1] + t * ld[1]];
                        if point_in_polygon(p, poly) {
                            best.offer(t, || n);
                        }
                    }
                }
            }
            // Side faces: edge i -> i+1, outward normal (dy, -dx) for a CCW polygon.
            let m = poly.len();
            for i in 0..m {
                let (a, b) = (poly[i], poly[(i + 1) % m]);
                let e = [b[0] - a[0], b[1] - a[1]];
                let n2 = [e[1], -e[0]];
                let den = n2[0] * ld[0] + n2[1] * ld[1];
                if den == 0.0 {
                    continue;
                }
                let t = (n2[0] * (a[0] - lo[0]) + n2[1] * (a[1] - lo[1])) / den;
                if !(t > 0.0 && t < best.t) {
                    continue;
                }
                let p = [lo[0] + t * ld[0], lo[1] + t * ld[1], lo[2] + t * ld[2]];
                let s = ((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / (e[0] * e[0] + e[1] * e[1]);
                if (0.0..=1.0).contains(&s) && (0.0..=*h).contains(&p[2]) {
                    best.offer(t, || {
                        unit_or(add(scale(ax[0], n2[0]), scale(ax[1], n2[1])), ax[0])
                    });
                }
            }
        }
    }
    best.get()
}

/// Even-odd point in polygon test.
fn point_in_polygon(p: [f64; 2], poly: &[[f64; 2]]) -> bool {
    let mut inside = false;
    let n = poly.len();
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            inside = !inside;
        }
        j = i;
    }
    inside
}

fn inside(s: &Shape, p: [f64; 3]) -> bool {
    let seg = |a: [f64; 3], w: [f64; 3], h: f64| {
        let s = dot(sub(p, a), w);
        (s, norm(sub(sub(p, a), scale(w, s))), h)
    };
    match s {
        Shape::Sphere { c, r } => norm(sub(p, *c)) <= *r,
        Shape::Cylinder(Axial { a, w, h, r }) => {
            let (s, rho, h) = seg(*a, *w, *h);
            (0.0..=h).contains(&s) && rho <= *r
        }
        Shape::Capsule(Axial { a, w, h, r }) => {
            let s = dot(sub(p, *a), *w).clamp(0.0, *h);
            norm(sub(p, add(*a, scale(*w, s)))) <= *r
        }
        Shape::Cone(Axial { a: apex, w, h, r }) => {
            let (s, rho, h) = seg(*apex, *w, *h);
            (0.0..=h).contains(&s) && rho <= r * s / h
        }
        Shape::Box { c, ax, e } => (0..3).all(|k| dot(sub(p, *c), ax[k]).abs() <= e[k]),
        Shape::Prism { o, ax, poly, h } => {
            let q = sub(p, *o);
            let z = dot(q, ax[2]);
            (0.0..=*h).contains(&z) && point_in_polygon([dot(q, ax[0]), dot(q, ax[1])], poly)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each primitive's first crossing from outside lies on its boundary: just before it the
    /// point is outside, just after it inside; the normal points out.
    #[test]
    fn first_crossings_are_entries_with_outward_normals() {
        let t = fabkit_designs::primitives::unit([0.3, -0.5, 0.8]);
        let prims = [
            Primitive::Sphere {
                centre_mm: [0.0, 0.0, 5.0],
                radius_mm: 1.2,
            },
            Primitive::Cylinder {
                base_mm: [0.5, 0.0, 4.0],
                top_mm: add([0.5, 0.0, 4.0], scale(t, 3.0)),
                radius_mm: 0.8,
            },
            Primitive::Cone {
                apex_mm: [0.0, 0.3, 4.0],
                base_mm: add([0.0, 0.3, 4.0], scale(t, 2.5)),
                base_radius_mm: 1.1,
            },
            Primitive::Capsule {
                p0_mm: [-0.5, 0.0, 4.5],
                p1_mm: add([-0.5, 0.0, 4.5], scale(t, 2.0)),
                radius_mm: 0.6,
            },
            Primitive::Box {
                centre_mm: [0.2, 0.1, 5.0],
                axes: [[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
                half_extents_mm: [1.0, 0.4, 0.7],
            },
            Primitive::Prism {
                origin_mm: [-1.0, -1.0, 4.2],
                x_axis: [1.0, 0.0, 0.0],
                y_axis: [0.0, 0.0, 1.0],
                polygon_mm: vec![
                    [0.0, 0.0],
                    [2.0, 0.0],
                    [2.0, 0.6],
                    [0.6, 0.6],
                    [0.6, 2.0],
                    [0.0, 2.0],
                ],
                height_mm: 1.5,
            },
        ];
        for (k, p) in prims.iter().enumerate() {
            let ex = ExactPrimitives::new(std::slice::from_ref(p)).unwrap();
            let mut hits = 0;
            for i in 0..400 {
                let a = i as f64 * 2.399_963;
                let z = 1.0 - 2.0 * ((i as f64 + 0.5) / 400.0);
                let d = [
                    (1.0 - z * z).sqrt() * a.cos(),
                    (1.0 - z * z).sqrt() * a.sin(),
                    z,
                ];
                let o = [0.1, 0.05, 4.8];
                let o = sub(o, scale(d, 10.0));
                assert!(!ex.contains(o));
                if let Some(c) = ex.first_crossing(o, d, f64::INFINITY) {
                    hits += 1;
                    let before = add(o, scale(d, c.t_mm - 1e-7));
                    let after = add(o, scale(d, c.t_mm + 1e-7));
                    assert!(
                        !ex.contains(before) && ex.contains(after),
                        "primitive {k} ray {i}"
                    );
                    assert!((norm(c.normal) - 1.0).abs() < 1e-9);
                    assert!(
                        dot(c.normal, d) <= 1e-9,
                        "primitive {k} ray {i}: normal {:?}",
                        c.normal
                    );
                    assert!(!ex.contains(add(add(o, scale(d, c.t_mm)), scale(c.normal, 1e-7))));
                }
            }
            // measured 71 to 400 hits
            assert!(hits > 50, "primitive {k}: {hits} hits");
        }
    }
}
