//! The ground-truth speed figures of the user guide (docs/src/benchmarks.md, "Ground truth") in one run: fabkit's
//! frame casts on the issue-6 scene (640 x 480 fisheye frame, R-Tac0 skin with six
//! protrusions, about 200k triangles) and, with the oracle venv (`FABKIT_ORACLE_PYTHON` or
//! `.venv-oracles`), Open3D's RaycastingScene on the same triangles and rays, both on one
//! thread, best of N, CPU time. `scripts/bench-groundtruth` runs it.
//!
//! Usage: cargo run --release -p fabkit-calibration --example groundtruth_benchmark [-- TOL_MM [REPS]]
//! FABKIT_GT_PROFILE=full (or =fast) only repeats one cast, for a profiler; FABKIT_GT_KEEP=1
//! keeps the scene files given to Open3D (for tests/bvh_eval).

use fabkit_calibration::groundtruth::mesh::{CastOrder, FrameHits, Hit, MeshCaster};
use fabkit_calibration::groundtruth::synthetic::{
    thread_cpu_time_s as cpu, BenchScene, FrameScratch,
};
use std::path::PathBuf;

fn npy(shape: &[usize], data: &[f32]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let mut h = format!(
        "{{'descr': '<f4', 'fortran_order': False, 'shape': ({}), }}",
        dims.join(", ")
    );
    let total = 10 + h.len() + 1;
    h.push_str(&" ".repeat(total.div_ceil(64) * 64 - total));
    h.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    out.extend_from_slice(h.as_bytes());
    data.iter()
        .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    out
}

