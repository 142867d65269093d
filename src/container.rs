//! The stream container (docs/FORMAT.md §2): a header, an index of independently decodable
//! units, then the units' payloads.
//!
//! ```text
//! magic "MshC"  format version (u8)  codec id (u8)
//! params: varint length + codec-specific bytes
//! grid: bits (u8), origin 3 × f64 LE, cell 3 × f64 LE
//! vertices (varint)  triangles (varint)                        -- of the full mesh
//! version 4 only: appearance block (flags u8, then each attribute's quantization, names)
//! index: units N (varint), payload bytes P (varint),
//!        N × { offset (varint), length (varint), parent (varint: 0 = none, k = unit i − k) }
//! payload: P bytes, every byte in exactly one unit
//! ```
//! A unit is what a decoder can take on its own once the units it depends on are decoded: a level
//! for the layered codecs (each level's parent is the level before), a meta-node for a hierarchy
//! fetched by parts. A reader holding the header and index can fetch any unit by its byte range;
//! a prefix of the stream decodes to the units wholly inside it. The index is checked whole —
//! counts against [`crate::limits`] and the bytes that hold them, ranges inside the payload,
//! no overlaps, no stray bytes — before anything is allocated for what it claims.

use crate::coding::varint;
use crate::error::{Error, Result};
use crate::limits;
use crate::mesh::attribute_quantization::{UvGrid, NORMAL_BITS_RANGE};
use crate::mesh::Grid;
use std::io::Read as _;

/// First bytes of every stream.
pub const MAGIC: [u8; 4] = *b"MshC";
/// Version of the stream syntax: bumped on every change to the bytes any codec writes
/// (docs/FORMAT.md, "History"). Versions 3 and 4 are version 2 with an appearance block after
/// the header and an appearance unit after the last level (4 predicts uvs and colours better,
/// so version 3's units no longer decode); version 5 is version 4 whose appearance block may
/// say that the values are coded inside the levels (`pm`), with no appearance unit. Each
/// stream is written in the oldest version that holds it — 2 without appearance, 4 with an
/// appearance unit — and this build reads 2, 4 and 5.
pub const FORMAT_VERSION: u8 = 5;
/// The version of streams with an appearance unit.
pub const APPEARANCE_UNIT_VERSION: u8 = 4;
/// The version of streams without appearance, and the oldest this build reads.
pub const GEOMETRY_ONLY_VERSION: u8 = 2;
/// The fewest bytes an index entry takes (three one-byte varints).
const MIN_ENTRY_BYTES: u64 = 3;

/// What a stream says about itself before its index.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Which codec wrote the units.
    pub codec_id: u8,
    /// Codec-specific parameters.
    pub params: Vec<u8>,
    /// The quantization grid of the full mesh.
    pub grid: Grid,
    /// Vertices of the full mesh.
    pub vertices: u64,
    /// Triangles of the full mesh.
    pub triangles: u64,
    /// What the appearance unit carries, when the stream has one (version 4).
    pub appearance: Option<AppearanceSpec>,
}

impl Header {
    /// The format version this header is written in: [`FORMAT_VERSION`] with appearance in
    /// the levels, [`APPEARANCE_UNIT_VERSION`] with an appearance unit,
    /// [`GEOMETRY_ONLY_VERSION`] without.
    pub fn version(&self) -> u8 {
        match &self.appearance {
            Some(a) if a.in_levels => FORMAT_VERSION,
            Some(_) => APPEARANCE_UNIT_VERSION,
            None => GEOMETRY_ONLY_VERSION,
        }
    }
}

