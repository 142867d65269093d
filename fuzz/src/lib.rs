//! What the fuzz targets do with their input. `tests/fuzz_regressions.rs` includes this file and
//! replays every saved input through the same functions, so a crash found here stays a test.
//!
//! A target fails (panics) only when meshcodec breaks a promise: a decoder or reader panics, a
//! decoded mesh is not a valid mesh within the header's counts, or an encode → decode round trip
//! is not lossless (docs/CONTRACT.md §3). Errors returned for bad input are the expected outcome.

use arbitrary::{Arbitrary, Result as ArbitraryResult, Unstructured};
use meshcodec::codecs::pm::iter::PMeshIter;
use meshcodec::codecs::{self, EncodeOptions, LevelMesh, Stop};
use meshcodec::container::{Header, FORMAT_VERSION, MAGIC};
use meshcodec::limits;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{generate, io, TriMesh};
use std::sync::OnceLock;

/// The codecs, in the order of their `decode_*` targets.
/// (`emc-ahead`, added last, keeps the indices `decode_mutated`'s saved inputs pick streams by.)
pub const CODECS: [&str; 8] = [
    "raw",
    "emc",
    "emc-paper",
    "pm",
    "pm-reordered",
    "came",
    "came-paper",
    "emc-ahead",
];

/// Decodes `body` as everything after the first seven bytes (magic, version, codec id, syntax)
/// of a stream of codec `name`, so the fuzzer spends its effort on that codec's syntax.
pub fn decode_as(name: &str, body: &[u8]) {
    decode_every_way(&stream_of(name, body));
}

/// Decodes `body` as everything after the first five bytes (magic, version) of a stream with
/// appearance: its first byte picks the codec, then its syntax, the header with its appearance
/// block, the index, the levels and the appearance unit, or levels whose vertex splits carry
/// the values (appearance flag 16, `pm`). Two targets take it, apart only by their seeds:
/// `decode_appearance` streams with an appearance unit, `decode_pm_wedges` pm streams with the
/// appearance in their splits.
pub fn decode_with_appearance(body: &[u8]) {
    let mut bytes = Vec::with_capacity(body.len() + 5);
    bytes.extend_from_slice(&MAGIC);
    bytes.push(FORMAT_VERSION);
    bytes.extend_from_slice(body);
    decode_every_way(&bytes);
}

/// A stream of codec `name`, in the syntax this build writes, whose bytes after the first seven
/// (magic, version, codec id, syntax) are `body`.
fn stream_of(name: &str, body: &[u8]) -> Vec<u8> {
    let codec = codecs::by_name(name).expect("a registered codec");
    let mut bytes = Vec::with_capacity(body.len() + 7);
    bytes.extend_from_slice(&MAGIC);
    bytes.push(FORMAT_VERSION);
    bytes.push(codec.id());
    bytes.push(codec.syntax());
    bytes.extend_from_slice(body);
    bytes
}

/// Decodes `body` (after the first seven bytes of a stream of CAME codec `name`) one meta-node
/// alone: the index's last unit after its ancestors only, as a view-dependent client fetches it.
pub fn decode_unit_alone(name: &str, body: &[u8]) {
    use meshcodec::codecs::came::{modelled, paper};
    let bytes = stream_of(name, body);
    match name {
        "came" => last_unit_alone(&bytes, modelled::params, modelled::ModelledUnits::default()),
        "came-paper" => last_unit_alone(&bytes, paper::params, paper::PaperUnits::default()),
        _ => panic!("{name} has no meta-nodes"),
    }
}

