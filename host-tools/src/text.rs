//! Text that comes from a log (firmware version, configuration lines) is
//! data, not terminal commands: control characters are shown escaped, so an
//! ESC sequence in a log cannot clear, retitle or recolour a screen.

use std::borrow::Cow;

/// `text` with every control character (C0, DEL, C1) written as `\u{..}`
/// (tab, newline and carriage return as `\t`, `\n`, `\r`); other text as is.
#[must_use]
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
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
    }

    proptest! {
        #[test]
        fn no_control_character_survives(s in any::<String>()) {
            prop_assert!(!escape_controls(&s).chars().any(char::is_control));
        }
    }
}
