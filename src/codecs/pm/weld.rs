//! Wedges from corner values (Hoppe 1998): the corners of one vertex that carry equal values are
//! one wedge, numbered in order of first corner, face by face — how the codec's level meshes
//! and the iterator's meshes get their wedges from the values the splits code.

use super::wedges::WedgeState;
use crate::hierarchy::pmesh::PmMesh;
use crate::mesh::canonical_attributes::CornerCode;

/// Faces' values around the mesh's wedges, for the codec's level meshes: wedge ids in order of
/// first corner, face by face.
pub fn weld(state: &WedgeState, mesh: &PmMesh) -> (Vec<[u32; 3]>, Vec<u32>, Vec<CornerCode>) {
    weld_values(mesh, &state.corners)
}

/// Wedges of `mesh` whose corners carry `values` (any value that tells wedges apart, such as a
/// pair of codes): the corners equal at one vertex are one wedge, numbered in order of first
/// corner, face by face.
pub fn weld_values<T: Copy + Eq + std::hash::Hash>(
    mesh: &PmMesh,
    values: &[[T; 3]],
) -> (Vec<[u32; 3]>, Vec<u32>, Vec<T>) {
    weld_face_values(mesh.faces.iter().map(|f| f.v), values, mesh.positions.len())
}

/// [`weld_values`] over plain `faces` of a mesh of about `vertices` vertices.
pub fn weld_face_values<T: Copy + Eq + std::hash::Hash>(
    faces: impl Iterator<Item = [u32; 3]>,
    values: &[[T; 3]],
    vertices: usize,
) -> (Vec<[u32; 3]>, Vec<u32>, Vec<T>) {
    let mut ids: std::collections::HashMap<(u32, T), u32> =
        std::collections::HashMap::with_capacity(vertices * 2);
    let mut wedge_vertex = Vec::new();
    let mut codes = Vec::new();
    let corners = faces
        .zip(values)
        .map(|(face, values)| {
            std::array::from_fn(|k| {
                *ids.entry((face[k], values[k])).or_insert_with(|| {
                    wedge_vertex.push(face[k]);
                    codes.push(values[k]);
                    wedge_vertex.len() as u32 - 1
                })
            })
        })
        .collect();
    (corners, wedge_vertex, codes)
}
