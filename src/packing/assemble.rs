//! A scene written back as one GLB with some primitives' data replaced: what no object names
//! any more is left out (the old accessors of a packed primitive, their buffer views and
//! bytes), the rest of the document is kept — its accessors and buffer views renumbered, every
//! reference the core specification defines to them followed — and images stored by URI are
//! embedded, their bytes untouched. The JSON is `gltf-json`'s; the container `gltf`'s.

use crate::error::{Error, Result};
use crate::mesh::scene::Scene;
use gltf_json::accessor::{ComponentType, GenericComponentType, Type};
use gltf_json::buffer::{Stride, Target};
use gltf_json::validation::{Checked, USize64};
use gltf_json::Index;
use std::collections::{BTreeMap, HashMap};

/// How an accessor stores its floats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// 32-bit floats.
    F32,
    /// Normalized unsigned shorts, for values in [0, 1] (uvs; core glTF).
    U16Norm,
    /// Normalized unsigned bytes, for values in [0, 1] (colours; core glTF).
    U8Norm,
    /// Normalized signed bytes, for values in [−1, 1], each element padded to four bytes
    /// (normals; `KHR_mesh_quantization`).
    I8Norm,
}

/// An accessor's new data.
#[derive(Clone, Debug)]
pub enum Data {
    /// Floats, `components` an element (positions carry their bounds, as glTF requires), stored
    /// as `storage` says.
    Float {
        values: Vec<f32>,
        components: usize,
        bounds: bool,
        storage: Storage,
    },
    /// Triangle indices (written as unsigned shorts when they fit).
    Indices(Vec<u32>),
    /// `count` elements of `components` floats and no buffer view (`--no-fallback`: a loader
    /// that reads the extension fills them), with the bounds glTF requires of POSITION.
    Empty {
        count: usize,
        components: usize,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    },
}

