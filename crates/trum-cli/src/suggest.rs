//! "Did you mean ...?" for values (preset, effect and column names), as clap does for flags.

/// Levenshtein distance of two strings, by characters, ignoring ASCII case.
fn distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().map(|c| c.to_ascii_lowercase()).collect();
    let b: Vec<char> = b.chars().map(|c| c.to_ascii_lowercase()).collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb)).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The candidate `input` most likely meant: `(alias, name)` pairs are tried by alias (a
/// display name, a name in other case) and answered by name. A candidate is close when it
/// equals the input in any case, contains it (or is contained in it) with at least 3
/// characters, or is within a third of its length in edits (at least 1, at most 3).
pub fn closest<'a>(input: &str, candidates: impl IntoIterator<Item = (&'a str, &'a str)>) -> Option<&'a str> {
    let lower = input.to_ascii_lowercase();
    let limit = (input.chars().count() / 3).clamp(1, 3);
    let mut best: Option<(usize, &str)> = None;
    for (alias, name) in candidates {
        let al = alias.to_ascii_lowercase();
        let d = if al == lower {
            0
        } else if lower.len() >= 3 && (al.contains(&lower) || lower.contains(&al)) {
            1
        } else {
            distance(&lower, &al)
        };
        if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, name));
        }
    }
    best.map(|(_, n)| n)
}

/// `"; did you mean 'x'?"`, or nothing.
pub fn hint<'a>(input: &str, candidates: impl IntoIterator<Item = (&'a str, &'a str)>) -> String {
    closest(input, candidates).map(|n| format!("; did you mean '{n}'?")).unwrap_or_default()
}

/// The same name as alias and answer.
pub fn names<'a>(list: impl IntoIterator<Item = &'a str>) -> impl Iterator<Item = (&'a str, &'a str)> {
    list.into_iter().map(|n| (n, n))
}

/// `"; did you mean 'trum60a'?"` for a preset name in another case, its display name
/// (`TRUM60A`) or a near miss.
pub fn preset_hint(input: &str) -> String {
    let presets = trum_core::presets::PRESETS;
    let display: Vec<(String, &str)> = presets.iter().map(|p| (p.motor().name, p.name)).collect();
    let pairs = presets.iter().map(|p| (p.name, p.name)).chain(display.iter().map(|(d, n)| (d.as_str(), *n)));
    hint(input, pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn close_names_are_suggested_and_far_ones_are_not() {
        let list = ["trum60a", "trum60-qut", "generic60"];
        assert_eq!(closest("TRUM60A", names(list)), Some("trum60a"));
        assert_eq!(closest("trum60", names(list)), Some("trum60a"));
        assert_eq!(closest("generc60", names(list)), Some("generic60"));
        assert_eq!(closest("shinsei", names(list)), None);
        assert_eq!(closest("speed_rmp", names(["speed_rpm", "speed_rad_s"])), Some("speed_rpm"));
        // a display name answers with the preset's name
        assert_eq!(closest("Shinsei USR60", [("Shinsei USR60", "usr60")]), Some("usr60"));
        assert_eq!(hint("radial_frction", names(["radial_friction"])), "; did you mean 'radial_friction'?");
        assert_eq!(hint("x", names(["radial_friction"])), "");
    }
}
