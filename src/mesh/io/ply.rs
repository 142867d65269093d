//! PLY through `ply-rs-bw`: ASCII, binary little- and big-endian; positions of any numeric type;
//! faces as `face` lists (`vertex_indices` or `vertex_index`) or `tristrips` (−1 separated
//! strips, alternate triangles flipped to keep one orientation). [`read_attributed`] also takes
//! vertex normals (`nx ny nz`), colours (`red green blue [alpha]`, integers over their type's
//! range or floats in [0, 1]), texture coordinates (`s t`, `u v`, `texture_u texture_v` or
//! `texture_s texture_t`) and per-face `texcoord` lists (a uv a corner, where seams are).
//! Other elements and properties are read past and ignored.

use crate::error::{Error, Result};
use crate::mesh::attributes::{AttributedMesh, Attributes, Corner};
use crate::mesh::TriMesh;
use glam::{DVec2, DVec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};
use smallvec::SmallVec;

/// A vertex as we need it: a position and its attributes. Each element is read into a record
/// of its own kind (a million faces in records with room for a vertex's fields, and the other
/// way round, cost hundreds of megabytes).
#[derive(Default)]
struct VertexRecord {
    xyz: [f64; 3],
    normal: [f64; 3],
    /// RGBA in [0, 1]; alpha 1 unless the file gives it.
    colour: [f64; 4],
    uv: [f64; 2],
}

/// A face or a triangle strip: its index list (a triangle's held inline) and corner uvs.
#[derive(Default)]
struct FaceRecord {
    indices: SmallVec<[i64; 4]>,
    /// A face's corner uvs, two numbers a corner.
    texcoord: Vec<f64>,
}

/// Any other element, read past.
struct Skipped;

/// A colour channel in [0, 1]: integers over their type's range, floats as they are.
fn channel(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::UChar(v) => v as f64 / 255.0,
        Property::UShort(v) => v as f64 / 65535.0,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn float_list(p: Property) -> Option<Vec<f64>> {
    Some(match p {
        Property::ListFloat(v) => v.into_iter().map(f64::from).collect(),
        Property::ListDouble(v) => v,
        _ => return None,
    })
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => v as f64,
        Property::UChar(v) => v as f64,
        Property::Short(v) => v as f64,
        Property::UShort(v) => v as f64,
        Property::Int(v) => v as f64,
        Property::UInt(v) => v as f64,
        Property::Float(v) => v as f64,
        Property::Double(v) => v,
        _ => return None,
    })
}

fn integer_list(p: Property) -> Option<SmallVec<[i64; 4]>> {
    fn widen<T: Copy + Into<i64>>(v: Vec<T>) -> SmallVec<[i64; 4]> {
        v.into_iter().map(Into::into).collect()
    }
    Some(match p {
        Property::ListChar(v) => widen(v),
        Property::ListUChar(v) => widen(v),
        Property::ListShort(v) => widen(v),
        Property::ListUShort(v) => widen(v),
        Property::ListInt(v) => widen(v),
        Property::ListUInt(v) => widen(v),
        _ => return None,
    })
}

