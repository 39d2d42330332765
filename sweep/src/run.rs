//! Running a sweep into its folder: parallel over variants, one result file per variant
//! written atomically, resume, shards.

use super::file::{FileOutputs, Mode, SweepSpec};
use super::plan::{hex, Plan, Shard, Variant};
use super::results::{render_csv, render_jsonl, Status, VariantResult};
use super::variants::{evaluate_variant, WriteFiles};
use super::SweepError;
use fabkit_designs::kit::Kit;
use fabkit_designs::materials::MaterialsTable;
use fabkit_designs::schema::Design;
use fabkit_designs::variant::canonical_json;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Format tag of `sweep.json`.
pub const FORMAT: &str = "fabkit-sweep/1";

/// How to run a sweep.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// The sweep folder: created if missing; a folder that holds something other than a
    /// fabkit sweep is refused.
    pub out_dir: PathBuf,
    /// Worker threads (variants built at once); `None`: one per core.
    pub jobs: Option<usize>,
    /// Run only this shard's variants.
    pub shard: Option<Shard>,
    /// Write each variant's build time into `results.csv` / `results.jsonl`. Without it the
    /// `build_time_s` cells are empty and the tables are the same bytes for the same sweep on
    /// any machine, thread count or sharding (each `variants/<id>.json` keeps its time).
    pub build_time: bool,
    /// The command line, recorded in `sweep.json` and in exported files.
    pub command_line: Vec<String>,
    /// fabkit version, recorded with every result; results of another version are recomputed.
    pub fabkit_version: String,
    /// Bound on each variant's estimated triangles ([`fabkit_designs::estimate::check_work`]); a variant
    /// past it is recorded with status error, before its kit is built.
    pub max_triangles: u64,
    /// Replace a folder that holds another sweep's output (another sweep file or plan, or
    /// another shard) whole, instead of refusing it ([`claim_sweep_dir`]).
    pub force: bool,
}

/// Writes the files of one variant ([`ExportWriter`]: those of `fabkit export`).
pub trait KitWriter: Sync {
    /// Writes `kit` into `job.dir` (replacing a previous export there) with the formats of
    /// `job.files`.
    ///
    /// # Errors
    /// A message; the variant is recorded with status error.
    fn write(&self, kit: &Kit, job: &FilesJob<'_>) -> Result<(), String>;
}

/// What a [`KitWriter`] gets besides the kit.
#[derive(Debug)]
pub struct FilesJob<'a> {
    /// `<sweep folder>/variants/<id>`.
    pub dir: PathBuf,
    pub files: FileOutputs,
    pub variant: &'a Variant,
    pub design: &'a Design,
    /// sha256 of the variant's resolved design (canonical JSON), 64 hex digits.
    pub design_sha256: String,
    /// `<base source> variant <id> of sweep <sweep file>`.
    pub design_source: String,
    pub chord_tolerance_mm: f64,
}

impl<'a> FilesJob<'a> {
    /// The job of variant `v` (its resolved `design`) into `dir`, its manifest naming
    /// `design_source` and the sha256 of the design's canonical JSON.
    pub fn new(
        dir: PathBuf,
        files: FileOutputs,
        variant: &'a Variant,
        design: &'a Design,
        design_source: String,
        chord_tolerance_mm: f64,
    ) -> FilesJob<'a> {
        let canon = canonical_json(&serde_json::to_value(design).unwrap_or_default());
        FilesJob {
            dir,
            files,
            variant,
            design,
            design_sha256: hex(&Sha256::digest(canon.as_bytes())),
            design_source,
            chord_tolerance_mm,
        }
    }
}

/// Writes a variant's files with `fabkit export`'s writer, into `variants/<id>/` of the sweep
/// folder (which the sweep checks is its own), laid out for the shipped printers' beds.
#[derive(Debug, Clone)]
pub struct ExportWriter {
    /// The command line recorded in each variant's manifest.json.
    pub command_line: Vec<String>,
}

