//! Mesh files: readers for OBJ, PLY, OFF, STL, Hoppe's `.m` and glTF 2.0; writers for PLY, OBJ,
//! VRML and glTF; OBJ, PLY and glTF with their appearance (wedges and materials,
//! `read_attributed` / `write_attributed`); and the lookup of mesh names in the data folders
//! (`$MESHCODEC_DATA`, then ../shared/meshes).
//!
//! Readers return the mesh as stored (unreferenced vertices kept where the format keeps them),
//! validated: finite coordinates, indices in range, at least one face.

mod appearance;
mod gltf;
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
pub const EXTENSIONS: [&str; 7] = ["ply", "obj", "off", "m", "stl", "gltf", "glb"];

/// Reads a mesh, choosing the reader by the file's extension: positions and triangles only
/// ([`read_mesh_and_appearance`] says what else the file holds).
pub fn read_mesh(path: &Path) -> Result<TriMesh> {
    let ext = extension(path);
    if is_gltf(&ext) {
        return Ok(read_attributed(path)?.mesh);
    }
    let bytes = std::fs::read(path)?;
    read_by_extension(&bytes, &ext)
}

fn is_gltf(ext: &str) -> bool {
    ext == "gltf" || ext == "glb"
}

/// What a glTF mesh carries, counted as [`appearance_of`] counts other files' attributes.
fn gltf_appearance(m: &AttributedMesh) -> Appearance {
    let a = &m.attributes;
    let wedges = |present: bool| if present { a.wedge_count() } else { 0 };
    Appearance {
        normals: wedges(a.normals.is_some()),
        uvs: wedges(a.uvs.is_some()),
        colours: wedges(a.colours.is_some()),
        materials: a
            .materials
            .as_ref()
            .map_or(0, |m| m.names.iter().filter(|n| !n.is_empty()).count()),
    }
}

