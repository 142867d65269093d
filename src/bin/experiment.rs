//! `experiment <codec> <mesh>`: encode, decode every level, measure, write results and plots,
//! print the level table. `experiment run FILE.toml`: a set of codecs × meshes × quantizations,
//! with one comparison chart per mesh.

use anyhow::{Context, Result};
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use meshcodec::codecs::{self, Codec};
use meshcodec::harness::{self, RunOptions};
use meshcodec::mesh::io::{mesh_name, resolve};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::plot;
use meshcodec::progress::Progress;
use meshcodec::results::{self, RunResult};
use meshcodec::sweep::{JobRecord, Shard, ShardManifest};
use serde::Deserialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Codec name (the list below).
    codec: Option<String>,
    /// Mesh file, or a name looked up in $MESHCODEC_DATA and ../shared/meshes.
    mesh: Option<String>,
    #[command(flatten)]
    settings: Settings,
}

#[derive(clap::Args, Clone)]
struct Settings {
    /// Quantization bits per axis (default: the codec's).
    #[arg(long)]
    quant: Option<u8>,
    /// Grid shape: cubic (docs/CONTRACT.md §1) or per-axis.
    #[arg(long, value_parser = meshcodec::cli::parse_grid)]
    grid: Option<GridShape>,
    /// Random samples per original triangle for the error metrics.
    #[arg(long, default_value_t = meshcodec::metrics::DEFAULT_SAMPLES_PER_TRIANGLE)]
    samples: usize,
    /// Most random samples a direction for the error metrics, whatever the mesh's size
    /// (docs/CONTRACT.md §5; each level's result records its samples and their uncertainty).
    #[arg(long, default_value_t = meshcodec::metrics::DEFAULT_MAX_SAMPLES)]
    max_samples: usize,
    /// Folder for results.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Also write the stream as results/CODEC/STEM.mc (figures decode it).
    #[arg(long)]
    keep_stream: bool,
    /// Code the file's normals, uvs, colours and materials too, with codecs that carry them
    /// (results as STEM-appearance, with the appearance error per level).
    #[arg(long)]
    appearance: bool,
    /// Qt: bits per uv axis when coding appearance.
    #[arg(long, default_value_t = meshcodec::mesh::attribute_quantization::DEFAULT_UV_BITS)]
    uv_bits: u8,
    /// Qn: bits per octahedral normal coordinate when coding appearance.
    #[arg(long, default_value_t = meshcodec::mesh::attribute_quantization::DEFAULT_NORMAL_BITS)]
    normal_bits: u8,
    /// With --appearance, normals derived from the positions over the input's normal wedges
    /// (results as STEM-appearance[-RULE]-derived-normals).
    #[arg(long)]
    derive_normals: bool,
    /// With --appearance, code it inside the levels (pm only: every level carries it), giving
    /// a collapsed wedge the values interpolated to where the vertex went (`fit`) or the
    /// survivor's (`keep`); results as STEM-appearance-RULE.
    #[arg(long, value_parser = ["fit", "keep"])]
    attributes: Option<String>,
}

impl Settings {
    /// The defaults, results in `out`.
    fn default_for(out: &Path) -> Settings {
        Settings {
            quant: None,
            grid: None,
            samples: meshcodec::metrics::DEFAULT_SAMPLES_PER_TRIANGLE,
            max_samples: meshcodec::metrics::DEFAULT_MAX_SAMPLES,
            out: out.to_path_buf(),
            keep_stream: false,
            appearance: false,
            uv_bits: meshcodec::mesh::attribute_quantization::DEFAULT_UV_BITS,
            normal_bits: meshcodec::mesh::attribute_quantization::DEFAULT_NORMAL_BITS,
            derive_normals: false,
            attributes: None,
        }
    }
}

