//! Codec statistics: counts and bit totals per syntax element that an encoder (or a codec's
//! measurement) records, stored in results/ under `codec_stats` and read by the paper tables.
//!
//! The statistics a table reads are [`Stat`]s, so renaming one fails to compile, and reading one
//! a codec did not record is an error rather than a zero (`tests::every_stat_is_recorded_by_its_codecs`
//! encodes with each codec and checks that every `Stat` it is said to record is there). Other
//! statistics (per-field bits of the context-modelled coders, split-distance histograms) are
//! recorded by name.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A field of Hoppe's vertex-split record, as PM codes it and its tables report it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum PmField {
    /// The base mesh's raw bits.
    Base,
    /// Split counts per level.
    Count,
    /// The face next to the split (index, or Δ from the previous split).
    Flclw,
    /// vs's corner in flclw.
    VsIndex,
    /// Rotations from vl to vr.
    VlrRot,
    /// Position prediction choice.
    Ii,
    /// Large position delta.
    VadL,
    /// Small position delta.
    VadS,
    /// Which faces of a mesh cut to a manifold were flipped (`pm::repair`).
    Repair,
}

impl PmField {
    /// The field's name in the coder's per-field bit count.
    pub fn name(self) -> &'static str {
        match self {
            PmField::Base => "base",
            PmField::Count => "count",
            PmField::Flclw => "flclw",
            PmField::VsIndex => "vs_index",
            PmField::VlrRot => "vlr_rot",
            PmField::Ii => "ii",
            PmField::VadL => "vad_l",
            PmField::VadS => "vad_s",
            PmField::Repair => "repair",
        }
    }
}

/// A wedge field of a PM vertex split (Hoppe 1998 Table 3's corners, fl/fr matid and wedge
/// deltas), as `pm` codes appearance inside its splits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WedgeField {
    /// Which value each changed corner takes (Hoppe's `corners`).
    Corners,
    /// uv residuals.
    Uv,
    /// Normal residuals.
    Normal,
    /// Colour residuals.
    Colour,
    /// Materials of fl and fr.
    Material,
}

impl WedgeField {
    /// The field's name in the coder's per-field bit count.
    pub fn name(self) -> &'static str {
        match self {
            WedgeField::Corners => "wedge",
            WedgeField::Uv => "uv",
            WedgeField::Normal => "normal",
            WedgeField::Colour => "colour",
            WedgeField::Material => "material",
        }
    }

    /// Every field.
    pub const ALL: [WedgeField; 5] = [
        WedgeField::Corners,
        WedgeField::Uv,
        WedgeField::Normal,
        WedgeField::Colour,
        WedgeField::Material,
    ];
}

/// A part of a CAME stream, as Table 3 of the paper splits it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum CameField {
    /// Tree shape and triangles' corner paths (n1, n2, n3).
    Connectivity,
    /// Dependencies.
    Dependencies,
    /// Difference vectors (and, in `came-paper`, the meta-nodes' frames).
    Coordinates,
    /// Multiresolution data: error-sphere radii.
    MrData,
    /// Normal cones (`came`; not in the paper).
    Cones,
    /// Deviations (`came`; not in the paper).
    Deviations,
    /// The priors every unit's contexts start from (`came` syntax 2; not in the paper).
    Priors,
    /// Triangles' own normals (`came` syntax 4; not in the paper).
    FaceNormals,
}

impl CameField {
    /// The field's name in the coder's per-field bit count.
    pub fn name(self) -> &'static str {
        match self {
            CameField::Connectivity => "connectivity",
            CameField::Dependencies => "dependencies",
            CameField::Coordinates => "coordinates",
            CameField::MrData => "spheres",
            CameField::Cones => "cones",
            CameField::Deviations => "deviations",
            CameField::Priors => "priors",
            CameField::FaceNormals => "triangle normals",
        }
    }

    /// Every field.
    pub const ALL: [CameField; 8] = [
        CameField::Connectivity,
        CameField::Dependencies,
        CameField::Coordinates,
        CameField::MrData,
        CameField::Cones,
        CameField::Deviations,
        CameField::Priors,
        CameField::FaceNormals,
    ];
}

