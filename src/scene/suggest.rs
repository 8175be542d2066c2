//! What a misspelt name should have been. For an undefined material name: a few defined
//! names, nearest by edit distance first, then how many more there are, and the nearest as a
//! "did you mean" when it is close. The work is bounded: names are compared only while a
//! budget of edit-distance cells lasts (after that, names are listed in file order), and each
//! missing name is ranked once. For unknown fields and enum variants, [`did_you_mean`] picks
//! the close one among the few names allowed there.

use std::collections::HashMap;

/// How many names are listed.
const LISTED: usize = 5;

/// Names longer than this (in characters) are not compared.
const MAX_COMPARED_CHARS: usize = 64;

/// Edit-distance cells (characters of one name times characters of the other) computed for
/// one scene at most: a few milliseconds.
const CELL_BUDGET: usize = 4_000_000;

/// The longest name shown in a message, in characters.
const SHOWN_CHARS: usize = 40;

/// Suggests defined material names for undefined ones.
pub(crate) struct Suggester<'s> {
    /// Defined names in file order.
    names: Vec<&'s str>,
    /// Characters of all names, each counted up to `MAX_COMPARED_CHARS`.
    name_chars: usize,
    cells_left: usize,
    said: HashMap<&'s str, (String, Option<String>)>,
}

impl<'s> Suggester<'s> {
    pub(crate) fn new(names: impl IntoIterator<Item = &'s str>) -> Self {
        let names: Vec<&str> = names.into_iter().collect();
        let name_chars = names.iter().map(|n| n.len().min(MAX_COMPARED_CHARS)).sum();
        Suggester {
            names,
            name_chars,
            cells_left: CELL_BUDGET,
            said: HashMap::new(),
        }
    }

    /// What `material` must be, for an object whose material `missing` is not defined, and
    /// the defined name it most likely meant (quoted): [`did_you_mean`] among the nearest.
    pub(crate) fn expected(&mut self, missing: &'s str) -> (String, Option<String>) {
        if self.names.is_empty() {
            return (
                "the name of a material defined in `materials` (none are)".to_owned(),
                None,
            );
        }
        if let Some(said) = self.said.get(missing) {
            return said.clone();
        }
        let (listed, suggestion) = match self.nearest(missing) {
            Some(listed) => {
                let suggestion = did_you_mean(missing, &listed).map(quoted);
                (listed, suggestion)
            }
            None => (self.names.iter().take(LISTED).copied().collect(), None),
        };
        let mut shown: Vec<String> = listed.iter().map(|n| quoted(n)).collect();
        if self.names.len() > listed.len() {
            shown.push(format!("and {} more", self.names.len() - listed.len()));
        }
        let said = (
            format!("a material defined in `materials` ({})", shown.join(", ")),
            suggestion,
        );
        self.said.insert(missing, said.clone());
        said
    }

    /// The defined names nearest to `missing`, nearest first (file order among equals);
    /// `None` when the budget does not cover comparing it with every name.
    fn nearest(&mut self, missing: &str) -> Option<Vec<&'s str>> {
        let query: Vec<char> = missing.chars().take(MAX_COMPARED_CHARS + 1).collect();
        if query.len() > MAX_COMPARED_CHARS {
            return None;
        }
        let cost = self.name_chars.saturating_mul(query.len().max(1));
        if cost > self.cells_left {
            return None;
        }
        self.cells_left -= cost;
        let mut ranked: Vec<(usize, usize)> = (self.names.iter().enumerate())
            .map(|(i, name)| (distance(&query, name).unwrap_or(usize::MAX), i))
            .collect();
        let keep = LISTED.min(ranked.len());
        ranked.select_nth_unstable(keep - 1);
        ranked.truncate(keep);
        ranked.sort_unstable();
        Some(ranked.into_iter().map(|(_, i)| self.names[i]).collect())
    }
}

/// Levenshtein distance between `a` and `b` in characters; `None` when `b` is too long to
/// compare.
fn distance(a: &[char], b: &str) -> Option<usize> {
    let b: Vec<char> = b.chars().take(MAX_COMPARED_CHARS + 1).collect();
    if b.len() > MAX_COMPARED_CHARS {
        return None;
    }
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitute = diagonal + usize::from(ca != cb);
            diagonal = row[j + 1];
            row[j + 1] = substitute.min(row[j] + 1).min(row[j + 1] + 1);
        }
    }
    Some(row[b.len()])
}

/// Whether a name `distance` edits away from one of `chars` characters is close enough to
/// suggest: at most a third of its characters, and at least one, may differ.
fn is_close(chars: usize, distance: usize) -> bool {
    distance <= (chars / 3).max(1)
}

