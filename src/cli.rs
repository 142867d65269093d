//! What the two binaries share: how they end (one line on stderr, exit status 1), how they
//! write to standard output, and how they parse the options both take.

use crate::mesh::quantize::GridShape;

/// Ends a binary: exit status 0, or 1 with the error on one line of stderr (docs/CONTRACT.md §7),
/// whatever line breaks the error's text holds.
pub fn exit_code(outcome: anyhow::Result<()>) -> std::process::ExitCode {
    match outcome {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            let message = format!("{e:#}").replace(['\n', '\t'], " ");
            eprintln!("error: {message}");
            std::process::ExitCode::FAILURE
        }
    }
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

/// Parses `--grid`: `cubic` or `per-axis`.
pub fn parse_grid(s: &str) -> Result<GridShape, String> {
    match s {
        "cubic" => Ok(GridShape::Cubic),
        "per-axis" => Ok(GridShape::PerAxis),
        _ => Err(format!("unknown grid '{s}' (cubic, per-axis)")),
    }
}
