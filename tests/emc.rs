//! EMC, both coders (`emc` and the paper's `emc-paper`): lossless on messy meshes, prefixes
//! equal levels, every cut decodes or fails cleanly, encoding is deterministic.

use meshcodec::codecs::{self, EncodeOptions, LevelMesh, Stop};
use meshcodec::mesh::generate;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::Error;
use proptest::prelude::*;

mod common;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(256)
}

/// Indices in range, no face repeating a vertex, loose edges in range and not degenerate.
fn assert_valid(level: &LevelMesh) {
    let n = level.mesh.positions.len() as u32;
    for f in &level.mesh.faces {
        assert!(
            f.iter().all(|&v| v < n),
            "face {f:?} out of range ({n} vertices)"
        );
        assert!(
            f[0] != f[1] && f[1] != f[2] && f[0] != f[2],
            "degenerate face {f:?}"
        );
    }
    for e in &level.loose_edges {
        assert!(e[0] < n && e[1] < n && e[0] != e[1], "bad edge {e:?}");
    }
    assert!(level.mesh.positions.iter().all(|p| p.is_finite()));
}

/// The EMC coders.
const CODERS: [&str; 3] = ["emc", "emc-ahead", "emc-paper"];

fn encode(
    codec: &str,
    seed: u64,
    bits: u8,
    per_axis: bool,
) -> Option<(meshcodec::mesh::CanonicalMesh, codecs::Encoded)> {
    let mesh = generate::messy(seed);
    let grid = if per_axis {
        GridShape::PerAxis
    } else {
        GridShape::Cubic
    };
    let options = EncodeOptions {
        quant_bits: bits,
        grid,
    };
    let canonical = codecs::canonical_for(&mesh, &options).ok()?;
    let encoded = codecs::by_name(codec).unwrap().encode(&canonical).unwrap();
    Some((canonical, encoded))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn full_decode_is_lossless_and_deterministic(codec in prop::sample::select(&CODERS[..]), seed in any::<u64>(), bits in 1u8..=24, per_axis in any::<bool>()) {
        let Some((canonical, encoded)) = encode(codec, seed, bits, per_axis) else { return Ok(()) };
        let (_, again) = encode(codec, seed, bits, per_axis).unwrap();
        prop_assert_eq!(&encoded.bytes, &again.bytes);
        let (decoded, levels) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        prop_assert_eq!(levels, bits as usize);
        prop_assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
    }

    #[test]
    fn a_stream_cut_after_level_k_is_level_k(codec in prop::sample::select(&CODERS[..]), seed in any::<u64>(), bits in 2u8..=16, per_axis in any::<bool>()) {
        let Some((_, encoded)) = encode(codec, seed, bits, per_axis) else { return Ok(()) };
        let mut decoder = codecs::open(&encoded.bytes).unwrap();
        for record in &encoded.levels {
            prop_assert!(decoder.advance().unwrap());
            let full = decoder.mesh().unwrap();
            assert_valid(&full);
            prop_assert_eq!(full.mesh.vertex_count(), record.vertices);
            let (cut, k) = codecs::decode(&encoded.bytes[..record.end_byte], Stop::All).unwrap();
            // Levels after this one that hold no bytes (emc-ahead's last, whose cells all went
            // ahead) are present in the cut too.
            let present = encoded.levels.iter().filter(|r| r.end_byte <= record.end_byte).count();
            prop_assert_eq!(k, present);
            if k == decoder.levels_decoded() {
                prop_assert!(cut == full, "cut after level {} differs", k);
            } else {
                let (whole, _) = codecs::decode(&encoded.bytes, Stop::Levels(k)).unwrap();
                prop_assert!(cut == whole, "cut after level {} differs", k);
            }
        }
        prop_assert!(!decoder.advance().unwrap());
    }

    #[test]
    fn every_cut_decodes_to_a_valid_mesh_or_a_clean_error(codec in prop::sample::select(&CODERS[..]), seed in any::<u64>(), bits in 1u8..=10) {
        let Some((_, encoded)) = encode(codec, seed, bits, false) else { return Ok(()) };
        let mut vertices = 0;
        let (_, _, header_len) = meshcodec::container::read_header_and_index(&encoded.bytes).unwrap();
        for cut in 0..encoded.bytes.len() {
            match codecs::decode(&encoded.bytes[..cut], Stop::All) {
                Ok((level, _)) => {
                    assert_valid(&level);
                    // A longer prefix never decodes to fewer vertices.
                    prop_assert!(level.mesh.vertex_count() >= vertices);
                    vertices = level.mesh.vertex_count();
                }
                Err(Error::Truncated(_)) => prop_assert!(cut < header_len, "only a cut header or index may fail"),
                Err(e) => prop_assert!(false, "cut {}: {}", cut, e),
            }
        }
    }
}