#[derive(Subcommand)]
enum Command {
    /// Run an experiment set (experiments/*.toml).
    Run {
        /// The set's TOML file.
        file: PathBuf,
        /// Run only shard I of N (from 1: every N-th job of the set, meshes × codecs ×
        /// quantizations in order) and write its manifest beside the results for
        /// `experiment merge`; the comparison charts wait for the merge.
        #[arg(long, value_parser = meshcodec::sweep::Shard::parse)]
        shard: Option<meshcodec::sweep::Shard>,
        #[command(flatten)]
        settings: Settings,
    },
    /// Join the results folders of a set's shards into one, as a single run writes it (every
    /// job's files, the comparison charts, the summary); refuses a missing or doubled job.
    Merge {
        /// The set's TOML file.
        file: PathBuf,
        /// The shards' results folders.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Folder for the merged results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Time simplification + PM construction on meshes from 5k to 3M faces (shared meshes,
    /// subdivided); writes results/pm/decimation.json.
    Decimation {
        /// Folder for results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// What cutting to a manifold costs pm on every shared mesh that is none, at 12 and 16 bits
    /// (both orderings); writes results/pm/repair-cost.json.
    RepairCost {
        /// Folder for results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// What the CAME tables need beyond `run experiments/came.toml`: both CAME codecs on a
    /// mesh of over a million triangles, VRML sizes, came-paper bunny streams at 3 and 5 bits
    /// per component; writes results/came/extras.json.
    CameExtras {
        /// Folder for results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// CAME's fly-through: 100 views around and into the million-triangle mesh, its came
    /// stream's meta-nodes read from a file as the views need them; writes
    /// results/came/flythrough.{json,csv,png,svg} and renders of the far and near frames.
    CameFly {
        /// Folder for results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// CAME's view-dependent table: far, middle and near views of bunny.ply, dragon-50k and the
    /// million-triangle mesh from a cold start, two-sided: faces, bytes read, adaptation time,
    /// measured screen-space error; writes results/came/vd.json and renders under
    /// results/came/vd/, and the full decodes (for experiments/meshopt_vd.py) under `work`.
    CameVd {
        /// Folder for results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        /// Folder for the full decodes (large; not results).
        #[arg(long, default_value = "target/came-vd")]
        work: PathBuf,
    },
    /// `emc` on bunny-closed-35k as shared and subdivided two and three times (35k → 557k →
    /// 2.2 M vertices) and on bunny.ply, the anchor: encode and decode times and peak memory;
    /// writes results/emc/scale.json.
    EmcScale {
        /// Folder for results.
        #[arg(long, default_value = "results")]
        out: PathBuf,
    },
    /// Regenerate the papers' tables and figures in paper-tables/ from results/.
    Tables {
        /// Folder of result files.
        #[arg(long, default_value = "results")]
        results: PathBuf,
        /// Folder to write the tables to.
        #[arg(long, default_value = "paper-tables")]
        out: PathBuf,
    },
}

/// An experiment set: every codec on every mesh at every quantization.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperimentSet {
    /// What the set is for.
    #[serde(default)]
    description: String,
    codecs: Vec<String>,
    meshes: Vec<String>,
    /// Quantization bits; absent: each codec's default.
    #[serde(default)]
    quant: Vec<u8>,
    /// Samples per triangle for the metrics.
    samples: Option<usize>,
    /// Most random samples a direction for the metrics.
    max_samples: Option<usize>,
    /// Grid shape ("cubic" or "per-axis"); absent: each codec's default.
    grid: Option<String>,
    /// Keep the streams beside the results.
    #[serde(default)]
    keep_streams: bool,
    /// Code appearance with the codecs that carry it.
    #[serde(default)]
    appearance: bool,
    /// Qt when coding appearance; absent: the default.
    uv_bits: Option<u8>,
    /// Qn when coding appearance; absent: the default.
    normal_bits: Option<u8>,
    /// Derive normals from the positions over the input's normal wedges.
    #[serde(default)]
    derive_normals: bool,
    /// Rules for appearance inside the levels ("fit", "keep"), each a run of its own; absent:
    /// the appearance unit.
    #[serde(default)]
    attributes: Vec<String>,
}

fn main() -> ExitCode {
    let command = Cli::command().after_help(meshcodec::cli::codec_list(None));
    let cli = Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit());
    let outcome = match &cli.command {
        Some(Command::Run {
            file,
            shard,
            settings,
        }) => run_set(file, *shard, settings),
        Some(Command::Merge { file, shards, out }) => merge(file, shards, out),
        Some(Command::Tables { results, out }) => tables(results, out),
        Some(Command::Decimation { out }) => decimation(out),
        Some(Command::RepairCost { out }) => repair_cost(out),
        Some(Command::CameExtras { out }) => came_extras(out),
        Some(Command::CameFly { out }) => came_fly(out),
        Some(Command::CameVd { out, work }) => came_vd(out, work),
        Some(Command::EmcScale { out }) => emc_scale(out),
        None => match (&cli.codec, &cli.mesh) {
            (Some(codec), Some(mesh)) => run_one(codec, mesh, &cli.settings).map(|_| ()),
            _ => Err(anyhow::anyhow!(
                "usage: experiment <codec> <mesh> [--quant BITS] [--samples N] [--max-samples N] [--out DIR] | experiment run FILE"
            )),
        },
    };
    meshcodec::cli::exit_code(outcome)
}

fn run_options(settings: &Settings, quant: Option<u8>) -> RunOptions {
    RunOptions {
        quant_bits: quant.or(settings.quant),
        grid: settings.grid,
        samples: meshcodec::metrics::SampleBudget {
            per_triangle: settings.samples,
            max: settings.max_samples,
        },
        progress: std::io::stderr().is_terminal(),
        appearance: settings.appearance.then_some(
            meshcodec::mesh::attribute_quantization::AttributeBits {
                uv: settings.uv_bits,
                normal: settings.normal_bits,
                derive_normals: settings.derive_normals,
            },
        ),
        appearance_in_levels: settings
            .attributes
            .as_deref()
            .and_then(|name| meshcodec::codecs::AttributeFit::by_name(name).ok()),
    }
}

fn run_one(codec_name: &str, mesh: &str, settings: &Settings) -> Result<(RunResult, Vec<PathBuf>)> {
    let codec = meshcodec::cli::codec_by_name(codec_name)?;
    let path = resolve(mesh).with_context(|| mesh.to_string())?;
    run_codec(
        codec,
        &path,
        &run_options(settings, None),
        &settings.out,
        settings.keep_stream,
    )
}

/// Runs one job; returns its result and the files it wrote.
fn run_codec(
    codec: &dyn Codec,
    path: &Path,
    options: &RunOptions,
    out: &Path,
    keep_stream: bool,
) -> Result<(RunResult, Vec<PathBuf>)> {
    let harness::RunOutput {
        result,
        stream,
        appearance,
    } = harness::run(codec, path, options).with_context(|| path.display().to_string())?;
    // What the file holds beyond what the run coded is said, not dropped unseen.
    if !appearance.is_empty() {
        let why = if options.appearance.is_none() {
            "--appearance codes it".to_string()
        } else {
            format!("{} carries positions and triangles only", codec.name())
        };
        eprintln!("note: {}: {appearance} not coded ({why})", path.display());
    }
    meshcodec::outln!(
        "{} on {} ({}): {} vertices, {} triangles at {} bits; {} bytes = {:.3} bits/vertex, \
         {:.3} bits/triangle",
        result.codec,
        result.mesh,
        result.source,
        result.vertices,
        result.triangles,
        result.quant_bits,
        result.bytes,
        result.bits_per_vertex(),
        result.bits_per_triangle(),
    );
    print!("{}", results::level_table(&result));
    let full_level = match (&result.lossless_error, codec.lossless()) {
        (None, _) => "lossless: yes".to_string(),
        (Some(_), false) => format!(
            "lossy by design: full level at Hausdorff {:.3e} of the bounding-box diagonal",
            result
                .levels
                .last()
                .and_then(|l| l.hausdorff)
                .unwrap_or(f64::NAN)
        ),
        (Some(e), true) => format!("lossless: NO — {e}"),
    };
    meshcodec::outln!(
        "encode {:.3} s, decode {:.4} s ({:.0} vertices/s); {full_level}",
        result.encode_seconds,
        result.decode_seconds,
        result.vertices as f64 / result.decode_seconds.max(1e-9),
    );
    let stem = results::result_stem(&codec.default_options(), &result);
    let mut written = harness::write_result(&result, &stem, out)
        .with_context(|| format!("writing results to {}", out.display()))?;
    if keep_stream {
        let path = results::path(out, &result.codec, &stem, ".mc");
        meshcodec::mesh::io::write_atomically(&path, &stream)?;
        written.push(path);
    }
    for path in &written {
        meshcodec::outln!("wrote {}", path.display());
    }
    if !result.lossless && codec.lossless() {
        anyhow::bail!("{} on {} is not lossless", result.codec, result.mesh);
    }
    Ok((result, written))
}

/// One codec on one mesh at one quantization, as a set numbers it.
struct Job<'a> {
    number: usize,
    /// Index of the mesh in the set.
    mesh: usize,
    path: &'a Path,
    codec: &'static dyn Codec,
    quant: Option<u8>,
    /// The in-level appearance rule, if any.
    rule: Option<&'a str>,
}

/// An experiment set read and resolved: its name, codecs, meshes and quantizations.
struct Set {
    name: String,
    description: String,
    codecs: Vec<&'static dyn Codec>,
    paths: Vec<PathBuf>,
    quants: Vec<Option<u8>>,
    rules: Vec<Option<String>>,
    settings: Settings,
}

impl Set {
    fn read(file: &Path, settings: &Settings) -> Result<Set> {
        let text = std::fs::read_to_string(file).with_context(|| file.display().to_string())?;
        let set: ExperimentSet = toml::from_str(&text)
            .with_context(|| format!("{}: bad experiment set", file.display()))?;
        let codecs = set
            .codecs
            .iter()
            .map(|c| meshcodec::cli::codec_by_name(c))
            .collect::<Result<Vec<_>, meshcodec::cli::UnknownCodec>>()
            .with_context(|| file.display().to_string())?;
        let paths = set
            .meshes
            .iter()
            .map(|m| resolve(m).with_context(|| m.clone()))
            .collect::<Result<Vec<_>>>()?;
        let quants: Vec<Option<u8>> = if set.quant.is_empty() {
            vec![None]
        } else {
            set.quant.iter().map(|&q| Some(q)).collect()
        };
        let grid = match &set.grid {
            Some(g) => Some(meshcodec::cli::parse_grid(g).map_err(anyhow::Error::msg)?),
            None => settings.grid,
        };
        let settings = Settings {
            samples: set.samples.unwrap_or(settings.samples),
            max_samples: set.max_samples.unwrap_or(settings.max_samples),
            grid,
            keep_stream: settings.keep_stream || set.keep_streams,
            appearance: settings.appearance || set.appearance,
            uv_bits: set.uv_bits.unwrap_or(settings.uv_bits),
            normal_bits: set.normal_bits.unwrap_or(settings.normal_bits),
            derive_normals: settings.derive_normals || set.derive_normals,
            ..settings.clone()
        };
        for rule in &set.attributes {
            meshcodec::codecs::AttributeFit::by_name(rule)
                .with_context(|| format!("{}: attributes", file.display()))?;
        }
        let rules = if set.attributes.is_empty() {
            vec![settings.attributes.clone()]
        } else {
            set.attributes.into_iter().map(Some).collect()
        };
        Ok(Set {
            name: mesh_name(file),
            description: set.description,
            codecs,
            paths,
            quants,
            rules,
            settings,
        })
    }

    /// Every job in order (meshes, then codecs, then quantizations, then appearance rules),
    /// numbered from 0, with the index of its mesh.
    fn jobs(&self) -> Vec<Job<'_>> {
        let mut jobs = Vec::new();
        for (mesh, path) in self.paths.iter().enumerate() {
            for &codec in &self.codecs {
                for &quant in &self.quants {
                    for rule in &self.rules {
                        jobs.push(Job {
                            number: jobs.len(),
                            mesh,
                            path,
                            codec,
                            quant,
                            rule: rule.as_deref(),
                        });
                    }
                }
            }
        }
        jobs
    }
}

fn run_set(file: &Path, shard: Option<Shard>, settings: &Settings) -> Result<()> {
    let set = Set::read(file, settings)?;
    let settings = &set.settings;
    let out = &settings.out;
    if !set.description.is_empty() {
        meshcodec::outln!("{}: {}", set.name, set.description);
    }
    let jobs = set.jobs();
    let mut records = Vec::new();
    let mut runs: Vec<Vec<RunResult>> = vec![Vec::new(); set.paths.len()];
    for &Job {
        number: job,
        mesh: mesh_index,
        path,
        codec,
        quant,
        rule,
    } in &jobs
    {
        if shard.is_some_and(|s| !s.owns(job)) {
            continue;
        }
        let options = RunOptions {
            appearance_in_levels: rule
                .and_then(|r| meshcodec::codecs::AttributeFit::by_name(r).ok()),
            ..run_options(settings, quant)
        };
        let mesh = mesh_name(path);
        let (refused, files) = match run_codec(codec, path, &options, out, settings.keep_stream) {
            Ok((run, files)) => {
                runs[mesh_index].push(run);
                (false, files)
            }
            // A codec that cannot take a mesh says why; the set goes on, and the reason is
            // kept beside the results for the tables.
            Err(e) if is_refusal(&e) => {
                std::fs::create_dir_all(out.join(codec.name()))?;
                let why = format!("{e:#}");
                let file = results::refusal_path(out, codec.name(), &mesh);
                meshcodec::mesh::io::write_atomically(&file, format!("{why}\n").as_bytes())?;
                meshcodec::outln!("{} refused {mesh}: {why}", codec.name());
                (true, vec![file])
            }
            Err(e) => return Err(e),
        };
        let files = files
            .iter()
            .map(|f| f.strip_prefix(out).unwrap_or(f).to_path_buf())
            .collect();
        records.push(JobRecord {
            job,
            codec: codec.name().to_string(),
            mesh,
            quant,
            refused,
            files,
        });
    }
    match shard {
        Some(shard) => {
            let manifest = ShardManifest {
                set: set.name.clone(),
                shard,
                jobs_in_set: jobs.len(),
                jobs: records,
            };
            let path = meshcodec::sweep::manifest_path(out, &set.name, shard);
            std::fs::create_dir_all(out)?;
            let text = serde_json::to_string_pretty(&manifest)?;
            meshcodec::mesh::io::write_atomically(&path, format!("{text}\n").as_bytes())?;
            meshcodec::outln!(
                "shard {shard}: {} of the set's {} jobs; wrote {} (experiment merge joins the shards)",
                manifest.jobs.len(),
                jobs.len(),
                path.display()
            );
            Ok(())
        }
        None => finish_set(&set, &runs, out),
    }
}

/// The comparison charts of every mesh and the summary table, from the set's results.
fn finish_set(set: &Set, runs: &[Vec<RunResult>], out: &Path) -> Result<()> {
    let mut summary = Vec::new();
    for (path, runs) in set.paths.iter().zip(runs) {
        if runs.is_empty() {
            continue;
        }
        let dir = out.join("compare").join(&set.name);
        std::fs::create_dir_all(&dir)?;
        let name = mesh_name(path);
        let title = format!("{name} ({})", set.name);
        plot::rate_resolution(runs, &title).draw(&dir.join(format!("{name}-rate-resolution")))?;
        plot::rate_distortion(runs, &title).draw(&dir.join(format!("{name}-rate-distortion")))?;
        meshcodec::outln!("wrote comparison charts to {}", dir.display());
        summary.extend(runs);
    }
    meshcodec::outln!(
        "\n{:<10} {:<22} {:>5} {:>10} {:>9} {:>9} {:>9}",
        "codec",
        "mesh",
        "quant",
        "bytes",
        "bpv",
        "bpt",
        "lossless"
    );
    for r in &summary {
        meshcodec::outln!(
            "{:<10} {:<22} {:>5} {:>10} {:>9.3} {:>9.3} {:>9}",
            r.codec,
            r.mesh,
            r.quant_bits,
            r.bytes,
            r.bits_per_vertex(),
            r.bits_per_triangle(),
            r.lossless
        );
    }
    Ok(())
}

/// `experiment merge`: every job's files copied from the shard that ran it, then the charts
/// and summary drawn from their results as a single run draws them.
fn merge(file: &Path, shards: &[PathBuf], out: &Path) -> Result<()> {
    let set = Set::read(file, &Settings::default_for(out))?;
    let jobs = set.jobs();
    let found = meshcodec::sweep::collect(&set.name, jobs.len(), shards)?;
    let mut runs: Vec<Vec<RunResult>> = vec![Vec::new(); set.paths.len()];
    for (job, (record, dir)) in jobs.iter().zip(&found) {
        let (path, codec) = (job.path, job.codec);
        if record.codec != codec.name()
            || record.mesh != mesh_name(path)
            || record.quant != job.quant
        {
            anyhow::bail!(
                "{}: job {n} is {} on {}, but the set's job {n} is {} on {}: the set changed since the shard ran",
                dir.display(),
                record.codec,
                record.mesh,
                codec.name(),
                mesh_name(path),
                n = job.number
            );
        }
        for relative in &record.files {
            let from = dir.join(relative);
            let bytes = std::fs::read(&from).with_context(|| from.display().to_string())?;
            let to = out.join(relative);
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent)?;
            }
            meshcodec::mesh::io::write_atomically(&to, &bytes)?;
            if !record.refused && relative.extension().is_some_and(|e| e == "json") {
                let run: RunResult = serde_json::from_slice(&bytes)
                    .with_context(|| format!("{}: not a result", from.display()))?;
                runs[job.mesh].push(run);
            }
        }
    }
    meshcodec::outln!(
        "merged {} jobs of {} from {} shards into {}",
        found.len(),
        set.name,
        shards.len(),
        out.display()
    );
    finish_set(&set, &runs, out)
}

