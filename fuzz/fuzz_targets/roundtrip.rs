//! Encode → decode with every codec on generated meshes (degenerate, duplicated, non-manifold
//! faces included): the full decode must be lossless.
#![no_main]
libfuzzer_sys::fuzz_target!(|input: meshcodec_fuzz::GeneratedMesh| {
    meshcodec_fuzz::round_trip(&input)
});
