//! The `pm-reordered` decoder on arbitrary bytes after a `pm-reordered` stream's first seven bytes.
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_as("pm-reordered", body));