fn last_unit_alone<U: meshcodec::codecs::came::decoded::UnitDecoder>(
    bytes: &[u8],
    params_of: fn(&Header) -> meshcodec::Result<meshcodec::codecs::came::Params>,
    units: U,
) {
    use meshcodec::codecs::came::decoded::CameDecoder;
    let Ok(reader) = meshcodec::container::StreamReader::open(bytes) else {
        return;
    };
    let index = reader.index().units.clone();
    let Ok(params) = params_of(reader.header()) else {
        return;
    };
    let Ok(mut decoder) = CameDecoder::new(reader, params, units) else {
        return;
    };
    let Some(mut at) = index.len().checked_sub(1) else {
        return;
    };
    let mut chain = vec![at];
    while let Some(p) = index[at].parent {
        chain.push(p);
        at = p;
    }
    for &i in chain.iter().rev() {
        if !matches!(decoder.decode_unit(i), Ok(true)) {
            return;
        }
    }
}

/// Decodes `bytes` level by level, checking every intermediate mesh and what a cut inside the
/// next level gives; then stopped after a number of passes (EMC's partial levels) that the input's
/// length picks; then through the PM iterator where the stream is PM's.
pub fn decode_every_way(bytes: &[u8]) {
    check_stream_info(bytes);
    let Ok(mut decoder) = codecs::open(bytes) else {
        return;
    };
    let header = decoder.header().clone();
    loop {
        match decoder.advance() {
            Ok(true) => {
                if let Ok(mesh) = decoder.mesh() {
                    check_level_mesh(&mesh, &header);
                }
            }
            Ok(false) => break,
            Err(_) => return,
        }
    }
    check_level_ends(bytes, decoder.levels(), decoder.levels_decoded());
    if let Some(partial) = decoder.partial_levels() {
        if partial.advance_partial().is_ok() {
            if let Ok(mesh) = decoder.mesh() {
                check_level_mesh(&mesh, &header);
            }
        }
    }
    if let Ok((mesh, _)) = codecs::decode(bytes, Stop::Passes(1 + bytes.len() % 8)) {
        check_level_mesh(&mesh, &header);
    }
    if codecs::by_id(header.codec_id).is_ok_and(|c| c.name().starts_with("pm")) {
        walk_pm_iterator(bytes);
    }
    check_progressive(bytes);
}

/// What a stream says of itself ([`codecs::StreamInfo`], which `meshcodec info` and the Python
/// and WebAssembly packages' `info` show, on any bytes a user hands them): made or refused,
/// never a panic, and when made, true of the bytes: one end a level, each unit's range within
/// the stream it declares and present exactly when the bytes hold it, truncated exactly when
/// they end before the stream does.
fn check_stream_info(bytes: &[u8]) {
    let Ok(info) = codecs::StreamInfo::of(bytes) else {
        return;
    };
    assert_eq!(info.levels, info.level_ends.len(), "one end a level");
    assert_eq!(info.bytes, bytes.len() as u64);
    assert_eq!(info.truncated, info.bytes < info.stream_bytes, "truncated");
    let appearance_unit = info.appearance.iter().flat_map(|a| &a.unit);
    for unit in info.units.iter().chain(appearance_unit) {
        assert_eq!(
            unit.first_byte + unit.bytes,
            unit.end_byte,
            "unit {}",
            unit.unit
        );
        assert!(unit.first_byte >= info.payload_start && unit.end_byte <= info.stream_bytes);
        assert_eq!(
            unit.present,
            unit.end_byte <= info.bytes,
            "unit {}",
            unit.unit
        );
    }
}

/// The stream fed to [`codecs::Progressive`] in a few chunks: every level handed over is the
/// level `decode` makes of the bytes received (what a browser's `ProgressiveDecoder` shows).
fn check_progressive(bytes: &[u8]) {
    let mut progressive = codecs::Progressive::new();
    let step = bytes.len() / 3 + 1;
    let mut received = 0;
    for chunk in bytes.chunks(step) {
        received += chunk.len();
        match progressive.push(chunk) {
            Ok(Some((mesh, level))) => {
                let whole = codecs::decode(&bytes[..received], Stop::Levels(level));
                assert!(
                    whole.as_ref().is_ok_and(|(m, n)| *n == level && *m == mesh),
                    "level {level} handed over after {received} bytes differs from its decode: {whole:?}"
                );
            }
            Ok(None) => {}
            Err(_) => return,
        }
    }
}

