//! `meshcodec`: encode a mesh, decode a stream (whole or any prefix), describe a stream, and
//! measure the distance between two meshes (Metro-style).

mod data;
mod describe;
mod info;
mod pack;

use anyhow::{Context, Result};
use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use data::DataAction;
use meshcodec::codecs::{self, Capability, EncodeRequest, EncodedMesh, LevelMesh, Stop};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::attributes::AttributedMesh;
use meshcodec::mesh::io::{
    read_attributed, read_mesh, write_atomically, write_attributed, write_mesh,
};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SAMPLES_PER_TRIANGLE, DEFAULT_SEED};
use meshcodec_lab::data::resolve;
use meshcodec_lab::harness::{encode_options, RunOptions};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    version,
    about = "Progressive mesh compression: encode, decode, info, view, distance"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Encode a mesh file into a stream.
    Encode {
        /// Codec name (the list below).
        #[arg(long, default_value = DEFAULT_CODEC)]
        codec: String,
        /// Quantization bits per axis (default: the codec's).
        #[arg(long)]
        quant: Option<u8>,
        /// Grid shape: cubic or per-axis (default: the codec's).
        #[arg(long, value_parser = meshcodec_lab::cli::parse_grid)]
        grid: Option<GridShape>,
        /// Encode only the geometry of a file that also holds normals, texture coordinates,
        /// colours or materials (without it, they are carried, or the file is refused by a codec
        /// that cannot carry them).
        #[arg(long)]
        drop_attributes: bool,
        /// Bits per texture-coordinate axis (Qt).
        #[arg(long, default_value_t = meshcodec::mesh::attribute_quantization::DEFAULT_UV_BITS)]
        uv_bits: u8,
        /// Bits per octahedral normal coordinate (Qn).
        #[arg(long, default_value_t = meshcodec::mesh::attribute_quantization::DEFAULT_NORMAL_BITS)]
        normal_bits: u8,
        /// Normals derived from the positions over the input's normal wedges (its normals then
        /// say only where the creases are): pm with --attributes codes no normal values at all
        /// (Hoppe 1998's Table 4 mode); the other codecs carry the derived normals.
        #[arg(long)]
        derive_normals: bool,
        /// Where the appearance goes when not the codec's own way (emc, emc-ahead: a part after
        /// each level, so that every level shows it; the others: an appearance unit after the
        /// last level): `fit` or `keep`, pm only, inside the vertex splits, so that every level
        /// carries it, a collapsed wedge taking the values interpolated to where its vertex went
        /// or the survivor's; `unit`, any codec that carries appearance, in an appearance unit
        /// after the last level.
        #[arg(long, value_parser = ["fit", "keep", "unit"])]
        attributes: Option<String>,
        /// Mesh file or name.
        input: String,
        /// Stream file to write.
        output: PathBuf,
    },
    /// Decode a stream (or a prefix of it) into a mesh file, with the normals, texture
    /// coordinates, colours and materials the stream carries.
    Decode {
        /// Stream file.
        input: PathBuf,
        /// Mesh file to write (.ply, .obj, .glb or .gltf; a format that cannot hold what the
        /// stream carries is refused, naming those that can).
        output: PathBuf,
        /// Write the geometry alone, dropping the normals, texture coordinates, colours and
        /// materials the stream carries.
        #[arg(long)]
        drop_attributes: bool,
        /// Stop after this many levels.
        #[arg(long, conflicts_with = "bytes")]
        level: Option<usize>,
        /// Use only the first N bytes of the stream.
        #[arg(long)]
        bytes: Option<usize>,
        /// Stop after this many passes (EMC: three per level, one per direction).
        #[arg(long, conflicts_with_all = ["level", "bytes"])]
        passes: Option<usize>,
    },
    /// Describe a stream (header, levels, units, appearance), or a mesh or glTF file (vertices,
    /// triangles, appearance, components, boundary and non-manifold edges; a packed scene's
    /// streams).
    Info {
        /// Stream, mesh or glTF file (or a mesh's bare name).
        input: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Adapt a CAME stream's hierarchy to a camera (view-dependent refinement) and write the
    /// adapted mesh, optionally with a render from that camera.
    View {
        /// CAME stream (came or came-paper).
        input: PathBuf,
        /// Mesh file to write (.ply or .obj).
        output: PathBuf,
        #[command(flatten)]
        camera: CameraArgs,
        /// Screen-space tolerance, pixels: nodes are refined while their deviation (came; the
        /// error sphere in came-paper and older came streams) spans this many pixels or more.
        #[arg(long, default_value_t = 1.0)]
        tolerance: f64,
        /// Face budget: the tolerance is raised until the mesh holds at most this many faces.
        #[arg(long)]
        faces: Option<usize>,
        /// Write a render from the camera.
        #[arg(long)]
        png: Option<PathBuf>,
        /// Refine the parts that face away from the eye too (for a surface drawn two-sided or
        /// seen from inside); by default, a node whose normal cone turns every face away stays
        /// coarse.
        #[arg(long)]
        two_sided: bool,
        /// Leave out the orientation guard: faster and a few percent fewer faces, but faces in
        /// view may turn over against the full mesh's (fold-overs); by default every face in
        /// view turns as its full-mesh triangle does.
        #[arg(long)]
        allow_fold_overs: bool,
    },
    /// Render a mesh file, or a stream's full level (or `--level`), flat-shaded from a camera
    /// into a PNG: the project's own rasterizer, which the browser viewer's test compares with.
    Render {
        /// Mesh file or name, or a stream (.mc).
        input: String,
        /// PNG to write.
        output: PathBuf,
        #[command(flatten)]
        camera: CameraArgs,
        /// A stream's level to draw (default: its last).
        #[arg(long)]
        level: Option<usize>,
    },
    /// Convert a mesh file to another format (.ply, .obj, .glb or .gltf), keeping its normals,
    /// texture coordinates, colours and materials where the output format holds them.
    Convert {
        /// Mesh file to read.
        input: String,
        /// Mesh file to write (a format that cannot hold what the input holds is refused,
        /// naming those that can).
        output: PathBuf,
        /// Write the geometry alone, dropping the input's normals, texture coordinates, colours
        /// and materials.
        #[arg(long)]
        drop_attributes: bool,
    },
    /// The test meshes a bare name calls up (data/meshes.tsv): `list` says where each is, or
    /// that it is not here; `fetch NAME|--all` downloads into the per-user cache
    /// ($MESHCODEC_CACHE, else ~/.cache/meshcodec/meshes) from $MESHCODEC_MIRROR when set, else
    /// from its public source, checking its sha256.
    Data {
        #[command(subcommand)]
        action: DataAction,
    },
    /// Pack a glTF scene (.gltf with its files, .glb) or any mesh file into a GLB whose
    /// triangle primitives are progressive streams (docs/GLTF.md: the MESHCODEC_progressive
    /// extension), each primitive's own accessors a coarse level that any glTF viewer shows;
    /// the rest of the scene kept. Primitives the codecs cannot take are kept as they are and
    /// listed on stderr.
    Pack {
        /// Scene or mesh file (a .gltf's buffers and images are read from beside it).
        input: String,
        /// GLB to write.
        output: PathBuf,
        /// Codec of the streams (emc carries the appearance with every level).
        #[arg(long, default_value = DEFAULT_CODEC)]
        codec: String,
        /// Quantization bits per axis of the positions.
        #[arg(long, default_value_t = 12)]
        quant: u8,
        /// Bits per texture-coordinate axis (Qt).
        #[arg(long, default_value_t = meshcodec::mesh::attribute_quantization::DEFAULT_UV_BITS)]
        uv_bits: u8,
        /// Bits per octahedral normal coordinate (Qn).
        #[arg(long, default_value_t = meshcodec::mesh::attribute_quantization::DEFAULT_NORMAL_BITS)]
        normal_bits: u8,
        /// The fallback level: the one whose triangles are nearest this share of the
        /// primitive's ...
        #[arg(long, default_value_t = 0.02)]
        fallback_share: f64,
        /// ... and at least this many triangles (or all of a smaller primitive's).
        #[arg(long, default_value_t = 256)]
        fallback_faces: usize,
        /// No fallback: the primitives' accessors hold no data, and the extension is
        /// required (a loader without it cannot draw them).
        #[arg(long)]
        no_fallback: bool,
        /// The streams in a file of their own beside the GLB (OUT.streams.bin), so that a
        /// client fetches their levels by HTTP Range requests.
        #[arg(long)]
        external: bool,
    },
    /// Decode every progressive stream of a packed GLB back into ordinary accessors (each
    /// primitive's full level, lossless at the stream's quantization); the rest as it was.
    Unpack {
        /// Packed GLB.
        input: PathBuf,
        /// GLB to write.
        output: PathBuf,
    },
    /// Distance between two meshes' surfaces: one-sided both ways, Hausdorff, RMS; and, when
    /// both have appearance, its error (uv texels, normal degrees, colour steps, materials).
    Distance {
        /// Reference mesh.
        a: String,
        /// Compared mesh.
        b: String,
        /// Random samples per triangle of A (taken on each mesh).
        #[arg(long, default_value_t = DEFAULT_SAMPLES_PER_TRIANGLE)]
        samples: usize,
        /// Most random samples on each mesh, whatever A's size.
        #[arg(long, default_value_t = meshcodec::metrics::DEFAULT_MAX_SAMPLES)]
        max_samples: usize,
        /// Sampler seed.
        #[arg(long, default_value_t = DEFAULT_SEED)]
        seed: u64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write every sample and its distance as CSV (direction,x,y,z,distance).
        #[arg(long)]
        write_samples: Option<PathBuf>,
    },
    /// Distance between two meshes' surfaces as a camera sees it, in pixels: both ways, over
    /// the samples in the frustum (A's vertices and face centroids to B; B's face centroids
    /// and edge midpoints to A), a distance d at depth z counting d over a pixel's size there,
    /// with no occlusion test — as paper-tables/came-vd.md measures a front against the full
    /// mesh.
    ScreenDistance {
        /// Reference mesh.
        a: String,
        /// Compared mesh.
        b: String,
        #[command(flatten)]
        camera: CameraArgs,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

/// A camera on the command line (`view`, `render`, `screen-distance`).
#[derive(clap::Args)]
struct CameraArgs {
    /// Eye position, x,y,z (the mesh's units).
    #[arg(long, value_parser = meshcodec_lab::cli::parse_vector, allow_hyphen_values = true)]
    eye: glam::DVec3,
    /// Point looked at, x,y,z.
    #[arg(long, value_parser = meshcodec_lab::cli::parse_vector, allow_hyphen_values = true)]
    target: glam::DVec3,
    /// Up direction, x,y,z.
    #[arg(long, value_parser = meshcodec_lab::cli::parse_vector, allow_hyphen_values = true, default_value = "0,1,0")]
    up: glam::DVec3,
    /// Vertical field of view, degrees.
    #[arg(long, default_value_t = 50.0)]
    fov: f64,
    /// Viewport, WIDTHxHEIGHT pixels.
    #[arg(long, value_parser = meshcodec_lab::cli::parse_size, default_value = "1280x720")]
    size: (u32, u32),
}

impl CameraArgs {
    /// The camera as the view-dependent front takes it.
    fn view_camera(&self) -> meshcodec::codecs::came::refine::Camera {
        meshcodec::codecs::came::refine::Camera {
            eye: self.eye,
            target: self.target,
            up: self.up,
            fov_degrees: self.fov,
            width: self.size.0,
            height: self.size.1,
        }
    }

    /// The camera as the rasterizer takes it.
    fn perspective(&self) -> meshcodec_lab::render::Perspective {
        meshcodec_lab::render::Perspective {
            eye: self.eye,
            target: self.target,
            up: self.up,
            fov_degrees: self.fov,
        }
    }
}

/// The codec `encode` uses when given none.
const DEFAULT_CODEC: &str = "emc";

fn main() -> ExitCode {
    let command = Cli::command().mut_subcommand("encode", |encode| {
        encode.after_help(meshcodec_lab::cli::codec_list(Some(DEFAULT_CODEC)))
    });
    let cli = Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit());
    let outcome = match cli.command {
        Command::Encode {
            codec,
            quant,
            grid,
            drop_attributes,
            uv_bits,
            normal_bits,
            derive_normals,
            attributes,
            input,
            output,
        } => encode(
            &codec,
            quant,
            grid,
            if drop_attributes {
                Attributes::Drop
            } else {
                Attributes::Carry(
                    AttributeBits {
                        uv: uv_bits,
                        normal: normal_bits,
                        derive_normals,
                    },
                    attributes
                        .as_deref()
                        .and_then(|name| codecs::AttributeFit::by_name(name).ok()),
                    attributes.as_deref() == Some("unit"),
                )
            },
            &input,
            &output,
        ),
        Command::Decode {
            input,
            output,
            drop_attributes,
            level,
            bytes,
            passes,
        } => decode(&input, &output, drop_attributes, level, bytes, passes),
        Command::Info { input, json } => resolve(&input)
            .with_context(|| input.clone())
            .and_then(|path| info::info(&path, json)),
        Command::View {
            input,
            output,
            camera,
            tolerance,
            faces,
            png,
            two_sided,
            allow_fold_overs,
        } => {
            let chosen =
                meshcodec::codecs::came::refine::View::new(&camera.view_camera(), tolerance)
                    .map(|v| v.two_sided(two_sided).keep_orientation(!allow_fold_overs));
            match chosen {
                Ok(chosen) => view(
                    &input,
                    &output,
                    &camera,
                    &chosen,
                    tolerance,
                    faces,
                    png.as_deref(),
                ),
                Err(e) => Err(e.into()),
            }
        }
        Command::Convert {
            input,
            output,
            drop_attributes,
        } => convert(&input, &output, drop_attributes),
        Command::Data { action } => data::run(action),
        Command::Pack {
            input,
            output,
            codec,
            quant,
            uv_bits,
            normal_bits,
            fallback_share,
            fallback_faces,
            no_fallback,
            external,
        } => pack::pack(&pack::PackArgs {
            input: &input,
            output: &output,
            codec: &codec,
            quant,
            bits: AttributeBits {
                uv: uv_bits,
                normal: normal_bits,
                derive_normals: false,
            },
            fallback: (!no_fallback).then_some(meshcodec::packing::Fallback {
                share: fallback_share,
                min_faces: fallback_faces,
            }),
            external,
        }),
        Command::Unpack { input, output } => pack::unpack(&input, &output),
        Command::Render {
            input,
            output,
            camera,
            level,
        } => render(&input, &output, &camera.perspective(), camera.size, level),
        Command::ScreenDistance { a, b, camera, json } => screen_distance(&a, &b, &camera, json),
        Command::Distance {
            a,
            b,
            samples,
            max_samples,
            seed,
            json,
            write_samples,
        } => distance(
            &a,
            &b,
            SampleBudget {
                per_triangle: samples,
                max: max_samples,
            },
            seed,
            json,
            write_samples.as_deref(),
        ),
    };
    meshcodec_lab::cli::exit_code(outcome)
}

fn render(
    input: &str,
    output: &Path,
    camera: &meshcodec_lab::render::Perspective,
    (width, height): (u32, u32),
    level: Option<usize>,
) -> Result<()> {
    if !(camera.fov_degrees > 0.0 && camera.fov_degrees < 180.0) {
        anyhow::bail!(
            "--fov {}: a field of view is between 0 and 180 degrees",
            camera.fov_degrees
        );
    }
    let mesh = if input.ends_with(".mc") {
        let stream = read_stream(Path::new(input))?;
        let stop = level.map_or(Stop::All, Stop::Levels);
        codecs::decode(&stream, stop)
            .with_context(|| input.to_string())?
            .0
            .mesh
    } else {
        if level.is_some() {
            anyhow::bail!("{input}: --level is for a stream (.mc)");
        }
        let path = resolve(input).with_context(|| input.to_string())?;
        read_mesh(&path).with_context(|| path.display().to_string())?
    };
    // save_png names the file in its errors.
    meshcodec_lab::render::render_perspective(&mesh, camera, width, height).save_png(output)?;
    meshcodec_lab::outln!(
        "wrote {}: {} faces from {}",
        output.display(),
        mesh.face_count(),
        input
    );
    Ok(())
}

fn convert(input: &str, output: &Path, drop_attributes: bool) -> Result<()> {
    let path = resolve(input).with_context(|| input.to_string())?;
    let mesh = if drop_attributes {
        AttributedMesh {
            mesh: read_mesh(&path).with_context(|| path.display().to_string())?,
            attributes: Default::default(),
        }
    } else {
        read_attributed(&path).with_context(|| path.display().to_string())?
    };
    write_carried(&mesh, output, "the input holds")?;
    meshcodec_lab::outln!(
        "wrote {}: {} vertices, {} triangles, {} wedges",
        output.display(),
        mesh.mesh.vertex_count(),
        mesh.mesh.face_count(),
        mesh.attributes.wedge_vertex.len()
    );
    Ok(())
}

/// Writes `mesh` with all it carries; a format that cannot hold it is refused in one line that
/// names the formats that can and `--drop-attributes`. `carrier` says whose appearance it is.
fn write_carried(mesh: &AttributedMesh, output: &Path, carrier: &str) -> Result<()> {
    let context = || output.display().to_string();
    match write_attributed(mesh, output) {
        Err(meshcodec::Error::Unsupported(why)) if !mesh.attributes.is_empty() => {
            let holding = meshcodec::mesh::io::formats_holding(mesh);
            let formats = if holding.is_empty() {
                "no format written here holds it all".to_string()
            } else {
                let listed: Vec<String> = holding.iter().map(|f| format!(".{f}")).collect();
                format!("formats that hold what {carrier}: {}", listed.join(", "))
            };
            Err(meshcodec::Error::Unsupported(format!(
                "{why}; {formats}; --drop-attributes writes the geometry alone"
            )))
            .with_context(context)
        }
        other => other.with_context(context),
    }
}

/// A mesh file with its appearance, or without it where the reader cannot keep what the file
/// holds (distances need the geometry alone).
fn load_attributed(name: &str) -> Result<(PathBuf, meshcodec::mesh::attributes::AttributedMesh)> {
    let path = resolve(name).with_context(|| name.to_string())?;
    match meshcodec::mesh::io::read_attributed(&path) {
        Ok(mesh) => Ok((path, mesh)),
        Err(_) => {
            let mesh = read_mesh(&path).with_context(|| path.display().to_string())?;
            Ok((
                path,
                meshcodec::mesh::attributes::AttributedMesh {
                    mesh,
                    attributes: Default::default(),
                },
            ))
        }
    }
}

/// What `encode` does with a file's appearance.
enum Attributes {
    /// Carries it at these bits (a codec that cannot is refused), inside the levels by this
    /// rule when given (pm).
    Carry(AttributeBits, Option<codecs::AttributeFit>, bool),
    /// Encodes the geometry alone.
    Drop,
}

fn encode(
    codec: &str,
    quant: Option<u8>,
    grid: Option<GridShape>,
    attributes: Attributes,
    input: &str,
    output: &Path,
) -> Result<()> {
    let codec = meshcodec_lab::cli::codec_by_name(codec)?;
    let path = resolve(input).with_context(|| input.to_string())?;
    let context = || path.display().to_string();
    let options = encode_options(
        codec,
        &RunOptions {
            quant_bits: quant,
            grid,
            ..RunOptions::default()
        },
    );
    // The file is read once: with its appearance when the codec carries it. The mesh as read
    // is handed over and dropped once canonical: on a large mesh it is a tenth of the peak.
    let mut request = EncodeRequest::geometry(codec);
    request.options = options;
    let mut dropped = None;
    let mesh = match attributes {
        Attributes::Carry(bits, in_levels, unit)
            if codec.capabilities().contains(&Capability::Attributes) =>
        {
            request.appearance = Some(bits);
            request.in_levels = in_levels;
            request.appearance_unit = unit;
            read_attributed(&path).with_context(context)?
        }
        _ => {
            let (mesh, appearance) =
                meshcodec::mesh::io::read_mesh_and_appearance(&path).with_context(context)?;
            if !appearance.is_empty() {
                if matches!(attributes, Attributes::Carry(..)) {
                    return Err(meshcodec::Error::Unsupported(format!(
                        "holds {appearance}, which {} does not carry (its full level is lossy); --drop-attributes encodes the geometry alone",
                        codec.name()
                    )))
                    .with_context(context);
                }
                dropped = Some(appearance);
            }
            AttributedMesh {
                mesh,
                attributes: Default::default(),
            }
        }
    };
    let EncodedMesh {
        canonical, encoded, ..
    } = request.encode(mesh).with_context(context)?;
    write_atomically(output, &encoded.bytes).with_context(|| output.display().to_string())?;
    // Said once the stream is written, so that a failure stays one line.
    if let Some(appearance) = dropped {
        eprintln!(
            "note: {}: {appearance} dropped (--drop-attributes)",
            path.display()
        );
    }
    let bits = encoded.bytes.len() as f64 * 8.0;
    meshcodec_lab::outln!(
        "{}: {} vertices, {} triangles at {} bits -> {} bytes in {} levels ({:.3} bits/vertex, {:.3} bits/triangle)",
        output.display(),
        canonical.vertex_count(),
        canonical.face_count(),
        options.quant_bits,
        encoded.bytes.len(),
        encoded.levels.len(),
        bits / canonical.vertex_count() as f64,
        bits / canonical.face_count() as f64
    );
    Ok(())
}

fn read_stream(input: &Path) -> Result<Vec<u8>> {
    std::fs::read(input).with_context(|| input.display().to_string())
}

fn decode(
    input: &Path,
    output: &Path,
    drop_attributes: bool,
    level: Option<usize>,
    bytes: Option<usize>,
    passes: Option<usize>,
) -> Result<()> {
    let stream = read_stream(input)?;
    let prefix = &stream[..bytes.unwrap_or(stream.len()).min(stream.len())];
    let stop = match (level, passes) {
        (Some(l), _) => Stop::Levels(l),
        (_, Some(p)) => Stop::Passes(p),
        _ => Stop::All,
    };
    let (decoded, levels) =
        codecs::decode(prefix, stop).with_context(|| input.display().to_string())?;
    if decoded.mesh.positions.is_empty() {
        anyhow::bail!(
            "{}: the first {} bytes hold no complete level",
            input.display(),
            prefix.len()
        );
    }
    match decoded.attributes {
        Some(attributes) if !drop_attributes => write_carried(
            &AttributedMesh {
                mesh: decoded.mesh.clone(),
                attributes,
            },
            output,
            "the stream carries",
        )?,
        _ => write_mesh(&decoded.mesh, output).with_context(|| output.display().to_string())?,
    }
    meshcodec_lab::outln!(
        "{}: level {levels}, {} vertices, {} triangles from {} bytes",
        output.display(),
        decoded.mesh.vertex_count(),
        decoded.mesh.face_count(),
        prefix.len()
    );
    Ok(())
}

fn view(
    input: &Path,
    output: &Path,
    camera: &CameraArgs,
    view: &meshcodec::codecs::came::refine::View,
    tolerance: f64,
    faces: Option<usize>,
    png: Option<&Path>,
) -> Result<()> {
    use meshcodec::codecs::came::refine::{Budget, ViewMesh};
    let context = || input.display().to_string();
    // Only the header, the index and the meta-nodes this view needs are read.
    let mut front = ViewMesh::open_file(input).with_context(context)?;
    let budget = Budget {
        operations: usize::MAX,
        faces,
    };
    let started = std::time::Instant::now();
    // The face budget is held by raising the tolerance from one adaptation to the next, until
    // the front settles with no split held back; meta-nodes are waited for as they are asked.
    let done = front.settle(view, budget, 64);
    let seconds = started.elapsed().as_secs_f64();
    let mesh = front.mesh();
    write_mesh(&mesh, output).with_context(|| output.display().to_string())?;
    meshcodec_lab::outln!(
        "{}: {} faces, {} vertices (tolerance {:.3} px{}); {} splits, {} collapses in {:.1} ms",
        output.display(),
        mesh.face_count(),
        mesh.vertex_count(),
        tolerance * front.tolerance_scale(),
        faces.map_or(String::new(), |f| format!(", budget {f} faces")),
        done.splits,
        done.collapses,
        seconds * 1e3
    );
    meshcodec_lab::outln!(
        "back faces: {}",
        if view.is_two_sided() {
            "refined like front faces (--two-sided)"
        } else if front.has_normal_cones() {
            "left coarse where a node's normal cone turns every face away"
        } else {
            "refined like front faces (the stream codes no normal cones)"
        }
    );
    if !view.keeps_orientation() {
        meshcodec_lab::outln!("orientation: not guarded (--allow-fold-overs)");
    } else if done.unsure == 0 {
        meshcodec_lab::outln!(
            "orientation: every face in view turns as its full-mesh triangle does"
        );
    } else {
        meshcodec_lab::outln!(
            "orientation: {} faces in view left unsure (a budget held their splits back, or their meta-nodes were refused)",
            done.unsure
        );
    }
    let fetched = front.fetched();
    meshcodec_lab::outln!(
        "read {} of {} bytes ({:.1}%), {} of {} meta-nodes",
        fetched.bytes_read,
        fetched.stream_bytes,
        100.0 * fetched.bytes_read as f64 / fetched.stream_bytes.max(1) as f64,
        fetched.units_loaded,
        fetched.units
    );
    for (unit, why) in front.refusals() {
        eprintln!("warning: meta-node {unit} refused, its branch stays coarse: {why}");
    }
    if let Some(png) = png {
        let (width, height) = camera.size;
        meshcodec_lab::render::render_perspective(&mesh, &camera.perspective(), width, height)
            .save_png(png)?;
        meshcodec_lab::outln!("wrote {}", png.display());
    }
    Ok(())
}

fn screen_distance(a: &str, b: &str, camera: &CameraArgs, json: bool) -> Result<()> {
    let (path_a, mesh_a) = load_attributed(a)?;
    let (path_b, mesh_b) = load_attributed(b)?;
    let view_camera = camera.view_camera();
    // The tolerance plays no part: only the frustum is used.
    let view = meshcodec::codecs::came::refine::View::new(&view_camera, 1.0)?;
    let reference = meshcodec_lab::came::screen_error::FullMesh::new(&mesh_a.mesh);
    let error = reference.screen_error(&mesh_b.mesh, &view_camera, &view);
    if error.samples == 0 {
        anyhow::bail!("no sample of either mesh lies in the camera's frustum");
    }
    if json {
        let report = serde_json::json!({
            "a": path_a.display().to_string(),
            "b": path_b.display().to_string(),
            "samples": error.samples,
            "max_px": error.max_px,
            "mean_px": error.mean_px,
            "worst_at": error.worst_at.to_array(),
            "worst_on": if error.worst_on_full { "a" } else { "b" },
        });
        meshcodec_lab::outln!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        meshcodec_lab::outln!(
            "{} samples in the frustum: max {:.3} px (a sample of {} at {:.6?}), mean {:.4} px",
            error.samples,
            error.max_px,
            if error.worst_on_full { "A" } else { "B" },
            error.worst_at.to_array(),
            error.mean_px
        );
    }
    Ok(())
}

fn distance(
    a: &str,
    b: &str,
    samples: SampleBudget,
    seed: u64,
    json: bool,
    dump: Option<&Path>,
) -> Result<()> {
    let (path_a, attributed_a) = load_attributed(a)?;
    let (path_b, attributed_b) = load_attributed(b)?;
    let mesh_a = &attributed_a.mesh;
    let reference = Reference::new(mesh_a, samples, seed);
    let appearance = meshcodec::metrics::appearance::AppearanceReference::new(
        &attributed_a,
        samples.count(mesh_a.face_count()),
        seed ^ 2,
    )
    .map(|r| r.compare(&attributed_b.mesh, Some(&attributed_b.attributes)))
    .filter(|e| *e != Default::default());
    let level = LevelMesh {
        mesh: attributed_b.mesh,
        ..LevelMesh::default()
    };
    let m = reference
        .measure(&level)
        .context("the compared mesh has no vertex")?;
    let diag = reference.diagonal;
    let (hausdorff, rms) = (m.hausdorff(), m.rms());
    if let Some(dump) = dump {
        let mut csv = String::from("direction,x,y,z,distance\n");
        let rows = [
            ("a_to_b", &reference.samples.points, &m.to_level),
            ("b_to_a", &m.level_samples.points, &m.to_original),
        ];
        for (direction, points, distances) in rows {
            for (p, d) in points.iter().zip(distances.iter()) {
                let _ = writeln!(csv, "{direction},{:?},{:?},{:?},{:?}", p.x, p.y, p.z, d);
            }
        }
        write_atomically(dump, csv.as_bytes()).with_context(|| dump.display().to_string())?;
    }
    let report = serde_json::json!({
        "a": path_a.display().to_string(),
        "b": path_b.display().to_string(),
        "diagonal": diag,
        "samples_per_triangle": samples.per_triangle,
        "max_samples": samples.max,
        "uncertainty": m.uncertainty(),
        "seed": seed,
        "a_to_b": m.forward,
        "b_to_a": m.backward,
        "hausdorff": hausdorff,
        "rms": rms,
        "hausdorff_relative": hausdorff / diag,
        "rms_relative": rms / diag,
        "hausdorff_paper": m.paper,
        "appearance": appearance,
    });
    if json {
        meshcodec_lab::outln!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    meshcodec_lab::outln!(
        "A = {} , B = {} (diagonal of A {:.6e})",
        path_a.display(),
        path_b.display(),
        diag
    );
    meshcodec_lab::outln!(
        "{:<8} {:>10} {:>13} {:>13} {:>13}",
        "",
        "samples",
        "max",
        "mean",
        "rms"
    );
    for (name, s) in [("A -> B", m.forward), ("B -> A", m.backward)] {
        meshcodec_lab::outln!(
            "{name:<8} {:>10} {:>13.6e} {:>13.6e} {:>13.6e}",
            s.samples,
            s.max,
            s.mean,
            s.rms
        );
    }
    let uncertainty = m.uncertainty();
    meshcodec_lab::outln!(
        "Hausdorff {hausdorff:.6e} ({:.6e} of diagonal, +{:.2}% from half the samples), RMS {rms:.6e} ({:.6e} of diagonal, ±{:.2}%)",
        hausdorff / diag,
        uncertainty.hausdorff * 100.0,
        rms / diag,
        uncertainty.rms * 100.0
    );
    if let Some(e) = appearance {
        let show =
            |v: Option<f64>, unit: &str| v.map_or("-".to_string(), |x| format!("{x:.4}{unit}"));
        meshcodec_lab::outln!(
            "appearance (mean over A's samples): uv {} (RMS {}), normal {} , colour {} , wrong material {}",
            show(e.uv_texels, " texels of 1024²"),
            show(e.uv_rms_texels, ""),
            show(e.normal_degrees, "°"),
            show(e.colour_steps, " /255"),
            show(e.wrong_material, "")
        );
    }
    Ok(())
}