fn is_refusal(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        matches!(
            c.downcast_ref::<meshcodec::Error>(),
            Some(meshcodec::Error::Unsupported(_))
        )
    })
}

fn tables(results: &Path, out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| out.display().to_string())?;
    let (written, missing) = meshcodec::tables::regenerate(results, out);
    for path in &written {
        meshcodec::outln!("wrote {}", path.display());
    }
    for why in &missing {
        meshcodec::outln!("skipped {why}");
    }
    if written.is_empty() {
        anyhow::bail!("no table could be made from {}", results.display());
    }
    Ok(())
}

fn came_extras(out: &Path) -> Result<()> {
    logged("came-extras: reading", |log| {
        meshcodec::came_extras::run(out, log)
    })
}

fn emc_scale(out: &Path) -> Result<()> {
    logged("emc-scale: reading and subdividing", |log| {
        meshcodec::emc_scale::run(out, log)
    })
}

fn came_vd(out: &Path, work: &Path) -> Result<()> {
    logged("came-vd: reading and encoding", |log| {
        meshcodec::came_vd::run(out, work, log)
    })
}

fn came_fly(out: &Path) -> Result<()> {
    logged("came-fly: reading and encoding", |log| {
        meshcodec::came_flythrough::run(out, log)
    })
}

/// Runs a long experiment that logs its steps: each line printed, a spinner on a terminal
/// timing what follows it (`first` until the first line), and the file it wrote said at the end.
fn logged(
    first: &str,
    run: impl FnOnce(&mut dyn FnMut(String)) -> meshcodec::Result<PathBuf>,
) -> Result<()> {
    let progress = Progress::on_terminal();
    progress.step(first);
    let path = run(&mut |line| {
        progress.println(&line);
        progress.step(format!("after: {line}"));
    })?;
    progress.finish();
    meshcodec::outln!("wrote {}", path.display());
    Ok(())
}