/// A primitive's new content: its attributes (by glTF name) and indices, and its
/// extensions (replacing the old).
#[derive(Clone, Debug, Default)]
pub struct Replacement {
    /// Attribute name and data.
    pub attributes: Vec<(String, Data)>,
    /// Indices, when the primitive has them.
    pub indices: Option<Data>,
    /// The primitive's extensions object (`None`: none).
    pub extensions: Option<serde_json::Map<String, serde_json::Value>>,
    /// The stream to store for it, whose buffer view the extension `name` takes as its
    /// `bufferView`.
    pub stream: Option<(Vec<u8>, &'static str)>,
}

/// Where the streams go.
#[derive(Clone, Debug)]
pub enum Streams {
    /// In the GLB's binary chunk.
    Embedded,
    /// In a buffer of their own, a file named by this URI beside the GLB; its bytes returned.
    External(String),
}

/// Extensions known to name no accessor and no buffer view (materials, textures, lights,
/// quantized attributes), and this crate's own, which `pack` refuses and `unpack` removes.
fn names_no_accessor(name: &str) -> bool {
    name.starts_with("KHR_materials_")
        || name.starts_with("KHR_texture_")
        || name.starts_with("EXT_texture_")
        || matches!(
            name,
            "KHR_lights_punctual" | "KHR_mesh_quantization" | super::extension::NAME
        )
}

/// Whether any object of `document` carries an extension that might name accessors or
/// buffer views (EXT_mesh_gpu_instancing's attributes, say), which the writer cannot renumber.
fn names_unknown_extensions(document: &gltf_json::Root) -> Result<bool> {
    fn walk(value: &serde_json::Value) -> bool {
        match value {
            serde_json::Value::Object(map) => map.iter().any(|(key, v)| {
                (key == "extensions"
                    && v.as_object()
                        .is_some_and(|e| e.keys().any(|name| !names_no_accessor(name))))
                    || walk(v)
            }),
            serde_json::Value::Array(items) => items.iter().any(walk),
            _ => false,
        }
    }
    let value = serde_json::to_value(document)
        .map_err(|e| Error::mesh(format!("glTF: the document does not serialize: {e}")))?;
    Ok(walk(&value))
}

/// The GLB of `scene` with `replacements` (by mesh and primitive), extension `used` added to
/// `extensionsUsed` (and `required`, when given, to `extensionsRequired`) and `removed` taken
/// from both; with external streams, also the streams' buffer.
pub fn write_glb(
    scene: &Scene,
    replacements: &HashMap<(usize, usize), Replacement>,
    used: &[&str],
    required: &[&str],
    removed: &[&str],
    streams: &Streams,
) -> Result<(Vec<u8>, Option<Vec<u8>>)> {
    let old = &scene.document;
    let mut doc = old.clone();
    // Accessors still named, by what names them; all of them, and every buffer view, when an
    // extension this writer does not know might name some.
    let keep_all = names_unknown_extensions(old)?;
    let mut accessor_used = vec![keep_all; old.accessors.len()];
    let mark = |i: usize, used: &mut Vec<bool>| -> Result<()> {
        *used.get_mut(i).ok_or_else(|| {
            Error::mesh(format!("glTF: accessor {i} of {}", old.accessors.len()))
        })? = true;
        Ok(())
    };
    for (m, mesh) in old.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if replacements.contains_key(&(m, p)) {
                continue;
            }
            for index in primitive.attributes.values() {
                mark(index.value(), &mut accessor_used)?;
            }
            if let Some(i) = primitive.indices {
                mark(i.value(), &mut accessor_used)?;
            }
            for target in primitive.targets.iter().flatten() {
                for i in [target.positions, target.normals, target.tangents]
                    .into_iter()
                    .flatten()
                {
                    mark(i.value(), &mut accessor_used)?;
                }
            }
        }
    }
    for skin in &old.skins {
        if let Some(i) = skin.inverse_bind_matrices {
            mark(i.value(), &mut accessor_used)?;
        }
    }
    for animation in &old.animations {
        for sampler in &animation.samplers {
            mark(sampler.input.value(), &mut accessor_used)?;
            mark(sampler.output.value(), &mut accessor_used)?;
        }
    }
    // Buffer views still named: by those accessors and by images.
    let mut view_used = vec![keep_all; old.buffer_views.len()];
    let mark_view = |i: usize, used: &mut Vec<bool>| -> Result<()> {
        *used.get_mut(i).ok_or_else(|| {
            Error::mesh(format!(
                "glTF: buffer view {i} of {}",
                old.buffer_views.len()
            ))
        })? = true;
        Ok(())
    };
    for (a, accessor) in old.accessors.iter().enumerate() {
        if !accessor_used[a] {
            continue;
        }
        if let Some(v) = accessor.buffer_view {
            mark_view(v.value(), &mut view_used)?;
        }
        if let Some(sparse) = &accessor.sparse {
            mark_view(sparse.indices.buffer_view.value(), &mut view_used)?;
            mark_view(sparse.values.buffer_view.value(), &mut view_used)?;
        }
    }
    for image in &old.images {
        if let Some(v) = image.buffer_view {
            mark_view(v.value(), &mut view_used)?;
        }
    }
    // The binary chunk: the kept views' bytes, then the images stored by URI, then the new
    // accessors and the streams.
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut view_map = vec![None; old.buffer_views.len()];
    for (v, view) in old.buffer_views.iter().enumerate() {
        if !view_used[v] {
            continue;
        }
        let bytes = view_bytes(scene, v)?;
        let mut kept = view.clone();
        kept.buffer = Index::new(0);
        kept.byte_offset = Some(USize64(append(&mut bin, bytes)));
        kept.byte_length = USize64(bytes.len() as u64);
        view_map[v] = Some(views.len() as u32);
        views.push(kept);
    }
    for (i, image) in doc.images.iter_mut().enumerate() {
        if let Some((bytes, mime)) = scene.image_files.get(i).and_then(|f| f.as_ref()) {
            let offset = append(&mut bin, bytes);
            views.push(view(0, offset, bytes.len(), None, None));
            image.uri = None;
            image.buffer_view = Some(Index::new(views.len() as u32 - 1));
            image.mime_type = Some(gltf_json::image::MimeType(mime.clone()));
        } else if let Some(v) = image.buffer_view {
            image.buffer_view = Some(Index::new(remap(&view_map, v.value())?));
        }
    }
    let mut accessors = Vec::new();
    let mut accessor_map = vec![None; old.accessors.len()];
    for (a, accessor) in old.accessors.iter().enumerate() {
        if !accessor_used[a] {
            continue;
        }
        let mut kept = accessor.clone();
        if let Some(v) = kept.buffer_view {
            kept.buffer_view = Some(Index::new(remap(&view_map, v.value())?));
        }
        if let Some(sparse) = kept.sparse.as_mut() {
            sparse.indices.buffer_view =
                Index::new(remap(&view_map, sparse.indices.buffer_view.value())?);
            sparse.values.buffer_view =
                Index::new(remap(&view_map, sparse.values.buffer_view.value())?);
        }
        accessor_map[a] = Some(accessors.len() as u32);
        accessors.push(kept);
    }
    let acc = |i: Index<gltf_json::Accessor>| -> Result<Index<gltf_json::Accessor>> {
        Ok(Index::new(remap(&accessor_map, i.value())?))
    };
    for skin in &mut doc.skins {
        if let Some(i) = skin.inverse_bind_matrices {
            skin.inverse_bind_matrices = Some(acc(i)?);
        }
    }
    for animation in &mut doc.animations {
        for sampler in &mut animation.samplers {
            sampler.input = acc(sampler.input)?;
            sampler.output = acc(sampler.output)?;
        }
    }
    let mut external = match streams {
        Streams::Embedded => None,
        Streams::External(_) => Some(Vec::new()),
    };
    for (m, mesh) in doc.meshes.iter_mut().enumerate() {
        for (p, primitive) in mesh.primitives.iter_mut().enumerate() {
            let Some(new) = replacements.get(&(m, p)) else {
                for index in primitive.attributes.values_mut() {
                    *index = acc(*index)?;
                }
                if let Some(i) = primitive.indices {
                    primitive.indices = Some(acc(i)?);
                }
                for target in primitive.targets.iter_mut().flatten() {
                    for slot in [
                        &mut target.positions,
                        &mut target.normals,
                        &mut target.tangents,
                    ] {
                        if let Some(i) = *slot {
                            *slot = Some(acc(i)?);
                        }
                    }
                }
                continue;
            };
            let mut attributes = BTreeMap::new();
            for (name, data) in &new.attributes {
                let semantic: Checked<gltf_json::mesh::Semantic> =
                    serde_json::from_value(serde_json::Value::String(name.clone()))
                        .map_err(|e| Error::mesh(format!("glTF: attribute {name}: {e}")))?;
                attributes.insert(
                    semantic,
                    push_accessor(&mut accessors, &mut views, &mut bin, data),
                );
            }
            primitive.attributes = attributes;
            primitive.indices = new
                .indices
                .as_ref()
                .map(|d| push_accessor(&mut accessors, &mut views, &mut bin, d));
            primitive.targets = None;
            let mut extensions = new.extensions.clone();
            if let (Some((stream, name)), Some(map)) = (&new.stream, extensions.as_mut()) {
                let view_index = match external.as_mut() {
                    None => {
                        let offset = append(&mut bin, stream);
                        views.push(view(0, offset, stream.len(), None, None));
                        views.len() - 1
                    }
                    Some(out) => {
                        let offset = append(out, stream);
                        views.push(view(1, offset, stream.len(), None, None));
                        views.len() - 1
                    }
                };
                if let Some(object) = map.get_mut(*name).and_then(|v| v.as_object_mut()) {
                    object.insert("bufferView".into(), view_index.into());
                }
            }
            primitive.extensions =
                extensions.map(|others| gltf_json::extensions::mesh::Primitive { others });
        }
    }
    doc.accessors = accessors;
    doc.buffer_views = views;
    pad(&mut bin);
    doc.buffers = vec![gltf_json::Buffer {
        byte_length: USize64(bin.len() as u64),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    }];
    if let (Streams::External(uri), Some(out)) = (streams, external.as_mut()) {
        pad(out);
        doc.buffers.push(gltf_json::Buffer {
            byte_length: USize64(out.len() as u64),
            name: Some("meshcodec streams".into()),
            uri: Some(uri.clone()),
            extensions: None,
            extras: Default::default(),
        });
    }
    // A buffer may not be empty: with every byte external, the streams' buffer is the only.
    if bin.is_empty() && doc.buffers.len() > 1 {
        doc.buffers.remove(0);
        for view in &mut doc.buffer_views {
            view.buffer = Index::new(view.buffer.value() as u32 - 1);
        }
    } else if bin.is_empty() {
        doc.buffers.clear();
    }
    for list in [&mut doc.extensions_used, &mut doc.extensions_required] {
        list.retain(|e| !removed.contains(&e.as_str()));
    }
    for (list, add) in [
        (&mut doc.extensions_used, used),
        (&mut doc.extensions_required, required),
    ] {
        for name in add {
            if !list.iter().any(|e| e == name) {
                list.push(name.to_string());
            }
        }
    }
    let mut json = serde_json::to_vec(&doc)
        .map_err(|e| Error::mesh(format!("glTF: the document cannot be written: {e}")))?;
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            length: 0,
        },
        json: std::borrow::Cow::Owned(json),
        bin: (!bin.is_empty()).then_some(std::borrow::Cow::Owned(bin)),
    };
    let bytes = glb
        .to_vec()
        .map_err(|e| Error::mesh(format!("glTF: the GLB cannot be written: {e}")))?;
    Ok((bytes, external))
}

