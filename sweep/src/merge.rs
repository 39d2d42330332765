//! `fabkit sweep merge`: joins the results tables of the shards of one sweep.

use super::results::{render_csv, render_jsonl, VariantResult};
use super::run::{
    claim_sweep_dir, json_pretty, read_record, write_atomic, SweepRecord, RESULTS_CSV,
    RESULTS_JSONL, SWEEP_JSON,
};
use super::SweepError;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// What [`merge`] wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct MergeSummary {
    pub shards: usize,
    pub variants: usize,
    pub results_csv: PathBuf,
    pub results_jsonl: PathBuf,
}

/// Joins the results of the shard folders `dirs` (each written by a run with `--shard I/N`)
/// into `out`: `results.csv` and `results.jsonl` in variant order, the same bytes as one
/// unsharded run of the sweep gives (with `build_time` false on both sides; see
/// [`super::RunOptions::build_time`]), and a `sweep.json` listing the shards and recording
/// `command_line`.
///
/// Checks, before writing anything: every folder holds a finished run (`sweep.json` and
/// `results.jsonl`) of the same sweep (same plan hash, variant count, parameters and fabkit
/// version) split into the same N shards; no shard appears twice and none is missing; every
/// row belongs to its folder's shard and no variant appears twice; every variant of the sweep
/// has a row; the ids in order give the sweep's plan hash.
///
/// # Errors
/// [`SweepError::Merge`] naming the folders and shards at fault, [`SweepError::Io`],
/// [`SweepError::ForeignDirectory`] for an `out` that holds something else,
/// [`SweepError::OtherSweep`] for one that holds another sweep's output (unless `force`, which
/// replaces it whole).
pub fn merge(
    dirs: &[PathBuf],
    out: &Path,
    build_time: bool,
    command_line: Vec<String>,
    force: bool,
) -> Result<MergeSummary, SweepError> {
    let err = |m: String| SweepError::Merge(m);
    if dirs.is_empty() {
        return Err(err("no shard folders given".into()));
    }
    for d in dirs {
        if same_dir(d, out) {
            return Err(err(format!(
                "the output folder {} is one of the shard folders; merge into a new folder",
                out.display()
            )));
        }
    }
    let mut records: Vec<(PathBuf, SweepRecord)> = Vec::new();
    for d in dirs {
        records.push((d.clone(), read_record(d)?));
    }
    let first = &records[0].1;
    let n = first.shard.map(|s| s.count).unwrap_or(1);
    check_same_sweep(&records)?;
    let by_shard = check_shards(&records, n)?;
    // Rows: each in its shard, none twice, none missing.
    let total = first.variant_count;
    let mut rows: Vec<Option<VariantResult>> = vec![None; total];
    for (d, r) in &records {
        let p = d.join(RESULTS_JSONL);
        let text = std::fs::read_to_string(&p).map_err(|e| {
            err(format!(
                "{}: {e}: the shard's run did not finish; run it again (it resumes)",
                p.display()
            ))
        })?;
        for (k, line) in text.lines().enumerate() {
            let row: VariantResult = serde_json::from_str(line)
                .map_err(|e| err(format!("{}:{}: {e}", p.display(), k + 1)))?;
            let i = row.index;
            let belongs = i < total && r.shard.is_none_or(|s| s.contains(i));
            if !belongs {
                return Err(err(format!(
                    "{}:{}: variant {i} does not belong to shard {}",
                    p.display(),
                    k + 1,
                    shard_name(r)
                )));
            }
            if rows[i].is_some() {
                return Err(err(format!(
                    "shards overlap: variant {i} ({}) appears twice (again in {})",
                    row.id,
                    p.display()
                )));
            }
            rows[i] = Some(row);
        }
    }
    let absent: Vec<usize> = (0..total).filter(|&i| rows[i].is_none()).collect();
    if let Some(&i) = absent.first() {
        let shard = i % n;
        return Err(err(format!(
            "{} variant(s) have no result, e.g. variant {i} of shard {shard}/{n} ({}); run that shard again (it resumes)",
            absent.len(),
            by_shard[shard].map(|d| d.display().to_string()).unwrap_or_default()
        )));
    }
    let mut rows: Vec<VariantResult> = rows.into_iter().flatten().collect();
    let mut h = Sha256::new();
    for r in &rows {
        h.update(r.id.as_bytes());
        h.update(b"\n");
    }
    if super::plan::hex(&h.finalize()) != first.plan_sha256 {
        return Err(err(
            "the ids of the rows do not make the sweep's plan: a shard table was edited or mixed up"
                .into(),
        ));
    }
    if !build_time {
        for r in &mut rows {
            r.build_time_s = None;
        }
    }
    let mut rec = first.clone();
    rec.shard = None;
    rec.build_time = build_time;
    rec.merged_from = records
        .iter()
        .map(|(d, _)| d.display().to_string())
        .collect();
    rec.command_line = command_line;
    claim_sweep_dir(out, &rec, force)?;
    let csv = out.join(RESULTS_CSV);
    let jsonl = out.join(RESULTS_JSONL);
    write_atomic(&out.join(SWEEP_JSON), &json_pretty(&rec))?;
    write_atomic(&jsonl, &render_jsonl(&rows))?;
    write_atomic(&csv, &render_csv(&first.parameters, &rows))?;
    Ok(MergeSummary {
        shards: n,
        variants: total,
        results_csv: csv,
        results_jsonl: jsonl,
    })
}