/// Reads a mesh as [`read_mesh`] does, and counts the appearance attributes (normals, texture
/// coordinates, colours, materials) the file holds beyond it, which the mesh does not carry.
pub fn read_mesh_and_appearance(path: &Path) -> Result<(TriMesh, Appearance)> {
    let ext = extension(path);
    if is_gltf(&ext) {
        let m = read_attributed(path)?;
        let found = gltf_appearance(&m);
        return Ok((m.mesh, found));
    }
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
        "gltf" | "glb" => gltf::read_attributed(bytes, None)?.mesh,
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
/// materials — by the file's extension. OBJ, PLY and glTF carry them; a file of another format that
/// holds appearance the reader cannot keep yet (OFF colours, `.m` normals) is refused, naming it.
pub fn read_attributed(path: &Path) -> Result<AttributedMesh> {
    let ext = extension(path);
    let bytes = std::fs::read(path)?;
    if is_gltf(&ext) {
        // A .gltf file's buffers may be files beside it.
        let m = gltf::read_attributed(&bytes, path.parent())?;
        m.mesh.validate()?;
        return Ok(m);
    }
    read_attributed_bytes(&bytes, &ext)
}

/// [`read_attributed`] from bytes in the given format.
pub fn read_attributed_bytes(bytes: &[u8], format: &str) -> Result<AttributedMesh> {
    let read = match format {
        "obj" => obj::read_attributed(bytes)?,
        "ply" => ply::read_attributed(bytes)?,
        // Embedded buffers only: from bytes there is no folder to find others in.
        "gltf" | "glb" => gltf::read_attributed(bytes, None)?,
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

/// Writes a mesh with its appearance as OBJ, PLY or glTF (`.gltf`, `.glb`) by the extension of
/// `path` (each holds what it can: a file that cannot hold some of the appearance is refused,
/// naming it), atomically.
pub fn write_attributed(mesh: &AttributedMesh, path: &Path) -> Result<()> {
    let bytes = write_attributed_bytes(mesh, &extension(path))?;
    write_atomically(path, &bytes)
}

/// [`write_attributed`] to bytes in the given format.
pub fn write_attributed_bytes(mesh: &AttributedMesh, format: &str) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    match format {
        "ply" => ply::write_attributed(mesh, &mut bytes)?,
        "obj" => obj::write_attributed(mesh, &mut bytes)?,
        "glb" => bytes = gltf::write_attributed(mesh, true)?,
        "gltf" => bytes = gltf::write_attributed(mesh, false)?,
        other => {
            return Err(Error::Unsupported(format!(
                "output format '.{other}' with attributes (writers: ply, obj, gltf, glb)"
            )))
        }
    }
    Ok(bytes)
}

/// The formats, of those [`write_attributed`] writes, that can hold `mesh` with all it carries
/// (PLY holds no materials and normals or colours per vertex only, OBJ colours per vertex
/// without alpha): what to suggest when one refuses it.
pub fn formats_holding(mesh: &AttributedMesh) -> Vec<&'static str> {
    ["ply", "obj", "glb", "gltf"]
        .into_iter()
        .filter(|format| write_attributed_bytes(mesh, format).is_ok())
        .collect()
}

/// Reads a mesh from bytes in the given format (an extension such as "ply").
pub fn read_mesh_bytes(bytes: &[u8], format: &str) -> Result<TriMesh> {
    read_by_extension(bytes, format)
}

/// Writes `mesh` as binary PLY (double positions), OBJ, VRML or glTF (`.gltf` with the buffer
/// embedded, `.glb`; single-precision positions), by the extension of `path`. The file
/// appears only when it is complete: it is written beside and renamed into place.
pub fn write_mesh(mesh: &TriMesh, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    match extension(path).as_str() {
        "ply" => write_ply(mesh, &mut bytes)?,
        "obj" => write_obj(mesh, &mut bytes)?,
        "wrl" => vrml::write_vrml(mesh, &mut bytes)?,
        "gltf" | "glb" => {
            let plain = AttributedMesh {
                mesh: mesh.clone(),
                attributes: Attributes::default(),
            };
            bytes = gltf::write_attributed(&plain, extension(path) == "glb")?;
        }
        other => {
            return Err(Error::Unsupported(format!(
                "output format '.{other}' (writers: ply, obj, wrl, gltf, glb)"
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
/// working directory, then the per-user cache ([`cache_dir`], where `meshcodec data fetch`
/// puts the meshes it downloads). (Within the repository, cargo sets `MESHCODEC_DATA` to the
/// `../shared/meshes` beside it for the programs and tests it runs: .cargo/config.toml.)
pub fn data_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os("MESHCODEC_DATA").filter(|d| !d.is_empty()) {
        dirs.push(PathBuf::from(d));
    }
    dirs.push(PathBuf::from("../shared/meshes"));
    if let Some(cache) = cache_dir() {
        dirs.push(cache);
    }
    dirs
}

/// The per-user folder of downloaded meshes: `$MESHCODEC_CACHE`, else
/// `$XDG_CACHE_HOME/meshcodec/meshes`, else `~/.cache/meshcodec/meshes` (`%LOCALAPPDATA%` on
/// Windows); `None` when none of these is set.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |name: &str| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(dir) = var("MESHCODEC_CACHE") {
        return Some(dir);
    }
    let base = var("XDG_CACHE_HOME")
        .or_else(|| var("HOME").map(|h| h.join(".cache")))
        .or_else(|| var("LOCALAPPDATA"))?;
    Some(base.join("meshcodec").join("meshes"))
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

/// Turns a path or a bare name into a mesh file: a path that exists is used as it is; a file
/// name (`spot.obj`) is looked up as it is in [`data_dirs`], a bare name as `<name>.*` there
/// (extensions in the order of [`EXTENSIONS`]). The path
/// returned is absolute, so that it still names the file from another working directory (a
/// program run in a scratch folder, a test's temporary directory).
pub fn resolve(name_or_path: &str) -> Result<PathBuf> {
    let as_path = Path::new(name_or_path);
    if as_path.is_file() {
        return Ok(std::path::absolute(as_path)?);
    }
    if name_or_path.contains('/') {
        return Err(Error::Io(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no such file",
        )));
    }
    // A file name with its extension (`spot.obj`) is looked up as it is.
    if !extension(as_path).is_empty() {
        if let Some(found) = data_dirs()
            .iter()
            .map(|dir| dir.join(name_or_path))
            .find(|candidate| candidate.is_file())
        {
            return Ok(std::fs::canonicalize(&found)?);
        }
        return Err(Error::Io(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no such file",
        )));
    }
    for dir in data_dirs() {
        for ext in EXTENSIONS {
            let candidate = dir.join(format!("{name_or_path}.{ext}"));
            if candidate.is_file() {
                return Ok(std::fs::canonicalize(&candidate)?);
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

/// How results name the file a mesh was read from, the same on every machine: a file of a data
/// folder as `../shared/meshes/<file>` or `$MESHCODEC_DATA/<file>`, a file under the working
/// directory relative to it, any other by its absolute path.
pub fn portable_source(path: &Path) -> String {
    let file = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let (Some(folder), Some(name)) = (file.parent(), file.file_name()) else {
        return path.display().to_string();
    };
    let name = name.to_string_lossy();
    let same_folder = |dir: &Path| std::fs::canonicalize(dir).is_ok_and(|d| d == folder);
    if std::env::var_os("MESHCODEC_DATA").is_some_and(|d| same_folder(Path::new(&d))) {
        return format!("$MESHCODEC_DATA/{name}");
    }
    if data_dirs().iter().any(|d| same_folder(d)) {
        return format!("../shared/meshes/{name}");
    }
    std::env::current_dir()
        .ok()
        .and_then(|cwd| std::fs::canonicalize(cwd).ok())
        .and_then(|cwd| file.strip_prefix(cwd).ok().map(Path::to_path_buf))
        .unwrap_or(file)
        .display()
        .to_string()
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

    /// PLY elements are read in file order whatever it is, each into its own kind of record:
    /// faces before vertices, an element we do not know between them (read past), strips and
    /// faces together; the attributed reader of a file without attributes returns none.
    #[test]
    fn ply_elements_in_any_order_and_unknown_elements_read_past() {
        let ply = "ply\nformat ascii 1.0\n\
            element face 2\nproperty list uchar int vertex_indices\n\
            element camera 1\nproperty float view_px\nproperty list uchar float extra\n\
            element vertex 5\nproperty double x\nproperty double y\nproperty float z\n\
            element tristrips 1\nproperty list int int vertex_indices\n\
            end_header\n\
            3 0 1 2\n4 0 2 3 4\n\
            1.5 2 0.25 0.5\n\
            0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 2 0\n\
            4 2 3 4 -1\n";
        let read = read_attributed_bytes(ply.as_bytes(), "ply").unwrap();
        assert_eq!(read.mesh.positions.len(), 5);
        assert_eq!(read.mesh.positions[4], glam::DVec3::new(0.5, 2.0, 0.0));
        // The triangle, the quad's fan (0 2 3, 0 3 4), the strip's triangle.
        assert_eq!(
            read.mesh.faces,
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [2, 3, 4]]
        );
        assert!(read.attributes.is_empty());
        assert_eq!(
            read_by_extension(ply.as_bytes(), "ply").unwrap().faces,
            read.mesh.faces
        );
    }

    /// The mesh at single precision, as glTF holds it.
    fn single(mut m: AttributedMesh) -> AttributedMesh {
        let f = |x: f64| x as f32 as f64;
        m.mesh
            .positions
            .iter_mut()
            .for_each(|p| *p = p.to_array().map(f).into());
        let a = &mut m.attributes;
        a.normals
            .iter_mut()
            .flatten()
            .for_each(|n| *n = n.to_array().map(f).into());
        a.uvs
            .iter_mut()
            .flatten()
            .for_each(|t| *t = t.to_array().map(f).into());
        a.colours.iter_mut().flatten().for_each(|c| *c = c.map(f));
        m
    }

    #[test]
    fn gltf_keeps_seams_materials_normals_and_colours() {
        for name in [
            "bunny-10k-textured.obj",
            "airplane-colored.ply",
            "dragon-res3.ply",
        ] {
            let Some(path) = shared(name) else {
                continue;
            };
            let mut mesh = single(read_attributed(&path).unwrap());
            if let Some(m) = &mut mesh.attributes.materials {
                m.library = None; // glTF names materials, it has no library file
            }
            for format in ["glb", "gltf"] {
                let bytes = write_attributed_bytes(&mesh, format).unwrap();
                let back = read_attributed_bytes(&bytes, format).unwrap();
                // glTF vertices are wedges: welded again by position, the wedges come back.
                assert_eq!(
                    back.attributes.wedge_count(),
                    mesh.attributes.wedge_count(),
                    "{name} {format}"
                );
                assert_eq!(back.mesh.faces.len(), mesh.mesh.faces.len());
                if mesh.attributes.wedge_count() > 0 && name != "dragon-res3.ply" {
                    // Vertices come back in first-use order; compare what every corner holds.
                    assert_round_trips(&mesh, format);
                }
            }
        }
    }

    #[test]
    fn gltf_files_with_buffers_beside_them_read_and_bytes_alone_refuse_them() {
        let dir = tempfile::tempdir().unwrap();
        let mesh = AttributedMesh {
            mesh: crate::mesh::generate::icosphere(1),
            attributes: Attributes::default(),
        };
        let mesh = single(mesh);
        let embedded = write_attributed_bytes(&mesh, "gltf").unwrap();
        // Move the buffer out into a file of its own, as exporters often write them.
        let mut json: serde_json::Value = serde_json::from_slice(&embedded).unwrap();
        let uri = json["buffers"][0]["uri"].as_str().unwrap().to_string();
        let data = uri.split_once(";base64,").unwrap().1;
        use base64::Engine as _;
        let bin = base64::engine::general_purpose::STANDARD
            .decode(data)
            .unwrap();
        std::fs::write(dir.path().join("mesh.bin"), bin).unwrap();
        json["buffers"][0]["uri"] = "mesh.bin".into();
        let text = serde_json::to_vec(&json).unwrap();
        let path = dir.path().join("mesh.gltf");
        std::fs::write(&path, &text).unwrap();
        let back = read_mesh(&path).unwrap();
        assert_eq!(back.faces.len(), mesh.mesh.faces.len());
        let e = read_attributed_bytes(&text, "gltf")
            .unwrap_err()
            .to_string();
        assert!(e.contains("file of its own"), "{e}");
        json["buffers"][0]["uri"] = "../outside.bin".into();
        std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
        assert!(read_mesh(&path).unwrap_err().to_string().contains("beside"));
    }

    #[test]
    fn gltf_split_vertices_weld_into_wedges_placed_by_their_node() {
        // fuzz/seeds/read_gltf: a torus split at its uv seams, normals, two materials, the node
        // translated by (0, 0, 1); as .gltf with an embedded buffer and as .glb.
        let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/read_gltf");
        let gltf = read_attributed(&seeds.join("torus.gltf")).unwrap();
        let glb = read_attributed(&seeds.join("torus.glb")).unwrap();
        assert!(gltf == glb);
        let (mesh, a) = (&gltf.mesh, &gltf.attributes);
        // 8 x 5 positions; the seams split the wrap-around rows: 9 x 6 glTF vertices.
        assert_eq!(mesh.positions.len(), 40);
        assert_eq!(a.wedge_count(), 54);
        assert_eq!(mesh.faces.len(), 80);
        assert!(a.normals.is_some() && a.colours.is_none());
        let materials = a.materials.as_ref().unwrap();
        assert_eq!(materials.names, ["inside", "outside"]);
        assert_eq!(materials.face.iter().filter(|&&m| m == 1).count(), 40);
        let lowest = mesh
            .positions
            .iter()
            .map(|p| p.z)
            .fold(f64::INFINITY, f64::min);
        // The tube's lowest sample, 0.4·sin(4/5 turn) below its centre, lifted by 1.
        let expected = 1.0 + 0.4 * (std::f64::consts::TAU * 0.8).sin();
        assert!(
            (lowest - expected).abs() < 1e-6,
            "{lowest}: the node's translation"
        );
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
