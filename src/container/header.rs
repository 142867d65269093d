//! The header (FORMAT.md §1): magic, version, codec and its syntax, parameters, grid, counts,
//! and the appearance block (§1.1) that says what appearance the stream carries and where.

use super::*;
use crate::coding::varint;
use crate::error::{Error, Result};
use crate::limits;
use crate::mesh::attribute_quantization::{UvGrid, NORMAL_BITS_RANGE};
use crate::mesh::Grid;

/// What a stream says about itself before its index.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// Which codec wrote the units.
    pub codec_id: u8,
    /// Which of the codec's syntaxes the parameters and units are in (`codecs::for_header`
    /// checks it against the codec's).
    pub syntax: u8,
    /// The syntax's parameters.
    pub params: Vec<u8>,
    /// The quantization grid of the full mesh.
    pub grid: Grid,
    /// Vertices of the full mesh.
    pub vertices: u64,
    /// Triangles of the full mesh.
    pub triangles: u64,
    /// What appearance the stream carries and where (an appearance unit, or the levels), when
    /// it carries any.
    pub appearance: Option<AppearanceSpec>,
}

/// What a stream's appearance unit carries and how it is quantized (docs/FORMAT.md §1.1).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AppearanceSpec {
    /// Qn of the wedges' octahedral normals, when there are normals.
    pub normal_bits: Option<u8>,
    /// The grid of the wedges' uvs, when there are uvs.
    pub uv_grid: Option<UvGrid>,
    /// Whether wedges carry 8-bit RGBA colours.
    pub colours: bool,
    /// The material names faces' ids index, when faces carry materials.
    pub materials: Option<MaterialNames>,
    /// Whether the values are coded inside the codec's own levels, so that every level carries
    /// them (`pm`), rather than in an appearance unit after the last.
    pub in_levels: bool,
    /// Whether the levels carry only which corners share a normal, each level's normals being
    /// derived from its positions (docs/FORMAT.md §6.3; with normals and `in_levels` only).
    pub derived_normals: bool,
    /// Whether the levels' new normals are predicted from the geometry of their vertex's faces
    /// (docs/FORMAT.md §6.3; with normals coded in the levels only).
    pub geometric_normals: bool,
    /// Whether every level is followed by a unit of its own appearance (docs/FORMAT.md §10:
    /// `emc`, `emc-ahead`), rather than the last by the appearance unit.
    pub level_parts: bool,
}

impl AppearanceSpec {
    /// How the stream's normals travel: "derived" (each level derives them from its positions
    /// over the normal groups), "predicted" (values predicted from the geometry of their
    /// vertex's faces), "coded" (values), or `None` without normals.
    pub fn normal_mode(&self) -> Option<&'static str> {
        self.normal_bits?;
        Some(if self.derived_normals {
            "derived"
        } else if self.geometric_normals {
            "predicted"
        } else {
            "coded"
        })
    }
}

/// Material names and the library they come from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MaterialNames {
    /// Names, indexed by material id.
    pub names: Vec<String>,
    /// The material library file (OBJ's `mtllib`), if any.
    pub library: Option<String>,
}

pub(super) const FLAG_NORMALS: u8 = 1;
pub(super) const FLAG_UVS: u8 = 2;
pub(super) const FLAG_COLOURS: u8 = 4;
pub(super) const FLAG_MATERIALS: u8 = 8;
pub(super) const FLAG_IN_LEVELS: u8 = 16;
pub(super) const FLAG_DERIVED_NORMALS: u8 = 32;
pub(super) const FLAG_GEOMETRIC_NORMALS: u8 = 64;
pub(super) const FLAG_LEVEL_PARTS: u8 = 128;

