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

#[cfg(test)]
mod tests {
    #[test]
    fn one_is_singular() {
        assert_eq!(super::plural(1, "episode"), "1 episode");
        assert_eq!(super::plural(0, "episode"), "0 episodes");
        assert_eq!(super::plural(2, "alert"), "2 alerts");
    }
}
