//! Appearance through every codec that carries it (docs/CONTRACT.md §2.1, §3): each shared mesh
//! with normals, uvs, colours or materials decodes to its canonical mesh with every corner's
//! quantized attributes and every face's material; a prefix without the appearance unit decodes
//! the full geometry alone; a damaged unit is an error, never a panic.

use meshcodec::codecs::{self, Capability, Stop};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::io::{read_attributed, resolve};
use meshcodec::Error;

#[path = "../../tests/common/mod.rs"]
mod common;
use common::spot_with_creased_normals;

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
            let cut = &encoded.bytes[..encoded.bytes.len() - 1];
            let (before, _) = codecs::decode(cut, Stop::All).unwrap();
            if codec
                .capabilities()
                .contains(&Capability::AppearanceWithLevels)
            {
                // Without the last level's last byte: the level before, with what it shows.
                let shown = before
                    .attributes
                    .as_ref()
                    .expect("the level before shows appearance");
                assert_eq!(shown.corners.len(), before.mesh.faces.len(), "{name}");
            } else {
                // Without the appearance unit's last byte: the whole geometry, no appearance.
                assert!(before.attributes.is_none());
                assert_eq!(canonical.check_lossless(&before.mesh), Ok(()), "{name}");
            }
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
    use meshcodec_lab::harness::{run, RunOptions};
    let path = resolve("spot").unwrap();
    let options = RunOptions {
        quant_bits: Some(12),
        samples: meshcodec::metrics::SampleBudget::per_triangle(2),
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
    // emc shows the appearance at every level, nearer the original's as levels come.
    let errors: Vec<f64> = earlier
        .iter()
        .map(|l| l.appearance.uv_texels.expect("every level has uvs"))
        .collect();
    assert!(errors.iter().all(|&e| e > uv), "{errors:?}");
    assert!(
        errors.last().unwrap() < errors.first().unwrap(),
        "{errors:?}"
    );
    assert_eq!(last.bits, r.bytes as u64 * 8);
    let csv = meshcodec_lab::results::levels_csv(r);
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
    use meshcodec::codecs::AttributeFit;
    // dragon-res3 and the fuzz seed torus-fin.obj (a fin, and a quad turned over) are no
    // oriented manifolds: pm cuts them, and the last level welds and turns back the corners too.
    let torus_fin = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fuzz/seeds/read_obj/torus-fin.obj"
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
                assert_full_level_lossless(&appearance, &canonical, decoder.as_ref(), &what);
                let (mut iter, end) = at_the_full_level(&encoded.bytes);
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

/// Normals derived from geometry (`--derive-normals`, Hoppe 1998's Table 4 mode): pm codes no
/// normal value, only which corners share one; every level's normals are those its own
/// geometry gives its groups, and the full level is the canonical mesh whose normals are derived.
#[test]
fn pm_derives_normals_from_geometry_and_codes_only_the_creases() {
    use meshcodec::codecs::pm::iter::Geomorph;
    use meshcodec::codecs::AttributeFit;
    use meshcodec::mesh::attribute_quantization::octahedral_code;
    let mesh = spot_with_creased_normals();
    let codec = codecs::by_name("pm-reordered").unwrap();
    let mut options = codec.default_options();
    options.quant_bits = 12;
    let derived = AttributeBits {
        derive_normals: true,
        ..AttributeBits::default()
    };
    let (canonical, appearance) =
        codecs::canonical_attributed_for(&mesh, &options, derived).unwrap();
    let (_, carried) =
        codecs::canonical_attributed_for(&mesh, &options, AttributeBits::default()).unwrap();
    // The flat part keeps a crease at every edge: about as many normal groups either way
    // (fewer where neighbouring faces' derived normals code alike and their groups merge).
    let groups = |a: &meshcodec::mesh::canonical_attributes::CanonicalAttributes| {
        let mut set = std::collections::HashSet::new();
        for (face, wedges) in canonical.faces.iter().zip(&a.corners) {
            for (&v, &w) in face.iter().zip(wedges) {
                set.insert((v, a.normals.as_ref().unwrap()[w as usize]));
            }
        }
        set.len()
    };
    let (ours, theirs) = (groups(&appearance), groups(&carried));
    assert!(
        ours <= theirs && ours * 50 > theirs * 49,
        "{ours} vs {theirs}"
    );
    assert_ne!(appearance.normals, carried.normals);
    for fit in [AttributeFit::Keep, AttributeFit::Fit] {
        let what = fit.name();
        let encoded =
            codecs::encode_attributed_with(codec, &canonical, Some(&appearance), Some(fit))
                .unwrap();
        assert!(encoded.stats.get_named("bits_normal").unwrap_or(0.0) == 0.0);
        let with_values =
            codecs::encode_attributed_with(codec, &canonical, Some(&carried), Some(fit)).unwrap();
        // Normal values are predicted from geometry; derived normals are labels alone.
        let spec = |bytes: &[u8]| {
            let reader = meshcodec::container::StreamReader::open(bytes).unwrap();
            reader.header().appearance.clone().unwrap()
        };
        let (ours, theirs) = (spec(&encoded.bytes), spec(&with_values.bytes));
        assert!(ours.derived_normals && !ours.geometric_normals);
        assert!(!theirs.derived_normals && theirs.geometric_normals);
        assert!(
            encoded.bytes.len() < with_values.bytes.len(),
            "{what}: {} vs {}",
            encoded.bytes.len(),
            with_values.bytes.len()
        );
        let mut decoder = codecs::open(&encoded.bytes).unwrap();
        let mut levels = 0;
        while decoder.advance().unwrap() {
            let level = decoder.mesh().unwrap();
            let a = level.attributes.as_ref().expect("every level");
            // Each wedge's normal is its group's: the area-weighted normal of the faces whose
            // corners at its vertex carry that normal.
            let bits = appearance.bits.normal;
            let normals = a.normals.as_ref().unwrap();
            let mut sums = std::collections::HashMap::new();
            for (f, face) in level.mesh.faces.iter().enumerate() {
                let p = face.map(|v| level.mesh.positions[v as usize]);
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                for k in 0..3 {
                    let code = octahedral_code(normals[a.corners[f][k] as usize], bits);
                    *sums.entry((face[k], code)).or_insert(glam::DVec3::ZERO) += n;
                }
            }
            for ((_, code), sum) in sums {
                let again = octahedral_code(sum, bits);
                let off = (code[0].abs_diff(again[0])).max(code[1].abs_diff(again[1]));
                // Cell centres against exact cells: a code may move by one step.
                assert!(off <= 1, "{what} level {levels}: {code:?} vs {again:?}");
            }
            levels += 1;
        }
        assert!(levels > 3, "{what}");
        assert_full_level_lossless(&appearance, &canonical, decoder.as_ref(), what);
        // Back to the base mesh and forward again; a geomorph between two levels.
        let (mut iter, end) = at_the_full_level(&encoded.bytes);
        iter.goto_nvertices(0).unwrap();
        let base_vertices = iter.nvertices();
        let morph = Geomorph::new(&mut iter, base_vertices * 2).unwrap();
        let at = |alpha| morph.evaluate_appearance(alpha).unwrap();
        assert!(at(0.0).normals.unwrap().iter().all(|n| n.is_normalized()));
        // At alpha 1 every corner has Mᶠ's normal (the geomorph's wedges split Mᶠ's further).
        let corner_normals = |a: &meshcodec::mesh::attributes::Attributes| -> Vec<glam::DVec3> {
            let normals = a.normals.as_ref().unwrap();
            a.corners
                .iter()
                .flatten()
                .map(|&w| normals[w as usize])
                .collect()
        };
        let (ends, ours) = (
            corner_normals(&at(1.0)),
            corner_normals(&iter.attributes().unwrap()),
        );
        // (Renormalized after the blend: equal up to rounding.)
        let differ = (0..ends.len())
            .filter(|&i| (ends[i] - ours[i]).length() > 1e-12)
            .count();
        assert_eq!(differ, 0, "{what}: of {} corners", ends.len());
        while iter.next().unwrap() {}
        assert_eq!(iter.attributes().unwrap(), end, "{what}");
    }
}

#[test]
fn derived_normals_are_carried_as_values_by_the_other_codecs_and_pm_refuses_them_on_a_cut_mesh() {
    use meshcodec::codecs::AttributeFit;
    let derived = AttributeBits {
        derive_normals: true,
        ..AttributeBits::default()
    };
    let mesh = spot_with_creased_normals();
    let codec = codecs::by_name("emc").unwrap();
    let (canonical, appearance) =
        codecs::canonical_attributed_for(&mesh, &codec.default_options(), derived).unwrap();
    let encoded = codecs::encode_attributed(codec, &canonical, Some(&appearance)).unwrap();
    let (full, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
    assert_eq!(
        appearance.check_lossless(&canonical, &full.mesh, full.attributes.as_ref().unwrap()),
        Ok(())
    );
    // dragon-res3 is no manifold: its cut would split normal groups at the copied vertices.
    let dragon = read_attributed(&resolve("dragon-res3").unwrap()).unwrap();
    let pm = codecs::by_name("pm").unwrap();
    let (canonical, appearance) =
        codecs::canonical_attributed_for(&dragon, &pm.default_options(), derived).unwrap();
    match codecs::encode_attributed_with(
        pm,
        &canonical,
        Some(&appearance),
        Some(AttributeFit::Keep),
    ) {
        Err(Error::Unsupported(why)) => assert!(why.contains("manifold"), "{why}"),
        other => panic!("{:?}", other.map(|e| e.bytes.len())),
    }
}

/// Checks that the level `decoder` stands at is the canonical mesh with its appearance.
fn assert_full_level_lossless(
    appearance: &meshcodec::mesh::canonical_attributes::CanonicalAttributes,
    canonical: &meshcodec::mesh::CanonicalMesh,
    decoder: &dyn codecs::LevelDecoder,
    what: &str,
) {
    let full = decoder.mesh().unwrap();
    let decoded = full.attributes.as_ref().expect("appearance decoded");
    assert_eq!(
        appearance.check_lossless(canonical, &full.mesh, decoded),
        Ok(()),
        "{what}"
    );
}

/// A PMeshIter over `stream` moved to its full level, and that level's appearance.
fn at_the_full_level(
    stream: &[u8],
) -> (
    meshcodec::codecs::pm::iter::PMeshIter<'_>,
    meshcodec::mesh::attributes::Attributes,
) {
    let mut iter = meshcodec::codecs::pm::iter::PMeshIter::from_stream(stream).unwrap();
    while iter.next().unwrap() {}
    let end = iter.attributes().unwrap();
    (iter, end)
}

/// Derived normals on an open manifold: groups at boundary vertices, whose fans end at the hole.
#[test]
fn pm_derives_normals_on_a_mesh_with_a_hole() {
    use meshcodec::codecs::AttributeFit;
    use meshcodec::mesh::attributes::Attributes;
    let mut mesh = spot_with_creased_normals();
    // Cut a cap off the top: the faces whose corners all lie above the 95th percentile of y.
    let positions = mesh.mesh.positions.clone();
    let mut ys: Vec<f64> = positions.iter().map(|p| p.y).collect();
    ys.sort_by(f64::total_cmp);
    let cut = ys[ys.len() * 95 / 100];
    let keep: Vec<usize> = (0..mesh.mesh.faces.len())
        .filter(|&f| {
            !mesh.mesh.faces[f]
                .iter()
                .all(|&v| positions[v as usize].y > cut)
        })
        .collect();
    assert!(keep.len() < mesh.mesh.faces.len());
    let old = mesh.attributes.clone();
    let faces: Vec<[u32; 3]> = keep.iter().map(|&f| mesh.mesh.faces[f]).collect();
    let corners: Vec<[meshcodec::mesh::attributes::Corner; 3]> = keep
        .iter()
        .map(|&f| {
            std::array::from_fn(|k| meshcodec::mesh::attributes::Corner {
                normal: old.normals.as_ref().map(|n| n[old.corners[f][k] as usize]),
                uv: old.uvs.as_ref().map(|t| t[old.corners[f][k] as usize]),
                colour: None,
            })
        })
        .collect();
    mesh.mesh.faces = faces;
    mesh.attributes = Attributes::weld(&mesh.mesh.faces, &corners).unwrap();
    let codec = codecs::by_name("pm-reordered").unwrap();
    let derived = AttributeBits {
        derive_normals: true,
        ..AttributeBits::default()
    };
    let (canonical, appearance) =
        codecs::canonical_attributed_for(&mesh, &codec.default_options(), derived).unwrap();
    let encoded = codecs::encode_attributed_with(
        codec,
        &canonical,
        Some(&appearance),
        Some(AttributeFit::Keep),
    )
    .unwrap();
    let mut decoder = codecs::open(&encoded.bytes).unwrap();
    while decoder.advance().unwrap() {}
    assert_full_level_lossless(
        &appearance,
        &canonical,
        decoder.as_ref(),
        "spot with a hole",
    );
}

/// `emc` and `emc-ahead` show the appearance at every level: each level holding at least 5% of
/// the mesh's vertices has a uv on every face corner, and the full level is lossless — on the
/// shared textured meshes, a rounded cube of quads whose edges are seams, and that cube read
/// back from a GLB.
#[test]
fn every_level_of_emc_shows_uvs_on_every_corner() {
    let cube = meshcodec::mesh::generate::textured_cube(12);
    let glb = meshcodec::mesh::io::write_attributed_bytes(&cube, "glb").unwrap();
    let from_glb = meshcodec::mesh::io::read_attributed_bytes(&glb, "glb").unwrap();
    let meshes = [
        ("spot", read_attributed(&resolve("spot").unwrap()).unwrap()),
        (
            "bunny-10k-textured",
            read_attributed(&resolve("bunny-10k-textured").unwrap()).unwrap(),
        ),
        ("textured cube", cube),
        ("textured cube from a GLB", from_glb),
    ];
    for (name, mesh) in &meshes {
        for codec in ["emc", "emc-ahead"] {
            let codec = codecs::by_name(codec).unwrap();
            let (canonical, appearance) = codecs::canonical_attributed_for(
                mesh,
                &codec.default_options(),
                AttributeBits::default(),
            )
            .unwrap();
            let encoded = codecs::encode_attributed(codec, &canonical, Some(&appearance)).unwrap();
            let mut decoder = codecs::open(&encoded.bytes).unwrap();
            let vertices = canonical.vertex_count();
            let mut shown = 0;
            while decoder.advance().unwrap() {
                let level = decoder.mesh().unwrap();
                if level.mesh.positions.len() * 20 < vertices {
                    continue;
                }
                let at = format!("{name} {} level {}", codec.name(), decoder.levels_decoded());
                let a = level.attributes.as_ref().expect(&at);
                a.validate(&level.mesh).expect(&at);
                let uvs = a.uvs.as_ref().expect(&at);
                assert_eq!(a.corners.len(), level.mesh.faces.len(), "{at}");
                assert!(uvs.iter().all(|t| t.is_finite()), "{at}");
                shown += 1;
            }
            assert!(shown >= 4, "{name}: {shown} levels");
            let full = decoder.mesh().unwrap();
            assert_eq!(
                appearance.check_lossless(
                    &canonical,
                    &full.mesh,
                    full.attributes.as_ref().unwrap()
                ),
                Ok(()),
                "{name} {}",
                codec.name()
            );
        }
    }
}
