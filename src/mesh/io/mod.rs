//! Mesh files: readers for OBJ, PLY, OFF, STL and Hoppe's `.m`; writers for PLY and OBJ; and the
//! lookup of mesh names in the data folders (`$MESHCODEC_DATA`, then ../shared/meshes).
//!
//! Readers return the mesh as stored (unreferenced vertices kept where the format keeps them),
//! validated: finite coordinates, indices in range, at least one face.

mod appearance;
mod m;
mod obj;
mod off;
mod ply;
mod stl;
mod text;
pub mod vrml;

pub use appearance::{appearance_of, Appearance};

use super::attributes::{AttributedMesh, Attributes};
use super::TriMesh;
use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// File extensions the readers understand, in the order a bare mesh name prefers them.
pub const EXTENSIONS: [&str; 5] = ["ply", "obj", "off", "m", "stl"];

/// Reads a mesh, choosing the reader by the file's extension: positions and triangles only
/// ([`read_mesh_and_appearance`] says what else the file holds).
pub fn read_mesh(path: &Path) -> Result<TriMesh> {
    let ext = extension(path);
    let bytes = std::fs::read(path)?;
    read_by_extension(&bytes, &ext)
}

/// Reads a mesh as [`read_mesh`] does, and counts the appearance attributes (normals, texture
/// coordinates, colours, materials) the file holds beyond it, which the mesh does not carry.
pub fn read_mesh_and_appearance(path: &Path) -> Result<(TriMesh, Appearance)> {
    let ext = extension(path);
    let bytes = std::fs::read(path)?;
    let mesh = read_by_extension(&bytes, &ext)?;
    let found = appearance::appearance_of(&bytes, &ext, mesh.positions.len(), mesh.faces.len());
    Ok((mesh, found))
}

fn read_by_extension(bytes: &[u8], ext: &str) -> Result<TriMesh> {
    let mesh = match ext {
        "obj" => obj::read(bytes)?,
        "ply" => ply::read(bytes)?,
        "off" => off::read(bytes)?,
        "stl" => stl::read(bytes)?,
        "m" => m::read(bytes)?,
        _ => {
            return Err(Error::Unsupported(format!(
                "mesh format '.{ext}' (readers: {})",
                EXTENSIONS.join(", ")
            )))
        }
    };
    mesh.validate()?;
    Ok(mesh)
}

/// Reads a mesh with its appearance — wedges (normals, texture coordinates, colours) and
/// materials — by the file's extension. OBJ and PLY carry them; a file of another format that
/// holds appearance the reader cannot keep yet (OFF colours, `.m` normals) is refused, naming it.
pub fn read_attributed(path: &Path) -> Result<AttributedMesh> {
    let ext = extension(path);
    let bytes = std::fs::read(path)?;
    read_attributed_bytes(&bytes, &ext)
}

/// [`read_attributed`] from bytes in the given format.
pub fn read_attributed_bytes(bytes: &[u8], format: &str) -> Result<AttributedMesh> {
    let read = match format {
        "obj" => obj::read_attributed(bytes)?,
        "ply" => ply::read_attributed(bytes)?,
        _ => {
            let mesh = read_by_extension(bytes, format)?;
            let found = appearance_of(bytes, format, mesh.positions.len(), mesh.faces.len());
            if !found.is_empty() {
                return Err(Error::Unsupported(format!(
                    "the .{format} reader keeps positions and faces only, and the file holds {found}"
                )));
            }
            return Ok(AttributedMesh {
                mesh,
                attributes: Attributes::default(),
            });
        }
    };
    read.mesh.validate()?;
    Ok(read)
}

/// Writes a mesh with its appearance as OBJ or PLY by the extension of `path` (each holds what
/// it can: a file that cannot hold some of the appearance is refused, naming it), atomically.
pub fn write_attributed(mesh: &AttributedMesh, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    match extension(path).as_str() {
        "ply" => ply::write_attributed(mesh, &mut bytes)?,
        "obj" => obj::write_attributed(mesh, &mut bytes)?,
        other => {
            return Err(Error::Unsupported(format!(
                "output format '.{other}' with attributes (writers: ply, obj)"
            )))
        }
    }
    write_atomically(path, &bytes)
}

/// [`write_attributed`] to bytes in the given format.
pub fn write_attributed_bytes(mesh: &AttributedMesh, format: &str) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    match format {
        "ply" => ply::write_attributed(mesh, &mut bytes)?,
        "obj" => obj::write_attributed(mesh, &mut bytes)?,
        other => {
            return Err(Error::Unsupported(format!(
                "output format '.{other}' with attributes (writers: ply, obj)"
            )))
        }
    }
    Ok(bytes)
}

/// Reads a mesh from bytes in the given format (an extension such as "ply").
pub fn read_mesh_bytes(bytes: &[u8], format: &str) -> Result<TriMesh> {
    read_by_extension(bytes, format)
}

