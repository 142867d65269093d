//! PLY through `ply-rs-bw`: ASCII, binary little- and big-endian; positions of any numeric type;
//! faces as `face` lists (`vertex_indices` or `vertex_index`) or `tristrips` (−1 separated
//! strips, alternate triangles flipped to keep one orientation). Other elements and properties
//! are read past and ignored.

use crate::error::{Error, Result};
use crate::mesh::TriMesh;
use glam::DVec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

/// One PLY element as we need it: a position, an index list, or neither.
#[derive(Default)]
struct Record {
    xyz: [f64; 3],
    indices: Vec<i64>,
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

fn integer_list(p: Property) -> Option<Vec<i64>> {
    fn widen<T: Copy + Into<i64>>(v: Vec<T>) -> Vec<i64> {
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

impl PropertyAccess for Record {
    fn new() -> Self {
        Record::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            "vertex_indices" | "vertex_index" => {
                return match integer_list(property) {
                    Some(list) => {
                        self.indices = list;
                        PropertyAccessResult::Set
                    }
                    None => PropertyAccessResult::UnsupportedType,
                };
            }
            _ => return PropertyAccessResult::Ignored,
        };
        match scalar(&property) {
            Some(v) => {
                self.xyz[axis] = v;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::UnsupportedType,
        }
    }
}

pub fn read(bytes: &[u8]) -> Result<TriMesh> {
    let parser = Parser::<Record>::new();
    // ply-rs reports over several lines; errors here are one line (docs/CONTRACT.md §7).
    let fault = |e: ply_rs_bw::parser::ParseError| {
        Error::mesh(format!("PLY: {}", one_line(&e.to_string())))
    };
    let mut reader = Reader::new(bytes);
    let header = parser.read_header(&mut reader).map_err(fault)?;
    check_counts(&header, bytes)?;
    let payload = parser.read_payload(&mut reader, &header).map_err(fault)?;
    let vertex_def = header
        .elements
        .get("vertex")
        .ok_or_else(|| Error::mesh("PLY: no vertex element"))?;
    for axis in ["x", "y", "z"] {
        if !vertex_def.properties.contains_key(axis) {
            return Err(Error::mesh(format!("PLY: vertex has no '{axis}' property")));
        }
    }
    let positions: Vec<DVec3> = payload
        .get("vertex")
        .map(|v| v.iter().map(|r| DVec3::from(r.xyz)).collect())
        .unwrap_or_default();
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
    let mut faces = Vec::new();
    for record in payload.get("face").into_iter().flatten() {
        let polygon = record
            .indices
            .iter()
            .map(|&i| index(i))
            .collect::<Result<Vec<u32>>>()?;
        super::text::fan(&polygon, &mut faces);
    }
    for record in payload.get("tristrips").into_iter().flatten() {
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
                }
            }
        }
    }
    Ok(TriMesh::new(positions, faces))
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
