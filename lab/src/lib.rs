//! # meshcodec-lab
//!
//! The lab over the codec core [`meshcodec`]: what measures the codecs on real meshes with
//! honest numbers, regenerates the papers' tables beside ours, and the `experiment` and
//! `meshcodec` programs.
//!
//! - [`harness`] runs a codec on a mesh and measures every level (bits per vertex and triangle,
//!   Hausdorff and RMS error, times); [`results`] writes and reads what it measured; [`sweep`]
//!   splits an experiment set into shards and merges them.
//! - [`plot`] draws rate–distortion curves; [`render`] draws meshes.
//! - [`tables`] regenerates paper-tables/ from results/: what the tables share, `emc` against the
//!   other coders, and appearance.
//! - One folder per paper for its experiments and tables: [`emc`] (Magnor & Girod), [`pm`]
//!   (Hoppe), [`came`] (Grabner, and view-dependent refinement).
//! - [`cli`] and [`progress`]: what the programs share (mesh lookup, errors, progress bars).

// Unsafe code is allowed only where it is needed, each block with its SAFETY reason: the
// allocator trim of `emc::scale`.
#![deny(unsafe_code)]
#![warn(clippy::undocumented_unsafe_blocks)]

pub mod came;
pub mod cli;
pub mod data;
pub mod emc;
pub mod harness;
pub mod plot;
pub mod pm;
pub mod progress;
pub mod render;
pub mod results;
pub mod sweep;
pub mod tables;
