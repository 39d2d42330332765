//! What the camera sees of the skin's inside ([`view_fraction`]), through the lip's opening,
//! the LED ring and the shaft's bore.

use super::dimensions::{levels, radii, skin_layer};
use super::params::ShaftBodyParams;
use crate::parts::family::FamilyInput;

/// Fraction of the skin's inner surface the camera sees, in [0, 1]: area-weighted over the
/// inner surface above the base plane, a point counting when it lies inside the lens's view
/// cone and its ray from the lens passes the lip's opening, the LED ring's bore and the
/// shaft's bore (the pins' shadows and the gel's refraction ignored).
pub fn view_fraction(sb: &ShaftBodyParams, input: FamilyInput<'_>) -> f64 {
    let FamilyInput { ctx, stack, tol } = input;
    let Some(skin) = skin_layer(stack) else {
        return 0.0;
    };
    let r = radii(ctx, sb, stack);
    let lv = levels(ctx, sb);
    let first = stack
        .layers
        .first()
        .map_or(skin.inner_offset_mm, |l| l.inner_offset_mm);
    let curve = ctx.body.offset_polyline(first, 0.0, tol);
    let zl = lv.lens_z_mm;
    let tan_half = (sb.camera.view_angle_deg / 2.0).to_radians().tan();
    // apertures: (z of the top of the narrowing, radius)
    let apertures = [
        (lv.skin_base_z_mm, r.lip_inner_mm),
        (
            lv.led_pcb_z_mm + sb.led_ring.thickness_mm,
            sb.led_ring.inner_diameter_mm / 2.0,
        ),
        (lv.led_pcb_z_mm, r.shaft_bore_mm),
    ];
    let seen = |p: [f64; 2]| {
        let dz = p[1] - zl;
        dz > 0.0
            && p[0] <= dz * tan_half
            && apertures
                .iter()
                .all(|&(z, ra)| z >= p[1] || p[0] * (z - zl) / dz <= ra)
    };
    let (mut total, mut visible) = (0.0, 0.0);
    for w in curve.points.windows(2) {
        let (a, b) = (w[0], w[1]);
        if a[1] < lv.skin_base_z_mm - 1e-9 || b[1] < lv.skin_base_z_mm - 1e-9 {
            continue;
        }
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
        let n = 16;
        for k in 0..n {
            let t = (k as f64 + 0.5) / n as f64;
            let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            let da = 2.0 * std::f64::consts::PI * p[0] * len / n as f64;
            total += da;
            if seen(p) {
                visible += da;
            }
        }
    }
    if total > 0.0 {
        visible / total
    } else {
        0.0
    }
}