#[test]
fn a_cut_inside_a_level_decodes_the_operations_before_it() {
    // The paper's syntax is a plain bit string: every complete operation of a cut level applies.
    let (_, encoded) = encode("emc-paper", 7, 12, false).unwrap();
    let (end5, end6) = (encoded.levels[4].end_byte, encoded.levels[5].end_byte);
    let at = |cut: usize| codecs::decode(&encoded.bytes[..cut], Stop::All).unwrap().0;
    let (l5, mid, l6) = (at(end5), at((end5 + end6) / 2), at(end6));
    assert!(l5.mesh.vertex_count() <= mid.mesh.vertex_count());
    assert!(mid.mesh.vertex_count() <= l6.mesh.vertex_count());
    assert!(mid != l5, "half a level adds refinements or splits");
}

#[test]
fn a_cut_inside_an_arithmetic_coded_level_decodes_the_level_before() {
    // A range coder's cut block would decode garbage, so `emc` stops at the last whole level.
    let (_, encoded) = encode("emc", 7, 12, false).unwrap();
    let (end5, end6) = (encoded.levels[4].end_byte, encoded.levels[5].end_byte);
    let at = |cut: usize| codecs::decode(&encoded.bytes[..cut], Stop::All).unwrap();
    let (l5, mid) = (at(end5), at((end5 + end6) / 2));
    assert_eq!(mid.1, 5);
    assert!(mid.0 == l5.0);
}

#[test]
fn corrupt_streams_fail_cleanly() {
    for codec in CODERS {
        let (_, encoded) = encode(codec, 11, 12, false).unwrap();
        let mut x = 0x9e37_79b9_u32;
        for _ in 0..2000 {
            let bytes = common::flip_bits(&encoded.bytes, &mut x, 4);
            if let Ok((level, _)) = codecs::decode(&bytes, Stop::All) {
                assert_valid(&level);
            }
        }
    }
}

#[test]
fn decoding_stops_after_any_pass() {
    for codec in CODERS {
        decoding_stops_after_any_pass_of(codec);
    }
}

fn decoding_stops_after_any_pass_of(codec: &str) {
    let (_, encoded) = encode(codec, 5, 12, false).unwrap();
    for level in 1..12 {
        let at_level = codecs::decode(&encoded.bytes, Stop::Levels(level))
            .unwrap()
            .0;
        let at_passes = codecs::decode(&encoded.bytes, Stop::Passes(3 * level))
            .unwrap()
            .0;
        assert!(at_level == at_passes, "3 passes are a level ({level})");
        let next = codecs::decode(&encoded.bytes, Stop::Levels(level + 1))
            .unwrap()
            .0;
        let mut previous = at_level.mesh.vertex_count();
        for extra in 1..3 {
            let mid = codecs::decode(&encoded.bytes, Stop::Passes(3 * level + extra))
                .unwrap()
                .0;
            assert_valid(&mid);
            let n = mid.mesh.vertex_count();
            assert!(previous <= n && n <= next.mesh.vertex_count());
            previous = n;
        }
    }
}

/// `emc` shows every vertex of an intermediate level inside its own cell of that level (where
/// its neighbours predict it), and from the level that decodes the last vertex on, the mesh's
/// own faces (its face corrections follow that level).
/// Every level of `bytes` decoded on a pool of `threads` threads.
fn levels_on(bytes: &[u8], threads: usize) -> Vec<LevelMesh> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut decoder = codecs::open(bytes).unwrap();
        let mut levels = Vec::new();
        while decoder.advance().unwrap() {
            levels.push(decoder.mesh().unwrap());
        }
        levels
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases() / 4))]

    /// Streams whose passes are sliced, down to passes of one visit: the same bytes whether the
    /// encoder codes the slabs one after another or at once, lossless, and every level the same
    /// whether the slabs are decoded one after another or at once.
    #[test]
    fn sliced_streams_are_lossless_and_alike_on_one_thread_and_on_several(seed in any::<u64>(), bits in 1u8..=14, slabs in 2u8..=8, log2 in 0u8..=6, ahead in 0u8..=3) {
        let mesh = generate::messy(seed);
        let options = EncodeOptions { quant_bits: bits, grid: GridShape::Cubic };
        let Ok(canonical) = codecs::canonical_for(&mesh, &options) else { return Ok(()) };
        let encode = || codecs::emc::modelled::encode_sliced_ahead(&canonical, ahead, slabs, log2).unwrap();
        let encoded = encode();
        // The encoder codes the slabs at once too, to the same bytes.
        let alone = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let encoded_alone = alone.install(encode);
        prop_assert!(encoded.bytes == encoded_alone.bytes, "the threads changed the stream");
        let one = levels_on(&encoded.bytes, 1);
        let several = levels_on(&encoded.bytes, 3);
        prop_assert_eq!(one.len(), bits as usize);
        prop_assert!(one == several, "the threads changed a level");
        let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        prop_assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
        for (level, record) in one.iter().zip(&encoded.levels) {
            assert_valid(level);
            prop_assert_eq!(level.mesh.vertex_count(), record.vertices);
        }
        // Cut and corrupt, it decodes or fails in one line.
        let mut state = seed as u32 | 1;
        for _ in 0..8 {
            let bytes = common::flip_bits(&encoded.bytes, &mut state, 4);
            if let Ok((level, _)) = codecs::decode(&bytes, Stop::All) {
                assert_valid(&level);
            }
        }
        for cut in (0..encoded.bytes.len()).step_by(7) {
            if let Ok((level, _)) = codecs::decode(&encoded.bytes[..cut], Stop::All) {
                assert_valid(&level);
            }
        }
    }
}

