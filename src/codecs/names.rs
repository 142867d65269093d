//! The one place that names the codecs of this build, the ids their streams carry and the
//! syntax each writes (docs/FORMAT.md §1). An id, once written into streams, is never given to
//! another codec; a change to the bytes a codec writes gives it a new syntax number.

/// A codec's name on the command line and in results/, its id in stream headers, and the
/// syntax of its parameters and units that this build writes and reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Naming {
    /// Name on the command line and in results/.
    pub name: &'static str,
    /// Codec id in the stream header.
    pub id: u8,
    /// The syntax byte of the stream header that this build writes (docs/FORMAT.md §1, and
    /// each codec's section).
    pub syntax: u8,
    /// The oldest syntax this build still reads (every one from it to `syntax`).
    pub reads_from: u8,
}

/// The uncompressed baseline.
pub const RAW: Naming = Naming {
    name: "raw",
    id: 0,
    syntax: 1,
    reads_from: 1,
};
/// Magnor & Girod's embedded mesh coding as published.
pub const EMC_PAPER: Naming = Naming {
    name: "emc-paper",
    id: 1,
    syntax: 1,
    reads_from: 1,
};
/// Hoppe's progressive meshes in collapse order.
pub const PM: Naming = Naming {
    name: "pm",
    id: 2,
    syntax: 1,
    reads_from: 1,
};
/// Hoppe's progressive meshes, reordered.
pub const PM_REORDERED: Naming = Naming {
    name: "pm-reordered",
    id: 3,
    syntax: 1,
    reads_from: 1,
};
/// Embedded mesh coding, context-modelled.
pub const EMC: Naming = Naming {
    name: "emc",
    id: 4,
    syntax: 1,
    reads_from: 1,
};
/// Embedded mesh coding, context-modelled, every position coded ahead of the octree's splits.
pub const EMC_AHEAD: Naming = Naming {
    name: "emc-ahead",
    id: 7,
    syntax: 1,
    reads_from: 1,
};

/// Compressed adaptive multiresolution encoding, context-modelled and lossless.
pub const CAME: Naming = Naming {
    name: "came",
    id: 6,
    syntax: 9,
    reads_from: 1,
};

/// Compressed adaptive multiresolution encoding as published (lossy).
pub const CAME_PAPER: Naming = Naming {
    name: "came-paper",
    id: 5,
    syntax: 1,
    reads_from: 1,
};

/// Every codec of this build.
pub const ALL: [Naming; 8] = [
    RAW,
    EMC_PAPER,
    PM,
    PM_REORDERED,
    EMC,
    CAME_PAPER,
    CAME,
    EMC_AHEAD,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_ids_are_unique() {
        for (i, a) in ALL.iter().enumerate() {
            for b in &ALL[i + 1..] {
                assert_ne!(a.name, b.name);
                assert_ne!(a.id, b.id, "{} and {}", a.name, b.name);
            }
        }
    }
}
