//! Codecs behind one object-safe trait, found by name or stream id in a registry.
//!
//! A codec encodes a [`CanonicalMesh`] into a stream of units (docs/FORMAT.md §2) and hands out a
//! [`LevelDecoder`] that walks a stream level by level, coarse to fine, as Hoppe's PMeshIter
//! walks vertex splits. The full decode of a stream is lossless: it equals the canonical mesh
//! (docs/CONTRACT.md §3). What only some codecs do is a [`Capability`] a caller asks for, and a
//! request for one a codec lacks is refused, never ignored.

pub mod appearance;
pub mod came;
mod descriptor;
pub mod emc;
pub mod info;
pub mod names;
pub mod pm;
mod progressive;
pub mod raw;
mod request;
pub mod stats;

use crate::container::{Header, StreamReader};
pub use crate::container::{LevelCost, LevelRecord};
use crate::error::{Error, Result};
use crate::mesh::attributes::Attributes;
use crate::mesh::canonical_attributes::CanonicalAttributes;
use crate::mesh::quantize::GridShape;
use crate::mesh::{CanonicalMesh, Grid, TriMesh, VertexId};
pub use descriptor::Descriptor;
pub use info::{CodecFacts, StreamInfo};
pub use request::{EncodeRequest, EncodedMesh};
pub use stats::{CameField, Stat, Stats};

/// How a mesh is quantized before it is encoded: the grid of its canonical mesh
/// (docs/CONTRACT.md §1). The canonical mesh carries its grid, so a codec is handed the mesh
/// alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncodeOptions {
    /// Bits per axis of the quantization grid (Q).
    pub quant_bits: u8,
    /// How cells are shaped.
    pub grid: GridShape,
}

/// An encoded stream and what each level cost.
#[derive(Clone, Debug)]
pub struct Encoded {
    /// The whole stream.
    pub bytes: Vec<u8>,
    /// One record per level, in stream order.
    pub levels: Vec<LevelRecord>,
    /// Codec-specific counts (bits per syntax element, operation counts…) for tables.
    pub stats: Stats,
}

/// The mesh a stream decodes to at some level: positions at cell centres (of the level's own,
/// possibly coarser, cells), faces, and edges that belong to no face (a coarse level of an
/// embedded coder may have edges before it has triangles).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LevelMesh {
    /// Vertices and faces.
    pub mesh: TriMesh,
    /// Edges not on any face.
    pub loose_edges: Vec<[VertexId; 2]>,
    /// Wedges and materials over `mesh`'s faces: at the full level of a stream with an
    /// appearance unit, once that unit is decoded (levels before it have none).
    pub attributes: Option<Attributes>,
}

/// What only some codecs do. A caller asks [`Codec::capabilities`]; decoding with a stop that
/// needs a capability the codec lacks is refused ([`decode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Capability {
    /// Stops after any pass inside a level (EMC: one direction of one octree level), through
    /// [`LevelDecoder::pass_stops`].
    PassStops,
    /// Decodes what is present of a level the stream was cut in, through
    /// [`LevelDecoder::partial_levels`].
    PartialLevels,
    /// Refines parts of the mesh view-dependently, units fetched by byte range, through
    /// [`Codec::selective_refinement`] (`came`, `came-paper`).
    SelectiveRefinement,
    /// Carries appearance attributes — normals, texture coordinates, colours, materials — in
    /// an appearance unit decoded with the full level ([`encode_attributed`]; every codec whose
    /// full decode is the canonical mesh).
    Attributes,
    /// Also carries appearance inside its levels, so that every level has it
    /// ([`Codec::encode_with_appearance`]; `pm`).
    AppearanceInLevels,
    /// Carries appearance in a part after each level, so that every level shows it
    /// (docs/FORMAT.md §10, [`appearance::levels`]): its levels keep their vertices' ids and add
    /// new ones (`emc`, `emc-ahead`). [`encode_attributed`] codes appearance that way for these
    /// codecs.
    AppearanceWithLevels,
}

/// How a codec that refines appearance level by level gives a collapsed wedge its values
/// (`pm`; docs/CONTRACT.md §2.1): interpolated along the collapsed edge to where the surviving
/// vertex went, or the survivor's own (the fast-QEM paper's rule).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AttributeFit {
    /// Interpolated to the collapsed position.
    #[default]
    Fit,
    /// The survivor's.
    Keep,
}

