//! The decoder's hierarchy: nodes as units decode them, triangles with their corners' leaf paths,
//! dependencies; the mesh at any depth of the front; and the level decoder both CAME codecs
//! share (levels = depths of the front, coarse to fine).

use super::knowledge::{status, Status};
use super::Params;
use crate::codecs::{LevelDecoder, LevelMesh};
use crate::container::{Header, Index, PartialIndex, StreamReader};
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::CodedCone;
pub use crate::hierarchy::came::face_normals::FaceNormal;
use crate::hierarchy::came::NodeId;
use crate::mesh::TriMesh;
use glam::DVec3;
use std::collections::HashMap;

/// A decoded node.
#[derive(Clone, Debug)]
pub struct Node {
    /// Its path.
    pub id: NodeId,
    /// Whether it is a leaf.
    pub leaf: bool,
    /// Its children, once its split is decoded.
    pub children: Option<[u32; 2]>,
    /// Its parent (`u32::MAX` for the root).
    pub parent: u32,
    /// Its position (grid units).
    pub position: [f64; 3],
    /// Its error sphere's radius (grid units).
    pub radius: f64,
    /// Its deviation (grid units, `hierarchy::came::deviation`): the error refinement
    /// projects; the sphere's radius in streams without deviations.
    pub deviation: f32,
    /// Its normal cone as coded ([`CodedCone::NONE`] where the stream has none).
    pub cone: CodedCone,
    /// Root of the unit that decoded the split creating it.
    pub created_unit: NodeId,
    /// Root of the unit that decoded its split.
    pub split_unit: Option<NodeId>,
}

// Every field counts: the decoder keeps two nodes a vertex (`limits::DECODE_MEMORY_MULTIPLE`).
const _: () = assert!(std::mem::size_of::<Node>() == 88);

/// A child's error bounds as a unit decodes them.
#[derive(Clone, Copy, Debug, Default)]
pub struct Bounds {
    /// Its error sphere's radius (grid units).
    pub radius: f64,
    /// Its deviation (grid units).
    pub deviation: f32,
    /// Its deviation's step on the grid anchored at the root's (syntax 6; 0 before).
    pub deviation_step: u16,
}

/// A decoded triangle: its corners' leaf paths in face order, the depth of its split, and what
/// the stream says of its normal.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// Leaf paths of the corners, oriented.
    pub corners: [NodeId; 3],
    /// Depth of the node whose split creates it.
    pub birth_depth: u8,
    /// Its normal in the mesh's units (`came` syntax 4), known where it is born.
    pub normal: FaceNormal,
}

// The normal lives in what was the record's padding: decoding takes no more memory for it.
const _: () = assert!(std::mem::size_of::<Triangle>() == 32);

/// A corner whose path waits at a node for the unit that splits it (`came` syntax 9).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WaitingCorner {
    /// The triangle (in decoding order) and which of its corners.
    pub triangle: u32,
    pub corner: u8,
    /// Which corner of its birth split it is (n1, n2, n3: the contexts its steps take).
    pub kind: u8,
    /// The node whose position its steps point to (a step codes whether the child nearer it
    /// holds the path).
    pub target: u32,
}

// Held for every corner that waits: small, so that decoding stays within its memory bound.
const _: () = assert!(std::mem::size_of::<WaitingCorner>() == 12);

/// The sizes of a [`DecodedTree`] at one moment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mark {
    pub nodes: usize,
    pub triangles: usize,
    pub dependencies: usize,
    pub dependency_nodes: usize,
}

