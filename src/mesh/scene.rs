//! A glTF scene as the codecs see it: the document kept whole (nodes, meshes, materials,
//! textures, images, cameras, animations, skins, extras, extensions), every buffer's bytes,
//! and each mesh primitive read once — a triangle primitive as a mesh with its appearance
//! (Hoppe's wedges: the vertices glTF split at seams welded back, `mesh::attributes`) in the
//! primitive's own coordinates, or the reason it is kept as it is.
//!
//! Accessors are read here rather than by the `gltf` crate, whose readers take only the
//! component types the core specification allows each attribute: files written by gltfpack or
//! `gltf-transform quantize` (KHR_mesh_quantization) store positions, normals and uvs as
//! normalized or plain integers. Every index a document names is checked before it is followed,
//! and an accessor's bytes against its buffer view and buffer.

use crate::error::{Error, Result};
use crate::mesh::attributes::{AttributedMesh, Attributes, Corner};
use crate::mesh::meshopt_views;
use crate::mesh::TriMesh;
use base64::Engine as _;
use glam::{DVec2, DVec3};
use gltf_json::accessor::ComponentType;
use gltf_json::mesh::{Mode, Semantic};
use gltf_json::validation::Checked;
use std::collections::HashMap;
use std::path::Path;

/// A glTF document and what it holds, read once.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The document as read: every object, extension and extra.
    pub document: gltf_json::Root,
    /// Each buffer's bytes (the GLB's binary chunk, a `data:` URI or a file beside a `.gltf`).
    pub buffers: Vec<Vec<u8>>,
    /// Each image's bytes and type, for images stored by URI (a GLB writer embeds them);
    /// `None` for images already in a buffer view.
    pub image_files: Vec<Option<(Vec<u8>, String)>>,
    /// Every primitive of every mesh, in order.
    pub primitives: Vec<ScenePrimitive>,
}

/// One primitive of one mesh.
#[derive(Clone, Debug)]
pub struct ScenePrimitive {
    /// Its mesh, in the document's list.
    pub mesh: usize,
    /// Its place in the mesh's primitives.
    pub primitive: usize,
    /// What it holds.
    pub content: Content,
}

/// What a primitive holds, for a mesh codec.
#[derive(Clone, Debug)]
pub enum Content {
    /// Indexed triangles with their appearance, in the primitive's coordinates: POSITION, and
    /// NORMAL, TEXCOORD_0 and COLOR_0 where it has them.
    Triangles(Box<AttributedMesh>),
    /// Kept as it is, and why: points or lines, skinned or morphed, an attribute the codecs do
    /// not carry.
    Kept(String),
}

impl Content {
    /// The triangles, when the primitive is one a codec takes.
    pub fn triangles(&self) -> Option<&AttributedMesh> {
        match self {
            Content::Triangles(m) => Some(m),
            Content::Kept(_) => None,
        }
    }
}

fn fault(what: impl std::fmt::Display) -> Error {
    Error::mesh(format!("glTF: {what}"))
}

/// The extension that compresses primitives with Draco; scenes using it are refused.
pub const DRACO_EXTENSION: &str = "KHR_draco_mesh_compression";

/// The attributes the codecs carry; a primitive with any other (but those a loader derives)
/// is kept as it is.
const CARRIED: [&str; 4] = ["POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0"];

