//! docs/FORMAT.md kept true: the format version, the codec ids and each codec's syntax number
//! it states are those the code writes, and its golden folder and newest History row name the
//! same version.

use meshcodec::codecs;
use meshcodec::container::FORMAT_VERSION;
use std::path::Path;

fn format_md() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/FORMAT.md"))
        .expect("docs/FORMAT.md")
}

/// The text between `start` and the next `end` after it.
fn between<'a>(text: &'a str, start: &str, end: &str) -> &'a str {
    let from = text
        .find(start)
        .unwrap_or_else(|| panic!("FORMAT.md no longer says {start:?}"))
        + start.len();
    let to = text[from..].find(end).expect("its end") + from;
    &text[from..to]
}

#[test]
fn the_format_version_stated_is_the_one_written() {
    let doc = format_md();
    let v = FORMAT_VERSION.to_string();
    assert_eq!(
        between(&doc, "# The meshcodec bitstream, format version ", "\n"),
        v
    );
    assert_eq!(
        between(&doc, "| version | u8 | format version: **", "**"),
        v
    );
    assert_eq!(between(&doc, "(this build reads version ", " "), v);
    assert_eq!(between(&doc, "`tests/golden/v", "/`"), v);
    assert!(Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("tests/golden/v{v}"))
        .is_dir());
    // The newest History row is this version's.
    let history = &doc[doc.find("## History").expect("a History")..];
    let last_row = history
        .lines()
        .rfind(|l| l.starts_with("| ") && !l.starts_with("| version"))
        .expect("a row");
    assert_eq!(between(last_row, "| ", " |"), v, "{last_row}");
}

#[test]
fn codec_ids_and_syntaxes_stated_are_those_of_the_code() {
    let doc = format_md();
    let ids = between(&doc, "| codec | u8 | codec id: ", " (");
    let mut listed = 0;
    for entry in ids.split(", ") {
        let (id, name) = entry.split_once(' ').expect("id `name`");
        let name = name.trim_matches('`');
        let codec = codecs::by_name(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(codec.id().to_string(), id, "{name}");
        listed += 1;
    }
    assert_eq!(listed, codecs::registry().len(), "FORMAT.md lists {ids}");
    let syntax_row = between(&doc, "| syntax | u8 |", "\n");
    let came = between(syntax_row, "**", "** for `came`");
    let others = between(syntax_row, "; its syntaxes", " for every other codec");
    for codec in codecs::registry() {
        let stated = if codec.name() == "came" {
            came
        } else {
            between(others, "**", "**")
        };
        assert_eq!(codec.syntax().to_string(), stated, "{}", codec.name());
    }
}
