//! Streams whose vertex splits carry the appearance (appearance flag 16, `pm --attributes`) on
//! arbitrary bytes after the magic and version: the codec id and syntax, the header with its
//! appearance block, the index and the levels with their wedge fields.
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_with_appearance(body));