/// Meshes of the decimation table: a shared mesh and how many times it is subdivided (×4 faces).
/// cow and teapot (×16: as many faces as the paper's czajnik, Polish for teapot) are no oriented
/// manifolds: they are cut to one first, as `pm` does, and the cut is timed with the rest.
const DECIMATION_MESHES: [(&str, u32); 8] = [
    ("cow", 0),
    ("spot", 0),
    ("teapot", 2),
    ("dragon-50k", 0),
    ("fandisk", 2),
    ("bunny-closed-35k", 2),
    ("armadillo-43k", 2),
    ("feline-26k", 3),
];

fn repair_cost(out: &Path) -> Result<()> {
    use meshcodec::codecs::pm::{Ordering, Pm};
    let dir = meshcodec::mesh::io::data_dirs()
        .into_iter()
        .find(|d| d.join("MANIFEST.md").is_file())
        .context("no folder of shared meshes (MESHCODEC_DATA, ../shared/meshes)")?;
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| meshcodec::mesh::io::read_mesh(p).is_ok())
        .collect();
    files.sort();
    // (file, subdivisions, bits): every shared mesh, and the one the welding at 16 bits makes
    // non-manifold once subdivided twice.
    let mut jobs: Vec<(PathBuf, u32, Vec<u8>)> =
        files.into_iter().map(|p| (p, 0, vec![12, 16])).collect();
    jobs.push((resolve("bunny-closed-35k")?, 2, vec![16]));
    let mut rows = Vec::new();
    meshcodec::outln!(
        "{:<22} {:>4} {:<13} {:>8} {:>7} {:>6} {:>6} {:>10} {:>10} {:>8}",
        "mesh",
        "Q",
        "codec",
        "defects",
        "copies",
        "flips",
        "cut",
        "bytes",
        "manifold",
        "cost"
    );
    let progress = Progress::on_terminal();
    for (path, times, all_bits) in &jobs {
        progress.step(format!("repair-cost: {}", mesh_name(path)));
        let mut mesh = meshcodec::mesh::io::read_mesh(path)?;
        let mut name = path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        for _ in 0..*times {
            mesh = meshcodec::mesh::generate::subdivide(&mesh);
        }
        if *times > 0 {
            name = format!("{name} ×{}", 4u32.pow(*times));
        }
        for &bits in all_bits {
            let options = codecs::EncodeOptions {
                quant_bits: bits,
                grid: GridShape::Cubic,
            };
            let canonical = codecs::canonical_for(&mesh, &options)?;
            let report = meshcodec::mesh::topology::analyze(&canonical.to_mesh());
            for ordering in [Ordering::Natural, Ordering::Reordered] {
                let pm = Pm { ordering };
                let Some(cost) = pm.repair_cost(&canonical)? else {
                    continue;
                };
                let share =
                    report.defects() as f64 / (report.edges + canonical.vertex_count()) as f64;
                let extra = cost.repaired_bytes as f64 / cost.manifold_bytes as f64 - 1.0;
                let line = format!(
                    "{:<22} {:>4} {:<13} {:>7.3}% {:>7} {:>6} {:>6} {:>10} {:>10} {:>+7.2}%\n",
                    name,
                    bits,
                    codecs::Codec::name(&pm),
                    100.0 * share,
                    cost.copies,
                    cost.flips,
                    cost.cut_edges,
                    cost.repaired_bytes,
                    cost.manifold_bytes,
                    100.0 * extra
                );
                progress.suspend(|| meshcodec::cli::write_stdout(&line))?;
                rows.push(serde_json::json!({
                    "mesh": name,
                    "quant_bits": bits,
                    "codec": codecs::Codec::name(&pm),
                    "vertices": canonical.vertex_count(),
                    "faces": canonical.face_count(),
                    "non_manifold_edges": report.non_manifold_edges,
                    "non_manifold_vertices": report.non_manifold_vertices,
                    "edges_used_twice_one_way": report.edges_used_twice_one_way,
                    "defect_share": share,
                    "cost": cost,
                    "extra_share": extra,
                }));
            }
        }
    }
    let dir = out.join("pm");
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("repair-cost.json");
    meshcodec::mesh::io::write_atomically(
        &path,
        format!(
            "{}\n",
            serde_json::to_string_pretty(&serde_json::json!({ "rows": rows }))?
        )
        .as_bytes(),
    )?;
    meshcodec::outln!("wrote {}", path.display());
    Ok(())
}

