//! Appearance through every codec that carries it (docs/CONTRACT.md §2.1, §3): each shared mesh
//! with normals, uvs, colours or materials decodes to its canonical mesh with every corner's
//! quantized attributes and every face's material; a prefix without the appearance unit decodes
//! the full geometry alone; a damaged unit is an error, never a panic.

use meshcodec::codecs::{self, Capability, Stop};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::io::{read_attributed, resolve};
use meshcodec::Error;

const MESHES: [&str; 4] = [
    "bunny-10k-textured",
    "spot",
    "airplane-colored",
    "dragon-res3",
];

#[test]
fn every_shared_mesh_with_appearance_round_trips_losslessly_through_every_codec_that_carries_it() {
    for name in MESHES {
        let mesh = read_attributed(&resolve(name).unwrap()).unwrap();
        assert!(!mesh.attributes.is_empty(), "{name}");
        for codec in codecs::registry() {
            let options = codec.default_options();
            let (canonical, appearance) =
                codecs::canonical_attributed_for(&mesh, &options, AttributeBits::default())
                    .unwrap();
            let encoded = match codecs::encode_attributed(codec, &canonical, Some(&appearance)) {
                Ok(e) => e,
                Err(Error::Unsupported(why)) => {
                    // Refused by the geometry (pm: not a 2-manifold) or for lossiness, never
                    // encoded without what it was given.
                    assert!(
                        !codec.capabilities().contains(&Capability::Attributes)
                            || why.contains("manifold"),
                        "{name} {}: {why}",
                        codec.name()
                    );
                    continue;
                }
                Err(e) => panic!("{name} {}: {e}", codec.name()),
            };
            let (full, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
            let decoded = full.attributes.as_ref().expect("appearance decoded");
            assert_eq!(
                appearance.check_lossless(&canonical, &full.mesh, decoded),
                Ok(()),
                "{name} {}",
                codec.name()
            );
            let ends = codecs::level_ends(&encoded.bytes).unwrap();
            assert_eq!(*ends.last().unwrap() as usize, encoded.bytes.len());
            // Without the appearance unit's last byte: the whole geometry, no appearance.
            let cut = &encoded.bytes[..encoded.bytes.len() - 1];
            let (geometry, _) = codecs::decode(cut, Stop::All).unwrap();
            assert!(geometry.attributes.is_none());
            assert_eq!(canonical.check_lossless(&geometry.mesh), Ok(()), "{name}");
        }
    }
}

#[test]
fn a_damaged_appearance_unit_is_an_error_or_another_appearance_never_a_panic() {
    let mesh = read_attributed(&resolve("spot").unwrap()).unwrap();
    let codec = codecs::by_name("emc").unwrap();
    let (canonical, appearance) =
        codecs::canonical_attributed_for(&mesh, &codec.default_options(), AttributeBits::default())
            .unwrap();
    let stream = codecs::encode_attributed(codec, &canonical, Some(&appearance))
        .unwrap()
        .bytes;
    let geometry = codec.encode(&canonical).unwrap().bytes.len();
    let unit_start = geometry + (stream.len() - geometry) / 2;
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..200 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let mut bad = stream.clone();
        let at = unit_start + (state as usize) % (stream.len() - unit_start);
        bad[at] ^= 1 << (state >> 61);
        let _ = codecs::decode(&bad, Stop::All);
    }
}

