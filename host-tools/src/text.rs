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
    }
}
