//! What a mesh file holds beyond positions and triangles — normals, texture coordinates,
//! colours, materials — counted so that nothing is dropped without a word: [`TriMesh`] (and so
//! every codec of this build) carries geometry only, and the binaries refuse to encode a file
//! with appearance unless asked to drop it.
//!
//! The count is a scan of the file apart from its reader, by the format's own names: OBJ `vn`,
//! `vt`, colours after `v`'s coordinates and `usemtl`; PLY vertex properties `nx ny nz`, `red
//! green blue alpha` (or `r g b a`, `diffuse_…`), `u v` / `s t` / `texture_u texture_v` /
//! `texture_s texture_t` and face `texcoord` lists; OFF's `N`, `C` and `ST` prefixes; `.m`'s
//! `normal=`, `uv=`, `rgb=` on vertices and corners and `matid=` on faces. STL holds none.
//!
//! [`TriMesh`]: crate::mesh::TriMesh

use std::collections::HashSet;
use std::fmt;

/// Appearance attributes found in a file, by count.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Appearance {
    /// Normals (per vertex or per corner, as stored).
    pub normals: usize,
    /// Texture coordinates.
    pub uvs: usize,
    /// Colours (per vertex or per corner).
    pub colours: usize,
    /// Distinct materials.
    pub materials: usize,
}

impl Appearance {
    /// Whether the file holds no appearance.
    pub fn is_empty(&self) -> bool {
        *self == Appearance::default()
    }
}

impl fmt::Display for Appearance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let parts: Vec<String> = [
            (self.normals, "normal", "normals"),
            (self.uvs, "texture coordinate", "texture coordinates"),
            (self.colours, "colour", "colours"),
            (self.materials, "material", "materials"),
        ]
        .into_iter()
        .filter(|&(n, _, _)| n > 0)
        .map(|(n, one, many)| format!("{n} {}", if n == 1 { one } else { many }))
        .collect();
        if parts.is_empty() {
            write!(f, "no appearance attributes")
        } else {
            write!(f, "{}", parts.join(", "))
        }
    }
}

/// The appearance held by `bytes`, a file of `format` (an extension) whose mesh has `vertices`
/// vertices and `faces` faces as read.
pub fn appearance_of(bytes: &[u8], format: &str, vertices: usize, faces: usize) -> Appearance {
    let text = String::from_utf8_lossy(bytes);
    match format {
        "obj" => obj(&text),
        "ply" => ply(bytes, vertices, faces),
        "off" => off(&text, vertices),
        "m" => m(&text),
        _ => Appearance::default(),
    }
}

fn obj(text: &str) -> Appearance {
    let mut found = Appearance::default();
    let mut materials = HashSet::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("vn") => found.normals += 1,
            Some("vt") => found.uvs += 1,
            // `v x y z r g b`: a colour after the coordinates (a fourth number alone is w).
            Some("v") if words.count() >= 6 => found.colours += 1,
            Some("usemtl") => {
                materials.insert(line.trim().to_string());
            }
            _ => {}
        }
    }
    found.materials = materials.len();
    found
}

fn ply(bytes: &[u8], vertices: usize, faces: usize) -> Appearance {
    // The header is ASCII up to `end_header`, whatever the body's encoding.
    let end = bytes
        .windows(10)
        .position(|w| w == b"end_header")
        .unwrap_or(bytes.len());
    let header = String::from_utf8_lossy(&bytes[..end]);
    let mut found = Appearance::default();
    let mut element = String::new();
    let (mut normal, mut colour, mut uv) = (false, false, false);
    let mut face_uvs = false;
    for line in header.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["element", name, ..] => element = name.to_string(),
            ["property", .., name] if element == "vertex" => match *name {
                "nx" | "ny" | "nz" => normal = true,
                "red" | "green" | "blue" | "alpha" | "r" | "g" | "b" | "a" => colour = true,
                n if n.starts_with("diffuse_") => colour = true,
                "u" | "v" | "s" | "t" | "texture_u" | "texture_v" | "texture_s" | "texture_t" => {
                    uv = true
                }
                _ => {}
            },
            ["property", "list", .., name] if element == "face" && name.starts_with("texcoord") => {
                face_uvs = true
            }
            _ => {}
        }
    }
    if normal {
        found.normals = vertices;
    }
    if colour {
        found.colours = vertices;
    }
    if uv {
        found.uvs = vertices;
    }
    if face_uvs {
        found.uvs += 3 * faces;
    }
    found
}

fn off(text: &str, vertices: usize) -> Appearance {
    let keyword = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .find(|l| !l.is_empty())
        .and_then(|l| l.split_whitespace().next())
        .unwrap_or("");
    let prefix = keyword.strip_suffix("OFF").unwrap_or("");
    let mut found = Appearance::default();
    if prefix.contains("ST") {
        found.uvs = vertices;
    }
    if prefix.contains('C') {
        found.colours = vertices;
    }
    if prefix.contains('N') {
        found.normals = vertices;
    }
    found
}

fn m(text: &str) -> Appearance {
    let mut found = Appearance::default();
    let mut materials = HashSet::new();
    for line in text.lines() {
        let record = line.split_whitespace().next().unwrap_or("");
        let Some(braces) = line.split_once('{').map(|(_, rest)| rest) else {
            continue;
        };
        match record {
            "Vertex" | "Corner" => {
                found.normals += braces.contains("normal=") as usize;
                found.uvs += braces.contains("uv=") as usize;
                found.colours += braces.contains("rgb=") as usize;
            }
            "Face" => {
                if let Some(at) = braces.find("matid=") {
                    let id: String = braces[at + 6..]
                        .chars()
                        .take_while(|c| !c.is_whitespace() && *c != '}')
                        .collect();
                    materials.insert(id);
                }
            }
            _ => {}
        }
    }
    found.materials = materials.len();
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_format_reports_what_it_holds_beyond_geometry() {
        let obj = "v 0 0 0\nv 1 0 0 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/1/1\nusemtl b\nusemtl a\n";
        let found = appearance_of(obj.as_bytes(), "obj", 3, 1);
        assert_eq!(
            found,
            Appearance {
                normals: 1,
                uvs: 2,
                colours: 1,
                materials: 2
            }
        );
        assert_eq!(
            found.to_string(),
            "1 normal, 2 texture coordinates, 1 colour, 2 materials"
        );
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty float confidence\nelement face 1\nproperty list uchar int vertex_indices\nproperty list uchar float texcoord\nend_header\n";
        let found = appearance_of(ply.as_bytes(), "ply", 3, 1);
        assert_eq!((found.colours, found.uvs, found.normals), (3, 3, 0));
        assert_eq!(appearance_of(b"CNOFF\n3 1 0\n", "off", 3, 1).normals, 3);
        assert_eq!(
            appearance_of(b"OFF\n3 1 0\n", "off", 3, 1),
            Appearance::default()
        );
        let m = "Vertex 1 0 0 0 {normal=(0 0 1)}\nVertex 2 1 0 0\nCorner 1 1 {uv=(0 0)}\nFace 1 1 2 3 {matid=4}\n";
        let found = appearance_of(m.as_bytes(), "m", 3, 1);
        assert_eq!((found.normals, found.uvs, found.materials), (1, 1, 1));
        assert!(appearance_of(b"solid x\nendsolid\n", "stl", 0, 0).is_empty());
    }
}
