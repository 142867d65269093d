//! Golden streams and rate pins: an accidental change to the bytes a codec writes, or to how
//! well it compresses, fails here.
//!
//! - `tests/golden/v<FORMAT_VERSION>/<codec>-<mesh>.mc` is each codec's stream of a small shared
//!   mesh at its default quantization, and `<mesh>-q<bits>.ply` the canonical mesh it decodes to.
//!   The encoder must reproduce every stream byte for byte, and each stream must decode exactly
//!   to that canonical mesh (docs/CONTRACT.md §3: same cells, same oriented faces).
//! - `tests/golden/rates.txt` pins each codec's bits per vertex on three meshes; a codec that
//!   codes any of them in more bits fails.
//!
//! - `tests/golden/v<FORMAT_VERSION>/emc-spot-appearance.mc` is `emc`'s stream of spot.obj with
//!   its uvs (12-bit positions and uvs): the appearance unit's bytes are pinned too, and the
//!   stream must decode to the canonical mesh with its appearance exactly.
//!
//! - `tests/golden/v<FORMAT_VERSION>/pm-reordered-*` pin `pm-reordered` with the appearance in
//!   its splits: spot's uvs, vw-beetle's normals predicted from geometry, and spot's creased
//!   normals derived.
//! - `*-before-*.mc` are streams of parameters today's encoders no longer choose (`emc` with its
//!   face corrections after the last level, `came` without normal cones, deviations or
//!   triangle normals, or of meta-nodes of 8 levels), kept to show that those parameters still
//!   decode as they did.
//!
//! All are regenerated on purpose with `UPDATE_GOLDEN=1 cargo test --release --test golden`,
//! which a change of syntax must come with (and a new format version: docs/FORMAT.md, History).

use meshcodec::codecs::{self, Codec, Stop};
use meshcodec::container::FORMAT_VERSION;
use meshcodec::mesh::io::{read_mesh, resolve, write_mesh};
use meshcodec::mesh::{CanonicalMesh, TriMesh};
use meshcodec::Error;
use std::fmt::Write as _;
use std::path::PathBuf;

mod common;

/// Small shared meshes every codec takes: a closed genus-2 surface and a bust of three
/// components.
const GOLDEN_MESHES: [&str; 2] = ["eight", "beethoven"];
/// Meshes whose rates are pinned.
const RATE_MESHES: [&str; 3] = ["eight", "beethoven", "spot"];

fn golden_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(format!("v{FORMAT_VERSION}"))
}

fn rates_file() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/golden/rates.txt")
}

fn updating() -> bool {
    std::env::var_os("UPDATE_GOLDEN").is_some_and(|v| v == "1")
}

/// Each of `meshes` as read, once.
fn read_all<const N: usize>(meshes: [&'static str; N]) -> [(&'static str, TriMesh); N] {
    meshes.map(|mesh| {
        let path = resolve(mesh).unwrap_or_else(|e| panic!("{mesh}: {e}"));
        (mesh, read_mesh(&path).unwrap())
    })
}

fn canonical(codec: &dyn Codec, original: &TriMesh) -> CanonicalMesh {
    codecs::canonical_for(original, &codec.default_options()).unwrap()
}

