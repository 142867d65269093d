//! Codecs behind one object-safe trait, found by name or stream id in a registry.
//!
//! A codec encodes a [`CanonicalMesh`] into a stream of levels (DESIGN.md A3) and hands out a
//! [`LevelDecoder`] that walks a stream level by level, coarse to fine, as Hoppe's PMeshIter
//! walks vertex splits. The full decode of a stream is lossless: it equals the canonical mesh.

pub mod emc;
pub mod pm;
pub mod raw;

use crate::container::{Header, StreamReader};
use crate::error::{Error, Result};
use crate::mesh::quantize::GridShape;
use crate::mesh::{CanonicalMesh, Grid, TriMesh, VertexId};

/// What an encoder is asked for.
#[derive(Clone, Debug, PartialEq)]
pub struct EncodeOptions {
    /// Bits per axis of the quantization grid (Q of DESIGN.md A2).
    pub quant_bits: u8,
    /// How cells are shaped.
    pub grid: GridShape,
}

/// One level as the encoder wrote it.
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

/// An encoded stream and what each level cost.
#[derive(Clone, Debug)]
pub struct Encoded {
    /// The whole stream.
    pub bytes: Vec<u8>,
    /// One record per level, in stream order.
    pub levels: Vec<LevelRecord>,
    /// Codec-specific counts (bits per syntax element, operation counts…) for tables.
    pub stats: std::collections::BTreeMap<String, f64>,
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
}

/// A progressive mesh codec.
pub trait Codec: Send + Sync {
    /// Name on the command line and in results/ (`raw`, `emc`, `pm`, …).
    fn name(&self) -> &'static str;
    /// Identifier in the stream header.
    fn id(&self) -> u8;
    /// One line on what the codec is.
    fn summary(&self) -> &'static str;
    /// Options used when the user gives none.
    fn default_options(&self) -> EncodeOptions {
        EncodeOptions {
            quant_bits: 12,
            grid: GridShape::Cubic,
        }
    }
    /// Encodes the canonical mesh; refuses with [`Error::Unsupported`] a mesh it cannot code.
    fn encode(&self, mesh: &CanonicalMesh, options: &EncodeOptions) -> Result<Encoded>;
    /// A decoder positioned before the first level of `stream` (whose header names this codec).
    fn decoder<'a>(&self, stream: StreamReader<'a>) -> Result<Box<dyn LevelDecoder + 'a>>;
    /// Codec-specific measurements of an encoded stream (PM: iteration rates), stored with the
    /// run's results.
    fn measure(&self, _stream: &[u8]) -> Result<std::collections::BTreeMap<String, f64>> {
        Ok(Default::default())
    }
}

/// Walks a stream level by level.
pub trait LevelDecoder {
    /// The stream's header.
    fn header(&self) -> &Header;
    /// Levels decoded so far.
    fn levels_decoded(&self) -> usize;
    /// Decodes the next complete level; `Ok(false)` when none is left (the stream's end, or the
    /// prefix ends inside the next level).
    fn advance(&mut self) -> Result<bool>;
    /// Decodes only the first `passes` passes of the next level and stops there (EMC: a pass is
    /// one direction of one octree level); `Ok(false)` for codecs without passes. No level can
    /// be decoded after it.
    fn advance_passes(&mut self, _passes: usize) -> Result<bool> {
        Ok(false)
    }
    /// Decodes what is present of a level the stream was cut in, where the codec's syntax allows
    /// it; `Ok(false)` when nothing more could be decoded.
    fn advance_partial(&mut self) -> Result<bool> {
        Ok(false)
    }
    /// The mesh after the levels decoded so far (an error where showing it would pass a limit).
    fn mesh(&self) -> Result<LevelMesh>;
}

/// Every codec of this build.
pub fn registry() -> Vec<&'static dyn Codec> {
    vec![
        &raw::Raw,
        &emc::paper::EmcPaper,
        &emc::modelled::Emc,
        &pm::Pm {
            ordering: pm::Ordering::Natural,
        },
        &pm::Pm {
            ordering: pm::Ordering::Reordered,
        },
    ]
}

/// The codec called `name`, or an error listing the names known.
pub fn by_name(name: &str) -> Result<&'static dyn Codec> {
    registry()
        .into_iter()
        .find(|c| c.name() == name)
        .ok_or_else(|| {
            let names: Vec<_> = registry().iter().map(|c| c.name()).collect();
            Error::Unsupported(format!(
                "unknown codec '{name}' (codecs: {})",
                names.join(", ")
            ))
        })
}

/// The codec whose streams carry `id`.
pub fn by_id(id: u8) -> Result<&'static dyn Codec> {
    registry()
        .into_iter()
        .find(|c| c.id() == id)
        .ok_or_else(|| Error::malformed(0, 5, format!("unknown codec id {id}")))
}

/// The canonical mesh that `codec` would encode for `mesh` under `options`.
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

/// A decoder for any stream, chosen by the codec id in its header.
pub fn open(bytes: &[u8]) -> Result<Box<dyn LevelDecoder + '_>> {
    let reader = StreamReader::open(bytes)?;
    by_id(reader.header().codec_id)?.decoder(reader)
}

/// Where to stop decoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stop {
    /// Every level present.
    All,
    /// After this many levels (or all present, if fewer).
    Levels(usize),
    /// After this many passes (EMC: three a level).
    Passes(usize),
}

/// Decodes `bytes` (a whole stream or any prefix) up to `stop`; returns the mesh and the number
/// of levels decoded. A prefix too short to hold the header is an error.
pub fn decode(bytes: &[u8], stop: Stop) -> Result<(LevelMesh, usize)> {
    let mut decoder = open(bytes)?;
    let wanted = match stop {
        Stop::All => usize::MAX,
        Stop::Levels(n) => n,
        Stop::Passes(n) => n / 3,
    };
    while decoder.levels_decoded() < wanted && decoder.advance()? {}
    match stop {
        Stop::All => {
            decoder.advance_partial()?;
        }
        Stop::Passes(n) if n % 3 > 0 && decoder.levels_decoded() == n / 3 => {
            decoder.advance_passes(n % 3)?;
        }
        _ => {}
    }
    Ok((decoder.mesh()?, decoder.levels_decoded()))
}