/// What a stream's appearance unit carries and how it is quantized (docs/FORMAT.md §1.1).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AppearanceSpec {
    /// Qn of the wedges' octahedral normals, when there are normals.
    pub normal_bits: Option<u8>,
    /// The grid of the wedges' uvs, when there are uvs.
    pub uv_grid: Option<UvGrid>,
    /// Whether wedges carry 8-bit RGBA colours.
    pub colours: bool,
    /// The material names faces' ids index, when faces carry materials.
    pub materials: Option<MaterialNames>,
    /// Whether the values are coded inside the codec's own levels, so that every level carries
    /// them (`pm`), rather than in an appearance unit after the last.
    pub in_levels: bool,
    /// Whether the levels carry only which corners share a normal, each level's normals being
    /// derived from its positions (docs/FORMAT.md §6.3; with normals and `in_levels` only).
    pub derived_normals: bool,
    /// Whether the levels' new normals are predicted from the geometry of their vertex's faces
    /// (docs/FORMAT.md §6.3; with normals coded in the levels only).
    pub geometric_normals: bool,
}

impl AppearanceSpec {
    /// How the stream's normals travel: "derived" (each level derives them from its positions
    /// over the normal groups), "predicted" (values predicted from the geometry of their
    /// vertex's faces), "coded" (values), or `None` without normals.
    pub fn normal_mode(&self) -> Option<&'static str> {
        self.normal_bits?;
        Some(if self.derived_normals {
            "derived"
        } else if self.geometric_normals {
            "predicted"
        } else {
            "coded"
        })
    }
}

/// Material names and the library they come from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MaterialNames {
    /// Names, indexed by material id.
    pub names: Vec<String>,
    /// The material library file (OBJ's `mtllib`), if any.
    pub library: Option<String>,
}

const FLAG_NORMALS: u8 = 1;
const FLAG_UVS: u8 = 2;
const FLAG_COLOURS: u8 = 4;
const FLAG_MATERIALS: u8 = 8;
const FLAG_IN_LEVELS: u8 = 16;
const FLAG_DERIVED_NORMALS: u8 = 32;
const FLAG_GEOMETRIC_NORMALS: u8 = 64;

