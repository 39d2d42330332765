//! Replays a recorded fabkit CSG tree ("fabkit-csg/1", written by `fabkit export --csg`) in
//! fabkit's own kernel (manifold-rust behind `Solid`): the booleans alone, timed, as
//! `tests/oracles/replay_csg.py` times the same tree in manifold3d (C++ Manifold).
//!
//! Usage: `cargo run --release -p fabkit-designs --example replay_csg -- CSG.json [RUNS]`
//! - CSG.json: the file `fabkit export NAME --csg CSG.json` wrote.
//! - RUNS (default 5): timed evaluations; the best is reported.
//!
//! Leaf meshes are turned into solids first (`Solid::from_mesh`, with its closed-manifold
//! check; not timed, as the Python replay loads its leaves untimed). Then every part's root is
//! evaluated with shared nodes built once, in id order (children first), each operation the
//! `Solid` method that recorded it: `union` as `Solid::union_all`, `compose`, `difference`,
//! `intersection`, `transform`, `split_keep` as one side of `Solid::split_by_plane`. The parts
//! are evaluated one after another; a boolean may use the kernel's own threads
//! (manifold-rust's `parallel` feature), as manifold3d may use its own.
//!
//! Prints one JSON object on stdout: `seconds_best`, `seconds_runs`, `seconds_load_leaves`,
//! and per part its volume and triangle count against the recorded ones (`same`: both equal to
//! the bit, which they are when the replay repeats the export's operations). Exit status 0, 1
//! when a part differs from its record, 2 on an unreadable file or a kernel error.
use fabkit_designs::geometry::{transform, Mesh, Solid};
use serde_json::{json, Value};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(path), runs) = (args.first(), args.get(1)) else {
        eprintln!("usage: replay_csg CSG.json [RUNS]");
        std::process::exit(2);
    };
    let runs: usize = match runs.map(|r| r.parse()) {
        None => 5,
        Some(Ok(n)) if n >= 1 => n,
        _ => {
            eprintln!(
                "replay_csg: RUNS = {}: must be a whole number >= 1",
                args[1]
            );
            std::process::exit(2);
        }
    };
    match replay(path, runs) {
        Ok((out, all_same)) => {
            println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
            std::process::exit(if all_same { 0 } else { 1 });
        }
        Err(e) => {
            eprintln!("replay_csg: {path}: {e}");
            std::process::exit(2);
        }
    }
}

/// The replay's JSON record, and whether every part equals its record.
fn replay(path: &str, runs: usize) -> Result<(Value, bool), String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let doc: Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    if doc["format"] != "fabkit-csg/1" {
        return Err("format must be \"fabkit-csg/1\"".into());
    }
    let (Some(nodes), Some(parts)) = (doc["nodes"].as_array(), doc["parts"].as_array()) else {
        return Err("needs 'nodes' and 'parts' arrays".into());
    };
    let t0 = Instant::now();
    let mut leaves: Vec<Option<Solid>> = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        if n["op"] == "mesh" {
            let mesh = Mesh {
                vertices: serde_json::from_value(n["vertices"].clone())
                    .map_err(|e| format!("nodes[{i}].vertices: {e}"))?,
                triangles: serde_json::from_value(n["triangles"].clone())
                    .map_err(|e| format!("nodes[{i}].triangles: {e}"))?,
            };
            leaves[i] = Some(Solid::from_mesh(&mesh).map_err(|e| format!("nodes[{i}]: {e}"))?);
        }
    }
    let load_s = t0.elapsed().as_secs_f64();
    let roots: Vec<usize> = parts
        .iter()
        .enumerate()
        .map(|(j, p)| {
            p["root"]
                .as_u64()
                .map(|r| r as usize)
                .filter(|&r| r < nodes.len())
                .ok_or(format!("parts[{j}].root: must be a node id"))
        })
        .collect::<Result<_, _>>()?;
    let mut seconds = Vec::new();
    let mut solids = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        solids = evaluate(nodes, &leaves, &roots)?;
        seconds.push(t.elapsed().as_secs_f64());
    }
    let mut all_same = true;
    let rows: Vec<Value> = parts
        .iter()
        .zip(&solids)
        .map(|(p, s)| {
            let (volume, triangles) = (s.volume(), s.triangle_count());
            let same = p["volume_mm3"].as_f64().map(f64::to_bits) == Some(volume.to_bits())
                && p["triangles"].as_u64() == Some(triangles as u64);
            all_same &= same;
            json!({"name": p["name"], "volume_mm3": volume, "recorded_volume_mm3": p["volume_mm3"],
                   "triangles": triangles, "recorded_triangles": p["triangles"], "same": same})
        })
        .collect();
    let best = seconds.iter().copied().fold(f64::INFINITY, f64::min);
    let out = json!({"seconds_best": best, "seconds_runs": seconds,
                     "seconds_load_leaves": load_s, "kernel": "manifold-rust", "parts": rows});
    Ok((out, all_same))
}