/// Everything decoded so far.
#[derive(Debug)]
pub struct DecodedTree {
    /// Nodes in decoding order; the root first.
    pub nodes: Vec<Node>,
    /// Node by packed path.
    pub lookup: HashMap<u64, u32, foldhash::fast::FixedState>,
    /// Triangles in decoding order.
    pub triangles: Vec<Triangle>,
    /// Per split decoded: the node and the range of `dependency_nodes` holding the splits it
    /// depends on (one array for all, so a split costs no allocation of its own).
    pub dependencies: Vec<(NodeId, std::ops::Range<u32>)>,
    /// The dependencies of every split, in decoding order.
    pub dependency_nodes: Vec<NodeId>,
    /// Per node, its deviation's step on the grid anchored at the root's (`came` syntax 6; 0
    /// before). Beside the nodes rather than in them: a node's record has no room left for it.
    pub deviation_steps: Vec<u16>,
    /// Once the hierarchy is checked complete: every triangle's corners as nodes, so that the
    /// full mesh needs no lookup of its own.
    leaf_corners: Option<Vec<[u32; 3]>>,
    /// `came` syntax 9: corner paths coded as far as their unit knows, waiting at the node
    /// where they stop for the unit that splits it to carry them on; by node.
    pub waiting: HashMap<u32, Vec<WaitingCorner>, foldhash::fast::FixedState>,
    /// What the unit being decoded did to corners coded before it, to undo it if the unit is
    /// refused: the corners it carried on (triangle, corner, the path before) in order, and
    /// the waiting lists it took.
    carried: Vec<(u32, u8, NodeId)>,
    taken: Vec<(u32, Vec<WaitingCorner>)>,
    max_nodes: usize,
    max_triangles: usize,
}

impl DecodedTree {
    /// A tree of `vertices` leaves to be, holding at most `triangles` triangles, decoded from
    /// `stream_bytes` bytes.
    pub fn new(vertices: u64, triangles: u64, stream_bytes: usize) -> DecodedTree {
        // Room for the nodes the header declares, as far as the stream's size can hold them
        // (a split costs more than a byte in any stream an encoder writes).
        let expected = (2 * vertices).min(2 * stream_bytes as u64) as usize;
        DecodedTree {
            nodes: Vec::with_capacity(expected),
            lookup: HashMap::with_capacity_and_hasher(expected, Default::default()),
            triangles: Vec::with_capacity(triangles.min(2 * stream_bytes as u64) as usize),
            dependencies: Vec::new(),
            dependency_nodes: Vec::new(),
            deviation_steps: Vec::with_capacity(expected),
            leaf_corners: None,
            waiting: HashMap::default(),
            carried: Vec::new(),
            taken: Vec::new(),
            max_nodes: (2 * vertices).saturating_sub(1) as usize,
            max_triangles: triangles as usize,
        }
    }

    /// How much is decoded now, to [`DecodedTree::roll_back`] to.
    pub fn mark(&self) -> Mark {
        Mark {
            nodes: self.nodes.len(),
            triangles: self.triangles.len(),
            dependencies: self.dependencies.len(),
            dependency_nodes: self.dependency_nodes.len(),
        }
    }

    /// Forgets everything decoded since `mark` (a unit that failed half-way).
    pub fn roll_back(&mut self, mark: Mark) {
        self.leaf_corners = None;
        // The corners the unit carried on, back to where they waited, latest first.
        for (t, k, before) in std::mem::take(&mut self.carried).into_iter().rev() {
            if let Some(t) = self.triangles.get_mut(t as usize) {
                t.corners[k as usize] = before;
            }
        }
        for (node, list) in std::mem::take(&mut self.taken) {
            self.waiting.insert(node, list);
        }
        // Corners wait only at nodes their unit created.
        self.waiting.retain(|&node, _| (node as usize) < mark.nodes);
        for i in mark.nodes.min(self.nodes.len())..self.nodes.len() {
            let id = self.nodes[i].id;
            self.lookup.remove(&id.packed());
            // The parent split by this unit, if it was decoded before it.
            if let Some(&parent) = id.parent().and_then(|p| self.lookup.get(&p.packed())) {
                if (parent as usize) < mark.nodes {
                    let p = &mut self.nodes[parent as usize];
                    p.children = None;
                    p.split_unit = None;
                }
            }
        }
        self.nodes.truncate(mark.nodes);
        self.deviation_steps.truncate(mark.nodes);
        self.triangles.truncate(mark.triangles);
        self.dependencies.truncate(mark.dependencies);
        self.dependency_nodes.truncate(mark.dependency_nodes);
    }