impl AppearanceSpec {
    fn write(&self, out: &mut Vec<u8>) {
        let flags = self.normal_bits.map_or(0, |_| FLAG_NORMALS)
            | self.uv_grid.map_or(0, |_| FLAG_UVS)
            | if self.colours { FLAG_COLOURS } else { 0 }
            | self.materials.as_ref().map_or(0, |_| FLAG_MATERIALS)
            | if self.in_levels { FLAG_IN_LEVELS } else { 0 }
            | if self.derived_normals {
                FLAG_DERIVED_NORMALS
            } else {
                0
            }
            | if self.geometric_normals {
                FLAG_GEOMETRIC_NORMALS
            } else {
                0
            };
        out.push(flags);
        if let Some(bits) = self.normal_bits {
            out.push(bits);
        }
        if let Some(grid) = &self.uv_grid {
            out.push(grid.bits);
            for v in grid.origin.iter().chain([&grid.cell]) {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        if let Some(materials) = &self.materials {
            varint::put(out, materials.names.len() as u64);
            for name in materials.names.iter().chain(&materials.library) {
                varint::put(out, name.len() as u64);
                out.extend_from_slice(name.as_bytes());
            }
            if materials.library.is_none() {
                varint::put(out, 0);
            }
        }
    }

    fn read(bytes: &[u8], pos: &mut usize) -> Result<AppearanceSpec> {
        let cut = || Error::Truncated("the stream ends inside its header".into());
        let byte = |pos: &mut usize| -> Result<u8> {
            let b = *bytes.get(*pos).ok_or_else(cut)?;
            *pos += 1;
            Ok(b)
        };
        let at = *pos;
        let flags = byte(pos)?;
        let attributes = FLAG_NORMALS | FLAG_UVS | FLAG_COLOURS | FLAG_MATERIALS;
        // Derived normals, or normals predicted from geometry (not both), need normals in the
        // levels.
        let normal_modes = flags & (FLAG_DERIVED_NORMALS | FLAG_GEOMETRIC_NORMALS);
        let bad_mode = normal_modes != 0
            && (normal_modes == FLAG_DERIVED_NORMALS | FLAG_GEOMETRIC_NORMALS
                || flags & (FLAG_NORMALS | FLAG_IN_LEVELS) != FLAG_NORMALS | FLAG_IN_LEVELS);
        let known = attributes | FLAG_IN_LEVELS | FLAG_DERIVED_NORMALS | FLAG_GEOMETRIC_NORMALS;
        if flags & attributes == 0 || flags & !known != 0 || bad_mode {
            return Err(Error::malformed(
                0,
                at,
                format!("appearance flags {flags:#04x}"),
            ));
        }
        let mut spec = AppearanceSpec {
            colours: flags & FLAG_COLOURS != 0,
            in_levels: flags & FLAG_IN_LEVELS != 0,
            derived_normals: flags & FLAG_DERIVED_NORMALS != 0,
            geometric_normals: flags & FLAG_GEOMETRIC_NORMALS != 0,
            ..AppearanceSpec::default()
        };
        if flags & FLAG_NORMALS != 0 {
            let bits = byte(pos)?;
            if !NORMAL_BITS_RANGE.contains(&bits) {
                return Err(Error::malformed(
                    0,
                    *pos - 1,
                    format!("normals of {bits} bits"),
                ));
            }
            spec.normal_bits = Some(bits);
        }
        if flags & FLAG_UVS != 0 {
            let bits = byte(pos)?;
            let mut floats = [0f64; 3];
            for f in &mut floats {
                let raw = bytes.get(*pos..*pos + 8).ok_or_else(cut)?;
                *f = f64::from_le_bytes(raw.try_into().expect("8 bytes"));
                *pos += 8;
            }
            let grid = UvGrid {
                bits,
                origin: [floats[0], floats[1]],
                cell: floats[2],
            };
            if !grid.is_valid() {
                return Err(Error::malformed(
                    0,
                    *pos - 25,
                    "uv grid: bits, origin or cell size out of range",
                ));
            }
            spec.uv_grid = Some(grid);
        }
        if flags & FLAG_MATERIALS != 0 {
            let count = read_count(bytes, pos, "materials", limits::MAX_MATERIALS)?;
            if count == 0 {
                return Err(Error::malformed(0, *pos, "appearance declares no material"));
            }
            let text = |pos: &mut usize| -> Result<String> {
                let at = *pos;
                let len = read_count(bytes, pos, "name bytes", limits::MAX_NAME_BYTES)? as usize;
                let raw = bytes.get(*pos..*pos + len).ok_or_else(cut)?;
                *pos += len;
                String::from_utf8(raw.to_vec())
                    .map_err(|_| Error::malformed(0, at, "a material name is not UTF-8"))
            };
            // Names take at least a byte each: no allocation beyond what the bytes hold.
            if ((bytes.len() - *pos) as u64) < count {
                return Err(cut());
            }
            let names = (0..count).map(|_| text(pos)).collect::<Result<_>>()?;
            let library = Some(text(pos)?).filter(|l| !l.is_empty());
            spec.materials = Some(MaterialNames { names, library });
        }
        Ok(spec)
    }
}

/// Where one unit's payload lies, and what it needs decoded first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitEntry {
    /// Offset of the unit's first byte from the payload's start.
    pub offset: u64,
    /// Bytes of the unit.
    pub length: u64,
    /// The unit that must be decoded before this one (always an earlier unit).
    pub parent: Option<usize>,
}

impl UnitEntry {
    /// One past the unit's last byte, from the payload's start.
    pub fn end(&self) -> u64 {
        self.offset + self.length
    }
}

/// The index of a stream's units.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Index {
    /// Units in decoding order.
    pub units: Vec<UnitEntry>,
    /// Bytes of the payload (the sum of the units' lengths, the appearance unit's included).
    pub payload_bytes: u64,
    /// The appearance unit, last in the stream, when the header declares appearance.
    pub appearance: Option<UnitEntry>,
}

impl Index {
    /// The index of units laid out back to back in order, each depending on the one before —
    /// the levels of a layered codec.
    pub fn layered(lengths: &[u64]) -> Index {
        Index::back_to_back(
            lengths
                .iter()
                .enumerate()
                .map(|(i, &length)| (length, i.checked_sub(1))),
        )
    }

