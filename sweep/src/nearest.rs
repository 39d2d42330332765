//! Hints for an unknown parameter path: the valid paths nearest to it.

use fabkit_designs::schema::Design;
use fabkit_designs::variant::{parameter_paths, path_keys};

/// Up to `n` valid paths nearest to the unknown `path`, best first: paths ending in the same
/// key come first (`markers.spacing_mm` finds `layers[0].markers[0].pattern.spacing_mm`), then
/// by similarity of the last key, then of the keys they share and of the whole string.
pub fn nearest_paths(design: &Design, path: &str, n: usize) -> Vec<String> {
    let asked = path_keys(path);
    let last = asked.last().cloned().unwrap_or_default();
    let mut scored: Vec<(f64, String)> = parameter_paths(design)
        .into_iter()
        .map(|p| {
            let k = path_keys(&p);
            let l = k.last().cloned().unwrap_or_default();
            let last_sim = strsim::normalized_damerau_levenshtein(&last, &l);
            let shared =
                asked.iter().filter(|a| k.contains(a)).count() as f64 / asked.len().max(1) as f64;
            let whole = strsim::normalized_levenshtein(path, &p);
            (2.0 * last_sim + shared + whole, p)
        })
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
    scored
        .into_iter()
        .filter(|(s, _)| *s >= 1.5)
        .take(n)
        .map(|(_, p)| p)
        .collect()
}