impl KitWriter for ExportWriter {
    fn write(&self, kit: &Kit, job: &FilesJob<'_>) -> Result<(), String> {
        use fabkit_export::{write_kit, ExportOptions, Formats, OutputCommand};
        let opts = ExportOptions {
            formats: Formats {
                stl: job.files.stl,
                threemf: job.files.threemf,
                step: false,
                mjcf: false,
                urdf: false,
                usd: false,
            },
            command_line: self.command_line.clone(),
            design_source: job.design_source.clone(),
            design_sha256: job.design_sha256.clone(),
            chord_tolerance_mm: job.chord_tolerance_mm,
            fabkit_version: env!("CARGO_PKG_VERSION").to_string(),
            printers: Default::default(),
            command: OutputCommand::SweepVariant,
            force: false,
            sim: Default::default(),
        };
        write_kit(kit, &job.dir, &opts)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
}

/// Progress of a run, reported from the worker threads.
#[derive(Debug)]
pub enum Event<'a> {
    /// Before the first variant: `selected` variants in this shard (of `total`), of which
    /// `complete` already have a result and are skipped.
    Start {
        total: usize,
        selected: usize,
        complete: usize,
    },
    /// A variant finished (in completion order, not index order).
    Done(&'a VariantResult),
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    /// Variants in the sweep.
    pub total: usize,
    /// Variants in this shard (all of them without a shard).
    pub selected: usize,
    /// Variants skipped because their results were complete.
    pub reused: usize,
    /// Ids of the variants built by this run, in index order.
    pub ran: Vec<String>,
    pub ok: usize,
    pub infeasible: usize,
    pub errors: usize,
    pub results_csv: PathBuf,
    pub results_jsonl: PathBuf,
}

/// `sweep.json`: what a sweep folder holds and how it was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRecord {
    /// [`FORMAT`].
    pub format: String,
    pub fabkit_version: String,
    pub sweep_file: String,
    pub sweep_sha256: String,
    pub base_source: String,
    pub base_sha256: String,
    pub preset: Option<String>,
    pub chord_tolerance_mm: f64,
    pub mode: Mode,
    pub seed: Option<u64>,
    pub count: Option<u64>,
    /// The varied parameter paths, in order (the CSV's parameter columns).
    pub parameters: Vec<String>,
    pub files: FileOutputs,
    /// Variants in the whole sweep.
    pub variant_count: usize,
    /// sha256 of the ids of the whole sweep, in order ([`Plan::plan_sha256`]).
    pub plan_sha256: String,
    /// The shard this folder holds; `None` for the whole sweep.
    pub shard: Option<Shard>,
    pub build_time: bool,
    pub command_line: Vec<String>,
    /// For a merged folder: the shard folders it was merged from.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub merged_from: Vec<String>,
}

pub(crate) const SWEEP_JSON: &str = "sweep.json";
pub(crate) const RESULTS_CSV: &str = "results.csv";
pub(crate) const RESULTS_JSONL: &str = "results.jsonl";
const VARIANTS: &str = "variants";

/// Writes `bytes` to `path` through a synced temporary sibling renamed into place, so that
/// `path` holds either its old content or all of the new one, even if the process is killed.
///
/// # Errors
/// [`SweepError::Io`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), SweepError> {
    let io = |e: std::io::Error| SweepError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// Whether `name` is a variant id (16 lowercase hex digits).
fn is_variant_id(name: &str) -> bool {
    name.len() == crate::plan::ID_HEX_DIGITS
        && name
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
}

/// Whether `name` in `variants/` is a temporary a killed run left: `tempfile`'s `.tmp*` file of
/// an atomic write, or an export's `.<id>.tmp-*` / `.<id>.old-*` folder.
fn is_leftover(name: &str) -> bool {
    if name.starts_with(".tmp") {
        return true;
    }
    let Some(rest) = name.strip_prefix('.') else {
        return false;
    };
    rest.split_once('.').is_some_and(|(id, tail)| {
        is_variant_id(id) && (tail.starts_with("tmp-") || tail.starts_with("old-"))
    })
}