impl AttributeFit {
    /// The name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            AttributeFit::Fit => "fit",
            AttributeFit::Keep => "keep",
        }
    }

    /// The rule called `name`.
    pub fn by_name(name: &str) -> Result<AttributeFit> {
        match name {
            "fit" => Ok(AttributeFit::Fit),
            "keep" => Ok(AttributeFit::Keep),
            _ => Err(Error::Unsupported(format!(
                "unknown attribute rule '{name}' (fit, keep)"
            ))),
        }
    }
}

/// A progressive mesh codec.
pub trait Codec: Send + Sync {
    /// What the codec is: name, id, summary, defaults, capabilities ([`Descriptor`]).
    fn descriptor(&self) -> &'static Descriptor;
    /// Name on the command line and in results/ ([`names`]).
    fn name(&self) -> &'static str {
        self.descriptor().naming.name
    }
    /// Identifier in the stream header ([`names`]).
    fn id(&self) -> u8 {
        self.descriptor().naming.id
    }

    /// The syntax byte of the streams it writes, the only one it reads.
    fn syntax(&self) -> u8 {
        self.descriptor().naming.syntax
    }
    /// One line on what the codec is.
    fn summary(&self) -> &'static str {
        self.descriptor().summary
    }
    /// The quantization used when the user gives none.
    fn default_options(&self) -> EncodeOptions {
        self.descriptor().default_options
    }
    /// What this codec does beyond decoding level by level.
    fn capabilities(&self) -> &'static [Capability] {
        self.descriptor().capabilities
    }
    /// Whether the full decode is the canonical mesh (docs/CONTRACT.md §3). A lossy codec's full
    /// level is reported with its error, never called lossless.
    fn lossless(&self) -> bool {
        self.descriptor().lossless
    }
    /// Encodes the canonical mesh (on its own grid); refuses with [`Error::Unsupported`] a mesh
    /// it cannot code.
    fn encode(&self, mesh: &CanonicalMesh) -> Result<Encoded>;
    /// A decoder positioned before the first level of `stream` (whose header names this codec).
    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>>;
    /// Codec-specific measurements of an encoded stream (PM: iteration rates), stored with the
    /// run's results; codecs with none return an empty set.
    fn measure(&self, stream: &[u8]) -> Result<Stats>;
    /// Encodes the canonical mesh with its appearance coded inside the levels, so that every
    /// level carries it, for codecs with [`Capability::AppearanceInLevels`]; `None` for the
    /// others, which carry appearance in an appearance unit after their last level
    /// ([`encode_attributed`]).
    fn encode_with_appearance(
        &self,
        _mesh: &CanonicalMesh,
        _appearance: &CanonicalAttributes,
        _fit: AttributeFit,
    ) -> Option<Result<Encoded>> {
        None
    }
    /// What the codec offers view-dependent refinement, for codecs with
    /// [`Capability::SelectiveRefinement`] (the CAME codecs); `None` for the others.
    fn selective_refinement(&self) -> Option<&dyn came::selective::SelectiveRefinement> {
        None
    }
    /// What a stream's header says that only this codec knows how to read, for
    /// [`StreamInfo`]; nothing by default.
    fn facts(&self, _header: &Header) -> CodecFacts {
        CodecFacts::default()
    }
    /// The most vertices any level of a stream with `header` may decode to: the header's by
    /// default (`pm` streams cut to a manifold hold copies before their last level).
    fn most_level_vertices(&self, header: &Header) -> u64 {
        header.vertices
    }
    /// How many bytes of the stream, from its first, decoding each level needs (entry k for
    /// level k + 1): where a reader of a stream still arriving can decode the next level. From
    /// the header and index alone; this default is for streams whose units are their levels.
    fn level_ends(&self, stream: &StreamReader) -> Result<Vec<u64>> {
        stream.require_layered()?;
        let start = stream.payload_start() as u64;
        Ok(stream
            .index()
            .units
            .iter()
            .map(|u| start + u.end())
            .collect())
    }
}

