//! Wavefront OBJ through `tobj`: positions, faces and — for [`read_attributed`] — texture
//! coordinates (`vt`), normals (`vn`), vertex colours (`v x y z r g b`), the materials faces
//! use (`usemtl`) and the library naming them (`mtllib`); polygons triangulated as fans.
//!
//! `tobj` is used with separate position / texture / normal indices (not `single_index`, which
//! would split vertices at UV seams): each corner's (vt, vn) pair makes the wedges. It numbers
//! each object's vertices by first use, so the objects are joined back into one vertex list by
//! exact position. Materials are taken from the `usemtl` lines themselves, in the order they
//! first appear (the .mtl file is not read: its name is kept to be written back).

use crate::error::{Error, Result};
use crate::mesh::attributes::{AttributedMesh, Attributes, Corner, Materials};
use crate::mesh::TriMesh;
use glam::{DVec2, DVec3};
use std::collections::HashMap;

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    Ok(load(bytes, false)?.mesh)
}

/// The mesh with its wedges and materials.
pub fn read_attributed(bytes: &[u8]) -> Result<AttributedMesh> {
    load(bytes, true)
}

fn load(bytes: &[u8], with_attributes: bool) -> Result<AttributedMesh> {
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
    let mut corners: Vec<[Corner; 3]> = Vec::new();
    let mut by_position: HashMap<[u64; 3], u32> = HashMap::new();
    let single = models.len() == 1;
    // Corners are gathered only from a file that has some attribute: a million faces of
    // attribute-less corners would cost hundreds of megabytes to find nothing.
    let carries = with_attributes
        && models.iter().any(|m| {
            !m.mesh.texcoord_indices.is_empty()
                || !m.mesh.normal_indices.is_empty()
                || !m.mesh.vertex_color.is_empty()
        });
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
        if carries {
            corners_of(mesh, &mut corners)?;
        }
    }
    let mesh = TriMesh::new(positions, faces);
    if !with_attributes {
        return Ok(AttributedMesh {
            mesh,
            attributes: Attributes::default(),
        });
    }
    let mut attributes = if carries {
        Attributes::weld(&mesh.faces, &corners)?
    } else {
        Attributes::default()
    };
    attributes.materials = materials(bytes, mesh.faces.len())?;
    attributes.validate(&mesh)?;
    Ok(AttributedMesh { mesh, attributes })
}

/// What each corner of a tobj model's triangles carries.
fn corners_of(mesh: &tobj::Mesh, out: &mut Vec<[Corner; 3]>) -> Result<()> {
    let n = mesh.indices.len();
    for (indices, what) in [
        (&mesh.texcoord_indices, "texture coordinates"),
        (&mesh.normal_indices, "normals"),
    ] {
        if !indices.is_empty() && indices.len() != n {
            return Err(Error::mesh(format!(
                "OBJ: {} of {n} corners have {what}; the others none",
                indices.len()
            )));
        }
    }
    let colours = !mesh.vertex_color.is_empty();
    if colours && mesh.vertex_color.len() != mesh.positions.len() {
        return Err(Error::mesh("OBJ: some vertices have colours, others none"));
    }
    let fetch = |values: &[f64], index: u32, size: usize| -> Result<Vec<f64>> {
        let at = index as usize * size;
        values
            .get(at..at + size)
            .map(<[f64]>::to_vec)
            .ok_or_else(|| Error::mesh(format!("OBJ: attribute index {index} out of range")))
    };
    for t in 0..n / 3 {
        let mut triangle = [Corner::default(); 3];
        for (k, corner) in triangle.iter_mut().enumerate() {
            let i = 3 * t + k;
            if let Some(&ti) = mesh.texcoord_indices.get(i) {
                let uv = fetch(&mesh.texcoords, ti, 2)?;
                corner.uv = Some(DVec2::new(uv[0], uv[1]));
            }
            if let Some(&ni) = mesh.normal_indices.get(i) {
                let n = fetch(&mesh.normals, ni, 3)?;
                corner.normal = Some(DVec3::new(n[0], n[1], n[2]));
            }
            if colours {
                let c = fetch(&mesh.vertex_color, mesh.indices[i], 3)?;
                corner.colour = Some([c[0], c[1], c[2], 1.0]);
            }
        }
        out.push(triangle);
    }
    Ok(())
}

