//! meshcodec in JavaScript: the codec core's decoders compiled to WebAssembly, with
//! wasm-bindgen bindings shaped like the ecosystem's mesh decoders (Draco's `DecoderModule`,
//! meshoptimizer's `MeshoptDecoder`): bytes in, typed arrays out.
//!
//! `bash web/build.sh` writes `web/pkg/meshcodec.js` (an ES module: `await init({module_or_path})`,
//! then the functions), its `.wasm` and TypeScript types; Node 20 and browsers load the same
//! files. Errors are JavaScript `Error`s carrying the library's one-line message
//! (docs/CONTRACT.md §7) and a `code`; a corrupt or cut stream ends in one, never in a trap.
//!
//! These are the raw bindings: web/index.js is the package's API over them (options objects,
//! every argument validated, `MeshcodecError`), with its TypeScript declarations in
//! web/index.d.ts.

use glam::DVec3;
use js_sys::{Array, Float32Array, Float64Array, Object, Reflect, Uint32Array};
use meshcodec::codecs::came::refine::{head_length, Budget, Camera, Fetch, View, ViewMesh};
use meshcodec::codecs::{self, LevelMesh, Progressive, Stop};
use meshcodec::container::Header;
use meshcodec::mesh::attributes::Attributes;
use wasm_bindgen::prelude::*;

/// What every binding returns: its value, or a JavaScript `Error` with a `code`.
type JsResult<T> = Result<T, JsValue>;

/// A JavaScript `Error` named `MeshcodecError` with its one-line `message` and a `code` saying
/// what kind of fault it is (`corrupt`, `truncated`, `unsupported`, `limit`, `invalid-mesh`,
/// `io`, `internal`): what the package's `MeshcodecError` carries (web/index.js).
fn error(code: &str, message: &str) -> JsValue {
    let e = js_sys::Error::new(&message.replace(['\n', '\t'], " "));
    e.set_name("MeshcodecError");
    // Setting a property on a fresh Error cannot fail.
    let _ = Reflect::set(&e, &JsValue::from_str("code"), &JsValue::from_str(code));
    e.into()
}

/// A library error as a JavaScript one, its code from the library's kind of error.
fn to_js(e: meshcodec::Error) -> JsValue {
    use meshcodec::Error as E;
    let code = match &e {
        E::Malformed { .. } => "corrupt",
        E::Truncated(_) => "truncated",
        E::Unsupported(_) => "unsupported",
        E::Limit(_) => "limit",
        E::InvalidMesh(_) => "invalid-mesh",
        E::Io(_) => "io",
    };
    error(code, &e.to_string())
}

fn set(object: &Object, key: &str, value: impl Into<JsValue>) -> JsResult<()> {
    Reflect::set(object, &JsValue::from_str(key), &value.into())
        .map(|_| ())
        .map_err(|_| error("internal", &format!("cannot set {key}")))
}

/// A level's appearance as Hoppe's wedges, the library's own values: `corners` (Uint32Array, the
/// wedge of each face corner, face by face), `wedgeVertex` (Uint32Array, each wedge's vertex),
/// and where the stream carries them `normals` (Float64Array, x, y, z a wedge), `uvs` (u, v a
/// wedge), `colours` (r, g, b, a in [0, 1] a wedge), `materials` ({`face`: Uint32Array of each
/// face's material, `names`: an Array of strings}).
fn appearance_object(a: &Attributes) -> JsResult<Object> {
    let object = Object::new();
    let corners: Vec<u32> = a.corners.iter().flatten().copied().collect();
    set(&object, "corners", Uint32Array::from(corners.as_slice()))?;
    set(
        &object,
        "wedgeVertex",
        Uint32Array::from(a.wedge_vertex.as_slice()),
    )?;
    if let Some(normals) = &a.normals {
        let flat: Vec<f64> = normals.iter().flat_map(|n| [n.x, n.y, n.z]).collect();
        set(&object, "normals", Float64Array::from(flat.as_slice()))?;
    }
    if let Some(uvs) = &a.uvs {
        let flat: Vec<f64> = uvs.iter().flat_map(|t| [t.x, t.y]).collect();
        set(&object, "uvs", Float64Array::from(flat.as_slice()))?;
    }
    if let Some(colours) = &a.colours {
        let flat: Vec<f64> = colours.iter().flatten().copied().collect();
        set(&object, "colours", Float64Array::from(flat.as_slice()))?;
    }
    if let Some(materials) = &a.materials {
        let m = Object::new();
        set(&m, "face", Uint32Array::from(materials.face.as_slice()))?;
        let names = Array::new();
        for name in &materials.names {
            names.push(&JsValue::from_str(name));
        }
        set(&m, "names", names)?;
        set(&object, "materials", m)?;
    }
    Ok(object)
}

