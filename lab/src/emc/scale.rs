//! How `emc`'s cost grows with the mesh: bunny-closed-35k as shared and subdivided two and three
//! times at edge midpoints (35k → 557k → 2.2 M vertices), each encoded and decoded in-process at
//! 12 bits, with bunny.ply measured in the same run as the anchor of the per-vertex rates. The
//! large meshes' streams have slabs (`codecs::emc::SLABS`): each is decoded on one thread and
//! on all of them, and encoded once more without slabs for what the slabs cost.
//! Writes results/emc/scale.json.
//!
//! Memory is the process's peak resident size over each phase (Linux with glibc: the allocator
//! gives back its free memory and the peak is reset through /proc/self/clear_refs before the
//! phase, read from /proc/self/status after it; elsewhere none is reported). It includes what
//! the phase's caller holds: the canonical mesh during encoding, the stream during decoding, and
//! the program itself (about 20 MB). The encode's peak is its first run's on each mesh: after a
//! decode, the allocator keeps memory in the decoder threads' arenas that it does not give back,
//! which raised the next encode's peak by up to 33 MB on the ×16 mesh.

use crate::came::extras::table_mesh;
use meshcodec::codecs::emc::modelled::encode_sliced;
use meshcodec::codecs::emc::{EmcParams, Syntax, SLICED_VISITS_LOG2};
use meshcodec::codecs::{self, EncodeOptions, Stop};
use meshcodec::error::{Error, Result};
use meshcodec::mesh::io::write_atomically;
use meshcodec::mesh::quantize::GridShape;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The meshes: a shared mesh and how often it is subdivided (×4 faces each).
pub const MESHES: [(&str, u32); 4] = [
    ("bunny", 0),
    ("bunny-closed-35k", 0),
    ("bunny-closed-35k", 2),
    ("bunny-closed-35k", 3),
];

/// Quantization of every row.
pub const QUANT_BITS: u8 = 12;

/// The command that makes the results.
pub const COMMAND: &str = "cargo run --release --bin experiment -- emc-scale";

/// One mesh through `emc`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ScaleRow {
    /// Shared mesh name.
    pub mesh: String,
    /// Times subdivided.
    pub subdivisions: u32,
    /// Vertices of the canonical mesh.
    pub vertices: usize,
    /// Triangles of the canonical mesh.
    pub triangles: usize,
    /// Stream bytes.
    pub bytes: usize,
    /// Best encode time (canonical mesh → stream).
    pub encode_seconds: f64,
    /// Best full decode time, on all threads.
    pub decode_seconds: f64,
    /// Best full decode time on one thread.
    pub decode_seconds_one_thread: f64,
    /// Slabs of the stream (1: none).
    pub slabs: u8,
    /// Stream bytes without slabs (the same as `bytes` where there are none).
    pub unsliced_bytes: usize,
    /// Peak resident bytes over the first encode of the mesh, if the system reports it.
    pub encode_peak_bytes: Option<u64>,
    /// Peak resident bytes over a decode (the most of the runs), if the system reports it.
    pub decode_peak_bytes: Option<u64>,
    /// Whether the decoded mesh is the canonical mesh exactly.
    pub lossless: bool,
    /// Threads the encoder and the decoder used (all of them).
    pub threads: usize,
}

/// What `emc-scale` writes.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ScaleResults {
    /// The command that made it.
    pub command: String,
    /// Quantization bits.
    pub quant_bits: u8,
    /// One row per mesh, smallest first.
    pub rows: Vec<ScaleRow>,
}

/// Resets the process's peak resident size to what is allocated now; whether the system allows
/// it. The allocator first gives back the memory it kept from earlier phases (glibc), else the
/// peak would start from that.
#[allow(unsafe_code)]
fn reset_peak() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free memory of the allocator to the system.
    unsafe {
        libc::malloc_trim(0);
    }
    cfg!(all(target_os = "linux", target_env = "gnu"))
        && std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The process's peak resident size since the last reset, in bytes.