/// `codecs::level_ends` of a stream of `levels` levels whose first `decoded` levels decoded:
/// one end a level, never decreasing, and the prefix up to the last decoded level's end decodes
/// that level again (what a reader of an arriving stream relies on).
fn check_level_ends(bytes: &[u8], levels: usize, decoded: usize) {
    let Ok(ends) = codecs::level_ends(bytes) else {
        return;
    };
    assert_eq!(ends.len(), levels, "one end a level");
    assert!(ends.windows(2).all(|w| w[0] <= w[1]), "ends never decrease");
    if decoded == 0 {
        return;
    }
    let end = ends[decoded - 1];
    if end <= bytes.len() as u64 {
        let again = codecs::decode(&bytes[..end as usize], Stop::Levels(decoded));
        assert!(
            again.as_ref().is_ok_and(|(_, n)| *n == decoded),
            "the first {end} bytes should decode {decoded} levels: {again:?}"
        );
    }
}

/// Steps a PM iterator forward, back, and to vertex and face counts, checking the mesh's
/// adjacency after each move; an iterator reading the same bytes as an input stream, level by
/// level, must reach the same meshes.
fn walk_pm_iterator(bytes: &[u8]) {
    let Ok(mut iter) = PMeshIter::from_stream(bytes) else {
        assert!(PMeshIter::from_reader(bytes).is_err());
        return;
    };
    let mut streamed = PMeshIter::from_reader(bytes).expect("the same bytes as a stream");
    for _ in 0..64 {
        let (a, b) = (iter.next(), streamed.next());
        assert_eq!(a.is_ok(), b.is_ok(), "from_stream {a:?}, from_reader {b:?}");
        if !matches!(a, Ok(true)) {
            break;
        }
    }
    iter.mesh()
        .check_invariants()
        .expect("PM iterator mesh after next()");
    assert!(
        iter.mesh() == streamed.mesh(),
        "from_stream and from_reader differ"
    );
    let forward = iter.nvertices();
    while iter.prev() {}
    iter.mesh()
        .check_invariants()
        .expect("PM iterator mesh after prev()");
    if iter.goto_nvertices(forward / 2 + 1).is_ok() {
        iter.mesh()
            .check_invariants()
            .expect("after goto_nvertices");
    }
    if iter.goto_nfaces(usize::MAX).is_ok() {
        iter.mesh().check_invariants().expect("after goto_nfaces");
    }
}

/// A decoded mesh must index only its own vertices, have finite positions, no degenerate
/// triangles, and stay within the counts its header declared (an EMC level may list a few more
/// triangles than the full mesh has, up to [`limits::level_triangles`]; a pm stream of a mesh
/// cut to a manifold, as many more vertices as its parameters say it copied).
pub fn check_level_mesh(level: &LevelMesh, header: &Header) {
    let mesh = &level.mesh;
    let n = mesh.positions.len();
    let most = codecs::most_level_vertices(header);
    assert!(
        n as u64 <= most,
        "{n} vertices decoded, header declares {} ({most} with copies)",
        header.vertices
    );
    assert!(
        mesh.faces.len() <= limits::level_triangles(header.triangles),
        "{} triangles decoded, header declares {}",
        mesh.faces.len(),
        header.triangles
    );
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    for face in &mesh.faces {
        assert!(face.iter().all(|&v| (v as usize) < n), "{face:?} of {n}");
        assert!(
            face[0] != face[1] && face[1] != face[2] && face[0] != face[2],
            "degenerate triangle {face:?}"
        );
    }
    for edge in &level.loose_edges {
        assert!(edge.iter().all(|&v| (v as usize) < n) && edge[0] != edge[1]);
    }
    if let Some(attributes) = &level.attributes {
        assert!(
            header.appearance.is_some(),
            "appearance from a stream without"
        );
        if let Err(e) = attributes.validate(mesh) {
            panic!("decoded appearance fails validation: {e}");
        }
    }
}