impl PropertyAccess for VertexRecord {
    fn new() -> Self {
        VertexRecord {
            colour: [0.0, 0.0, 0.0, 1.0],
            ..VertexRecord::default()
        }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let set = |slot: &mut f64, value: Option<f64>| match value {
            Some(v) => {
                *slot = v;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::UnsupportedType,
        };
        match name {
            "x" => set(&mut self.xyz[0], scalar(&property)),
            "y" => set(&mut self.xyz[1], scalar(&property)),
            "z" => set(&mut self.xyz[2], scalar(&property)),
            "nx" => set(&mut self.normal[0], scalar(&property)),
            "ny" => set(&mut self.normal[1], scalar(&property)),
            "nz" => set(&mut self.normal[2], scalar(&property)),
            "red" => set(&mut self.colour[0], channel(&property)),
            "green" => set(&mut self.colour[1], channel(&property)),
            "blue" => set(&mut self.colour[2], channel(&property)),
            "alpha" => set(&mut self.colour[3], channel(&property)),
            "s" | "u" | "texture_u" | "texture_s" => set(&mut self.uv[0], scalar(&property)),
            "t" | "v" | "texture_v" | "texture_t" => set(&mut self.uv[1], scalar(&property)),
            _ => PropertyAccessResult::Ignored,
        }
    }
}

impl PropertyAccess for FaceRecord {
    fn new() -> Self {
        FaceRecord::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        match name {
            "vertex_indices" | "vertex_index" => match integer_list(property) {
                Some(list) => {
                    self.indices = list;
                    PropertyAccessResult::Set
                }
                None => PropertyAccessResult::UnsupportedType,
            },
            "texcoord" => match float_list(property) {
                Some(list) => {
                    self.texcoord = list;
                    PropertyAccessResult::Set
                }
                None => PropertyAccessResult::UnsupportedType,
            },
            _ => PropertyAccessResult::Ignored,
        }
    }
}

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }

    fn set_property(&mut self, _: &str, _: Property) -> PropertyAccessResult {
        PropertyAccessResult::Ignored
    }
}

/// Which attributes the vertex and face elements declare.
struct Declared {
    normals: bool,
    colours: bool,
    uvs: bool,
    face_uvs: bool,
}

impl Declared {
    fn of(header: &Header) -> Declared {
        let vertex = |names: &[&str]| {
            header
                .elements
                .get("vertex")
                .is_some_and(|e| names.iter().all(|n| e.properties.contains_key(*n)))
        };
        let any_pair = ["s", "u", "texture_u", "texture_s"]
            .iter()
            .zip(["t", "v", "texture_v", "texture_t"])
            .any(|(a, b)| vertex(&[a, b]));
        Declared {
            normals: vertex(&["nx", "ny", "nz"]),
            colours: vertex(&["red", "green", "blue"]),
            uvs: any_pair,
            face_uvs: header
                .elements
                .get("face")
                .is_some_and(|e| e.properties.contains_key("texcoord")),
        }
    }
}

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    Ok(load(bytes, false)?.mesh)
}

/// The mesh with its wedges: one a vertex, split where face `texcoord` lists make seams.
pub fn read_attributed(bytes: &[u8]) -> Result<AttributedMesh> {
    load(bytes, true)
}

