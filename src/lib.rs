//! # meshcodec
//!
//! Progressive ("embedded") triangle-mesh compression for research: codecs from the classic
//! papers behind one [`codecs::Codec`] trait, and a harness that measures them on real meshes
//! with honest numbers — bits per vertex and triangle, Hausdorff and RMS error per level.
//!
//! | codec | what it is | when to use it |
//! |---|---|---|
//! | `raw` | the uncompressed indexed face set, 3·Q bits a vertex | the baseline row of every table |
//! | `emc` | Magnor & Girod's embedded mesh coding, context-modelled: octree splits of positions and connectivity together, any topology, lossless | the smallest progressive stream; levels as the bytes arrive |
//! | `emc-ahead` | `emc` with every position coded two levels ahead of the octree's splits | streams read in part: better intermediate levels for a larger lossless stream |
//! | `emc-paper` | the same as published (Table 1) | reproducing the paper |
//! | `pm`, `pm-reordered` | Hoppe's progressive meshes: QEM collapses, coded vertex splits, wedges in the splits | intermediate levels of the best quality for their bits |
//! | `came` | Grabner's compressed vertex hierarchy, context-modelled and lossless, meta-nodes read on demand | view-dependent refinement ([`codecs::came::refine`]) |
//! | `came-paper` | the same as published (lossy) | reproducing the paper |
//!
//! Layers (see ARCHITECTURE.md): [`mesh`] knows no bits, [`coding`] knows no meshes, [`codecs`]
//! joins them through the stream [`container`]. This crate is the codec core; the `metrics`
//! feature adds distances between meshes (sampling, point-to-surface). What measures the codecs
//! (the harness, the papers' experiments and tables, plots, the `experiment` and `meshcodec`
//! programs) is the lab, the workspace crate `meshcodec-lab` in lab/. The contract the codecs
//! keep is docs/CONTRACT.md; the bytes they write are docs/FORMAT.md.
//!
//! ```
//! use meshcodec::codecs::{self, Stop};
//! use meshcodec::mesh::generate;
//!
//! let mesh = generate::torus(1.0, 0.4, 24, 12);
//! let codec = codecs::by_name("raw")?;
//! let canonical = codecs::canonical_for(&mesh, &codec.default_options())?;
//! let encoded = codec.encode(&canonical)?;
//! let (decoded, _levels) = codecs::decode(&encoded.bytes, Stop::All)?;
//! assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
//! # Ok::<(), meshcodec::Error>(())
//! ```

// Unsafe code is allowed only where it is needed, each block with its SAFETY reason: the raw
// views of `emc`'s slab lanes (`codecs::emc::clusters`, `codecs::emc::modelled::walk`) and the
// prefetch hint.
#![deny(unsafe_code)]
#![warn(clippy::undocumented_unsafe_blocks)]

pub mod codecs;
pub mod coding;
pub mod container;
pub mod error;
pub mod hierarchy;
pub mod limits;
pub mod mesh;
pub mod packing;
mod prefetch;

#[cfg(feature = "metrics")]
pub mod metrics;

pub use error::{Error, Result};

/// The README's Rust quick start, compiled and run by `cargo test --doc` as written there.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeQuickStart;
