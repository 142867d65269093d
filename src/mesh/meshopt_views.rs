//! `EXT_meshopt_compression` (meshoptimizer's vertex and index codecs on glTF buffer views, as
//! gltfpack writes them) decoded when a scene is read, so that the rest of the reader sees plain
//! views: each compressed view's bytes decoded (with its filter) into a buffer of their own, the
//! view pointed at it, the extension gone from the views, the buffers and the document's lists.
//! The codecs are meshoptimizer's own (the `meshopt` crate, built with the `meshopt` feature);
//! without it such a scene is refused in one line.

use crate::error::{Error, Result};
use gltf_json::validation::USize64;
use gltf_json::Index;
use serde::Deserialize;

/// The extension's name.
pub const NAME: &str = "EXT_meshopt_compression";

/// A decoded view may be at most this many times its compressed bytes (meshoptimizer's vertex
/// codec spends at least two bits a group of 16 bytes; its index codec a byte a triangle), and
/// at most a quarter of the address space: an input cannot make the reader allocate more.
const MOST_EXPANSION: u64 = 72;

/// The extension object on a buffer view.
#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Compressed {
    buffer: u32,
    #[serde(default)]
    byte_offset: u64,
    byte_length: u64,
    byte_stride: u64,
    count: u64,
    mode: String,
    #[serde(default)]
    filter: Option<String>,
}

