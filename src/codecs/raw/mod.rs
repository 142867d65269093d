//! `raw`: the uncompressed baseline row of every table.
//!
//! Based on: no paper — the plain indexed face set every compression paper measures against.
//! One level: each vertex's cell index as 3 × Q bits, then each triangle as 3 × ⌈log2 V⌉ bits.
//!
//! Glossary: Q = quantization bits per axis, V = vertices, T = triangles.

use super::{names, Capability, Codec, Encoded, LevelDecoder, LevelMesh, Stats};
use crate::codecs::descriptor::cubic;
use crate::codecs::Descriptor;
use crate::coding::bits::index_bits;
use crate::coding::{BitSink, BitSource, SyntaxClass};
use crate::container::{Header, LevelCost, StreamReader, StreamWriter};
use crate::error::{Error, Result};
use crate::mesh::{CanonicalMesh, TriMesh};

/// The `raw` codec.
pub struct Raw;

/// What `Raw` is.
const DESCRIPTOR: Descriptor = Descriptor {
    naming: names::RAW,
    summary: "uncompressed baseline: 3·Q bits per vertex, 3·⌈log2 V⌉ bits per triangle, one level",
    default_options: cubic(12),
    capabilities: &[Capability::Attributes],
    lossless: true,
};

impl Codec for Raw {
    fn descriptor(&self) -> &'static Descriptor {
        &DESCRIPTOR
    }

    fn measure(&self, _stream: &[u8]) -> Result<Stats> {
        Ok(Stats::default())
    }

    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded> {
        let header = Header {
            codec_id: self.id(),
            syntax: self.syntax(),
            params: Vec::new(),
            grid: mesh.grid,
            vertices: mesh.vertex_count() as u64,
            triangles: mesh.face_count() as u64,
            appearance: None,
        };
        let mut sink = BitSink::default();
        let q = mesh.grid.bits as u32;
        for cell in &mesh.cells {
            for &c in cell {
                sink.put(SyntaxClass::Geometry, q, c);
            }
        }
        let b = index_bits(mesh.vertex_count() as u64);
        for face in &mesh.faces {
            for &v in face {
                sink.put(SyntaxClass::Connectivity, b, v);
            }
        }
        let (payload, ledger) = sink.finish();
        let mut writer = StreamWriter::new(&header);
        writer.push_level(
            &payload,
            LevelCost {
                connectivity_bits: ledger.connectivity,
                geometry_bits: ledger.geometry,
                vertices: mesh.vertex_count(),
                triangles: mesh.face_count(),
            },
        );
        let (bytes, levels) = writer.finish();
        Ok(Encoded {
            levels,
            bytes,
            stats: Stats::default(),
        })
    }

    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>> {
        stream.require_layered()?;
        if stream.index().len() != 1 {
            return Err(Error::malformed(
                0,
                0,
                format!(
                    "raw streams have 1 level, this one declares {}",
                    stream.index().len()
                ),
            ));
        }
        Ok(Box::new(RawDecoder {
            stream,
            mesh: TriMesh::default(),
            decoded: 0,
        }))
    }
}

struct RawDecoder<'a> {
    stream: StreamReader<'a>,
    mesh: TriMesh,
    decoded: usize,
}

impl LevelDecoder for RawDecoder<'_> {
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        self.stream.extend(more)?;
        Ok(true)
    }
    fn header(&self) -> &Header {
        self.stream.header()
    }

    fn levels(&self) -> usize {
        1
    }

    fn levels_decoded(&self) -> usize {
        self.decoded
    }

    fn advance(&mut self) -> Result<bool> {
        let header = self.stream.header().clone();
        let Some(level) = self.stream.next_level() else {
            return Ok(false);
        };
        let (v, t) = (header.vertices, header.triangles);
        let q = header.grid.bits as u64;
        let b = index_bits(v) as u64;
        // The payload must hold every field before anything is allocated for them.
        let needed_bits = 3 * q * v + 3 * b * t;
        if (level.bytes.len() as u64) < needed_bits.div_ceil(8) {
            return Err(Error::malformed(
                0,
                level.start,
                format!(
                    "level of {} bytes cannot hold {v} vertices and {t} triangles",
                    level.bytes.len()
                ),
            ));
        }
        let mut source = BitSource::new(level.bytes);
        let mut positions = Vec::with_capacity(v as usize);
        for _ in 0..v {
            let mut cell = [0u32; 3];
            for c in &mut cell {
                *c = source.get(q as u32).expect("length checked above");
            }
            positions.push(header.grid.dequantize(cell));
        }
        let mut faces = Vec::with_capacity(t as usize);
        for i in 0..t {
            let mut face = [0u32; 3];
            for slot in &mut face {
                *slot = source.get(b as u32).expect("length checked above");
            }
            if face.iter().any(|&x| x as u64 >= v)
                || face[0] == face[1]
                || face[1] == face[2]
                || face[0] == face[2]
            {
                return Err(Error::malformed(
                    0,
                    level.start,
                    format!("triangle {i} {face:?} is degenerate or out of range ({v} vertices)"),
                ));
            }
            faces.push(face);
        }
        self.mesh = TriMesh::new(positions, faces);
        self.decoded = 1;
        Ok(true)
    }

    fn mesh(&self) -> Result<LevelMesh> {
        Ok(LevelMesh {
            mesh: self.mesh.clone(),
            loose_edges: Vec::new(),
            attributes: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{canonical_for, decode, Stop};
    use crate::mesh::generate;

    #[test]
    fn raw_is_lossless_and_costs_what_it_says() {
        let mesh = generate::messy(3);
        let canonical = canonical_for(&mesh, &Raw.default_options()).unwrap();
        let encoded = Raw.encode(&canonical).unwrap();
        let (decoded, levels) = decode(&encoded.bytes, Stop::All).unwrap();
        assert_eq!(levels, 1);
        assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
        let (v, t) = (
            canonical.vertex_count() as u64,
            canonical.face_count() as u64,
        );
        let record = encoded.levels[0];
        assert_eq!(record.geometry_bits, 36 * v);
        assert_eq!(record.connectivity_bits, 3 * index_bits(v) as u64 * t);
    }

    #[test]
    fn every_prefix_decodes_or_fails_cleanly() {
        let mesh = generate::icosphere(1);
        let canonical = canonical_for(&mesh, &Raw.default_options()).unwrap();
        let bytes = Raw.encode(&canonical).unwrap().bytes;
        for cut in 0..bytes.len() {
            match decode(&bytes[..cut], Stop::All) {
                Ok((level, n)) => assert!(n == 0 && level.mesh.faces.is_empty()),
                Err(Error::Truncated(_)) => {}
                Err(e) => panic!("cut {cut}: unexpected {e}"),
            }
        }
    }
}
