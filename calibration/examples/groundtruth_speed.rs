//! Quick timing of the ground-truth casts on the benchmark scene (the criterion bench is
//! `cargo bench -p fabkit-calibration --bench groundtruth`).
use fabkit_calibration::groundtruth::synthetic::BenchScene;
use fabkit_calibration::groundtruth::*;
use std::time::Instant;

fn cpu() -> f64 {
    fabkit_calibration::groundtruth::synthetic::thread_cpu_time_s()
}

fn main() {
    let tol: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(0.0015);
    let t0 = Instant::now();
    let s = BenchScene::new(tol);
    println!(
        "scene {:.2} s: body {} tris, protrusions {} tris",
        t0.elapsed().as_secs_f64(),
        s.body_mesh.triangles.len(),
        s.protrusion_mesh.triangles.len()
    );
    let t0 = Instant::now();
    let (all, prot) = s.casters();
    println!(
        "bvh build {:.3} s ({} nodes)",
        t0.elapsed().as_secs_f64(),
        all.node_count()
    );
    let n = s.rays.len();
    let t0 = cpu();
    s.rays.tiles();
    println!("ray tiles {:.2} ms (once per camera)", (cpu() - t0) * 1e3);
    let inf = vec![f64::INFINITY; n];
    let mut best = f64::INFINITY;
    let mut hits = None;
    for _ in 0..15 {
        let t0 = cpu();
        let h = all.cast(&s.rays, &inf);
        best = best.min(cpu() - t0);
        hits = Some(h);
    }
    println!(
        "full cast {:.2} ms, {:.2} M rays/s",
        best * 1e3,
        n as f64 / best / 1e6
    );
    let mut bestf = f64::INFINITY;
    let (mut te, mut ts, mut nn) = (vec![0.0; n], vec![0.0; n], vec![[0.0; 3]; n]);
    let mut out = mesh::FrameHits {
        t_mm: vec![],
        triangle: vec![],
        normal: vec![],
    };
    for _ in 0..15 {
        let t0 = cpu();
        s.surface
            .exit_all(s.rays.origin_mm, &s.rays.dirs, &mut te, &mut ts, &mut nn);
        for t in te.iter_mut() {
            if !t.is_finite() {
                *t = 0.0;
            }
        }
        prot.cast_into(&s.rays, &te, &mut out);
        std::hint::black_box(&out);
        bestf = bestf.min(cpu() - t0);
    }
    let t0 = cpu();
    for _ in 0..5 {
        s.surface
            .exit_all(s.rays.origin_mm, &s.rays.dirs, &mut te, &mut ts, &mut nn);
    }
    println!("exit_all alone {:.2} ms", (cpu() - t0) / 5.0 * 1e3);
    let t0 = cpu();
    for _ in 0..5 {
        std::hint::black_box(reference_hits(&s.rays, &s.surface));
    }
    println!("reference_hits alone {:.2} ms", (cpu() - t0) / 5.0 * 1e3);
    let zero = vec![0.0; n];
    let t0 = cpu();
    for _ in 0..5 {
        std::hint::black_box(prot.cast(&s.rays, &zero));
    }
    println!(
        "cast with all rays inactive {:.2} ms",
        (cpu() - t0) / 5.0 * 1e3
    );
    let r = reference_hits(&s.rays, &s.surface);
    let limit: Vec<f64> = r
        .t_exit_mm
        .iter()
        .map(|t| if t.is_finite() { *t } else { 0.0 })
        .collect();
    let t0 = cpu();
    for _ in 0..5 {
        std::hint::black_box(prot.cast(&s.rays, &limit));
    }
    println!("protrusion cast alone {:.2} ms", (cpu() - t0) / 5.0 * 1e3);
    println!(
        "analytic reference + protrusion triangles {:.2} ms",
        bestf * 1e3
    );
    // accuracy of the mesh cast against the exact render
    let r = reference_hits(&s.rays, &s.surface);
    let ex = indented_hits(&s.rays, &r, &s.exact, s.surface.base_z_mm());
    let h = hits.unwrap();
    let (mut worst, mut mism) = (0.0f64, 0);
    for p in 0..n {
        let a = ex.t_exit_mm[p].min(if ex.contact[p] {
            ex.t_mm[p]
        } else {
            f64::INFINITY
        });
        let b = h.t_mm[p];
        let b = if ex.t_mm[p].is_finite() { b } else { f64::NAN };
        let a = if ex.t_mm[p].is_finite() { a } else { f64::NAN };
        if a.is_finite() != b.is_finite() {
            mism += 1;
            continue;
        }
        if a.is_finite() && (a - b).abs() > worst {
            worst = (a - b).abs();
            if worst > 0.01 && mism < 1000 {
                mism += 1000;
                println!(
                    "pixel {p} ({}, {}): exact {a} contact {} mesh {b} tri {}",
                    p % 640,
                    p / 640,
                    ex.contact[p],
                    h.triangle[p]
                );
            }
        }
    }
    println!("mesh vs exact: worst {:.4} mm, mismatches {mism}", worst);
}