/// The faces' materials from the file's `usemtl` lines (names in order of first use; faces
/// before the first `usemtl` take the unnamed material ""), and its `mtllib`; `None` when the
/// file names no material. Each `f` line of n corners is n − 2 triangles, in file order as tobj
/// returns them.
fn materials(bytes: &[u8], triangles: usize) -> Result<Option<Materials>> {
    let mut names: Vec<String> = Vec::new();
    let mut ids: HashMap<String, u32> = HashMap::new();
    let mut library = None;
    let mut current: Option<u32> = None;
    let mut face = Vec::new();
    let mut any = false;
    for line in bytes.split(|&b| b == b'\n') {
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("mtllib") => {
                let name = words.collect::<Vec<_>>().join(" ");
                if library.is_none() && !name.is_empty() {
                    library = Some(name);
                }
            }
            Some("usemtl") => {
                let name = words.collect::<Vec<_>>().join(" ");
                if name.is_empty() {
                    continue; // tobj ignores it too
                }
                any = true;
                let next = names.len() as u32;
                let id = *ids.entry(name.clone()).or_insert_with(|| {
                    names.push(name);
                    next
                });
                current = Some(id);
            }
            Some("f") => {
                let corners = words.count();
                let id = match current {
                    Some(id) => id,
                    None => {
                        let next = names.len() as u32;
                        *ids.entry(String::new()).or_insert_with(|| {
                            names.push(String::new());
                            next
                        })
                    }
                };
                face.extend(std::iter::repeat_n(id, corners.saturating_sub(2)));
            }
            _ => {}
        }
    }
    if !any {
        return Ok(None);
    }
    if face.len() != triangles {
        return Err(Error::mesh(format!(
            "OBJ: the usemtl lines cover {} triangles, the faces are {triangles}",
            face.len()
        )));
    }
    Ok(Some(Materials {
        face,
        names,
        library,
    }))
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

/// Writes an attributed mesh as OBJ: `mtllib` when the materials came from a library, one `v`
/// a vertex (with its colour when colours are per vertex), one `vt` and `vn` a wedge, `usemtl`
/// where the material changes, `f v/vt/vn`. Numbers in Rust's shortest round-trip form, so they
/// read back as the same doubles. OBJ holds colours per vertex only: a mesh whose colours
/// differ between the wedges of a vertex is refused, and a vertex no face uses is written white.
pub fn write_attributed(m: &AttributedMesh, out: &mut impl std::io::Write) -> Result<()> {
    use std::fmt::Write as _;
    let (mesh, a) = (&m.mesh, &m.attributes);
    let mut vertex_colour: Vec<Option<[f64; 4]>> = vec![None; mesh.positions.len()];
    if let Some(colours) = &a.colours {
        for (w, &v) in a.wedge_vertex.iter().enumerate() {
            let c = colours[w];
            match vertex_colour[v as usize] {
                Some(seen) if seen != c => {
                    return Err(Error::Unsupported(format!(
                        "OBJ holds colours per vertex, and vertex {v} has two"
                    )))
                }
                _ => vertex_colour[v as usize] = Some(c),
            }
        }
        if let Some(c) = colours.iter().find(|c| c[3] != 1.0) {
            return Err(Error::Unsupported(format!(
                "OBJ holds no alpha, and a colour has {}",
                c[3]
            )));
        }
    }
    let mut text = String::with_capacity(mesh.positions.len() * 60 + mesh.faces.len() * 40);
    let _ = writeln!(text, "# meshcodec");
    if let Some(library) = a.materials.as_ref().and_then(|m| m.library.as_ref()) {
        let _ = writeln!(text, "mtllib {library}");
    }
    // A vertex no face uses has no wedge, so no colour; OBJ's colours are all or none (a
    // reader refuses a file that gives some vertices one and others none), so it gets white,
    // which no face can show.
    if a.colours.is_some() {
        for c in &mut vertex_colour {
            c.get_or_insert([1.0; 4]);
        }
    }
    for (p, c) in mesh.positions.iter().zip(&vertex_colour) {
        match c {
            Some(c) => {
                let _ = writeln!(
                    text,
                    "v {:?} {:?} {:?} {:?} {:?} {:?}",
                    p.x, p.y, p.z, c[0], c[1], c[2]
                );
            }
            None => {
                let _ = writeln!(text, "v {:?} {:?} {:?}", p.x, p.y, p.z);
            }
        }
    }
    for t in a.uvs.iter().flatten() {
        let _ = writeln!(text, "vt {:?} {:?}", t.x, t.y);
    }
    for n in a.normals.iter().flatten() {
        let _ = writeln!(text, "vn {:?} {:?} {:?}", n.x, n.y, n.z);
    }
    let mut material = None;
    for (f, face) in mesh.faces.iter().enumerate() {
        if let Some(m) = &a.materials {
            let id = m.face[f];
            // The unnamed material "" is that of faces before any `usemtl`.
            if material != Some(id) && !m.names[id as usize].is_empty() {
                material = Some(id);
                let _ = writeln!(text, "usemtl {}", m.names[id as usize]);
            }
        }
        text.push('f');
        for k in 0..3 {
            let v = face[k] + 1;
            let w = a.corners.get(f).map(|c| c[k] + 1);
            let _ = match (w, a.uvs.is_some(), a.normals.is_some()) {
                (Some(w), true, true) => write!(text, " {v}/{w}/{w}"),
                (Some(w), true, false) => write!(text, " {v}/{w}"),
                (Some(w), false, true) => write!(text, " {v}//{w}"),
                _ => write!(text, " {v}"),
            };
        }
        text.push('\n');
    }
    out.write_all(text.as_bytes())?;
    Ok(())
}
