//! Text that comes from a log (firmware version, configuration lines) is
//! data, not terminal commands: control characters are shown escaped, so an
//! ESC sequence in a log cannot clear, retitle or recolour a screen.

use std::borrow::Cow;

/// `text` with every control character (C0, DEL, C1) and every
/// bidirectional formatting character (U+202A-U+202E, U+2066-U+2069, which
/// reorder what a terminal shows) written as `\u{..}` (tab, newline and
/// carriage return as `\t`, `\n`, `\r`); other text as is.
#[must_use]
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    if !text.chars().any(needs_escape) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if needs_escape(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

fn needs_escape(c: char) -> bool {
    c.is_control() || matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}')
}

/// JSON text with the characters [`escape_controls`] escapes that JSON
/// leaves as they are (DEL, C1 controls, bidirectional formatting) written
/// as `\uXXXX` escapes: the same JSON value, safe to print on a terminal.
/// (Outside strings JSON text is ASCII, so every such character is inside
/// a string, where a `\u` escape means that character.)
#[must_use]
pub fn json_terminal_safe(json: String) -> String {
    if !json.chars().any(needs_escape) {
        return json;
    }
    use std::fmt::Write;
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        // Raw newlines, returns and tabs are JSON's whitespace between values.
        if needs_escape(c) && !matches!(c, '\n' | '\r' | '\t') {
            let _ = write!(out, "\\u{:04x}", u32::from(c));
        } else {
            out.push(c);
        }
    }
    out
}

/// `value` as one line of JSON and a newline, written to `out` as it is
/// serialised (a campaign's kicks make tens of megabytes: never held whole),
/// with the characters [`json_terminal_safe`] escapes escaped the same way.
///
/// # Errors
/// What writing to `out` returns, or a value that is not JSON.
pub fn write_json_line<W: std::io::Write>(
    mut out: W,
    value: &impl serde::Serialize,
) -> std::io::Result<()> {
    let mut ser = serde_json::Serializer::with_formatter(&mut out, TerminalSafe);
    value.serialize(&mut ser)?;
    out.write_all(b"\n")?;
    out.flush()
}

/// serde_json's compact format with [`needs_escape`] characters in strings
/// written as `\uXXXX` (serde_json escapes C0 itself; these are DEL, C1
/// and bidirectional formatting, which it leaves as they are).
struct TerminalSafe;

impl serde_json::ser::Formatter for TerminalSafe {
    fn write_string_fragment<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        fragment: &str,
    ) -> std::io::Result<()> {
        let mut rest = fragment;
        while let Some((i, c)) = rest.char_indices().find(|&(_, c)| needs_escape(c)) {
            writer.write_all(&rest.as_bytes()[..i])?;
            write!(writer, "\\u{:04x}", u32::from(c))?;
            rest = &rest[i + c.len_utf8()..];
        }
        writer.write_all(rest.as_bytes())
    }
}

/// A file name as messages show it: [`escape_controls`] of its text, so a
/// name cannot forge lines or send a terminal commands.
#[must_use]
pub fn shown(path: impl AsRef<std::path::Path>) -> String {
    escape_controls(&path.as_ref().to_string_lossy()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_streamed_json_line_escapes_what_a_terminal_obeys() {
        let mut out = Vec::new();
        write_json_line(
            &mut out,
            &serde_json::json!({ "a\u{9b}": "x\u{7f}\u{1b}y\u{202e}é" }),
        )
        .unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "{\"a\\u009b\":\"x\\u007f\\u001by\\u202eé\"}\n"
        );
    }

    #[test]
    fn escape_sequences_are_shown_not_obeyed() {
        assert_eq!(escape_controls("fw 1.0"), "fw 1.0");
        assert_eq!(escape_controls("a\u{1b}[2Jb"), "a\\u{1b}[2Jb");
        assert_eq!(escape_controls("x\u{9b}y\u{7f}\n"), "x\\u{9b}y\\u{7f}\\n");
        assert_eq!(escape_controls("µ°é"), "µ°é");
        assert_eq!(escape_controls("a\u{202e}b"), "a\\u{202e}b");
        assert_eq!(
            shown(std::path::Path::new("x\n\u{7}.WBL")),
            "x\\n\\u{7}.WBL"
        );
    }

    proptest! {
        #[test]
        fn no_control_character_survives(s in any::<String>()) {
            prop_assert!(!escape_controls(&s).chars().any(needs_escape));
        }

        #[test]
        fn terminal_safe_json_is_the_same_value_without_controls(s in any::<String>()) {
            let json = serde_json::to_string(&serde_json::json!({ "log": s })).unwrap();
            let safe = json_terminal_safe(json);
            prop_assert!(!safe.chars().any(needs_escape), "{}", safe);
            let back: serde_json::Value = serde_json::from_str(&safe).unwrap();
            prop_assert_eq!(back["log"].as_str(), Some(s.as_str()));
        }

        /// Written as it is serialised, the same text as escaped after.
        #[test]
        fn a_streamed_json_line_is_the_escaped_one(s in any::<String>(), n in 0..4usize) {
            let value = serde_json::json!({ "log": s, "kicks": vec![s.clone(); n] });
            let mut streamed = Vec::new();
            write_json_line(&mut streamed, &value).unwrap();
            let escaped = json_terminal_safe(serde_json::to_string(&value).unwrap()) + "\n";
            prop_assert_eq!(String::from_utf8(streamed).unwrap(), escaped);
        }
    }
}
