//! Progressive meshes: lossless round trips on random manifold meshes (boundaries, several
//! components), next/prev symmetry, goto, invariants after every step, geomorphs, cut streams;
//! and the same on random meshes that are no oriented manifold (fins, bow-ties, repeated,
//! reversed and flipped faces, coincident vertices, several components), which pm cuts to one,
//! with no crack at any level.

use meshcodec::codecs::pm::iter::{Geomorph, PMeshIter};
use meshcodec::codecs::{self, EncodeOptions, Stop};
use meshcodec::mesh::generate;
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::{CanonicalMesh, TriMesh};
use meshcodec::Error;
use proptest::prelude::*;

mod common;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(256)
}

/// A manifold mesh with boundaries and several components, from a seed.
fn manifold(seed: u64) -> TriMesh {
    let parts = [
        generate::terrain(20 + (seed % 60) as usize, seed),
        generate::icosphere((seed % 2) as u32 + 1),
        generate::torus(2.0, 0.5, 6 + (seed % 5) as u32, 4 + (seed % 3) as u32),
    ];
    let mut mesh = TriMesh::default();
    for (i, part) in parts.iter().enumerate().take(1 + (seed % 3) as usize) {
        let base = mesh.positions.len() as u32;
        let offset = glam::DVec3::new(3.0 * i as f64, (seed % 7) as f64 * 0.1, 0.0);
        mesh.positions
            .extend(part.positions.iter().map(|p| *p + offset));
        mesh.faces
            .extend(part.faces.iter().map(|f| f.map(|v| v + base)));
    }
    mesh
}

fn encode(seed: u64, codec: &str, bits: u8) -> Option<(CanonicalMesh, codecs::Encoded)> {
    let mesh = manifold(seed);
    let options = EncodeOptions {
        quant_bits: bits,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options).ok()?;
    Some(encode_canonical(canonical, codec))
}

fn encode_canonical(canonical: CanonicalMesh, codec: &str) -> (CanonicalMesh, codecs::Encoded) {
    // Any mesh goes through: one that is no oriented manifold is cut to one.
    match codecs::by_name(codec).unwrap().encode(&canonical) {
        Ok(e) => (canonical, e),
        Err(e) => panic!("{e}"),
    }
}

/// A mesh that is no oriented manifold, from a seed: `generate::messy` (fins, a bow-tie,
/// repeated and reversed faces, coincident vertices, components), with some faces flipped
/// against their neighbours.
fn non_manifold(seed: u64) -> TriMesh {
    let mut mesh = generate::messy(seed);
    let n = mesh.faces.len();
    for k in 0..(seed % 4) as usize {
        let f = (seed as usize / 4 + 7 * k) % n;
        mesh.faces[f].swap(1, 2);
    }
    mesh
}

