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
/// known name (`the parameters are a, b, c`, `what` naming them).
#[must_use]
pub fn suggest(name: &str, known: &[&str], what: &str) -> String {
    let closest = known
        .iter()
        .map(|k| (strsim::levenshtein(name, k), *k))
        .min_by_key(|&(edits, _)| edits);
    match closest {
        Some((edits, k)) if edits <= CLOSE_EDITS.min(name.len() / 2) => {
            format!("did you mean {k:?}?")
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
    }
}