impl AppearanceSpec {
    pub(super) fn write(&self, out: &mut Vec<u8>) {
        let flags = self.normal_bits.map_or(0, |_| FLAG_NORMALS)
            | self.uv_grid.map_or(0, |_| FLAG_UVS)
            | if self.colours { FLAG_COLOURS } else { 0 }
            | self.materials.as_ref().map_or(0, |_| FLAG_MATERIALS)
            | if self.in_levels { FLAG_IN_LEVELS } else { 0 }
            | if self.derived_normals {
                FLAG_DERIVED_NORMALS
            } else {
                0
            }
            | if self.geometric_normals {
                FLAG_GEOMETRIC_NORMALS
            } else {
                0
            }
            | if self.level_parts {
                FLAG_LEVEL_PARTS
            } else {
                0
            };
        out.push(flags);
        if let Some(bits) = self.normal_bits {
            out.push(bits);
        }
        if let Some(grid) = &self.uv_grid {
            out.push(grid.bits);
            for v in grid.origin.iter().chain([&grid.cell]) {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        if let Some(materials) = &self.materials {
            varint::put(out, materials.names.len() as u64);
            for name in materials.names.iter().chain(&materials.library) {
                varint::put(out, name.len() as u64);
                out.extend_from_slice(name.as_bytes());
            }
            if materials.library.is_none() {
                varint::put(out, 0);
            }
        }
    }

    pub(super) fn read(bytes: &[u8], pos: &mut usize) -> Result<AppearanceSpec> {
        let cut = || Error::Truncated("the stream ends inside its header".into());
        let byte = |pos: &mut usize| -> Result<u8> {
            let b = *bytes.get(*pos).ok_or_else(cut)?;
            *pos += 1;
            Ok(b)
        };
        let at = *pos;
        let flags = byte(pos)?;
        let attributes = FLAG_NORMALS | FLAG_UVS | FLAG_COLOURS | FLAG_MATERIALS;
        // Derived normals, or normals predicted from geometry (not both), need normals in the
        // levels.
        let normal_modes = flags & (FLAG_DERIVED_NORMALS | FLAG_GEOMETRIC_NORMALS);
        let bad_mode = normal_modes != 0
            && (normal_modes == FLAG_DERIVED_NORMALS | FLAG_GEOMETRIC_NORMALS
                || flags & (FLAG_NORMALS | FLAG_IN_LEVELS) != FLAG_NORMALS | FLAG_IN_LEVELS);
        // The values travel in the splits (16) or in units after the levels (128), not both.
        let two_places =
            flags & (FLAG_IN_LEVELS | FLAG_LEVEL_PARTS) == FLAG_IN_LEVELS | FLAG_LEVEL_PARTS;
        if flags & attributes == 0 || bad_mode || two_places {
            return Err(Error::malformed(
                0,
                at,
                format!("appearance flags {flags:#04x}"),
            ));
        }
        let mut spec = AppearanceSpec {
            colours: flags & FLAG_COLOURS != 0,
            in_levels: flags & FLAG_IN_LEVELS != 0,
            derived_normals: flags & FLAG_DERIVED_NORMALS != 0,
            geometric_normals: flags & FLAG_GEOMETRIC_NORMALS != 0,
            level_parts: flags & FLAG_LEVEL_PARTS != 0,
            ..AppearanceSpec::default()
        };
        if flags & FLAG_NORMALS != 0 {
            let bits = byte(pos)?;
            if !NORMAL_BITS_RANGE.contains(&bits) {
                return Err(Error::malformed(
                    0,
                    *pos - 1,
                    format!("normals of {bits} bits"),
                ));
            }
            spec.normal_bits = Some(bits);
        }
        if flags & FLAG_UVS != 0 {
            let bits = byte(pos)?;
            let mut floats = [0f64; 3];
            for f in &mut floats {
                let raw = bytes.get(*pos..*pos + 8).ok_or_else(cut)?;
                *f = f64::from_le_bytes(raw.try_into().expect("8 bytes"));
                *pos += 8;
            }
            let grid = UvGrid {
                bits,
                origin: [floats[0], floats[1]],
                cell: floats[2],
            };
            if !grid.is_valid() {
                return Err(Error::malformed(
                    0,
                    *pos - 25,
                    "uv grid: bits, origin or cell size out of range",
                ));
            }
            spec.uv_grid = Some(grid);
        }
        if flags & FLAG_MATERIALS != 0 {
            let count = read_count(bytes, pos, "materials", limits::MAX_MATERIALS)?;
            if count == 0 {
                return Err(Error::malformed(0, *pos, "appearance declares no material"));
            }
            let text = |pos: &mut usize| -> Result<String> {
                let at = *pos;
                let len = read_count(bytes, pos, "name bytes", limits::MAX_NAME_BYTES)? as usize;
                let raw = bytes.get(*pos..*pos + len).ok_or_else(cut)?;
                *pos += len;
                String::from_utf8(raw.to_vec())
                    .map_err(|_| Error::malformed(0, at, "a material name is not UTF-8"))
            };
            // Names take at least a byte each: no allocation beyond what the bytes hold.
            if ((bytes.len() - *pos) as u64) < count {
                return Err(cut());
            }
            let names = (0..count).map(|_| text(pos)).collect::<Result<_>>()?;
            let library = Some(text(pos)?).filter(|l| !l.is_empty());
            spec.materials = Some(MaterialNames { names, library });
        }
        Ok(spec)
    }
}

impl Header {
    /// True when the index's last unit is the appearance unit (docs/FORMAT.md §1.1): the
    /// stream carries appearance outside its levels.
    pub fn has_appearance_unit(&self) -> bool {
        self.appearance
            .as_ref()
            .is_some_and(|a| !a.in_levels && !a.level_parts)
    }

    /// True when every level is followed by a unit of its appearance (docs/FORMAT.md §10).
    pub fn has_level_parts(&self) -> bool {
        self.appearance.as_ref().is_some_and(|a| a.level_parts)
    }

    /// Appends the header's bytes to `out`.
    pub fn write(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&MAGIC);
        out.push(FORMAT_VERSION);
        out.push(self.codec_id);
        out.push(self.syntax);
        varint::put(out, self.params.len() as u64);
        out.extend_from_slice(&self.params);
        out.push(self.grid.bits);
        for v in self.grid.origin.iter().chain(&self.grid.cell) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        varint::put(out, self.vertices);
        varint::put(out, self.triangles);
        match &self.appearance {
            Some(appearance) => appearance.write(out),
            None => out.push(0),
        }
    }

    /// Reads a header from the start of `bytes`; returns it and the offset of the index.
    pub fn read(bytes: &[u8]) -> Result<(Header, usize)> {
        let cut = || Error::Truncated("the stream ends inside its header".into());
        let bad = |byte: usize, what: &str| Error::malformed(0, byte, what);
        if bytes.len() < MAGIC.len() {
            return Err(cut());
        }
        if bytes[..4] != MAGIC {
            return Err(bad(0, "not a meshcodec stream (bad magic)"));
        }
        let version = *bytes.get(4).ok_or_else(cut)?;
        if version != FORMAT_VERSION {
            let earlier = if (2..FORMAT_VERSION).contains(&version) {
                "; re-encode the mesh with this build"
            } else {
                ""
            };
            return Err(Error::Unsupported(format!(
                "stream format version {version} (this build reads version {FORMAT_VERSION}{earlier})"
            )));
        }
        let codec_id = *bytes.get(5).ok_or_else(cut)?;
        let syntax = *bytes.get(6).ok_or_else(cut)?;
        let mut pos = 7;
        let param_len = read_count(bytes, &mut pos, "parameter bytes", limits::MAX_PARAM_BYTES)?;
        let params = bytes
            .get(pos..pos + param_len as usize)
            .ok_or_else(cut)?
            .to_vec();
        pos += param_len as usize;
        let bits = *bytes.get(pos).ok_or_else(cut)?;
        if bits == 0 || bits > crate::mesh::quantize::MAX_QUANT_BITS {
            return Err(bad(pos, &format!("quantization of {bits} bits")));
        }
        pos += 1;
        let mut floats = [0f64; 6];
        for f in &mut floats {
            let raw = bytes.get(pos..pos + 8).ok_or_else(cut)?;
            *f = f64::from_le_bytes(raw.try_into().expect("8 bytes"));
            pos += 8;
        }
        let grid = Grid {
            origin: [floats[0], floats[1], floats[2]],
            cell: [floats[3], floats[4], floats[5]],
            bits,
        };
        let far_corner_finite =
            (0..3).all(|a| (grid.origin[a] + grid.cell[a] * (1u64 << bits) as f64).is_finite());
        if !floats.iter().all(|f| f.is_finite())
            || !grid.cell.iter().all(|&c| c > 0.0)
            || !far_corner_finite
        {
            return Err(bad(
                pos - 48,
                "grid origin or cell size is not a finite positive number",
            ));
        }
        let vertices = read_count(bytes, &mut pos, "vertices", limits::MAX_VERTICES)?;
        let triangles = read_count(bytes, &mut pos, "triangles", limits::MAX_TRIANGLES)?;
        if vertices == 0 || triangles == 0 {
            // No encoder writes an empty mesh (empty input is refused before encoding).
            return Err(bad(
                pos,
                &format!("header declares {vertices} vertices and {triangles} triangles"),
            ));
        }
        let appearance = match bytes.get(pos).ok_or_else(cut)? {
            0 => {
                pos += 1;
                None
            }
            _ => Some(AppearanceSpec::read(bytes, &mut pos)?),
        };
        let header = Header {
            codec_id,
            syntax,
            params,
            grid,
            vertices,
            triangles,
            appearance,
        };
        Ok((header, pos))
    }
}