/// Walks a stream level by level. `Send`, so a decoder can move to another thread (the Python
/// package decodes with the interpreter's lock released).
pub trait LevelDecoder: Send {
    /// The stream's header.
    fn header(&self) -> &Header;
    /// Levels the stream holds when whole.
    fn levels(&self) -> usize;
    /// Levels decoded so far.
    fn levels_decoded(&self) -> usize;
    /// Decodes the next complete level; `Ok(false)` when none is left (the stream's end, or the
    /// prefix ends inside the next level).
    fn advance(&mut self) -> Result<bool>;
    /// The mesh after the levels decoded so far (an error where showing it would pass a limit).
    fn mesh(&self) -> Result<LevelMesh>;
    /// Stops inside a level, for codecs with [`Capability::PassStops`]; `None` for the others.
    fn pass_stops(&mut self) -> Option<&mut dyn PassStops> {
        None
    }
    /// Decodes part of a cut level, for codecs with [`Capability::PartialLevels`]; `None` for
    /// the others.
    fn partial_levels(&mut self) -> Option<&mut dyn PartialLevels> {
        None
    }
    /// Takes the stream's next bytes as they arrive (a decoder opened by [`open_owned`] on a
    /// prefix): the levels they complete decode next, from where the decoder stands.
    /// `Ok(false)` from a decoder that cannot take more, and has not taken them (it is opened
    /// again on the longer prefix); bytes past the stream's end are an error.
    fn extend(&mut self, _more: &[u8]) -> Result<bool> {
        Ok(false)
    }
    /// Per vertex of the current level, the **representative** it stands for: a name, unique,
    /// of a vertex of the full mesh, which keeps it to the full level (docs/FORMAT.md §10,
    /// [`appearance::levels`]); `None` when every vertex stands for the vertex of the full mesh
    /// with its id.
    fn representatives(&self) -> Option<Vec<u32>> {
        None
    }
}

/// A decoder that can stop after any pass of a level.
pub trait PassStops {
    /// Passes in one level.
    fn passes_per_level(&self) -> usize;
    /// Decodes only the first `passes` passes of the next level and stops there; no level can
    /// be decoded after it. `Ok(false)` when the next level is not present.
    fn advance_passes(&mut self, passes: usize) -> Result<bool>;
}

/// A decoder that can decode part of a level the stream was cut in.
pub trait PartialLevels {
    /// Decodes what is present of the level the stream was cut in; `Ok(false)` when nothing
    /// more could be decoded.
    fn advance_partial(&mut self) -> Result<bool>;
}

pub use progressive::Progressive;

/// Every codec of this build.
pub fn registry() -> Vec<&'static dyn Codec> {
    vec![
        &raw::Raw,
        &emc::paper::EmcPaper,
        &emc::modelled::Emc { ahead_levels: 0 },
        &emc::modelled::Emc {
            ahead_levels: emc::modelled::AHEAD_LEVELS,
        },
        &pm::Pm {
            ordering: pm::Ordering::Natural,
        },
        &pm::Pm {
            ordering: pm::Ordering::Reordered,
        },
        &came::paper::CamePaper {
            component_bits: came::paper::DEFAULT_COMPONENT_BITS,
        },
        &came::modelled::Came,
    ]
}

/// The codec called `name`, or an error listing the names known.
pub fn by_name(name: &str) -> Result<&'static dyn Codec> {
    registry()
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| {
            let known: Vec<_> = registry().iter().map(|c| c.name()).collect();
            Error::Unsupported(format!(
                "unknown codec '{name}' (codecs: {})",
                known.join(", ")
            ))
        })
}

/// The codec whose streams carry `id`; an id this build does not know is unsupported
/// (docs/CONTRACT.md §7: a stream of a later build's codec is valid, just not readable here).
pub fn by_id(id: u8) -> Result<&'static dyn Codec> {
    registry()
        .into_iter()
        .find(|c| c.id() == id)
        .ok_or_else(|| {
            let known: Vec<String> = registry().iter().map(|c| c.id().to_string()).collect();
            Error::Unsupported(format!(
                "unknown codec id {id} (this build reads ids {})",
                known.join(", ")
            ))
        })
}

