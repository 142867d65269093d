//! Line-oriented parsing shared by the text formats that have no crate of their own (OFF, `.m`).

use crate::error::{Error, Result};

/// Non-blank lines with their 1-based numbers, `#` comments removed.
pub fn content_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines().enumerate().filter_map(|(i, line)| {
        let line = line.split('#').next().unwrap_or("").trim();
        (!line.is_empty()).then_some((i + 1, line))
    })
}

/// Parses a number token, naming the line and what it should have been.
pub fn number<T: std::str::FromStr>(token: Option<&str>, line: usize, what: &str) -> Result<T> {
    let token = token.ok_or_else(|| Error::mesh_at(line, format!("missing {what}")))?;
    token
        .parse()
        .map_err(|_| Error::mesh_at(line, format!("{what} '{token}' is not a number")))
}

/// The bytes as UTF-8 text (lossy: a stray byte in a comment is no reason to refuse a file).
pub fn as_text(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(bytes)
}

/// Triangulates a polygon (vertex list) as a fan around its first corner.
pub fn fan(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    for k in 1..polygon.len().saturating_sub(1) {
        out.push([polygon[0], polygon[k], polygon[k + 1]]);
    }
}
