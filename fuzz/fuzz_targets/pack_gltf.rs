//! `meshcodec pack` / `unpack` on arbitrary bytes read as a glTF scene (fuzz/src/lib.rs).
#![no_main]
libfuzzer_sys::fuzz_target!(|bytes: &[u8]| meshcodec_fuzz::pack_gltf(bytes));
