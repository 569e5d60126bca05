//! "Did you mean": the closest of a list of names to a mistyped one, by edit distance.

/// Edits (insertions, deletions, substitutions, swaps of two neighbours) that turn `a` into `b`:
/// the optimal string alignment distance.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    // d[i][j]: distance between a[..i] and b[..j].
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    d[0] = (0..=b.len()).collect();
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

/// The name of `names` closest to `typed`, if it is close enough to be what was meant: at most
/// a third of the longer name's letters edited (at least one), or `typed` a prefix of it.
pub fn closest<'a>(typed: &str, names: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let typed_lower = typed.to_lowercase();
    names
        .into_iter()
        .filter(|n| *n != typed)
        .map(|n| (edit_distance(&typed_lower, &n.to_lowercase()), n))
        .filter(|(d, n)| {
            let len = typed.chars().count().max(n.chars().count());
            *d <= (len / 3).max(1) || (typed.len() >= 3 && n.starts_with(typed))
        })
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n)
}

/// `"; did you mean `NAME`?"` for the closest name, or nothing.
pub fn did_you_mean<'a>(typed: &str, names: impl IntoIterator<Item = &'a str>) -> String {
    match closest(typed, names) {
        Some(n) => format!("; did you mean `{n}`?"),
        None => String::new(),
    }
}

/// Adds a "did you mean" to serde's "unknown field `x`, expected one of `a`, `b`, ..." (or
/// "unknown variant"), from the names the message itself lists.
pub fn suggest_in_message(message: &str) -> String {
    let Some((_, rest)) = message
        .split_once("unknown field `")
        .or_else(|| message.split_once("unknown variant `"))
    else {
        return message.to_owned();
    };
    let Some((typed, expected)) = rest.split_once('`') else {
        return message.to_owned();
    };
    // The expected names are the backticked words after the typed one.
    let names: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
    let hint = did_you_mean(typed, names.iter().copied());
    if hint.is_empty() {
        message.to_owned()
    } else {
        format!("{}{hint}", message.trim_end())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_counts_edits_and_swaps() {
        assert_eq!(edit_distance("smoke", "smoke"), 0);
        assert_eq!(edit_distance("smok", "smoke"), 1);
        assert_eq!(edit_distance("fountian", "fountain"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
    }

    #[test]
    fn closest_name_only_when_close() {
        let names = ["fire", "snow", "fountain", "smoke", "e1"];
        assert_eq!(closest("smok", names), Some("smoke"));
        assert_eq!(closest("fountian", names), Some("fountain"));
        assert_eq!(closest("waterfall", names), None);
        assert_eq!(closest("fire", names), None);
    }

    #[test]
    fn serde_messages_get_a_suggestion() {
        let m = "unknown field `pointsize`, expected one of `resolution`, `point_size`, `mode`";
        assert!(suggest_in_message(m).ends_with("did you mean `point_size`?"));
        let m = "unknown variant `sprite`, expected `points` or `sprites`";
        assert!(suggest_in_message(m).ends_with("did you mean `sprites`?"));
        let m = "unknown field `zzz`, expected `a`";
        assert_eq!(suggest_in_message(m), m);
    }
}