fn main() {
    let mut args = std::env::args().skip(1);
    let tol: f64 = args
        .next()
        .map(|s| s.parse().expect("TOL_MM"))
        .unwrap_or(0.00085);
    let reps: usize = args.next().map(|s| s.parse().expect("REPS")).unwrap_or(15);
    let scene = BenchScene::new(tol);
    let t0 = cpu();
    let (all, prot) = scene.casters();
    let build = cpu() - t0;
    let rays = &scene.rays;
    let t0 = cpu();
    rays.tiles();
    rays.raster();
    let tiles = cpu() - t0;
    let n = rays.len();
    println!(
        "scene: {} triangles (skin {}, protrusions {}) at {tol} mm, {n} rays; hierarchy build {:.0} ms, ray tiles and cube-face cells {:.1} ms (once per camera)",
        all.triangle_count(),
        scene.body_mesh.triangles.len(),
        scene.protrusion_mesh.triangles.len(),
        build * 1e3,
        tiles * 1e3
    );
    let inf = vec![f64::INFINITY; n];
    let mut out = FrameHits {
        t_mm: vec![],
        triangle: vec![],
        normal: vec![],
    };
    let mut full = f64::INFINITY;
    for _ in 0..reps {
        let t0 = cpu();
        all.cast_into(rays, &inf, &mut out);
        full = full.min(cpu() - t0);
    }
    let mut tiles_order = f64::INFINITY;
    for _ in 0..reps.min(5) {
        let t0 = cpu();
        all.cast_each_in(CastOrder::Tiles, rays, &inf, &mut |_| {});
        tiles_order = tiles_order.min(cpu() - t0);
    }
    let mut prot_orders = [f64::INFINITY; 2];
    let skin = MeshCaster::new(&scene.body_mesh).cast(rays, &inf).t_mm;
    for _ in 0..reps.min(5) {
        for (k, order) in [CastOrder::Tiles, CastOrder::Triangles]
            .into_iter()
            .enumerate()
        {
            let t0 = cpu();
            prot.cast_each_in(order, rays, &skin, &mut |_| {});
            prot_orders[k] = prot_orders[k].min(cpu() - t0);
        }
    }
    println!("orders: full cast in tiles {:.2} ms; protrusions up to the skin: tiles {:.2} ms, triangles {:.2} ms", tiles_order * 1e3, prot_orders[0] * 1e3, prot_orders[1] * 1e3);
    let mut scratch = FrameScratch::default();
    let mut hits: Vec<Hit> = Vec::new();
    let (mut all_rays, mut reachable, mut reference) =
        (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let (mut te, mut ts) = (vec![0.0; n], vec![0.0; n]);
    let mut cast = 0;
    for _ in 0..reps {
        let t0 = cpu();
        scene
            .surface
            .exit_all(rays.origin_mm, &rays.dirs, &mut te, &mut ts, None);
        reference = reference.min(cpu() - t0);
        let t0 = cpu();
        scene.protrusion_frame_all_rays(&prot, &mut scratch, &mut hits);
        all_rays = all_rays.min(cpu() - t0);
        let t0 = cpu();
        cast = scene.protrusion_frame(&prot, &mut scratch, &mut hits);
        reachable = reachable.min(cpu() - t0);
    }
    println!(
        "fabkit full cast: {:.2} ms CPU, {:.2} M rays per CPU-second",
        full * 1e3,
        n as f64 / full / 1e6
    );
    println!(
        "fabkit analytic reference for every ray ({:.2} ms) + protrusion triangles: {:.2} ms CPU per frame",
        reference * 1e3,
        all_rays * 1e3
    );
    println!(
        "fabkit reachable rays only ({cast} of {n}: closed-form skin + protrusion triangles): {:.2} ms CPU per frame",
        reachable * 1e3
    );
    if std::env::var("FABKIT_GT_PROFILE").is_ok_and(|v| v == "full") {
        for _ in 0..30 {
            all.cast_into(rays, &inf, &mut out);
        }
        return;
    }
    if std::env::var("FABKIT_GT_PROFILE").is_ok() {
        for _ in 0..300 {
            scene.protrusion_frame(&prot, &mut scratch, &mut hits);
        }
        return;
    }
    let py = std::env::var("FABKIT_ORACLE_PYTHON")
        .map(PathBuf::from)
        .ok()
        .or_else(|| {
            let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../.venv-oracles/bin/python");
            p.exists().then_some(p)
        });
    let Some(py) = py else {
        println!("Open3D: skipped (no oracle python; run scripts/setup-oracles)");
        return;
    };
    let d = std::env::temp_dir().join(format!("fabkit-gt-bench-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let mesh = scene.combined_mesh();
    let v: Vec<f32> = mesh
        .vertices
        .iter()
        .flat_map(|p| p.map(|c| c as f32))
        .collect();
    let t: Vec<f32> = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(|i| i as f32))
        .collect();
    let o = rays.origin_mm.map(|c| c as f32);
    let r: Vec<f32> = rays
        .dirs
        .iter()
        .flat_map(|dd| {
            let dd = if dd.iter().all(|c| c.is_finite()) {
                dd.map(|c| c as f32)
            } else {
                [0.0; 3]
            };
            [o[0], o[1], o[2], dd[0], dd[1], dd[2]]
        })
        .collect();
    std::fs::write(d.join("vertices.npy"), npy(&[mesh.vertices.len(), 3], &v)).unwrap();
    std::fs::write(d.join("triangles.npy"), npy(&[mesh.triangles.len(), 3], &t)).unwrap();
    std::fs::write(d.join("rays.npy"), npy(&[n, 6], &r)).unwrap();
    let script =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/oracles/open3d_raycast.py");
    let o = std::process::Command::new(&py)
        .arg(script)
        .arg(&d)
        .arg("--time")
        .arg(reps.to_string())
        .output()
        .unwrap();
    // FABKIT_GT_KEEP=1 keeps the scene files (vertices.npy, triangles.npy, rays.npy) for other tools.
    if std::env::var("FABKIT_GT_KEEP").is_ok_and(|v| v == "1") {
        println!("scene files kept in {}", d.display());
    } else {
        let _ = std::fs::remove_dir_all(&d);
    }
    if !o.status.success() {
        println!("Open3D failed: {}", String::from_utf8_lossy(&o.stderr));
        return;
    }
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let o3d = j["best_cpu_s"].as_f64().unwrap();
    println!(
        "Open3D {} RaycastingScene (nthreads=1), same triangles and rays: {:.2} ms CPU, {:.2} M rays per CPU-second",
        j["open3d_version"],
        o3d * 1e3,
        n as f64 / o3d / 1e6
    );
    println!(
        "ratio of Open3D's full cast to fabkit's: full cast {:.2}, analytic + protrusions {:.2}, reachable rays only {:.2}",
        o3d / full,
        o3d / all_rays,
        o3d / reachable
    );
}
