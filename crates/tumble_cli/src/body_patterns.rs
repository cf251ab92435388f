//! `tumble run --bodies`: which bodies' rows a trajectory records.

use bevy_ecs::prelude::*;
use globset::{GlobBuilder, GlobSet, GlobSetBuilder};
use tumble_scene::text::terminal_safe;

use crate::exit::{self, Failure};

/// The patterns of `--bodies`, compiled once into one matcher, with the text of each (in
/// order) for the error that names a pattern matching nothing.
pub(crate) struct BodyPatterns {
    items: Vec<String>,
    set: GlobSet,
}

/// The comma-separated patterns of `--bodies`, each checked: shell globs as `globset` reads
/// them (`*`, `?`, `[abc]`, `[a-z]`, `[!abc]` and `[^abc]` for "not one of", `{a,b}` is not
/// available since `,` separates patterns, `\` escapes the next character). Patterns are
/// composed (Unicode form C) as the scene's names are, so `é` typed either way finds `é`.
pub(crate) fn body_patterns(list: &str) -> Result<BodyPatterns, Failure> {
    let mut items = Vec::new();
    let mut set = GlobSetBuilder::new();
    let list = tumble_scene::text::composed(list);
    for item in list.split(',') {
        let item = item.trim();
        if item.is_empty() {
            return Err(Failure::new(
                exit::ERROR,
                format!(
                    "--bodies: an empty name in `{}`; expected names or patterns separated by \
                     commas",
                    terminal_safe(&list)
                ),
            ));
        }
        let glob = GlobBuilder::new(item)
            .literal_separator(false)
            .backslash_escape(true)
            .build()
            .map_err(|e| {
                Failure::new(
                    exit::ERROR,
                    format!(
                        "--bodies: `{}` is not a pattern: {}",
                        terminal_safe(item),
                        terminal_safe(&e.kind().to_string())
                    ),
                )
            })?;
        set.add(glob);
        items.push(item.to_owned());
    }
    let set = set.build().map_err(|e| {
        Failure::new(
            exit::ERROR,
            format!("--bodies: {}", terminal_safe(&e.to_string())),
        )
    })?;
    Ok(BodyPatterns { items, set })
}

/// Indices of the bodies that match any of `patterns`, in file order; a pattern that matches
/// none is an error (a typo must not give an empty trajectory). One pass of the compiled set
/// over the names: linear in the names, not in names × patterns.
pub(crate) fn select_bodies(
    patterns: &BodyPatterns,
    bodies: &[(String, Entity)],
) -> Result<Vec<usize>, Failure> {
    let mut used = vec![false; patterns.items.len()];
    let mut selected = Vec::new();
    let mut hits = Vec::new();
    for (i, (name, _)) in bodies.iter().enumerate() {
        patterns.set.matches_into(name.as_str(), &mut hits);
        if !hits.is_empty() {
            selected.push(i);
        }
        for &k in &hits {
            used[k] = true;
        }
    }
    if let Some(k) = used.iter().position(|used| !used) {
        return Err(Failure::new(
            exit::ERROR,
            format!(
                "--bodies: `{}` matches no body of the scene",
                terminal_safe(&patterns.items[k])
            ),
        ));
    }
    Ok(selected)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(names: &[&str]) -> Vec<(String, Entity)> {
        names
            .iter()
            .enumerate()
            .map(|(i, n)| ((*n).to_owned(), Entity::from_raw_u32(i as u32).unwrap()))
            .collect()
    }

    fn selected(list: &str, bodies: &[&str]) -> Result<Vec<usize>, String> {
        let patterns = body_patterns(list).map_err(|f| f.message)?;
        select_bodies(&patterns, &names(bodies)).map_err(|f| f.message)
    }

    /// The syntax a shell user knows: `[!..]` and `[^..]` negate, `\` escapes, `*` and `?`
    /// match any run and one character, including `/` (names are not paths).
    #[test]
    fn body_patterns_are_shell_globs() {
        let bodies = ["m1", "m2", "m*", "a/b", "b12"];
        assert_eq!(selected("m[^1]", &bodies), Ok(vec![1, 2]));
        assert_eq!(selected("m[!1]", &bodies), Ok(vec![1, 2]));
        assert_eq!(selected("m\\*", &bodies), Ok(vec![2]));
        assert_eq!(selected("a*", &bodies), Ok(vec![3]));
        assert_eq!(selected("b1?,m1", &bodies), Ok(vec![0, 4]));
        let error = selected("m1,zz*", &bodies).unwrap_err();
        assert_eq!(error, "--bodies: `zz*` matches no body of the scene");
    }

    /// 5000 patterns against 2000 names: one compiled set, one pass over the names. The bound
    /// is loose for a shared machine; the pattern-by-pattern loop it replaced took 32 s.
    #[test]
    fn many_patterns_against_many_names_are_quick() {
        let bodies: Vec<String> = (0..2000).map(|i| format!("body{i}")).collect();
        let refs: Vec<&str> = bodies.iter().map(String::as_str).collect();
        let list: Vec<String> = (0..5000).map(|i| format!("body{}*", i % 2000)).collect();
        let start = std::time::Instant::now();
        let picked = selected(&list.join(","), &refs).unwrap();
        assert_eq!(picked.len(), 2000);
        let took = start.elapsed();
        assert!(took < std::time::Duration::from_secs(5), "{took:?}");
    }
}
