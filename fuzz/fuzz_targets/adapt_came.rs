//! View-dependent refinement of arbitrary `came` streams: up to 16 bytes pick views, the rest
//! follows a stream's first seven bytes; every invariant is checked after each adaptation.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| meshcodec_fuzz::adapt_came(data));