/// A statistic the paper tables read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Stat {
    /// emc-paper: bytes of the stream's header (without the index).
    HeaderBytes,
    /// emc-paper: 3-cliques of the final edge graph.
    Cliques,
    /// emc-paper: bits of connecting-edge flags.
    ConnectingFlagBits,
    /// emc-paper: bits of STAY / MOVE / DUPLICATE codes.
    EdgeCodeBits,
    /// emc-paper: raw refinement bits.
    RefinementBits,
    /// emc-paper: bits of split-distance codes.
    SplitDistanceBits,
    /// emc-paper: bits of the final face corrections.
    FaceCorrectionBits,
    /// emc-paper: 3-cliques that are no face.
    FalseTriangles,
    /// emc-paper: faces present with both orientations.
    DoubleSidedFaces,
    /// emc-paper: faces whose orientation propagation gets wrong.
    OrientationExceptions,
    /// pm: vertices of the base mesh M⁰.
    BaseVertices,
    /// pm: faces of the base mesh M⁰.
    BaseFaces,
    /// pm: vertex splits.
    Vsplits,
    /// pm: bits of one vsplit field, summed over the stream.
    FieldBits(PmField),
    /// pm: PMeshIter from M⁰ to Mⁿ in memory, vertex splits a second.
    GotoFullVerticesPerSecond,
    /// pm: PMeshIter from Mⁿ back to M⁰ in memory, edge collapses a second.
    GotoBaseVerticesPerSecond,
    /// pm: decoding the stream, vertex splits a second.
    StreamDecodeVerticesPerSecond,
    /// came, came-paper: depth of the vertex hierarchy.
    HierarchyDepth,
    /// came, came-paper: meta-nodes (units) of the stream.
    MetaNodes,
    /// came, came-paper: dependencies per inner node after the redundant ones are dropped.
    DependenciesPerNode,
    /// came, came-paper: dependencies per inner node before.
    RawDependenciesPerNode,
    /// came, came-paper: seconds to build the hierarchy.
    HierarchySeconds,
    /// came, came-paper: bits of one part of the stream, summed over its units.
    CameBits(CameField),
}

impl Stat {
    /// The statistic's key in results/ files.
    pub fn key(self) -> String {
        match self {
            Stat::HeaderBytes => "header_bytes".into(),
            Stat::Cliques => "cliques".into(),
            Stat::ConnectingFlagBits => "connecting_flag_bits".into(),
            Stat::EdgeCodeBits => "edge_code_bits".into(),
            Stat::RefinementBits => "refinement_bits".into(),
            Stat::SplitDistanceBits => "split_distance_bits".into(),
            Stat::FaceCorrectionBits => "face_correction_bits".into(),
            Stat::FalseTriangles => "false_triangles".into(),
            Stat::DoubleSidedFaces => "double_sided_faces".into(),
            Stat::OrientationExceptions => "orientation_exceptions".into(),
            Stat::BaseVertices => "base_vertices".into(),
            Stat::BaseFaces => "base_faces".into(),
            Stat::Vsplits => "vsplits".into(),
            Stat::FieldBits(field) => format!("bits_{}", field.name()),
            Stat::GotoFullVerticesPerSecond => "goto_full_vertices_per_second".into(),
            Stat::GotoBaseVerticesPerSecond => "goto_base_vertices_per_second".into(),
            Stat::StreamDecodeVerticesPerSecond => "stream_decode_vertices_per_second".into(),
            Stat::HierarchyDepth => "hierarchy_depth".into(),
            Stat::MetaNodes => "meta_nodes".into(),
            Stat::DependenciesPerNode => "dependencies_per_node".into(),
            Stat::RawDependenciesPerNode => "raw_dependencies_per_node".into(),
            Stat::HierarchySeconds => "hierarchy_seconds".into(),
            Stat::CameBits(field) => format!("came_bits_{}", field.name()),
        }
    }
}

