//! Progressive streams inside glTF (docs/GLTF.md): [`pack`] codes every triangle primitive of
//! a scene as a stream of its own, stored in the GLB (or beside it) and named by the
//! `MESHCODEC_progressive` extension on the primitive, whose ordinary accessors keep a coarse
//! level that any glTF loader draws; [`unpack`] puts every stream's full level back into
//! ordinary accessors. The rest of the scene — nodes and their transforms, materials,
//! textures, images (bytes untouched), samplers, cameras, animations, skins, extras, and
//! extensions this build does not know — is kept; primitives a codec cannot take (points,
//! lines, skinned or morphed, attributes the codecs do not carry) stay as they are and are
//! listed.

pub mod assemble;
pub mod extension;

use crate::codecs::EncodeRequest;
use crate::codecs::{self, Codec, EncodeOptions, LevelMesh, Stop};
use crate::container::FORMAT_VERSION;
use crate::error::{Error, Result};
use crate::mesh::attribute_quantization::AttributeBits;
use crate::mesh::scene::{Content, Scene};
use assemble::{write_glb, Data, Replacement, Storage, Streams};
use extension::{Level, Progressive, NAME};
use std::collections::HashMap;

/// How [`pack`] codes a scene.
#[derive(Clone, Copy)]
pub struct PackOptions {
    /// The codec of every stream.
    pub codec: &'static dyn Codec,
    /// Positions' bits per axis.
    pub quant_bits: u8,
    /// Appearance quantization (uvs, normals).
    pub bits: AttributeBits,
    /// The fallback each primitive's accessors hold; `None`: none (`--no-fallback`: the
    /// extension is then required).
    pub fallback: Option<Fallback>,
}

/// How coarse the fallback is: the level whose faces lie nearest (by ratio) `share` of the
/// primitive's, and at least `min_faces` (or all of a smaller primitive's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fallback {
    /// Share of the faces.
    pub share: f64,
    /// Fewest faces.
    pub min_faces: usize,
}

impl Default for Fallback {
    /// About 2% of the faces, at least 256: enough to recognize the object.
    fn default() -> Self {
        Fallback {
            share: 0.02,
            min_faces: 256,
        }
    }
}

impl PackOptions {
    /// `emc` (which codes the appearance with its levels) at 12 bits, uvs at 12, normals at
    /// 10, the default fallback.
    pub fn new() -> Result<PackOptions> {
        Ok(PackOptions {
            codec: codecs::by_name("emc")?,
            quant_bits: 12,
            bits: AttributeBits::default(),
            fallback: Some(Fallback::default()),
        })
    }
}

/// What [`pack`] did with one primitive.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveReport {
    /// Its mesh and place in the mesh.
    pub mesh: usize,
    /// Its place in the mesh.
    pub primitive: usize,
    /// Its mesh's name, if any.
    pub name: Option<String>,
    /// Coded, or kept and why.
    pub outcome: Outcome,
}

/// A primitive coded, or kept as it was.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Coded: the stream's bytes, its levels, the fallback's level and faces.
    Packed {
        stream_bytes: usize,
        levels: usize,
        fallback_level: usize,
        fallback_faces: usize,
        faces: usize,
    },
    /// Kept as it was, and why.
    Kept(String),
}

/// A packed scene: the GLB, the streams' file with `--external`, what happened to each
/// primitive.
#[derive(Debug)]
pub struct Packed {
    /// The GLB.
    pub glb: Vec<u8>,
    /// The streams, when they go in a file of their own.
    pub streams: Option<Vec<u8>>,
    /// One entry a primitive.
    pub report: Vec<PrimitiveReport>,
}

