//! `meshcodec info` on a mesh or glTF file (anything not a stream): what a user checks before
//! encoding — each primitive's vertices, triangles and appearance, its components, boundary and
//! non-manifold edges — and, in a packed scene, each primitive's stream.

use anyhow::{Context, Result};
use meshcodec::mesh::attributes::AttributedMesh;
use meshcodec::mesh::scene::{Content, Scene};
use meshcodec::mesh::topology::{analyze, TopologyReport};
use meshcodec::packing::extension::{Progressive, NAME};
use meshcodec_lab::tables::thousands;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// `info --json` on a file.
#[derive(Serialize)]
struct FileReport {
    file: String,
    meshes: usize,
    primitives: Vec<PrimitiveReport>,
}

/// One primitive: its mesh and appearance, or why a codec would keep it, or its stream.
#[derive(Serialize)]
struct PrimitiveReport {
    mesh: usize,
    primitive: usize,
    name: Option<String>,
    #[serde(flatten)]
    holds: Option<MeshReport>,
    #[serde(skip_serializing_if = "Option::is_none")]
    kept: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    stream: Option<StreamReport>,
}

#[derive(Serialize)]
struct MeshReport {
    vertices: usize,
    triangles: usize,
    /// Hoppe's wedges: a vertex has one a side of each seam.
    wedges: usize,
    appearance: Vec<&'static str>,
    materials: usize,
    topology: TopologyReport,
}

/// A packed primitive's stream, as its extension describes it.
#[derive(Serialize)]
struct StreamReport {
    codec: String,
    format_version: u8,
    levels: usize,
    bytes: u64,
    vertices: u64,
    triangles: u64,
    fallback_level: u32,
    fallback_triangles: u64,
}

fn mesh_report(m: &AttributedMesh) -> MeshReport {
    let a = &m.attributes;
    let mut appearance = Vec::new();
    for (name, present) in [
        ("normals", a.normals.is_some()),
        ("uvs", a.uvs.is_some()),
        ("colours", a.colours.is_some()),
        ("materials", a.materials.is_some()),
    ] {
        if present {
            appearance.push(name);
        }
    }
    MeshReport {
        vertices: m.mesh.vertex_count(),
        triangles: m.mesh.face_count(),
        wedges: a.wedge_vertex.len(),
        appearance,
        materials: a.materials.as_ref().map_or(0, |x| x.names.len()),
        topology: analyze(&m.mesh),
    }
}

fn stream_report(object: &serde_json::Value) -> Option<StreamReport> {
    let p: Progressive = serde_json::from_value(object.clone()).ok()?;
    let last = p.levels.last()?;
    let fallback = (p.fallback_level as usize)
        .checked_sub(1)
        .and_then(|i| p.levels.get(i));
    Some(StreamReport {
        codec: p.codec.clone(),
        format_version: p.format_version,
        levels: p.levels.len(),
        bytes: last.byte_length,
        vertices: last.vertices,
        triangles: last.faces,
        fallback_level: p.fallback_level,
        fallback_triangles: fallback.map_or(0, |l| l.faces),
    })
}

/// Describes the mesh or scene file `input`.
pub fn describe(input: &Path, json: bool) -> Result<()> {
    let scene = Scene::open(input).with_context(|| input.display().to_string())?;
    let mut primitives = Vec::new();
    for p in &scene.primitives {
        let definition = &scene.document.meshes[p.mesh];
        let extension = definition.primitives[p.primitive]
            .extensions
            .as_ref()
            .and_then(|e| e.others.get(NAME));
        let (holds, kept) = match &p.content {
            Content::Triangles(m) => (Some(mesh_report(m)), None),
            Content::Kept(why) => (None, extension.is_none().then(|| why.clone())),
        };
        primitives.push(PrimitiveReport {
            mesh: p.mesh,
            primitive: p.primitive,
            name: definition.name.clone(),
            holds,
            kept,
            stream: extension.and_then(stream_report),
        });
    }
    if json {
        let report = FileReport {
            file: input.display().to_string(),
            meshes: scene.document.meshes.len(),
            primitives,
        };
        meshcodec_lab::outln!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    let mut text = String::new();
    let gltf = matches!(
        input
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("gltf" | "glb")
    );
    if gltf {
        let _ = writeln!(
            text,
            "{}: glTF scene, {} meshes, {} primitives",
            input.display(),
            scene.document.meshes.len(),
            primitives.len()
        );
    }
    for p in &primitives {
        let what = if gltf {
            let name = p
                .name
                .as_deref()
                .map_or(String::new(), |n| format!(" '{n}'"));
            format!("  mesh {}{name} primitive {}", p.mesh, p.primitive)
        } else {
            input.display().to_string()
        };
        if let Some(m) = &p.holds {
            let appearance = if m.appearance.is_empty() {
                "no appearance".to_string()
            } else {
                let materials = if m.materials > 0 {
                    format!(", {} materials", m.materials)
                } else {
                    String::new()
                };
                format!(
                    "{} ({} wedges{materials})",
                    m.appearance.join(", "),
                    thousands(m.wedges)
                )
            };
            let t = &m.topology;
            let _ = writeln!(
                text,
                "{what}: {} vertices, {} triangles; {appearance}\n{}  components {}, boundary edges {}, non-manifold edges {}, non-manifold vertices {}, {}",
                thousands(m.vertices),
                thousands(m.triangles),
                if gltf { "  " } else { "" },
                thousands(t.components),
                thousands(t.boundary_edges),
                thousands(t.non_manifold_edges),
                thousands(t.non_manifold_vertices),
                if t.edges_used_twice_one_way == 0 {
                    "faces oriented alike".to_string()
                } else {
                    format!("{} edges two faces run the same way", thousands(t.edges_used_twice_one_way))
                }
            );
        } else if let Some(s) = &p.stream {
            let _ = writeln!(
                text,
                "{what}: stream of codec {}, format version {}, {} levels in {} bytes: {} vertices, {} triangles; fallback level {} ({} triangles)",
                s.codec,
                s.format_version,
                s.levels,
                thousands(s.bytes as usize),
                thousands(s.vertices as usize),
                thousands(s.triangles as usize),
                s.fallback_level,
                thousands(s.fallback_triangles as usize)
            );
        } else if let Some(why) = &p.kept {
            let _ = writeln!(text, "{what}: not coded by `pack`: {why}");
        }
    }
    meshcodec_lab::cli::write_stdout(&text)?;
    Ok(())
}