/// Reads `bytes` as a mesh file of `format`; a mesh that reads must be valid. Read with its
/// appearance, it must have the same geometry and valid wedges, and a writer that takes it must
/// give a file that reads back to the same corners.
pub fn read_as(format: &str, bytes: &[u8]) {
    // The appearance count scans any bytes, read or not.
    let _ = io::appearance_of(bytes, format, 3, 1);
    let plain = io::read_mesh_bytes(bytes, format);
    if let Ok(mesh) = &plain {
        mesh.validate().expect("a mesh the reader accepted");
        let _ = io::appearance_of(bytes, format, mesh.positions.len(), mesh.faces.len());
    }
    let Ok(attributed) = io::read_attributed_bytes(bytes, format) else {
        return;
    };
    let mesh = plain.expect("a file read with its appearance reads without it");
    assert!(
        attributed.mesh == mesh,
        "the appearance changed the geometry"
    );
    attributed
        .attributes
        .validate(&attributed.mesh)
        .expect("wedges the reader accepted");
    derive_normals_of(&attributed);
    for out in ["ply", "obj", "glb"] {
        let Ok(written) = io::write_attributed_bytes(&attributed, out) else {
            continue;
        };
        let back = io::read_attributed_bytes(&written, out).expect("a file we wrote reads");
        assert_eq!(back.mesh.faces.len(), attributed.mesh.faces.len());
        // PLY keeps every vertex apart; OBJ objects are joined by exact position, which may
        // weld two vertices of one place.
        if out == "ply" {
            assert!(back == attributed, "ply changed the attributed mesh");
        }
    }
}

/// The canonical mesh of a mesh with normals, its normals derived from the positions over its
/// normal groups (docs/CONTRACT.md §2.1): built without a panic, its wedges valid and its own
/// appearance lossless against it.
fn derive_normals_of(attributed: &meshcodec::mesh::attributes::AttributedMesh) {
    if attributed.attributes.normals.is_none() || attributed.mesh.faces.len() > 4096 {
        return;
    }
    let options = EncodeOptions {
        quant_bits: 10,
        grid: GridShape::Cubic,
    };
    let bits = meshcodec::mesh::attribute_quantization::AttributeBits {
        derive_normals: true,
        ..Default::default()
    };
    let Ok((canonical, appearance)) = codecs::canonical_attributed_for(attributed, &options, bits)
    else {
        return;
    };
    let mesh = canonical.to_mesh();
    let values = appearance.to_attributes();
    values.validate(&mesh).expect("derived normals' wedges");
    assert_eq!(
        appearance.check_lossless(&canonical, &mesh, &values),
        Ok(()),
        "the canonical mesh with derived normals is not itself"
    );
}

/// One edit of a valid stream.
#[derive(Arbitrary, Debug)]
pub enum Mutation {
    /// Flips one bit.
    Flip { at: u32, bit: u8 },
    /// Overwrites one byte.
    Set { at: u32, byte: u8 },
    /// Cuts the stream.
    Cut { at: u32 },
    /// Inserts bytes.
    Insert { at: u32, bytes: Vec<u8> },
    /// Removes a range.
    Remove { at: u32, len: u16 },
    /// Copies a range of another valid stream over this one (splices two codecs' syntax).
    Splice {
        from_stream: u8,
        from: u32,
        at: u32,
        len: u16,
    },
}

/// Input of `decode_mutated`: which valid stream, and what to do to it.
#[derive(Arbitrary, Debug)]
pub struct MutatedStream {
    /// Index into [`valid_streams`].
    pub stream: u8,
    /// Edits applied in order.
    pub mutations: Vec<Mutation>,
}

