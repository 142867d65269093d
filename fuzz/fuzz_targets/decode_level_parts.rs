//! Streams whose levels each carry an appearance part (docs/FORMAT.md §10) on arbitrary bytes
//! after the magic and version: the same entry as `decode_appearance`, apart by its seeds
//! (`emc` and `emc-ahead` streams of textured and coloured meshes).
#![no_main]
libfuzzer_sys::fuzz_target!(|body: &[u8]| meshcodec_fuzz::decode_with_appearance(body));