/// Writes `mesh` as binary PLY (double positions), OBJ or VRML, by the extension of `path`. The file
/// appears only when it is complete: it is written beside and renamed into place.
pub fn write_mesh(mesh: &TriMesh, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    match extension(path).as_str() {
        "ply" => write_ply(mesh, &mut bytes)?,
        "obj" => write_obj(mesh, &mut bytes)?,
        "wrl" => vrml::write_vrml(mesh, &mut bytes)?,
        other => {
            return Err(Error::Unsupported(format!(
                "output format '.{other}' (writers: ply, obj, wrl)"
            )))
        }
    }
    write_atomically(path, &bytes)
}

/// Writes `bytes` to `path` through a temporary file beside it, so no partial file is left.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let tmp = dir.join(format!(".{name}.partial-{}", std::process::id()));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })?;
    Ok(())
}

/// Binary little-endian PLY with double positions and int face lists.
pub fn write_ply(mesh: &TriMesh, out: &mut impl Write) -> std::io::Result<()> {
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment meshcodec\nelement vertex {}\n\
         property double x\nproperty double y\nproperty double z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.faces.len()
    )?;
    let mut body = Vec::with_capacity(mesh.positions.len() * 24 + mesh.faces.len() * 13);
    for p in &mesh.positions {
        for c in p.to_array() {
            body.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in &mesh.faces {
        body.push(3);
        for &v in f {
            body.extend_from_slice(&(v as i32).to_le_bytes());
        }
    }
    out.write_all(&body)
}

/// OBJ with positions printed in Rust's shortest round-trip form (at most 17 significant
/// digits): they parse back to the same doubles, hence re-quantize to the same cells.
pub fn write_obj(mesh: &TriMesh, out: &mut impl Write) -> std::io::Result<()> {
    let mut text = String::with_capacity(mesh.positions.len() * 60 + mesh.faces.len() * 24);
    use std::fmt::Write as _;
    let _ = writeln!(text, "# meshcodec");
    for p in &mesh.positions {
        let _ = writeln!(text, "v {:?} {:?} {:?}", p.x, p.y, p.z);
    }
    for f in &mesh.faces {
        let _ = writeln!(text, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    out.write_all(text.as_bytes())
}

fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Folders searched for a bare mesh name: `$MESHCODEC_DATA`, then `../shared/meshes` from the
/// working directory and from the crate's own folder.
pub fn data_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os("MESHCODEC_DATA") {
        dirs.push(PathBuf::from(d));
    }
    dirs.push(PathBuf::from("../shared/meshes"));
    dirs.push(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes"));
    dirs
}

/// Mesh names (file stems with a readable extension) found in the data folders.
pub fn known_names() -> Vec<String> {
    let mut names: Vec<String> = data_dirs()
        .iter()
        .filter_map(|d| std::fs::read_dir(d).ok())
        .flatten()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| EXTENSIONS.contains(&extension(p).as_str()))
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    names.dedup();
    names
}

/// Turns a path or a bare name into a mesh file: a path that exists is used as it is; a name is
/// looked up as `<name>.*` in [`data_dirs`] (extensions in the order of [`EXTENSIONS`]).
pub fn resolve(name_or_path: &str) -> Result<PathBuf> {
    let as_path = Path::new(name_or_path);
    if as_path.is_file() {
        return Ok(as_path.to_path_buf());
    }
    let looks_like_path = name_or_path.contains('/') || !extension(as_path).is_empty();
    if looks_like_path {
        return Err(Error::Io(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no such file",
        )));
    }
    for dir in data_dirs() {
        for ext in EXTENSIONS {
            let candidate = dir.join(format!("{name_or_path}.{ext}"));
            if candidate.is_file() {
                return Ok(candidate);
            }
        }
    }
    let known = known_names();
    Err(Error::Unsupported(if known.is_empty() {
        "unknown mesh name and no data folder found (set MESHCODEC_DATA)".to_string()
    } else {
        format!("unknown mesh name; known names: {}", known.join(", "))
    }))
}

/// The short name of a mesh path: its file stem.
pub fn mesh_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn ply_and_obj_writers_round_trip_exactly() {
        let mesh = generate::torus(1.0, 0.3, 12, 7);
        for format in ["ply", "obj"] {
            let mut bytes = Vec::new();
            match format {
                "ply" => write_ply(&mesh, &mut bytes).unwrap(),
                _ => write_obj(&mesh, &mut bytes).unwrap(),
            }
            let back = read_mesh_bytes(&bytes, format).unwrap();
            // tobj numbers OBJ vertices by first use, so only PLY keeps the vertex order.
            if format == "ply" {
                assert!(back == mesh, "ply changed the mesh");
            }
            let sorted = |m: &TriMesh| {
                let mut corners: Vec<[[u64; 3]; 3]> = m
                    .faces
                    .iter()
                    .map(|f| f.map(|v| m.positions[v as usize].to_array().map(f64::to_bits)))
                    .map(|c| {
                        let k = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
                        [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
                    })
                    .collect();
                corners.sort_unstable();
                corners
            };
            assert!(sorted(&back) == sorted(&mesh), "{format} changed the mesh");
        }
    }

    fn shared(name: &str) -> Option<PathBuf> {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../shared/meshes")
            .join(name);
        path.exists().then_some(path)
    }

    /// Written and read again, an attributed mesh is the same mesh: positions, faces, wedges,
    /// attributes and materials.
    fn assert_round_trips(mesh: &AttributedMesh, format: &str) {
        let bytes = write_attributed_bytes(mesh, format).unwrap();
        let back = read_attributed_bytes(&bytes, format).unwrap();
        assert_eq!(
            back.attributes.wedge_count(),
            mesh.attributes.wedge_count(),
            "{format}"
        );
        if format == "ply" {
            assert!(back == *mesh, "ply changed the attributed mesh");
        }
        // OBJ renumbers vertices by first use: compare what each corner carries.
        let corners = |m: &AttributedMesh| {
            let mut all: Vec<String> = (0..m.mesh.faces.len())
                .map(|f| {
                    let material = m
                        .attributes
                        .materials
                        .as_ref()
                        .map(|x| x.names[x.face[f] as usize].clone());
                    let c: Vec<String> = (0..3)
                        .map(|k| {
                            let p = m.mesh.positions[m.mesh.faces[f][k] as usize];
                            format!("{p:?} {:?}", m.attributes.corner(f, k))
                        })
                        .collect();
                    format!("{c:?} {material:?}")
                })
                .collect();
            all.sort();
            all
        };
        assert!(
            corners(&back) == corners(mesh),
            "{format} changed the corners"
        );
    }

    #[test]
    fn textured_obj_files_keep_their_seams_and_materials() {
        let Some(path) = shared("bunny-10k-textured.obj") else {
            return;
        };
        let mesh = read_attributed(&path).unwrap();
        let a = &mesh.attributes;
        let uvs = a.uvs.as_ref().expect("uvs");
        assert!(a.normals.is_none() && a.colours.is_none());
        // More wedges than vertices: the seams.
        assert!(
            a.wedge_count() > mesh.mesh.positions.len(),
            "{}",
            a.wedge_count()
        );
        assert_eq!(uvs.len(), a.wedge_count());
        let materials = a.materials.as_ref().expect("usemtl");
        assert_eq!(
            materials.library.as_deref(),
            Some("./bunny10k_textured.mtl")
        );
        assert_eq!(materials.face.len(), mesh.mesh.faces.len());
        assert_round_trips(&mesh, "obj");
        // PLY keeps the seams as per-face texcoord lists, and refuses the materials.
        assert!(write_attributed_bytes(&mesh, "ply").is_err());
        let mut no_materials = mesh.clone();
        no_materials.attributes.materials = None;
        assert_round_trips(&no_materials, "ply");
    }

    #[test]
    fn ply_normals_and_colours_round_trip_per_vertex() {
        for name in ["airplane-colored.ply", "dragon-res3.ply"] {
            let Some(path) = shared(name) else {
                continue;
            };
            let mesh = read_attributed(&path).unwrap();
            let a = &mesh.attributes;
            assert!(a.colours.is_some() || a.normals.is_some(), "{name}");
            assert!(a.per_vertex(mesh.mesh.positions.len()), "{name}");
            assert_round_trips(&mesh, "ply");
            let translucent = a.colours.iter().flatten().any(|c| c[3] != 1.0);
            if translucent {
                // OBJ has no alpha: refused rather than dropped.
                let e = write_attributed_bytes(&mesh, "obj")
                    .unwrap_err()
                    .to_string();
                assert!(e.contains("alpha"), "{e}");
            } else {
                assert_round_trips(&mesh, "obj");
            }
        }
    }

    #[test]
    fn readers_that_cannot_keep_appearance_refuse_it() {
        let m = "Vertex 1 0 0 0 {normal=(0 0 1)}\nVertex 2 1 0 0\nVertex 3 0 1 0\nFace 1 1 2 3\n";
        let e = read_attributed_bytes(m.as_bytes(), "m")
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 normal"), "{e}");
        let off = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n";
        let e = read_attributed_bytes(off.as_bytes(), "off")
            .unwrap_err()
            .to_string();
        assert!(e.contains("colours"), "{e}");
        let plain = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        assert!(read_attributed_bytes(plain.as_bytes(), "off")
            .unwrap()
            .attributes
            .is_empty());
    }
}