    /// Adds the root (an inner node: the meshes CAME codes have triangles).
    pub fn add_root(&mut self, position: [f64; 3], radius: f64, deviation: f32, cone: CodedCone) {
        self.nodes.push(Node {
            id: NodeId::ROOT,
            leaf: false,
            children: None,
            parent: u32::MAX,
            position,
            radius,
            deviation,
            cone,
            created_unit: NodeId::ROOT,
            split_unit: None,
        });
        self.lookup.insert(NodeId::ROOT.packed(), 0);
        self.deviation_steps.push(0);
    }

    /// The node at `id`, if decoded.
    pub fn get(&self, id: NodeId) -> Option<u32> {
        self.lookup.get(&id.packed()).copied()
    }

    /// The status of decoded node `i` from the unit rooted at `unit`.
    pub fn status_of(&self, i: u32, unit: NodeId) -> Status {
        let n = &self.nodes[i as usize];
        status(n.leaf, n.split_unit, n.created_unit, unit)
    }

    /// Splits node `s` into children with the given leaf flags, positions, error bounds and
    /// cones, decoded by the unit rooted at `unit`.
    #[allow(clippy::too_many_arguments)]
    pub fn split(
        &mut self,
        s: u32,
        leaf: [bool; 2],
        positions: [[f64; 3]; 2],
        bounds: [Bounds; 2],
        cones: [CodedCone; 2],
        unit: NodeId,
        at: usize,
    ) -> Result<[u32; 2]> {
        if self.nodes.len() + 2 > self.max_nodes {
            return Err(Error::malformed(
                0,
                at,
                "the hierarchy has more nodes than its vertices allow",
            ));
        }
        let first = self.nodes.len() as u32;
        let parent = &mut self.nodes[s as usize];
        if parent.children.is_some() || parent.leaf {
            return Err(Error::malformed(0, at, "a node is split twice"));
        }
        parent.split_unit = Some(unit);
        let id = parent.id;
        parent.children = Some([first, first + 1]);
        for side in 0..2 {
            let child = id
                .child(side == 1)
                .ok_or_else(|| Error::malformed(0, at, "the hierarchy is deeper than 52 levels"))?;
            self.lookup.insert(child.packed(), first + side as u32);
            self.nodes.push(Node {
                id: child,
                leaf: leaf[side],
                children: None,
                parent: s,
                position: positions[side],
                radius: bounds[side].radius,
                deviation: bounds[side].deviation,
                cone: cones[side],
                created_unit: unit,
                split_unit: None,
            });
            self.deviation_steps.push(bounds[side].deviation_step);
        }
        Ok([first, first + 1])
    }

    /// Records the dependencies of split `s` (those pushed onto `dependency_nodes` since
    /// `first`).
    pub fn close_dependencies(&mut self, s: NodeId, first: usize) {
        let range = first as u32..self.dependency_nodes.len() as u32;
        self.dependencies.push((s, range));
    }

    /// Corner `corner` of triangle `triangle`, whose path stops at node `node` (a node its
    /// unit created and does not split), waits there for the unit that splits it.
    pub fn wait(&mut self, node: u32, waiting: WaitingCorner) {
        self.waiting.entry(node).or_default().push(waiting);
    }

    /// Takes the corners waiting at node `node` for the unit that splits it: how many, each
    /// then read by [`DecodedTree::taken`] (in the order they began to wait).
    pub fn take_waiting(&mut self, node: u32) -> usize {
        match self.waiting.remove(&node) {
            Some(list) => {
                let count = list.len();
                self.taken.push((node, list));
                count
            }
            None => 0,
        }
    }

