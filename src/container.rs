//! The stream container of DESIGN.md A3: a header, then levels, each prefixed by its length.
//!
//! ```text
//! magic "MshC"  format version (u8)  codec id (u8)
//! params: varint length + codec-specific bytes
//! grid: bits (u8), origin 3 × f64 LE, cell 3 × f64 LE
//! vertices (varint)  triangles (varint)  levels (varint)      -- of the full mesh
//! level*: varint byte length + payload
//! ```
//! Levels carry their own lengths so that a prefix of the stream decodes to its last complete
//! level without knowing how the codec's syntax ends, and so that a range coder's output can be
//! flushed per level. Counts are checked against [`crate::limits`] before any use.

use crate::coding::varint;
use crate::error::{Error, Result};
use crate::limits;
use crate::mesh::Grid;
use std::io::Read as _;

/// First bytes of every stream.
pub const MAGIC: [u8; 4] = *b"MshC";
/// Version of the container syntax; bumped whenever a stream of the old syntax would not decode.
pub const FORMAT_VERSION: u8 = 1;

/// What a stream says about itself before its levels.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Which codec wrote the levels.
    pub codec_id: u8,
    /// Codec-specific parameters.
    pub params: Vec<u8>,
    /// The quantization grid of the full mesh.
    pub grid: Grid,
    /// Vertices of the full mesh.
    pub vertices: u64,
    /// Triangles of the full mesh.
    pub triangles: u64,
    /// Levels in the stream.
    pub levels: u64,
}

impl Header {
    /// Appends the header's bytes to `out`.
    pub fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.push(FORMAT_VERSION);
        out.push(self.codec_id);
        varint::put(out, self.params.len() as u64);
        out.extend_from_slice(&self.params);
        out.push(self.grid.bits);
        for v in self.grid.origin.iter().chain(&self.grid.cell) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        varint::put(out, self.vertices);
        varint::put(out, self.triangles);
        varint::put(out, self.levels);
    }

    /// Reads a header from the start of `bytes`; returns it and the offset of the first level.
    pub fn read(bytes: &[u8]) -> Result<(Header, usize)> {
        let cut = || Error::Truncated("the stream ends inside its header".into());
        let bad = |byte: usize, what: &str| Error::malformed(0, byte, what);
        if bytes.len() < MAGIC.len() {
            return Err(cut());
        }
        if bytes[..4] != MAGIC {
            return Err(bad(0, "not a meshcodec stream (bad magic)"));
        }
        let version = *bytes.get(4).ok_or_else(cut)?;
        if version != FORMAT_VERSION {
            return Err(Error::Unsupported(format!(
                "stream format version {version} (this build reads version {FORMAT_VERSION})"
            )));
        }
        let codec_id = *bytes.get(5).ok_or_else(cut)?;
        let mut pos = 6;
        let count = |pos: &mut usize, what: &str, limit: u64| -> Result<u64> {
            let at = *pos;
            let value = varint::get(bytes, pos).map_err(|f| match f {
                varint::VarintFault::Truncated => cut(),
                varint::VarintFault::Overflow => bad(at, &format!("{what} overflows 64 bits")),
            })?;
            if value > limit {
                return Err(Error::Limit(format!(
                    "stream declares {value} {what} (at most {limit})"
                )));
            }
            Ok(value)
        };
        let param_len = count(&mut pos, "parameter bytes", limits::MAX_PARAM_BYTES)? as usize;
        let params = bytes.get(pos..pos + param_len).ok_or_else(cut)?.to_vec();
        pos += param_len;
        let bits = *bytes.get(pos).ok_or_else(cut)?;
        if bits == 0 || bits > crate::mesh::quantize::MAX_QUANT_BITS {
            return Err(bad(pos, &format!("quantization of {bits} bits")));
        }
        pos += 1;
        let mut floats = [0f64; 6];
        for f in &mut floats {
            let raw = bytes.get(pos..pos + 8).ok_or_else(cut)?;
            *f = f64::from_le_bytes(raw.try_into().expect("8 bytes"));
            pos += 8;
        }
        let grid = Grid {
            origin: [floats[0], floats[1], floats[2]],
            cell: [floats[3], floats[4], floats[5]],
            bits,
        };
        let far_corner_finite =
            (0..3).all(|a| (grid.origin[a] + grid.cell[a] * (1u64 << bits) as f64).is_finite());
        if !floats.iter().all(|f| f.is_finite())
            || !grid.cell.iter().all(|&c| c > 0.0)
            || !far_corner_finite
        {
            return Err(bad(
                pos - 48,
                "grid origin or cell size is not a finite positive number",
            ));
        }
        let vertices = count(&mut pos, "vertices", limits::MAX_VERTICES)?;
        let triangles = count(&mut pos, "triangles", limits::MAX_TRIANGLES)?;
        let levels = count(&mut pos, "levels", limits::MAX_LEVELS)?;
        if vertices == 0 || triangles == 0 || levels == 0 {
            // No encoder writes an empty mesh (empty input is refused before encoding).
            return Err(bad(
                pos,
                &format!(
                    "header declares {vertices} vertices, {triangles} triangles, {levels} levels"
                ),
            ));
        }
        let header = Header {
            codec_id,
            params,
            grid,
            vertices,
            triangles,
            levels,
        };
        Ok((header, pos))
    }
}

