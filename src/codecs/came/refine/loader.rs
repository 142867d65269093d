//! Meta-nodes fetched on demand: where a stream's bytes come from, and the loader that reads a
//! unit by its byte range and decodes it — on a thread of its own, or inline at the next
//! adaptation — handing the view-dependent mesh only what the unit added.
//!
//! Allocation follows what arrives, never what the index claims: a unit is read with the
//! source's length as its bound (a unit said to lie past the source's end is refused unread),
//! and the decoded tree grows unit by unit.

use crate::codecs::came::decoded::{to_world, DecodedTree, DecodedUnit};
use crate::codecs::came::refining_codec;
use crate::codecs::came::selective::DetachedUnits;
use crate::container::{read_header_and_index, Header, Index, PartialIndex};
use crate::error::{Error, Result};
use crate::hierarchy::came::cones::NormalCone;
use crate::hierarchy::came::face_normals::FaceNormal;
use crate::hierarchy::came::NodeId;
use glam::DVec3;
use smallvec::SmallVec;
use std::io::{Read, Seek, SeekFrom};
use std::sync::mpsc;

pub(super) const NONE: u32 = u32::MAX;

/// Where a stream's bytes come from: a file, any `Read + Seek`, or bytes already fetched.
pub trait ByteSource: Send {
    /// Up to `len` bytes from offset `start`; fewer only where the source ends.
    fn read_at(&mut self, start: u64, len: u64) -> std::io::Result<Vec<u8>>;
    /// The source's length in bytes, when it is known.
    fn size(&mut self) -> Option<u64>;
}

/// Any seekable reader (a file, a cursor) as a [`ByteSource`].
pub struct SeekSource<R>(pub R);

impl<R: Read + Seek + Send> ByteSource for SeekSource<R> {
    fn read_at(&mut self, start: u64, len: u64) -> std::io::Result<Vec<u8>> {
        self.0.seek(SeekFrom::Start(start))?;
        let mut bytes = Vec::new();
        (&mut self.0).take(len).read_to_end(&mut bytes)?;
        Ok(bytes)
    }

    fn size(&mut self) -> Option<u64> {
        self.0.seek(SeekFrom::End(0)).ok()
    }
}

/// Bytes already fetched: a whole stream, or a prefix of one.
impl ByteSource for Vec<u8> {
    fn read_at(&mut self, start: u64, len: u64) -> std::io::Result<Vec<u8>> {
        let from = (start.min(self.len() as u64)) as usize;
        let to = (start.saturating_add(len).min(self.len() as u64)) as usize;
        Ok(self[from..to].to_vec())
    }

    fn size(&mut self) -> Option<u64> {
        Some(self.len() as u64)
    }
}

/// How many of a stream's first bytes [`Fetch::External`] needs to open it (its header, its
/// index and its first unit), once `prefix` holds the header and the index; `None` while it
/// does not (fetch a longer prefix and ask again).
pub fn head_length(prefix: &[u8]) -> Result<Option<u64>> {
    match read_header_and_index(prefix) {
        Ok((_, index, payload_start)) => Ok(Some(
            payload_start as u64 + index.units.first().map_or(0, |u| u.end()),
        )),
        Err(Error::Truncated(_)) => Ok(None),
        Err(e) => Err(e),
    }
}

/// How units are fetched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fetch {
    /// A loader thread reads and decodes the units asked for while the caller goes on; an
    /// adaptation uses those that have arrived.
    Background,
    /// The units one adaptation asks for are read and decoded at the start of the next, on
    /// the caller's thread (deterministic: for tests and fuzzing).
    Inline,
    /// The caller fetches the units asked for ([`ViewMesh::wanted`](super::ViewMesh::wanted),
    /// their byte ranges) and hands their bytes over
    /// ([`ViewMesh::supply`](super::ViewMesh::supply)), where reads are asynchronous: a
    /// browser's `Range` requests. The source holds the stream's first bytes only: the header,
    /// the index and the first unit.
    External,
}