impl Scene {
    /// Reads a scene from a file: a `.gltf` (its buffers and images beside it) or `.glb` as
    /// it is, any other mesh file the readers take as a scene of one mesh named after it
    /// ([`Scene::from_mesh`]).
    pub fn open(path: &Path) -> Result<Scene> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        if ext == "gltf" || ext == "glb" {
            let bytes = std::fs::read(path)?;
            return Scene::read(&bytes, path.parent());
        }
        let mesh = crate::mesh::io::read_attributed(path)?;
        let name = path
            .file_stem()
            .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
        Scene::from_mesh(mesh, &name)
    }

    /// Reads a `.gltf` or `.glb` from `bytes`; `dir` is where a `.gltf`'s buffers and images
    /// lie (none: only those embedded are found).
    pub fn read(bytes: &[u8], dir: Option<&Path>) -> Result<Scene> {
        let (json, bin) = if bytes.starts_with(b"glTF") {
            if let Some(length) = bytes.get(8..12) {
                if u32::from_le_bytes(length.try_into().expect("four bytes")) < 12 {
                    return Err(fault("a GLB header giving a length under 12 bytes"));
                }
            }
            let glb = gltf::binary::Glb::from_slice(bytes).map_err(fault)?;
            (glb.json.into_owned(), glb.bin.map(|b| b.into_owned()))
        } else {
            (bytes.to_vec(), None)
        };
        let mut document: gltf_json::Root = serde_json::from_slice(&json).map_err(fault)?;
        if document
            .extensions_used
            .iter()
            .any(|e| e == DRACO_EXTENSION)
        {
            return Err(Error::Unsupported(format!(
                "the scene's meshes are compressed with {DRACO_EXTENSION}; decode them first (e.g. `npx @gltf-transform/cli copy IN OUT.glb`, which writes them plain)"
            )));
        }
        let mut buffers = Vec::with_capacity(document.buffers.len());
        for (i, buffer) in document.buffers.iter().enumerate() {
            if meshopt_views::is_fallback(buffer) {
                // Stands in for compressed views' bytes, which are decoded below.
                buffers.push(Vec::new());
                continue;
            }
            let data = match &buffer.uri {
                None => bin.clone().ok_or_else(|| {
                    fault(format!(
                        "buffer {i} refers to a binary chunk the file lacks"
                    ))
                })?,
                Some(uri) => load_uri(uri, dir)?,
            };
            if (data.len() as u64) < buffer.byte_length.0 {
                return Err(Error::Truncated(format!(
                    "glTF buffer {i} holds {} of its {} bytes",
                    data.len(),
                    buffer.byte_length.0
                )));
            }
            buffers.push(data);
        }
        meshopt_views::decode_views(&mut document, &mut buffers)?;
        let mut image_files = Vec::with_capacity(document.images.len());
        for image in &document.images {
            image_files.push(match (&image.uri, &image.buffer_view) {
                (Some(uri), None) => {
                    let mime = image
                        .mime_type
                        .as_ref()
                        .map(|m| m.0.clone())
                        .unwrap_or_else(|| mime_of(uri).to_string());
                    Some((load_uri(uri, dir)?, mime))
                }
                _ => None,
            });
        }
        let mut scene = Scene {
            document,
            buffers,
            image_files,
            primitives: Vec::new(),
        };
        let skinned = scene.skinned_meshes();
        for (m, mesh) in scene.document.meshes.iter().enumerate() {
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                let content = match kept_because(primitive, skinned.contains(&m)) {
                    Some(why) => Content::Kept(why),
                    None => Content::Triangles(Box::new(scene.triangles(primitive)?)),
                };
                scene.primitives.push(ScenePrimitive {
                    mesh: m,
                    primitive: p,
                    content,
                });
            }
        }
        Ok(scene)
    }

    /// A mesh file that is not glTF as a scene: one node, one mesh named `name`, one
    /// primitive a material (faces of one material each, the material named as the file
    /// names it) or one for the whole mesh.
    pub fn from_mesh(mesh: AttributedMesh, name: &str) -> Result<Scene> {
        let mut document = gltf_json::Root {
            asset: gltf_json::Asset {
                generator: Some("meshcodec".into()),
                ..Default::default()
            },
            ..Default::default()
        };
        let groups: Vec<(Option<String>, Vec<usize>)> = match &mesh.attributes.materials {
            Some(m) => (0..m.names.len())
                .map(|id| {
                    let faces = (0..m.face.len())
                        .filter(|&f| m.face[f] as usize == id)
                        .collect();
                    (Some(m.names[id].clone()), faces)
                })
                .filter(|(_, faces): &(_, Vec<usize>)| !faces.is_empty())
                .collect(),
            None => vec![(None, (0..mesh.mesh.faces.len()).collect())],
        };
        let mut primitives = Vec::new();
        let mut gltf_primitives = Vec::new();
        for (p, (material, faces)) in groups.into_iter().enumerate() {
            let material = material.map(|name| {
                document.materials.push(gltf_json::Material {
                    name: Some(name),
                    ..Default::default()
                });
                gltf_json::Index::new(document.materials.len() as u32 - 1)
            });
            gltf_primitives.push(gltf_json::mesh::Primitive {
                attributes: Default::default(),
                extensions: None,
                extras: Default::default(),
                indices: None,
                material,
                mode: Checked::Valid(Mode::Triangles),
                targets: None,
            });
            primitives.push(ScenePrimitive {
                mesh: 0,
                primitive: p,
                content: Content::Triangles(Box::new(faces_of(&mesh, &faces)?)),
            });
        }
        document.meshes.push(gltf_json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(name.to_string()),
            primitives: gltf_primitives,
            weights: None,
        });
        document.nodes.push(gltf_json::Node {
            mesh: Some(gltf_json::Index::new(0)),
            name: Some(name.to_string()),
            ..Default::default()
        });
        document.scenes.push(gltf_json::Scene {
            extensions: None,
            extras: Default::default(),
            name: None,
            nodes: vec![gltf_json::Index::new(0)],
        });
        document.scene = Some(gltf_json::Index::new(0));
        Ok(Scene {
            document,
            buffers: Vec::new(),
            image_files: Vec::new(),
            primitives,
        })
    }

    /// The meshes that a skinned node draws.
    fn skinned_meshes(&self) -> Vec<usize> {
        self.document
            .nodes
            .iter()
            .filter(|n| n.skin.is_some())
            .filter_map(|n| n.mesh.map(|m| m.value()))
            .collect()
    }

    /// An accessor's elements as f64 components (normalized integers as the specification
    /// maps them), `components` a element; refused past its view or buffer.
    pub fn accessor(&self, index: usize) -> Result<(Vec<f64>, usize)> {
        let accessor = self.document.accessors.get(index).ok_or_else(|| {
            fault(format!(
                "accessor {index} of {}",
                self.document.accessors.len()
            ))
        })?;
        if accessor.sparse.is_some() {
            return Err(Error::Unsupported(format!(
                "glTF accessor {index} is sparse (the codecs read dense accessors)"
            )));
        }
        let components = match accessor.type_ {
            Checked::Valid(t) => t.multiplicity(),
            Checked::Invalid => return Err(fault(format!("accessor {index}'s type"))),
        };
        let component = match accessor.component_type {
            Checked::Valid(t) => t.0,
            Checked::Invalid => return Err(fault(format!("accessor {index}'s component type"))),
        };
        let size = component.size();
        let count = accessor.count.0 as usize;
        let Some(view_index) = accessor.buffer_view else {
            // No view: zeros (glTF 2.0 §5.1.1).
            return Ok((
                vec![0.0; count.saturating_mul(components).min(1 << 28)],
                components,
            ));
        };
        let view = self
            .document
            .buffer_views
            .get(view_index.value())
            .ok_or_else(|| {
                fault(format!(
                    "accessor {index} names buffer view {}",
                    view_index.value()
                ))
            })?;
        let buffer = self.buffers.get(view.buffer.value()).ok_or_else(|| {
            fault(format!(
                "buffer view {} names buffer {}",
                view_index.value(),
                view.buffer.value()
            ))
        })?;
        let view_start = view.byte_offset.map_or(0, |o| o.0) as usize;
        let view_end = view_start.checked_add(view.byte_length.0 as usize);
        let view_bytes = view_end
            .and_then(|end| buffer.get(view_start..end))
            .ok_or_else(|| {
                fault(format!(
                    "buffer view {} runs past its buffer",
                    view_index.value()
                ))
            })?;
        let element = size * components;
        let stride = view.byte_stride.map_or(element, |s| s.0);
        let offset = accessor.byte_offset.map_or(0, |o| o.0) as usize;
        let needed = if count == 0 {
            Some(0)
        } else {
            (count - 1)
                .checked_mul(stride)
                .and_then(|x| x.checked_add(offset))
                .and_then(|x| x.checked_add(element))
        };
        if stride < element || needed.is_none_or(|n| n > view_bytes.len()) {
            return Err(fault(format!(
                "accessor {index} ({count} × {element} bytes, stride {stride}) runs past its buffer view"
            )));
        }
        let mut out = Vec::with_capacity(count * components);
        for e in 0..count {
            let at = offset + e * stride;
            for c in 0..components {
                let b = &view_bytes[at + c * size..at + (c + 1) * size];
                out.push(read_component(component, accessor.normalized, b));
            }
        }
        Ok((out, components))
    }

    /// A triangle primitive as a mesh with its appearance.
    fn triangles(&self, primitive: &gltf_json::mesh::Primitive) -> Result<AttributedMesh> {
        let attribute = |name: &str| {
            primitive.attributes.iter().find_map(|(s, i)| match s {
                Checked::Valid(s) if semantic_name(s) == name => Some(i.value()),
                _ => None,
            })
        };
        let position =
            attribute("POSITION").ok_or_else(|| fault("a primitive without POSITION"))?;
        let (points, k) = self.accessor(position)?;
        if k != 3 {
            return Err(fault("POSITION is not of three components"));
        }
        let n = points.len() / 3;
        let points: Vec<DVec3> = points
            .chunks_exact(3)
            .map(|p| DVec3::new(p[0], p[1], p[2]))
            .collect();
        if points.iter().any(|p| !p.is_finite()) {
            return Err(fault("a POSITION that is not finite"));
        }
        let read = |name: &str, width: &[usize]| -> Result<Option<(Vec<f64>, usize)>> {
            let Some(i) = attribute(name) else {
                return Ok(None);
            };
            let (values, k) = self.accessor(i)?;
            if !width.contains(&k) {
                return Err(fault(format!("{name} with {k} components")));
            }
            if values.len() / k != n {
                return Err(fault(format!("{name} has another count than POSITION")));
            }
            Ok(Some((values, k)))
        };
        let normals = read("NORMAL", &[3])?;
        let uvs = read("TEXCOORD_0", &[2])?;
        let colours = read("COLOR_0", &[3, 4])?;
        let indices: Vec<u32> = match primitive.indices {
            Some(i) => {
                let (values, k) = self.accessor(i.value())?;
                if k != 1 {
                    return Err(fault("indices are not scalars"));
                }
                values.iter().map(|&x| x as u32).collect()
            }
            None => (0..n as u32).collect(),
        };
        if !indices.len().is_multiple_of(3) {
            return Err(fault("a triangle list whose length is no multiple of 3"));
        }
        // Vertices welded by exact position: glTF split them wherever an attribute jumps.
        let mut positions = Vec::new();
        let mut by_position: HashMap<[u64; 3], u32> = HashMap::new();
        let welded: Vec<u32> = points
            .iter()
            .map(|&p| {
                let key = p.to_array().map(|x| (x + 0.0).to_bits());
                *by_position.entry(key).or_insert_with(|| {
                    positions.push(p);
                    (positions.len() - 1) as u32
                })
            })
            .collect();
        let mut faces = Vec::with_capacity(indices.len() / 3);
        let mut corners = Vec::with_capacity(indices.len() / 3);
        for tri in indices.chunks_exact(3) {
            let mut face = [0u32; 3];
            let mut corner = [Corner::default(); 3];
            for k in 0..3 {
                let i = tri[k] as usize;
                if i >= n {
                    return Err(fault(format!("index {i} out of range ({n} vertices)")));
                }
                face[k] = welded[i];
                corner[k] = Corner {
                    normal: normals
                        .as_ref()
                        .map(|(v, _)| DVec3::new(v[3 * i], v[3 * i + 1], v[3 * i + 2])),
                    uv: uvs
                        .as_ref()
                        .map(|(v, _)| DVec2::new(v[2 * i], v[2 * i + 1])),
                    colour: colours.as_ref().map(|(v, k)| {
                        let c = &v[k * i..k * i + k];
                        [c[0], c[1], c[2], if *k == 4 { c[3] } else { 1.0 }]
                    }),
                };
            }
            faces.push(face);
            corners.push(corner);
        }
        let mesh = TriMesh::new(positions, faces);
        let attributes = Attributes::weld(&mesh.faces, &corners)?;
        attributes.validate(&mesh)?;
        Ok(AttributedMesh { mesh, attributes })
    }
}