/// Positions as x, y, z: a Float64Array (the library's own values), or a Float32Array (for GPU
/// upload, rounded once here).
fn positions_array(positions: &[DVec3], float32: bool) -> JsValue {
    if float32 {
        let flat: Vec<f32> = positions
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
            .collect();
        Float32Array::from(flat.as_slice()).into()
    } else {
        let flat: Vec<f64> = positions.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        Float64Array::from(flat.as_slice()).into()
    }
}

/// A decoded level as a plain object: `positions` (Float64Array of x, y, z, or Float32Array), `indices`
/// (Uint32Array of triangle corners), `level`, `levels`, `codec`, `vertices`, `triangles`,
/// `meshVertices` (of the full mesh), and `appearance` where the level carries normals, uvs,
/// colours or materials ([`appearance_object`]; `null` otherwise).
fn level_object(
    mesh: &LevelMesh,
    level: usize,
    levels: usize,
    header: &Header,
    float32: bool,
) -> JsResult<Object> {
    let codec = codecs::by_id(header.codec_id).map_err(to_js)?.name();
    let indices: Vec<u32> = mesh.mesh.faces.iter().flatten().copied().collect();
    let object = Object::new();
    set(
        &object,
        "positions",
        positions_array(&mesh.mesh.positions, float32),
    )?;
    set(&object, "indices", Uint32Array::from(indices.as_slice()))?;
    set(&object, "level", level as u32)?;
    set(&object, "levels", levels as u32)?;
    set(&object, "codec", codec)?;
    set(&object, "vertices", mesh.mesh.positions.len() as u32)?;
    set(&object, "triangles", mesh.mesh.faces.len() as u32)?;
    set(&object, "meshVertices", header.vertices as f64)?;
    let appearance = match &mesh.attributes {
        Some(a) if !a.is_empty() => appearance_object(a)?.into(),
        _ => JsValue::NULL,
    };
    set(&object, "appearance", appearance)?;
    Ok(object)
}

/// Decodes a stream, or the levels a prefix of it holds: every level, or the first `level`
/// levels, of the first `nbytes` bytes (all when absent); positions as a Float32Array when
/// `float32`. Arguments are taken as they come: web/index.js's `decode` validates them.
#[wasm_bindgen]
pub fn decode(
    bytes: &[u8],
    level: Option<u32>,
    nbytes: Option<u32>,
    float32: Option<bool>,
) -> JsResult<Object> {
    let prefix = &bytes[..nbytes.map_or(bytes.len(), |n| (n as usize).min(bytes.len()))];
    let stop = level.map_or(Stop::All, |l| Stop::Levels(l as usize));
    let mut decoder = codecs::open(prefix).map_err(to_js)?;
    let levels = decoder.levels();
    let (mesh, decoded) = codecs::decode_with(decoder.as_mut(), stop).map_err(to_js)?;
    if mesh.mesh.positions.is_empty() {
        return Err(error(
            "truncated",
            &format!("the first {} bytes hold no complete level", prefix.len()),
        ));
    }
    let header = decoder.header().clone();
    level_object(&mesh, decoded, levels, &header, float32.unwrap_or(false))
}

/// The byte each level of a stream ends at, from a prefix holding its header and index.
#[wasm_bindgen(js_name = levelEnds)]
pub fn level_ends(bytes: &[u8]) -> JsResult<Vec<f64>> {
    Ok(codecs::level_ends(bytes)
        .map_err(to_js)?
        .into_iter()
        .map(|end| end as f64)
        .collect())
}

/// What a stream's header and index say, without decoding it: the library's `StreamInfo`
/// (`codec`, `formatVersion`, `syntax`, `bytes`, `streamBytes`, `truncated`, `quantBits`,
/// `origin`, `cell`, `vertices`, `triangles`, `levels`, `levelEnds`, `payloadStart`, `layered`,
/// `units` with each one's byte range, `appearance` or null, `vertexCopies`, `normalCones`): the
/// keys of `meshcodec info --json` and of the Python package's `info`, in camelCase.
#[wasm_bindgen]
pub fn info(bytes: &[u8]) -> JsResult<JsValue> {
    let info = codecs::StreamInfo::of(bytes).map_err(to_js)?;
    let value = serde_json::to_value(&info).map_err(|e| error("internal", &e.to_string()))?;
    js_value(&value)
}