    /// The `i`-th corner [`DecodedTree::take_waiting`] took last.
    pub fn taken(&self, i: usize) -> WaitingCorner {
        self.taken.last().expect("corners taken").1[i]
    }

    /// Corner `corner` of triangle `triangle` carried on to `path`.
    pub fn carry(&mut self, triangle: u32, corner: u8, path: NodeId) {
        let t = &mut self.triangles[triangle as usize];
        self.carried
            .push((triangle, corner, t.corners[corner as usize]));
        t.corners[corner as usize] = path;
    }

    /// The corners the unit being decoded carried on: (triangle, corner) in order.
    pub fn carried(&self) -> impl Iterator<Item = (u32, u8)> + '_ {
        self.carried.iter().map(|&(t, k, _)| (t, k))
    }

    /// The unit decoded last is kept: what would undo it is forgotten.
    pub fn accept(&mut self) {
        self.carried.clear();
        self.taken.clear();
        if self.waiting.is_empty() {
            // Every path is complete: the table's room goes too.
            self.waiting = HashMap::default();
        }
    }

    /// The splits split `i` (in decoding order) depends on.
    pub fn dependencies_of(&self, i: usize) -> (NodeId, &[NodeId]) {
        let (s, range) = &self.dependencies[i];
        (
            *s,
            &self.dependency_nodes[range.start as usize..range.end as usize],
        )
    }

    /// Adds a triangle, within the header's count.
    pub fn add_triangle(&mut self, triangle: Triangle, at: usize) -> Result<()> {
        if self.triangles.len() >= self.max_triangles {
            return Err(Error::malformed(
                0,
                at,
                "more triangles than the header declares",
            ));
        }
        self.leaf_corners = None;
        self.triangles.push(triangle);
        Ok(())
    }

    /// The mesh of the front at `depth`: every node at that depth and every leaf above it, at
    /// their positions mapped through `to_world`.
    pub fn mesh_at(&self, depth: u8, to_world: impl Fn([f64; 3]) -> DVec3) -> Result<TriMesh> {
        let deepest = self.nodes.iter().all(|n| n.id.len() <= depth);
        if let (true, Some(corners)) = (deepest, &self.leaf_corners) {
            // The front is every leaf, and every triangle's corners are known nodes.
            let mut index = vec![u32::MAX; self.nodes.len()];
            let mut positions = Vec::new();
            for (i, n) in self.nodes.iter().enumerate().filter(|(_, n)| n.leaf) {
                index[i] = positions.len() as u32;
                positions.push(to_world(n.position));
            }
            let faces = corners
                .iter()
                .map(|c| c.map(|i| index[i as usize]))
                .collect();
            return Ok(TriMesh { positions, faces });
        }
        let mut index = vec![u32::MAX; self.nodes.len()];
        let mut positions = Vec::new();
        for (i, n) in self.nodes.iter().enumerate() {
            let len = n.id.len();
            if len == depth || (n.leaf && len < depth) {
                index[i] = positions.len() as u32;
                positions.push(to_world(n.position));
            }
        }
        let mut faces = Vec::new();
        for t in self.triangles.iter().filter(|t| t.birth_depth < depth) {
            let mut face = [0u32; 3];
            for (k, corner) in t.corners.iter().enumerate() {
                let v = self
                    .get(corner.ancestor(depth))
                    .map(|i| index[i as usize])
                    .filter(|&v| v != u32::MAX)
                    .ok_or_else(|| {
                        Error::malformed(0, 0, "a triangle's corner is no node of the front")
                    })?;
                face[k] = v;
            }
            faces.push(face);
        }
        Ok(TriMesh { positions, faces })
    }
}

/// A node's position in grid units (cell centres at whole numbers) in the mesh's units.
pub fn to_world(grid: &crate::mesh::Grid, p: [f64; 3]) -> DVec3 {
    DVec3::new(
        grid.origin[0] + (p[0] + 0.5) * grid.cell[0],
        grid.origin[1] + (p[1] + 0.5) * grid.cell[1],
        grid.origin[2] + (p[2] + 0.5) * grid.cell[2],
    )
}