/// The bytes of old buffer view `v`.
fn view_bytes(scene: &Scene, v: usize) -> Result<&[u8]> {
    let view = &scene.document.buffer_views[v];
    let buffer = scene
        .buffers
        .get(view.buffer.value())
        .ok_or_else(|| Error::mesh(format!("glTF: buffer view {v} names a missing buffer")))?;
    let start = view.byte_offset.map_or(0, |o| o.0) as usize;
    start
        .checked_add(view.byte_length.0 as usize)
        .and_then(|end| buffer.get(start..end))
        .ok_or_else(|| Error::mesh(format!("glTF: buffer view {v} runs past its buffer")))
}

fn remap(map: &[Option<u32>], i: usize) -> Result<u32> {
    map.get(i)
        .copied()
        .flatten()
        .ok_or_else(|| Error::mesh(format!("glTF: a reference to {i}, which is not kept")))
}

/// Appends `bytes` at a four-byte boundary; returns where they start.
fn append(bin: &mut Vec<u8>, bytes: &[u8]) -> u64 {
    pad(bin);
    let at = bin.len() as u64;
    bin.extend_from_slice(bytes);
    at
}

fn pad(bin: &mut Vec<u8>) {
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
}

fn view(
    buffer: u32,
    offset: u64,
    length: usize,
    stride: Option<usize>,
    target: Option<Target>,
) -> gltf_json::buffer::View {
    gltf_json::buffer::View {
        buffer: Index::new(buffer),
        byte_length: USize64(length as u64),
        byte_offset: Some(USize64(offset)),
        byte_stride: stride.map(Stride),
        name: None,
        target: target.map(Checked::Valid),
        extensions: None,
        extras: Default::default(),
    }
}

