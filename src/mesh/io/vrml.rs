//! A plain VRML 2.0 writer: one Shape with an IndexedFaceSet, as the paper tables' "VRML"
//! columns count it (Grabner's Table 2 gives every model's plain and gzip'd VRML size). Write
//! only: no reader takes VRML.

use crate::mesh::TriMesh;
use std::fmt::Write as _;
use std::io::Write;

/// Writes `mesh` as a VRML 2.0 IndexedFaceSet: coordinates as the shortest decimals that read
/// back as the same 32-bit floats, one point and one face (ending in −1) a line.
pub fn write_vrml(mesh: &TriMesh, out: &mut impl Write) -> std::io::Result<()> {
    let mut text = String::with_capacity(mesh.positions.len() * 32 + mesh.faces.len() * 24);
    text.push_str(
        "#VRML V2.0 utf8\nShape {\n geometry IndexedFaceSet {\n  coord Coordinate {\n   point [\n",
    );
    for p in &mesh.positions {
        let _ = writeln!(text, "{} {} {},", p.x as f32, p.y as f32, p.z as f32);
    }
    text.push_str("   ]\n  }\n  coordIndex [\n");
    for [a, b, c] in &mesh.faces {
        let _ = writeln!(text, "{a}, {b}, {c}, -1,");
    }
    text.push_str("  ]\n }\n}\n");
    out.write_all(text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_is_one_shape_with_three_points_and_one_face() {
        let mesh = TriMesh::new(
            vec![
                glam::DVec3::ZERO,
                glam::DVec3::new(1.5, 0.0, 0.0),
                glam::DVec3::new(0.0, -0.25, 1e-3),
            ],
            vec![[0, 1, 2]],
        );
        let mut bytes = Vec::new();
        write_vrml(&mesh, &mut bytes).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert!(text.starts_with("#VRML V2.0 utf8\n"));
        assert!(text.contains("1.5 0 0,\n0 -0.25 0.001,\n"), "{text}");
        assert!(text.contains("0, 1, 2, -1,\n"), "{text}");
        assert_eq!(text.matches('{').count(), text.matches('}').count());
    }
}