#[test]
fn a_mesh_with_materials_alone_keeps_them_through_every_codec_that_carries_appearance() {
    let obj = b"mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nusemtl red\nf 1 2 3\nusemtl blue\nf 2 4 3\nf 2 5 4\n";
    let mesh = meshcodec::mesh::io::read_attributed_bytes(obj, "obj").unwrap();
    assert!(mesh.attributes.corners.is_empty() && mesh.attributes.materials.is_some());
    for codec in codecs::registry() {
        if !codec.capabilities().contains(&Capability::Attributes) {
            continue;
        }
        let (canonical, appearance) = codecs::canonical_attributed_for(
            &mesh,
            &codec.default_options(),
            AttributeBits::default(),
        )
        .unwrap();
        let encoded = codecs::encode_attributed(codec, &canonical, Some(&appearance)).unwrap();
        let (full, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        let decoded = full.attributes.as_ref().expect("appearance decoded");
        assert_eq!(
            appearance.check_lossless(&canonical, &full.mesh, decoded),
            Ok(()),
            "{}",
            codec.name()
        );
    }
}

#[test]
fn the_harness_codes_appearance_when_asked_and_measures_it_at_the_level_that_carries_it() {
    use meshcodec::harness::{run, RunOptions};
    let path = resolve("spot").unwrap();
    let options = RunOptions {
        quant_bits: Some(12),
        samples_per_triangle: 2,
        appearance: Some(AttributeBits::default()),
        ..RunOptions::default()
    };
    let emc = codecs::by_name("emc").unwrap();
    let out = run(emc, &path, &options).unwrap();
    let r = &out.result;
    assert!(r.lossless, "{:?}", r.lossless_error);
    assert!(out.appearance.is_empty(), "nothing left uncoded");
    let appearance = r.appearance.as_ref().unwrap();
    assert_eq!(appearance.fields, ["uvs"]);
    assert!(appearance.wedges > r.vertices);
    assert!(appearance.bits > 0 && appearance.bits < r.bytes as u64 * 8);
    let (last, earlier) = r.levels.split_last().unwrap();
    // 12-bit uvs are off by a fraction of a texel of a 1024² texture.
    let uv = last.appearance.uv_texels.unwrap();
    assert!(uv > 0.0 && uv < 1.0, "{uv}");
    assert!(earlier.iter().all(|l| l.appearance.uv_texels.is_none()));
    assert_eq!(last.bits, r.bytes as u64 * 8);
    let csv = meshcodec::results::levels_csv(r);
    assert!(csv.lines().next().unwrap().ends_with("wrong_material"));
    // Without appearance the same run is geometry alone, and says what it left.
    let plain = run(
        emc,
        &path,
        &RunOptions {
            appearance: None,
            ..options.clone()
        },
    )
    .unwrap();
    assert!(plain.result.appearance.is_none());
    assert!(!plain.appearance.is_empty());
    assert!(plain.result.bytes < r.bytes);
    // A codec that cannot carry it codes the geometry and leaves the appearance uncoded.
    let lossy = run(codecs::by_name("came-paper").unwrap(), &path, &options).unwrap();
    assert!(lossy.result.appearance.is_none() && !lossy.appearance.is_empty());
}

/// `pm` with the appearance inside its vertex splits (`--attributes fit|keep`): every level
/// carries it, the full level is lossless with it, PMeshIter walks back to the base mesh and
/// forward again to the same appearance, and a cut or damaged stream is an error.
#[test]
fn pm_carries_appearance_at_every_level_with_either_rule() {
    use meshcodec::codecs::pm::iter::PMeshIter;
    use meshcodec::codecs::AttributeFit;
    // dragon-res3 and the fuzz seed torus-fin.obj (a fin, and a quad turned over) are no
    // oriented manifolds: pm cuts them, and the last level welds and turns back the corners too.
    let torus_fin = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fuzz/seeds/read_obj/torus-fin.obj"
    );
    for path in [
        resolve("spot").unwrap(),
        resolve("airplane-colored").unwrap(),
        resolve("dragon-res3").unwrap(),
        torus_fin.into(),
    ] {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let mesh = read_attributed(&path).unwrap();
        for codec_name in ["pm", "pm-reordered"] {
            let codec = codecs::by_name(codec_name).unwrap();
            let mut options = codec.default_options();
            options.quant_bits = 12;
            let (canonical, appearance) =
                codecs::canonical_attributed_for(&mesh, &options, AttributeBits::default())
                    .unwrap();
            for fit in [AttributeFit::Fit, AttributeFit::Keep] {
                let what = format!("{name} {codec_name} {}", fit.name());
                let encoded =
                    codecs::encode_attributed_with(codec, &canonical, Some(&appearance), Some(fit))
                        .unwrap();
                assert_eq!(encoded.bytes[4], meshcodec::container::FORMAT_VERSION);
                let mut decoder = codecs::open(&encoded.bytes).unwrap();
                let mut levels = 0;
                while decoder.advance().unwrap() {
                    let level = decoder.mesh().unwrap();
                    let attributes = level.attributes.as_ref().expect("every level");
                    assert_eq!(attributes.corners.len(), level.mesh.faces.len(), "{what}");
                    levels += 1;
                }
                assert!(levels > 1, "{what}");
                let full = decoder.mesh().unwrap();
                assert_eq!(
                    appearance.check_lossless(
                        &canonical,
                        &full.mesh,
                        full.attributes.as_ref().unwrap()
                    ),
                    Ok(()),
                    "{what}"
                );
                let mut iter = PMeshIter::from_stream(&encoded.bytes).unwrap();
                while iter.next().unwrap() {}
                let end = iter.attributes().unwrap();
                iter.goto_nvertices(0).unwrap();
                let base = iter.attributes().unwrap();
                assert_eq!(base.corners.len(), iter.nfaces(), "{what}");
                while iter.next().unwrap() {}
                assert_eq!(iter.attributes().unwrap(), end, "{what}");
                // Cut inside the last level: the levels before it, with their appearance.
                let cut = &encoded.bytes[..encoded.bytes.len() - 3];
                let (partial, _) = codecs::decode(cut, Stop::All).unwrap();
                assert!(partial.attributes.is_some(), "{what}");
                // Damaged bytes in the levels: an error or a mesh, never a panic.
                let mut damaged = encoded.bytes.clone();
                let at = damaged.len() / 2;
                damaged[at] ^= 0x5a;
                let _ = codecs::decode(&damaged, Stop::All);
            }
        }
    }
}

