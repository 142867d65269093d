//! OFF (Object File Format): `OFF`, counts `nv nf ne`, vertex lines, face lines `n i1 … in`.
//! Variants with colours or normals (COFF, NOFF, …) carry extra numbers that are skipped.

use super::text::{as_text, content_lines, fan, number};
use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use glam::DVec3;

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    let text = as_text(bytes);
    let mut lines = content_lines(&text);
    let (first_no, first) = lines.next().ok_or_else(|| Error::mesh("empty OFF file"))?;
    let mut tokens = first.split_whitespace();
    let keyword = tokens.next().unwrap_or("");
    if !keyword.ends_with("OFF") {
        return Err(Error::mesh_at(first_no, "not an OFF file (no OFF keyword)"));
    }
    if keyword.contains('4') || keyword.starts_with('n') {
        return Err(Error::Unsupported(format!(
            "OFF variant '{keyword}' (only 3D vertices are read)"
        )));
    }
    let (counts_no, counts_line): (usize, Vec<&str>) = {
        let rest: Vec<&str> = tokens.collect();
        if rest.is_empty() {
            let (no, line) = lines
                .next()
                .ok_or_else(|| Error::Truncated("OFF file ends before its counts".into()))?;
            (no, line.split_whitespace().collect())
        } else {
            (first_no, rest)
        }
    };
    let mut counts = counts_line.into_iter();
    let nv: usize = number(counts.next(), counts_no, "vertex count")?;
    let nf: usize = number(counts.next(), counts_no, "face count")?;
    // Capacity is bounded by the file's size, never by what its header claims.
    let mut positions = Vec::with_capacity(nv.min(bytes.len() / 6));
    let mut faces = Vec::with_capacity(nf.min(bytes.len() / 6));
    for _ in 0..nv {
        let (no, line) = lines.next().ok_or_else(|| {
            Error::Truncated(format!(
                "OFF file ends after {} of {nv} vertices",
                positions.len()
            ))
        })?;
        let mut t = line.split_whitespace();
        let x = number(t.next(), no, "x")?;
        let y = number(t.next(), no, "y")?;
        let z = number(t.next(), no, "z")?;
        positions.push(DVec3::new(x, y, z));
    }
    let mut polygon = Vec::new();
    for f in 0..nf {
        let (no, line) = lines
            .next()
            .ok_or_else(|| Error::Truncated(format!("OFF file ends after {f} of {nf} faces")))?;
        let mut t = line.split_whitespace();
        let n: usize = number(t.next(), no, "face size")?;
        polygon.clear();
        for _ in 0..n {
            let v: u32 = number(t.next(), no, "vertex index")?;
            if v as usize >= nv {
                return Err(Error::mesh_at(
                    no,
                    format!("face index {v} out of range ({nv} vertices)"),
                ));
            }
            polygon.push(v);
        }
        fan(&polygon, &mut faces);
    }
    Ok(TriMesh::new(positions, faces))
}