/// What one unit added to the tree, before it is kept ([`CameDecoder::decode_unit_checked`]).
pub struct DecodedUnit<'t> {
    /// The tree, with the unit decoded.
    pub tree: &'t DecodedTree,
    /// The unit's root node.
    pub root: u32,
    /// The tree before the unit: what lies past this mark is the unit's.
    pub since: Mark,
    /// The units under this one in the index, with their root nodes.
    pub child_units: Vec<(usize, u32)>,
}

/// Decodes one unit into the tree: what differs between `came-paper` and `came`.
pub trait UnitDecoder {
    /// Decodes the unit rooted at node `root` from `bytes` (starting at stream offset `at`);
    /// the stream's first unit, found on an empty tree, decodes the root itself. Returns the
    /// roots of its child units, in order.
    fn decode_unit(
        &self,
        tree: &mut DecodedTree,
        header: &Header,
        params: &Params,
        root: u32,
        bytes: &[u8],
        at: usize,
    ) -> Result<Vec<u32>>;
}

/// The level decoder of both CAME codecs. Units decode in stream order for levels, or any unit
/// once its ancestors are ([`CameDecoder::decode_unit`]): a unit's root is the k-th child root
/// of its parent unit when it is the parent's k-th child in the index.
pub struct CameDecoder<'a, U: UnitDecoder> {
    header: Header,
    index: Index,
    /// Offset of the payload in the stream.
    payload_start: usize,
    /// The stream or prefix the units are read from (empty for a detached decoder, which is
    /// given each unit's bytes).
    bytes: std::borrow::Cow<'a, [u8]>,
    params: Params,
    units: U,
    tree: DecodedTree,
    /// Per unit: the roots of its child units, once it is decoded.
    child_roots: Vec<Option<Vec<u32>>>,
    /// Per unit: its children in the index (consecutive: the index lists units breadth first).
    unit_children: Vec<std::ops::Range<usize>>,
    /// Units the index lists, of which `index` holds those read so far (a detached decoder's
    /// index grows as a client reads on: [`CameDecoder::extend_index`]).
    listed: usize,
    /// Per unit: the triangles it decoded (a range of `tree.triangles`).
    unit_triangles: Vec<Option<std::ops::Range<usize>>>,
    /// Units decoded in stream order for levels.
    units_in_order: usize,
    levels_decoded: usize,
}

impl<'a, U: UnitDecoder> CameDecoder<'a, U> {
    /// A decoder before the first level.
    pub fn new(stream: StreamReader<'a>, params: Params, units: U) -> Result<Self> {
        let (header, index, payload_start, bytes) = stream.into_parts();
        Self::with_parts(header, index, payload_start, bytes, params, units)
    }