/// Codes `scene`'s triangle primitives as progressive streams (see the module docs);
/// `external`: the URI, beside the GLB, of a file to hold the streams instead.
pub fn pack(scene: &Scene, options: &PackOptions, external: Option<&str>) -> Result<Packed> {
    let on_a_primitive = scene.document.meshes.iter().any(|m| {
        m.primitives.iter().any(|p| {
            p.extensions
                .as_ref()
                .is_some_and(|e| e.others.contains_key(NAME))
        })
    });
    if on_a_primitive
        || scene
            .document
            .extensions_used
            .iter()
            .any(|e| e == extension::NAME)
    {
        return Err(Error::Unsupported(format!(
            "the scene is packed already ({NAME}); `meshcodec unpack` it first"
        )));
    }
    let mut replacements = HashMap::new();
    let mut report = Vec::new();
    for primitive in &scene.primitives {
        let name = scene.document.meshes[primitive.mesh].name.clone();
        let outcome = match &primitive.content {
            Content::Kept(why) => Outcome::Kept(why.clone()),
            Content::Triangles(mesh) => {
                let (replacement, outcome) = pack_one(mesh, options).map_err(|e| {
                    e.context(&format!(
                        "mesh {} primitive {}",
                        primitive.mesh, primitive.primitive
                    ))
                })?;
                replacements.insert((primitive.mesh, primitive.primitive), replacement);
                outcome
            }
        };
        report.push(PrimitiveReport {
            mesh: primitive.mesh,
            primitive: primitive.primitive,
            name,
            outcome,
        });
    }
    // No stream, no streams' file (a glTF buffer may not be empty).
    let streams = match external {
        Some(uri) if !replacements.is_empty() => Streams::External(uri.to_string()),
        _ => Streams::Embedded,
    };
    let mut used = Vec::new();
    let mut required = Vec::new();
    if !replacements.is_empty() {
        used.push(NAME);
        if options.fallback.is_none() {
            required.push(NAME);
        }
    }
    if replacements.values().any(quantized) {
        used.push(QUANTIZATION);
        required.push(QUANTIZATION);
    }
    let (glb, streams) = write_glb(scene, &replacements, &used, &required, &[], &streams)?;
    Ok(Packed {
        glb,
        streams,
        report,
    })
}

/// One triangle primitive coded: its replacement in the document and what happened.
fn pack_one(
    mesh: &crate::mesh::attributes::AttributedMesh,
    options: &PackOptions,
) -> Result<(Replacement, Outcome)> {
    let request = EncodeRequest {
        codec: options.codec,
        options: EncodeOptions {
            quant_bits: options.quant_bits,
            ..options.codec.default_options()
        },
        appearance: (!mesh.attributes.is_empty()).then_some(options.bits),
        in_levels: None,
        appearance_unit: false,
    };
    let made = request.encode(mesh.clone())?;
    let stream = made.encoded.bytes;
    // Each level's size as a decoder shows it (an encoder's records need not know its
    // faces: emc's levels before the last are its decoder's cliques).
    let ends = codecs::level_ends(&stream)?;
    let mut decoder = codecs::open(&stream)?;
    let mut shown = Vec::with_capacity(ends.len());
    let mut full = None;
    while decoder.advance()? {
        let level = decoder.mesh()?;
        shown.push((level.mesh.vertex_count(), level.mesh.face_count()));
        full = Some(level);
    }
    drop(decoder);
    let full = full.ok_or_else(|| Error::Unsupported("a stream without levels".into()))?;
    let levels: Vec<Level> = ends
        .iter()
        .zip(&shown)
        .map(|(&end, &(vertices, faces))| Level {
            byte_length: end,
            faces: faces as u64,
            vertices: vertices as u64,
        })
        .collect();
    let faces = made.canonical.face_count();
    let attributes = present_attributes(&full);
    let (fallback_level, data) = match options.fallback {
        Some(fallback) => {
            let level = fallback_level(&levels, faces, fallback);
            let (mesh, _) = codecs::decode(&stream, Stop::Levels(level))?;
            (level, compact(gltf_arrays(&mesh, &attributes)?))
        }
        None => (0, empty_arrays(&full, &attributes)?),
    };
    let fallback_faces = levels
        .get(fallback_level.wrapping_sub(1))
        .map_or(0, |l| l.faces as usize);
    let progressive = Progressive {
        buffer_view: 0,
        codec: options.codec.name().to_string(),
        format_version: FORMAT_VERSION,
        levels,
        fallback_level: fallback_level as u32,
        attributes: attributes.iter().map(|a| a.to_string()).collect(),
    };
    let mut extensions = serde_json::Map::new();
    extensions.insert(
        NAME.into(),
        serde_json::to_value(&progressive).map_err(|e| Error::mesh(format!("glTF: {e}")))?,
    );
    let outcome = Outcome::Packed {
        stream_bytes: stream.len(),
        levels: progressive.levels.len(),
        fallback_level,
        fallback_faces,
        faces,
    };
    let (attribute_data, indices) = data;
    Ok((
        Replacement {
            attributes: attribute_data,
            indices,
            extensions: Some(extensions),
            stream: Some((stream, NAME)),
        },
        outcome,
    ))
}

