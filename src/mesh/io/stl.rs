//! STL, binary or ASCII. STL stores a triangle soup; corners are welded on exact position so that
//! neighbouring triangles share vertices (a tolerance would change the mesh).

use super::text::{as_text, number};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use glam::DVec3;
use std::collections::HashMap;

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 {
            return read_binary(bytes, n as usize);
        }
    }
    let head = &bytes[..bytes.len().min(512)];
    let looks_ascii =
        head.trim_ascii_start().starts_with(b"solid") && as_text(head).contains("facet");
    if looks_ascii || bytes.len() < 84 && bytes.trim_ascii_start().starts_with(b"solid") {
        return read_ascii(bytes);
    }
    if bytes.len() < 84 {
        return Err(Error::Truncated(
            "STL file shorter than its 84-byte header".into(),
        ));
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
    Err(Error::Truncated(format!(
        "binary STL header claims {n} triangles ({} bytes) but the file has {} bytes",
        84 + 50 * n,
        bytes.len()
    )))
}

/// Welds corners that have the same coordinates to the bit.
#[derive(Default)]
struct Welder {
    index: HashMap<[u64; 3], u32>,
    positions: Vec<DVec3>,
}

impl Welder {
    fn vertex(&mut self, p: DVec3) -> u32 {
        let key = p.to_array().map(|c| (c + 0.0).to_bits()); // + 0.0 folds −0 onto 0
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            (self.positions.len() - 1) as u32
        })
    }
}

fn read_binary(bytes: &[u8], n: usize) -> Result<TriMesh> {
    let mut welder = Welder::default();
    let mut faces = Vec::with_capacity(n);
    for record in bytes[84..].chunks_exact(50) {
        let f32_at = |o: usize| {
            f32::from_le_bytes([record[o], record[o + 1], record[o + 2], record[o + 3]]) as f64
        };
        let mut face = [0u32; 3];
        for (k, slot) in face.iter_mut().enumerate() {
            let o = 12 + 12 * k;
            *slot = welder.vertex(DVec3::new(f32_at(o), f32_at(o + 4), f32_at(o + 8)));
        }
        faces.push(face);
    }
    Ok(TriMesh::new(welder.positions, faces))
}

fn read_ascii(bytes: &[u8]) -> Result<TriMesh> {
    let text = as_text(bytes);
    let mut welder = Welder::default();
    let mut faces = Vec::new();
    let mut corners: Vec<u32> = Vec::with_capacity(3);
    for (i, line) in text.lines().enumerate() {
        let no = i + 1;
        let mut t = line.split_whitespace();
        match t.next() {
            Some("vertex") => {
                let x = number(t.next(), no, "x")?;
                let y = number(t.next(), no, "y")?;
                let z = number(t.next(), no, "z")?;
                corners.push(welder.vertex(DVec3::new(x, y, z)));
            }
            Some("endloop") => {
                if corners.len() < 3 {
                    return Err(Error::mesh_at(no, "facet with fewer than 3 vertices"));
                }
                super::text::fan(&corners, &mut faces);
                corners.clear();
            }
            _ => {}
        }
    }
    if !corners.is_empty() {
        return Err(Error::Truncated("ASCII STL ends inside a facet".into()));
    }
    Ok(TriMesh::new(welder.positions, faces))
}