#[test]
fn emc_levels_show_vertices_in_their_cells_and_the_mesh_faces_once_all_are_decoded() {
    use meshcodec::mesh::canonical::rotate_to_smallest;
    let faces = |level: &LevelMesh| {
        let mut faces: Vec<_> = level
            .mesh
            .faces
            .iter()
            .map(|&f| rotate_to_smallest(f))
            .collect();
        faces.sort_unstable();
        faces
    };
    let mut settled_before_the_last = 0;
    for (seed, per_axis) in [(3, false), (8, true), (21, false), (34, false)] {
        let (canonical, encoded) = encode("emc", seed, 12, per_axis).unwrap();
        let (full, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        let grid = canonical.grid;
        let cells: Vec<[u32; 3]> = full
            .mesh
            .positions
            .iter()
            .map(|&p| grid.quantize(p))
            .collect();
        let mut decoder = codecs::open(&encoded.bytes).unwrap();
        let mut moved = 0;
        for level in 1..=12u32 {
            assert!(decoder.advance().unwrap());
            let shown = decoder.mesh().unwrap();
            let shift = 12 - level;
            for (v, &p) in shown.mesh.positions.iter().enumerate() {
                let cell = grid.quantize(p).map(|c| c >> shift);
                assert_eq!(
                    cell,
                    cells[v].map(|c| c >> shift),
                    "seed {seed} level {level} vertex {v}"
                );
                let centre = grid.coarse_centre(cell, [shift as u8; 3]);
                moved += (p != centre) as usize;
            }
            if shown.mesh.vertex_count() == canonical.vertex_count() {
                assert_eq!(faces(&shown), faces(&full), "seed {seed} level {level}");
                settled_before_the_last += (level < 12) as usize;
            }
        }
        assert!(
            moved > 0,
            "seed {seed}: no vertex shown off its cell's centre"
        );
    }
    assert!(settled_before_the_last > 0);
}

/// A slab table that lies (too long, or more splits than a slab visits) is refused in one line
/// naming it, and so is a level whose slab streams are not all read.
/// `emc-ahead` codes the octree `emc` codes, in another order: every level holds as many
/// vertices and triangles as `emc`'s, on every grid, with and without a lookahead deep enough
/// to reach the last level; its full level is the mesh.
#[test]
fn emc_ahead_levels_hold_the_vertices_and_triangles_of_emcs() {
    for seed in 0..cases() as u64 {
        for (bits, ahead) in [(12, 2), (6, 8), (9, 1)] {
            let Some((canonical, plain)) = encode("emc", seed, bits, seed % 2 == 1) else {
                continue;
            };
            let encoded =
                codecs::emc::modelled::encode_sliced_ahead(&canonical, ahead, 1, 13).unwrap();
            let ahead_levels = levels_on(&encoded.bytes, 1);
            let plain_levels = levels_on(&plain.bytes, 1);
            assert_eq!(ahead_levels.len(), plain_levels.len());
            for (l, (a, p)) in ahead_levels.iter().zip(&plain_levels).enumerate() {
                assert_valid(a);
                assert_eq!(
                    (a.mesh.vertex_count(), a.mesh.faces.len()),
                    (p.mesh.vertex_count(), p.mesh.faces.len()),
                    "seed {seed}, {bits} bits, {ahead} ahead, level {}",
                    l + 1
                );
            }
            let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
            assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
        }
    }
}

#[test]
fn a_lying_slab_table_is_refused() {
    let mesh = generate::messy(5);
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options).unwrap();
    let encoded = codecs::emc::modelled::encode_sliced(&canonical, 3, 2).unwrap();
    let bytes = &encoded.bytes;
    let (_, index, start) = meshcodec::container::read_header_and_index(bytes).unwrap();
    // The first level with a table: its payload starts with the table's length.
    let level = index
        .units
        .iter()
        .map(|unit| start + unit.offset as usize)
        .find(|&at| bytes[at] > 0)
        .expect("some level has a sliced pass");
    let refused = |edit: &dyn Fn(&mut Vec<u8>), why: &str| {
        let mut lying = bytes.clone();
        edit(&mut lying);
        match codecs::decode(&lying, Stop::All) {
            Err(e) => assert!(e.to_string().contains(why), "{why}: {e}"),
            Ok(_) => panic!("{why}: decoded"),
        }
    };
    // The table's length runs past the level.
    refused(&|b| b[level] = 0x7f, "runs past its payload");
    // The first slab splits more vertices than it visits.
    refused(
        &|b| b[level + 1] = 0x7f,
        "splits more vertices than a slab visits",
    );
    // The first slab's stream is listed shorter: the next slabs read from the wrong place, or
    // bytes are left over.
    refused(&|b| b[level + 2] = b[level + 2].saturating_sub(4), "slab");
}