/// What the front takes a coded deviation of a `came` stream for, times (syntax 3 on): the
/// deviations are measured on the level meshes and on fronts around each node one and two
/// levels finer (`hierarchy::came::deviation`), and a front can mix depths in more ways. At 1.0
/// two of 120 random views of bunny.ply strayed 1.001 and 1.009 px at 1 px
/// (lab/tests/came_view_error.rs with 60 views and two seeds); at 1.1 none did, nor did the
/// far, middle and near views of bunny.ply, dragon-50k and the million-triangle mesh, nor the
/// fly-through (paper-tables/came-vd.md).
pub const DEVIATION_MARGIN: f64 = 1.1;

/// The same for syntax 1 and 2, whose deviations measured fans among neighbours two levels
/// finer one way only. On dragon-50k's middle view of `experiment came-vd` (1.5 diagonals,
/// 1 px, `lab/examples/came_vd_probe.rs`), at 1.0 the adapted mesh strayed up to 1.09 px from
/// the full one (20,500 faces), at 1.5 up to 1.15 px (29,422), at 1.75 up to 0.84 px (38,098).
pub const DEVIATION_MARGIN_BEFORE_SYNTAX_3: f64 = 1.75;

/// What the front takes a coded deviation for, times, in a `came` stream of this syntax.
pub fn deviation_margin(syntax: u8) -> f64 {
    if syntax >= 3 {
        DEVIATION_MARGIN
    } else {
        DEVIATION_MARGIN_BEFORE_SYNTAX_3
    }
}

/// A node a unit added.
#[derive(Clone, Copy, Debug)]
pub(super) struct NewNode {
    pub id: NodeId,
    /// `NONE` for the root.
    pub parent: u32,
    /// Position and error-sphere radius in world units.
    pub center: DVec3,
    pub radius: f64,
    /// Deviation in world units: the error refinement projects.
    pub deviation: f64,
    /// Normal cone ([`NormalCone::NONE`] where the stream has none).
    pub cone: NormalCone,
}

/// A split's dependency: the node, once it is decoded (`NONE` before).
#[derive(Clone, Copy, Debug)]
pub(super) struct Dependency {
    pub id: NodeId,
    pub node: u32,
}

/// What one unit added to the hierarchy, numbered as the loader's tree numbers it (which the
/// view-dependent mesh follows by taking the units in the order they were decoded).
#[derive(Debug, Default)]
pub(super) struct UnitDelta {
    pub nodes: Vec<NewNode>,
    /// Per triangle: the node whose split creates it, its corners' leaf paths, and what the
    /// stream says of its normal.
    pub triangles: Vec<(u32, [NodeId; 3], FaceNormal)>,
    /// Per split: the node and the splits it depends on.
    pub splits: Vec<(u32, SmallVec<[Dependency; 2]>)>,
    /// The units under this one and the nodes whose splits each holds first, open until they
    /// are loaded.
    pub opens: Vec<(usize, u32)>,
    /// Corners of earlier units' triangles whose paths this unit carried on (`came` syntax 9):
    /// the triangle (numbered as the loader's tree numbers them), the corner and its path now.
    pub carried: Vec<(u32, u8, NodeId)>,
}

/// A unit fetched, or why it was refused.
pub(super) struct Loaded {
    pub unit: usize,
    /// Bytes read from the source for it.
    pub bytes: u64,
    pub outcome: Result<UnitDelta>,
}

