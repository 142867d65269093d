//! View-dependent selective refinement over a CAME hierarchy (Hoppe, "View-dependent
//! refinement of progressive meshes", SIGGRAPH 1997, with Grabner's node-to-node dependencies
//! and error spheres instead of face neighbourhoods and deviation cones).
//!
//! Glossary:
//! - front: the active nodes, a cut of the hierarchy (every leaf has exactly one active node on
//!   its path from the root); the nodes above it are *split*, those below it *below*.
//! - vsplit(v_s): v_s leaves the front, v_t and v_u join it, the triangles born at v_s appear and
//!   the triangles with a corner at v_s move that corner to v_t or v_u (one path bit appended).
//!   Legal when every node v_s depends on is split (Hoppe's fn0..fn3 present); otherwise those
//!   are split first ("forced split").
//! - ecol(v_s): the inverse (one path bit dropped); legal when v_t and v_u are active and no
//!   split node depends on v_s.
//! - r_v: the error sphere's radius at v (every vertex of v's subtree lies within r_v of v);
//!   the spheres cull and place the test.
//! - e_v: the deviation at v (`came` streams, `hierarchy::came::deviation`): how far the
//!   surface under v lies from the simplified surface around v, measured at encoding, monotone
//!   up the hierarchy; where a stream has none (`came-paper`, and `came` streams written
//!   before deviations) e_v = r_v, the paper's test.
//! - τ: the screen-space tolerance in pixels; φ: the vertical field of view; H: the viewport's
//!   height in pixels; κ = 2·τ·tan(φ/2) / H. A node is refined while its sphere meets the view
//!   frustum and its deviation could span τ pixels or more on the screen somewhere in the
//!   sphere: e_v·√(1 + t²) ≥ κ·z, z the sphere's least depth and t its largest tangent off the
//!   axis ([`View::wants_split`]) — Hoppe's δ_v ≥ κ·|v − e|, made an upper bound.
//!
//! - n̂_v, α_v: the node's normal cone (axis, half-angle), holding the normal of every face with
//!   a corner under v; `came` streams code one per inner node (docs/FORMAT.md §8.2, about 2
//!   bits a triangle). Back-face culling: a node is not refined while every point of its sphere
//!   sees every normal of its cone from behind ([`View::faces_away`]), Hoppe's test made to
//!   hold over the sphere. The surface is then drawn one-sided; [`View::two_sided`] turns it
//!   off. `came-paper` streams and `came` streams of cone bits 0 have none: every node
//!   is refined as if it faced the eye.
//! - counterpart: the full mesh's triangle an adapted face stands for (each corner at its
//!   leaf); a fold-over is a face turned 90° or more from its counterpart. The front keeps
//!   every face in view certain not to be one (`front`'s module docs: the orientation guard;
//!   [`View::keep_orientation`] turns it off).

mod front;
mod loader;
mod view;

pub use front::{Adapted, Budget, Fetched, Pick, PresentTriangle, ViewMesh};
pub use loader::{
    deviation_margin, head_length, ByteSource, Fetch, Reads, SeekSource, DEVIATION_MARGIN,
};
pub use view::{Camera, View};