    /// The index of units of these lengths and parents, laid out back to back in order.
    pub fn back_to_back(units: impl IntoIterator<Item = (u64, Option<usize>)>) -> Index {
        let mut offset = 0;
        let units = units
            .into_iter()
            .map(|(length, parent)| {
                let unit = UnitEntry {
                    offset,
                    length,
                    parent,
                };
                offset += length;
                unit
            })
            .collect();
        Index {
            units,
            payload_bytes: offset,
            appearance: None,
        }
    }

    /// True when the units are levels: back to back in order, each depending on the one before.
    pub fn is_layered(&self) -> bool {
        let mut offset = 0;
        self.units.iter().enumerate().all(|(i, unit)| {
            let in_place = unit.offset == offset && unit.parent == i.checked_sub(1);
            offset += unit.length;
            in_place
        })
    }

    /// Refuses an index whose units are not levels (`at`: the payload's offset, for the error).
    pub fn require_layered(&self, at: usize) -> Result<()> {
        if !self.is_layered() {
            return Err(Error::malformed(
                0,
                at,
                "index: this codec's units are levels, laid out in order, each after the one before",
            ));
        }
        Ok(())
    }

    /// Number of units.
    pub fn len(&self) -> usize {
        self.units.len()
    }

    /// True when the index lists no unit (no stream has such an index).
    pub fn is_empty(&self) -> bool {
        self.units.is_empty()
    }

    /// Appends the index's bytes to `out`.
    pub fn write(&self, out: &mut Vec<u8>) {
        varint::put(
            out,
            (self.units.len() + self.appearance.is_some() as usize) as u64,
        );
        varint::put(out, self.payload_bytes);
        for (i, unit) in self.units.iter().chain(&self.appearance).enumerate() {
            varint::put(out, unit.offset);
            varint::put(out, unit.length);
            varint::put(out, unit.parent.map_or(0, |p| (i - p) as u64));
        }
    }

    /// Reads and checks an index from `bytes` at `pos`.
    fn read(bytes: &[u8], pos: &mut usize) -> Result<Index> {
        let units = read_count(bytes, pos, "units", limits::MAX_UNITS)?;
        let payload_bytes = read_count(bytes, pos, "payload bytes", u64::MAX >> 1)?;
        if units == 0 {
            return Err(Error::malformed(0, *pos, "the index lists no unit"));
        }
        // Nothing is allocated for the entries before the bytes that must hold them are there.
        if ((bytes.len() - *pos) as u64) < units * MIN_ENTRY_BYTES {
            return Err(Error::Truncated("the stream ends inside its index".into()));
        }
        let mut entries = Vec::with_capacity(units as usize);
        for i in 0..units as usize {
            let at = *pos;
            // Bounded so that their sum cannot overflow; checked against the payload below.
            let offset = read_count(bytes, pos, "unit offset", u64::MAX >> 2)?;
            let length = read_count(bytes, pos, "unit length", u64::MAX >> 2)?;
            let back = read_count(bytes, pos, "parent distance", i as u64)?;
            if offset + length > payload_bytes {
                return Err(Error::malformed(
                    0,
                    at,
                    format!(
                        "index: unit {i} (bytes {offset}..{}) runs past the {payload_bytes} payload bytes",
                        offset + length
                    ),
                ));
            }
            entries.push(UnitEntry {
                offset,
                length,
                parent: (back > 0).then(|| i - back as usize),
            });
        }
        let mut by_offset: Vec<usize> = (0..entries.len()).collect();
        by_offset.sort_by_key(|&i| (entries[i].offset, entries[i].length));
        for pair in by_offset.windows(2) {
            let (a, b) = (entries[pair[0]], entries[pair[1]]);
            if b.offset < a.end() {
                return Err(Error::malformed(
                    0,
                    *pos,
                    format!(
                        "index: units {} (bytes {}..{}) and {} (bytes {}..{}) overlap",
                        pair[0],
                        a.offset,
                        a.end(),
                        pair[1],
                        b.offset,
                        b.end()
                    ),
                ));
            }
        }
        let covered: u64 = entries.iter().map(|u| u.length).sum();
        if covered != payload_bytes {
            return Err(Error::malformed(
                0,
                *pos,
                format!(
                    "index: units cover {covered} of the {payload_bytes} payload bytes it declares"
                ),
            ));
        }
        Ok(Index {
            units: entries,
            payload_bytes,
            appearance: None,
        })
    }
}