/// The faces `faces` of `mesh`, with their corners' appearance (materials dropped: the part is
/// one material), over the vertices they use.
fn faces_of(mesh: &AttributedMesh, faces: &[usize]) -> Result<AttributedMesh> {
    let mut vertex_map: HashMap<u32, u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut out_faces = Vec::with_capacity(faces.len());
    let mut corners = Vec::with_capacity(faces.len());
    let a = &mesh.attributes;
    for &f in faces {
        let face = mesh.mesh.faces[f].map(|v| {
            *vertex_map.entry(v).or_insert_with(|| {
                positions.push(mesh.mesh.positions[v as usize]);
                (positions.len() - 1) as u32
            })
        });
        out_faces.push(face);
        corners.push(std::array::from_fn(|k| a.corner(f, k)));
    }
    let part = TriMesh::new(positions, out_faces);
    let attributes = if a.normals.is_some() || a.uvs.is_some() || a.colours.is_some() {
        Attributes::weld(&part.faces, &corners)?
    } else {
        Attributes::default()
    };
    Ok(AttributedMesh {
        mesh: part,
        attributes,
    })
}

/// Why a primitive is kept as it is, or `None` for triangles a codec takes.
fn kept_because(primitive: &gltf_json::mesh::Primitive, skinned: bool) -> Option<String> {
    match primitive.mode {
        Checked::Valid(Mode::Triangles) => {}
        Checked::Valid(mode) => return Some(format!("{mode:?} (the codecs take triangle lists)")),
        Checked::Invalid => return Some("a mode this reader does not know".into()),
    }
    if skinned {
        return Some("skinned (a skin's joints follow its vertices)".into());
    }
    if primitive.targets.as_ref().is_some_and(|t| !t.is_empty()) {
        return Some("morph targets (they follow its vertices)".into());
    }
    if primitive
        .extensions
        .as_ref()
        .is_some_and(|e| !e.others.is_empty())
    {
        let names: Vec<&str> = primitive
            .extensions
            .iter()
            .flat_map(|e| e.others.keys())
            .map(String::as_str)
            .collect();
        return Some(format!("extensions {names:?}"));
    }
    let other: Vec<String> = primitive
        .attributes
        .keys()
        .map(|s| match s {
            Checked::Valid(s) => semantic_name(s),
            Checked::Invalid => "an unknown attribute".into(),
        })
        .filter(|name| !CARRIED.contains(&name.as_str()))
        .collect();
    if !other.is_empty() {
        return Some(format!("attributes {other:?} that the codecs do not carry"));
    }
    None
}

