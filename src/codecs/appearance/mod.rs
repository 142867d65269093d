//! Appearance (normals, texture coordinates, colours, materials) carried by any codec whose full
//! decode is the canonical mesh: one **appearance unit** after the stream's last unit, coded
//! against the decoded full mesh (docs/FORMAT.md §9, docs/CONTRACT.md §2.1).
//!
//! Based on: H. Hoppe, *Efficient implementation of progressive meshes*, Computers & Graphics
//! 22(1), 1998, §3 (../shared/papers/000_54780623804685d2.txt) for the model — faces point to
//! wedges, wedges to vertices, a seam is several wedges at one vertex, faces carry material ids;
//! and Draco's attribute coders for the idea that an attribute coder needs only the order in
//! which the decoder meets vertices, not how connectivity was coded (see
//! ../shared/papers/attributes-reading-notes.md). Because the unit is coded against the decoded
//! mesh, the same coder serves the octree (`emc`), vertex splits (`pm`) and the vertex
//! hierarchy (`came`); the price is that levels before the last have no appearance.
//!
//! # Glossary
//! | Hoppe 1998 | here |
//! |---|---|
//! | corner (vertex, face) | `corners[f][k]`, the wedge of face f's k-th corner |
//! | wedge | a wedge id; `wedge_vertex[w]` its vertex; its values are a [`CornerCode`] |
//! | S/T_LSAME, S/T_RSAME (corner continues a neighbour's wedge) | the `wedge` bits: "same as the corner across this edge" |
//! | wedge delta | the residual of a new wedge's values after prediction |
//! | material prediction from an adjacent face | the `material` bit: "same as the face across an edge" |

pub mod births;
pub mod charts;
pub mod coder;
pub mod decoder;
pub mod levels;
pub mod predict;
pub mod traversal;

use crate::coding::arith::{ArithDecoder, ArithEncoder};
use crate::container::{AppearanceSpec, MaterialNames};
use crate::error::{Error, Result};
use crate::mesh::attribute_quantization::{colour_value, octahedral_normal};
use crate::mesh::attributes::{Attributes, Materials, WedgeId};
use crate::mesh::canonical_attributes::{CanonicalAttributes, CornerCode};
use crate::mesh::{CanonicalMesh, TriMesh, VertexId};
use std::collections::HashMap;

/// Decoded appearance, quantized: wedges of the decoded mesh's corners and their codes.
#[derive(Clone, Debug, PartialEq)]
pub struct Appearance {
    /// Wedge of each corner, face by face of the decoded mesh.
    pub corners: Vec<[WedgeId; 3]>,
    /// Vertex of each wedge.
    pub wedge_vertex: Vec<VertexId>,
    /// Quantized values of each wedge.
    pub codes: Vec<CornerCode>,
    /// Material of each face.
    pub materials: Option<Vec<u32>>,
}

/// What the header declares for `appearance`.
pub fn spec_of(appearance: &CanonicalAttributes) -> AppearanceSpec {
    AppearanceSpec {
        normal_bits: appearance.normals.as_ref().map(|_| appearance.bits.normal),
        uv_grid: appearance.uvs.as_ref().and(appearance.uv_grid),
        colours: appearance.colours.is_some(),
        materials: appearance.materials.as_ref().map(|m| MaterialNames {
            names: m.names.clone(),
            library: m.library.clone(),
        }),
        in_levels: false,
        derived_normals: false,
        geometric_normals: false,
        level_parts: false,
    }
}