#[test]
fn a_pm_geomorph_carries_appearance_from_the_coarse_corners_to_the_fine_ones() {
    use meshcodec::codecs::pm::iter::{Geomorph, PMeshIter};
    use meshcodec::codecs::AttributeFit;
    let mesh = read_attributed(&resolve("spot").unwrap()).unwrap();
    let codec = codecs::by_name("pm").unwrap();
    let mut options = codec.default_options();
    options.quant_bits = 12;
    let (canonical, appearance) =
        codecs::canonical_attributed_for(&mesh, &options, AttributeBits::default()).unwrap();
    let encoded = codecs::encode_attributed_with(
        codec,
        &canonical,
        Some(&appearance),
        Some(AttributeFit::Fit),
    )
    .unwrap();
    let mut iter = PMeshIter::from_stream(&encoded.bytes).unwrap();
    iter.goto_nvertices(iter.nvertices() + 200).unwrap();
    let coarse_mesh = iter.level_mesh();
    let coarse = coarse_mesh.attributes.unwrap();
    let coarse_faces = iter.nfaces();
    let fine_n = iter.nvertices() * 3;
    let morph = Geomorph::new(&mut iter, fine_n).unwrap();
    let fine = iter.attributes().unwrap();
    let uv_of = |a: &meshcodec::mesh::attributes::Attributes, f: usize, k: usize| {
        a.uvs.as_ref().unwrap()[a.corners[f][k] as usize]
    };
    // Alpha 1: every corner has Mᶠ's value.
    let at1 = morph.evaluate_appearance(1.0).unwrap();
    assert_eq!(at1.corners.len(), fine.corners.len());
    for f in 0..fine.corners.len() {
        for k in 0..3 {
            assert_eq!(uv_of(&at1, f, k), uv_of(&fine, f, k));
        }
    }
    assert_eq!(at1.materials, fine.materials);
    // Alpha 0: a face of Mᶜ has its Mᶜ values; a face created since has, at each corner, one of
    // the values its ancestor vertex shows in Mᶜ.
    let at0 = morph.evaluate_appearance(0.0).unwrap();
    let ancestor_values = |p: glam::DVec3| -> Vec<glam::DVec2> {
        let v = coarse_mesh
            .mesh
            .positions
            .iter()
            .position(|q| *q == p)
            .unwrap() as u32;
        (0..coarse.wedge_vertex.len())
            .filter(|&w| coarse.wedge_vertex[w] == v)
            .map(|w| coarse.uvs.as_ref().unwrap()[w])
            .collect()
    };
    let mut moved = 0;
    for f in 0..at0.corners.len() {
        for k in 0..3 {
            let uv = uv_of(&at0, f, k);
            if f < coarse_faces {
                assert_eq!(uv, uv_of(&coarse, f, k), "face {f} corner {k}");
            } else {
                let p = morph.coarse[morph.faces[f][k] as usize];
                assert!(ancestor_values(p).contains(&uv), "face {f} corner {k}");
            }
            moved += usize::from(uv != uv_of(&fine, f, k));
        }
    }
    assert!(moved > 0, "the two ends differ somewhere");
    // Halfway, each uv lies between its ends.
    let half = morph.evaluate_appearance(0.5).unwrap();
    for (w, uv) in half.uvs.as_ref().unwrap().iter().enumerate() {
        let (a, b) = (at0.uvs.as_ref().unwrap()[w], at1.uvs.as_ref().unwrap()[w]);
        assert!((*uv - (a + b) * 0.5).length() < 1e-12);
    }
}
