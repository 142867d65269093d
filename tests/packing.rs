//! `meshcodec pack` and `unpack` through the library (docs/GLTF.md): a scene's triangle
//! primitives become progressive streams beside coarse fallbacks, the rest of the scene kept;
//! unpacking gives back the canonical meshes; a damaged scene is an error, never a panic.

use meshcodec::codecs::{self, Stop};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use meshcodec::mesh::generate;
use meshcodec::mesh::scene::{Content, Scene};
use meshcodec::packing::{self, extension, Outcome, PackOptions};
use meshcodec::Error;
use std::path::Path;

/// A scene of two meshes — a textured cube and a plain torus — placed by two nodes, with a
/// material and a camera and an extra, written as a GLB by the library's writer first and
/// then given a second primitive by hand.
fn two_mesh_scene() -> Vec<u8> {
    let cube = generate::textured_cube(10);
    let glb = meshcodec::mesh::io::write_attributed_bytes(&cube, "glb").unwrap();
    let mut scene = Scene::read(&glb, None).unwrap();
    // A second mesh, geometry only, as a scene of its own, merged by packing both.
    let torus = meshcodec::mesh::attributes::AttributedMesh {
        mesh: generate::torus(2.0, 0.5, 24, 12),
        attributes: Default::default(),
    };
    let torus_scene = Scene::from_mesh(torus, "torus").unwrap();
    let doc = &mut scene.document;
    doc.meshes.push(torus_scene.document.meshes[0].clone());
    doc.nodes.push(gltf_json::Node {
        mesh: Some(gltf_json::Index::new(1)),
        translation: Some([3.0, 0.0, 0.0]),
        name: Some("the torus".into()),
        ..Default::default()
    });
    let node = doc.nodes.len() as u32 - 1;
    doc.scenes[0].nodes.push(gltf_json::Index::new(node));
    doc.cameras.push(
        serde_json::from_value(serde_json::json!({
            "type": "perspective",
            "perspective": {"yfov": 0.8, "znear": 0.01}
        }))
        .unwrap(),
    );
    doc.asset.copyright = Some("test".into());
    let mut primitives = scene.primitives.clone();
    primitives.extend(torus_scene.primitives.into_iter().map(|mut p| {
        p.mesh = 1;
        p
    }));
    scene.primitives = primitives;
    let options = PackOptions {
        fallback: None,
        ..PackOptions::new().unwrap()
    };
    // Packing and unpacking both writes the scene through the same assembly: the unpacked
    // scene is a plain GLB of both meshes.
    let packed = packing::pack(&scene, &options, None).unwrap();
    let unpacked = packing::unpack(&Scene::read(&packed.glb, None).unwrap()).unwrap();
    unpacked.glb
}

#[test]
fn a_packed_scene_keeps_its_nodes_materials_and_cameras_and_unpacks_to_the_canonical_meshes() {
    let glb = two_mesh_scene();
    let scene = Scene::read(&glb, None).unwrap();
    assert_eq!(scene.document.meshes.len(), 2);
    assert!(scene
        .primitives
        .iter()
        .all(|p| matches!(p.content, Content::Triangles(_))));
    let options = PackOptions::new().unwrap();
    let packed = packing::pack(&scene, &options, None).unwrap();
    assert!(packed.streams.is_none());
    assert_eq!(packed.report.len(), 2);
    let again = Scene::read(&packed.glb, None).unwrap();
    let doc = &again.document;
    assert_eq!(doc.nodes.len(), scene.document.nodes.len());
    assert_eq!(doc.nodes[1].translation, Some([3.0, 0.0, 0.0]));
    assert_eq!(doc.cameras.len(), 1);
    assert_eq!(doc.asset.copyright.as_deref(), Some("test"));
    assert!(doc.extensions_used.iter().any(|e| e == extension::NAME));
    assert!(doc.extensions_required.is_empty());
    for (m, mesh) in doc.meshes.iter().enumerate() {
        let primitive = &mesh.primitives[0];
        let object = primitive.extensions.as_ref().unwrap().others[extension::NAME].clone();
        let progressive: extension::Progressive = serde_json::from_value(object).unwrap();
        // The fallback: a level between the first and the last, in ordinary accessors.
        assert!(progressive.fallback_level > 1, "mesh {m}");
        assert!(
            (progressive.fallback_level as usize) < progressive.levels.len(),
            "mesh {m}"
        );
        let fallback = &progressive.levels[progressive.fallback_level as usize - 1];
        let indices = primitive.indices.unwrap().value();
        assert_eq!(
            doc.accessors[indices].count.0,
            3 * fallback.faces,
            "mesh {m}"
        );
        let stream = packing::stream_bytes(&again, progressive.buffer_view as usize).unwrap();
        assert_eq!(
            progressive.levels.last().unwrap().byte_length as usize,
            stream.len()
        );
        assert_eq!(
            codecs::level_ends(stream).unwrap().len(),
            progressive.levels.len()
        );
        // The fallback is the stream's level, decoded.
        let (level, _) =
            codecs::decode(stream, Stop::Levels(progressive.fallback_level as usize)).unwrap();
        assert_eq!(level.mesh.faces.len() as u64, fallback.faces);
        let textured = m == 0;
        assert_eq!(
            progressive.attributes.contains(&"TEXCOORD_0".to_string()),
            textured
        );
    }
    // Unpacked: each full level, its positions re-quantizing to the canonical mesh.
    let unpacked = packing::unpack(&again).unwrap();
    assert_eq!(unpacked.primitives, 2);
    let plain = Scene::read(&unpacked.glb, None).unwrap();
    assert!(!plain
        .document
        .extensions_used
        .iter()
        .any(|e| e == extension::NAME));
    for (p, original) in plain.primitives.iter().zip(&scene.primitives) {
        let (Some(back), Some(original)) = (p.content.triangles(), original.content.triangles())
        else {
            panic!("a primitive was kept");
        };
        let codec = codecs::by_name("emc").unwrap();
        let bits = AttributeBits::default();
        let (canonical, appearance) =
            codecs::canonical_attributed_for(original, &codec.default_options(), bits).unwrap();
        let _ = appearance;
        assert_eq!(canonical.check_lossless(&back.mesh), Ok(()));
    }
}