/// The codec that reads a stream with `header`: the one its id names, if the header's syntax
/// is the one that codec reads (docs/FORMAT.md §1).
pub fn for_header(header: &Header) -> Result<&'static dyn Codec> {
    let codec = by_id(header.codec_id)?;
    let naming = codec.descriptor().naming;
    if !(naming.reads_from..=naming.syntax).contains(&header.syntax) {
        let reads = if naming.reads_from == naming.syntax {
            format!("syntax {}", naming.syntax)
        } else {
            format!("syntax {} to {}", naming.reads_from, naming.syntax)
        };
        return Err(Error::Unsupported(format!(
            "{} stream of syntax {} (this build reads {reads})",
            codec.name(),
            header.syntax,
        )));
    }
    Ok(codec)
}

/// The canonical mesh that a codec encodes for `mesh` quantized by `options`.
pub fn canonical_for(mesh: &TriMesh, options: &EncodeOptions) -> Result<CanonicalMesh> {
    let grid = Grid::fit(mesh, options.quant_bits, options.grid)?;
    let canonical = CanonicalMesh::new(mesh, grid)?;
    if canonical.faces.is_empty() {
        return Err(Error::mesh(format!(
            "empty mesh: every face is degenerate at {} bits",
            options.quant_bits
        )));
    }
    Ok(canonical)
}

/// Encodes `canonical` with `codec` and, when `appearance` has anything to carry, appends the
/// appearance unit coded against the stream's own full decode (docs/FORMAT.md §9). A codec
/// without [`Capability::Attributes`] refuses appearance.
pub fn encode_attributed(
    codec: &dyn Codec,
    canonical: &CanonicalMesh,
    appearance: Option<&CanonicalAttributes>,
) -> Result<Encoded> {
    encode_attributed_with(codec, canonical, appearance, None)
}

/// [`encode_attributed`], or, with `in_levels`, the appearance coded inside the levels by a
/// codec that can (`pm`), so that every level carries it, collapsed wedges valued by the rule
/// given.
pub fn encode_attributed_with(
    codec: &dyn Codec,
    canonical: &CanonicalMesh,
    appearance: Option<&CanonicalAttributes>,
    in_levels: Option<AttributeFit>,
) -> Result<Encoded> {
    let Some(appearance) = appearance.filter(|a| !a.is_empty()) else {
        return codec.encode(canonical);
    };
    if !codec.capabilities().contains(&Capability::Attributes) {
        return Err(Error::Unsupported(format!(
            "{} cannot carry normals, uvs, colours or materials (its full level is lossy)",
            codec.name()
        )));
    }
    if let Some(fit) = in_levels {
        return codec
            .encode_with_appearance(canonical, appearance, fit)
            .unwrap_or_else(|| {
                Err(Error::Unsupported(format!(
                    "{} does not code appearance in vertex splits (--attributes fit|keep is for pm)",
                    codec.name()
                )))
            });
    }
    if codec
        .capabilities()
        .contains(&Capability::AppearanceWithLevels)
    {
        return encode_with_level_parts(codec, canonical, appearance);
    }
    encode_with_appearance_unit(codec, canonical, appearance)
}

/// `canonical` encoded by `codec` (one with [`Capability::AppearanceWithLevels`]) with
/// `appearance` in a part after each level (docs/FORMAT.md §10).
fn encode_with_level_parts(
    codec: &dyn Codec,
    canonical: &CanonicalMesh,
    appearance: &CanonicalAttributes,
) -> Result<Encoded> {
    let mut encoded = codec.encode(canonical)?;
    let vertices: Vec<usize> = encoded.levels.iter().map(|l| l.vertices).collect();
    let plan = appearance::levels::PartsPlan::for_levels(&vertices, canonical.vertex_count());
    let parts = appearance::levels::encode(&encoded.bytes, canonical, appearance, plan)?;
    let bytes: usize = parts.parts.iter().map(Vec::len).sum();
    encoded.stats.add_named("appearance_bytes", bytes as f64);
    encoded
        .stats
        .add_named("appearance_settled_level", parts.settled_at as f64);
    encoded
        .stats
        .add_named("appearance_birth_levels", plan.birth_levels as f64);
    for (field, bits) in parts.fields {
        encoded
            .stats
            .add_named(&format!("appearance_bits_{field}"), bits);
    }
    let mut writer = crate::container::StreamWriter::reopen(
        std::mem::take(&mut encoded.bytes),
        &encoded.levels,
    )?;
    writer.set_level_parts(appearance::spec_of(appearance), parts.parts)?;
    (encoded.bytes, encoded.levels) = writer.finish();
    Ok(encoded)
}