/// Builds a stream level by level.
pub struct StreamWriter {
    bytes: Vec<u8>,
    level_ends: Vec<usize>,
}

impl StreamWriter {
    /// Starts a stream with `header` (whose `levels` must equal the levels pushed).
    pub fn new(header: &Header) -> Self {
        let mut bytes = Vec::new();
        header.write(&mut bytes);
        StreamWriter {
            bytes,
            level_ends: Vec::new(),
        }
    }

    /// Appends one level's payload.
    pub fn push_level(&mut self, payload: &[u8]) {
        varint::put(&mut self.bytes, payload.len() as u64);
        self.bytes.extend_from_slice(payload);
        self.level_ends.push(self.bytes.len());
    }

    /// The stream and, for each level, the byte offset where it ends.
    pub fn finish(self) -> (Vec<u8>, Vec<usize>) {
        (self.bytes, self.level_ends)
    }
}

/// One level's payload as found in a stream.
#[derive(Clone, Copy, Debug)]
pub struct LevelPayload<'a> {
    /// Level number, from 0.
    pub index: usize,
    /// Offset of the payload's first byte in the stream (for error messages).
    pub start: usize,
    /// The payload.
    pub bytes: &'a [u8],
}

/// Reads a stream's levels in order.
#[derive(Clone, Debug)]
pub struct StreamReader<'a> {
    header: Header,
    bytes: &'a [u8],
    pos: usize,
    next_level: usize,
    truncated: bool,
    partial_start: Option<usize>,
}

impl<'a> StreamReader<'a> {
    /// Parses the header of `bytes`.
    pub fn open(bytes: &'a [u8]) -> Result<Self> {
        let (header, pos) = Header::read(bytes)?;
        Ok(StreamReader {
            header,
            bytes,
            pos,
            next_level: 0,
            truncated: false,
            partial_start: None,
        })
    }

    /// The stream's header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The whole stream (or prefix) being read.
    pub fn bytes(&self) -> &'a [u8] {
        self.bytes
    }

    /// The next complete level, or `None` when the stream has no more (all declared levels read,
    /// or the bytes end inside the next one: then [`StreamReader::truncated`] is true).
    pub fn next_level(&mut self) -> Result<Option<LevelPayload<'a>>> {
        if self.next_level as u64 >= self.header.levels {
            if self.pos < self.bytes.len() {
                return Err(Error::malformed(
                    self.next_level,
                    self.pos,
                    format!("{} bytes after the last level", self.bytes.len() - self.pos),
                ));
            }
            return Ok(None);
        }
        let mut pos = self.pos;
        let len = match varint::get(self.bytes, &mut pos) {
            Ok(len) => len,
            Err(varint::VarintFault::Truncated) => {
                self.truncated = true;
                return Ok(None);
            }
            Err(varint::VarintFault::Overflow) => {
                return Err(Error::malformed(
                    self.next_level,
                    self.pos,
                    "level length overflows",
                ))
            }
        };
        let available = (self.bytes.len() - pos) as u64;
        if len > available {
            self.truncated = true;
            self.partial_start = Some(pos);
            return Ok(None);
        }
        let payload = LevelPayload {
            index: self.next_level,
            start: pos,
            bytes: &self.bytes[pos..pos + len as usize],
        };
        self.pos = pos + len as usize;
        self.next_level += 1;
        Ok(Some(payload))
    }

    /// True when the bytes ended inside a level.
    pub fn truncated(&self) -> bool {
        self.truncated
    }

    /// The bytes present of the level the stream was cut in (after its complete length
    /// prefix), for codecs that can decode part of a level.
    pub fn partial_level(&self) -> Option<LevelPayload<'a>> {
        self.partial_start.map(|start| LevelPayload {
            index: self.next_level,
            start,
            bytes: &self.bytes[start..],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Header {
        Header {
            codec_id: 7,
            params: vec![1, 2, 3],
            grid: Grid {
                origin: [0.5, -1.0, 2.0],
                cell: [0.25, 0.25, 0.125],
                bits: 12,
            },
            vertices: 1000,
            triangles: 2000,
            levels: 2,
        }
    }

    #[test]
    fn header_and_levels_round_trip_and_every_prefix_reads_cleanly() {
        let mut writer = StreamWriter::new(&header());
        writer.push_level(&[9; 5]);
        writer.push_level(&[8; 300]);
        let (bytes, ends) = writer.finish();
        let mut reader = StreamReader::open(&bytes).unwrap();
        assert_eq!(reader.header(), &header());
        assert_eq!(reader.next_level().unwrap().unwrap().bytes, &[9; 5]);
        assert_eq!(reader.next_level().unwrap().unwrap().bytes.len(), 300);
        assert!(reader.next_level().unwrap().is_none());
        assert_eq!(ends.last(), Some(&bytes.len()));
        for cut in 0..bytes.len() {
            match StreamReader::open(&bytes[..cut]) {
                Err(Error::Truncated(_)) => {}
                Err(e) => panic!("cut {cut}: {e}"),
                Ok(mut r) => {
                    let mut complete = 0;
                    while r.next_level().unwrap().is_some() {
                        complete += 1;
                    }
                    let expected = ends.iter().filter(|&&e| e <= cut).count();
                    assert_eq!(complete, expected, "cut {cut}");
                }
            }
        }
    }

    #[test]
    fn foreign_and_oversized_headers_are_refused() {
        assert!(matches!(
            Header::read(b"PK\x03\x04 zip file"),
            Err(Error::Malformed { .. })
        ));
        let mut big = header();
        big.vertices = 1 << 31;
        let mut bytes = Vec::new();
        big.write(&mut bytes);
        assert!(matches!(Header::read(&bytes), Err(Error::Limit(_))));
    }
}

/// A level's payload read from any source.
#[derive(Clone, Debug)]
pub struct OwnedLevel {
    /// Level number, from 0.
    pub index: usize,
    /// Offset of the payload's first byte in the stream.
    pub start: usize,
    /// The payload.
    pub bytes: Vec<u8>,
}

/// Where levels come from: bytes in memory, or an input stream read as levels are needed.
pub trait LevelSource {
    /// The stream's header.
    fn header(&self) -> &Header;
    /// The next complete level, or `None` when no complete level follows (end or cut).
    fn next_owned_level(&mut self) -> Result<Option<OwnedLevel>>;
}

impl LevelSource for StreamReader<'_> {
    fn header(&self) -> &Header {
        StreamReader::header(self)
    }

    fn next_owned_level(&mut self) -> Result<Option<OwnedLevel>> {
        Ok(self.next_level()?.map(|l| OwnedLevel {
            index: l.index,
            start: l.start,
            bytes: l.bytes.to_vec(),
        }))
    }
}