/// A varint count at `pos`, no larger than `limit`.
fn read_count(bytes: &[u8], pos: &mut usize, what: &str, limit: u64) -> Result<u64> {
    let at = *pos;
    let value = varint::get(bytes, pos).map_err(|f| match f {
        varint::VarintFault::Truncated => {
            Error::Truncated("the stream ends inside its header".into())
        }
        varint::VarintFault::Overflow => {
            Error::malformed(0, at, format!("{what} overflows 64 bits"))
        }
    })?;
    if value > limit {
        return Err(Error::Limit(format!(
            "stream declares {value} {what} (at most {limit})"
        )));
    }
    Ok(value)
}

impl Header {
    /// Appends the header's bytes to `out`.
    pub fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.push(self.version());
        out.push(self.codec_id);
        varint::put(out, self.params.len() as u64);
        out.extend_from_slice(&self.params);
        out.push(self.grid.bits);
        for v in self.grid.origin.iter().chain(&self.grid.cell) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        varint::put(out, self.vertices);
        varint::put(out, self.triangles);
        if let Some(appearance) = &self.appearance {
            appearance.write(out);
        }
    }

    /// Reads a header from the start of `bytes`; returns it and the offset of the index.
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
        if ![
            GEOMETRY_ONLY_VERSION,
            APPEARANCE_UNIT_VERSION,
            FORMAT_VERSION,
        ]
        .contains(&version)
        {
            return Err(Error::Unsupported(format!(
                "stream format version {version} (this build reads versions {GEOMETRY_ONLY_VERSION}, {APPEARANCE_UNIT_VERSION} and {FORMAT_VERSION})"
            )));
        }
        let codec_id = *bytes.get(5).ok_or_else(cut)?;
        let mut pos = 6;
        let param_len = read_count(bytes, &mut pos, "parameter bytes", limits::MAX_PARAM_BYTES)?;
        let params = bytes
            .get(pos..pos + param_len as usize)
            .ok_or_else(cut)?
            .to_vec();
        pos += param_len as usize;
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
        let vertices = read_count(bytes, &mut pos, "vertices", limits::MAX_VERTICES)?;
        let triangles = read_count(bytes, &mut pos, "triangles", limits::MAX_TRIANGLES)?;
        if vertices == 0 || triangles == 0 {
            // No encoder writes an empty mesh (empty input is refused before encoding).
            return Err(bad(
                pos,
                &format!("header declares {vertices} vertices and {triangles} triangles"),
            ));
        }
        let appearance = if version == GEOMETRY_ONLY_VERSION {
            None
        } else {
            let at = pos;
            let spec = AppearanceSpec::read(bytes, &mut pos)?;
            // Each version says where the values are: 4 in a unit, 5 in the levels.
            if spec.in_levels != (version == FORMAT_VERSION) {
                return Err(Error::malformed(
                    0,
                    at,
                    format!("version {version} streams do not carry appearance that way"),
                ));
            }
            Some(spec)
        };
        let header = Header {
            codec_id,
            params,
            grid,
            vertices,
            triangles,
            appearance,
        };
        Ok((header, pos))
    }
}