/// Decodes every compressed view of `document` in place, appending the decoded bytes to
/// `buffers`; `buffers[i]` is buffer `i`'s bytes (a fallback buffer's may be empty).
pub fn decode_views(document: &mut gltf_json::Root, buffers: &mut Vec<Vec<u8>>) -> Result<()> {
    for v in 0..document.buffer_views.len() {
        let Some(object) = document.buffer_views[v]
            .extensions
            .as_mut()
            .and_then(|e| e.others.remove(NAME))
        else {
            continue;
        };
        let at = |what: String| Error::mesh(format!("glTF: buffer view {v}: {NAME}: {what}"));
        let compressed: Compressed =
            serde_json::from_value(object).map_err(|e| at(e.to_string()))?;
        let source = buffers
            .get(compressed.buffer as usize)
            .ok_or_else(|| at(format!("buffer {} of {}", compressed.buffer, buffers.len())))?;
        let end = compressed
            .byte_offset
            .checked_add(compressed.byte_length)
            .filter(|&end| end <= source.len() as u64)
            .ok_or_else(|| {
                at(format!(
                    "bytes {}+{} past buffer {}'s {}",
                    compressed.byte_offset,
                    compressed.byte_length,
                    compressed.buffer,
                    source.len()
                ))
            })?;
        let encoded = &source[compressed.byte_offset as usize..end as usize];
        let decoded_bytes = compressed
            .count
            .checked_mul(compressed.byte_stride)
            .filter(|&n| n <= MOST_EXPANSION * encoded.len() as u64 + 4096 && n < 1 << 34)
            .ok_or_else(|| {
                at(format!(
                    "{} elements of {} bytes from {} bytes",
                    compressed.count,
                    compressed.byte_stride,
                    encoded.len()
                ))
            })?;
        let bytes = decode(&compressed, encoded).map_err(|e| at(e.to_string()))?;
        debug_assert_eq!(bytes.len() as u64, decoded_bytes);
        let view = &mut document.buffer_views[v];
        view.buffer = Index::new(buffers.len() as u32);
        view.byte_offset = Some(USize64(0));
        view.byte_length = USize64(bytes.len() as u64);
        document.buffers.push(gltf_json::Buffer {
            byte_length: USize64(bytes.len() as u64),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        buffers.push(bytes);
        if view
            .extensions
            .as_ref()
            .is_some_and(|e| e.others.is_empty())
        {
            view.extensions = None;
        }
    }
    for buffer in &mut document.buffers {
        if let Some(e) = buffer.extensions.as_mut() {
            e.others.remove(NAME);
            if e.others.is_empty() {
                buffer.extensions = None;
            }
        }
    }
    document.extensions_used.retain(|e| e != NAME);
    document.extensions_required.retain(|e| e != NAME);
    Ok(())
}

/// Whether buffer `buffer` is a fallback a compressed view stands in for (it may hold no bytes).
pub fn is_fallback(buffer: &gltf_json::Buffer) -> bool {
    buffer
        .extensions
        .as_ref()
        .and_then(|e| e.others.get(NAME))
        .and_then(|o| o.get("fallback"))
        .and_then(|f| f.as_bool())
        .unwrap_or(false)
}

#[cfg(feature = "meshopt")]
fn decode(c: &Compressed, encoded: &[u8]) -> std::result::Result<Vec<u8>, String> {
    let count = c.count as usize;
    let stride = c.byte_stride as usize;
    let failed = |e: meshopt::Error| format!("{} data the decoder rejects ({e})", c.mode);
    match c.mode.as_str() {
        "ATTRIBUTES" => {
            if stride == 0 || !stride.is_multiple_of(4) || stride > 256 {
                return Err(format!("attributes of {stride} bytes (4 to 256, by fours)"));
            }
            let mut words = vertex_words(encoded, count, stride / 4).map_err(failed)?;
            filter(c.filter.as_deref().unwrap_or("NONE"), stride, &mut words)?;
            Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
        }
        "TRIANGLES" | "INDICES" => {
            let triangles = c.mode == "TRIANGLES";
            if triangles && !count.is_multiple_of(3) {
                return Err(format!("{count} triangle indices"));
            }
            match stride {
                2 if triangles => Ok(le(
                    meshopt::decode_index_buffer::<u16>(encoded, count).map_err(failed)?
                )),
                4 if triangles => Ok(le(
                    meshopt::decode_index_buffer::<u32>(encoded, count).map_err(failed)?
                )),
                2 => Ok(le(
                    meshopt::decode_index_sequence::<u16>(encoded, count).map_err(failed)?
                )),
                4 => Ok(le(
                    meshopt::decode_index_sequence::<u32>(encoded, count).map_err(failed)?
                )),
                _ => Err(format!("indices of {stride} bytes (2 or 4)")),
            }
        }
        other => Err(format!("mode {other:?}")),
    }
}

#[cfg(not(feature = "meshopt"))]
fn decode(c: &Compressed, _: &[u8]) -> std::result::Result<Vec<u8>, String> {
    Err(format!(
        "{} data (filter {}): this build reads it only with the `meshopt` feature (the CLI and the Python package have it)",
        c.mode,
        c.filter.as_deref().unwrap_or("NONE")
    ))
}

/// Little-endian bytes of integers.
#[cfg(feature = "meshopt")]
fn le<T: Into<u64> + Copy>(values: Vec<T>) -> Vec<u8> {
    let size = std::mem::size_of::<T>();
    values
        .iter()
        .flat_map(|&v| v.into().to_le_bytes().into_iter().take(size))
        .collect()
}

/// `count` elements of `words` 32-bit words each, as meshoptimizer's vertex codec decodes them.
#[cfg(feature = "meshopt")]
fn vertex_words(
    encoded: &[u8],
    count: usize,
    words: usize,
) -> std::result::Result<Vec<u32>, meshopt::Error> {
    /// One element: its size is what tells the decoder the stride.
    #[derive(Clone, Copy)]
    #[repr(transparent)]
    struct Element<const N: usize>([u32; N]);
    impl<const N: usize> Default for Element<N> {
        fn default() -> Self {
            Element([0; N])
        }
    }
    macro_rules! by_width {
        ($($n:literal)*) => {
            match words {
                $($n => meshopt::decode_vertex_buffer::<Element<$n>>(encoded, count)
                    .map(|v| v.into_iter().flat_map(|e| e.0).collect()),)*
                _ => unreachable!("stride checked: 4 to 256 bytes"),
            }
        };
    }
    by_width!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31
        32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58 59 60
        61 62 63 64)
}

/// The view's filter undone in place on its decoded words.
#[cfg(feature = "meshopt")]
fn filter(name: &str, stride: usize, words: &mut [u32]) -> std::result::Result<(), String> {
    // Words as the narrower components a filter works on, and back.
    fn as_i8x4(w: u32) -> [i8; 4] {
        w.to_le_bytes().map(|b| b as i8)
    }
    fn as_i16x4(pair: &[u32]) -> [i16; 4] {
        let [a, b] = [pair[0], pair[1]];
        [a as i16, (a >> 16) as i16, b as i16, (b >> 16) as i16]
    }
    fn from_i16x4(v: [i16; 4]) -> [u32; 2] {
        let word = |lo: i16, hi: i16| (lo as u16 as u32) | ((hi as u16 as u32) << 16);
        [word(v[0], v[1]), word(v[2], v[3])]
    }
    match (name, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => {
            let mut v: Vec<[i8; 4]> = words.iter().map(|&w| as_i8x4(w)).collect();
            meshopt::decode_filter_oct(&mut v);
            for (w, x) in words.iter_mut().zip(v) {
                *w = u32::from_le_bytes(x.map(|c| c as u8));
            }
        }
        ("OCTAHEDRAL" | "QUATERNION", 8) => {
            let mut v: Vec<[i16; 4]> = words.chunks_exact(2).map(as_i16x4).collect();
            if name == "OCTAHEDRAL" {
                meshopt::decode_filter_oct(&mut v);
            } else {
                meshopt::decode_filter_quat(&mut v);
            }
            for (pair, x) in words.chunks_exact_mut(2).zip(v) {
                pair.copy_from_slice(&from_i16x4(x));
            }
        }
        ("EXPONENTIAL", _) => {
            // Each 32-bit component decodes on its own.
            let mut v: Vec<[u32; 1]> = words.iter().map(|&w| [w]).collect();
            meshopt::decode_filter_exp(&mut v);
            for (w, [x]) in words.iter_mut().zip(v) {
                *w = x;
            }
        }
        _ => return Err(format!("filter {name:?} on {stride}-byte elements")),
    }
    Ok(())
}