#[test]
fn encoders_reproduce_the_golden_streams_and_these_decode_exactly() {
    let dir = golden_dir();
    if updating() {
        std::fs::create_dir_all(&dir).unwrap();
    }
    let originals = read_all(GOLDEN_MESHES);
    let mut failures = Vec::new();
    for codec in codecs::registry() {
        for (mesh, original) in &originals {
            let canonical = canonical(codec, original);
            let bytes = codec.encode(&canonical).unwrap().bytes;
            let stream_path = dir.join(format!("{}-{mesh}.mc", codec.name()));
            let mesh_path = dir.join(format!("{mesh}-q{}.ply", canonical.grid.bits));
            if updating() {
                std::fs::write(&stream_path, &bytes).unwrap();
                write_mesh(&canonical.to_mesh(), &mesh_path).unwrap();
            }
            let Ok(golden) = std::fs::read(&stream_path) else {
                failures.push(format!(
                    "{} missing (make it with UPDATE_GOLDEN=1)",
                    stream_path.display()
                ));
                continue;
            };
            if golden != bytes {
                let first = golden.iter().zip(&bytes).position(|(a, b)| a != b);
                failures.push(format!(
                    "{} on {mesh}: the encoder's {} bytes differ from the golden stream's {} (first at byte {})",
                    codec.name(),
                    bytes.len(),
                    golden.len(),
                    first.unwrap_or(golden.len().min(bytes.len()))
                ));
            }
            // The stored canonical mesh, on the stream's grid (its cell centres re-quantize
            // exactly), must be today's canonical mesh, and the golden stream must decode to it.
            let stored =
                CanonicalMesh::new(&read_mesh(&mesh_path).unwrap(), canonical.grid).unwrap();
            if stored.normal_form() != canonical.normal_form() {
                failures.push(format!(
                    "{}: not the canonical mesh of {mesh} at {} bits",
                    mesh_path.display(),
                    canonical.grid.bits
                ));
            }
            match codecs::decode(&golden, Stop::All) {
                Ok((decoded, _)) if !codec.lossless() => {
                    // A lossy codec's full level keeps the mesh's vertices and faces.
                    let counts = |m: &TriMesh| (m.vertex_count(), m.face_count());
                    if counts(&decoded.mesh) != counts(&stored.to_mesh()) {
                        failures.push(format!(
                            "{} on {mesh}: the golden stream decodes to {:?} vertices and faces, not {:?}",
                            codec.name(),
                            counts(&decoded.mesh),
                            counts(&stored.to_mesh())
                        ));
                    }
                }
                Ok((decoded, _)) => {
                    if let Err(e) = stored.check_lossless(&decoded.mesh) {
                        failures.push(format!(
                            "{} on {mesh}: the golden stream does not decode to {}: {e}",
                            codec.name(),
                            mesh_path.display()
                        ));
                    }
                }
                Err(e) => failures.push(format!(
                    "{} on {mesh}: the golden stream does not decode: {e}",
                    codec.name()
                )),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `emc` streams with the face corrections after the last level (the fourth parameter byte 0,
/// as `emc` wrote before they moved to the level that decodes the last vertex) still decode
/// exactly, level by level as the new ones: `emc-eight-before-settled-faces.mc` is the golden
/// stream of that build, kept (its header in today's format).
#[test]
fn emc_streams_with_the_corrections_after_the_last_level_still_decode() {
    let old = std::fs::read(golden_dir().join("emc-eight-before-settled-faces.mc")).unwrap();
    let codec = codecs::by_name("emc").unwrap();
    let [(_, eight)] = read_all(["eight"]);
    let canonical = canonical(codec, &eight);
    let new = codec.encode(&canonical).unwrap().bytes;
    let params = |bytes: &[u8]| {
        meshcodec::container::StreamReader::open(bytes)
            .unwrap()
            .header()
            .params
            .clone()
    };
    assert_eq!(
        (params(&old)[3], params(&new)[3]),
        (0, 1),
        "where the corrections go"
    );
    let (mut old_levels, mut new_levels) =
        (codecs::open(&old).unwrap(), codecs::open(&new).unwrap());
    let mut levels = 0;
    while old_levels.advance().unwrap() {
        assert!(new_levels.advance().unwrap());
        let (o, n) = (old_levels.mesh().unwrap(), new_levels.mesh().unwrap());
        assert_eq!(o.mesh.positions, n.mesh.positions, "level {levels}");
        levels += 1;
        if levels == old_levels.levels() {
            assert!(o == n, "the full levels are the same mesh");
            canonical.check_lossless(&o.mesh).unwrap();
        } else if o.mesh.faces != n.mesh.faces {
            // The new stream shows the mesh's own faces once every vertex is decoded: the
            // old one shows every 3-clique until its last level.
            assert_eq!(n.mesh.vertex_count(), canonical.vertex_count());
            assert!(n.mesh.faces.len() <= o.mesh.faces.len());
        }
    }
    assert!(!new_levels.advance().unwrap());
}

/// A kept `came` golden stream of eight, checked to decode exactly to today's canonical mesh,
/// and today's `came` stream of the same mesh.
fn kept_came_stream_and_todays(file: &str) -> (Vec<u8>, Vec<u8>) {
    let old = std::fs::read(golden_dir().join(file)).unwrap();
    let codec = codecs::by_name("came").unwrap();
    let [(_, eight)] = read_all(["eight"]);
    let canonical = canonical(codec, &eight);
    let (decoded, _) = codecs::decode(&old, Stop::All).unwrap();
    canonical.check_lossless(&decoded.mesh).unwrap();
    let new = codec.encode(&canonical).unwrap().bytes;
    (old, new)
}

/// A camera 25 units from eight.off's centre.
fn far_camera_on_eight() -> meshcodec::codecs::came::refine::Camera {
    meshcodec::codecs::came::refine::Camera {
        eye: glam::DVec3::new(0.0, 0.0, 25.0),
        target: glam::DVec3::ZERO,
        up: glam::DVec3::Y,
        fov_degrees: 40.0,
        width: 640,
        height: 480,
    }
}

/// Each stream's front settles on [`far_camera_on_eight`] at a quarter pixel, sure of every
/// face, its invariants holding; returns each front's faces.
fn settle_far_from_eight(streams: &[&[u8]]) -> Vec<usize> {
    use meshcodec::codecs::came::refine::{Budget, View, ViewMesh};
    let view = View::new(&far_camera_on_eight(), 0.25).unwrap();
    let mut faces = Vec::new();
    for bytes in streams {
        let mut front = ViewMesh::from_stream(bytes).unwrap();
        let adapted = front.settle(&view, Budget::UNLIMITED, 64);
        assert!(adapted.settled && adapted.unsure == 0, "{adapted:?}");
        front.check_invariants().unwrap();
        assert!(front.face_count() > 0);
        faces.push(front.face_count());
    }
    faces
}

fn header_of(bytes: &[u8]) -> meshcodec::container::Header {
    meshcodec::container::StreamReader::open(bytes)
        .unwrap()
        .header()
        .clone()
}

/// `came` streams without normal cones (the fifth parameter byte 0, as `came` wrote before them)
/// still decode exactly, and refine view-dependently without culling:
/// `came-eight-before-cones.mc` is the golden stream of that build, kept (its header in today's
/// format).
#[test]
fn came_streams_without_normal_cones_still_decode_and_refine() {
    use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
    let (old, new) = kept_came_stream_and_todays("came-eight-before-cones.mc");
    let camera = Camera {
        eye: glam::DVec3::new(0.0, 0.0, 3.0),
        target: glam::DVec3::ZERO,
        up: glam::DVec3::Y,
        fov_degrees: 40.0,
        width: 640,
        height: 480,
    };
    let view = View::new(&camera, 0.5).unwrap();
    let faces = |bytes: &[u8], view: &View| {
        let mut front = ViewMesh::from_stream(bytes).unwrap();
        front.settle(view, Budget::UNLIMITED, 64);
        front.check_invariants().unwrap();
        (front.face_count(), front.has_normal_cones())
    };
    let (old_faces, old_cones) = faces(&old, &view);
    let (new_faces, new_cones) = faces(&new, &view);
    let (two_sided, _) = faces(&new, &view.clone().two_sided(true));
    assert!(!old_cones && new_cones);
    // Without cones every node is refined as if it faced the eye: as two-sided.
    assert_eq!(old_faces, two_sided);
    assert!(new_faces < two_sided, "{new_faces} of {two_sided}");
}

/// `came` streams without deviations (the sixth parameter byte 0, as `came` wrote before them)
/// still decode exactly, and refine by their spheres, the paper's test:
/// `came-eight-before-deviations.mc` is the golden stream of that build, kept (its header in
/// today's format). The deviations leave a view's front coarser.
#[test]
fn came_streams_without_deviations_still_decode_and_refine_by_their_spheres() {
    use meshcodec::codecs::came::refine::{Budget, View, ViewMesh};
    let (old, new) = kept_came_stream_and_todays("came-eight-before-deviations.mc");
    assert_eq!(header_of(&old).params[5], 0);
    assert!(header_of(&new).params[5] > 0);
    let camera = far_camera_on_eight();
    let view = View::new(&camera, 1.0)
        .unwrap()
        .two_sided(true)
        .keep_orientation(false);
    let faces = |bytes: &[u8]| {
        let mut front = ViewMesh::from_stream(bytes).unwrap();
        front.settle(&view, Budget::UNLIMITED, 64);
        front.check_invariants().unwrap();
        front.face_count()
    };
    // A quarter fewer at least (1,102 against 1,536 with syntax 2's deviations).
    let (old_faces, new_faces) = (faces(&old), faces(&new));
    assert!(
        new_faces * 4 < old_faces * 3,
        "{new_faces} against {old_faces}"
    );
}

/// `came` streams of syntax 3, before each triangle's normal was coded, still decode exactly
/// and refine with the orientation guard, which then reads what decides a face from the
/// meta-nodes under it: `came-eight-before-triangle-normals.mc` is the golden stream of that
/// build, kept. Today's stream says something of every triangle's normal; syntax 3's of none.
#[test]
fn came_streams_without_triangle_normals_still_decode_and_refine_with_the_guard() {
    use meshcodec::codecs::came::decode_tree;
    use meshcodec::codecs::came::refine::{Budget, View, ViewMesh};
    let (old, new) = kept_came_stream_and_todays("came-eight-before-triangle-normals.mc");
    assert_eq!(header_of(&old).syntax, 3);
    assert!(header_of(&new).syntax >= 4);
    let unknown = |bytes: &[u8]| {
        let (_, tree) = decode_tree(bytes).unwrap();
        let unknown = tree
            .triangles
            .iter()
            .filter(|t| !t.normal.is_known())
            .count();
        (unknown, tree.triangles.len())
    };
    let (old_unknown, old_triangles) = unknown(&old);
    assert_eq!(old_unknown, old_triangles);
    assert_eq!(unknown(&new).0, 0);
    let camera = far_camera_on_eight();
    let view = View::new(&camera, 1.0).unwrap().two_sided(true);
    for bytes in [&old, &new] {
        let mut front = ViewMesh::from_stream(bytes).unwrap();
        let adapted = front.settle(&view, Budget::UNLIMITED, 64);
        assert!(adapted.settled && adapted.unsure == 0, "{adapted:?}");
        front.check_invariants().unwrap();
    }
}

/// `came` streams of syntax 4, whose meta-nodes hold 8 levels each, still decode exactly and
/// refine: `came-eight-before-bands.mc` is the golden stream of that build, kept. Today's cuts
/// units by depth band (docs/FORMAT.md §8.1), a ninth parameter byte giving the regions' levels.
#[test]
fn came_streams_of_eight_level_meta_nodes_still_decode_and_refine() {
    let (old, new) = kept_came_stream_and_todays("came-eight-before-bands.mc");
    let (old_header, new_header) = (header_of(&old), header_of(&new));
    assert_eq!((old_header.syntax, old_header.params.len()), (4, 8));
    assert!(new_header.syntax >= 5 && new_header.params.len() == 9);
    settle_far_from_eight(&[&old, &new]);
}

/// `came` streams of syntax 6, whose hierarchy was built balanced as the paper's (b = 1), still
/// decode exactly and refine: `came-eight-before-quadric-order.mc` is the golden stream of that
/// build, kept. Today's is built by quadric error alone (docs/FORMAT.md §8, History), so its
/// tree is deeper and a far view's front, a simplified mesh, holds fewer faces.
#[test]
fn came_streams_of_balanced_hierarchies_still_decode_and_refine() {
    use meshcodec::codecs::came::decode_tree;
    let (old, new) = kept_came_stream_and_todays("came-eight-before-quadric-order.mc");
    assert_eq!(header_of(&old).syntax, 6);
    assert!(header_of(&new).syntax >= 7);
    let depth = |bytes: &[u8]| {
        let (_, tree) = decode_tree(bytes).unwrap();
        tree.nodes.iter().map(|n| n.id.len()).max().unwrap()
    };
    let (old_depth, new_depth) = (depth(&old), depth(&new));
    assert!(new_depth > old_depth, "{new_depth} against {old_depth}");
    let [old_faces, new_faces] = settle_far_from_eight(&[&old, &new])[..] else {
        unreachable!("one count a stream")
    };
    assert!(new_faces < old_faces, "{new_faces} against {old_faces}");
}

/// `came` streams of syntax 7, whose bands span regions of six levels, still decode exactly and
/// refine: `came-eight-before-regions-of-four.mc` is the golden stream of that build, kept.
/// Today's cuts the same tree into bands over regions of four (docs/FORMAT.md §8.1): the far
/// front on eight.off is the same from either (on larger meshes fronts may differ by a few
/// faces, a front's passes following the order its units came in).
#[test]
fn came_streams_of_six_level_regions_still_decode_and_refine() {
    let (old, new) = kept_came_stream_and_todays("came-eight-before-regions-of-four.mc");
    let (old_header, new_header) = (header_of(&old), header_of(&new));
    assert_eq!((old_header.syntax, old_header.params[8]), (7, 6));
    assert!(new_header.syntax >= 8);
    assert_eq!(new_header.params[8], 4);
    let [old_faces, new_faces] = settle_far_from_eight(&[&old, &new])[..] else {
        unreachable!("one count a stream")
    };
    assert_eq!(old_faces, new_faces);
}

/// `came` streams of syntax 8, whose corner paths run down to their leaves in the meta-node
/// that codes their triangle, still decode exactly and refine:
/// `came-eight-before-waiting-paths.mc` is the golden stream of that build, kept. Today's
/// codes a path only as far as its meta-node knows the hierarchy and carries it on in the
/// meta-node splitting the node it stops at (docs/FORMAT.md §8.2): the same tree, fronts and
/// faces, in a smaller stream.
#[test]
fn came_streams_of_paths_to_the_leaves_still_decode_and_refine() {
    let (old, new) = kept_came_stream_and_todays("came-eight-before-waiting-paths.mc");
    assert_eq!(header_of(&old).syntax, 8);
    assert!(header_of(&new).syntax >= 9);
    assert!(new.len() < old.len(), "{} against {}", new.len(), old.len());
    let [old_faces, new_faces] = settle_far_from_eight(&[&old, &new])[..] else {
        unreachable!("one count a stream")
    };
    assert_eq!(old_faces, new_faces);
}

/// `came` streams of syntax 5, whose deviation codes step by 2^(−1/2) below the parent's,
/// still decode exactly and refine: `came-eight-before-anchored-deviations.mc` is the golden
/// stream of that build, kept. Today's codes the nodes above depth 11 in quarter steps on a
/// grid anchored at the root's deviation (docs/FORMAT.md §8.2), so those bound tighter.
#[test]
fn came_streams_of_half_step_deviations_still_decode_and_refine() {
    use meshcodec::codecs::came::decode_tree;
    use meshcodec::hierarchy::came::deviation::FINE_DEVIATION_DEPTHS;
    let (old, new) = kept_came_stream_and_todays("came-eight-before-anchored-deviations.mc");
    assert_eq!(header_of(&old).syntax, 5);
    assert!(header_of(&new).syntax >= 6);
    // The deviations of the nodes above the fine depth, summed: the quarter steps hold them
    // closer to what was measured.
    let coarse_sum = |bytes: &[u8]| -> f64 {
        let (_, tree) = decode_tree(bytes).unwrap();
        for node in &tree.nodes[1..] {
            let parent = &tree.nodes[node.parent as usize];
            assert!(node.deviation <= parent.deviation, "{:?}", node.id);
        }
        tree.nodes
            .iter()
            .filter(|n| (n.id.len() as usize) < FINE_DEVIATION_DEPTHS)
            .map(|n| n.deviation as f64)
            .sum()
    };
    let (old_sum, new_sum) = (coarse_sum(&old), coarse_sum(&new));
    assert!(new_sum < old_sum, "{new_sum} against {old_sum}");
    settle_far_from_eight(&[&old, &new]);
}

#[test]
fn streams_of_another_format_version_are_refused_in_one_line() {
    let codec = codecs::by_name("raw").unwrap();
    let [(_, eight)] = read_all(["eight"]);
    let mut bytes = codec.encode(&canonical(codec, &eight)).unwrap().bytes;
    for version in [0, 1, 2, 3, 4, 5, 6, FORMAT_VERSION + 1, 255] {
        bytes[4] = version;
        match codecs::decode(&bytes, Stop::All) {
            Err(e @ Error::Unsupported(_)) => {
                let text = e.to_string();
                assert!(!text.contains('\n'), "{text}");
                assert!(text.contains(&format!("version {version}")), "{text}");
            }
            other => panic!("version {version}: {:?}", other.map(|(_, n)| n)),
        }
    }
}

/// Encodes `mesh` with its appearance by `codec` (inside the levels by `fit`, else in the
/// appearance unit), checks where the header says the appearance is, compares the stream with
/// the pinned stream `file` and decodes the pinned stream losslessly, appearance included.
fn appearance_golden(codec: &str, mesh: &str, fit: Option<codecs::AttributeFit>, file: &str) {
    let original = meshcodec::mesh::io::read_attributed(&resolve(mesh).unwrap()).unwrap();
    let bits = meshcodec::mesh::attribute_quantization::AttributeBits::default();
    appearance_golden_of(codec, &original, bits, fit, file);
}

/// [`appearance_golden`] of a mesh in memory, its appearance quantized by `bits`.
fn appearance_golden_of(
    codec: &str,
    original: &meshcodec::mesh::attributes::AttributedMesh,
    bits: meshcodec::mesh::attribute_quantization::AttributeBits,
    fit: Option<codecs::AttributeFit>,
    file: &str,
) {
    let codec = codecs::by_name(codec).unwrap();
    let (canonical, appearance) =
        codecs::canonical_attributed_for(original, &codec.default_options(), bits).unwrap();
    let bytes = codecs::encode_attributed_with(codec, &canonical, Some(&appearance), fit)
        .unwrap()
        .bytes;
    assert_eq!(bytes[4], FORMAT_VERSION);
    let header = meshcodec::container::StreamReader::open(&bytes)
        .unwrap()
        .header()
        .clone();
    assert_eq!(
        header.appearance.map(|a| a.in_levels),
        Some(fit.is_some()),
        "where the appearance is"
    );
    let golden = golden_dir().join(file);
    if updating() {
        std::fs::create_dir_all(golden.parent().unwrap()).unwrap();
        std::fs::write(&golden, &bytes).unwrap();
    }
    let pinned = std::fs::read(&golden).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (UPDATE_GOLDEN=1 cargo test --release --test golden)",
            golden.display()
        )
    });
    assert!(
        pinned == bytes,
        "{file} changed ({} bytes, pinned {}): a syntax change needs a new format version and UPDATE_GOLDEN=1",
        bytes.len(),
        pinned.len()
    );
    let (decoded, _) = codecs::decode(&pinned, Stop::All).unwrap();
    appearance
        .check_lossless(
            &canonical,
            &decoded.mesh,
            decoded.attributes.as_ref().unwrap(),
        )
        .unwrap();
}

#[test]
fn the_appearance_golden_stream_is_reproduced_and_decodes_exactly() {
    appearance_golden("emc", "spot", None, "emc-spot-appearance.mc");
}

#[test]
fn the_golden_stream_with_appearance_in_pm_splits_is_reproduced_and_decodes_exactly() {
    appearance_golden(
        "pm-reordered",
        "spot",
        Some(codecs::AttributeFit::Fit),
        "pm-reordered-spot-appearance-fit.mc",
    );
}

/// Normals in pm's splits, both ways (docs/FORMAT.md §6.3): predicted from the geometry of
/// their vertex's faces (flag 64) on vw-beetle.obj, a mesh pm cuts to a manifold; and derived
/// from the positions over their groups (flag 32) on spot with creased normals.
#[test]
fn the_golden_streams_with_normals_in_pm_splits_are_reproduced_and_decode_exactly() {
    use meshcodec::mesh::attribute_quantization::AttributeBits;
    let beetle = meshcodec::mesh::io::read_attributed(&resolve("vw-beetle").unwrap()).unwrap();
    appearance_golden_of(
        "pm-reordered",
        &beetle,
        AttributeBits::default(),
        Some(codecs::AttributeFit::Keep),
        "pm-reordered-vw-beetle-normals-keep.mc",
    );
    let derived = AttributeBits {
        derive_normals: true,
        ..AttributeBits::default()
    };
    appearance_golden_of(
        "pm-reordered",
        &common::spot_with_creased_normals(),
        derived,
        Some(codecs::AttributeFit::Keep),
        "pm-reordered-spot-creased-derived-normals-keep.mc",
    );
}

/// pm and pm-reordered of bunny-res4 (Stanford's crude decimation: fins, bow-ties, repeated
/// faces), which they cut to an oriented manifold (docs/FORMAT.md §6.2): the streams are pinned
/// and decode exactly to the canonical mesh.
#[test]
fn the_golden_streams_of_a_mesh_cut_to_a_manifold_are_reproduced_and_decode_exactly() {
    let [(mesh, original)] = read_all(["bunny-res4"]);
    for name in ["pm", "pm-reordered"] {
        let codec = codecs::by_name(name).unwrap();
        let canonical = canonical(codec, &original);
        let bytes = codec.encode(&canonical).unwrap().bytes;
        assert!(
            bytes.len() > 8 && bytes[7] > 1,
            "{name}: the stream says nothing of a cut"
        );
        let path = golden_dir().join(format!("{name}-{mesh}.mc"));
        if updating() {
            std::fs::write(&path, &bytes).unwrap();
        }
        let pinned = std::fs::read(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e} (UPDATE_GOLDEN=1 cargo test --release --test golden)",
                path.display()
            )
        });
        assert!(pinned == bytes, "{name} on {mesh}: the stream changed");
        let (decoded, _) = codecs::decode(&pinned, Stop::All).unwrap();
        canonical.check_lossless(&decoded.mesh).unwrap();
    }
}