    /// A decoder given each unit's bytes by [`CameDecoder::decode_unit_bytes`] rather than
    /// holding the stream: for units fetched on demand, from a file or a network.
    pub fn detached(
        header: Header,
        index: Index,
        payload_start: usize,
        params: Params,
        units: U,
    ) -> Result<CameDecoder<'static, U>> {
        CameDecoder::with_parts(
            header,
            index,
            payload_start,
            std::borrow::Cow::Borrowed(&[]),
            params,
            units,
        )
    }

    fn with_parts(
        header: Header,
        index: Index,
        payload_start: usize,
        bytes: std::borrow::Cow<'a, [u8]>,
        params: Params,
        units: U,
    ) -> Result<Self> {
        if header.vertices < 3 || header.triangles == 0 {
            return Err(Error::malformed(
                0,
                0,
                "a CAME stream codes a mesh of at least one triangle",
            ));
        }
        let mut children: Vec<std::ops::Range<usize>> = Vec::with_capacity(index.len());
        for (i, unit) in index.units.iter().enumerate() {
            children.push(i + 1..i + 1);
            match unit.parent {
                Some(p) if p >= i => {
                    return Err(Error::malformed(0, 0, "a unit's parent comes after it"))
                }
                Some(p) if children[p].is_empty() => children[p] = i..i + 1,
                Some(p) if children[p].end == i => children[p].end += 1,
                Some(_) => {
                    return Err(Error::malformed(
                        0,
                        0,
                        format!("the index lists unit {i} apart from its parent's other children"),
                    ))
                }
                None if i > 0 => {
                    return Err(Error::malformed(0, 0, "only the first unit has no parent"))
                }
                None => {}
            }
        }
        // Room as far as the bytes at hand justify; a detached decoder's tree grows with the
        // units it is given.
        let known = bytes.len().max(payload_start);
        let tree = DecodedTree::new(header.vertices, header.triangles, known);
        Ok(CameDecoder {
            child_roots: vec![None; index.len()],
            unit_triangles: vec![None; index.len()],
            unit_children: children,
            listed: index.len(),
            header,
            index,
            payload_start,
            bytes,
            params,
            units,
            tree,
            units_in_order: 0,
            levels_decoded: 0,
        })
    }

    /// Takes the entries of `index` past those this decoder holds: a detached decoder's index
    /// read entry by entry as a client fetches on (docs/FORMAT.md §2). A unit decodes once its
    /// own entry is in: its children's numbers come with it. The appearance unit, where the
    /// header declares one, is not the codec's.
    pub fn extend_index(&mut self, index: &PartialIndex) -> Result<()> {
        let codec_units = index.codec_units(&self.header);
        for i in self.index.len()..index.index.len().min(codec_units) {
            let entry = index.index.units[i];
            if i > 0 && entry.parent.is_none() {
                return Err(Error::malformed(0, 0, "only the first unit has no parent"));
            }
            let children = &index.children[i];
            self.index.units.push(entry);
            self.unit_children
                .push(children.start.min(codec_units)..children.end.min(codec_units));
            self.child_roots.push(None);
            self.unit_triangles.push(None);
        }
        self.listed = codec_units;
        Ok(())
    }

    /// Everything decoded so far.
    pub fn tree(&self) -> &DecodedTree {
        &self.tree
    }

    /// The triangles unit `i` decoded, if it is decoded.
    pub fn unit_triangles(&self, i: usize) -> Option<&[Triangle]> {
        let range = self.unit_triangles.get(i)?.clone()?;
        Some(&self.tree.triangles[range])
    }

    /// Decodes every unit not decoded yet, in stream order, and checks that the hierarchy is
    /// complete.
    pub fn decode_everything(&mut self) -> Result<()> {
        for i in 0..self.index.len() {
            if self.child_roots[i].is_none() && !self.decode_unit(i)? {
                return Err(Error::malformed(
                    i + 1,
                    self.bytes.len(),
                    format!("the stream ends inside unit {i}"),
                ));
            }
        }
        self.check_complete()
    }

    /// The tree decoded so far.
    pub fn into_tree(self) -> DecodedTree {
        self.tree
    }

    /// The root of unit `i`, if its parent is decoded (the first unit's root is the tree's).
    fn unit_root(&self, i: usize) -> Result<Option<u32>> {
        let Some(parent) = self.index.units[i].parent else {
            return Ok(Some(0));
        };
        let Some(roots) = &self.child_roots[parent] else {
            return Ok(None);
        };
        let rank = i - self.unit_children[parent].start;
        roots.get(rank).copied().map(Some).ok_or_else(|| {
            Error::malformed(
                i + 1,
                self.payload_start,
                format!("unit {i} has no meta-node under its parent unit {parent}"),
            )
        })
    }

    /// Decodes unit `i`, its ancestors decoded; `Ok(false)` if its bytes are not in the prefix.
    /// Errors if it is decoded already or a parent is missing.
    pub fn decode_unit(&mut self, i: usize) -> Result<bool> {
        let Some(entry) = self.index.units.get(i) else {
            return Err(self.no_unit(i));
        };
        let start = self.payload_start + entry.offset as usize;
        let end = self.payload_start + entry.end() as usize;
        // A copy: the decoder's bytes may be its own, and decoding changes the decoder.
        let Some(bytes) = self.bytes.get(start..end).map(<[u8]>::to_vec) else {
            return Ok(false);
        };
        self.decode_unit_bytes(i, &bytes)?;
        Ok(true)
    }

    fn no_unit(&self, i: usize) -> Error {
        if i < self.listed {
            return Error::Unsupported(format!(
                "unit {i} is not in the index read so far ({} of {} entries)",
                self.index.len(),
                self.listed
            ));
        }
        Error::Unsupported(format!("no unit {i}: the stream has {}", self.listed))
    }

    /// Decodes unit `i` from `bytes`, the payload its index entry points to (read from wherever
    /// the stream is), its ancestors decoded. On an error the tree is left as it was before, so
    /// the other units still decode.
    pub fn decode_unit_bytes(&mut self, i: usize, bytes: &[u8]) -> Result<()> {
        self.decode_unit_checked(i, bytes, |_| Ok(()))
    }

    /// [`CameDecoder::decode_unit_bytes`], then `check` on what the unit added before it is
    /// kept: an error from either leaves the tree as it was.
    pub fn decode_unit_checked<T>(
        &mut self,
        i: usize,
        bytes: &[u8],
        check: impl FnOnce(&DecodedUnit) -> Result<T>,
    ) -> Result<T> {
        let Some(entry) = self.index.units.get(i) else {
            return Err(self.no_unit(i));
        };
        let start = self.payload_start + entry.offset as usize;
        if bytes.len() as u64 != entry.length {
            return Err(Error::Truncated(format!(
                "unit {i} has {} of its {} bytes",
                bytes.len(),
                entry.length
            )));
        }
        if self.child_roots[i].is_some() {
            return Err(Error::Unsupported(format!("unit {i} is decoded already")));
        }
        let Some(root) = self.unit_root(i)? else {
            return Err(Error::Unsupported(format!(
                "unit {i} needs its parent unit decoded first"
            )));
        };
        let mark = self.tree.mark();
        let decoded = self
            .units
            .decode_unit(
                &mut self.tree,
                &self.header,
                &self.params,
                root,
                bytes,
                start,
            )
            .and_then(|children| {
                let expected = self.unit_children[i].len();
                if children.len() != expected {
                    return Err(Error::malformed(
                        i + 1,
                        start,
                        format!(
                            "unit {i} opens {} meta-nodes, the index lists {expected} under it",
                            children.len()
                        ),
                    ));
                }
                let unit = DecodedUnit {
                    tree: &self.tree,
                    root,
                    since: mark,
                    child_units: self.unit_children[i]
                        .clone()
                        .zip(&children)
                        .map(|(j, &root)| (j, root))
                        .collect(),
                };
                check(&unit).map(|checked| (checked, children))
            });
        match decoded {
            Ok((checked, children)) => {
                self.tree.accept();
                self.child_roots[i] = Some(children);
                self.unit_triangles[i] = Some(mark.triangles..self.tree.triangles.len());
                Ok(checked)
            }
            Err(e) => {
                self.tree.roll_back(mark);
                Err(e)
            }
        }
    }

    /// Depth of the next unit's first splits in stream order, once its parent is decoded.
    fn next_unit_depth(&self) -> Result<Option<u8>> {
        let i = self.units_in_order;
        if i >= self.index.len() {
            return Ok(None);
        }
        match self.unit_root(i)? {
            Some(_) if i == 0 => Ok(Some(0)),
            Some(root) => {
                let top = self.tree.nodes[root as usize].id.len();
                Ok(Some(self.params.shape().band(top).start))
            }
            None => Err(Error::malformed(
                i + 1,
                self.payload_start,
                format!("unit {i} depends on a unit after it"),
            )),
        }
    }

    fn check_complete(&mut self) -> Result<()> {
        let at = self.payload_start;
        let header = &self.header;
        if self.child_roots.iter().any(Option::is_none) {
            return Err(Error::malformed(
                0,
                at,
                "the hierarchy is complete before the index's last unit",
            ));
        }
        let leaves = self.tree.nodes.iter().filter(|n| n.leaf).count() as u64;
        let open = self
            .tree
            .nodes
            .iter()
            .any(|n| !n.leaf && n.children.is_none());
        if leaves != header.vertices || open {
            return Err(Error::malformed(
                0,
                at,
                format!(
                    "the hierarchy has {leaves} leaves, the header {} vertices",
                    header.vertices
                ),
            ));
        }
        if self.tree.triangles.len() as u64 != header.triangles {
            return Err(Error::malformed(
                0,
                at,
                format!(
                    "{} triangles decoded, the header declares {}",
                    self.tree.triangles.len(),
                    header.triangles
                ),
            ));
        }
        let cells = header.grid.cells_per_axis() as f64;
        for n in self.tree.nodes.iter().filter(|n| n.leaf) {
            if n.position.iter().any(|&x| !(0.0..cells).contains(&x)) {
                return Err(Error::malformed(0, at, "a vertex lies outside the grid"));
            }
        }
        let tree = &self.tree;
        let corners = tree
            .triangles
            .iter()
            .map(|t| {
                let mut nodes = [0u32; 3];
                for (node, c) in nodes.iter_mut().zip(t.corners) {
                    *node = tree
                        .get(c)
                        .filter(|&i| tree.nodes[i as usize].leaf)
                        .ok_or_else(|| {
                            Error::malformed(0, at, "a triangle's corner is no vertex")
                        })?;
                }
                Ok(nodes)
            })
            .collect::<Result<Vec<_>>>()?;
        self.tree.leaf_corners = Some(corners);
        Ok(())
    }
}

