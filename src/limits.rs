//! Every bound the decoders and readers enforce, in one place. A stream or file past one of these
//! is refused with [`crate::Error::Limit`] before anything is allocated for it.

/// Most vertices a stream may declare (2^28: 6 GiB of double positions).
pub const MAX_VERTICES: u64 = 1 << 28;
/// Most triangles a stream may declare.
pub const MAX_TRIANGLES: u64 = 1 << 29;
/// Most levels a stream may declare.
pub const MAX_LEVELS: u64 = 1 << 16;
/// Most bytes of codec parameters in a header.
pub const MAX_PARAM_BYTES: u64 = 1 << 12;
