//! What the two binaries share: how they end (one line on stderr, exit status 1), how they
//! write to standard output, and how they parse the options both take.

use meshcodec::mesh::quantize::GridShape;

/// Ends a binary: exit status 0, or 1 with the error on one line of stderr (docs/CONTRACT.md §7),
/// whatever line breaks the error's text holds; an unknown codec name is followed by the list
/// of codecs.
pub fn exit_code(outcome: anyhow::Result<()>) -> std::process::ExitCode {
    match outcome {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let message = format!("{e:#}").replace(['\n', '\t'], " ");
            eprintln!("error: {message}");
            if e.chain().any(|cause| cause.is::<UnknownCodec>()) {
                eprint!("{}", codec_list(None));
            }
            std::process::ExitCode::FAILURE
        }
    }
}

/// A codec name that names no codec of this build: the binaries list the codecs after the
/// error line.
#[derive(Debug)]
pub struct UnknownCodec(meshcodec::Error);

impl std::fmt::Display for UnknownCodec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for UnknownCodec {}

/// The codec called `name`, for the binaries: an unknown name is an [`UnknownCodec`].
pub fn codec_by_name(name: &str) -> Result<&'static dyn meshcodec::codecs::Codec, UnknownCodec> {
    meshcodec::codecs::by_name(name).map_err(UnknownCodec)
}

/// Every codec of this build, one line each with what it is, under a heading: for `--help` and
/// after an unknown codec name; `default` is marked as such.
pub fn codec_list(default: Option<&str>) -> String {
    let codecs = meshcodec::codecs::registry();
    let width = codecs.iter().map(|c| c.name().len()).max().unwrap_or(0);
    let mut text = String::from("Codecs:\n");
    for codec in codecs {
        let marker = if Some(codec.name()) == default {
            " (default)"
        } else {
            ""
        };
        text.push_str(&format!(
            "  {:width$}  {}{marker}\n",
            codec.name(),
            codec.summary()
        ));
    }
    text
}

/// Writes `text` to standard output for a binary. A reader that has gone away (`meshcodec info
/// s.mc | head -1`) is not an error: the rest is dropped, where `println!` would panic.
pub fn write_stdout(text: &str) -> std::io::Result<()> {
    use std::io::Write as _;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => other,
    }
}

/// `println!` for the binaries, through [`write_stdout`]; use inside a function returning a
/// `Result` whose error takes an `std::io::Error`.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::write_stdout(&format!("{}\n", format_args!($($arg)*)))?
    };
}

/// Parses a point or direction `x,y,z`.
pub fn parse_vector(s: &str) -> Result<glam::DVec3, String> {
    let parts: Vec<Result<f64, _>> = s.split(',').map(|x| x.trim().parse::<f64>()).collect();
    match parts.as_slice() {
        [Ok(x), Ok(y), Ok(z)] if x.is_finite() && y.is_finite() && z.is_finite() => {
            Ok(glam::DVec3::new(*x, *y, *z))
        }
        _ => Err(format!("'{s}' is no x,y,z of three numbers")),
    }
}

/// Parses a viewport `WxH` in pixels (each 1..=16384).
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("'{s}' is no WIDTHxHEIGHT in pixels (each 1 to 16384)");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    if !(1..=16384).contains(&w) || !(1..=16384).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

/// Parses `--grid`: `cubic` or `per-axis`.
pub fn parse_grid(s: &str) -> Result<GridShape, String> {
    match s {
        "cubic" => Ok(GridShape::Cubic),
        "per-axis" => Ok(GridShape::PerAxis),
        _ => Err(format!("unknown grid '{s}' (cubic, per-axis)")),
    }
}