/// What `decoded` added, checked so that the view-dependent mesh can take it as it is.
fn delta(decoded: &DecodedUnit, header: &Header) -> Result<UnitDelta> {
    let bad = |what: &str| Error::malformed(0, 0, what.to_string());
    let tree: &DecodedTree = decoded.tree;
    let since = decoded.since;
    let cell = header.grid.cell.iter().fold(0.0f64, |m, &c| m.max(c.abs()));
    // Syntax 1 and 2's deviations were measured on fewer fronts than a front mixes.
    let margin = match super::super::modelled::params(header) {
        Ok(p) if p.deviation_bits > 0 => deviation_margin(header.syntax),
        _ => 1.0,
    };
    let root_id = tree.nodes[decoded.root as usize].id;
    let split_here = |i: u32| tree.nodes[i as usize].split_unit == Some(root_id);
    let mut out = UnitDelta::default();
    for (i, n) in tree.nodes.iter().enumerate().skip(since.nodes) {
        let parent = match n.id.parent() {
            None if i == 0 => NONE,
            None => return Err(bad("a second root")),
            Some(p) => tree
                .get(p)
                .ok_or_else(|| bad("a node without its parent"))?,
        };
        out.nodes.push(NewNode {
            id: n.id,
            parent,
            center: to_world(&header.grid, n.position),
            radius: n.radius * cell,
            deviation: n.deviation as f64 * cell * margin,
            cone: n.cone.decoded(),
        });
    }
    for t in &tree.triangles[since.triangles..] {
        let c = t.corners;
        // Two corners part at the birth node, the third higher up.
        let birth_len = c[0]
            .common_len(c[1])
            .max(c[1].common_len(c[2]))
            .max(c[0].common_len(c[2]));
        let birth = (0..3)
            .map(|k| c[k].ancestor(birth_len))
            .find(|b| b.len() == t.birth_depth)
            .and_then(|b| tree.get(b))
            .filter(|&b| split_here(b))
            .ok_or_else(|| bad("a triangle's corners do not part at a split of its unit"))?;
        out.triangles.push((birth, c, t.normal));
    }
    for k in since.dependencies..tree.dependencies.len() {
        let (s, deps) = tree.dependencies_of(k);
        let s = tree
            .get(s)
            .filter(|&s| split_here(s))
            .ok_or_else(|| bad("dependencies of no split of the unit"))?;
        let mut list = SmallVec::new();
        for &d in deps {
            let node = tree.get(d).unwrap_or(NONE);
            if node != NONE && tree.nodes[node as usize].leaf {
                return Err(bad("a split depends on a vertex"));
            }
            list.push(Dependency { id: d, node });
        }
        out.splits.push((s, list));
    }
    for (t, k) in tree.carried() {
        out.carried
            .push((t, k, tree.triangles[t as usize].corners[k as usize]));
    }
    // Every node a child unit splits first: its root, or (depth bands) the open nodes under
    // it, which this unit created.
    for &(unit, root) in &decoded.child_units {
        let mut stack = vec![root];
        while let Some(v) = stack.pop() {
            let node = &tree.nodes[v as usize];
            match node.children {
                Some([t, u]) => stack.extend([u, t]),
                None if !node.leaf => out.opens.push((unit, v)),
                None => {}
            }
        }
    }
    Ok(out)
}

/// How much of the stream a loader reads at a time before its payload: a client trading the
/// number of its reads against the bytes they carry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reads {
    /// The first read: the header and the index's first entries.
    pub first: u64,
    /// Each read of the index after it.
    pub index: u64,
}

impl Reads {
    /// 512 bytes each: the header and about 150 entries of a `came` stream's index (the units
    /// of two or three breadth-first tiers of a coarse view), then as many at a time.
    pub const DEFAULT: Reads = Reads {
        first: 512,
        index: 512,
    };
}

/// Reads units from a source and decodes them.
pub(super) struct Worker {
    source: Box<dyn ByteSource>,
    /// The stream's first bytes: the header and the index as far as it is read (and, where a
    /// read ran on, the payload's first bytes).
    head: Vec<u8>,
    decoder: Box<dyn DetachedUnits>,
    header: Header,
    /// The index, read entry by entry as far as the units asked for need.
    index: PartialIndex,
    payload_start: u64,
    size: Option<u64>,
    /// Bytes of the index read at a time.
    index_read: u64,
}

