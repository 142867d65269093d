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
    check_face_indices(bytes)?;
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

/// tobj (4.0) turns a face index of 0, or a relative one reaching before the first element, into
/// a huge unsigned index and then multiplies it unchecked, which can wrap onto a real vertex
/// instead of failing. So every index of every `f` and `l` line is checked here first, reading
/// the lines as tobj does: nonzero, relative ones within the elements read so far, absolute ones
/// within the elements in the file.
fn check_face_indices(bytes: &[u8]) -> Result<()> {
    let mut so_far = [0usize; 3]; // v, vt, vn
    let mut highest = [0usize; 3];
    for (number, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => so_far[0] += 1,
            Some("vt") => so_far[1] += 1,
            Some("vn") => so_far[2] += 1,
            Some("f") | Some("l") => {
                for word in words {
                    for (kind, part) in word.split('/').enumerate().take(3) {
                        let bad =
                            || Error::mesh(format!("OBJ line {}: face index '{part}'", number + 1));
                        if part.is_empty() {
                            continue;
                        }
                        let Ok(index) = part.parse::<isize>() else {
                            continue; // tobj refuses it itself
                        };
                        if index == 0 || (index < 0 && index.unsigned_abs() > so_far[kind]) {
                            return Err(bad());
                        }
                        highest[kind] = highest[kind].max(index.max(0) as usize);
                    }
                }
            }
            _ => {}
        }
    }
    if let Some(kind) = (0..3).find(|&k| highest[k] > so_far[k]) {
        let name = ["vertex", "texture coordinate", "normal"][kind];
        return Err(Error::mesh(format!(
            "OBJ: face index {} past the {} {name} lines",
            highest[kind], so_far[kind]
        )));
    }
    Ok(())
}
