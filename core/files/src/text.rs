//! Text from outside (logs, exports, calibration files, model metadata): how it is accepted and
//! how it is quoted back.
//!
//! * A UTF-8 byte-order mark at the start is part of the encoding, not of the text: editors on
//!   Windows and some exporters write one ([`strip_bom`]).
//! * An error message quotes what it could not read, but only an excerpt ([`excerpt`]): a
//!   one-megabyte "tag" must not become a one-megabyte message, and control characters are
//!   escaped so that a terminal shows them as text.
//! * Text shown on screen (a title, an annotation) is cut to a length ([`truncate_chars`]),
//!   not quoted.

/// The UTF-8 byte-order mark, U+FEFF.
pub const BOM: char = '\u{feff}';

/// `text` without a leading byte-order mark.
pub fn strip_bom(text: &str) -> &str {
    text.strip_prefix(BOM).unwrap_or(text)
}

/// Most characters an excerpt quotes.
pub const EXCERPT_CHARS: usize = 40;

/// `text` quoted for a message: debug-escaped (control characters and quotes visible), at most
/// [`EXCERPT_CHARS`] characters of it, with `…` and the full length when cut.
pub fn excerpt(text: &str) -> String {
    let n = text.chars().count();
    if n <= EXCERPT_CHARS {
        format!("{text:?}")
    } else {
        let head: String = text.chars().take(EXCERPT_CHARS).collect();
        format!("{head:?}… ({n} characters)")
    }
}

/// `text` cut after `max_chars` characters, with `…` where it was cut.
pub fn truncate_chars(text: &str, max_chars: usize) -> String {
    match text.char_indices().nth(max_chars) {
        Some((end, _)) => format!("{}…", &text[..end]),
        None => text.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_megabyte_is_quoted_as_forty_characters() {
        let long = "x".repeat(1 << 20);
        let quoted = excerpt(&long);
        assert!(quoted.len() < 80, "{quoted}");
        assert!(quoted.contains("1048576 characters"));
        assert_eq!(excerpt("acc\u{1b}[2J"), "\"acc\\u{1b}[2J\"");
        assert_eq!(strip_bom("\u{feff}phantogram"), "phantogram");
        assert_eq!(strip_bom("phantogram"), "phantogram");
        assert_eq!(truncate_chars("émail", 3), "éma…");
        assert_eq!(truncate_chars("émail", 5), "émail");
    }
}