/// Valid streams of every codec for a few small meshes (a torus, a sphere, a bumpy terrain with
/// a boundary, and a non-manifold mesh, which pm cuts to a manifold), encoded once.
pub fn valid_streams() -> &'static [Vec<u8>] {
    static STREAMS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    STREAMS.get_or_init(|| {
        let meshes = [
            generate::torus(1.0, 0.4, 8, 5),
            generate::icosphere(0),
            generate::terrain(24, 7),
            generate::messy(2),
        ];
        let mut streams = Vec::new();
        for name in CODECS {
            let codec = codecs::by_name(name).expect("registered");
            for (mesh, bits) in meshes.iter().zip([12, 8, 10, 12]) {
                let options = EncodeOptions {
                    quant_bits: bits,
                    grid: GridShape::Cubic,
                };
                let canonical = codecs::canonical_for(mesh, &options).expect("generated meshes");
                if let Ok(encoded) = codec.encode(&canonical) {
                    streams.push(encoded.bytes);
                }
            }
        }
        streams
    })
}

/// Applies `input`'s edits to one of the valid streams and decodes the result every way.
pub fn decode_mutated(input: &MutatedStream) {
    let streams = valid_streams();
    let mut bytes = streams[input.stream as usize % streams.len()].clone();
    mutate(&mut bytes, &input.mutations, streams);
    decode_every_way(&bytes);
}

/// Applies `mutations` to `bytes` in order; splices copy from `others`.
fn mutate(bytes: &mut Vec<u8>, mutations: &[Mutation], others: &[Vec<u8>]) {
    for mutation in mutations {
        let at = |at: u32, len: usize| at as usize % (len + 1);
        match mutation {
            Mutation::Flip { at: a, bit } => {
                if !bytes.is_empty() {
                    let k = *a as usize % bytes.len();
                    bytes[k] ^= 1 << (bit % 8);
                }
            }
            Mutation::Set { at: a, byte } => {
                if !bytes.is_empty() {
                    let k = *a as usize % bytes.len();
                    bytes[k] = *byte;
                }
            }
            Mutation::Cut { at: a } => bytes.truncate(at(*a, bytes.len())),
            Mutation::Insert {
                at: a,
                bytes: extra,
            } => {
                let k = at(*a, bytes.len());
                bytes.splice(k..k, extra.iter().copied());
            }
            Mutation::Remove { at: a, len } => {
                let k = at(*a, bytes.len());
                let end = (k + *len as usize).min(bytes.len());
                bytes.drain(k..end);
            }
            Mutation::Splice {
                from_stream,
                from,
                at: a,
                len,
            } => {
                let other = &others[*from_stream as usize % others.len()];
                let from = at(*from, other.len());
                let end = (from + *len as usize).min(other.len());
                let k = at(*a, bytes.len());
                let end_here = (k + (end - from)).min(bytes.len());
                bytes.splice(k..end_here, other[from..end].iter().copied());
            }
        }
    }
}

/// A mesh built from fuzz input: positions on a small integer lattice (so that coincident and
/// collinear vertices are common) and triangles over them.
#[derive(Debug)]
pub struct GeneratedMesh {
    /// Quantization bits to encode with.
    pub quant_bits: u8,
    /// Grid shape to encode with.
    pub grid: GridShape,
    /// The mesh.
    pub mesh: TriMesh,
    /// Edits of each codec's stream of the mesh, decoded after the lossless check.
    pub mutations: Vec<Mutation>,
}

impl<'a> Arbitrary<'a> for GeneratedMesh {
    fn arbitrary(u: &mut Unstructured<'a>) -> ArbitraryResult<Self> {
        let quant_bits = u.int_in_range(2..=16)?;
        let grid = if u.arbitrary()? {
            GridShape::Cubic
        } else {
            GridShape::PerAxis
        };
        let vertex_count = u.int_in_range(3..=64usize)?;
        let scale = f64::from(u.int_in_range(1..=1000u16)?);
        let mut positions = Vec::with_capacity(vertex_count);
        for _ in 0..vertex_count {
            let [x, y, z]: [i8; 3] = u.arbitrary()?;
            positions.push(glam::DVec3::new(x.into(), y.into(), z.into()) * scale);
        }
        let face_count = u.int_in_range(1..=128usize)?;
        let mut faces = Vec::with_capacity(face_count);
        for _ in 0..face_count {
            let mut face = [0u32; 3];
            for v in &mut face {
                *v = u.int_in_range(0..=vertex_count as u32 - 1)?;
            }
            faces.push(face);
        }
        Ok(GeneratedMesh {
            quant_bits,
            grid,
            mesh: TriMesh::new(positions, faces),
            mutations: u.arbitrary()?,
        })
    }
}

