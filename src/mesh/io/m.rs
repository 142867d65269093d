//! Hoppe's `.m` format: `Vertex id x y z {attributes}` and `Face id v1 v2 v3 {attributes}`, ids
//! 1-based and arbitrary. Other records (Corner, Edge) carry attributes and are skipped.

use super::text::{as_text, content_lines, fan, number};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use glam::DVec3;
use std::collections::HashMap;

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    let text = as_text(bytes);
    let mut positions = Vec::new();
    let mut index_of: HashMap<u64, u32> = HashMap::new();
    let mut pending_faces: Vec<(usize, Vec<u64>)> = Vec::new();
    for (no, line) in content_lines(&text) {
        // Attributes in braces never hold geometry we read.
        let line = line.split('{').next().unwrap_or("");
        let mut t = line.split_whitespace();
        match t.next() {
            Some("Vertex") => {
                let id: u64 = number(t.next(), no, "vertex id")?;
                let x = number(t.next(), no, "x")?;
                let y = number(t.next(), no, "y")?;
                let z = number(t.next(), no, "z")?;
                if index_of.insert(id, positions.len() as u32).is_some() {
                    return Err(Error::mesh_at(no, format!("vertex id {id} defined twice")));
                }
                positions.push(DVec3::new(x, y, z));
            }
            Some("Face") => {
                let _id: u64 = number(t.next(), no, "face id")?;
                let ids = t
                    .map(|tok| number(Some(tok), no, "vertex id"))
                    .collect::<Result<Vec<u64>>>()?;
                if ids.len() < 3 {
                    return Err(Error::mesh_at(no, "face with fewer than 3 vertices"));
                }
                pending_faces.push((no, ids));
            }
            _ => {}
        }
    }
    // Faces may name vertices defined after them, so they are resolved at the end.
    let mut faces = Vec::with_capacity(pending_faces.len());
    let mut polygon = Vec::new();
    for (no, ids) in pending_faces {
        polygon.clear();
        for id in ids {
            let v = index_of
                .get(&id)
                .ok_or_else(|| Error::mesh_at(no, format!("face names undefined vertex {id}")))?;
            polygon.push(*v);
        }
        fan(&polygon, &mut faces);
    }
    Ok(TriMesh::new(positions, faces))
}