/// The fallback's level (1-based): the one whose faces are nearest, by ratio, the share
/// asked (at least the fewest faces asked, at most all), among the levels with faces.
fn fallback_level(levels: &[Level], faces: usize, fallback: Fallback) -> usize {
    let target = (fallback.share * faces as f64)
        .max(fallback.min_faces as f64)
        .min(faces as f64)
        .max(1.0);
    levels
        .iter()
        .enumerate()
        .filter(|(_, l)| l.faces > 0)
        .min_by(|(_, a), (_, b)| {
            let off = |l: &Level| (l.faces as f64 / target).ln().abs();
            off(a).total_cmp(&off(b))
        })
        .map_or(levels.len(), |(i, _)| i + 1)
}

/// The glTF attributes a decoded level fills, in order.
fn present_attributes(level: &LevelMesh) -> Vec<&'static str> {
    let mut names = vec!["POSITION"];
    if let Some(a) = &level.attributes {
        if a.normals.is_some() {
            names.push("NORMAL");
        }
        if a.uvs.is_some() {
            names.push("TEXCOORD_0");
        }
        if a.colours.is_some() {
            names.push("COLOR_0");
        }
    }
    names
}

/// A primitive's attributes (by glTF name) and its indices, as glTF arrays.
pub type Arrays = (Vec<(String, Data)>, Option<Data>);

/// A decoded level as glTF vertex arrays (one vertex a wedge, as glTF splits them) and
/// indices.
pub fn gltf_arrays(level: &LevelMesh, names: &[&str]) -> Result<Arrays> {
    let mesh = &level.mesh;
    let float = |values: Vec<f32>, components: usize, bounds: bool| Data::Float {
        values,
        components,
        bounds,
        storage: Storage::F32,
    };
    let (vertex_of, indices): (Vec<u32>, Vec<u32>) = match &level.attributes {
        Some(a) => (
            a.wedge_vertex.clone(),
            a.corners.iter().flatten().copied().collect(),
        ),
        None => (
            (0..mesh.positions.len() as u32).collect(),
            mesh.faces.iter().flatten().copied().collect(),
        ),
    };
    let mut out = Vec::new();
    for &name in names {
        let data = match (name, &level.attributes) {
            ("POSITION", _) => float(
                vertex_of
                    .iter()
                    .flat_map(|&v| mesh.positions[v as usize].to_array().map(|x| x as f32))
                    .collect(),
                3,
                true,
            ),
            ("NORMAL", Some(a)) => float(
                a.normals
                    .iter()
                    .flatten()
                    .flat_map(|n| n.normalize_or_zero().to_array().map(|x| x as f32))
                    .collect(),
                3,
                false,
            ),
            ("TEXCOORD_0", Some(a)) => float(
                a.uvs
                    .iter()
                    .flatten()
                    .flat_map(|t| t.to_array().map(|x| x as f32))
                    .collect(),
                2,
                false,
            ),
            ("COLOR_0", Some(a)) => float(
                a.colours
                    .iter()
                    .flatten()
                    .flat_map(|c| c.map(|x| x as f32))
                    .collect(),
                4,
                false,
            ),
            _ => {
                return Err(Error::Unsupported(format!(
                    "a level without the {name} the stream's full level has"
                )))
            }
        };
        out.push((name.to_string(), data));
    }
    Ok((out, Some(Data::Indices(indices))))
}

/// A fallback's arrays stored small, as a coarse preview needs: normals as normalized bytes
/// (`KHR_mesh_quantization`), uvs in [0, 1] as normalized shorts, colours as normalized bytes;
/// positions stay floats (quantized positions would need the node's transform to scale them).
fn compact((attributes, indices): Arrays) -> Arrays {
    let attributes = attributes
        .into_iter()
        .map(|(name, data)| {
            let data = match data {
                Data::Float {
                    values,
                    components,
                    bounds,
                    ..
                } => {
                    let storage = match name.as_str() {
                        "NORMAL" => Storage::I8Norm,
                        "TEXCOORD_0" if values.iter().all(|x| (0.0..=1.0).contains(x)) => {
                            Storage::U16Norm
                        }
                        "COLOR_0" => Storage::U8Norm,
                        _ => Storage::F32,
                    };
                    Data::Float {
                        values,
                        components,
                        bounds,
                        storage,
                    }
                }
                other => other,
            };
            (name, data)
        })
        .collect();
    (attributes, indices)
}