/// The name glTF gives an attribute.
pub fn semantic_name(semantic: &Semantic) -> String {
    match semantic {
        Semantic::Positions => "POSITION".into(),
        Semantic::Normals => "NORMAL".into(),
        Semantic::Tangents => "TANGENT".into(),
        Semantic::Colors(n) => format!("COLOR_{n}"),
        Semantic::TexCoords(n) => format!("TEXCOORD_{n}"),
        Semantic::Joints(n) => format!("JOINTS_{n}"),
        Semantic::Weights(n) => format!("WEIGHTS_{n}"),
        Semantic::Extras(name) => name.clone(),
    }
}

/// One component, as glTF 2.0 §3.11 maps normalized integers to [0, 1] or [−1, 1].
fn read_component(component: ComponentType, normalized: bool, b: &[u8]) -> f64 {
    let (value, scale) = match component {
        ComponentType::I8 => (b[0] as i8 as f64, 127.0),
        ComponentType::U8 => (b[0] as f64, 255.0),
        ComponentType::I16 => (i16::from_le_bytes([b[0], b[1]]) as f64, 32767.0),
        ComponentType::U16 => (u16::from_le_bytes([b[0], b[1]]) as f64, 65535.0),
        ComponentType::U32 => (u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64, 1.0),
        ComponentType::F32 => (f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64, 1.0),
    };
    if normalized && !matches!(component, ComponentType::F32 | ComponentType::U32) {
        (value / scale).max(-1.0)
    } else {
        value
    }
}

