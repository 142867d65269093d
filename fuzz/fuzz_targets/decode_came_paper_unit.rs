//! One `came-paper` meta-node decoded alone after its ancestors, on arbitrary bytes after a
//! `came-paper` stream's first seven bytes.
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_unit_alone("came-paper", body));