/// Reads the header and index at the start of `bytes`; returns them and the payload's offset.
/// When the header declares an appearance unit, the index's last unit is that unit: it is
/// taken out of the units into [`Index::appearance`], so a codec sees its own units only.
pub fn read_header_and_index(bytes: &[u8]) -> Result<(Header, Index, usize)> {
    let (header, mut pos) = Header::read(bytes)?;
    let mut index = Index::read(bytes, &mut pos)?;
    if header.appearance.as_ref().is_some_and(|a| !a.in_levels) {
        if index.units.len() < 2 {
            return Err(Error::malformed(
                0,
                pos,
                "index: a stream with appearance needs a unit of geometry and the appearance unit",
            ));
        }
        let unit = index.units.pop().expect("two units or more");
        if unit.end() != index.payload_bytes {
            return Err(Error::malformed(
                0,
                pos,
                "index: the appearance unit is not the payload's last bytes",
            ));
        }
        index.appearance = Some(unit);
    }
    Ok((header, index, pos))
}

/// What a layered encoder reports about one level as it writes it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelCost {
    /// Connectivity bits booked in this level alone.
    pub connectivity_bits: u64,
    /// Geometry bits booked in this level alone.
    pub geometry_bits: u64,
    /// Vertices of the mesh after this level.
    pub vertices: usize,
    /// Triangles of the mesh after this level.
    pub triangles: usize,
}

/// One level as the encoder wrote it, with the cost of the stream up to its end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelRecord {
    /// Offset in the stream where this level ends (so bits so far = 8 × end_byte).
    pub end_byte: usize,
    /// Connectivity bits booked in this level and all before it.
    pub connectivity_bits: u64,
    /// Geometry bits booked in this level and all before it.
    pub geometry_bits: u64,
    /// Vertices of the mesh after this level.
    pub vertices: usize,
    /// Triangles of the mesh after this level.
    pub triangles: usize,
}

/// Builds a stream unit by unit: the header and index are written when it finishes. A layered
/// codec pushes one unit per level ([`StreamWriter::push_level`]); a hierarchical one pushes its
/// units with their parents ([`StreamWriter::push_unit`]) and marks where each level ends
/// ([`StreamWriter::mark_level`]).
pub struct StreamWriter {
    header: Header,
    payload: Vec<u8>,
    units: Vec<(u64, Option<usize>)>,
    /// Per level: payload bytes up to its end, and its cost.
    marks: Vec<(u64, LevelCost)>,
}

impl StreamWriter {
    /// Starts a stream with `header`.
    pub fn new(header: &Header) -> Self {
        StreamWriter {
            header: header.clone(),
            payload: Vec::new(),
            units: Vec::new(),
            marks: Vec::new(),
        }
    }

    /// Appends one level's payload and what it cost: a unit whose parent is the level before.
    pub fn push_level(&mut self, payload: &[u8], cost: LevelCost) {
        let parent = self.units.len().checked_sub(1);
        self.push_unit(payload, parent);
        self.mark_level(cost);
    }

    /// Appends one unit that depends on unit `parent` (an earlier one), or on none; returns its
    /// number.
    pub fn push_unit(&mut self, payload: &[u8], parent: Option<usize>) -> usize {
        debug_assert!(parent.is_none_or(|p| p < self.units.len()));
        self.payload.extend_from_slice(payload);
        self.units.push((payload.len() as u64, parent));
        self.units.len() - 1
    }

    /// Ends a level after the units pushed so far; `cost` is what this level added.
    pub fn mark_level(&mut self, cost: LevelCost) {
        self.marks.push((self.payload.len() as u64, cost));
    }

