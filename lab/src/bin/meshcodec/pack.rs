//! `meshcodec pack` and `unpack`: a glTF scene's triangle primitives as progressive streams
//! inside a GLB (docs/GLTF.md), and back.

use anyhow::{Context, Result};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::io::write_atomically;
use meshcodec::mesh::scene::Scene;
use meshcodec::packing::{self, Fallback, Outcome, PackOptions};
use meshcodec_lab::data::resolve;
use std::path::Path;

/// What `pack` is asked.
pub struct PackArgs<'a> {
    pub input: &'a str,
    pub output: &'a Path,
    pub codec: &'a str,
    pub quant: u8,
    pub bits: AttributeBits,
    pub fallback: Option<Fallback>,
    pub external: bool,
}

/// Reads a scene: a `.gltf` (with the files beside it) or `.glb` as it is, any other mesh
/// file (or shared mesh name) as a scene of one mesh.
pub fn read_scene(input: &str) -> Result<(std::path::PathBuf, Scene)> {
    let path = resolve(input).with_context(|| input.to_string())?;
    let scene = Scene::open(&path).with_context(|| path.display().to_string())?;
    Ok((path, scene))
}

pub fn pack(args: &PackArgs) -> Result<()> {
    if args
        .output
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("glb"))
    {
        anyhow::bail!("{}: pack writes a .glb", args.output.display());
    }
    let (path, scene) = read_scene(args.input)?;
    let codec = meshcodec_lab::cli::codec_by_name(args.codec)?;
    let options = PackOptions {
        codec,
        quant_bits: args.quant,
        bits: args.bits,
        fallback: args.fallback,
    };
    let streams_path = args.output.with_extension("streams.bin");
    let uri = streams_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let packed = packing::pack(&scene, &options, args.external.then_some(uri.as_str()))
        .with_context(|| path.display().to_string())?;
    for p in &packed.report {
        let name = p
            .name
            .as_deref()
            .map_or(String::new(), |n| format!(" '{n}'"));
        match &p.outcome {
            Outcome::Packed {
                stream_bytes,
                levels,
                fallback_level,
                fallback_faces,
                faces,
            } => eprintln!(
                "mesh {}{name} primitive {}: {} triangles -> {} in {stream_bytes} bytes, {levels} levels; fallback {}",
                p.mesh,
                p.primitive,
                faces,
                codec.name(),
                if *fallback_level == 0 {
                    "none".to_string()
                } else {
                    format!("level {fallback_level} ({fallback_faces} triangles)")
                }
            ),
            Outcome::Kept(why) => eprintln!(
                "mesh {}{name} primitive {}: kept as it is: {why}",
                p.mesh,
                p.primitive
            ),
        }
    }
    write_atomically(args.output, &packed.glb)
        .with_context(|| args.output.display().to_string())?;
    if let Some(streams) = &packed.streams {
        write_atomically(&streams_path, streams)
            .with_context(|| streams_path.display().to_string())?;
    }
    let coded = packed
        .report
        .iter()
        .filter(|p| matches!(p.outcome, Outcome::Packed { .. }))
        .count();
    meshcodec_lab::outln!(
        "wrote {}: {} bytes, {coded} of {} primitives progressive{}",
        args.output.display(),
        packed.glb.len(),
        packed.report.len(),
        packed.streams.as_ref().map_or(String::new(), |s| format!(
            "; their streams in {} ({} bytes)",
            streams_path.display(),
            s.len()
        ))
    );
    Ok(())
}

pub fn unpack(input: &Path, output: &Path) -> Result<()> {
    let context = || input.display().to_string();
    let bytes = std::fs::read(input).with_context(context)?;
    let scene = Scene::read(&bytes, input.parent()).with_context(context)?;
    let unpacked = packing::unpack(&scene).with_context(context)?;
    write_atomically(output, &unpacked.glb).with_context(|| output.display().to_string())?;
    meshcodec_lab::outln!(
        "wrote {}: {} bytes, {} primitives decoded",
        output.display(),
        unpacked.glb.len(),
        unpacked.primitives
    );
    Ok(())
}
