//! CAME's node identifiers (Grabner §3.1, §3.4): a node is named by its bit path from the root,
//! 0 for the left child v_t and 1 for the right child v_u, packed in one u64 as the paper's
//! implementation does — 6 bits `up`, 6 bits length, 52 bits of path.
//!
//! An absolute identifier has `up` = 0. A relative identifier names a node from another one: go
//! `up` levels to the junction, then follow `len` bits down. A triangle's corner moves with the
//! front by one bit: [`NodeId::ancestor`] of its leaf path at the front's length.

use std::fmt;

/// Longest path a packed identifier holds, so the deepest hierarchy this crate builds.
pub const MAX_DEPTH: u8 = 52;

const PATH_BITS: u32 = 52;
const LEN_SHIFT: u32 = 52;
const UP_SHIFT: u32 = 58;
const PATH_MASK: u64 = (1 << PATH_BITS) - 1;

/// A bit path through the vertex hierarchy, possibly relative (`up` > 0).
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct NodeId(u64);

impl NodeId {
    /// The root: the empty path.
    pub const ROOT: NodeId = NodeId(0);

    /// An identifier from its parts; `None` if a part does not fit (`up`, `len` ≤ 52, `path` <
    /// 2^len).
    pub fn new(up: u8, len: u8, path: u64) -> Option<NodeId> {
        if up > MAX_DEPTH || len > MAX_DEPTH || (len < 64 && path >> len != 0) {
            return None;
        }
        Some(NodeId(
            (up as u64) << UP_SHIFT | (len as u64) << LEN_SHIFT | path,
        ))
    }

    /// The packed form.
    pub fn packed(self) -> u64 {
        self.0
    }

    /// Levels to go up before following the path (0 for an absolute identifier).
    pub fn up(self) -> u8 {
        (self.0 >> UP_SHIFT) as u8
    }

    /// Bits in the path.
    pub fn len(self) -> u8 {
        (self.0 >> LEN_SHIFT & 63) as u8
    }

    /// Whether the path is empty.
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }

    /// The path, its first bit the most significant of `len` bits.
    pub fn path(self) -> u64 {
        self.0 & PATH_MASK
    }

    /// The child on side `bit` (0 = v_t, 1 = v_u); `None` past [`MAX_DEPTH`].
    pub fn child(self, bit: bool) -> Option<NodeId> {
        let len = self.len();
        if len >= MAX_DEPTH {
            return None;
        }
        NodeId::new(self.up(), len + 1, self.path() << 1 | bit as u64)
    }

    /// The parent; `None` for the empty path.
    pub fn parent(self) -> Option<NodeId> {
        let len = self.len().checked_sub(1)?;
        NodeId::new(self.up(), len, self.path() >> 1)
    }

    /// Bit `i` of the path, counted from its start (`i` < len).
    pub fn bit(self, i: u8) -> bool {
        debug_assert!(i < self.len());
        self.path() >> (self.len() - 1 - i) & 1 == 1
    }

    /// The first `len` bits of the path (the whole path if it is shorter).
    pub fn ancestor(self, len: u8) -> NodeId {
        let own = self.len();
        if len >= own {
            return self;
        }
        NodeId(
            (self.up() as u64) << UP_SHIFT | (len as u64) << LEN_SHIFT | self.path() >> (own - len),
        )
    }

    /// Whether `self` is `other` or one of its ancestors (its path a prefix of `other`'s).
    pub fn is_ancestor_of(self, other: NodeId) -> bool {
        self.len() <= other.len() && other.ancestor(self.len()) == self
    }

    /// Length of the longest common prefix of two paths.
    pub fn common_len(self, other: NodeId) -> u8 {
        let n = self.len().min(other.len());
        let (a, b) = (self.ancestor(n).path(), other.ancestor(n).path());
        let differing = 64 - (a ^ b).leading_zeros() as u8;
        n - differing
    }

    /// `self` (absolute) as seen from `from` (absolute): up to their junction, then down.
    pub fn relative_to(self, from: NodeId) -> NodeId {
        let common = self.common_len(from);
        let down = self.len() - common;
        NodeId::new(
            from.len() - common,
            down,
            self.path() & ((1u64 << down) - 1),
        )
        .expect("parts of valid identifiers fit")
    }

    /// The absolute node a relative identifier names from `from`; `None` if it goes above the
    /// root or past [`MAX_DEPTH`].
    pub fn resolve(self, from: NodeId) -> Option<NodeId> {
        let junction = from.len().checked_sub(self.up())?;
        let len = junction.checked_add(self.len())?;
        if len > MAX_DEPTH {
            return None;
        }
        let base = from.ancestor(junction).path();
        NodeId::new(0, len, base << self.len() | self.path())
    }
}

impl fmt::Debug for NodeId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "NodeId(")?;
        if self.up() > 0 {
            write!(f, "up {} ", self.up())?;
        }
        write!(f, "\"")?;
        for i in 0..self.len() {
            write!(f, "{}", self.bit(i) as u8)?;
        }
        write!(f, "\")")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id(bits: &str) -> NodeId {
        bits.chars()
            .fold(NodeId::ROOT, |n, c| n.child(c == '1').unwrap())
    }

    /// The example of the paper's Figure 2: three corners and their paths relative to the split.
    #[test]
    fn relative_identifiers_of_figure_2() {
        let (v1, v2, v3) = (id("111010001001"), id("111010001111"), id("111010011111"));
        let vs = id("111010001");
        let n1 = v1.relative_to(vs);
        assert_eq!((n1.up(), n1.len(), n1.path()), (0, 3, 0b001));
        assert_eq!(v2.relative_to(vs).path(), 0b111);
        let n3 = v3.relative_to(vs);
        assert_eq!((n3.up(), n3.len(), n3.path()), (2, 5, 0b11111));
        for v in [v1, v2, v3] {
            assert_eq!(v.relative_to(vs).resolve(vs), Some(v));
        }
        assert_eq!(v1.common_len(v3), 7);
        assert!(vs.is_ancestor_of(v1) && !vs.is_ancestor_of(v3));
    }

    #[test]
    fn a_corner_follows_the_front_by_one_bit() {
        let leaf = id("0110");
        assert_eq!(leaf.ancestor(2), id("01"));
        assert_eq!(leaf.ancestor(2).child(leaf.bit(2)).unwrap(), id("011"));
        assert_eq!(id("011").parent(), Some(id("01")));
        assert_eq!(NodeId::ROOT.parent(), None);
        assert_eq!(leaf.ancestor(9), leaf);
    }

    #[test]
    fn paths_stop_at_52_bits_and_bad_relatives_do_not_resolve() {
        let mut n = NodeId::ROOT;
        for i in 0..MAX_DEPTH {
            n = n.child(i % 3 == 0).unwrap();
        }
        assert_eq!(n.len(), 52);
        assert_eq!(n.child(true), None);
        assert_eq!(NodeId::new(0, 3, 8), None);
        let up_too_far = NodeId::new(5, 1, 1).unwrap();
        assert_eq!(up_too_far.resolve(id("01")), None);
        assert_eq!(NodeId::new(1, 52, 0).unwrap().resolve(n), None);
    }
}
