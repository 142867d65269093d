//! Reading a stream's units: from bytes borrowed or owned (and growing as they arrive), or level
//! by level from an input stream.

use super::*;
use crate::error::{Error, Result};

/// One unit's payload as found in a stream.
#[derive(Clone, Copy, Debug)]
pub struct LevelPayload<'a> {
    /// Unit number, from 0.
    pub index: usize,
    /// Offset of the payload's first byte in the stream (for error messages).
    pub start: usize,
    /// The payload.
    pub bytes: &'a [u8],
}

/// Reads a stream's units: in order as levels, or any one by its index entry. Its bytes are
/// borrowed ([`StreamReader::open`]) or its own ([`StreamReader::open_owned`]), and then grow as
/// more of the stream arrives ([`StreamReader::extend`]), so that a decoder fed chunks goes on
/// from where it stopped.
#[derive(Clone, Debug)]
pub struct StreamReader<'a> {
    header: Header,
    index: Index,
    bytes: std::borrow::Cow<'a, [u8]>,
    payload_start: usize,
    next_level: usize,
}

impl<'a> StreamReader<'a> {
    /// Parses the header and index of `bytes` (a whole stream or a prefix).
    pub fn open(bytes: &'a [u8]) -> Result<Self> {
        Self::from_cow(std::borrow::Cow::Borrowed(bytes))
    }

    fn from_cow(bytes: std::borrow::Cow<'a, [u8]>) -> Result<Self> {
        let (header, index, payload_start) = read_header_and_index(&bytes)?;
        let reader = StreamReader {
            header,
            index,
            bytes,
            payload_start,
            next_level: 0,
        };
        reader.check_length(reader.bytes.len())?;
        Ok(reader)
    }

    /// Refuses a stream of `len` bytes that runs past the payload's end.
    fn check_length(&self, len: usize) -> Result<()> {
        check_stream_length(&self.index, self.payload_start, len)
    }

    /// Its header, index, payload offset and bytes.
    pub fn into_parts(self) -> (Header, Index, usize, std::borrow::Cow<'a, [u8]>) {
        (self.header, self.index, self.payload_start, self.bytes)
    }

    /// Refuses a stream whose units are not levels.
    pub fn require_layered(&self) -> Result<()> {
        self.index.require_layered(self.payload_start)
    }

    /// The stream's header.
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// The stream's index.
    pub fn index(&self) -> &Index {
        &self.index
    }

    /// Offset of the payload's first byte in the stream.
    pub fn payload_start(&self) -> usize {
        self.payload_start
    }

    /// The whole stream (or prefix) being read.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// Unit `i`, when all its bytes are present (and, in a stream whose levels have
    /// appearance parts, its part's too: a level is decoded with its appearance).
    pub fn unit(&self, i: usize) -> Option<LevelPayload<'_>> {
        let entry = self.index.units.get(i)?;
        let start = self.payload_start + entry.offset as usize;
        let end = self.payload_start + entry.end() as usize;
        if let Some(part) = self.index.level_parts.get(i) {
            if self.bytes.len() < self.payload_start + part.end() as usize {
                return None;
            }
        }
        self.bytes.get(start..end).map(|bytes| LevelPayload {
            index: i,
            start,
            bytes,
        })
    }

    /// The appearance part of level `i` (docs/FORMAT.md §10), when the stream has level parts
    /// and its bytes are present.
    pub fn level_part(&self, i: usize) -> Option<LevelPayload<'_>> {
        let entry = self.index.level_parts.get(i)?;
        let start = self.payload_start + entry.offset as usize;
        let end = self.payload_start + entry.end() as usize;
        self.bytes.get(start..end).map(|bytes| LevelPayload {
            index: i,
            start,
            bytes,
        })
    }

    /// The appearance unit — its bytes, number and first byte — when the stream has one and
    /// it is wholly present.
    pub fn appearance_unit(&self) -> Option<(&[u8], usize, usize)> {
        let entry = self.index.appearance?;
        let start = self.payload_start + entry.offset as usize;
        let end = self.payload_start + entry.end() as usize;
        self.bytes
            .get(start..end)
            .map(|bytes| (bytes, self.index.units.len(), start))
    }

    /// The next complete level, or `None` when the stream has no more (all levels read, or the
    /// bytes end inside the next one: then [`StreamReader::truncated`] is true).
    pub fn next_level(&mut self) -> Option<LevelPayload<'_>> {
        let present = self.unit(self.next_level).is_some();
        if !present {
            return None;
        }
        self.next_level += 1;
        self.unit(self.next_level - 1)
    }

    /// True when the bytes end before the payload does.
    pub fn truncated(&self) -> bool {
        ((self.bytes.len() - self.payload_start) as u64) < self.index.payload_bytes
    }

    /// The bytes present of the next level when the stream was cut inside it, for codecs that
    /// can decode part of a level.
    pub fn partial_level(&self) -> Option<LevelPayload<'_>> {
        let entry = self.index.units.get(self.next_level)?;
        let start = self.payload_start + entry.offset as usize;
        let bytes = self.bytes.get(start..)?;
        (bytes.len() < entry.length as usize).then_some(LevelPayload {
            index: self.next_level,
            start,
            bytes,
        })
    }
}