/// Encodes `input` with every codec that accepts it and checks that the full decode is lossless
/// (docs/CONTRACT.md §3; a lossy codec's keeps every vertex and face) and that every level
/// decodes to a valid mesh; then decodes the stream again with the input's edits applied.
pub fn round_trip(input: &GeneratedMesh) {
    let options = EncodeOptions {
        quant_bits: input.quant_bits,
        grid: input.grid,
    };
    let Ok(canonical) = codecs::canonical_for(&input.mesh, &options) else {
        return;
    };
    for codec in codecs::registry() {
        let encoded = match codec.encode(&canonical) {
            Ok(encoded) => encoded,
            Err(meshcodec::Error::Unsupported(_)) => continue,
            Err(e) => panic!("{}: encoding failed: {e}", codec.name()),
        };
        let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All)
            .unwrap_or_else(|e| panic!("{}: own stream does not decode: {e}", codec.name()));
        if !codec.lossless() {
            // Lossy by design: every vertex and face comes back, moved.
            let counts = |m: &TriMesh| (m.vertex_count(), m.face_count());
            assert_eq!(
                counts(&decoded.mesh),
                counts(&canonical.to_mesh()),
                "{}: vertices and faces lost",
                codec.name()
            );
        } else if let Err(why) = canonical.check_lossless(&decoded.mesh) {
            panic!("{}: not lossless: {why}", codec.name());
        }
        // Every level of a stream an encoder wrote must show, within the decoders' limits.
        {
            let mut decoder = codecs::open(&encoded.bytes).expect("own stream opens");
            while decoder.advance().expect("own stream decodes") {
                if let Err(e) = decoder.mesh() {
                    let level = decoder.levels_decoded();
                    panic!("{}: level {level} of its own stream: {e}", codec.name());
                }
            }
        }
        decode_every_way(&encoded.bytes);
        if !input.mutations.is_empty() {
            let mut bytes = encoded.bytes;
            mutate(&mut bytes, &input.mutations, valid_streams());
            decode_every_way(&bytes);
        }
    }
}

/// Adapts the front of a `came` stream (the bytes after its first seven, behind up to 16 bytes
/// that pick four views and how much of the index is read at a time) to those views, a face
/// budget and the full mesh, its meta-nodes fetched on demand (inline), checking every
/// invariant after each adaptation: a corrupt or cut meta-node is refused for its branch while
/// the rest adapts.
pub fn adapt_came(data: &[u8]) {
    use meshcodec::codecs::came::refine::{Budget, Camera, Fetch, Reads, View, ViewMesh};
    let (views, body) = data.split_at(data.len().min(16));
    // The index read a few bytes at a time, as far as the meta-nodes the views fetch.
    let byte = |i: usize| views.get(i).copied().unwrap_or(0) as u64;
    let reads = Reads {
        first: 1 + byte(4) % 96,
        index: 1 + byte(5) % 16,
    };
    let Ok(mut front) = ViewMesh::open_reading(stream_of("came", body), Fetch::Inline, reads)
    else {
        return;
    };
    for chunk in views.chunks(4) {
        let byte = |i: usize| chunk.get(i).copied().unwrap_or(0);
        let axis = |i: usize| (byte(i) as f64 - 128.0) / 16.0;
        let camera = Camera {
            eye: glam::DVec3::new(axis(0), axis(1), axis(2)),
            target: glam::DVec3::ZERO,
            up: glam::DVec3::Y,
            fov_degrees: 10.0 + byte(3) as f64 / 2.0,
            width: 640,
            height: 480,
        };
        let Ok(view) = View::new(&camera, byte(3) as f64 / 32.0) else {
            continue;
        };
        // Both sides and the orientation guard off, now and then.
        let view = view
            .two_sided(byte(0) % 3 == 0)
            .keep_orientation(byte(1) % 5 != 0);
        let budget = Budget {
            operations: 1 + 16 * byte(3) as usize,
            faces: (byte(3) % 2 == 1).then_some(64 * byte(2) as usize),
        };
        front.settle(&view, budget, 1 + byte(1) as usize % 4);
        assert_eq!(front.check_invariants(), Ok(()));
    }
    front.settle(&View::everything(), Budget::UNLIMITED, 64);
    assert_eq!(front.check_invariants(), Ok(()));
    adapt_came_external(&stream_of("came", body), views);
    let mesh = front.mesh();
    assert!(mesh
        .faces
        .iter()
        .flatten()
        .all(|&v| (v as usize) < mesh.positions.len()));
}

