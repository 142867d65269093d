//! `came-paper` streams: arbitrary bytes after the first seven (magic, version, codec id, syntax).
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_as("came-paper", body));