/// `canonical` encoded by `codec` with `appearance` in one appearance unit after the last
/// level (docs/FORMAT.md §9), whatever the codec's own way: the unit every codec but
/// `came-paper` can carry, for comparing with the codec's way.
pub fn encode_with_appearance_unit(
    codec: &dyn Codec,
    canonical: &CanonicalMesh,
    appearance: &CanonicalAttributes,
) -> Result<Encoded> {
    if !codec.capabilities().contains(&Capability::Attributes) {
        return Err(Error::Unsupported(format!(
            "{} cannot carry normals, uvs, colours or materials (its full level is lossy)",
            codec.name()
        )));
    }
    let mut encoded = codec.encode(canonical)?;
    let (full, _) = decode(&encoded.bytes, Stop::All)?;
    let (unit, fields) = appearance::encode(&full.mesh, canonical, appearance)?;
    encoded
        .stats
        .add_named("appearance_bytes", unit.len() as f64);
    for (field, bits) in fields {
        encoded
            .stats
            .add_named(&format!("appearance_bits_{field}"), bits);
    }
    let mut writer = crate::container::StreamWriter::reopen(
        std::mem::take(&mut encoded.bytes),
        &encoded.levels,
    )?;
    writer.set_appearance(appearance::spec_of(appearance), unit);
    (encoded.bytes, encoded.levels) = writer.finish();
    Ok(encoded)
}

/// The canonical mesh and appearance that a codec encodes for `mesh` with its attributes,
/// quantized by `options` and `bits` (docs/CONTRACT.md §2.1).
pub fn canonical_attributed_for(
    mesh: &crate::mesh::attributes::AttributedMesh,
    options: &EncodeOptions,
    bits: crate::mesh::attribute_quantization::AttributeBits,
) -> Result<(CanonicalMesh, CanonicalAttributes)> {
    let grid = Grid::fit(&mesh.mesh, options.quant_bits, options.grid)?;
    let (canonical, appearance) = crate::mesh::canonical_attributes::canonical_with_attributes(
        &mesh.mesh,
        &mesh.attributes,
        grid,
        bits,
    )?;
    if canonical.faces.is_empty() {
        return Err(Error::mesh(format!(
            "empty mesh: every face is degenerate at {} bits",
            options.quant_bits
        )));
    }
    Ok((canonical, appearance))
}

/// A decoder for any stream, chosen by the codec id in its header; a stream with an appearance
/// unit decodes it after its last level.
pub fn open(bytes: &[u8]) -> Result<Box<dyn LevelDecoder + '_>> {
    open_reader(StreamReader::open(bytes)?)
}

/// [`open`] on bytes the decoder keeps, so that it can take more as they arrive
/// ([`LevelDecoder::extend`]; [`Progressive`] feeds it).
pub fn open_owned(bytes: Vec<u8>) -> Result<Box<dyn LevelDecoder>> {
    open_reader(StreamReader::open_owned(bytes)?)
}

