//! Small helpers for the words of reports.

/// `1 episode`, `2 episodes`, `0 episodes`.
#[must_use]
pub fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        format!("1 {word}")
    } else {
        format!("{n} {word}s")
    }
}

/// Names at most this many edits from an unknown one are offered as what
/// was meant (beyond, the whole list is given).
const CLOSE_EDITS: usize = 3;

/// What to say after "`name` is unknown": the known name closest to it
/// when one is a few edits away (`did you mean "x"?`), otherwise every
/// known name (`the parameters are a, b, c`, `what` naming them). A name
/// without a dot is also held against the last part of dotted ones
/// (`trial` is a slip of `geometry.trail`).
#[must_use]
pub fn suggest(name: &str, known: &[&str], what: &str) -> String {
    let edits = |k: &str| {
        let last = k.rsplit('.').next().unwrap_or(k);
        let whole = strsim::levenshtein(name, k);
        if name.contains('.') {
            whole
        } else {
            whole.min(strsim::levenshtein(name, last))
        }
    };
    let best = known.iter().map(|k| edits(k)).min();
    let close: Vec<&str> = known
        .iter()
        .copied()
        .filter(|k| Some(edits(k)) == best)
        .collect();
    match (best, close.as_slice()) {
        (Some(edits), [k]) if edits <= CLOSE_EDITS.min(name.len() / 2) => {
            format!("did you mean {k:?}?")
        }
        // As near as each other: `mass` could be any body's.
        (Some(edits), several) if edits <= CLOSE_EDITS.min(name.len() / 2) => {
            let quoted: Vec<String> = several.iter().map(|k| format!("{k:?}")).collect();
            format!("did you mean one of {}?", quoted.join(", "))
        }
        _ => format!("the {what} are {}", known.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn one_is_singular() {
        assert_eq!(super::plural(1, "episode"), "1 episode");
        assert_eq!(super::plural(0, "episode"), "0 episodes");
        assert_eq!(super::plural(2, "alert"), "2 alerts");
    }

    #[test]
    fn a_near_name_is_suggested_and_a_far_one_gets_the_list() {
        let known = ["steer_head.stiffness", "steer_head.damping", "trail"];
        assert_eq!(
            super::suggest("steer_head.stifness", &known, "parameters"),
            "did you mean \"steer_head.stiffness\"?"
        );
        assert_eq!(
            super::suggest("mass", &known, "parameters"),
            "the parameters are steer_head.stiffness, steer_head.damping, trail"
        );
        // The last part of a dotted name, as typed or with a slip.
        let known = ["geometry.trail", "geometry.wheelbase", "rear_wheel.mass"];
        for typed in ["trail", "trial", "wheelbse"] {
            let said = super::suggest(typed, &known, "parameters");
            assert!(
                said.starts_with("did you mean \"geometry."),
                "{typed}: {said}"
            );
        }
        assert_eq!(
            super::suggest("geometry.trial", &known, "parameters"),
            "did you mean \"geometry.trail\"?"
        );
        // Several as near: all of them.
        assert_eq!(
            super::suggest("mass", &["fork.mass", "frame.mass", "trail"], "parameters"),
            "did you mean one of \"fork.mass\", \"frame.mass\"?"
        );
        // A dotted name is not matched by its parts alone.
        assert!(super::suggest("rear.mas", &known, "parameters").starts_with("the parameters"));
    }
}
