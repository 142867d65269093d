//! Streams with an appearance unit on arbitrary bytes after the magic and version: the first
//! byte picks the codec, the second its syntax, the rest is its header with the appearance
//! block, the index with the appearance unit, the levels and the unit.
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_with_appearance(body));
