//! Progressive meshes: lossless round trips on random manifold meshes (boundaries, several
//! components), next/prev symmetry, goto, invariants after every step, geomorphs, cut streams.

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
    match codecs::by_name(codec).unwrap().encode(&canonical) {
        Ok(e) => Some((canonical, e)),
        // Coarse grids can weld a manifold into a non-manifold: refused, not a failure here.
        Err(Error::Unsupported(_)) => None,
        Err(e) => panic!("{e}"),
    }
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

#[test]
fn non_manifold_meshes_are_refused_with_counts() {
    let mesh = generate::messy(4);
    let options = EncodeOptions {
        quant_bits: 16,
        grid: GridShape::Cubic,
    };
    let canonical = codecs::canonical_for(&mesh, &options).unwrap();
    match codecs::by_name("pm").unwrap().encode(&canonical) {
        Err(Error::Unsupported(why)) => assert!(why.contains("non-manifold"), "{why}"),
        other => panic!("expected a refusal, got {:?}", other.map(|e| e.bytes.len())),
    }
}

#[test]
fn corrupt_streams_fail_cleanly() {
    let (_, encoded) = encode(9, "pm", 14).unwrap();
    let mut x = 0x1234_5678_u32;
    for _ in 0..1000 {
        let bytes = common::flip_bits(&encoded.bytes, &mut x, 3);
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