/// Reads a stream's levels from an input stream (a file, a socket), one level at a time, so a
/// decoder can start before the rest has arrived.
pub struct ReadLevels<R: std::io::Read> {
    reader: R,
    header: Header,
    offset: usize,
    next_level: usize,
}

impl<R: std::io::Read> ReadLevels<R> {
    /// Reads the header (and nothing beyond it) from `reader`.
    pub fn open(mut reader: R) -> Result<Self> {
        // The header's length is only known once it parses: read a byte at a time.
        let mut bytes = Vec::new();
        loop {
            match Header::read(&bytes) {
                Ok((header, _)) => {
                    return Ok(ReadLevels {
                        offset: bytes.len(),
                        reader,
                        header,
                        next_level: 0,
                    })
                }
                Err(Error::Truncated(what)) => {
                    let mut byte = [0u8];
                    if reader.read(&mut byte)? == 0 {
                        return Err(Error::Truncated(what));
                    }
                    bytes.push(byte[0]);
                }
                Err(e) => return Err(e),
            }
        }
    }
}

impl<R: std::io::Read> LevelSource for ReadLevels<R> {
    fn header(&self) -> &Header {
        &self.header
    }

    fn next_owned_level(&mut self) -> Result<Option<OwnedLevel>> {
        if self.next_level as u64 >= self.header.levels {
            return Ok(None);
        }
        let mut length_bytes = Vec::new();
        let len = loop {
            let mut byte = [0u8];
            if self.reader.read(&mut byte)? == 0 {
                return Ok(None);
            }
            length_bytes.push(byte[0]);
            let mut pos = 0;
            match varint::get(&length_bytes, &mut pos) {
                Ok(len) => break len,
                Err(varint::VarintFault::Truncated) => continue,
                Err(varint::VarintFault::Overflow) => {
                    return Err(Error::malformed(
                        self.next_level,
                        self.offset,
                        "level length overflows",
                    ))
                }
            }
        };
        self.offset += length_bytes.len();
        // Read what arrives rather than allocating what the length claims.
        let mut bytes = Vec::new();
        (&mut self.reader).take(len).read_to_end(&mut bytes)?;
        if (bytes.len() as u64) < len {
            return Ok(None);
        }
        let level = OwnedLevel {
            index: self.next_level,
            start: self.offset,
            bytes,
        };
        self.offset += len as usize;
        self.next_level += 1;
        Ok(Some(level))
    }
}
