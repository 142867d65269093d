//! glTF 2.0 (`.gltf` and `.glb`) through the `gltf` crate: indexed triangle primitives with
//! POSITION, NORMAL, TEXCOORD_0, COLOR_0 and their materials.
//!
//! glTF splits a vertex wherever an attribute jumps (a uv seam is two vertices at one place).
//! Reading welds vertices at exactly one position back into one mesh vertex, and their
//! attributes become wedges (`mesh::attributes`), so a seam cannot open when the mesh
//! coarsens; every node's mesh is placed by its world transform (normals by its inverse
//! transpose). Writing splits again: one glTF vertex a wedge, one primitive a run of faces of
//! one material, all sharing one vertex buffer, in a `.glb` or a `.gltf` with the buffer
//! embedded. Buffers come from the GLB's binary chunk, from `data:` URIs, or — reading a
//! `.gltf` file — from files beside it. Images are not read: a mesh codec has no use for them.

use crate::error::{Error, Result};
use crate::mesh::attributes::{AttributedMesh, Attributes, Corner, Materials};
use crate::mesh::TriMesh;
use base64::Engine as _;
use glam::{DMat3, DMat4, DVec2, DVec3};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

fn fault(what: impl std::fmt::Display) -> Error {
    Error::mesh(format!("glTF: {what}"))
}