/// The solids of `roots`, every node they need built once, children first.
fn evaluate(
    nodes: &[Value],
    leaves: &[Option<Solid>],
    roots: &[usize],
) -> Result<Vec<Solid>, String> {
    let child_ids = |i: usize| -> Result<Vec<usize>, String> {
        let ids: Vec<usize> = nodes[i]["children"]
            .as_array()
            .map(|c| {
                c.iter()
                    .filter_map(|x| x.as_u64().map(|x| x as usize))
                    .collect()
            })
            .unwrap_or_default();
        match ids.iter().find(|&&c| c >= i) {
            Some(c) => Err(format!("nodes[{i}].children: {c} is not below {i}")),
            None => Ok(ids),
        }
    };
    let mut needed = vec![false; nodes.len()];
    let mut stack = roots.to_vec();
    while let Some(i) = stack.pop() {
        if !needed[i] {
            needed[i] = true;
            stack.extend(child_ids(i)?);
        }
    }
    let mut memo: Vec<Option<Solid>> = vec![None; nodes.len()];
    for i in (0..nodes.len()).filter(|&i| needed[i]) {
        let n = &nodes[i];
        let ch: Vec<Solid> = child_ids(i)?
            .iter()
            .map(|&c| memo[c].clone().ok_or(format!("nodes[{c}] not built")))
            .collect::<Result<_, _>>()?;
        let kernel = |e: fabkit_designs::geometry::GeometryError| format!("nodes[{i}]: {e}");
        let s = match n["op"].as_str().unwrap_or("") {
            "mesh" => leaves[i].clone().ok_or(format!("nodes[{i}]: no mesh"))?,
            "union" => Solid::union_all(&ch).map_err(kernel)?,
            "compose" => Solid::compose(&ch),
            "difference" if ch.len() == 2 => ch[0].difference(&ch[1]).map_err(kernel)?,
            "intersection" if ch.len() == 2 => ch[0].intersection(&ch[1]).map_err(kernel)?,
            "transform" if ch.len() == 1 => {
                let a = transform::from_json(&n["matrix"])
                    .ok_or(format!("nodes[{i}].matrix: must be 3 rows of 4 numbers"))?;
                ch[0].transform(&a)
            }
            "split_keep" if ch.len() == 1 => {
                let normal: [f64; 3] = serde_json::from_value(n["normal"].clone())
                    .map_err(|e| format!("nodes[{i}].normal: {e}"))?;
                let offset = n["offset"]
                    .as_f64()
                    .ok_or(format!("nodes[{i}].offset: must be a number"))?;
                let (positive, negative) = ch[0].split_by_plane(normal, offset);
                if n["side"] == "positive" {
                    positive
                } else {
                    negative
                }
            }
            op => return Err(format!("nodes[{i}].op = {op:?} with {} children", ch.len())),
        };
        memo[i] = Some(s);
    }
    roots
        .iter()
        .map(|&r| memo[r].clone().ok_or(format!("nodes[{r}] not built")))
        .collect()
}
