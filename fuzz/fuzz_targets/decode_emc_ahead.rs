//! The `emc-ahead` decoder on arbitrary bytes after a `emc-ahead` stream's first seven bytes.
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_as("emc-ahead", body));
