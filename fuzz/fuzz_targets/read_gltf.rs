//! The glTF reader (.gltf JSON or .glb, embedded buffers) on arbitrary bytes.
#![no_main]
libfuzzer_sys::fuzz_target!(|bytes: &[u8]| meshcodec_fuzz::read_as("glb", bytes));
