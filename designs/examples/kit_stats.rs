//! Builds a library design and prints its parts: `cargo run --release -p fabkit-designs --example kit_stats -- rtac0 [direct|master]`
use fabkit_designs::{build_kit, library, ChordTolerance};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("rtac0");
    let mut d = library::load(name)?;
    if let Some(s) = args.get(2) {
        d.mold.strategy = if s == "direct" {
            fabkit_designs::schema::MoldStrategy::Direct
        } else {
            fabkit_designs::schema::MoldStrategy::Master
        };
    }
    let t0 = std::time::Instant::now();
    let kit = build_kit(&d, ChordTolerance::default())?;
    println!("built in {:.3} s", t0.elapsed().as_secs_f64());
    for p in &kit.parts {
        let m = p.solid.mesh();
        println!(
            "{:32} {:>10.2} mm3 genus {:2} shells {} tris {:7} bbox {:?} check {:?}",
            p.name,
            p.solid.volume(),
            p.solid.genus(),
            p.solid.shell_count(),
            m.triangles.len(),
            p.solid.bounding_box().map(|b| b.size()),
            m.check_closed_manifold()
        );
    }
    for c in &kit.casts {
        println!("{c:?}");
    }
    println!(
        "{}",
        serde_json::to_string_pretty(&kit.summary["envelope_mm"])?
    );
    Ok(())
}