    /// The stream and, for each level, where it ends and what the stream cost up to there.
    pub fn finish(self) -> (Vec<u8>, Vec<LevelRecord>) {
        let mut bytes = Vec::with_capacity(self.payload.len() + 64 + 12 * self.units.len());
        self.header.write(&mut bytes);
        Index::back_to_back(self.units.iter().copied()).write(&mut bytes);
        let start = bytes.len();
        bytes.extend_from_slice(&self.payload);
        let (mut connectivity, mut geometry) = (0, 0);
        let records = self
            .marks
            .iter()
            .map(|&(end, cost)| {
                connectivity += cost.connectivity_bits;
                geometry += cost.geometry_bits;
                LevelRecord {
                    end_byte: start + end as usize,
                    connectivity_bits: connectivity,
                    geometry_bits: geometry,
                    vertices: cost.vertices,
                    triangles: cost.triangles,
                }
            })
            .collect();
        (bytes, records)
    }
}

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
        reader.check_length()?;
        Ok(reader)
    }

    /// Refuses bytes past the payload's end.
    fn check_length(&self) -> Result<()> {
        let present = (self.bytes.len() - self.payload_start) as u64;
        if present > self.index.payload_bytes {
            return Err(Error::malformed(
                self.index.len(),
                self.payload_start + self.index.payload_bytes as usize,
                format!(
                    "{} bytes after the last unit",
                    present - self.index.payload_bytes
                ),
            ));
        }
        Ok(())
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

    /// Unit `i`, when all its bytes are present.
    pub fn unit(&self, i: usize) -> Option<LevelPayload<'_>> {
        let entry = self.index.units.get(i)?;
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
        let room = (self.payload_start as u64 + self.index.payload_bytes)
            .saturating_sub(self.bytes.len() as u64);
        if more.len() as u64 > room {
            return Err(Error::malformed(
                self.index.len(),
                self.payload_start + self.index.payload_bytes as usize,
                format!("{} bytes after the last unit", more.len() as u64 - room),
            ));
        }
        self.bytes.to_mut().extend_from_slice(more);
        Ok(())
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
}