/// The same stream refined with its units fetched by the caller (`Fetch::External`, a
/// browser's `Range` requests) from its first bytes: units handed over as asked, some cut
/// short or asked for twice as `views` says; every invariant holds after each adaptation.
fn adapt_came_external(stream: &[u8], views: &[u8]) {
    use meshcodec::codecs::came::refine::{head_length, Budget, Fetch, View, ViewMesh};
    let Ok(Some(head)) = head_length(stream) else {
        return;
    };
    let head = (head as usize).min(stream.len());
    let Ok(mut front) = ViewMesh::open(stream[..head].to_vec(), Fetch::External) else {
        return;
    };
    let cut = views.first().copied().unwrap_or(0);
    for round in 0..32 {
        let done = front.adapt(&View::everything(), Budget::UNLIMITED);
        assert_eq!(front.check_invariants(), Ok(()));
        if done.settled {
            break;
        }
        for (k, (unit, range)) in front.wanted().into_iter().enumerate() {
            let start = (range.start as usize).min(stream.len());
            let mut end = (range.end as usize).min(stream.len());
            if cut != 0 && (k + round) % (cut as usize) == 0 {
                end = end.saturating_sub(1).max(start);
            }
            assert!(front.supply(unit, &stream[start..end]).is_ok());
            assert!(front.supply(unit, &stream[start..end]).is_err());
        }
    }
}

/// `meshcodec pack` and `unpack` on arbitrary bytes read as a glTF scene (.gltf JSON with
/// embedded buffers, or .glb): reading, packing, reading the packed GLB back and unpacking it
/// either succeed or end in one error line. A scene that packs unpacks to the full level of
/// every stream, and the fallback level never has more faces than the full one. Arbitrary bytes
/// that already are a packed scene (the seeds are) exercise `unpack`'s stream and extension
/// reading directly.
pub fn pack_gltf(bytes: &[u8]) {
    use meshcodec::mesh::scene::Scene;
    use meshcodec::packing::{self, Outcome, PackOptions};
    let Ok(scene) = Scene::read(bytes, None) else {
        return;
    };
    if let Err(e) = packing::unpack(&scene) {
        assert!(!e.to_string().contains('\n'), "a two-line error: {e}");
    }
    let mut options = PackOptions::new().expect("emc is registered");
    options.quant_bits = 10;
    let packed = match packing::pack(&scene, &options, None) {
        Ok(packed) => packed,
        Err(e) => {
            assert!(!e.to_string().contains('\n'), "a two-line error: {e}");
            return;
        }
    };
    for primitive in &packed.report {
        if let Outcome::Packed {
            fallback_faces,
            faces,
            ..
        } = primitive.outcome
        {
            assert!(fallback_faces <= faces, "a fallback finer than the mesh");
        }
    }
    let back = Scene::read(&packed.glb, None).expect("a packed scene reads");
    let unpacked = packing::unpack(&back).expect("a packed scene unpacks");
    let coded = packed
        .report
        .iter()
        .filter(|p| matches!(p.outcome, Outcome::Packed { .. }))
        .count();
    assert_eq!(unpacked.primitives, coded, "a stream lost in the GLB");
    Scene::read(&unpacked.glb, None).expect("an unpacked scene reads");
}