/// The first entry of the non-empty folder `dir` that a sweep does not write, and why; `None`
/// when `dir` holds a fabkit sweep record (`sweep.json`) and nothing but what a sweep writes:
/// `sweep.json`, `results.csv`, `results.jsonl`, a `.tmp*` file of an interrupted atomic write,
/// and `variants/` with `<id>.json` files, `<id>/` export folders and a killed run's temporaries.
fn foreign_entry(dir: &Path) -> Result<Option<(String, &'static str)>, SweepError> {
    let io = |p: &Path| {
        let p = p.display().to_string();
        move |e: std::io::Error| SweepError::Io {
            path: p.clone(),
            message: e.to_string(),
        }
    };
    let record = dir.join(SWEEP_JSON);
    let is_record =
        std::fs::symlink_metadata(&record).is_ok_and(|m| m.is_file()) && read_record(dir).is_ok();
    if !is_record {
        let why = if record.exists() {
            "is there, and the folder's sweep.json is not a fabkit sweep record"
        } else {
            "is there, and the folder holds no fabkit sweep (sweep.json)"
        };
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .map_err(io(dir))?
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        let first = names
            .iter()
            .find(|n| n.as_str() != SWEEP_JSON)
            .or(names.first())
            .cloned()
            .unwrap_or_default();
        return Ok(Some((first, why)));
    }
    for e in std::fs::read_dir(dir).map_err(io(dir))? {
        let e = e.map_err(io(dir))?;
        let name = e.file_name().to_string_lossy().into_owned();
        let t = e.file_type().map_err(io(&e.path()))?;
        let ok = match name.as_str() {
            SWEEP_JSON | RESULTS_CSV | RESULTS_JSONL => t.is_file(),
            VARIANTS => t.is_dir(),
            n => n.starts_with(".tmp") && t.is_file(),
        };
        if !ok {
            return Ok(Some((name, "is not a file a sweep writes")));
        }
    }
    let vdir = dir.join(VARIANTS);
    if vdir.is_dir() {
        for e in std::fs::read_dir(&vdir).map_err(io(&vdir))? {
            let e = e.map_err(io(&vdir))?;
            let name = e.file_name().to_string_lossy().into_owned();
            let t = e.file_type().map_err(io(&e.path()))?;
            let ok = if let Some(id) = name.strip_suffix(".json") {
                is_variant_id(id) && t.is_file()
            } else {
                (is_variant_id(&name) && t.is_dir()) || (is_leftover(&name) && !t.is_symlink())
            };
            if !ok {
                return Ok(Some((
                    format!("{VARIANTS}/{name}"),
                    "is not a file a sweep writes",
                )));
            }
        }
    }
    Ok(None)
}

/// Prepares `dir` as a sweep folder: a missing or empty folder, or one that holds a fabkit sweep
/// and nothing else (see [`foreign_entry`]). A folder of the user's, even one with a
/// `sweep.json` of its own, is refused and left untouched.
pub(crate) fn claim_dir(dir: &Path) -> Result<(), SweepError> {
    let io = |e: std::io::Error| SweepError::Io {
        path: dir.display().to_string(),
        message: e.to_string(),
    };
    let foreign = |entry: String, why: &str| SweepError::ForeignDirectory {
        path: dir.display().to_string(),
        entry,
        why: why.to_string(),
    };
    match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(io(e)),
        Ok(md) if md.file_type().is_symlink() || !md.is_dir() => {
            let what = if md.file_type().is_symlink() {
                "is a symbolic link (hint: pass the target folder itself)"
            } else {
                "is not a folder"
            };
            return Err(foreign(String::new(), what));
        }
        Ok(_) => {
            let empty = std::fs::read_dir(dir).map_err(io)?.next().is_none();
            if !empty {
                if let Some((entry, why)) = foreign_entry(dir)? {
                    return Err(foreign(entry, why));
                }
            }
        }
    }
    std::fs::create_dir_all(dir).map_err(io)
}

/// A sweep's output in words, for the refusal of a folder that holds another one: its sweep
/// file, the first 12 hex digits of its sha256, and its shard or merge.
fn sweep_words(r: &SweepRecord) -> String {
    let what = match (&r.shard, r.merged_from.is_empty()) {
        (Some(s), _) => format!("shard {s}"),
        (None, false) => format!("merged from {} shards", r.merged_from.len()),
        (None, true) => "all variants".to_string(),
    };
    format!(
        "{} (sweep file sha256 {}..., {} variants, {what})",
        r.sweep_file,
        &r.sweep_sha256[..r.sweep_sha256.len().min(12)],
        r.variant_count
    )
}