fn open_reader(reader: StreamReader<'_>) -> Result<Box<dyn LevelDecoder + '_>> {
    let appearance = reader.header().appearance.clone().filter(|a| !a.in_levels);
    let codec = for_header(reader.header())?;
    let in_levels = reader
        .header()
        .appearance
        .as_ref()
        .is_some_and(|a| a.in_levels);
    if in_levels
        && !codec
            .capabilities()
            .contains(&Capability::AppearanceInLevels)
    {
        return Err(Error::malformed(
            0,
            5,
            format!("{} streams do not carry appearance that way", codec.name()),
        ));
    }
    if reader.header().has_level_parts() {
        if !codec
            .capabilities()
            .contains(&Capability::AppearanceWithLevels)
        {
            return Err(Error::malformed(
                0,
                5,
                format!(
                    "{} streams do not carry appearance after each level",
                    codec.name()
                ),
            ));
        }
        let spec = reader.header().appearance.clone().unwrap_or_default();
        let parts = reader.clone();
        let inner = codec.decoder(reader)?;
        return Ok(Box::new(appearance::levels::WithLevelParts::new(
            inner, parts, spec,
        )));
    }
    Ok(match appearance {
        Some(spec) => {
            // A second view of the stream for the appearance unit, the codec's decoder taking
            // the reader.
            let stream = reader.clone();
            let inner = codec.decoder(reader)?;
            Box::new(appearance::decoder::WithAppearance::new(
                inner, spec, stream,
            ))
        }
        None => codec.decoder(reader)?,
    })
}

/// The most vertices any level of a stream with `header` may decode to
/// ([`Codec::most_level_vertices`]; an unknown codec: the header's).
pub fn most_level_vertices(header: &Header) -> u64 {
    for_header(header).map_or(header.vertices, |codec| codec.most_level_vertices(header))
}

/// The bytes each level of a stream needs ([`Codec::level_ends`]), from a prefix holding at
/// least its header and index ([`Error::Truncated`] when it does not yet). The full level of a
/// stream with appearance ends with its appearance unit.
pub fn level_ends(bytes: &[u8]) -> Result<Vec<u64>> {
    level_ends_of(&StreamReader::open(bytes)?)
}

/// [`level_ends`] of a stream already open.
pub(crate) fn level_ends_of(reader: &StreamReader) -> Result<Vec<u64>> {
    let mut ends = for_header(reader.header())?.level_ends(reader)?;
    if let (Some(unit), Some(last)) = (reader.index().appearance, ends.last_mut()) {
        *last = reader.payload_start() as u64 + unit.end();
    }
    // A level is decoded with its appearance part.
    for (end, part) in ends.iter_mut().zip(&reader.index().level_parts) {
        *end = reader.payload_start() as u64 + part.end();
    }
    Ok(ends)
}

/// A golden stream of tests/golden/, for the crate's tests.
#[cfg(test)]
pub(crate) fn golden(name: &str) -> Vec<u8> {
    let path = format!("{}/tests/golden/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Where to stop decoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// Every level present (and, for codecs with [`Capability::PartialLevels`], what is present
    /// of a cut level).
    All,
    /// After this many levels (or all present, if the bytes hold fewer); more than the stream
    /// holds is refused.
    Levels(usize),
    /// After this many passes, for codecs with [`Capability::PassStops`] (EMC: three a level);
    /// refused for the others.
    Passes(usize),
}

/// Decodes `bytes` (a whole stream or any prefix) up to `stop`; returns the mesh and the number
/// of levels decoded. A prefix too short to hold the header and index is an error, and so is a
/// stop the stream or its codec cannot honour.
pub fn decode(bytes: &[u8], stop: Stop) -> Result<(LevelMesh, usize)> {
    on_pool(|| decode_with(open(bytes)?.as_mut(), stop))
}

/// Runs `work` on rayon's pool, the calling thread waiting; inside the pool, where it is
/// called. From a thread outside the pool (a program's main thread) every parallel loop of a
/// decoder hands its work over to the pool and waits, hundreds of times a decode, and what it
/// allocates comes from that thread's heap; on the pool the thread running the decode takes
/// part in its loops. bunny-closed-35k ×16, `emc` on two cores: 0.42–0.45 → 0.40–0.41 s
/// (best of 8 in one process), 0.447–0.453 → 0.432–0.436 s (one decode a process).
pub(crate) fn on_pool<R: Send>(work: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| work())
}

/// [`decode`] with a decoder already opened (where the caller also wants its
/// [`LevelDecoder::levels`] or header): decodes from where it stands up to `stop`.
pub fn decode_with(decoder: &mut dyn LevelDecoder, stop: Stop) -> Result<(LevelMesh, usize)> {
    let codec = for_header(decoder.header())?;
    let levels = decoder.levels();
    let per_level = decoder.pass_stops().map(|p| p.passes_per_level());
    // Whole levels to decode, then passes of the next one.
    let (wanted, passes) = match stop {
        Stop::All => (usize::MAX, 0),
        Stop::Levels(n) if n > levels => {
            return Err(Error::Unsupported(format!(
                "cannot stop after level {n}: the stream has {levels} levels"
            )))
        }
        Stop::Levels(n) => (n, 0),
        Stop::Passes(n) => {
            let Some(per_level) = per_level else {
                return Err(Error::Unsupported(format!(
                    "codec {} cannot stop inside a level (stop by level or by bytes)",
                    codec.name()
                )));
            };
            if n > per_level * levels {
                return Err(Error::Unsupported(format!(
                    "cannot stop after pass {n}: the stream has {} passes",
                    per_level * levels
                )));
            }
            (n / per_level, n % per_level)
        }
    };
    while decoder.levels_decoded() < wanted && decoder.advance()? {}
    if stop == Stop::All {
        if let Some(partial) = decoder.partial_levels() {
            partial.advance_partial()?;
        }
    } else if passes > 0 && decoder.levels_decoded() == wanted {
        if let Some(stops) = decoder.pass_stops() {
            stops.advance_passes(passes)?;
        }
    }
    Ok((decoder.mesh()?, decoder.levels_decoded()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    /// A stream of a codec id or a syntax this build does not read is refused as unsupported
    /// (docs/CONTRACT.md §7), in one line.
    #[test]
    fn streams_of_an_unknown_codec_or_syntax_are_unsupported_in_one_line() {
        let mut bytes = golden("v8/raw-eight.mc");
        bytes[5] = 200;
        let e = decode(&bytes, Stop::All).map(|_| ()).unwrap_err();
        assert!(matches!(e, Error::Unsupported(_)), "{e}");
        assert!(e.to_string().contains("unknown codec id 200"), "{e}");
        let mut bytes = golden("v8/emc-eight.mc");
        bytes[6] = 2;
        let e = decode(&bytes, Stop::All).map(|_| ()).unwrap_err();
        assert!(matches!(e, Error::Unsupported(_)), "{e}");
        assert!(e.to_string().contains("emc stream of syntax 2"), "{e}");
        assert!(!e.to_string().contains('\n'));
    }

    /// With the names unique (`names::tests`), every named codec is registered, found by its
    /// name and by its id, and nothing else is registered.
    #[test]
    fn every_named_codec_is_found_by_name_and_by_id() {
        for naming in names::ALL {
            assert_eq!(by_name(naming.name).unwrap().id(), naming.id);
            assert_eq!(by_id(naming.id).unwrap().name(), naming.name);
        }
        assert_eq!(registry().len(), names::ALL.len());
    }

    #[test]
    fn decoders_offer_exactly_the_capabilities_their_codecs_list() {
        let mesh = generate::icosphere(2);
        for codec in registry() {
            let canonical = canonical_for(&mesh, &codec.default_options()).unwrap();
            let bytes = codec.encode(&canonical).unwrap().bytes;
            let mut decoder = open(&bytes).unwrap();
            let has = |c| codec.capabilities().contains(&c);
            assert_eq!(
                decoder.pass_stops().is_some(),
                has(Capability::PassStops),
                "{}",
                codec.name()
            );
            assert_eq!(
                decoder.partial_levels().is_some(),
                has(Capability::PartialLevels),
                "{}",
                codec.name()
            );
            // Selective refinement: the hook is there exactly when listed, and its whole
            // hierarchy has a leaf a vertex; the others are refused by name in one line.
            assert_eq!(
                codec.selective_refinement().is_some(),
                has(Capability::SelectiveRefinement),
                "{}",
                codec.name()
            );
            match came::decode_tree(&bytes) {
                Ok((header, tree)) => {
                    assert!(has(Capability::SelectiveRefinement), "{}", codec.name());
                    let leaves = tree.nodes.iter().filter(|n| n.leaf).count();
                    assert_eq!(leaves as u64, header.vertices, "{}", codec.name());
                }
                Err(e) => {
                    assert!(
                        !has(Capability::SelectiveRefinement),
                        "{}: {e}",
                        codec.name()
                    );
                    assert!(e.to_string().contains(codec.name()), "{e}");
                }
            }
            if !has(Capability::PassStops) {
                let e = decode(&bytes, Stop::Passes(1)).unwrap_err();
                assert!(e.to_string().contains("cannot stop inside a level"), "{e}");
            }
            let levels = decoder.levels();
            let e = decode(&bytes, Stop::Levels(levels + 1)).unwrap_err();
            assert!(e.to_string().contains("has"), "{e}");
        }
    }
}
