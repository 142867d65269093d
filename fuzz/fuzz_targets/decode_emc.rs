//! The `emc` decoder on arbitrary bytes after a `emc` stream's first seven bytes.
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_as("emc", body));
