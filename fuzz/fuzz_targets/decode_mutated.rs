//! Every decoder on valid streams with bits flipped, bytes set, cut, inserted, removed, and
//! ranges spliced in from other codecs' streams.
#![no_main]
libfuzzer_sys::fuzz_target!(|input: meshcodec_fuzz::MutatedStream| {
    meshcodec_fuzz::decode_mutated(&input)
});