/// The type a file's name suggests for an image.
fn mime_of(uri: &str) -> &'static str {
    let lower = uri.to_ascii_lowercase();
    if lower.ends_with(".png") {
        "image/png"
    } else if lower.ends_with(".ktx2") {
        "image/ktx2"
    } else if lower.ends_with(".webp") {
        "image/webp"
    } else {
        "image/jpeg"
    }
}

/// The bytes a buffer's or image's URI names: a `data:` URI, or a file beside the document.
pub(crate) fn load_uri(uri: &str, dir: Option<&Path>) -> Result<Vec<u8>> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| fault("a data URI that is not base64"))?;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| fault(format!("a base64 buffer: {e}")));
    }
    let Some(dir) = dir else {
        return Err(Error::Unsupported(format!(
            "glTF file '{uri}' is a file of its own, and only the glTF's bytes were given"
        )));
    };
    let decoded = percent_decode(uri);
    if decoded.contains("://")
        || Path::new(&decoded).is_absolute()
        || decoded.split('/').any(|p| p == "..")
    {
        return Err(Error::Unsupported(format!(
            "glTF file '{uri}' is not a file beside the glTF"
        )));
    }
    std::fs::read(dir.join(&decoded))
        .map_err(|e| Error::Io(std::io::Error::new(e.kind(), format!("{uri}: {e}"))))
}

/// A URI's %XX escapes decoded (glTF URIs are RFC 3986: spaces come as %20).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            if let Some(v) = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
            {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}