impl Worker {
    /// Reads the index on until it lists `unit` (each unit's entry counts its children, so
    /// their numbers come with it); returns the bytes read.
    fn read_index_through(&mut self, unit: usize) -> Result<u64> {
        let mut read = 0;
        while self.index.index.len() <= unit {
            if self.index.is_complete() {
                return Err(Error::Unsupported(format!(
                    "no unit {unit}: the stream has {}",
                    self.index.listed
                )));
            }
            let from = self.head.len() as u64;
            let to = (from + self.index_read)
                .min(self.payload_start)
                .max(from + 1);
            let more = self.source.read_at(from, to - from)?;
            if more.is_empty() {
                return Err(Error::Truncated("the stream ends inside its index".into()));
            }
            read += more.len() as u64;
            self.head.extend_from_slice(&more);
            self.index.read_on(&self.head)?;
        }
        self.decoder.extend_index(&self.index)?;
        Ok(read)
    }

    fn load(&mut self, unit: usize) -> Loaded {
        let refused = |bytes: u64, e: Error| Loaded {
            unit,
            bytes,
            outcome: Err(e),
        };
        let index_read = match self.read_index_through(unit) {
            Ok(read) => read,
            Err(e) => return refused(0, e),
        };
        let entry = self.index.index.units[unit];
        let start = self.payload_start + entry.offset;
        if let Some(size) = self.size.filter(|&size| start + entry.length > size) {
            return refused(
                index_read,
                Error::Truncated(format!(
                    "unit {unit} ends at byte {}, past the stream's end at {size}",
                    start + entry.length
                )),
            );
        }
        // What the head holds is not read again.
        let end = start + entry.length;
        let held = self.head.len() as u64;
        let mut bytes = self.head[start.min(held) as usize..end.min(held) as usize].to_vec();
        let from = start.max(held);
        let mut read = 0;
        if from < end {
            match self.source.read_at(from, end - from) {
                Ok(rest) => {
                    read = rest.len() as u64;
                    bytes.extend_from_slice(&rest);
                }
                Err(e) => return refused(index_read, Error::Io(e)),
            }
        }
        Loaded {
            unit,
            bytes: index_read + read,
            outcome: self.decode(unit, &bytes),
        }
    }

    /// Decodes `unit` from its bytes: what it added, checked.
    fn decode(&mut self, unit: usize, bytes: &[u8]) -> Result<UnitDelta> {
        let header = &self.header;
        let mut added = None;
        self.decoder.decode_unit_then(unit, bytes, &mut |decoded| {
            added = Some(delta(decoded, header)?);
            Ok(())
        })?;
        added.ok_or_else(|| Error::malformed(0, 0, format!("unit {unit} added nothing")))
    }
}

/// What [`Loader::open`] read before the first unit: the header, the index's first entries,
/// the root unit.
pub(super) struct Opened {
    /// The stream's meta-nodes, as its index counts them.
    pub units: usize,
    /// The stream's length as the header and index give it.
    pub stream_bytes: u64,
    /// Bytes read for the header and the index's first entries.
    pub head_bytes: u64,
    pub root: Loaded,
}

/// A unit asked for, with what orders it among the others: its priority (larger first: the
/// screen error of the node waiting for it, never negative, as the bits of an `f64`, which
/// order as the values do), then the order of asking.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Request {
    priority: u64,
    first: std::cmp::Reverse<u64>,
    unit: usize,
}

/// Units asked for and not yet fetched, the most wanted first.
#[derive(Default)]
pub(super) struct Requests {
    heap: std::collections::BinaryHeap<Request>,
    asked: u64,
}

impl Requests {
    fn push(&mut self, unit: usize, priority: f64) {
        self.asked += 1;
        self.heap.push(Request {
            priority: priority.max(0.0).to_bits(),
            first: std::cmp::Reverse(self.asked),
            unit,
        });
    }