/// [`claim_dir`], and a folder that holds another sweep's output is refused, naming both: a
/// sweep folder holds one sweep, so that its tables list exactly the variants beside them.
/// The same sweep (sweep file and plan) is another sweep's unless it is the same shard, or
/// for a merge (`ours` merged from shards) the whole sweep. With `force` the other sweep's
/// folder is emptied first (it holds only a fabkit sweep's files, [`claim_dir`] checked), so
/// that nothing of it is mixed with this one.
///
/// # Errors
/// [`SweepError::ForeignDirectory`], [`SweepError::OtherSweep`], [`SweepError::Io`].
pub(crate) fn claim_sweep_dir(
    dir: &Path,
    ours: &SweepRecord,
    force: bool,
) -> Result<(), SweepError> {
    claim_dir(dir)?;
    if !dir.join(SWEEP_JSON).exists() {
        return Ok(());
    }
    // claim_dir refused a folder whose sweep.json is not a record fabkit wrote
    let theirs = read_record(dir)?;
    let same_sweep =
        theirs.sweep_sha256 == ours.sweep_sha256 && theirs.plan_sha256 == ours.plan_sha256;
    let same_part = if ours.merged_from.is_empty() {
        theirs.shard == ours.shard && theirs.merged_from.is_empty()
    } else {
        theirs.shard.is_none()
    };
    if same_sweep && same_part {
        return Ok(());
    }
    if !force {
        return Err(SweepError::OtherSweep {
            path: dir.display().to_string(),
            theirs: sweep_words(&theirs),
            ours: sweep_words(ours),
        });
    }
    let io = |p: &Path| {
        let p = p.display().to_string();
        move |e: std::io::Error| SweepError::Io {
            path: p.clone(),
            message: e.to_string(),
        }
    };
    for e in std::fs::read_dir(dir).map_err(io(dir))? {
        let p = e.map_err(io(dir))?.path();
        let md = std::fs::symlink_metadata(&p).map_err(io(&p))?;
        if md.is_dir() {
            std::fs::remove_dir_all(&p).map_err(io(&p))?;
        } else {
            std::fs::remove_file(&p).map_err(io(&p))?;
        }
    }
    Ok(())
}

pub(crate) fn read_record(dir: &Path) -> Result<SweepRecord, SweepError> {
    let p = dir.join(SWEEP_JSON);
    let text = std::fs::read_to_string(&p).map_err(|e| SweepError::Io {
        path: p.display().to_string(),
        message: e.to_string(),
    })?;
    let r: SweepRecord = serde_json::from_str(&text).map_err(|e| SweepError::Io {
        path: p.display().to_string(),
        message: format!("not a fabkit sweep record: {e}"),
    })?;
    if r.format != FORMAT {
        return Err(SweepError::Io {
            path: p.display().to_string(),
            message: format!("format {:?}, expected {FORMAT:?}", r.format),
        });
    }
    // A record is read back from disk: its numbers are checked before anything is sized by
    // them (a merge allocates one slot per variant and per shard).
    let bad = |field: &str, value: String, rule: String| SweepError::Io {
        path: p.display().to_string(),
        message: format!("{field} = {value}: {rule}; not a record fabkit wrote"),
    };
    if r.variant_count as u64 > crate::plan::MAX_VARIANTS {
        return Err(bad(
            "variant_count",
            r.variant_count.to_string(),
            format!("must be at most {}", crate::plan::MAX_VARIANTS),
        ));
    }
    if let Some(s) = r.shard {
        if s.count == 0 || s.index >= s.count || s.count as u64 > crate::plan::MAX_VARIANTS {
            return Err(bad(
                "shard",
                format!("{}/{}", s.index, s.count),
                format!("needs 0 <= I < N <= {}", crate::plan::MAX_VARIANTS),
            ));
        }
    }
    Ok(r)
}

pub(crate) fn json_pretty<T: Serialize>(v: &T) -> Vec<u8> {
    let mut b = serde_json::to_vec_pretty(v).unwrap_or_default();
    b.push(b'\n');
    b
}

/// The record of `spec` run with `opts`.
pub fn record(spec: &SweepSpec, plan: &Plan, opts: &RunOptions) -> SweepRecord {
    SweepRecord {
        format: FORMAT.into(),
        fabkit_version: opts.fabkit_version.clone(),
        sweep_file: spec.origin.clone(),
        sweep_sha256: spec.sha256.clone(),
        base_source: spec.base.source.clone(),
        base_sha256: spec.base.sha256.clone(),
        preset: spec.preset.clone(),
        chord_tolerance_mm: spec.chord_tolerance.mm(),
        mode: spec.mode,
        seed: (spec.mode == Mode::Random).then_some(spec.seed),
        count: spec.count,
        parameters: spec.parameters.iter().map(|p| p.path.clone()).collect(),
        files: spec.files,
        variant_count: plan.variants.len(),
        plan_sha256: plan.plan_sha256.clone(),
        shard: opts.shard,
        build_time: opts.build_time,
        command_line: opts.command_line.clone(),
        merged_from: vec![],
    }
}