fn decimation(out: &Path) -> Result<()> {
    use meshcodec::codecs::pm::ManifoldInput;
    use meshcodec::hierarchy::simplify::{
        progressive_mesh, simplify, simplify_constrained, Placement,
    };
    let mut rows = Vec::new();
    let progress = Progress::on_terminal();
    for (name, times) in DECIMATION_MESHES {
        progress.step(format!("decimation: {name} x{}", 4u32.pow(times)));
        let path = resolve(name).with_context(|| name.to_string())?;
        let mut mesh =
            meshcodec::mesh::io::read_mesh(&path).with_context(|| path.display().to_string())?;
        for _ in 0..times {
            mesh = meshcodec::mesh::generate::subdivide(&mesh);
        }
        // 24 bits: fine enough that subdivision midpoints never weld.
        let options = codecs::EncodeOptions {
            quant_bits: 24,
            grid: GridShape::Cubic,
        };
        let canonical = codecs::canonical_for(&mesh, &options)?;
        // The check that the mesh is an oriented manifold (or its cut to one) is pm's step, not
        // the decimation's: timed apart.
        let started = std::time::Instant::now();
        let input = ManifoldInput::of(&canonical)?;
        let manifold_seconds = started.elapsed().as_secs_f64();
        let started = std::time::Instant::now();
        let simplified = match &input.cut {
            None => simplify(&input.cells, &input.faces, Placement::Optimal),
            Some(_) => simplify_constrained(
                &input.cells,
                &input.faces,
                Placement::Optimal,
                input.constraints(),
            ),
        };
        let simplify_seconds = started.elapsed().as_secs_f64();
        let pm = progressive_mesh(&input.faces, &simplified);
        let total_seconds = started.elapsed().as_secs_f64();
        let faces = canonical.face_count();
        let line = format!(
            "{name} x{}: {faces} faces -> base {} vertices; manifold check or cut {manifold_seconds:.2} s; simplify {simplify_seconds:.2} s, with PM construction {total_seconds:.2} s ({:.0} faces/s)\n",
            4u32.pow(times),
            pm.base.positions.len(),
            faces as f64 / total_seconds
        );
        progress.suspend(|| meshcodec::cli::write_stdout(&line))?;
        rows.push(serde_json::json!({
            "mesh": name,
            "cut_to_a_manifold": input.cut.is_some(),
            "subdivisions": times,
            "faces": faces,
            "vertices": canonical.vertex_count(),
            "base_vertices": pm.base.positions.len(),
            "vsplits": pm.vsplits.len(),
            "manifold_seconds": manifold_seconds,
            "simplify_seconds": simplify_seconds,
            "total_seconds": total_seconds,
            "faces_per_second": faces as f64 / total_seconds,
        }));
    }
    let dir = out.join("pm");
    std::fs::create_dir_all(&dir)?;
    let report = serde_json::json!({ "threads": rayon::current_num_threads(), "rows": rows });
    let path = dir.join("decimation.json");
    meshcodec::mesh::io::write_atomically(
        &path,
        format!("{}\n", serde_json::to_string_pretty(&report)?).as_bytes(),
    )?;
    meshcodec::outln!("wrote {}", path.display());
    Ok(())
}