/// The glTF type of elements of `components` components.
fn type_of(components: usize) -> Type {
    match components {
        2 => Type::Vec2,
        3 => Type::Vec3,
        4 => Type::Vec4,
        _ => Type::Scalar,
    }
}

/// Appends an accessor of `data`, with its buffer view when it has bytes.
fn push_accessor(
    accessors: &mut Vec<gltf_json::Accessor>,
    views: &mut Vec<gltf_json::buffer::View>,
    bin: &mut Vec<u8>,
    data: &Data,
) -> Index<gltf_json::Accessor> {
    let (component, type_, count, bytes, min, max, target) = match data {
        Data::Empty {
            count,
            components,
            bounds,
        } => (
            ComponentType::F32,
            type_of(*components),
            *count,
            None,
            bounds.as_ref().map(|b| serde_json::json!(b.0)),
            bounds.as_ref().map(|b| serde_json::json!(b.1)),
            None,
        ),
        Data::Float {
            values,
            components,
            bounds,
            storage,
        } => {
            let type_ = type_of(*components);
            let (min, max) = if *bounds {
                let mut lo = vec![f32::INFINITY; *components];
                let mut hi = vec![f32::NEG_INFINITY; *components];
                for element in values.chunks_exact(*components) {
                    for (k, &x) in element.iter().enumerate() {
                        lo[k] = lo[k].min(x);
                        hi[k] = hi[k].max(x);
                    }
                }
                (Some(serde_json::json!(lo)), Some(serde_json::json!(hi)))
            } else {
                (None, None)
            };
            let (component, bytes, stride): (_, Vec<u8>, _) = match storage {
                Storage::F32 => (
                    ComponentType::F32,
                    values.iter().flat_map(|x| x.to_le_bytes()).collect(),
                    None,
                ),
                Storage::U16Norm => (
                    ComponentType::U16,
                    values
                        .iter()
                        .flat_map(|&x| ((x.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes())
                        .collect(),
                    None,
                ),
                Storage::U8Norm => (
                    ComponentType::U8,
                    values
                        .iter()
                        .map(|&x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
                        .collect(),
                    None,
                ),
                Storage::I8Norm => {
                    // Elements of three bytes take four (glTF aligns a vertex attribute's
                    // elements to four bytes).
                    let padded = components.next_multiple_of(4);
                    let mut bytes = vec![0u8; values.len() / components * padded];
                    for (e, element) in values.chunks_exact(*components).enumerate() {
                        for (k, &x) in element.iter().enumerate() {
                            bytes[e * padded + k] =
                                ((x.clamp(-1.0, 1.0) * 127.0).round() as i8) as u8;
                        }
                    }
                    (
                        ComponentType::I8,
                        bytes,
                        (padded != *components).then_some(padded),
                    )
                }
            };
            let normalized = *storage != Storage::F32;
            let buffer_view = {
                let offset = append(bin, &bytes);
                views.push(view(
                    0,
                    offset,
                    bytes.len(),
                    stride,
                    Some(Target::ArrayBuffer),
                ));
                Index::new(views.len() as u32 - 1)
            };
            accessors.push(gltf_json::Accessor {
                buffer_view: Some(buffer_view),
                byte_offset: None,
                count: USize64((values.len() / components) as u64),
                component_type: Checked::Valid(GenericComponentType(component)),
                extensions: None,
                extras: Default::default(),
                type_: Checked::Valid(type_),
                min,
                max,
                name: None,
                normalized,
                sparse: None,
            });
            return Index::new(accessors.len() as u32 - 1);
        }
        Data::Indices(indices) => {
            let short = indices.iter().all(|&i| i < u16::MAX as u32);
            let bytes: Vec<u8> = if short {
                indices
                    .iter()
                    .flat_map(|&i| (i as u16).to_le_bytes())
                    .collect()
            } else {
                indices.iter().flat_map(|i| i.to_le_bytes()).collect()
            };
            (
                if short {
                    ComponentType::U16
                } else {
                    ComponentType::U32
                },
                Type::Scalar,
                indices.len(),
                Some(bytes),
                None,
                None,
                Some(Target::ElementArrayBuffer),
            )
        }
    };
    let buffer_view = bytes.map(|bytes| {
        let offset = append(bin, &bytes);
        views.push(view(0, offset, bytes.len(), None, target));
        Index::new(views.len() as u32 - 1)
    });
    accessors.push(gltf_json::Accessor {
        buffer_view,
        byte_offset: None,
        count: USize64(count as u64),
        component_type: Checked::Valid(GenericComponentType(component)),
        extensions: None,
        extras: Default::default(),
        type_: Checked::Valid(type_),
        min,
        max,
        name: None,
        normalized: false,
        sparse: None,
    });
    Index::new(accessors.len() as u32 - 1)
}