/// A codec's statistics, by key.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Stats(BTreeMap<String, f64>);

impl Stats {
    /// Sets `stat`.
    pub fn set(&mut self, stat: Stat, value: f64) {
        self.0.insert(stat.key(), value);
    }

    /// Adds `value` to `stat` (from zero).
    pub fn add(&mut self, stat: Stat, value: f64) {
        self.add_named(&stat.key(), value);
    }

    /// Adds `value` to the statistic called `key`, one no table reads.
    pub fn add_named(&mut self, key: &str, value: f64) {
        *self.0.entry(key.to_string()).or_default() += value;
    }

    /// `stat`, if recorded.
    pub fn get(&self, stat: Stat) -> Option<f64> {
        self.0.get(&stat.key()).copied()
    }

    /// The statistic called `key`, if recorded.
    pub fn get_named(&self, key: &str) -> Option<f64> {
        self.0.get(key).copied()
    }

    /// `stat`, or an error naming it when the codec did not record it.
    pub fn require(&self, stat: Stat) -> Result<f64> {
        self.get(stat).ok_or_else(|| {
            Error::Unsupported(format!("no statistic '{}' in the result", stat.key()))
        })
    }

    /// Adds every statistic of `other`.
    pub fn extend(&mut self, other: Stats) {
        self.0.extend(other.0);
    }

    /// True when nothing is recorded.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Every statistic, by key.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> {
        self.0.iter().map(|(k, &v)| (k.as_str(), v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codecs::{by_name, canonical_for};
    use crate::mesh::generate;

    /// The statistics each codec records, as the tables expect them.
    fn recorded_by(codec: &str) -> Vec<Stat> {
        use PmField::*;
        use Stat::*;
        match codec {
            "emc-paper" => vec![
                HeaderBytes,
                Cliques,
                ConnectingFlagBits,
                EdgeCodeBits,
                RefinementBits,
                SplitDistanceBits,
                FaceCorrectionBits,
                FalseTriangles,
                DoubleSidedFaces,
                OrientationExceptions,
            ],
            "came" | "came-paper" => {
                let mut stats = vec![
                    HierarchyDepth,
                    MetaNodes,
                    DependenciesPerNode,
                    RawDependenciesPerNode,
                    HierarchySeconds,
                ];
                stats.extend(CameField::ALL.map(CameBits));
                stats
            }
            "pm" | "pm-reordered" => {
                let mut stats = vec![
                    BaseVertices,
                    BaseFaces,
                    Vsplits,
                    GotoFullVerticesPerSecond,
                    GotoBaseVerticesPerSecond,
                    StreamDecodeVerticesPerSecond,
                ];
                let fields = [Base, Count, Flclw, VsIndex, VlrRot, Ii, VadL];
                stats.extend(fields.map(FieldBits));
                if codec == "pm" {
                    stats.push(FieldBits(VadS));
                }
                stats
            }
            _ => Vec::new(),
        }
    }

    #[test]
    fn every_stat_is_recorded_by_its_codecs() {
        let mesh = generate::torus(1.0, 0.4, 40, 20);
        for name in ["emc-paper", "pm", "pm-reordered", "came", "came-paper"] {
            let codec = by_name(name).unwrap();
            let canonical = canonical_for(&mesh, &codec.default_options()).unwrap();
            let encoded = codec.encode(&canonical).unwrap();
            let mut stats = encoded.stats;
            stats.extend(codec.measure(&encoded.bytes).unwrap());
            for stat in recorded_by(name) {
                assert!(
                    stats.require(stat).is_ok(),
                    "{name} does not record {stat:?}"
                );
            }
        }
    }

    #[test]
    fn a_missing_stat_is_an_error_not_a_zero() {
        let e = Stats::default().require(Stat::Cliques).unwrap_err();
        assert!(e.to_string().contains("cliques"), "{e}");
    }
}