#[test]
fn external_streams_and_no_fallback() {
    let scene = Scene::read(&two_mesh_scene(), None).unwrap();
    let options = PackOptions {
        fallback: None,
        ..PackOptions::new().unwrap()
    };
    let packed = packing::pack(&scene, &options, Some("scene.streams.bin")).unwrap();
    let streams = packed.streams.expect("a file of streams");
    let glb = gltf::binary::Glb::from_slice(&packed.glb).unwrap();
    let doc: gltf_json::Root = serde_json::from_slice(&glb.json).unwrap();
    // Without a fallback every byte is a stream: the streams' file is the only buffer.
    assert_eq!(doc.buffers.len(), 1);
    assert_eq!(doc.buffers[0].uri.as_deref(), Some("scene.streams.bin"));
    assert_eq!(doc.buffers[0].byte_length.0 as usize, streams.len());
    assert!(doc.extensions_required.iter().any(|e| e == extension::NAME));
    // Without a fallback the accessors hold no data, POSITION its bounds.
    let primitive = &doc.meshes[0].primitives[0];
    for index in primitive.attributes.values() {
        assert!(doc.accessors[index.value()].buffer_view.is_none());
    }
    assert!(primitive.indices.is_none());
    // Read back with the streams' file beside it, the streams decode.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.streams.bin"), &streams).unwrap();
    let again = Scene::read(&packed.glb, Some(dir.path())).unwrap();
    let unpacked = packing::unpack(&again).unwrap();
    assert_eq!(unpacked.primitives, 2);
    // Without it, one line naming the file.
    let missing = Scene::read(&packed.glb, Some(&dir.path().join("nowhere"))).unwrap_err();
    assert!(
        missing.to_string().contains("scene.streams.bin"),
        "{missing}"
    );
}

/// `scene` edited by hand, written as a GLB and read again.
fn rewritten(scene: &Scene) -> Scene {
    let glb = meshcodec::packing::assemble::write_glb(
        scene,
        &Default::default(),
        &[],
        &[],
        &[],
        &meshcodec::packing::assemble::Streams::Embedded,
    )
    .unwrap()
    .0;
    Scene::read(&glb, None).unwrap()
}

#[test]
fn primitives_the_codecs_cannot_take_are_kept_and_listed() {
    let mut scene = Scene::read(&two_mesh_scene(), None).unwrap();
    // The torus as points.
    scene.document.meshes[1].primitives[0].mode =
        gltf_json::validation::Checked::Valid(gltf_json::mesh::Mode::Points);
    let scene = rewritten(&scene);
    assert!(matches!(&scene.primitives[1].content, Content::Kept(why) if why.contains("Points")));
    let packed = packing::pack(&scene, &PackOptions::new().unwrap(), None).unwrap();
    assert!(matches!(packed.report[0].outcome, Outcome::Packed { .. }));
    assert!(matches!(&packed.report[1].outcome, Outcome::Kept(_)));
    let again = Scene::read(&packed.glb, None).unwrap();
    // The points keep their accessors, renumbered.
    let points = &again.document.meshes[1].primitives[0];
    let position = points.attributes.values().next().unwrap().value();
    let (values, _) = again.accessor(position).unwrap();
    assert_eq!(values.len() / 3, 24 * 12);
    // A scene with nothing to code, packed with `--external`, names no streams' file (a glTF
    // buffer may not be empty).
    let mut points_only = scene;
    points_only.document.meshes.remove(0);
    points_only
        .document
        .nodes
        .retain(|n| n.mesh.is_some_and(|m| m.value() == 1));
    for node in &mut points_only.document.nodes {
        node.mesh = Some(gltf_json::Index::new(0));
    }
    points_only.document.scenes[0].nodes = vec![gltf_json::Index::new(0)];
    let points_only = rewritten(&points_only);
    let packed = packing::pack(&points_only, &PackOptions::new().unwrap(), Some("s.bin")).unwrap();
    assert!(packed.streams.is_none());
    let doc: gltf_json::Root =
        serde_json::from_slice(&gltf::binary::Glb::from_slice(&packed.glb).unwrap().json).unwrap();
    assert!(doc
        .buffers
        .iter()
        .all(|b| b.uri.is_none() && b.byte_length.0 > 0));
}