    fn pop(&mut self) -> Option<usize> {
        self.heap.pop().map(|r| r.unit)
    }

    fn is_empty(&self) -> bool {
        self.heap.is_empty()
    }
}

/// The loader: a thread reading and decoding units, or a queue worked through inline; either
/// way the units asked for are fetched most wanted first.
pub(super) enum Loader {
    Inline {
        worker: Box<Worker>,
        queue: Requests,
    },
    Background {
        requests: mpsc::Sender<(usize, f64)>,
        results: mpsc::Receiver<Loaded>,
    },
    External {
        worker: Box<Worker>,
        /// Asked for, not yet handed to the caller.
        wanted: Requests,
        /// Supplied by the caller and decoded, not yet collected.
        supplied: Vec<Loaded>,
    },
}

impl Loader {
    /// Reads the header of the stream in `source`, the first entries of its index (`reads` at
    /// a time) and its first (root) unit.
    pub(super) fn open(
        mut source: Box<dyn ByteSource>,
        fetch: Fetch,
        reads: Reads,
    ) -> Result<(Loader, Opened)> {
        let size = source.size();
        // The header's length is known once it parses: read growing prefixes (an external
        // source's bytes all at once: the caller fetched them for this, the whole index with
        // them).
        let mut want = match (fetch, size) {
            (Fetch::External, Some(size)) => size.max(1),
            _ => reads.first.max(1),
        };
        let mut head = Vec::new();
        let mut head_bytes = 0u64;
        let (header, mut index) = loop {
            // Each try reads on from where the last stopped.
            let more = source.read_at(head.len() as u64, want - head.len() as u64)?;
            head_bytes += more.len() as u64;
            let ended = (more.len() as u64) < want - head.len() as u64;
            head.extend_from_slice(&more);
            let parsed = Header::read(&head)
                .and_then(|(header, mut pos)| Ok((header, PartialIndex::start(&head, &mut pos)?)));
            match parsed {
                Ok(parts) => break parts,
                Err(Error::Truncated(_)) if !ended => want *= 4,
                Err(e) => return Err(e),
            }
        };
        index.read_on(&head)?;
        let payload_start = index.payload_start as u64;
        let stream_bytes = payload_start + index.index.payload_bytes;
        // An external source is a prefix: its length says nothing of the stream's, and it
        // holds the whole index.
        if fetch == Fetch::External && !index.is_complete() {
            return Err(Error::Truncated("the stream ends inside its index".into()));
        }
        let size = size.filter(|_| fetch != Fetch::External);
        // The index's bytes must be there before anything is allocated for what it lists.
        if size.is_some_and(|size| size < payload_start) {
            return Err(Error::Truncated("the stream ends inside its index".into()));
        }
        if let Some(extra) = size
            .and_then(|s| s.checked_sub(stream_bytes))
            .filter(|&e| e > 0)
        {
            return Err(Error::malformed(
                index.listed,
                stream_bytes as usize,
                format!("{extra} bytes after the last unit"),
            ));
        }
        let units = index.codec_units(&header);
        if units == 0 {
            return Err(Error::malformed(
                0,
                payload_start as usize,
                "index: a stream with appearance needs a unit of geometry and the appearance unit",
            ));
        }
        // The detached decoder starts from no entry and takes them as they are read.
        let no_entries = Index {
            units: Vec::new(),
            payload_bytes: index.index.payload_bytes,
            appearance: None,
            level_parts: Vec::new(),
        };
        let decoder =
            refining_codec(&header)?.detached(&header, &no_entries, payload_start as usize)?;
        let mut worker = Box::new(Worker {
            source,
            head,
            decoder,
            header: header.clone(),
            index,
            payload_start,
            size,
            index_read: reads.index.max(1),
        });
        // The index lists a unit at least (`Index::read` refuses one that lists none).
        let root = worker.load(0);
        let loader = match fetch {
            Fetch::Inline => Loader::Inline {
                worker,
                queue: Requests::default(),
            },
            Fetch::External => Loader::External {
                worker,
                wanted: Requests::default(),
                supplied: Vec::new(),
            },
            Fetch::Background => {
                let (requests, inbox) = mpsc::channel::<(usize, f64)>();
                let (outbox, results) = mpsc::channel();
                std::thread::Builder::new()
                    .name("came-loader".into())
                    .spawn(move || {
                        // Before each unit, every request that came meanwhile joins the queue,
                        // so the most wanted goes first. Ends when the view-dependent mesh is
                        // dropped (its sender with it).
                        let mut queue = Requests::default();
                        loop {
                            if queue.is_empty() {
                                match inbox.recv() {
                                    Ok((unit, priority)) => queue.push(unit, priority),
                                    Err(_) => break,
                                }
                            }
                            for (unit, priority) in inbox.try_iter() {
                                queue.push(unit, priority);
                            }
                            let Some(unit) = queue.pop() else { continue };
                            if outbox.send(worker.load(unit)).is_err() {
                                break;
                            }
                        }
                    })?;
                Loader::Background { requests, results }
            }
        };
        let opened = Opened {
            units,
            stream_bytes,
            head_bytes,
            root,
        };
        Ok((loader, opened))
    }

