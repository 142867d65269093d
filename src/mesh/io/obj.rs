//! Wavefront OBJ through `tobj`: positions and faces only, polygons triangulated as fans.
//!
//! `tobj` is used with separate position / texture indices (not `single_index`, which would split
//! vertices at UV seams). It numbers each object's vertices by first use, so the objects are
//! joined back into one vertex list by exact position.

use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use glam::DVec3;
use std::collections::HashMap;

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(bytes);
    // Materials are not geometry: a missing .mtl must not stop the mesh from loading.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Ok((Vec::new(), Default::default()))
    })
    .map_err(|e| Error::mesh(format!("OBJ: {e}")))?;
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let mut by_position: HashMap<[u64; 3], u32> = HashMap::new();
    let single = models.len() == 1;
    for model in &models {
        let mesh = &model.mesh;
        if mesh.positions.len() % 3 != 0 || mesh.indices.len() % 3 != 0 {
            return Err(Error::mesh("OBJ: malformed position or index list"));
        }
        let local: Vec<u32> = mesh
            .positions
            .chunks_exact(3)
            .map(|c| {
                // tobj is built with `use_f64`: positions arrive as the file's doubles.
                let p = DVec3::new(c[0], c[1], c[2]);
                if single {
                    positions.push(p);
                    return (positions.len() - 1) as u32;
                }
                let key = p.to_array().map(|x| (x + 0.0).to_bits());
                *by_position.entry(key).or_insert_with(|| {
                    positions.push(p);
                    (positions.len() - 1) as u32
                })
            })
            .collect();
        for tri in mesh.indices.chunks_exact(3) {
            let mut face = [0u32; 3];
            for (slot, &i) in face.iter_mut().zip(tri) {
                *slot = *local
                    .get(i as usize)
                    .ok_or_else(|| Error::mesh(format!("OBJ: face index {i} out of range")))?;
            }
            faces.push(face);
        }
    }
    Ok(TriMesh::new(positions, faces))
}