/// A JSON value as a JavaScript one, its objects' keys in camelCase.
fn js_value(value: &serde_json::Value) -> JsResult<JsValue> {
    use serde_json::Value;
    Ok(match value {
        Value::Null => JsValue::NULL,
        Value::Bool(b) => JsValue::from_bool(*b),
        Value::Number(n) => JsValue::from_f64(n.as_f64().unwrap_or(f64::NAN)),
        Value::String(s) => JsValue::from_str(s),
        Value::Array(items) => {
            let array = Array::new();
            for item in items {
                array.push(&js_value(item)?);
            }
            array.into()
        }
        Value::Object(map) => {
            let object = Object::new();
            for (key, item) in map {
                set(&object, &camel_case(key), js_value(item)?)?;
            }
            object.into()
        }
    })
}

/// `snake_case` as `camelCase`.
fn camel_case(key: &str) -> String {
    let mut out = String::with_capacity(key.len());
    let mut upper = false;
    for c in key.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// A decoder fed a stream's bytes as they arrive (the chunks of `fetch()`'s `ReadableStream`):
/// each `push` returns the newest level its bytes completed, if any. Every codec's stream is
/// decoded once, each level going on from the last (`incremental` says so).
#[wasm_bindgen]
pub struct ProgressiveDecoder {
    inner: Progressive,
    float32: bool,
}

#[wasm_bindgen]
impl ProgressiveDecoder {
    /// A decoder with no bytes yet; its levels' positions as a Float32Array when `float32`.
    #[wasm_bindgen(constructor)]
    pub fn new(float32: Option<bool>) -> ProgressiveDecoder {
        ProgressiveDecoder {
            inner: Progressive::new(),
            float32: float32.unwrap_or(false),
        }
    }

    /// Takes the next chunk; returns the newest level now complete (a level object as
    /// `decode` returns), or `undefined` when the chunk completed none. Levels completed by
    /// the same chunk are handed over as one, the newest.
    pub fn push(&mut self, chunk: &[u8]) -> JsResult<JsValue> {
        let Some((mesh, level)) = self.inner.push(chunk).map_err(to_js)? else {
            return Ok(JsValue::UNDEFINED);
        };
        if mesh.mesh.positions.is_empty() {
            return Err(error(
                "truncated",
                &format!(
                    "the first {} bytes hold no complete level",
                    self.inner.received()
                ),
            ));
        }
        let header = self
            .inner
            .header()
            .ok_or_else(|| error("internal", "a level before the header"))?;
        Ok(level_object(&mesh, level, self.inner.levels(), header, self.float32)?.into())
    }

    /// Bytes taken so far.
    #[wasm_bindgen(getter)]
    pub fn received(&self) -> f64 {
        self.inner.received() as f64
    }

    /// Levels the stream holds (0 until its header and index are in).
    #[wasm_bindgen(getter)]
    pub fn levels(&self) -> u32 {
        self.inner.levels() as u32
    }

    /// Levels handed over so far.
    #[wasm_bindgen(getter)]
    pub fn level(&self) -> u32 {
        self.inner.level() as u32
    }

    /// Whether each level is decoded once, going on from the last (else from the first level
    /// at each hand-over).
    #[wasm_bindgen(getter)]
    pub fn incremental(&self) -> bool {
        self.inner.incremental()
    }
}

/// A `came` stream refined to a camera, its meta-nodes fetched by the caller (a browser's
/// `Range` requests): made from the stream's first bytes (`cameHeadLength` says how many), it
/// adapts to a camera with the units at hand, lists the units it wants as byte ranges
/// (`wanted`), takes their bytes (`supply`) and adapts again.
#[wasm_bindgen]
pub struct CameView {
    mesh: ViewMesh,
}

/// How many of a `came` stream's first bytes `new CameView` needs (header, index, first unit),
/// or `undefined` while `prefix` is too short to say (fetch a longer one).
#[wasm_bindgen(js_name = cameHeadLength)]
pub fn came_head_length(prefix: &[u8]) -> JsResult<Option<f64>> {
    Ok(head_length(prefix).map_err(to_js)?.map(|n| n as f64))
}

fn vector(v: &[f64], name: &str) -> JsResult<DVec3> {
    match v {
        [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(error(
            "invalid-argument",
            &format!("{name}: three numbers expected"),
        )),
    }
}

#[wasm_bindgen]
impl CameView {
    /// The front at the root, from the stream's first `cameHeadLength(…)` bytes (or more).
    #[wasm_bindgen(constructor)]
    pub fn new(head: &[u8]) -> JsResult<CameView> {
        let mesh = ViewMesh::open(head.to_vec(), Fetch::External).map_err(to_js)?;
        Ok(CameView { mesh })
    }

    /// Adapts to a camera (`eye`, `target`, `up` as [x, y, z]; vertical field of view in
    /// degrees; viewport in pixels) at `tolerance` pixels, with the units supplied so far;
    /// `twoSided` refines faces turned away too. Returns `{splits, collapses, waiting,
    /// settled, faces, vertices}`; `waiting` splits wait for the units `wanted` lists.
    #[allow(clippy::too_many_arguments)]
    pub fn adapt(
        &mut self,
        eye: &[f64],
        target: &[f64],
        up: &[f64],
        fov_degrees: f64,
        width: u32,
        height: u32,
        tolerance: f64,
        two_sided: bool,
    ) -> JsResult<Object> {
        let camera = Camera {
            eye: vector(eye, "eye")?,
            target: vector(target, "target")?,
            up: vector(up, "up")?,
            fov_degrees,
            width,
            height,
        };
        let view = View::new(&camera, tolerance)
            .map_err(to_js)?
            .two_sided(two_sided);
        let done = self.mesh.adapt(&view, Budget::UNLIMITED);
        let object = Object::new();
        set(&object, "splits", done.splits as f64)?;
        set(&object, "collapses", done.collapses as f64)?;
        set(&object, "waiting", done.waiting as f64)?;
        set(&object, "settled", done.settled)?;
        set(&object, "faces", self.mesh.face_count() as f64)?;
        set(&object, "vertices", self.mesh.vertex_count() as f64)?;
        Ok(object)
    }

    /// The units the adaptations asked for since the last call, as `[unit, firstByte,
    /// endByte, …]` (byte offsets in the stream, the end exclusive), in the order asked.
    pub fn wanted(&mut self) -> Float64Array {
        let flat: Vec<f64> = self
            .mesh
            .wanted()
            .into_iter()
            .flat_map(|(unit, range)| [unit as f64, range.start as f64, range.end as f64])
            .collect();
        Float64Array::from(flat.as_slice())
    }

    /// Hands over unit `unit`'s bytes, as `wanted` asked: decoded now, taken in at the next
    /// `adapt` (refused there, its branch left coarse, if cut or corrupt). An `Error` if the
    /// unit was not asked for or was supplied already.
    pub fn supply(&mut self, unit: u32, bytes: &[u8]) -> JsResult<()> {
        self.mesh.supply(unit as usize, bytes).map_err(to_js)
    }

    /// The adapted mesh: `{positions: Float64Array (Float32Array when `float32`), indices:
    /// Uint32Array, vertices, triangles}`.
    pub fn mesh(&self, float32: Option<bool>) -> JsResult<Object> {
        let mesh = self.mesh.mesh();
        let indices: Vec<u32> = mesh.faces.iter().flatten().copied().collect();
        let object = Object::new();
        set(
            &object,
            "positions",
            positions_array(&mesh.positions, float32.unwrap_or(false)),
        )?;
        set(&object, "indices", Uint32Array::from(indices.as_slice()))?;
        set(&object, "vertices", mesh.positions.len() as f64)?;
        set(&object, "triangles", mesh.faces.len() as f64)?;
        Ok(object)
    }

    /// What has been fetched: `{bytesRead, streamBytes, unitsLoaded, unitsRefused, units}`
    /// (bytes read: the first bytes and every unit supplied).
    pub fn fetched(&self) -> JsResult<Object> {
        let f = self.mesh.fetched();
        let object = Object::new();
        set(&object, "bytesRead", f.bytes_read as f64)?;
        set(&object, "streamBytes", f.stream_bytes as f64)?;
        set(&object, "unitsLoaded", f.units_loaded as f64)?;
        set(&object, "unitsRefused", f.units_refused as f64)?;
        set(&object, "units", f.units as f64)?;
        Ok(object)
    }
}
