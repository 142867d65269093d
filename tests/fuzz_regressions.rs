//! Replays the fuzz targets' inputs through the same functions the targets call
//! (fuzz/src/lib.rs): every crash the fuzzers found, as a named test, then every seed and saved
//! regression input. See FUZZING.md.

#[path = "../fuzz/src/lib.rs"]
#[allow(dead_code)]
mod exercise;

use arbitrary::{Arbitrary, Unstructured};
use std::path::{Path, PathBuf};

/// Runs one input of fuzz target `target` as the target would.
fn replay(target: &str, bytes: &[u8]) {
    match target {
        "decode_mutated" => {
            if let Ok(input) =
                exercise::MutatedStream::arbitrary_take_rest(Unstructured::new(bytes))
            {
                exercise::decode_mutated(&input);
            }
        }
        "adapt_came" => exercise::adapt_came(bytes),
        "pack_gltf" => exercise::pack_gltf(bytes),
        "decode_appearance" => exercise::decode_with_appearance(bytes),
        "decode_pm_wedges" | "decode_level_parts" => exercise::decode_with_appearance(bytes),
        "roundtrip" => {
            if let Ok(input) =
                exercise::GeneratedMesh::arbitrary_take_rest(Unstructured::new(bytes))
            {
                exercise::round_trip(&input);
            }
        }
        _ => {
            let codec = target.strip_prefix("decode_").map(|c| c.replace('_', "-"));
            if let Some(came) = codec.as_deref().and_then(|c| c.strip_suffix("-unit")) {
                exercise::decode_unit_alone(came, bytes);
            } else if let Some(codec) = target.strip_prefix("decode_") {
                exercise::decode_as(&codec.replace('_', "-"), bytes);
            } else if let Some(format) = target.strip_prefix("read_") {
                exercise::read_as(format, bytes);
            } else {
                panic!("no fuzz target called {target}");
            }
        }
    }
}

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz")
}

fn replay_file(target: &str, name: &str) {
    let path = fuzz_dir().join("regressions").join(target).join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    replay(target, &bytes);
}

/// One test per crash found, named after what was wrong.
macro_rules! regressions {
    ($($test:ident: $target:literal / $file:literal;)*) => {
        $(
            #[test]
            fn $test() {
                replay_file($target, $file);
            }
        )*
    };
}

regressions! {
    emc_header_declaring_no_vertices_is_refused: "decode_emc" / "header-declares-no-vertices";
    pm_base_mesh_with_a_non_manifold_vertex_is_refused: "decode_pm" / "non-manifold-base-mesh";
    pm_last_level_welding_a_face_into_a_degenerate_one_is_refused: "decode_pm" / "last-level-welds-a-face-into-a-degenerate-one";
    a_mutated_cut_pm_stream_welding_a_face_is_refused: "decode_mutated" / "cut-pm-stream-whose-last-level-welds-a-face";
    came_contraction_of_a_tiny_lattice_mesh_ends: "roundtrip" / "came-contraction-slow-on-a-tiny-lattice";
    obj_texture_index_past_the_list_is_refused: "read_obj" / "texture-index-overflows-in-tobj";
    ply_element_with_records_but_no_properties_is_refused: "read_ply" / "element-without-properties";
    gltf_primitive_naming_an_accessor_past_the_list_is_refused: "read_gltf" / "position-accessor-past-the-list";
    glb_header_shorter_than_itself_is_refused: "read_gltf" / "glb-length-below-its-header";
    gltf_accessors_lost_to_a_misspelled_key_are_refused: "read_gltf" / "accessors-key-misspelled-in-a-document-with-stray-bytes";
    gltf_uvs_of_an_unsigned_int_type_are_refused: "read_gltf" / "texcoords-of-integer-component-type";
    gltf_indices_of_a_float_type_are_refused: "read_gltf" / "indices-of-float-component-type";
    positions_beyond_f32_are_refused_by_the_gltf_writer: "read_ply" / "positions-beyond-f32-written-as-gltf";
    colours_beyond_f32_are_refused_by_the_gltf_writer: "read_obj" / "colours-beyond-f32-written-as-gltf";
    obj_writer_colours_every_vertex_when_some_are_in_no_face: "read_ply" / "colours-with-vertices-no-face-uses-written-as-obj";
    came_guard_skips_a_corner_not_above_its_leaf: "adapt_came" / "guard-corner-not-above-its-leaf";
    came_node_decoded_beyond_the_grid_is_refused: "decode_came" / "node-position-beyond-the-grid";
    level_unit_in_while_its_appearance_part_is_cut_is_present: "decode_level_parts" / "level-unit-in-while-its-part-is-cut";
    a_primitive_packed_already_is_refused_though_extensions_used_misses_it: "pack_gltf" / "extension-on-a-primitive-not-in-extensions-used";
}

#[test]
fn every_seed_and_regression_input_replays_cleanly() {
    let mut replayed = 0;
    for kind in ["seeds", "regressions"] {
        let Ok(targets) = std::fs::read_dir(fuzz_dir().join(kind)) else {
            continue;
        };
        for target in targets {
            let target = target.unwrap().path();
            let name = target.file_name().unwrap().to_string_lossy().into_owned();
            for input in std::fs::read_dir(&target).unwrap() {
                let bytes = std::fs::read(input.unwrap().path()).unwrap();
                replay(&name, &bytes);
                replayed += 1;
            }
        }
    }
    assert!(replayed >= 20, "only {replayed} inputs found under fuzz/");
}

/// The committed corpus (fuzz/corpus.tar.xz, unpacked to a scratch folder) through the same
/// functions, each input within 4 s: what `bash fuzz/replay.sh` checks under libFuzzer with its
/// memory limits too, here without building the fuzz targets.
#[test]
fn the_committed_corpus_replays_cleanly_and_quickly() {
    let archive = fuzz_dir().join("corpus.tar.xz");
    let scratch = tempfile::tempdir().unwrap();
    let unpacked = std::process::Command::new("tar")
        .arg("-C")
        .arg(scratch.path())
        .arg("-xJf")
        .arg(&archive)
        .status()
        .expect("tar runs");
    assert!(
        unpacked.success(),
        "tar could not unpack {}",
        archive.display()
    );
    let mut replayed = 0;
    let mut slowest = (0.0, String::new());
    for target in std::fs::read_dir(scratch.path().join("corpus")).unwrap() {
        let target = target.unwrap().path();
        let name = target.file_name().unwrap().to_string_lossy().into_owned();
        for input in std::fs::read_dir(&target).unwrap() {
            let path = input.unwrap().path();
            let bytes = std::fs::read(&path).unwrap();
            let started = std::time::Instant::now();
            replay(&name, &bytes);
            let took = started.elapsed().as_secs_f64();
            if took > slowest.0 {
                slowest = (took, format!("{name}/{}", path.display()));
            }
            replayed += 1;
        }
    }
    assert!(replayed >= 5000, "only {replayed} corpus inputs");
    assert!(slowest.0 <= 4.0, "{} took {:.1} s", slowest.1, slowest.0);
}