/// The name among `allowed` that `found` most likely meant, if one is [close](is_close):
/// the nearest by Damerau-Levenshtein distance (adjacent swaps count as one edit), ignoring
/// case; the first in `allowed` among equals. Names longer than 64 characters are not
/// compared.
pub(crate) fn did_you_mean<'a>(found: &str, allowed: &[&'a str]) -> Option<&'a str> {
    let found_chars = found.chars().count();
    if found_chars > MAX_COMPARED_CHARS {
        return None;
    }
    let found = found.to_lowercase();
    (allowed.iter())
        .filter(|name| name.chars().count() <= MAX_COMPARED_CHARS)
        .map(|name| (strsim::damerau_levenshtein(&found, &name.to_lowercase()), *name))
        .filter(|&(d, _)| is_close(found_chars, d))
        .min_by_key(|&(d, _)| d)
        .map(|(_, name)| name)
}

/// A name as a message shows it: quoted and escaped like Rust's `{:?}`, cut to 40
/// characters (`"aaaa..."`).
pub(crate) fn quoted(name: &str) -> String {
    match name.char_indices().nth(SHOWN_CHARS) {
        Some((cut, _)) => format!("{:?}...", &name[..cut]),
        None => format!("{name:?}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance() {
        let d = |a: &str, b: &str| distance(&a.chars().collect::<Vec<_>>(), b);
        assert_eq!(d("leef", "leaf"), Some(1));
        assert_eq!(d("", "abc"), Some(3));
        assert_eq!(d("kitten", "sitting"), Some(3));
        assert_eq!(d("é", "e"), Some(1));
        assert_eq!(d("a", &"b".repeat(65)), None);
    }

    #[test]
    fn lists_the_nearest_few_then_counts_the_rest() {
        let names: Vec<String> = (0..100)
            .map(|i| format!("stone{i}"))
            .chain(["leaf".to_owned()])
            .collect();
        let mut s = Suggester::new(names.iter().map(String::as_str));
        assert_eq!(
            s.expected("leef").0,
            "a material defined in `materials` (\"leaf\", \"stone0\", \"stone1\", \"stone2\", \"stone3\", and 96 more)"
        );
        assert_eq!(
            s.expected("stone42x").0,
            "a material defined in `materials` (\"stone42\", \"stone2\", \"stone4\", \"stone12\", \"stone20\", and 96 more)"
        );
        let mut none = Suggester::new([]);
        assert_eq!(
            none.expected("x").0,
            "the name of a material defined in `materials` (none are)"
        );
        let mut two = Suggester::new(["ground", "leaf"]);
        assert_eq!(
            two.expected("leef").0,
            "a material defined in `materials` (\"leaf\", \"ground\")"
        );
    }

    #[test]
    fn the_nearest_name_is_suggested_when_close() {
        let mut s = Suggester::new(["ground", "leaf", "bark"]);
        assert_eq!(s.expected("leef").1.as_deref(), Some("\"leaf\""));
        assert_eq!(s.expected("brak").1.as_deref(), Some("\"bark\""));
        assert_eq!(s.expected("stone").1, None);
        assert_eq!(s.expected("x").1, None);
        assert_eq!(Suggester::new([]).expected("leef").1, None);
    }

    #[test]
    fn did_you_mean_picks_a_close_allowed_name() {
        let fields = ["mode", "cascade_count", "resolution", "split_lambda"];
        assert_eq!(did_you_mean("cascade_cont", &fields), Some("cascade_count"));
        assert_eq!(did_you_mean("resloution", &fields), Some("resolution"));
        assert_eq!(did_you_mean("Mode", &fields), Some("mode"));
        assert_eq!(did_you_mean("cascades", &fields), None);
        assert_eq!(did_you_mean("x", &fields), None);
        let variants = ["Pcf", "Pcss", "Vsm", "Evsm", "Evsm4", "Msm"];
        assert_eq!(did_you_mean("Psss", &variants), Some("Pcss"));
        assert_eq!(did_you_mean("PCSS", &variants), Some("Pcss"));
        assert_eq!(did_you_mean("Soft", &variants), None);
        assert_eq!(did_you_mean(&"a".repeat(100), &["a"]), None);
        assert_eq!(did_you_mean("a", &[]), None);
    }

    #[test]
    fn the_budget_falls_back_to_file_order() {
        let names: Vec<String> = (0..20_000).map(|i| format!("m{i:05}")).collect();
        let missing: Vec<String> = (0..100).map(|i| format!("m{:05}x", 19_999 - i)).collect();
        let mut s = Suggester::new(names.iter().map(String::as_str));
        let mut ranked = 0;
        for (i, missing) in missing.iter().enumerate() {
            let said = s.expected(missing).0;
            ranked += usize::from(said.contains(&format!("\"m{:05}\"", 19_999 - i)));
            assert!(said.ends_with("and 19995 more)"), "{said}");
        }
        assert!((1..100).contains(&ranked), "{ranked} of 100 ranked");
        assert_eq!(quoted(&"x".repeat(50)), format!("\"{}\"...", "x".repeat(40)));
    }
}
