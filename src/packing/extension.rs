//! The `MESHCODEC_progressive` glTF extension on a mesh primitive (docs/GLTF.md): where the
//! primitive's progressive stream lies, which codec wrote it, each level's end and size, and
//! which glTF attribute each part of the stream fills. Written and read with serde, as the
//! `gltf-json` crate writes every other object of the document.

use serde::{Deserialize, Serialize};

/// The extension's name, in `extensionsUsed` and on each primitive.
pub const NAME: &str = "MESHCODEC_progressive";

/// The extension object on one primitive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct Progressive {
    /// The buffer view holding the whole stream (in the GLB's binary chunk, or with
    /// `--external` in a buffer of its own fetched by URI).
    pub buffer_view: u32,
    /// The codec that wrote the stream (`meshcodec info` names it too; the stream's header
    /// says it again).
    pub codec: String,
    /// The stream's format version (docs/FORMAT.md §1).
    pub format_version: u8,
    /// Each level: where it ends in the stream and what it decodes to. A loader that wants
    /// "enough" fetches the stream's first `byteLength` bytes of the level it wants.
    pub levels: Vec<Level>,
    /// The level the primitive's own accessors hold (1-based; 0 with `--no-fallback`, when
    /// they hold nothing).
    pub fallback_level: u32,
    /// The glTF attribute each part of a decoded level fills: `POSITION` from the positions,
    /// `NORMAL`, `TEXCOORD_0`, `COLOR_0` from the wedges' normals, uvs and colours.
    pub attributes: Vec<String>,
}

/// One level of a primitive's stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct Level {
    /// Bytes of the stream, from its first, that decoding this level needs.
    pub byte_length: u64,
    /// Triangles of the level.
    pub faces: u64,
    /// Vertices of the level (positions; a glTF loader splits them per wedge).
    pub vertices: u64,
}