fn encode_non_manifold(
    seed: u64,
    codec: &str,
    bits: u8,
) -> Option<(CanonicalMesh, codecs::Encoded)> {
    let options = EncodeOptions {
        quant_bits: bits,
        grid: GridShape::Cubic,
    };
    // Coarse grids can weld every face away: nothing to code then.
    let canonical = codecs::canonical_for(&non_manifold(seed), &options).ok()?;
    Some(encode_canonical(canonical, codec))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn full_decode_is_lossless(seed in any::<u64>(), reordered in any::<bool>(), bits in 8u8..=20) {
        let codec = if reordered { "pm-reordered" } else { "pm" };
        let Some((canonical, encoded)) = encode(seed, codec, bits) else { return Ok(()) };
        let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        prop_assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
        let (_, again) = encode(seed, codec, bits).unwrap();
        prop_assert_eq!(encoded.bytes, again.bytes);
    }

    #[test]
    fn iteration_keeps_invariants_and_next_prev_restore(seed in any::<u64>(), reordered in any::<bool>()) {
        let codec = if reordered { "pm-reordered" } else { "pm" };
        let Some((_, encoded)) = encode(seed, codec, 16) else { return Ok(()) };
        let mut iter = PMeshIter::from_stream(&encoded.bytes).unwrap();
        let base = iter.mesh().clone();
        let mut states = vec![base.clone()];
        iter.mesh().check_invariants().unwrap();
        while iter.next().unwrap() {
            iter.mesh().check_invariants().unwrap();
            states.push(iter.mesh().clone());
        }
        // prev() walks back through exactly the same meshes.
        for expected in states.iter().rev().skip(1) {
            prop_assert!(iter.prev());
            prop_assert!(iter.mesh() == expected);
        }
        prop_assert!(!iter.prev());
        // goto_nvertices(n) is the first n − |V⁰| splits applied.
        let n = base.positions.len() + (states.len() - 1) / 2;
        iter.goto_nvertices(n).unwrap();
        prop_assert!(iter.mesh() == &states[n - base.positions.len()]);
        iter.goto_nfaces(usize::MAX).unwrap();
        prop_assert!(iter.mesh() == states.last().unwrap());
    }

    #[test]
    fn geomorph_ends_are_the_two_meshes(seed in any::<u64>()) {
        let Some((_, encoded)) = encode(seed, "pm", 16) else { return Ok(()) };
        let mut iter = PMeshIter::from_stream(&encoded.bytes).unwrap();
        let coarse_n = iter.nvertices() + 3;
        iter.goto_nvertices(coarse_n).unwrap();
        let coarse = iter.level_mesh().mesh;
        let fine_n = coarse.positions.len() * 2 + 5;
        let morph = Geomorph::new(&mut iter, fine_n).unwrap();
        let fine = iter.level_mesh().mesh;
        prop_assert!(morph.evaluate(1.0) == fine);
        // At alpha 0 every vertex sits on a vertex of the coarse mesh: its geometry.
        let at0 = morph.evaluate(0.0);
        for p in &at0.positions {
            prop_assert!(coarse.positions.contains(p));
        }
        for f in &at0.faces {
            let [a, b, c] = at0.corners(*f);
            let collapsed = a == b || b == c || a == c;
            let on_coarse = coarse.faces.iter().any(|g| {
                let q = coarse.corners(*g);
                [a, b, c].iter().all(|p| q.contains(p))
            });
            prop_assert!(collapsed || on_coarse, "face {:?} is neither degenerate nor a coarse face", f);
        }
    }

    #[test]
    fn every_cut_decodes_or_errors_cleanly(seed in any::<u64>(), cut in any::<prop::sample::Index>()) {
        let Some((_, encoded)) = encode(seed, "pm-reordered", 12) else { return Ok(()) };
        let cut = cut.index(encoded.bytes.len());
        match codecs::decode(&encoded.bytes[..cut], Stop::All) {
            Ok((level, k)) => {
                let expected = encoded.levels.iter().filter(|l| l.end_byte <= cut).count();
                prop_assert_eq!(k, expected);
                if k > 0 {
                    prop_assert_eq!(level.mesh.vertex_count(), encoded.levels[k - 1].vertices);
                }
            }
            Err(Error::Truncated(_)) => {}
            Err(e) => prop_assert!(false, "cut {}: {}", cut, e),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases() / 2))]

    #[test]
    fn a_mesh_that_is_no_oriented_manifold_decodes_losslessly(seed in any::<u64>(), reordered in any::<bool>(), bits in 6u8..=20) {
        let codec = if reordered { "pm-reordered" } else { "pm" };
        let Some((canonical, encoded)) = encode_non_manifold(seed, codec, bits) else { return Ok(()) };
        let (decoded, levels) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        prop_assert_eq!(levels, encoded.levels.len());
        prop_assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
        prop_assert_eq!(decoded.mesh.vertex_count(), encoded.levels.last().unwrap().vertices);
        let (_, again) = encode_non_manifold(seed, codec, bits).unwrap();
        prop_assert_eq!(encoded.bytes, again.bytes);
    }

    #[test]
    fn a_cut_mesh_iterates_with_invariants_and_without_cracks(seed in any::<u64>(), reordered in any::<bool>()) {
        let codec = if reordered { "pm-reordered" } else { "pm" };
        let Some((_, encoded)) = encode_non_manifold(seed, codec, 16) else { return Ok(()) };
        common::walk_without_cracks(&encoded.bytes, true);
        // goto, and a geomorph between two levels of the manifold.
        let mut iter = PMeshIter::from_stream(&encoded.bytes).unwrap();
        let base = iter.nvertices();
        iter.goto_nvertices(usize::MAX).unwrap();
        let full = iter.nvertices();
        iter.goto_nvertices(base).unwrap();
        prop_assert_eq!(iter.nvertices(), base);
        let fine_n = (base + full) / 2;
        let morph = Geomorph::new(&mut iter, fine_n).unwrap();
        prop_assert!(morph.evaluate(1.0) == meshcodec::codecs::pm::iter::to_trimesh(iter.mesh(), &iter.header().grid));
        // The prefix of every level decodes.
        for k in 1..=encoded.levels.len() {
            let (level, got) = codecs::decode(&encoded.bytes[..encoded.levels[k - 1].end_byte], Stop::All).unwrap();
            prop_assert_eq!(got, k);
            prop_assert_eq!(level.mesh.vertex_count(), encoded.levels[k - 1].vertices);
        }
    }
}