#[test]
fn a_scene_already_packed_or_compressed_with_draco_is_refused_in_one_line() {
    let scene = Scene::read(&two_mesh_scene(), None).unwrap();
    let packed = packing::pack(&scene, &PackOptions::new().unwrap(), None).unwrap();
    let again = Scene::read(&packed.glb, None).unwrap();
    let twice = packing::pack(&again, &PackOptions::new().unwrap(), None).unwrap_err();
    assert!(twice.to_string().contains("unpack"), "{twice}");
    let mut draco = scene.document.clone();
    draco
        .extensions_used
        .push("KHR_draco_mesh_compression".into());
    let json = serde_json::to_vec(&draco).unwrap();
    let refused = Scene::read(&json, None).unwrap_err();
    assert!(matches!(refused, Error::Unsupported(_)));
    assert!(
        refused.to_string().contains("decode them first"),
        "{refused}"
    );
}

/// Damaged scenes: each an error in one line, never a panic.
#[test]
fn bad_gltf_is_an_error_never_a_panic() {
    let glb = two_mesh_scene();
    let glb_parts = gltf::binary::Glb::from_slice(&glb).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&glb_parts.json).unwrap();
    let with = |edit: &dyn Fn(&mut serde_json::Value)| -> Vec<u8> {
        let mut doc = json.clone();
        edit(&mut doc);
        let text = serde_json::to_vec(&doc).unwrap();
        gltf::binary::Glb {
            header: glb_parts.header,
            json: std::borrow::Cow::Owned(text),
            bin: glb_parts.bin.clone(),
        }
        .to_vec()
        .unwrap()
    };
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("broken JSON", b"{\"asset\": ".to_vec()),
        ("a GLB cut short", glb[..glb.len() / 2].to_vec()),
        (
            "a buffer shorter than it says",
            with(&|d| d["buffers"][0]["byteLength"] = 1_000_000_000.into()),
        ),
        (
            "an accessor out of range",
            with(&|d| d["meshes"][0]["primitives"][0]["indices"] = 999.into()),
        ),
        (
            "an accessor past its view",
            with(&|d| d["accessors"][0]["count"] = 1_000_000.into()),
        ),
        (
            "a view past its buffer",
            with(&|d| d["bufferViews"][0]["byteLength"] = 1_000_000_000.into()),
        ),
        (
            "indices past the vertices",
            with(&|d| {
                let position = d["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
                    .as_u64()
                    .unwrap();
                d["accessors"][position as usize]["count"] = 3.into();
            }),
        ),
        (
            "an external buffer",
            with(&|d| d["buffers"][0]["uri"] = "missing.bin".into()),
        ),
    ];
    for (what, bytes) in cases {
        let outcome = Scene::read(&bytes, None)
            .and_then(|scene| packing::pack(&scene, &PackOptions::new()?, None).map(|_| ()));
        let e = outcome.expect_err(what);
        assert!(!e.to_string().contains('\n'), "{what}: {e}");
    }
}

/// A scene gltfpack compressed with EXT_meshopt_compression (fuzz/seeds/pack_gltf: the torus
/// seed through `gltfpack -cc`: quantized positions, octahedral normals, compressed indices)
/// reads as the plain scene does: the same triangles, unit normals (the filter undone), and it
/// packs and unpacks.
#[test]
#[cfg_attr(
    not(feature = "meshopt"),
    ignore = "reads EXT_meshopt_compression with the meshopt feature"
)]
fn a_scene_compressed_with_meshopt_is_decoded() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/pack_gltf");
    let plain = Scene::open(&seeds.join("torus.glb")).unwrap();
    let compressed = Scene::open(&seeds.join("torus-gltfpack.glb")).unwrap();
    assert!(compressed
        .document
        .extensions_used
        .iter()
        .all(|e| e != "EXT_meshopt_compression"));
    let faces = |scene: &Scene| -> usize {
        scene
            .primitives
            .iter()
            .map(|p| p.content.triangles().expect("triangles").mesh.faces.len())
            .sum()
    };
    assert_eq!(faces(&compressed), faces(&plain));
    for primitive in &compressed.primitives {
        let mesh = primitive.content.triangles().unwrap();
        let normals = mesh.attributes.normals.as_ref().expect("normals");
        for n in normals {
            assert!(
                (n.length() - 1.0).abs() < 0.02,
                "a normal of length {}",
                n.length()
            );
        }
    }
    let packed = packing::pack(&compressed, &PackOptions::new().unwrap(), None).unwrap();
    let again = Scene::read(&packed.glb, None).unwrap();
    assert_eq!(
        packing::unpack(&again).unwrap().primitives,
        compressed.primitives.len()
    );
}