fn load(bytes: &[u8], with_attributes: bool) -> Result<AttributedMesh> {
    // ply-rs reports over several lines; errors here are one line (docs/CONTRACT.md §7).
    let fault = |e: ply_rs_bw::parser::ParseError| {
        Error::mesh(format!("PLY: {}", one_line(&e.to_string())))
    };
    let mut reader = Reader::new(bytes);
    let header = Parser::<Skipped>::new()
        .read_header(&mut reader)
        .map_err(fault)?;
    check_counts(&header, bytes)?;
    // The elements in file order, each into its own kind of record.
    let (mut vertices, mut face_records, mut strips) = (Vec::new(), Vec::new(), Vec::new());
    for (name, def) in &header.elements {
        match name.as_str() {
            "vertex" => {
                vertices = Parser::<VertexRecord>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(fault)?
            }
            "face" | "tristrips" => {
                let records = Parser::<FaceRecord>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(fault)?;
                if name == "face" {
                    face_records = records;
                } else {
                    strips = records;
                }
            }
            _ => {
                Parser::<Skipped>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(fault)?;
            }
        }
    }
    let vertex_def = header
        .elements
        .get("vertex")
        .ok_or_else(|| Error::mesh("PLY: no vertex element"))?;
    for axis in ["x", "y", "z"] {
        if !vertex_def.properties.contains_key(axis) {
            return Err(Error::mesh(format!("PLY: vertex has no '{axis}' property")));
        }
    }
    let positions: Vec<DVec3> = vertices.iter().map(|r| DVec3::from(r.xyz)).collect();
    let n = positions.len() as i64;
    let index = |i: i64| -> Result<u32> {
        if (0..n).contains(&i) {
            Ok(i as u32)
        } else {
            Err(Error::mesh(format!(
                "PLY: face index {i} out of range ({n} vertices)"
            )))
        }
    };
    let declared = Declared::of(&header);
    // Corners are gathered only from a file that declares some attribute (a million faces of
    // attribute-less corners would cost hundreds of megabytes to find nothing).
    let with_attributes = with_attributes
        && (declared.normals || declared.colours || declared.uvs || declared.face_uvs);
    // What a corner of vertex v carries from the vertex element.
    let vertex_corner = |v: u32| {
        let r = &vertices[v as usize];
        Corner {
            normal: declared.normals.then(|| DVec3::from(r.normal)),
            uv: declared.uvs.then(|| DVec2::from(r.uv)),
            colour: declared.colours.then_some(r.colour),
        }
    };
    let mut faces = Vec::new();
    let mut corners: Vec<[Corner; 3]> = Vec::new();
    for (f, record) in face_records.iter().enumerate() {
        let polygon = record
            .indices
            .iter()
            .map(|&i| index(i))
            .collect::<Result<Vec<u32>>>()?;
        let first = faces.len();
        super::text::fan(&polygon, &mut faces);
        if !with_attributes {
            continue;
        }
        let corner_uvs = declared.face_uvs && !record.texcoord.is_empty();
        if corner_uvs && record.texcoord.len() != 2 * polygon.len() {
            return Err(Error::mesh(format!(
                "PLY: face {f} has {} corners but {} texcoord values",
                polygon.len(),
                record.texcoord.len()
            )));
        }
        let corner = |k: usize| {
            let mut c = vertex_corner(polygon[k]);
            if corner_uvs {
                c.uv = Some(DVec2::new(
                    record.texcoord[2 * k],
                    record.texcoord[2 * k + 1],
                ));
            }
            c
        };
        // The fan's triangles, corner by corner (super::text::fan's order).
        for k in 1..(faces.len() - first + 1) {
            corners.push([corner(0), corner(k), corner(k + 1)]);
        }
    }
    for record in &strips {
        for strip in record.indices.split(|&i| i < 0) {
            let strip = strip
                .iter()
                .map(|&i| index(i))
                .collect::<Result<Vec<u32>>>()?;
            for (k, w) in strip.windows(3).enumerate() {
                let tri = if k % 2 == 0 {
                    [w[0], w[1], w[2]]
                } else {
                    [w[1], w[0], w[2]]
                };
                // Strips repeat a vertex to turn corners; those triangles are not faces.
                if tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2] {
                    faces.push(tri);
                    if with_attributes {
                        corners.push(tri.map(vertex_corner));
                    }
                }
            }
        }
    }
    let mesh = TriMesh::new(positions, faces);
    let attributes = if with_attributes {
        let attributes = Attributes::weld(&mesh.faces, &corners)?;
        attributes.validate(&mesh)?;
        attributes
    } else {
        Attributes::default()
    };
    Ok(AttributedMesh { mesh, attributes })
}

