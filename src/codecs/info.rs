//! What a stream says of itself without decoding it: one description, [`StreamInfo`], which
//! `meshcodec info` (text and `--json`), the Python package's `info` and the WebAssembly
//! package's `info` all render from its serde form, so each key means the same everywhere. What
//! only a codec knows how to read of its header it says itself ([`Codec::facts`]).

use super::{for_header, level_ends_of, Codec};
use crate::container::StreamReader;
use crate::error::Result;
use serde::Serialize;

/// A stream's header and index, described ([`StreamInfo::of`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StreamInfo {
    /// The codec that wrote it.
    pub codec: &'static str,
    /// Its format version (docs/FORMAT.md §1).
    pub format_version: u8,
    /// The codec's syntax it is written in (docs/FORMAT.md §1).
    pub syntax: u8,
    /// Bytes given (a prefix, or the whole stream).
    pub bytes: u64,
    /// Bytes of the whole stream, as its index says.
    pub stream_bytes: u64,
    /// Whether the bytes given end before the stream does.
    pub truncated: bool,
    /// Bits per axis of the quantization grid (Q).
    pub quant_bits: u8,
    /// The grid's smallest corner.
    pub origin: [f64; 3],
    /// The grid's cell size on each axis.
    pub cell: [f64; 3],
    /// Vertices of the full mesh.
    pub vertices: u64,
    /// Triangles of the full mesh.
    pub triangles: u64,
    /// Levels of the stream.
    pub levels: usize,
    /// The bytes each level needs, from the stream's first ([`level_ends`](super::level_ends)): the full level of a
    /// stream with an appearance unit ends with that unit.
    pub level_ends: Vec<u64>,
    /// Where the units start.
    pub payload_start: u64,
    /// Whether each unit is a level (else units are meta-nodes, CAME, each with its parent).
    pub layered: bool,
    /// Every unit, with its parent and byte range in the stream.
    pub units: Vec<UnitInfo>,
    /// What appearance the stream carries, if any.
    pub appearance: Option<AppearanceInfo>,
    /// What the codec reads of its header.
    #[serde(flatten)]
    pub facts: CodecFacts,
}

/// One unit of a stream's index.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct UnitInfo {
    /// Its position in the index.
    pub unit: usize,
    /// The unit decoded before it (meta-nodes), if any.
    pub parent: Option<usize>,
    /// Its first byte, from the stream's first.
    pub first_byte: u64,
    /// One past its last byte.
    pub end_byte: u64,
    /// Its length.
    pub bytes: u64,
    /// Whether the bytes given hold all of it.
    pub present: bool,
}

/// The appearance a stream carries (docs/FORMAT.md §5).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AppearanceInfo {
    /// Qn of the octahedral normals, when there are normals.
    pub normal_bits: Option<u8>,
    /// How normals travel: "coded", "predicted" from the geometry, or "derived" from it.
    pub normals: Option<&'static str>,
    /// Qt of the uvs, when there are uvs.
    pub uv_bits: Option<u8>,
    /// The uv grid's smallest corner.
    pub uv_origin: Option<[f64; 2]>,
    /// The uv grid's cell.
    pub uv_cell: Option<f64>,
    /// Whether wedges carry colours.
    pub colours: bool,
    /// The materials' names, when faces carry materials.
    pub materials: Option<Vec<String>>,
    /// The material library the mesh named.
    pub material_library: Option<String>,
    /// Whether the values are coded inside every level (`pm`) rather than in a unit after the
    /// last.
    pub in_levels: bool,
    /// The appearance unit, when the values are in one.
    pub unit: Option<UnitInfo>,
    /// The unit of each level's appearance, which follows it (docs/FORMAT.md §10: `emc`,
    /// `emc-ahead`); empty when the values are elsewhere. `unit` is the level's number.
    pub level_parts: Vec<UnitInfo>,
}

/// What only the codec of a stream knows how to read of its header ([`Codec::facts`]); what a
/// codec does not say is absent (`None`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct CodecFacts {
    /// `pm` streams of a mesh cut to an oriented 2-manifold: the vertex copies the levels before
    /// the last hold at their originals' cells.
    pub vertex_copies: Option<u64>,
    /// CAME streams: whether inner nodes carry normal cones (back faces culled when refining).
    pub normal_cones: Option<bool>,
}

