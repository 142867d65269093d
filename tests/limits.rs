//! Resource bounds (src/limits.rs), measured with a counting allocator: a stream or file that
//! claims more than it holds is refused before anything is allocated for the claim, and decoding
//! takes memory in proportion to the decoded mesh.

use meshcodec::codecs::{self, EncodeOptions, Stop};
use meshcodec::coding::varint;
use meshcodec::container::{self, Header};
use meshcodec::mesh::io::read_mesh_bytes;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{generate, io};
use meshcodec::Error;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// The system allocator, keeping the bytes in use and their peak.
struct Counting;

static IN_USE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let now = IN_USE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(now, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        IN_USE.fetch_sub(layout.size(), Ordering::Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Tests measure one at a time.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Runs `f` and returns its result and the most bytes it had allocated at once.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = IN_USE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed) - before)
}

const ONE_MIB: usize = 1 << 20;

/// A valid stream of `codec` for a small torus, and its header.
fn stream(codec: &str) -> (Vec<u8>, Header, usize) {
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let mesh = generate::torus(1.0, 0.4, 12, 8);
    let canonical = codecs::canonical_for(&mesh, &options).unwrap();
    let bytes = codecs::by_name(codec)
        .unwrap()
        .encode(&canonical)
        .unwrap()
        .bytes;
    let (header, body) = Header::read(&bytes).unwrap();
    (bytes, header, body)
}

/// `bytes` with its header replaced by `header`.
fn with_header(bytes: &[u8], body: usize, header: &Header) -> Vec<u8> {
    let mut out = Vec::new();
    header.write(&mut out);
    out.extend_from_slice(&bytes[body..]);
    out
}

#[test]
fn headers_claiming_too_much_are_refused_as_limits() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    for codec in meshcodec::codecs::names::ALL.map(|n| n.name) {
        let (bytes, header, body) = stream(codec);
        for (what, claim) in [
            (
                "2^31 vertices",
                Header {
                    vertices: 1 << 31,
                    ..header.clone()
                },
            ),
            (
                "2^40 triangles",
                Header {
                    triangles: 1 << 40,
                    ..header.clone()
                },
            ),
        ] {
            let hostile = with_header(&bytes, body, &claim);
            let (outcome, peak) = peak_of(|| codecs::decode(&hostile, Stop::All));
            assert!(
                matches!(outcome, Err(Error::Limit(_))),
                "{codec}, {what}: {:?}",
                outcome.map(|(m, _)| m.mesh.vertex_count())
            );
            assert!(peak < ONE_MIB, "{codec}, {what}: {peak} bytes allocated");
        }
        // An index claiming 10^9 units, more than its entry bytes can list, or entry bytes
        // the stream does not hold, allocates nothing.
        let (_, index, payload_start) = container::read_header_and_index(&bytes).unwrap();
        let mut pos = body;
        let counts: Vec<u64> = (0..3)
            .map(|_| varint::get(&bytes, &mut pos).unwrap())
            .collect();
        let entries = &bytes[pos..payload_start];
        for (units, entry_bytes) in [
            (1_000_000_000u64, counts[1]),
            (1 << 19, counts[1]),
            (1 << 19, 1 << 20),
        ] {
            let mut hostile = bytes[..body].to_vec();
            varint::put(&mut hostile, units);
            varint::put(&mut hostile, entry_bytes);
            varint::put(&mut hostile, index.payload_bytes);
            hostile.extend_from_slice(entries);
            hostile.extend_from_slice(&bytes[payload_start..]);
            let (outcome, peak) = peak_of(|| codecs::decode(&hostile, Stop::All));
            assert!(
                matches!(
                    outcome,
                    Err(Error::Limit(_)) | Err(Error::Truncated(_)) | Err(Error::Malformed { .. })
                ),
                "{codec}, {units} units in {entry_bytes} bytes: {:?}",
                outcome.map(|(m, _)| m.mesh.vertex_count())
            );
            assert!(
                peak < ONE_MIB,
                "{codec}, {units} units: {peak} bytes allocated"
            );
        }
    }
}

#[test]
fn claims_within_the_limits_cost_only_what_the_stream_holds() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    // The most a header may claim, over levels of a few hundred bytes: every decoder must
    // stop at what its levels hold, not at what the header promised.
    for codec in meshcodec::codecs::names::ALL.map(|n| n.name) {
        let (bytes, header, body) = stream(codec);
        let claim = Header {
            vertices: meshcodec::limits::MAX_VERTICES,
            triangles: meshcodec::limits::MAX_TRIANGLES,
            ..header
        };
        let hostile = with_header(&bytes, body, &claim);
        let (_, peak) = peak_of(|| codecs::decode(&hostile, Stop::All));
        assert!(peak < 4 * ONE_MIB, "{codec}: {peak} bytes allocated");
    }
}

#[test]
fn mesh_files_claiming_more_than_they_hold_are_refused_before_allocating() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    let ply_header = |format: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 2000000000\nproperty float x\n\
             property float y\nproperty float z\nelement face 2000000000\n\
             property list uchar int vertex_indices\nend_header\n"
        )
        .into_bytes()
    };
    let mut stl = vec![b'x'; 80];
    stl.extend_from_slice(&4_000_000_000u32.to_le_bytes());
    stl.extend_from_slice(&[0; 50]);
    let cases: Vec<(&str, Vec<u8>)> = vec![
        (
            "ply",
            [ply_header("binary_little_endian"), vec![0; 12]].concat(),
        ),
        ("ply", [ply_header("ascii"), b"0 0 0\n".to_vec()].concat()),
        (
            "ply",
            b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
              property float z\nelement junk 100000000\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                .to_vec(),
        ),
        ("off", b"OFF\n2000000000 2000000000 0\n0 0 0\n".to_vec()),
        ("stl", stl),
        (
            "obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4000000000\n".to_vec(),
        ),
        (
            "obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/-9223372036854775807 2 3\n".to_vec(),
        ),
        (
            "m",
            b"Vertex 4000000000 0 0 0\nFace 1 4000000000 1 1\n".to_vec(),
        ),
    ];
    for (format, bytes) in cases {
        let (outcome, peak) = peak_of(|| read_mesh_bytes(&bytes, format));
        assert!(outcome.is_err(), "{format}: {bytes:?} read");
        assert!(peak < ONE_MIB, "{format}: {peak} bytes allocated");
    }
}

#[test]
fn decoding_takes_memory_in_proportion_to_the_mesh() {
    let _one = ONE_AT_A_TIME.lock().unwrap();
    // Bytes of the decoded mesh: positions (3 doubles) and faces (3 indices).
    let mesh = io::read_mesh(&io::resolve("bunny-3k-closed").unwrap()).unwrap();
    for codec in meshcodec::codecs::names::ALL.map(|n| n.name) {
        let codec = codecs::by_name(codec).unwrap();
        let options = codec.default_options();
        let canonical = codecs::canonical_for(&mesh, &options).unwrap();
        let bytes = codec.encode(&canonical).unwrap().bytes;
        let ((decoded, _), peak) = peak_of(|| codecs::decode(&bytes, Stop::All).unwrap());
        let size = decoded.mesh.vertex_count() * 24 + decoded.mesh.face_count() * 12;
        let multiple = peak as f64 / size as f64;
        println!(
            "{}: peak {peak} bytes, {multiple:.1} × the mesh",
            codec.name()
        );
        assert!(
            multiple <= meshcodec::limits::DECODE_MEMORY_MULTIPLE as f64,
            "{}: {multiple:.1} × the decoded mesh",
            codec.name()
        );
    }
}