/// Reads glTF from `bytes`; `dir` is where a `.gltf` file's external buffers lie (none for
/// bytes alone: only embedded buffers then).
pub fn read_attributed(bytes: &[u8], dir: Option<&Path>) -> Result<AttributedMesh> {
    check_before_the_crate(bytes)?;
    let gltf = gltf::Gltf::from_slice(bytes).map_err(fault)?;
    let mut buffers = Vec::new();
    for buffer in gltf.document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf
                .blob
                .clone()
                .ok_or_else(|| fault("a buffer refers to a binary chunk the file lacks"))?,
            gltf::buffer::Source::Uri(uri) => crate::mesh::scene::load_uri(uri, dir)?,
        };
        if data.len() < buffer.length() {
            return Err(Error::Truncated(format!(
                "glTF buffer {} holds {} of its {} bytes",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    let mut reading = Reading::default();
    let document = &gltf.document;
    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            for node in scene.nodes() {
                reading.node(&node, DMat4::IDENTITY, &buffers, 0)?;
            }
        }
        // No scene: every mesh where it stands.
        None => {
            for mesh in document.meshes() {
                reading.mesh(&mesh, DMat4::IDENTITY, &buffers)?;
            }
        }
    }
    reading.finish(document)
}

/// What the `gltf` crate (1.4) does not survive, refused before it reads the file
/// (fuzz/regressions/read_gltf): a GLB header whose length is less than the header itself (the
/// crate subtracts unchecked); a primitive naming an accessor past the list (gltf-json checks a
/// primitive's POSITION bounds by indexing the list unchecked); and an accessor whose component
/// type or shape does not fit the attribute it holds (the crate's readers reach `unreachable!`).
/// Anything else malformed is left to the crate.
fn check_before_the_crate(bytes: &[u8]) -> Result<()> {
    if let Some(length) = bytes.get(8..12).filter(|_| bytes.starts_with(b"glTF")) {
        let length = u32::from_le_bytes(length.try_into().expect("four bytes"));
        if length < 12 {
            return Err(fault(format!(
                "a GLB header giving a length of {length} bytes"
            )));
        }
    }
    let json: std::borrow::Cow<[u8]> = if bytes.starts_with(b"glTF") {
        match gltf::binary::Glb::from_slice(bytes) {
            Ok(glb) => glb.json,
            Err(e) => return Err(fault(e)),
        }
    } else {
        std::borrow::Cow::Borrowed(bytes)
    };
    // Lossily: serde skips the bytes of keys it ignores without checking that they are UTF-8,
    // so the crate reads documents a strict parse would refuse.
    let text = String::from_utf8_lossy(&json);
    let Ok(root) = serde_json::from_str::<serde_json::Value>(&text) else {
        return Ok(()); // the crate says what is wrong with it
    };
    let accessors = root["accessors"]
        .as_array()
        .map(Vec::as_slice)
        .unwrap_or_default();
    const BYTE: u64 = 5121;
    const SHORT: u64 = 5123;
    const INT: u64 = 5125;
    const FLOAT: u64 = 5126;
    // (component types, shapes) an attribute may have, for those this reader reads.
    let fits = |semantic: &str| -> Option<(&[u64], &[&str])> {
        Some(match semantic {
            "POSITION" | "NORMAL" => (&[FLOAT], &["VEC3"]),
            "TEXCOORD_0" => (&[BYTE, SHORT, FLOAT], &["VEC2"]),
            "COLOR_0" => (&[BYTE, SHORT, FLOAT], &["VEC3", "VEC4"]),
            "indices" => (&[BYTE, SHORT, INT], &["SCALAR"]),
            _ => return None,
        })
    };
    let primitives = root["meshes"]
        .as_array()
        .into_iter()
        .flatten()
        .flat_map(|m| m["primitives"].as_array().into_iter().flatten());
    for primitive in primitives {
        let named = primitive["attributes"]
            .as_object()
            .into_iter()
            .flatten()
            .map(|(k, v)| (k.as_str(), v))
            .chain(std::iter::once(("indices", &primitive["indices"])))
            .chain(
                primitive["targets"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .filter_map(|t| t.as_object())
                    .flatten()
                    .map(|(_, v)| ("target", v)),
            );
        for (semantic, index) in named {
            let Some(i) = index.as_u64() else {
                continue; // absent, or not an index: the crate refuses the latter
            };
            let Some(accessor) = accessors.get(i as usize) else {
                return Err(fault(format!(
                    "a primitive names accessor {i} of {}",
                    accessors.len()
                )));
            };
            if let Some((components, shapes)) = fits(semantic) {
                let component = accessor["componentType"].as_u64().unwrap_or(0);
                let shape = accessor["type"].as_str().unwrap_or("");
                if !components.contains(&component) || !shapes.contains(&shape) {
                    return Err(fault(format!(
                        "{semantic} in accessor {i} of component type {component} and type '{shape}'"
                    )));
                }
            }
        }
    }
    Ok(())
}

/// The mesh as it is read: positions welded by exact place, faces with their corners'
/// attributes and materials.
#[derive(Default)]
struct Reading {
    positions: Vec<DVec3>,
    by_position: HashMap<[u64; 3], u32>,
    faces: Vec<[u32; 3]>,
    corners: Vec<[Corner; 3]>,
    /// Material index (in the document) of each face; `None` for the default material.
    materials: Vec<Option<usize>>,
}

/// Node nesting beyond which a file is refused (the scene graph is a tree, but a file can lie).
const MAX_DEPTH: usize = 64;

impl Reading {
    fn node(
        &mut self,
        node: &gltf::Node,
        parent: DMat4,
        buffers: &[Vec<u8>],
        depth: usize,
    ) -> Result<()> {
        if depth > MAX_DEPTH {
            return Err(fault("nodes nested deeper than 64 (a cycle?)"));
        }
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let world = parent * DMat4::from_cols_array_2d(&local);
        if let Some(mesh) = node.mesh() {
            self.mesh(&mesh, world, buffers)?;
        }
        for child in node.children() {
            self.node(&child, world, buffers, depth + 1)?;
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh, world: DMat4, buffers: &[Vec<u8>]) -> Result<()> {
        let normal_matrix = DMat3::from_mat4(world).inverse().transpose();
        for primitive in mesh.primitives() {
            if primitive.mode() != Mode::Triangles {
                return Err(Error::Unsupported(format!(
                    "glTF primitive mode {:?} (triangles only)",
                    primitive.mode()
                )));
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let points: Vec<DVec3> = reader
                .read_positions()
                .ok_or_else(|| fault("a primitive without POSITION"))?
                .map(|p| world.transform_point3(DVec3::from(p.map(f64::from))))
                .collect();
            let n = points.len();
            let normals: Option<Vec<DVec3>> = reader.read_normals().map(|it| {
                it.map(|v| normal_matrix * DVec3::from(v.map(f64::from)))
                    .collect()
            });
            let uvs: Option<Vec<DVec2>> = reader.read_tex_coords(0).map(|it| {
                it.into_f32()
                    .map(|t| DVec2::from(t.map(f64::from)))
                    .collect()
            });
            let colours: Option<Vec<[f64; 4]>> = reader
                .read_colors(0)
                .map(|it| it.into_rgba_f32().map(|c| c.map(f64::from)).collect());
            for (what, len) in [
                ("NORMAL", normals.as_ref().map(Vec::len)),
                ("TEXCOORD_0", uvs.as_ref().map(Vec::len)),
                ("COLOR_0", colours.as_ref().map(Vec::len)),
            ] {
                if len.is_some_and(|l| l != n) {
                    return Err(fault(format!("{what} has another count than POSITION")));
                }
            }
            let local: Vec<u32> = points
                .iter()
                .map(|&p| {
                    let key = p.to_array().map(|x| (x + 0.0).to_bits());
                    *self.by_position.entry(key).or_insert_with(|| {
                        self.positions.push(p);
                        (self.positions.len() - 1) as u32
                    })
                })
                .collect();
            let indices: Vec<u32> = match reader.read_indices() {
                Some(it) => it.into_u32().collect(),
                None => (0..n as u32).collect(),
            };
            if !indices.len().is_multiple_of(3) {
                return Err(fault("a triangle list whose length is no multiple of 3"));
            }
            let material = primitive.material().index();
            for tri in indices.chunks_exact(3) {
                let mut face = [0u32; 3];
                let mut corner = [Corner::default(); 3];
                for k in 0..3 {
                    let i = tri[k] as usize;
                    if i >= n {
                        return Err(fault(format!("index {i} out of range ({n} vertices)")));
                    }
                    face[k] = local[i];
                    corner[k] = Corner {
                        normal: normals.as_ref().map(|v| v[i]),
                        uv: uvs.as_ref().map(|v| v[i]),
                        colour: colours.as_ref().map(|v| v[i]),
                    };
                }
                self.faces.push(face);
                self.corners.push(corner);
                self.materials.push(material);
            }
        }
        Ok(())
    }

    fn finish(self, document: &gltf::Document) -> Result<AttributedMesh> {
        let mesh = TriMesh::new(self.positions, self.faces);
        let mut attributes = Attributes::weld(&mesh.faces, &self.corners)?;
        if document.materials().next().is_some() {
            // Ids in order of first use; the default material (none named) is "".
            let mut ids: HashMap<Option<usize>, u32> = HashMap::new();
            let mut names = Vec::new();
            let mut face = Vec::with_capacity(self.materials.len());
            for m in &self.materials {
                let next = names.len() as u32;
                let id = *ids.entry(*m).or_insert_with(|| {
                    let name = m
                        .and_then(|i| document.materials().nth(i))
                        .and_then(|mat| mat.name().map(str::to_string))
                        .unwrap_or_else(|| m.map(|i| format!("material{i}")).unwrap_or_default());
                    names.push(name);
                    next
                });
                face.push(id);
            }
            attributes.materials = Some(Materials {
                face,
                names,
                library: None,
            });
        }
        attributes.validate(&mesh)?;
        Ok(AttributedMesh { mesh, attributes })
    }
}

/// Writes glTF 2.0: binary (`.glb`) when `binary`, else JSON with the buffer embedded.
pub fn write_attributed(m: &AttributedMesh, binary: bool) -> Result<Vec<u8>> {
    let (mesh, a) = (&m.mesh, &m.attributes);
    // The glTF vertices: one a wedge, or one a mesh vertex when there are no wedges.
    let wedges = !a.wedge_vertex.is_empty();
    let vertex_of: Vec<u32> = if wedges {
        a.wedge_vertex.clone()
    } else {
        (0..mesh.positions.len() as u32).collect()
    };
    let corner_vertex = |f: usize, k: usize| {
        if wedges {
            a.corners[f][k]
        } else {
            mesh.faces[f][k]
        }
    };
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    // Appends one accessor's data as its own buffer view, 4-byte aligned.
    let mut push = |bin: &mut Vec<u8>,
                    data: Vec<u8>,
                    count: usize,
                    kind: &str,
                    component: u32,
                    target: u32,
                    bounds: Option<(Vec<f64>, Vec<f64>)>| {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(serde_json::json!({
            "buffer": 0, "byteOffset": bin.len(), "byteLength": data.len(), "target": target
        }));
        bin.extend_from_slice(&data);
        let mut accessor = serde_json::json!({
            "bufferView": views.len() - 1, "componentType": component, "count": count, "type": kind
        });
        if let Some((min, max)) = bounds {
            accessor["min"] = serde_json::json!(min);
            accessor["max"] = serde_json::json!(max);
        }
        accessors.push(accessor);
        accessors.len() - 1
    };
    const FLOAT: u32 = 5126;
    const UINT: u32 = 5125;
    const ARRAY: u32 = 34962;
    const ELEMENTS: u32 = 34963;
    let floats = |values: &mut dyn Iterator<Item = f64>| -> Vec<u8> {
        values.flat_map(|x| (x as f32).to_le_bytes()).collect()
    };
    let points: Vec<DVec3> = vertex_of
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    // glTF stores 32-bit floats: a value beyond their range would become infinite.
    let beyond_f32 = |what: &str, values: &mut dyn Iterator<Item = f64>| -> Result<()> {
        let mut outside = values.filter(|x| !(*x as f32).is_finite());
        match outside.next() {
            Some(x) => Err(Error::Unsupported(format!(
                "glTF holds 32-bit floats; a {what} coordinate {x:e} is beyond their range"
            ))),
            None => Ok(()),
        }
    };
    beyond_f32("position", &mut points.iter().flat_map(|p| p.to_array()))?;
    if let Some(normals) = &a.normals {
        beyond_f32("normal", &mut normals.iter().flat_map(|n| n.to_array()))?;
    }
    if let Some(uvs) = &a.uvs {
        beyond_f32("texture", &mut uvs.iter().flat_map(|t| t.to_array()))?;
    }
    if let Some(colours) = &a.colours {
        beyond_f32("colour", &mut colours.iter().flatten().copied())?;
    }
    let (mut min, mut max) = (vec![f64::INFINITY; 3], vec![f64::NEG_INFINITY; 3]);
    for p in &points {
        for (axis, x) in p.to_array().into_iter().enumerate() {
            let x = x as f32 as f64;
            min[axis] = min[axis].min(x);
            max[axis] = max[axis].max(x);
        }
    }
    let mut attributes = serde_json::Map::new();
    let count = points.len();
    let position = push(
        &mut bin,
        floats(&mut points.iter().flat_map(|p| p.to_array())),
        count,
        "VEC3",
        FLOAT,
        ARRAY,
        Some((min, max)),
    );
    attributes.insert("POSITION".into(), position.into());
    if let Some(normals) = &a.normals {
        let data = floats(&mut normals.iter().flat_map(|n| n.to_array()));
        let i = push(&mut bin, data, count, "VEC3", FLOAT, ARRAY, None);
        attributes.insert("NORMAL".into(), i.into());
    }
    if let Some(uvs) = &a.uvs {
        let data = floats(&mut uvs.iter().flat_map(|t| t.to_array()));
        let i = push(&mut bin, data, count, "VEC2", FLOAT, ARRAY, None);
        attributes.insert("TEXCOORD_0".into(), i.into());
    }
    if let Some(colours) = &a.colours {
        let data = floats(&mut colours.iter().flatten().copied());
        let i = push(&mut bin, data, count, "VEC4", FLOAT, ARRAY, None);
        attributes.insert("COLOR_0".into(), i.into());
    }
    // One primitive a run of faces of one material, so the faces keep their order.
    let material_of = |f: usize| a.materials.as_ref().map(|m| m.face[f]);
    let mut primitives = Vec::new();
    let mut f = 0;
    while f < mesh.faces.len() {
        let material = material_of(f);
        let start = f;
        while f < mesh.faces.len() && material_of(f) == material {
            f += 1;
        }
        let indices: Vec<u8> = (start..f)
            .flat_map(|g| (0..3).map(move |k| (g, k)))
            .flat_map(|(g, k)| corner_vertex(g, k).to_le_bytes())
            .collect();
        let i = push(
            &mut bin,
            indices,
            3 * (f - start),
            "SCALAR",
            UINT,
            ELEMENTS,
            None,
        );
        let mut primitive =
            serde_json::json!({ "attributes": attributes, "indices": i, "mode": 4 });
        if let Some(id) = material {
            primitive["material"] = id.into();
        }
        primitives.push(primitive);
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut root = serde_json::json!({
        "asset": { "version": "2.0", "generator": "meshcodec" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": primitives }],
        "accessors": accessors,
        "bufferViews": views,
    });
    if let Some(m) = &a.materials {
        root["materials"] = m
            .names
            .iter()
            .map(|name| serde_json::json!({ "name": name }))
            .collect();
    }
    let buffer = if binary {
        serde_json::json!({ "byteLength": bin.len() })
    } else {
        let data = base64::engine::general_purpose::STANDARD.encode(&bin);
        serde_json::json!({
            "byteLength": bin.len(),
            "uri": format!("data:application/octet-stream;base64,{data}")
        })
    };
    root["buffers"] = serde_json::json!([buffer]);
    let json = serde_json::to_vec(&root).map_err(fault)?;
    if !binary {
        return Ok(json);
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0, // set by to_vec
        },
        json: std::borrow::Cow::Owned(json),
        bin: Some(std::borrow::Cow::Owned(bin)),
    };
    glb.to_vec().map_err(fault)
}