    /// Asks for `unit` (once: the caller keeps track), `priority` saying how much it is wanted
    /// (the screen error of the node waiting for it): units waiting are fetched largest first.
    pub fn request(&mut self, unit: usize, priority: f64) {
        match self {
            Loader::Inline { queue, .. } => queue.push(unit, priority),
            Loader::Background { requests, .. } => {
                // A loader thread that ended (it only ends with us) leaves the unit waiting.
                let _ = requests.send((unit, priority));
            }
            Loader::External { wanted, .. } => wanted.push(unit, priority),
        }
    }

    /// The units asked for since the last call, each with its byte range in the stream, most
    /// wanted first (external fetching; none otherwise).
    pub fn take_wanted(&mut self) -> Vec<(usize, std::ops::Range<u64>)> {
        let Loader::External { worker, wanted, .. } = self else {
            return Vec::new();
        };
        std::iter::from_fn(|| wanted.pop())
            .map(|unit| {
                let entry = worker.index.index.units[unit];
                let start = worker.payload_start + entry.offset;
                (unit, start..start + entry.length)
            })
            .collect()
    }

    /// Decodes `bytes`, the caller's fetch of `unit`'s byte range: collected at the next
    /// adaptation, refused there if they are not the unit's bytes (cut, or corrupt).
    pub fn supply(&mut self, unit: usize, bytes: &[u8]) {
        if let Loader::External {
            worker, supplied, ..
        } = self
        {
            let length = worker.index.index.units[unit].length;
            let outcome = if bytes.len() as u64 != length {
                Err(Error::Truncated(format!(
                    "unit {unit} is {length} bytes; {} were supplied",
                    bytes.len()
                )))
            } else {
                worker.decode(unit, bytes)
            };
            supplied.push(Loaded {
                unit,
                bytes: bytes.len() as u64,
                outcome,
            });
        }
    }

    /// The units fetched since the last call: every one asked for when `block`, else what has
    /// arrived. `outstanding` is how many were asked for and not yet handed back.
    pub fn collect(&mut self, outstanding: usize, block: bool) -> Vec<Loaded> {
        match self {
            Loader::Inline { worker, queue } => std::iter::from_fn(|| queue.pop())
                .map(|u| worker.load(u))
                .collect(),
            Loader::External { supplied, .. } => std::mem::take(supplied),
            Loader::Background { results, .. } => {
                let mut out: Vec<Loaded> = results.try_iter().collect();
                while block && out.len() < outstanding {
                    match results.recv() {
                        Ok(loaded) => out.push(loaded),
                        Err(_) => break,
                    }
                }
                out
            }
        }
    }
}
