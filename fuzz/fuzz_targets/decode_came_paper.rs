//! `came-paper` streams: arbitrary bytes after the first six (magic, version, codec id).
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_as("came-paper", body));
