//! Times the stages of the ShadowTac open mold: `cargo run --release -p fabkit-designs --example marker_timing`
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::{layers, library, stack, ChordTolerance};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let tol = ChordTolerance::new(0.005)?;
    let d = library::load("shadowtac")?.with_preset("published_469")?;
    let t = Instant::now();
    let st = stack::validate(&d, &MaterialsTable::embedded()?, tol)?;
    println!("validate {:.3}", t.elapsed().as_secs_f64());
    let t = Instant::now();
    let pm = layers::place_layer_markers(&d, &st.layers[0], tol);
    println!(
        "place {:.3} ({} markers)",
        t.elapsed().as_secs_f64(),
        pm[0].markers.len()
    );
    {
        use fabkit_designs::geometry::{revolve, Solid};
        let t = Instant::now();
        let base = Solid::from_mesh(&revolve(&d.body.solid_profile(0.0, 1.0, tol.half()), tol)?)?;
        println!(
            "  base {:.3} ({} tris)",
            t.elapsed().as_secs_f64(),
            base.triangle_count()
        );
        let t = Instant::now();
        let local =
            fabkit_designs::markers::local_feature(&pm[0].spec.feature, pm[0].embed_mm, tol)?;
        let feats: Vec<Solid> = pm[0]
            .markers
            .iter()
            .map(|m| local.transform(&fabkit_designs::markers::frame_to(m.position_mm, m.normal)))
            .collect();
        println!(
            "  features {:.3} ({} tris each)",
            t.elapsed().as_secs_f64(),
            local.triangle_count()
        );
        let t = Instant::now();
        let c = Solid::compose(&feats);
        println!(
            "  compose {:.3} ({} tris)",
            t.elapsed().as_secs_f64(),
            c.triangle_count()
        );
        let t = Instant::now();
        let u = base.union(&c)?;
        println!(
            "  union {:.3} ({} tris)",
            t.elapsed().as_secs_f64(),
            u.triangle_count()
        );
        let t = Instant::now();
        let lm = local.mesh();
        let mut big = fabkit_designs::Mesh {
            vertices: vec![],
            triangles: vec![],
        };
        for mk in &pm[0].markers {
            let a = fabkit_designs::markers::frame_to(mk.position_mm, mk.normal);
            let off = big.vertices.len() as u32;
            big.vertices.extend(lm.vertices.iter().map(|v| {
                [
                    a[0][0] * v[0] + a[0][1] * v[1] + a[0][2] * v[2] + a[0][3],
                    a[1][0] * v[0] + a[1][1] * v[1] + a[1][2] * v[2] + a[1][3],
                    a[2][0] * v[0] + a[2][1] * v[1] + a[2][2] * v[2] + a[2][3],
                ]
            }));
            big.triangles.extend(
                lm.triangles
                    .iter()
                    .map(|t| [t[0] + off, t[1] + off, t[2] + off]),
            );
        }
        let c2 = Solid::from_mesh(&big)?;
        println!(
            "  concat+import {:.3} ({} tris)",
            t.elapsed().as_secs_f64(),
            c2.triangle_count()
        );
        let t = Instant::now();
        let u2 = base.union(&c2)?;
        println!(
            "  union2 {:.3} ({} tris)",
            t.elapsed().as_secs_f64(),
            u2.triangle_count()
        );
        let t = Instant::now();
        let m = u.mesh();
        println!(
            "  mesh out {:.3} ({} tris)",
            t.elapsed().as_secs_f64(),
            m.triangles.len()
        );
    }
    let t = Instant::now();
    let s = layers::layer_solid(&d, &st, 0, tol)?;
    println!(
        "layer_solid {:.3} ({} tris)",
        t.elapsed().as_secs_f64(),
        s.triangle_count()
    );
    let t = Instant::now();
    let out = layers::build_layer(&d, &st, 0, tol)?;
    println!(
        "build_layer {:.3} ({} tris)",
        t.elapsed().as_secs_f64(),
        out.parts[0].solid.triangle_count()
    );
    Ok(())
}

#[allow(dead_code)]
fn unused() {}