impl StreamInfo {
    /// The description of `bytes`, a whole stream or a prefix holding at least its header and
    /// index.
    pub fn of(bytes: &[u8]) -> Result<StreamInfo> {
        let reader = StreamReader::open(bytes)?;
        let header = reader.header();
        let codec: &dyn Codec = for_header(header)?;
        let index = reader.index();
        let start = reader.payload_start() as u64;
        // Present: its bytes are all in (a level's unit may be, while the reader holds the
        // level back until its appearance part is in too).
        let received = bytes.len() as u64;
        let unit = |i: usize, entry: &crate::container::UnitEntry| UnitInfo {
            unit: i,
            parent: entry.parent,
            first_byte: start + entry.offset,
            end_byte: start + entry.end(),
            bytes: entry.length,
            present: start + entry.end() <= received,
        };
        let units = index
            .units
            .iter()
            .enumerate()
            .map(|(i, entry)| unit(i, entry))
            .collect();
        let appearance = header.appearance.as_ref().map(|spec| AppearanceInfo {
            normal_bits: spec.normal_bits,
            normals: spec.normal_mode(),
            uv_bits: spec.uv_grid.map(|g| g.bits),
            uv_origin: spec.uv_grid.map(|g| g.origin),
            uv_cell: spec.uv_grid.map(|g| g.cell),
            colours: spec.colours,
            materials: spec.materials.as_ref().map(|m| m.names.clone()),
            material_library: spec.materials.as_ref().and_then(|m| m.library.clone()),
            in_levels: spec.in_levels,
            unit: index.appearance.map(|entry| unit(index.len(), &entry)),
            level_parts: index
                .level_parts
                .iter()
                .enumerate()
                .map(|(i, entry)| unit(i, entry))
                .collect(),
        });
        let ends = level_ends_of(&reader)?;
        Ok(StreamInfo {
            codec: codec.name(),
            format_version: crate::container::FORMAT_VERSION,
            syntax: header.syntax,
            bytes: bytes.len() as u64,
            stream_bytes: start + index.payload_bytes,
            truncated: reader.truncated(),
            quant_bits: header.grid.bits,
            origin: header.grid.origin,
            cell: header.grid.cell,
            vertices: header.vertices,
            triangles: header.triangles,
            levels: ends.len(),
            level_ends: ends,
            payload_start: start,
            // A CAME stream's units are meta-nodes, even one of a single unit (whose index
            // is trivially laid out as levels): its levels are depths.
            layered: index.is_layered() && codec.selective_refinement().is_none(),
            units,
            appearance,
            facts: codec.facts(header),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{golden, level_ends};

    /// Every golden stream described: levels as `level_ends` says, units laid end to end up to
    /// the stream's last byte, what each codec reads of its header, and a prefix called
    /// truncated with the units past it absent.
    #[test]
    fn streams_describe_themselves() {
        for name in [
            "v8/raw-eight.mc",
            "v8/emc-beethoven.mc",
            "v8/emc-paper-eight.mc",
            "v8/pm-bunny-res4.mc",
            "v8/pm-reordered-eight.mc",
            "v8/came-eight.mc",
            "v8/came-paper-eight.mc",
            "v8/emc-spot-appearance.mc",
            "v8/pm-reordered-spot-appearance-fit.mc",
        ] {
            let bytes = golden(name);
            let info = StreamInfo::of(&bytes).unwrap();
            assert_eq!(info.level_ends, level_ends(&bytes).unwrap(), "{name}");
            assert_eq!(info.levels, info.level_ends.len(), "{name}");
            assert_eq!(info.bytes, bytes.len() as u64, "{name}");
            assert_eq!(info.stream_bytes, info.bytes, "{name}");
            assert!(!info.truncated && info.units.iter().all(|u| u.present));
            let mut end = info.payload_start;
            let parts = info.appearance.iter().flat_map(|a| &a.level_parts);
            let mut in_stream_order: Vec<&UnitInfo> = Vec::new();
            for (i, level) in info.units.iter().enumerate() {
                in_stream_order.push(level);
                in_stream_order.extend(parts.clone().nth(i));
            }
            in_stream_order.extend(info.appearance.iter().flat_map(|a| &a.unit));
            for unit in in_stream_order {
                assert_eq!(unit.first_byte, end, "{name}: unit {}", unit.unit);
                assert_eq!(unit.end_byte - unit.first_byte, unit.bytes);
                end = unit.end_byte;
            }
            assert_eq!(end, info.bytes, "{name}");
            let codec = crate::codecs::by_name(info.codec).unwrap();
            let header = StreamReader::open(&bytes).unwrap().header().clone();
            assert_eq!(info.facts, codec.facts(&header), "{name}");
            let refines = codec.selective_refinement().is_some();
            assert_eq!(info.facts.normal_cones.is_some(), refines, "{name}");
            assert_eq!(info.layered, !refines, "{name}: units are levels");

            let cut =
                &bytes[..(info.payload_start + (info.bytes - info.payload_start) / 2) as usize];
            let prefix = StreamInfo::of(cut).unwrap();
            assert!(prefix.truncated, "{name}");
            assert!(prefix.units.iter().any(|u| !u.present), "{name}");
            assert_eq!(prefix.stream_bytes, info.stream_bytes, "{name}");
        }
    }

    /// The keys every renderer shows (the command line's `info --json`, the Python package's
    /// `info`; the WebAssembly package's in camelCase), flattened facts included.
    #[test]
    fn the_serde_form_has_the_documented_keys() {
        let info = StreamInfo::of(&golden("v8/pm-bunny-res4.mc")).unwrap();
        let value = serde_json::to_value(&info).unwrap();
        let keys: Vec<&str> = value
            .as_object()
            .unwrap()
            .keys()
            .map(|k| k.as_str())
            .collect();
        for key in [
            "codec",
            "format_version",
            "syntax",
            "bytes",
            "stream_bytes",
            "truncated",
            "quant_bits",
            "origin",
            "cell",
            "vertices",
            "triangles",
            "levels",
            "level_ends",
            "payload_start",
            "layered",
            "units",
            "appearance",
            "vertex_copies",
            "normal_cones",
        ] {
            assert!(keys.contains(&key), "{key} missing from {keys:?}");
        }
        assert_eq!(value["units"][0]["first_byte"], info.payload_start);
    }
}