/// Writes an attributed mesh as binary little-endian PLY: double positions; per vertex, the
/// normals and colours (uchar channels when every value is a multiple of 1/255, doubles
/// otherwise) and the uvs when each vertex has one; uvs a vertex has several of (seams) as
/// per-face `texcoord` lists. PLY holds normals and colours per vertex only: a mesh whose
/// normals or colours differ between the wedges of a vertex is refused. Materials are refused.
pub fn write_attributed(m: &AttributedMesh, out: &mut impl std::io::Write) -> Result<()> {
    let (mesh, a) = (&m.mesh, &m.attributes);
    let n = mesh.positions.len();
    if a.materials.is_some() {
        return Err(Error::Unsupported("PLY holds no materials".into()));
    }
    let per_vertex = |what: &str| Error::Unsupported(format!("PLY holds {what} per vertex only"));
    let normals = match &a.normals {
        Some(v) => Some(
            a.per_vertex_values(v, n)
                .ok_or_else(|| per_vertex("normals"))?,
        ),
        None => None,
    };
    let colours = match &a.colours {
        Some(v) => Some(
            a.per_vertex_values(v, n)
                .ok_or_else(|| per_vertex("colours"))?,
        ),
        None => None,
    };
    let vertex_uvs = a.uvs.as_ref().and_then(|v| a.per_vertex_values(v, n));
    let face_uvs = a.uvs.is_some() && vertex_uvs.is_none();
    let bytes_colour = colours.as_ref().is_some_and(|c| {
        c.iter()
            .flatten()
            .all(|&x| (0.0..=1.0).contains(&x) && (x * 255.0).round() / 255.0 == x)
    });
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment meshcodec\nelement vertex {n}\n\
         property double x\nproperty double y\nproperty double z\n"
    );
    if normals.is_some() {
        header.push_str("property double nx\nproperty double ny\nproperty double nz\n");
    }
    if colours.is_some() {
        let t = if bytes_colour { "uchar" } else { "double" };
        for c in ["red", "green", "blue", "alpha"] {
            header.push_str(&format!("property {t} {c}\n"));
        }
    }
    if vertex_uvs.is_some() {
        header.push_str("property double s\nproperty double t\n");
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar int vertex_indices\n",
        mesh.faces.len()
    ));
    if face_uvs {
        header.push_str("property list uchar double texcoord\n");
    }
    header.push_str("end_header\n");
    let mut body = Vec::with_capacity(n * 80 + mesh.faces.len() * 64);
    let put = |body: &mut Vec<u8>, x: f64| body.extend_from_slice(&x.to_le_bytes());
    for (i, p) in mesh.positions.iter().enumerate() {
        p.to_array().into_iter().for_each(|x| put(&mut body, x));
        if let Some(normals) = &normals {
            normals[i]
                .to_array()
                .into_iter()
                .for_each(|x| put(&mut body, x));
        }
        if let Some(colours) = &colours {
            for x in colours[i] {
                if bytes_colour {
                    body.push((x * 255.0).round() as u8);
                } else {
                    put(&mut body, x);
                }
            }
        }
        if let Some(uvs) = &vertex_uvs {
            uvs[i]
                .to_array()
                .into_iter()
                .for_each(|x| put(&mut body, x));
        }
    }
    for (f, face) in mesh.faces.iter().enumerate() {
        body.push(3);
        for &v in face {
            body.extend_from_slice(&(v as i32).to_le_bytes());
        }
        if face_uvs {
            body.push(6);
            for k in 0..3 {
                let uv = a.corner(f, k).uv.unwrap_or_default();
                put(&mut body, uv.x);
                put(&mut body, uv.y);
            }
        }
    }
    out.write_all(header.as_bytes())?;
    out.write_all(&body)?;
    Ok(())
}

fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// ply-rs allocates a record for every one an element's header line declares: an element with
/// no properties reads no bytes, so "element x 100000000" becomes gigabytes from a tiny file.
/// Each record is refused before reading unless the bytes after the header can hold it: in
/// binary files its scalars and list lengths, in ASCII at least a digit and a separator a
/// property.
fn check_counts(header: &Header, bytes: &[u8]) -> Result<()> {
    let Some(at) = bytes.windows(10).position(|w| w == b"end_header") else {
        return Ok(()); // ply-rs refuses the file itself
    };
    let body = bytes.len() - at;
    let size = |t: &ScalarType| match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    };
    let mut needed = 0u128;
    for element in header.elements.values() {
        if element.count > 0 && element.properties.is_empty() {
            return Err(Error::mesh(format!(
                "PLY: element '{}' declares {} records but no properties",
                element.name, element.count
            )));
        }
        let record: usize = element
            .properties
            .values()
            .map(|p| match (&header.encoding, &p.data_type) {
                (Encoding::Ascii, _) => 2,
                (_, PropertyType::Scalar(t)) | (_, PropertyType::List(t, _)) => size(t),
            })
            .sum();
        needed += element.count as u128 * record as u128;
    }
    if needed > body as u128 {
        return Err(Error::Truncated(format!(
            "PLY header declares records of at least {needed} bytes but {body} bytes follow it"
        )));
    }
    Ok(())
}