/// The appearance unit for `appearance` of `canonical`, coded against `decoded`, the full decode
/// of the stream's geometry (equal to `canonical` up to vertex and face order). Also returns
/// the estimated bits per field.
pub fn encode(
    decoded: &TriMesh,
    canonical: &CanonicalMesh,
    appearance: &CanonicalAttributes,
) -> Result<(Vec<u8>, std::collections::BTreeMap<&'static str, f64>)> {
    // Each decoded face's canonical face, and the rotation between them.
    let key = |cells: [[u32; 3]; 3]| {
        let r = (0..3).min_by_key(|&k| cells[k]).expect("three corners");
        ([cells[r], cells[(r + 1) % 3], cells[(r + 2) % 3]], r)
    };
    let mut canonical_face: HashMap<[[u32; 3]; 3], (usize, usize)> =
        HashMap::with_capacity(canonical.faces.len());
    for (f, face) in canonical.faces.iter().enumerate() {
        let (k, r) = key(face.map(|v| canonical.cells[v as usize]));
        canonical_face.insert(k, (f, r));
    }
    let grid = canonical.grid;
    let mut corners = Vec::with_capacity(decoded.faces.len());
    let mut materials = appearance.materials.as_ref().map(|_| Vec::new());
    for face in &decoded.faces {
        let (k, r) = key(face.map(|v| grid.quantize(decoded.positions[v as usize])));
        let &(f, s) = canonical_face.get(&k).ok_or_else(|| {
            Error::Unsupported("the decoded geometry is not the canonical mesh".into())
        })?;
        // Decoded corner i is rotated corner (i − r), canonical corner (i − r + s).
        let wedges = appearance.corners[f];
        corners.push(std::array::from_fn(|i| {
            appearance.code(wedges[(i + 3 - r + s) % 3])
        }));
        if let (Some(out), Some(m)) = (materials.as_mut(), &appearance.materials) {
            out.push(m.face[f]);
        }
    }
    let truth = coder::Truth {
        corners: &corners,
        materials: materials.as_deref(),
    };
    let mut encoder = ArithEncoder::default();
    coder::run(
        &mut encoder,
        decoded,
        &spec_of(appearance),
        Some(&truth),
        None,
    )?;
    let fields = encoder.field_bits.clone();
    let (bytes, _) = encoder.finish();
    Ok((bytes, fields))
}

/// Decodes the appearance unit `bytes` (unit number `unit`, at byte `start` of the stream) of a
/// stream whose header declares `spec`, against `mesh`, the stream's decoded full level.
pub fn decode(
    bytes: &[u8],
    unit: usize,
    start: usize,
    spec: &AppearanceSpec,
    mesh: &TriMesh,
) -> Result<Attributes> {
    let coder = ArithDecoder::new(bytes).ok_or_else(|| {
        Error::malformed(unit, start, "appearance unit is not whole 32-bit words")
    })?;
    let mut reader = coder::Reader { coder, unit, start };
    let appearance = coder::run(&mut reader, mesh, spec, None, None).map_err(|e| match e {
        Error::Malformed { what, .. } => Error::malformed(unit, start, what),
        e => e,
    })?;
    Ok(to_attributes(&appearance, spec))
}

/// The values of decoded codes: uv cell centres, unit normals, colours in [0, 1].
pub fn to_attributes(appearance: &Appearance, spec: &AppearanceSpec) -> Attributes {
    let codes = &appearance.codes;
    Attributes {
        corners: appearance.corners.clone(),
        wedge_vertex: appearance.wedge_vertex.clone(),
        normals: spec.normal_bits.map(|bits| {
            codes
                .iter()
                .map(|c| octahedral_normal(c.normal.unwrap_or_default(), bits))
                .collect()
        }),
        uvs: spec.uv_grid.map(|grid| {
            codes
                .iter()
                .map(|c| grid.dequantize(c.uv.unwrap_or_default()))
                .collect()
        }),
        colours: spec.colours.then(|| {
            codes
                .iter()
                .map(|c| colour_value(c.colour.unwrap_or_default()))
                .collect()
        }),
        materials: match (&appearance.materials, &spec.materials) {
            (Some(face), Some(names)) => Some(Materials {
                face: face.clone(),
                names: names.names.clone(),
                library: names.library.clone(),
            }),
            _ => None,
        },
    }
}