/// Every record after the first is of the same sweep (variants, varied parameters, fabkit
/// version) and of the same split into shards as the first.
///
/// # Errors
/// [`SweepError::Merge`] naming the folder that differs and how.
fn check_same_sweep(records: &[(PathBuf, SweepRecord)]) -> Result<(), SweepError> {
    let err = |m: String| SweepError::Merge(m);
    let (first_dir, first) = &records[0];
    let n = first.shard.map(|s| s.count).unwrap_or(1);
    for (d, r) in &records[1..] {
        let what = if r.plan_sha256 != first.plan_sha256 || r.variant_count != first.variant_count {
            Some("a different sweep (its variants differ)")
        } else if r.parameters != first.parameters {
            Some("a different sweep (its varied parameters differ)")
        } else if r.fabkit_version != first.fabkit_version {
            Some("another fabkit version")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(err(format!(
                "{} holds {what} than {}",
                d.display(),
                first_dir.display()
            )));
        }
        if r.shard.map(|s| s.count).unwrap_or(1) != n {
            return Err(err(format!(
                "{} is shard {} but {} is shard {}: shards of different splits",
                d.display(),
                shard_name(r),
                first_dir.display(),
                shard_name(first)
            )));
        }
    }
    Ok(())
}

/// Every shard of the `n` exactly once among the records; the folder of each shard.
///
/// # Errors
/// [`SweepError::Merge`] naming two folders of one shard, or the missing shards.
fn check_shards(
    records: &[(PathBuf, SweepRecord)],
    n: usize,
) -> Result<Vec<Option<&Path>>, SweepError> {
    let err = |m: String| SweepError::Merge(m);
    let mut by_shard: Vec<Option<&Path>> = vec![None; n];
    for (d, r) in records {
        let i = r.shard.map(|s| s.index).unwrap_or(0);
        if let Some(other) = by_shard[i] {
            return Err(err(format!(
                "shards overlap: {} and {} are both shard {i}/{n}",
                other.display(),
                d.display()
            )));
        }
        by_shard[i] = Some(d);
    }
    let missing: Vec<String> = by_shard
        .iter()
        .enumerate()
        .filter(|(_, d)| d.is_none())
        .map(|(i, _)| format!("{i}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(err(format!(
            "missing shard(s) {} of the {n}; run them with --shard and pass their folders",
            missing.join(", ")
        )));
    }
    Ok(by_shard)
}

fn shard_name(r: &SweepRecord) -> String {
    r.shard
        .map(|s| s.to_string())
        .unwrap_or_else(|| "0/1 (unsharded)".into())
}

fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}
