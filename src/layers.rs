//! The crate's layers, checked on its sources: the solver (`sph`) imports neither the
//! benchmark, the output, the reference nor the plots; the output and the reference do not
//! import the solver; and no files import each other, directly or in a ring. Without this
//! test such knots came back one convenient `use` at a time (issue 62 cut six of them).
//!
//! A file's imports are the `crate::a::b` and `super::b` paths in its code outside comments,
//! up to its tests (the first `#[cfg(test)]`), each resolved to the deepest source file that
//! exists. A child naming its own parent module (`super::X` in `sph/halo.rs`, meaning
//! `sph/mod.rs`) is how a module's parts share its items, not a knot, and is left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules and the top-level modules they must not import.
const FORBIDDEN: &[(&str, &[&str])] = &[
    (
        "sph",
        &[
            "bench",
            "output",
            "reference",
            "plot",
            "validation",
            "run",
            "case",
        ],
    ),
    ("output", &["sph"]),
    ("reference", &["sph"]),
];

/// The source files under `src/`, by their module path (`["sph", "halo"]`; `mod.rs` and
/// `lib.rs` are their folder's module).
fn modules(src: &Path) -> BTreeMap<Vec<String>, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).unwrap().with_extension("");
            let mut name: Vec<String> = rel.iter().map(|c| c.to_string_lossy().into()).collect();
            if matches!(name.last().map(String::as_str), Some("mod" | "lib")) {
                name.pop();
            }
            out.insert(name, path);
        }
    }
    out
}

/// The module paths `text` (of the module `at`) names, relative paths made absolute.
fn named_paths(text: &str, at: &[String]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let parent = at[..at.len().saturating_sub(1)].to_vec();
    for line in text.lines() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            break;
        }
        if code.starts_with("//") {
            continue;
        }
        let code = code.split("//").next().unwrap_or("");
        for (prefix, base) in [("crate::", Vec::new()), ("super::", parent.clone())] {
            for (k, _) in code.match_indices(prefix) {
                let before = code[..k].chars().last();
                if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':') {
                    continue;
                }
                let mut rest = &code[k + prefix.len()..];
                let mut path = base.clone();
                loop {
                    let len = (rest.bytes())
                        .take_while(|c| c.is_ascii_alphanumeric() || *c == b'_')
                        .count();
                    if len == 0 {
                        break;
                    }
                    path.push(rest[..len].to_string());
                    match rest[len..].strip_prefix("::") {
                        Some(r) => rest = r,
                        None => break,
                    }
                }
                out.push(path);
            }
        }
    }
    out
}

/// The file modules each module imports (the deepest existing module of each path named),
/// leaving out its own ancestors.
fn imports(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let files = modules(src);
    let mut out = BTreeMap::new();
    for (module, path) in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let mut targets = BTreeSet::new();
        for mut named in named_paths(&text, module) {
            while !named.is_empty() && !files.contains_key(&named) {
                named.pop();
            }
            if named.is_empty() || named == *module || module.starts_with(&named) {
                continue;
            }
            targets.insert(named);
        }
        out.insert(module.clone(), targets);
    }
    out
}

/// A ring of imports through `start`, if there is one.
fn ring(
    graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
    start: &Vec<String>,
) -> Option<Vec<Vec<String>>> {
    let mut stack = vec![(start.clone(), vec![start.clone()])];
    let mut seen = BTreeSet::new();
    while let Some((node, path)) = stack.pop() {
        for next in graph.get(&node).into_iter().flatten() {
            if next == start {
                return Some(path.clone());
            }
            if seen.insert(next.clone()) {
                let mut longer = path.clone();
                longer.push(next.clone());
                stack.push((next.clone(), longer));
            }
        }
    }
    None
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn the_solver_output_and_reference_keep_to_their_layers() {
    let graph = imports(&src());
    let mut broken = Vec::new();
    for (module, targets) in &graph {
        for (from, not) in FORBIDDEN {
            if module.first().map(String::as_str) != Some(from) {
                continue;
            }
            for t in targets {
                if t.first().is_some_and(|top| not.contains(&top.as_str())) {
                    broken.push(format!("{} imports {}", module.join("::"), t.join("::")));
                }
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

#[test]
fn no_files_import_each_other() {
    let graph = imports(&src());
    let rings: Vec<String> = (graph.keys())
        .filter_map(|m| ring(&graph, m))
        .map(|r| {
            r.iter()
                .map(|m| m.join("::"))
                .collect::<Vec<_>>()
                .join(" -> ")
        })
        .collect();
    assert!(rings.is_empty(), "import rings:\n{}", rings.join("\n"));
}

/// The check sees what it is for: a path of each form resolves, a ring is found.
#[test]
fn the_checks_see_paths_and_rings() {
    let at = ["sph".to_string(), "halo".to_string()];
    let named = named_paths(
        "use crate::decomposition::Slabs;\nuse super::buffers::{A, B};\n// crate::x\nlet v = super::probes::moved(p);",
        &at,
    );
    let want: Vec<Vec<String>> = [
        vec!["decomposition", "Slabs"],
        vec!["sph", "buffers"],
        vec!["sph", "probes", "moved"],
    ]
    .iter()
    .map(|p| p.iter().map(|s| s.to_string()).collect())
    .collect();
    assert_eq!(named, want);
    let graph: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = [
        (vec!["a".to_string()], [vec!["b".to_string()]].into()),
        (vec!["b".to_string()], [vec!["a".to_string()]].into()),
    ]
    .into();
    assert!(ring(&graph, &vec!["a".to_string()]).is_some());
    let graph: BTreeMap<_, _> = [(vec!["a".to_string()], [vec!["b".to_string()]].into())].into();
    assert!(ring(&graph, &vec!["a".to_string()]).is_none());
}
