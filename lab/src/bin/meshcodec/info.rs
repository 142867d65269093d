//! `meshcodec info`: what a stream says of itself (header, grid, levels or meta-nodes, units
//! present, appearance), as text or JSON, with each level's mesh sizes from decoding it.

use super::read_stream;
use anyhow::{Context, Result};
use meshcodec::codecs::{self, LevelMesh};
use meshcodec::container::StreamReader;
use std::fmt::Write as _;
use std::path::Path;

pub fn info(input: &Path, json: bool) -> Result<()> {
    let stream = read_stream(input)?;
    let context = || input.display().to_string();
    let reader = StreamReader::open(&stream).with_context(context)?;
    let header = reader.header().clone();
    let codec = codecs::by_id(header.codec_id).with_context(context)?;
    // Level sizes from the index where each unit is a level, mesh sizes from decoding. In a
    // stream of meta-nodes (CAME) a level takes every unit rooted above it, so only the units'
    // count is listed.
    let layered = reader.index().is_layered();
    let units = reader.index().len();
    let present = (0..units).map_while(|i| reader.unit(i)).count();
    let mut decoder = codecs::open(&stream).with_context(context)?;
    let declared = decoder.levels();
    let mut levels = Vec::new();
    while decoder.advance().with_context(context)? {
        let LevelMesh {
            mesh, loose_edges, ..
        } = decoder.mesh()?;
        let level = decoder.levels_decoded();
        let unit = layered.then(|| reader.unit(level - 1)).flatten();
        levels.push(serde_json::json!({
            "level": level,
            "end_byte": unit.as_ref().map(|u| u.start + u.bytes.len()),
            "payload_bytes": unit.as_ref().map(|u| u.bytes.len()),
            "vertices": mesh.vertex_count(),
            "triangles": mesh.face_count(),
            "loose_edges": loose_edges.len(),
        }));
    }
    // Meta-nodes (CAME): each unit's parent and byte range in the file, as a client that
    // fetches them by range needs them.
    let payload_start = reader.payload_start() as u64;
    let meta_nodes: Vec<serde_json::Value> = if layered {
        Vec::new()
    } else {
        reader
            .index()
            .units
            .iter()
            .enumerate()
            .map(|(i, u)| {
                serde_json::json!({
                    "unit": i,
                    "parent": u.parent,
                    "first_byte": payload_start + u.offset,
                    "end_byte": payload_start + u.end(),
                    "bytes": u.length,
                })
            })
            .collect()
    };
    // The appearance block and where its unit lies.
    let appearance = header.appearance.as_ref().map(|spec| {
        let entry = reader.index().appearance;
        serde_json::json!({
            "normal_bits": spec.normal_bits,
            "normals": spec.normal_mode(),
            "uv_bits": spec.uv_grid.map(|g| g.bits),
            "uv_origin": spec.uv_grid.map(|g| g.origin),
            "uv_cell": spec.uv_grid.map(|g| g.cell),
            "colours": spec.colours,
            "materials": spec.materials.as_ref().map(|m| &m.names),
            "material_library": spec.materials.as_ref().and_then(|m| m.library.as_ref()),
            "unit_first_byte": entry.map(|u| payload_start + u.offset),
            "unit_end_byte": entry.map(|u| payload_start + u.end()),
            "unit_bytes": entry.map(|u| u.length),
            "unit_present": reader.appearance_unit().is_some(),
        })
    });
    let sizes = &levels;
    // A pm stream of a mesh that was no oriented manifold: the levels before the last are the
    // manifold's, copies included.
    let copies = match codec.name() {
        "pm" | "pm-reordered" => codecs::pm::vertex_copies(&header),
        _ => None,
    };
    // A came stream with normal cones serves back-face culling (`meshcodec view`).
    let normal_cones = match codec.name() {
        "came" => codecs::came::modelled::params(&header)
            .ok()
            .map(|p| p.cone_bits > 0),
        "came-paper" => Some(false),
        _ => None,
    };
    let report = serde_json::json!({
        "file": input.display().to_string(),
        "bytes": stream.len(),
        "format_version": header.version(),
        "codec": codec.name(),
        "origin": header.grid.origin,
        "cell": header.grid.cell,
        "bits": header.grid.bits,
        "vertices": header.vertices,
        "triangles": header.triangles,
        "levels_declared": declared,
        "payload_start": reader.payload_start(),
        "levels_present": sizes.len(),
        "units": units,
        "units_present": present,
        "truncated": reader.truncated(),
        "levels": levels,
        "meta_nodes": meta_nodes,
        "appearance": appearance,
        "vertex_copies": copies,
        "normal_cones": normal_cones,
    });
    if json {
        meshcodec_lab::outln!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{}: {} bytes, format version {}, codec {}",
        input.display(),
        stream.len(),
        header.version(),
        codec.name()
    );
    let _ = writeln!(
        text,
        "grid: {} bits, origin {:?}, cell {:?}",
        header.grid.bits, header.grid.origin, header.grid.cell
    );
    let _ = writeln!(
        text,
        "full mesh: {} vertices, {} triangles; {} of {} levels present{}{}",
        header.vertices,
        header.triangles,
        sizes.len(),
        declared,
        if layered {
            String::new()
        } else {
            format!(" ({present} of {units} meta-node units)")
        },
        if reader.truncated() {
            " (truncated)"
        } else {
            ""
        }
    );
    if let Some(cones) = normal_cones {
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
    if let Some(copies) = copies {
        let _ = writeln!(
            text,
            "cut to an oriented 2-manifold: {copies} vertex copies, kept at their originals' cells by the levels before the last, which welds them back"
        );
    }
    if let Some(spec) = &header.appearance {
        let mut carried = Vec::new();
        if let Some(bits) = spec.normal_bits {
            let mode = match spec.normal_mode() {
                Some("derived") => ", derived from the positions over their groups",
                Some("predicted") => ", predicted from the geometry of their vertex's faces",
                _ => "",
            };
            carried.push(format!(
                "normals (octahedral, {bits} bits a coordinate{mode})"
            ));
        }
        if let Some(g) = spec.uv_grid {
            carried.push(format!(
                "uvs ({} bits, origin {:?}, cell {})",
                g.bits, g.origin, g.cell
            ));
        }
        if spec.colours {
            carried.push("colours (8 bits a channel)".into());
        }
        if let Some(m) = &spec.materials {
            carried.push(format!(
                "{} material(s) {:?}{}",
                m.names.len(),
                m.names,
                m.library
                    .as_ref()
                    .map_or(String::new(), |l| format!(" from {l}"))
            ));
        }
        let in_levels = if spec.in_levels {
            "; in every level"
        } else {
            ""
        };
        let unit = reader
            .index()
            .appearance
            .map_or(in_levels.to_string(), |u| {
                format!(
                    "; unit at bytes {}..{} ({} bytes{})",
                    payload_start + u.offset,
                    payload_start + u.end(),
                    u.length,
                    if reader.appearance_unit().is_some() {
                        ""
                    } else {
                        ", not present"
                    }
                )
            });
        let _ = writeln!(text, "appearance: {}{unit}", carried.join(", "));
    }
    let _ = writeln!(
        text,
        "{:>5} {:>10} {:>10} {:>10} {:>10}",
        "level", "end byte", "bytes", "vertices", "triangles"
    );
    // A table cell: a number, or a dash where there is none.
    let cell = |row: &serde_json::Value, key: &str| match &row[key] {
        serde_json::Value::Null => "—".to_string(),
        v => v.to_string(),
    };
    for l in &levels {
        let cell = |key: &str| cell(l, key);
        let _ = writeln!(
            text,
            "{:>5} {:>10} {:>10} {:>10} {:>10}",
            cell("level"),
            cell("end_byte"),
            cell("payload_bytes"),
            cell("vertices"),
            cell("triangles")
        );
    }
    if !meta_nodes.is_empty() {
        let _ = writeln!(
            text,
            "{:>9} {:>8} {:>11} {:>10} {:>8}",
            "meta-node", "parent", "first byte", "end byte", "bytes"
        );
        for m in &meta_nodes {
            let cell = |key: &str| cell(m, key);
            let _ = writeln!(
                text,
                "{:>9} {:>8} {:>11} {:>10} {:>8}",
                cell("unit"),
                cell("parent"),
                cell("first_byte"),
                cell("end_byte"),
                cell("bytes")
            );
        }
    }
    meshcodec_lab::cli::write_stdout(&text)?;
    Ok(())
}