/// Whether `replacement` stores an attribute as `KHR_mesh_quantization` allows only.
fn quantized(replacement: &Replacement) -> bool {
    replacement.attributes.iter().any(|(_, d)| {
        matches!(
            d,
            Data::Float {
                storage: Storage::I8Norm,
                ..
            }
        )
    })
}

/// The extension that lets a fallback's normals be bytes.
const QUANTIZATION: &str = "KHR_mesh_quantization";

/// Accessors with a count and no data, sized as the full level's (`--no-fallback`).
fn empty_arrays(full: &LevelMesh, names: &[&str]) -> Result<Arrays> {
    let (arrays, _) = gltf_arrays(full, names)?;
    Ok((
        arrays
            .into_iter()
            .map(|(name, data)| {
                let Data::Float {
                    values, components, ..
                } = data
                else {
                    unreachable!("gltf_arrays makes floats")
                };
                let bounds = (name == "POSITION").then(|| {
                    let mut lo = vec![f32::INFINITY; 3];
                    let mut hi = vec![f32::NEG_INFINITY; 3];
                    for p in values.chunks_exact(3) {
                        for k in 0..3 {
                            lo[k] = lo[k].min(p[k]);
                            hi[k] = hi[k].max(p[k]);
                        }
                    }
                    (lo, hi)
                });
                (
                    name,
                    Data::Empty {
                        count: values.len() / components,
                        components,
                        bounds,
                    },
                )
            })
            .collect(),
        None,
    ))
}

/// What [`unpack`] did: the GLB and how many primitives it unpacked.
#[derive(Debug)]
pub struct Unpacked {
    /// The GLB.
    pub glb: Vec<u8>,
    /// Primitives whose streams were decoded.
    pub primitives: usize,
}

/// Every stream's full level back into its primitive's ordinary accessors, the extension
/// gone; the rest of the scene as it was. `external`: the bytes of a file holding the
/// streams (`--external`), when the GLB names one.
pub fn unpack(scene: &Scene) -> Result<Unpacked> {
    let mut replacements = HashMap::new();
    for (m, mesh) in scene.document.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let Some(object) = primitive
                .extensions
                .as_ref()
                .and_then(|e| e.others.get(NAME))
            else {
                continue;
            };
            let at = |e: Error| e.context(&format!("mesh {m} primitive {p}"));
            let progressive: Progressive = serde_json::from_value(object.clone())
                .map_err(|e| Error::mesh(format!("glTF: {NAME} of mesh {m} primitive {p}: {e}")))?;
            let stream = stream_bytes(scene, progressive.buffer_view as usize).map_err(at)?;
            let (full, _) = codecs::decode(stream, Stop::All).map_err(at)?;
            let names: Vec<&str> = present_attributes(&full);
            let (attributes, indices) = gltf_arrays(&full, &names).map_err(at)?;
            let mut extensions = primitive
                .extensions
                .as_ref()
                .map(|e| e.others.clone())
                .unwrap_or_default();
            extensions.remove(NAME);
            replacements.insert(
                (m, p),
                Replacement {
                    attributes,
                    indices,
                    extensions: (!extensions.is_empty()).then_some(extensions),
                    stream: None,
                },
            );
        }
    }
    let primitives = replacements.len();
    let (glb, _) = write_glb(scene, &replacements, &[], &[], &[NAME], &Streams::Embedded)?;
    Ok(Unpacked { glb, primitives })
}

/// The bytes of buffer view `view` of `scene` (a stream).
pub fn stream_bytes(scene: &Scene, view: usize) -> Result<&[u8]> {
    let v = scene.document.buffer_views.get(view).ok_or_else(|| {
        Error::mesh(format!(
            "glTF: buffer view {view} of {}",
            scene.document.buffer_views.len()
        ))
    })?;
    let buffer = scene
        .buffers
        .get(v.buffer.value())
        .ok_or_else(|| Error::mesh(format!("glTF: buffer view {view} names a missing buffer")))?;
    let start = v.byte_offset.map_or(0, |o| o.0) as usize;
    start
        .checked_add(v.byte_length.0 as usize)
        .and_then(|end| buffer.get(start..end))
        .ok_or_else(|| Error::Truncated(format!("glTF buffer view {view} runs past its buffer")))
}