impl StreamReader<'static> {
    /// Parses the header and index of `bytes` (a whole stream or a prefix), keeping them.
    pub fn open_owned(bytes: Vec<u8>) -> Result<Self> {
        Self::from_cow(std::borrow::Cow::Owned(bytes))
    }
}

impl StreamReader<'_> {
    /// Takes the stream's next bytes (as they arrive): the levels they complete can be read
    /// next. Bytes past the payload's end are refused, and not taken.
    pub fn extend(&mut self, more: &[u8]) -> Result<()> {
        self.check_length(self.bytes.len() + more.len())?;
        self.bytes.to_mut().extend_from_slice(more);
        Ok(())
    }
}

/// Refuses a stream of `len` bytes, its payload starting at `payload_start`, that runs past the
/// end of the payload `index` lists: for decoders that hold the stream's bytes apart from a
/// [`StreamReader`] and take more as they arrive.
pub fn check_stream_length(index: &Index, payload_start: usize, len: usize) -> Result<()> {
    let present = (len - payload_start) as u64;
    if present > index.payload_bytes {
        return Err(Error::malformed(
            index.len(),
            payload_start + index.payload_bytes as usize,
            format!(
                "{} bytes after the last unit",
                present - index.payload_bytes
            ),
        ));
    }
    Ok(())
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

impl LevelPayload<'_> {
    /// A copy of the payload.
    pub fn to_owned_level(&self) -> OwnedLevel {
        OwnedLevel {
            index: self.index,
            start: self.start,
            bytes: self.bytes.to_vec(),
        }
    }
}

impl OwnedLevel {
    /// The payload, borrowed.
    pub fn payload(&self) -> LevelPayload<'_> {
        LevelPayload {
            index: self.index,
            start: self.start,
            bytes: &self.bytes,
        }
    }
}

/// Where levels come from: bytes in memory, or an input stream read as levels are needed.
pub trait LevelSource {
    /// The stream's header.
    fn header(&self) -> &Header;
    /// The next complete level, or `None` when no complete level follows (end or cut).
    fn next_owned_level(&mut self) -> Result<Option<OwnedLevel>>;
    /// Takes the stream's next bytes as they arrive, so that the levels they complete can be
    /// read next; `Ok(false)` from a source that cannot (it reads its own input).
    fn extend(&mut self, _more: &[u8]) -> Result<bool> {
        Ok(false)
    }
}

impl LevelSource for StreamReader<'_> {
    fn header(&self) -> &Header {
        StreamReader::header(self)
    }

    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        StreamReader::extend(self, more)?;
        Ok(true)
    }

    fn next_owned_level(&mut self) -> Result<Option<OwnedLevel>> {
        Ok(self.next_level().map(|l| OwnedLevel {
            index: l.index,
            start: l.start,
            bytes: l.bytes.to_vec(),
        }))
    }
}

/// Reads a layered stream's levels from an input stream (a file, a socket), one level at a time,
/// so a decoder can start before the rest has arrived.
pub struct ReadLevels<R: std::io::Read> {
    reader: R,
    header: Header,
    index: Index,
    offset: usize,
    next_level: usize,
}

impl<R: std::io::Read> ReadLevels<R> {
    /// Reads the header and index (and nothing beyond them) from `reader`.
    pub fn open(mut reader: R) -> Result<Self> {
        // The header's length is only known once it parses: read a byte at a time.
        let mut bytes = Vec::new();
        loop {
            match read_header_and_index(&bytes) {
                Ok((header, index, offset)) => {
                    index.require_layered(offset)?;
                    if header.has_level_parts() {
                        return Err(Error::Unsupported(
                            "levels read from an input stream carry no appearance parts".into(),
                        ));
                    }
                    return Ok(ReadLevels {
                        offset,
                        reader,
                        header,
                        index,
                        next_level: 0,
                    });
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
        let Some(entry) = self.index.units.get(self.next_level) else {
            return Ok(None);
        };
        // Read what arrives rather than allocating what the index claims.
        let mut bytes = Vec::new();
        (&mut self.reader)
            .take(entry.length)
            .read_to_end(&mut bytes)?;
        if (bytes.len() as u64) < entry.length {
            return Ok(None);
        }
        let level = OwnedLevel {
            index: self.next_level,
            start: self.offset,
            bytes,
        };
        self.offset += entry.length as usize;
        self.next_level += 1;
        Ok(Some(level))
    }
}