/// (codec, mesh, bits per vertex) rows of the pin file.
fn pinned_rates() -> Vec<(String, String, f64)> {
    let text = std::fs::read_to_string(rates_file()).unwrap_or_default();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let cells: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(cells.len(), 3, "bad rate pin line: {l}");
            (
                cells[0].to_string(),
                cells[1].to_string(),
                cells[2].parse().expect("bits per vertex"),
            )
        })
        .collect()
}

#[test]
fn no_codec_codes_a_pinned_mesh_in_more_bits_than_its_pin() {
    let originals = read_all(RATE_MESHES);
    let mut measured = Vec::new();
    for codec in codecs::registry() {
        for (mesh, original) in &originals {
            let canonical = canonical(codec, original);
            let bytes = codec.encode(&canonical).unwrap().bytes.len();
            let bpv = bytes as f64 * 8.0 / canonical.vertex_count() as f64;
            measured.push((codec.name().to_string(), mesh.to_string(), bpv));
        }
    }
    if updating() {
        let mut text = String::from(
            "# Bits per vertex of each codec's whole stream at its default quantization.\n\
             # A codec that needs more on any of these meshes fails tests/golden.rs; regenerate\n\
             # on purpose with UPDATE_GOLDEN=1 cargo test --release --test golden.\n",
        );
        for (codec, mesh, bpv) in &measured {
            let _ = writeln!(text, "{codec:<14} {mesh:<10} {bpv:.4}");
        }
        std::fs::write(rates_file(), text).unwrap();
    }
    let pins = pinned_rates();
    let mut failures = Vec::new();
    for (codec, mesh, bpv) in &measured {
        match pins.iter().find(|(c, m, _)| c == codec && m == mesh) {
            // Pins are written to 4 decimals; allow for that rounding only.
            Some((_, _, pin)) if *bpv > pin + 0.00005 => failures.push(format!(
                "{codec} on {mesh}: {bpv:.4} bits/vertex, pinned at {pin:.4} (+{:.2}%)",
                (bpv / pin - 1.0) * 100.0
            )),
            Some(_) => {}
            None => failures.push(format!(
                "{codec} on {mesh}: no pin in {} (make it with UPDATE_GOLDEN=1)",
                rates_file().display()
            )),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
