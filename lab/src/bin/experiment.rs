//! `experiment <codec> <mesh>`: encode, decode every level, measure, write results and plots,
//! print the level table. `experiment run FILE.toml`: a set of codecs × meshes × quantizations,
//! with one comparison chart per mesh.

use anyhow::{Context, Result};
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use meshcodec::codecs::Codec;
use meshcodec::mesh::io::mesh_name;
use meshcodec::mesh::quantize::GridShape;
use meshcodec_lab::data::resolve;
use meshcodec_lab::harness::{self, RunOptions};
use meshcodec_lab::plot;
use meshcodec_lab::progress::Progress;
use meshcodec_lab::results::{self, RunResult};
use meshcodec_lab::sweep::{JobRecord, Shard, ShardManifest};
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
    #[arg(long, value_parser = meshcodec_lab::cli::parse_grid)]
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
    /// survivor's (`keep`); or `unit`: in an appearance unit after the last level whatever the
    /// codec's own way (emc and emc-ahead code it with their levels); results as
    /// STEM-appearance-RULE.
    #[arg(long, value_parser = ["fit", "keep", "unit"])]
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
        #[arg(long, value_parser = meshcodec_lab::sweep::Shard::parse)]
        shard: Option<meshcodec_lab::sweep::Shard>,
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
    let command = Cli::command().after_help(meshcodec_lab::cli::codec_list(None));
    let cli = Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit());
    let outcome = match &cli.command {
        Some(Command::Run {
            file,
            shard,
            settings,
        }) => run_set(file, *shard, settings),
        Some(Command::Merge { file, shards, out }) => merge(file, shards, out),
        Some(Command::Tables { results, out }) => tables(results, out),
        Some(Command::Decimation { out }) => meshcodec_lab::pm::decimation::run(out),
        Some(Command::RepairCost { out }) => meshcodec_lab::pm::repair_cost::run(out),
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
    meshcodec_lab::cli::exit_code(outcome)
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
        appearance_unit: settings.attributes.as_deref() == Some("unit"),
    }
}

fn run_one(codec_name: &str, mesh: &str, settings: &Settings) -> Result<(RunResult, Vec<PathBuf>)> {
    let codec = meshcodec_lab::cli::codec_by_name(codec_name)?;
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
    meshcodec_lab::outln!(
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
    meshcodec_lab::outln!(
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
        meshcodec_lab::outln!("wrote {}", path.display());
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
            .map(|c| meshcodec_lab::cli::codec_by_name(c))
            .collect::<Result<Vec<_>, meshcodec_lab::cli::UnknownCodec>>()
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
            Some(g) => Some(meshcodec_lab::cli::parse_grid(g).map_err(anyhow::Error::msg)?),
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
        for rule in set.attributes.iter().filter(|r| *r != "unit") {
            meshcodec::codecs::AttributeFit::by_name(rule)
                .with_context(|| format!("{}: attributes (fit, keep, unit)", file.display()))?;
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
        meshcodec_lab::outln!("{}: {}", set.name, set.description);
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
            appearance_unit: rule == Some("unit"),
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
                meshcodec_lab::outln!("{} refused {mesh}: {why}", codec.name());
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
            let path = meshcodec_lab::sweep::manifest_path(out, &set.name, shard);
            std::fs::create_dir_all(out)?;
            let text = serde_json::to_string_pretty(&manifest)?;
            meshcodec::mesh::io::write_atomically(&path, format!("{text}\n").as_bytes())?;
            meshcodec_lab::outln!(
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
        meshcodec_lab::outln!("wrote comparison charts to {}", dir.display());
        summary.extend(runs);
    }
    meshcodec_lab::outln!(
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
        meshcodec_lab::outln!(
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
    let found = meshcodec_lab::sweep::collect(&set.name, jobs.len(), shards)?;
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
    meshcodec_lab::outln!(
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
    let (written, missing) = meshcodec_lab::tables::regenerate(results, out);
    for path in &written {
        meshcodec_lab::outln!("wrote {}", path.display());
    }
    for why in &missing {
        meshcodec_lab::outln!("skipped {why}");
    }
    if written.is_empty() {
        anyhow::bail!("no table could be made from {}", results.display());
    }
    Ok(())
}

fn came_extras(out: &Path) -> Result<()> {
    logged("came-extras: reading", |log| {
        meshcodec_lab::came::extras::run(out, log)
    })
}

fn emc_scale(out: &Path) -> Result<()> {
    logged("emc-scale: reading and subdividing", |log| {
        meshcodec_lab::emc::scale::run(out, log)
    })
}

fn came_vd(out: &Path, work: &Path) -> Result<()> {
    logged("came-vd: reading and encoding", |log| {
        meshcodec_lab::came::vd::run(out, work, log)
    })
}

fn came_fly(out: &Path) -> Result<()> {
    logged("came-fly: reading and encoding", |log| {
        meshcodec_lab::came::flythrough::run(out, log)
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
    meshcodec_lab::outln!("wrote {}", path.display());
    Ok(())
}