/// Runs the variants of `plan` (those of `opts.shard`) that have no complete result in
/// `opts.out_dir`, then writes the results table of every selected variant.
///
/// Folder layout:
/// - `sweep.json` ([`SweepRecord`]), written first;
/// - `variants/<id>.json`: each variant's [`VariantResult`], written atomically as soon as the
///   variant is done, after its files;
/// - `variants/<id>/`: the files of `fabkit export`, when the sweep asks for them;
/// - `results.csv` and `results.jsonl` ([`render_csv`], [`render_jsonl`]), in variant order,
///   written atomically at the end (a table from an earlier run is removed at the start).
///
/// A result is complete, and its variant skipped, when `variants/<id>.json` reads back with
/// the same id, status ok or infeasible, the same fabkit version and the files asked for.
/// A killed run leaves complete results for the variants it finished and nothing for the
/// others (temporary files are removed by the next run). Run one process per folder.
///
/// Variants are built in parallel on `opts.jobs` threads (rayon; 1 to 4 x the CPUs, else
/// [`SweepError::Jobs`] before anything is written); each variant's numbers do not depend on
/// the thread count and the tables are in variant order.
///
/// # Errors
/// [`SweepError::ForeignDirectory`], [`SweepError::Io`], or a sweep that asks for files
/// without a `writer` ([`SweepError::File`]). A variant's failure is not an error of the run:
/// it is recorded with status error (and infeasible variants with their violations).
pub fn run(
    spec: &SweepSpec,
    plan: &Plan,
    opts: &RunOptions,
    writer: Option<&dyn KitWriter>,
    on_event: &(dyn Fn(Event<'_>) + Sync),
) -> Result<RunSummary, SweepError> {
    if spec.files.any() && writer.is_none() {
        return Err(SweepError::File {
            at: spec.origin.clone(),
            message: "outputs ask for files but no file writer was given".into(),
        });
    }
    let materials = MaterialsTable::embedded().map_err(|m| SweepError::File {
        at: "designs/materials.yaml".into(),
        message: m,
    })?;
    if let Some(jobs) = opts.jobs {
        let cpus = std::thread::available_parallelism().map_or(1, usize::from);
        let max = 4 * cpus;
        if !(1..=max).contains(&jobs) {
            return Err(SweepError::Jobs { jobs, max, cpus });
        }
    }
    let dir = &opts.out_dir;
    let rec = record(spec, plan, opts);
    claim_sweep_dir(dir, &rec, opts.force)?;
    let vdir = dir.join(VARIANTS);
    let io = |p: &Path| {
        let p = p.display().to_string();
        move |e: std::io::Error| SweepError::Io {
            path: p.clone(),
            message: e.to_string(),
        }
    };
    std::fs::create_dir_all(&vdir).map_err(io(&vdir))?;
    remove_leftovers(&vdir)?;
    for t in [RESULTS_CSV, RESULTS_JSONL] {
        let p = dir.join(t);
        if p.exists() {
            std::fs::remove_file(&p).map_err(io(&p))?;
        }
    }
    write_atomic(&dir.join(SWEEP_JSON), &json_pretty(&rec))?;

    let selected: Vec<&Variant> = plan
        .variants
        .iter()
        .filter(|v| opts.shard.is_none_or(|s| s.contains(v.index)))
        .collect();
    // One listing of variants/ rather than one open per variant: a sweep of millions of
    // variants starts at once.
    let results_on_disk: std::collections::HashSet<std::ffi::OsString> = std::fs::read_dir(&vdir)
        .map_err(io(&vdir))?
        .flatten()
        .map(|e| e.file_name())
        .collect();
    let mut done: Vec<Option<VariantResult>> = selected
        .par_iter()
        .map(|v| {
            let name = std::ffi::OsString::from(format!("{}.json", v.id));
            results_on_disk
                .contains(&name)
                .then(|| complete_result(&vdir, v, spec.files, &opts.fabkit_version))
                .flatten()
        })
        .collect();
    let reused = done.iter().filter(|d| d.is_some()).count();
    on_event(Event::Start {
        total: plan.variants.len(),
        selected: selected.len(),
        complete: reused,
    });
    let pending: Vec<(usize, &Variant)> = selected
        .iter()
        .enumerate()
        .filter(|(k, _)| done[*k].is_none())
        .map(|(k, v)| (k, *v))
        .collect();
    let work = || -> Result<Vec<(usize, VariantResult)>, SweepError> {
        pending
            .par_iter()
            .map(|&(k, v)| {
                let r = run_variant(spec, v, &vdir, &materials, opts, writer);
                write_atomic(&vdir.join(format!("{}.json", v.id)), &json_pretty(&r))?;
                fabkit_export::hold::hold_point("sweep-variant-written");
                on_event(Event::Done(&r));
                Ok((k, r))
            })
            .collect()
    };
    let fresh = match opts.jobs {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| SweepError::Io {
                path: "thread pool".into(),
                message: e.to_string(),
            })?
            .install(work)?,
        None => work()?,
    };
    let ran: Vec<String> = fresh.iter().map(|(_, r)| r.id.clone()).collect();
    for (k, r) in fresh {
        done[k] = Some(r);
    }
    let rows: Vec<VariantResult> = done
        .into_iter()
        .flatten()
        .map(|mut r| {
            if !opts.build_time {
                r.build_time_s = None;
            }
            r
        })
        .collect();
    let count = |s: Status| rows.iter().filter(|r| r.status == s).count();
    let parameters: Vec<String> = spec.parameters.iter().map(|p| p.path.clone()).collect();
    let csv = dir.join(RESULTS_CSV);
    let jsonl = dir.join(RESULTS_JSONL);
    write_atomic(&jsonl, &render_jsonl(&rows))?;
    write_atomic(&csv, &render_csv(&parameters, &rows))?;
    Ok(RunSummary {
        total: plan.variants.len(),
        selected: selected.len(),
        reused,
        ran,
        ok: count(Status::Ok),
        infeasible: count(Status::Infeasible),
        errors: count(Status::Error),
        results_csv: csv,
        results_jsonl: jsonl,
    })
}

/// Removes temporary files and folders a killed run left in `variants/` (`tempfile`'s `.tmp*`
/// files and the export's `.<id>.tmp-*` / `.<id>.old-*` folders; see [`is_leftover`]).
fn remove_leftovers(vdir: &Path) -> Result<(), SweepError> {
    let entries = std::fs::read_dir(vdir).map_err(|e| SweepError::Io {
        path: vdir.display().to_string(),
        message: e.to_string(),
    })?;
    for e in entries.flatten() {
        if is_leftover(&e.file_name().to_string_lossy()) {
            let p = e.path();
            let _ = if p.is_dir() {
                std::fs::remove_dir_all(&p)
            } else {
                std::fs::remove_file(&p)
            };
        }
    }
    Ok(())
}

/// The stored result of `v` when it is complete (see [`run`]), with this plan's index and
/// parameters.
fn complete_result(
    vdir: &Path,
    v: &Variant,
    files: FileOutputs,
    version: &str,
) -> Option<VariantResult> {
    let text = std::fs::read_to_string(vdir.join(format!("{}.json", v.id))).ok()?;
    let mut r: VariantResult = serde_json::from_str(&text).ok()?;
    let has_files = (!files.stl || r.files.stl) && (!files.threemf || r.files.threemf);
    let ok = r.id == v.id
        && r.status != Status::Error
        && r.fabkit_version == version
        && (!files.any()
            || r.status != Status::Ok
            || (has_files && vdir.join(&v.id).join("manifest.json").is_file()));
    if !ok {
        return None;
    }
    r.index = v.index;
    r.params = v.params.iter().cloned().collect();
    Some(r)
}

fn run_variant(
    spec: &SweepSpec,
    v: &Variant,
    vdir: &Path,
    materials: &MaterialsTable,
    opts: &RunOptions,
    writer: Option<&dyn KitWriter>,
) -> VariantResult {
    let tol = spec.chord_tolerance;
    let write = |design: &Design, kit: &Kit| -> Result<(), String> {
        let job = FilesJob::new(
            vdir.join(&v.id),
            spec.files,
            v,
            design,
            format!(
                "{} variant {} of sweep {}",
                spec.base.source, v.id, spec.origin
            ),
            tol.mm(),
        );
        match writer {
            Some(w) => w.write(kit, &job),
            None => Ok(()),
        }
    };
    let write: Option<WriteFiles<'_>> = if writer.is_some() && spec.files.any() {
        Some(&write)
    } else {
        None
    };
    evaluate_variant(
        v,
        spec.resolve(&v.params).map_err(|e| e.to_string()),
        materials,
        tol,
        opts.max_triangles,
        &opts.fabkit_version,
        spec.files,
        write,
    )
}