#[test]
fn a_cut_mesh_corrupted_fails_cleanly() {
    let (_, encoded) = encode_non_manifold(4, "pm", 16).unwrap();
    assert_corruptions_fail_cleanly(&encoded.bytes, 0x9e37_79b9);
}

#[test]
fn corrupt_streams_fail_cleanly() {
    let (_, encoded) = encode(9, "pm", 14).unwrap();
    assert_corruptions_fail_cleanly(&encoded.bytes, 0x1234_5678);
}

/// 1,000 copies of `stream` with a few bits flipped (from `seed`) decode to an error or to a
/// mesh that indexes only its own vertices, never a panic.
fn assert_corruptions_fail_cleanly(stream: &[u8], seed: u32) {
    let mut x = seed;
    for _ in 0..1000 {
        let bytes = common::flip_bits(stream, &mut x, 3);
        if let Ok((level, _)) = codecs::decode(&bytes, Stop::All) {
            let n = level.mesh.positions.len() as u32;
            assert!(level.mesh.faces.iter().flatten().all(|&v| v < n));
        }
    }
}

/// A reader that hands out a few bytes per call, as a network would.
struct Trickle<'a> {
    bytes: &'a [u8],
    step: usize,
}

impl std::io::Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.step = self.step % 7 + 1;
        let n = self.step.min(buf.len()).min(self.bytes.len());
        buf[..n].copy_from_slice(&self.bytes[..n]);
        self.bytes = &self.bytes[n..];
        Ok(n)
    }
}

#[test]
fn an_input_stream_gives_the_same_sequence_as_bytes_in_memory() {
    let (_, encoded) = encode(21, "pm-reordered", 16).unwrap();
    let mut memory = PMeshIter::from_stream(&encoded.bytes).unwrap();
    let mut stream = PMeshIter::from_reader(Trickle {
        bytes: &encoded.bytes,
        step: 0,
    })
    .unwrap();
    assert!(memory.mesh() == stream.mesh());
    while memory.next().unwrap() {
        assert!(stream.next().unwrap());
        assert!(memory.mesh() == stream.mesh());
    }
    assert!(!stream.next().unwrap());
    assert!(
        stream.prev(),
        "records read from the stream are kept for prev()"
    );
    // A stream cut inside a level yields the complete levels before it.
    let k = encoded.levels.len() - 2;
    let cut = encoded.levels[k].end_byte + 3;
    let mut partial = PMeshIter::from_reader(&encoded.bytes[..cut]).unwrap();
    while partial.next().unwrap() {}
    assert_eq!(partial.nvertices(), encoded.levels[k].vertices);
}

#[test]
fn the_generated_meshes_need_copies_and_flips() {
    let (mut copies, mut flips, mut whole) = (0.0, 0.0, 0);
    for seed in 0..16 {
        let (_, encoded) = encode_non_manifold(seed, "pm", 16).unwrap();
        let stat = |name: &str| encoded.stats.get_named(name);
        match (stat("repair_copies"), stat("repair_flips")) {
            (Some(c), Some(f)) => {
                copies += c;
                flips += f;
            }
            _ => whole += 1,
        }
        // Vertices of Mⁿ sharing a cell are a vertex and its copies, nothing else.
        let c = stat("repair_copies").unwrap_or(0.0) as usize;
        let together = common::walk_without_cracks(&encoded.bytes, false);
        assert!(
            together == 0 || (together > c && together <= 2 * c),
            "{together} {c}"
        );
        assert_eq!(together == 0, c == 0);
    }
    assert!(
        copies > 0.0 && flips > 0.0,
        "{copies} copies, {flips} flips"
    );
    assert!(whole < 16, "every generated mesh was an oriented manifold");
}