impl LevelSource for StreamReader<'_> {
    fn header(&self) -> &Header {
        StreamReader::header(self)
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
            appearance: None,
        }
    }

    fn two_levels() -> (Vec<u8>, Vec<LevelRecord>) {
        let mut writer = StreamWriter::new(&header());
        writer.push_level(&[9; 5], LevelCost::default());
        writer.push_level(&[8; 300], LevelCost::default());
        writer.finish()
    }

    /// A stream with `header()` and the given index over `payload`.
    fn with_index(index: &Index, payload: &[u8]) -> Vec<u8> {
        let mut bytes = Vec::new();
        header().write(&mut bytes);
        index.write(&mut bytes);
        bytes.extend_from_slice(payload);
        bytes
    }

    #[test]
    fn header_and_levels_round_trip_and_every_prefix_reads_cleanly() {
        let (bytes, records) = two_levels();
        let mut reader = StreamReader::open(&bytes).unwrap();
        assert!(reader.require_layered().is_ok());
        assert_eq!(reader.header(), &header());
        assert_eq!(reader.next_level().unwrap().bytes, &[9; 5]);
        assert_eq!(reader.next_level().unwrap().bytes.len(), 300);
        assert!(reader.next_level().is_none());
        assert_eq!(records.last().map(|r| r.end_byte), Some(bytes.len()));
        for cut in 0..bytes.len() {
            match StreamReader::open(&bytes[..cut]) {
                Err(Error::Truncated(_)) => {}
                Err(e) => panic!("cut {cut}: {e}"),
                Ok(mut r) => {
                    let mut complete = 0;
                    while r.next_level().is_some() {
                        complete += 1;
                    }
                    let expected = records.iter().filter(|r| r.end_byte <= cut).count();
                    assert_eq!(complete, expected, "cut {cut}");
                    assert!(r.truncated());
                }
            }
        }
    }

    #[test]
    fn any_unit_is_found_from_the_header_and_index_alone() {
        let (bytes, records) = two_levels();
        let (_, index, payload_start) = read_header_and_index(&bytes).unwrap();
        let unit = index.units[1];
        let start = payload_start + unit.offset as usize;
        assert_eq!(start, records[0].end_byte);
        assert_eq!(&bytes[start..start + unit.length as usize], &[8; 300]);
        assert_eq!(unit.parent, Some(0));
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

    #[test]
    fn normal_modes_are_declared_only_with_normals_inside_the_levels() {
        let spec = AppearanceSpec {
            normal_bits: Some(10),
            in_levels: true,
            derived_normals: true,
            ..AppearanceSpec::default()
        };
        let mut bytes = Vec::new();
        spec.write(&mut bytes);
        assert_eq!(AppearanceSpec::read(&bytes, &mut 0).unwrap(), spec);
        // Either normal mode without normals, or without the levels carrying them, or both
        // modes at once: refused.
        let both = FLAG_NORMALS | FLAG_IN_LEVELS | FLAG_GEOMETRIC_NORMALS;
        for flags in [FLAG_UVS | FLAG_IN_LEVELS, FLAG_NORMALS, both] {
            let mut bad = bytes.clone();
            bad[0] = flags | FLAG_DERIVED_NORMALS;
            let err = AppearanceSpec::read(&bad, &mut 0).unwrap_err();
            assert!(err.to_string().contains("appearance flags"), "{err}");
        }
    }

    #[test]
    fn unknown_versions_are_refused() {
        let (mut bytes, _) = two_levels();
        bytes[4] = 1;
        let e = StreamReader::open(&bytes).unwrap_err();
        assert!(e.to_string().contains("format version 1"), "{e}");
        // Version 3's appearance units are not version 4's.
        bytes[4] = 3;
        let e = StreamReader::open(&bytes).unwrap_err();
        assert!(e.to_string().contains("format version 3"), "{e}");
    }

    #[test]
    fn lying_indexes_are_refused() {
        let entry = |offset, length, parent| UnitEntry {
            offset,
            length,
            parent,
        };
        let past = Index {
            units: vec![entry(0, 4, None), entry(4, 10, Some(0))],
            payload_bytes: 8,
            appearance: None,
        };
        let e = StreamReader::open(&with_index(&past, &[0; 8])).unwrap_err();
        assert!(e.to_string().contains("runs past"), "{e}");
        let overlapping = Index {
            units: vec![entry(0, 6, None), entry(4, 2, Some(0))],
            payload_bytes: 8,
            appearance: None,
        };
        let e = StreamReader::open(&with_index(&overlapping, &[0; 8])).unwrap_err();
        assert!(e.to_string().contains("overlap"), "{e}");
        let gap = Index {
            units: vec![entry(0, 2, None), entry(4, 2, Some(0))],
            payload_bytes: 8,
            appearance: None,
        };
        let e = StreamReader::open(&with_index(&gap, &[0; 8])).unwrap_err();
        assert!(e.to_string().contains("cover 4 of the 8"), "{e}");
        // A count of units the bytes cannot hold is refused before any entry is read.
        let mut huge = Vec::new();
        header().write(&mut huge);
        varint::put(&mut huge, limits::MAX_UNITS);
        varint::put(&mut huge, 8);
        assert!(matches!(
            StreamReader::open(&huge),
            Err(Error::Truncated(_))
        ));
        // Units out of order are a valid index, but not the levels of a layered codec.
        let swapped = Index {
            units: vec![entry(4, 4, None), entry(0, 4, Some(0))],
            payload_bytes: 8,
            appearance: None,
        };
        let bytes = with_index(&swapped, &[0; 8]);
        assert!(StreamReader::open(&bytes).is_ok());
        assert!(StreamReader::open(&bytes)
            .unwrap()
            .require_layered()
            .is_err());
    }

    #[test]
    fn bytes_after_the_payload_are_refused() {
        let (mut bytes, _) = two_levels();
        bytes.push(0);
        let e = StreamReader::open(&bytes).unwrap_err();
        assert!(e.to_string().contains("after the last unit"), "{e}");
    }

    #[test]
    fn levels_read_from_an_input_stream_match() {
        let (bytes, _) = two_levels();
        let mut source = ReadLevels::open(&bytes[..]).unwrap();
        assert_eq!(
            source.next_owned_level().unwrap().unwrap().bytes,
            vec![9; 5]
        );
        assert_eq!(source.next_owned_level().unwrap().unwrap().bytes.len(), 300);
        assert!(source.next_owned_level().unwrap().is_none());
    }
}