impl<U: UnitDecoder + Send> LevelDecoder for CameDecoder<'_, U> {
    fn header(&self) -> &Header {
        &self.header
    }

    fn levels(&self) -> usize {
        self.params.depth as usize
    }

    fn levels_decoded(&self) -> usize {
        self.levels_decoded
    }

    fn advance(&mut self) -> Result<bool> {
        let depth = self.params.depth as usize;
        if self.levels_decoded >= depth {
            return Ok(false);
        }
        // The front at depth k needs every split above depth k.
        let k = self.levels_decoded + 1;
        while let Some(top) = self.next_unit_depth()? {
            if top as usize >= k {
                break;
            }
            if !self.decode_unit(self.units_in_order)? {
                return Ok(false);
            }
            self.units_in_order += 1;
        }
        self.levels_decoded = k;
        if k == depth {
            self.check_complete()?;
        }
        Ok(true)
    }

    fn mesh(&self) -> Result<LevelMesh> {
        let grid = &self.header.grid;
        let mesh = self
            .tree
            .mesh_at(self.levels_decoded as u8, |p| to_world(grid, p))?;
        Ok(LevelMesh {
            mesh,
            loose_edges: Vec::new(),
            attributes: None,
        })
    }

    /// The next bytes join the stream's: the units they complete decode at the next
    /// `advance`, into the tree as it stands (a new depth band's units go on from the last).
    /// A detached decoder, given each unit's bytes, holds no stream to extend.
    fn extend(&mut self, more: &[u8]) -> Result<bool> {
        if self.bytes.is_empty() {
            return Ok(false);
        }
        crate::container::check_stream_length(
            &self.index,
            self.payload_start,
            self.bytes.len() + more.len(),
        )?;
        self.bytes.to_mut().extend_from_slice(more);
        Ok(true)
    }
}