fn peak() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Runs `work`, returning its result and the peak resident size over it.
fn with_peak<T>(work: impl FnOnce() -> Result<T>) -> Result<(T, Option<u64>)> {
    let reset = reset_peak();
    let value = work()?;
    Ok((value, peak().filter(|_| reset)))
}

/// Measures every mesh and writes results/emc/scale.json under `results`.
pub fn run(results: &Path, log: &mut dyn FnMut(String)) -> Result<PathBuf> {
    let codec = codecs::by_name("emc")?;
    let options = EncodeOptions {
        quant_bits: QUANT_BITS,
        grid: GridShape::Cubic,
    };
    let mut rows = Vec::new();
    for (name, subdivisions) in MESHES {
        let (_, mesh) = table_mesh(name, subdivisions)?;
        let canonical = codecs::canonical_for(&mesh, &options)?;
        drop(mesh);
        // Small meshes are timed more often: their times are short and this machine is noisy.
        let repeats = if canonical.face_count() > 500_000 {
            2
        } else {
            5
        };
        let one_thread = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .map_err(|e| Error::Unsupported(format!("no thread pool: {e}")))?;
        let (mut encode_seconds, mut decode_seconds) = (f64::INFINITY, f64::INFINITY);
        let mut decode_seconds_one_thread = f64::INFINITY;
        let (mut encode_peak_bytes, mut decode_peak_bytes) = (None, None);
        let mut bytes = Vec::new();
        let mut lossless = false;
        for repeat in 0..repeats {
            let started = Instant::now();
            let (encoded, encode_peak) = with_peak(|| codec.encode(&canonical))?;
            encode_seconds = encode_seconds.min(started.elapsed().as_secs_f64());
            bytes = encoded.bytes;
            let started = Instant::now();
            let ((decoded, _), decode_peak) = with_peak(|| codecs::decode(&bytes, Stop::All))?;
            decode_seconds = decode_seconds.min(started.elapsed().as_secs_f64());
            lossless = canonical.check_lossless(&decoded.mesh).is_ok();
            drop(decoded);
            let started = Instant::now();
            let (alone, _) = one_thread.install(|| codecs::decode(&bytes, Stop::All))?;
            decode_seconds_one_thread =
                decode_seconds_one_thread.min(started.elapsed().as_secs_f64());
            lossless &= canonical.check_lossless(&alone.mesh).is_ok();
            if repeat == 0 {
                encode_peak_bytes = encode_peak;
            }
            decode_peak_bytes = decode_peak_bytes.max(decode_peak);
        }
        let slabs = EmcParams::for_mesh(&canonical, Syntax::Modelled).slabs;
        let unsliced_bytes = if slabs > 1 {
            encode_sliced(&canonical, 1, SLICED_VISITS_LOG2)?
                .bytes
                .len()
        } else {
            bytes.len()
        };
        log(format!(
            "emc on {name} x{}: {} vertices, {} bytes ({unsliced_bytes} without slabs), encode {encode_seconds:.3} s, decode {decode_seconds:.3} s ({decode_seconds_one_thread:.3} s on one thread), lossless {lossless}",
            4u32.pow(subdivisions),
            canonical.vertex_count(),
            bytes.len()
        ));
        rows.push(ScaleRow {
            mesh: name.to_string(),
            subdivisions,
            vertices: canonical.vertex_count(),
            triangles: canonical.face_count(),
            bytes: bytes.len(),
            encode_seconds,
            decode_seconds,
            decode_seconds_one_thread,
            slabs,
            unsliced_bytes,
            encode_peak_bytes,
            decode_peak_bytes,
            lossless,
            threads: rayon::current_num_threads(),
        });
    }
    let out = results.join("emc").join("scale.json");
    std::fs::create_dir_all(out.parent().expect("a file in a folder"))?;
    let json = serde_json::to_string_pretty(&ScaleResults {
        command: COMMAND.to_string(),
        quant_bits: QUANT_BITS,
        rows,
    })
    .map_err(|e| Error::Io(e.into()))?;
    write_atomically(&out, format!("{json}\n").as_bytes())?;
    Ok(out)
}
