//! `meshcodec info`: what a stream says of itself (header, grid, levels or meta-nodes, units
//! present, appearance), as text or JSON, with each level's mesh sizes from decoding it.

use super::read_stream;
use anyhow::{Context, Result};
use meshcodec::codecs::{self, LevelMesh, StreamInfo};
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// `info --json`: the stream's [`StreamInfo`] (the keys the Python and WebAssembly packages'
/// `info` use too), the file, and each level's mesh sizes from decoding it.
#[derive(Serialize)]
struct Report<'a> {
    file: String,
    #[serde(flatten)]
    info: &'a StreamInfo,
    level_sizes: &'a [LevelSize],
}

/// One decoded level's sizes; its end byte and bytes where each unit is a level.
#[derive(Serialize)]
struct LevelSize {
    level: usize,
    end_byte: Option<u64>,
    payload_bytes: Option<u64>,
    /// Bytes of the level's appearance part, in streams whose levels have one.
    #[serde(skip_serializing_if = "Option::is_none")]
    appearance_bytes: Option<u64>,
    vertices: usize,
    triangles: usize,
    loose_edges: usize,
}

pub fn info(input: &Path, json: bool) -> Result<()> {
    let stream = read_stream(input)?;
    // Anything but a stream (a mesh or glTF file) is described as a mesh; a `.mc` file is
    // always read as a stream (and refused as one when it is not).
    let mc = input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mc"));
    if !mc && !stream.starts_with(&meshcodec::container::MAGIC) {
        return super::describe::describe(input, json);
    }
    let context = || input.display().to_string();
    let info = StreamInfo::of(&stream).with_context(context)?;
    // Mesh sizes from decoding every level present; where each unit is a level, its bytes.
    let mut decoder = codecs::open(&stream).with_context(context)?;
    let mut level_sizes = Vec::new();
    while decoder.advance().with_context(context)? {
        let LevelMesh {
            mesh, loose_edges, ..
        } = decoder.mesh()?;
        let level = decoder.levels_decoded();
        let unit = info.layered.then(|| &info.units[level - 1]);
        let part = info
            .appearance
            .as_ref()
            .and_then(|a| a.level_parts.get(level - 1));
        level_sizes.push(LevelSize {
            level,
            end_byte: unit.map(|_| info.level_ends[level - 1]),
            payload_bytes: unit.map(|u| u.bytes),
            appearance_bytes: part.map(|p| p.bytes),
            vertices: mesh.vertex_count(),
            triangles: mesh.face_count(),
            loose_edges: loose_edges.len(),
        });
    }
    if json {
        let report = Report {
            file: input.display().to_string(),
            info: &info,
            level_sizes: &level_sizes,
        };
        meshcodec_lab::outln!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let present = info.units.iter().take_while(|u| u.present).count();
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{}: {} bytes, format version {}, codec {} (syntax {})",
        input.display(),
        info.bytes,
        info.format_version,
        info.codec,
        info.syntax
    );
    let _ = writeln!(
        text,
        "grid: {} bits, origin {:?}, cell {:?}",
        info.quant_bits, info.origin, info.cell
    );
    let _ = writeln!(
        text,
        "full mesh: {} vertices, {} triangles; {} of {} levels present{}{}",
        info.vertices,
        info.triangles,
        level_sizes.len(),
        info.levels,
        if info.layered {
            String::new()
        } else {
            format!(" ({present} of {} meta-node units)", info.units.len())
        },
        if info.truncated { " (truncated)" } else { "" }
    );
    if let Some(cones) = info.facts.normal_cones {
        let _ = writeln!(
            text,
            "{}",
            if cones {
                "normal cones: one per inner node (back faces culled by `meshcodec view`)"
            } else {
                "normal cones: none (every node refined as if it faced the eye)"
            }
        );
    }
    if let Some(copies) = info.facts.vertex_copies {
        let _ = writeln!(
            text,
            "cut to an oriented 2-manifold: {copies} vertex copies, kept at their originals' cells by the levels before the last, which welds them back"
        );
    }
    if let Some(a) = &info.appearance {
        let mut carried = Vec::new();
        if let Some(bits) = a.normal_bits {
            let mode = match a.normals {
                Some("derived") => ", derived from the positions over their groups",
                Some("predicted") => ", predicted from the geometry of their vertex's faces",
                _ => "",
            };
            carried.push(format!(
                "normals (octahedral, {bits} bits a coordinate{mode})"
            ));
        }
        if let (Some(bits), Some(origin), Some(cell)) = (a.uv_bits, a.uv_origin, a.uv_cell) {
            carried.push(format!("uvs ({bits} bits, origin {origin:?}, cell {cell})"));
        }
        if a.colours {
            carried.push("colours (8 bits a channel)".into());
        }
        if let Some(names) = &a.materials {
            carried.push(format!(
                "{} material(s) {:?}{}",
                names.len(),
                names,
                a.material_library
                    .as_ref()
                    .map_or(String::new(), |l| format!(" from {l}"))
            ));
        }
        let where_ = match &a.unit {
            Some(u) => format!(
                "; unit at bytes {}..{} ({} bytes{})",
                u.first_byte,
                u.end_byte,
                u.bytes,
                if u.present { "" } else { ", not present" }
            ),
            None if a.in_levels => "; in every level".to_string(),
            None if !a.level_parts.is_empty() => {
                "; a part after each level (appearance column)".to_string()
            }
            None => String::new(),
        };
        let _ = writeln!(text, "appearance: {}{where_}", carried.join(", "));
    }
    let parts = level_sizes.iter().any(|l| l.appearance_bytes.is_some());
    let _ = writeln!(
        text,
        "{:>5} {:>10} {:>10} {:>10} {:>10}{}",
        "level",
        "end byte",
        "bytes",
        "vertices",
        "triangles",
        if parts { "  appearance" } else { "" }
    );
    // A table cell: a number, or a dash where there is none.
    let cell = |value: Option<u64>| value.map_or("—".to_string(), |v| v.to_string());
    for l in &level_sizes {
        let _ = writeln!(
            text,
            "{:>5} {:>10} {:>10} {:>10} {:>10}{}",
            l.level,
            cell(l.end_byte),
            cell(l.payload_bytes),
            l.vertices,
            l.triangles,
            if parts {
                format!(" {:>11}", cell(l.appearance_bytes))
            } else {
                String::new()
            }
        );
    }
    if !info.layered {
        let _ = writeln!(
            text,
            "{:>9} {:>8} {:>11} {:>10} {:>8}",
            "meta-node", "parent", "first byte", "end byte", "bytes"
        );
        for u in &info.units {
            let _ = writeln!(
                text,
                "{:>9} {:>8} {:>11} {:>10} {:>8}",
                u.unit,
                cell(u.parent.map(|p| p as u64)),
                u.first_byte,
                u.end_byte,
                u.bytes
            );
        }
    }
    meshcodec_lab::cli::write_stdout(&text)?;
    Ok(())
}
