//! Each folder of the crate is a tree, not a ring: a file imports only files below it, so that
//! no file reaches itself through the files it imports.
//!
//! The graph is read from the sources. Its nodes are the files (`x.rs`, `x/mod.rs`); a file
//! imports another when its code, anywhere (a `use` line, a group `use a::{b, c::d}`, or an
//! inline path), names the other's module through `crate::…`, `super::…`, `self::…` or one of
//! its own child modules, the deepest module the path reaches being the one imported
//! (`super::Item` imports the parent file, `super::x::Item` the sibling `x`). Declaring a child
//! (`mod x;`) is not importing it. Comments are skipped, and so are tests (a `tests.rs` or
//! `*_tests.rs` file, or what follows `#[cfg(test)]`), which may import anything.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The folders held to be trees, under src/.
const FOLDERS: [&str; 8] = [
    "solver/analysis",
    "solver/engine",
    "solver/model",
    "cli",
    "plot",
    "study",
    "export",
    "service",
];

/// A module's path from the crate root (`["solver", "analysis", "summary"]`).
type ModPath = Vec<String>;

/// Every module file of the library under `dir`, by its module path; `at` is `dir`'s.
fn modules(dir: &Path, at: &ModPath, out: &mut BTreeMap<ModPath, PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir() {
            let mut inner = at.clone();
            inner.push(name);
            modules(&path, &inner, out);
        } else if path.extension().is_some_and(|e| e == "rs") && name != "main" {
            let mut m = at.clone();
            if name != "mod" && name != "lib" {
                m.push(name);
            }
            out.insert(m, path);
        }
    }
}

/// A file's code: its text before its tests, with comments cut and each string literal
/// emptied.
fn code(text: &str) -> String {
    let before_tests: Vec<&str> = text
        .lines()
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .collect();
    let chars: Vec<char> = before_tests.join("\n").chars().collect();
    let at = |i: usize| chars.get(i).copied().unwrap_or(' ');
    let mut out = String::with_capacity(chars.len());
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let word = i > 0 && (at(i - 1).is_alphanumeric() || at(i - 1) == '_');
        let hashes = chars[i + 1..].iter().take_while(|&&h| h == '#').count();
        let raw = c == 'r' && !word && at(i + 1 + hashes) == '"';
        if c == '/' && at(i + 1) == '/' {
            while i < chars.len() && chars[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && at(i + 1) == '*' {
            i += 2;
            while i < chars.len() && !(chars[i] == '*' && at(i + 1) == '/') {
                i += 1;
            }
            i += 2;
        } else if c == '"' || raw {
            // A string, raw (`r#"…"#`) or with escapes.
            let hashes = if raw { hashes } else { 0 };
            i += if raw { 2 + hashes } else { 1 };
            while i < chars.len() {
                if !raw && chars[i] == '\\' {
                    i += 2;
                    continue;
                }
                let closes = chars[i] == '"' && (1..=hashes).all(|k| at(i + k) == '#');
                i += 1;
                if closes {
                    i += hashes;
                    break;
                }
            }
            out.push_str("\"\"");
        } else if c == '\'' && at(i + 1) == '\\' {
            // An escaped char literal (`'\''`).
            i += 3;
            while i < chars.len() && chars[i] != '\'' {
                i += 1;
            }
            i += 1;
        } else if c == '\'' && at(i + 2) == '\'' {
            // A char literal (`'"'`); a lifetime stays.
            i += 3;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

/// A token of code, as far as paths go.
#[derive(Debug, Clone, PartialEq)]
enum Token {
    Ident(String),
    Sep,
    Open,
    Close,
    Comma,
    Star,
    Other,
}

fn tokens(code: &str) -> Vec<Token> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_alphanumeric() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(Token::Ident(chars[start..i].iter().collect()));
            continue;
        }
        out.push(match c {
            ':' if chars.get(i + 1) == Some(&':') => {
                i += 1;
                Token::Sep
            }
            '{' => Token::Open,
            '}' => Token::Close,
            ',' => Token::Comma,
            '*' => Token::Star,
            c if c.is_whitespace() => {
                i += 1;
                continue;
            }
            _ => Token::Other,
        });
        i += 1;
    }
    out
}

/// Every path of two or more segments in the code, a `use` group expanded into its paths
/// (`a::{b, c::d}` gives `a::b` and `a::c::d`).
fn paths(code: &str) -> Vec<ModPath> {
    let t = tokens(code);
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let starts = matches!(&t[i], Token::Ident(_))
            && t.get(i + 1) == Some(&Token::Sep)
            && (i == 0 || t[i - 1] != Token::Sep);
        if starts {
            i = path_at(&t, i, Vec::new(), &mut out);
        } else {
            i += 1;
        }
    }
    out
}

/// Reads the path (or group of paths) at `t[i]` after `prefix` into `out`; the index after it.
fn path_at(t: &[Token], mut i: usize, mut prefix: ModPath, out: &mut Vec<ModPath>) -> usize {
    while let Some(Token::Ident(s)) = t.get(i) {
        prefix.push(s.clone());
        i += 1;
        if t.get(i) != Some(&Token::Sep) {
            break;
        }
        i += 1;
        match t.get(i) {
            Some(Token::Open) => {
                i += 1;
                while i < t.len() && t[i] != Token::Close {
                    match t[i] {
                        Token::Ident(_) => i = path_at(t, i, prefix.clone(), out),
                        _ => i += 1,
                    }
                }
                return i + 1;
            }
            Some(Token::Star) => break,
            _ => {}
        }
    }
    out.push(prefix);
    i
}

/// The module file a path in module `from` reaches, if it names one of the crate's.
fn resolve(from: &ModPath, path: &ModPath, known: &BTreeMap<ModPath, PathBuf>) -> Option<ModPath> {
    let mut base = from.clone();
    let mut rest = path.as_slice();
    match rest.first()?.as_str() {
        "crate" => {
            base.clear();
            rest = &rest[1..];
        }
        "self" => rest = &rest[1..],
        "super" => {
            while rest.first().is_some_and(|s| s == "super") {
                base.pop()?;
                rest = &rest[1..];
            }
        }
        child => {
            let mut m = base.clone();
            m.push(child.to_string());
            if !known.contains_key(&m) {
                return None;
            }
        }
    }
    for segment in rest {
        let mut m = base.clone();
        m.push(segment.clone());
        if !known.contains_key(&m) {
            break;
        }
        base = m;
    }
    Some(base)
}

/// A cycle of the graph (its nodes in order, the first repeated last), if it has one.
fn cycle<N: Ord + Clone>(edges: &BTreeMap<N, BTreeSet<N>>) -> Option<Vec<N>> {
    fn visit<N: Ord + Clone>(
        n: &N,
        edges: &BTreeMap<N, BTreeSet<N>>,
        done: &mut BTreeSet<N>,
        stack: &mut Vec<N>,
    ) -> Option<Vec<N>> {
        if let Some(at) = stack.iter().position(|m| m == n) {
            let mut ring = stack[at..].to_vec();
            ring.push(n.clone());
            return Some(ring);
        }
        if done.contains(n) {
            return None;
        }
        stack.push(n.clone());
        for m in edges.get(n).into_iter().flatten() {
            if let Some(ring) = visit(m, edges, done, stack) {
                return Some(ring);
            }
        }
        stack.pop();
        done.insert(n.clone());
        None
    }
    let mut done = BTreeSet::new();
    edges
        .keys()
        .find_map(|n| visit(n, edges, &mut done, &mut Vec::new()))
}

/// The import graph of the files under src/`folder`, as paths from src/.
fn graph(folder: &str) -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut known = BTreeMap::new();
    modules(&src, &Vec::new(), &mut known);
    let inside: ModPath = folder.split('/').map(String::from).collect();
    let name = |m: &ModPath| {
        let file = known[m].strip_prefix(&src).unwrap();
        file.display().to_string()
    };
    let mut edges = BTreeMap::new();
    for (m, file) in known.iter().filter(|(m, _)| m.starts_with(&inside)) {
        let stem = file.file_stem().unwrap().to_string_lossy();
        if stem == "tests" || stem.ends_with("_tests") {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        let to: BTreeSet<String> = paths(&code(&text))
            .iter()
            .filter_map(|p| resolve(m, p, &known))
            .filter(|t| t != m && t.starts_with(&inside) && known.contains_key(t))
            .map(|t| name(&t))
            .collect();
        edges.insert(name(m), to);
    }
    edges
}

#[test]
fn each_folder_is_a_tree_of_imports() {
    for folder in FOLDERS {
        let edges = graph(folder);
        assert!(edges.len() > 1, "no files in src/{folder}");
        if let Some(ring) = cycle(&edges) {
            panic!("src/{folder} imports in a ring: {}", ring.join(" -> "));
        }
    }
}

/// The analysis folder's graph holds the imports its files make, a group's and a child's
/// among them.
#[test]
fn the_graph_holds_a_folders_imports() {
    let edges = graph("solver/analysis");
    let from = |f: &str| &edges[&format!("solver/analysis/{f}")];
    assert!(
        from("folds.rs").contains("solver/analysis/faces.rs"),
        "{edges:?}"
    );
    assert!(from("summary.rs").contains("solver/analysis/verdict.rs"));
    assert!(from("verdict.rs").contains("solver/analysis/verdict/plausible.rs"));
    assert!(from("expected.rs").contains("solver/analysis/expected/tables.rs"));
}

#[test]
fn paths_are_read_from_groups_inline_paths_and_code_alone() {
    let text = "use super::{a::B, c, d::{e::F, G}};\nfn f() { crate::x::y(); } // super::z\n\
                const S: &str = \"super::w // self::u\"; const Q: char = '\"';\n\
                /* self::t */ const R: &str = r#\"self::s \" super::r\"#;\n\
                #[cfg(test)]\nmod tests { use super::v; }\n";
    let got: Vec<String> = paths(&code(text)).iter().map(|p| p.join("::")).collect();
    assert_eq!(
        got,
        [
            "super::a::B",
            "super::c",
            "super::d::e::F",
            "super::d::G",
            "crate::x::y"
        ]
    );
}

#[test]
fn a_path_reaches_the_deepest_module_it_names() {
    let known: BTreeMap<ModPath, PathBuf> = ["a", "a/b", "a/b/c", "a/d"]
        .iter()
        .map(|m| (m.split('/').map(String::from).collect(), PathBuf::new()))
        .collect();
    let m = |s: &str| -> ModPath { s.split('/').map(String::from).collect() };
    let at = m("a/b");
    let reach = |p: &str| resolve(&at, &m(&p.replace("::", "/")), &known);
    assert_eq!(reach("super::d::Item"), Some(m("a/d")));
    assert_eq!(reach("super::Item"), Some(m("a")));
    assert_eq!(reach("c::Item"), Some(m("a/b/c")));
    assert_eq!(reach("self::c"), Some(m("a/b/c")));
    assert_eq!(reach("crate::a::d"), Some(m("a/d")));
    assert_eq!(reach("std::mem"), None);
}

#[test]
fn the_cycle_finder_finds_a_ring_and_passes_a_tree() {
    let graph = |pairs: &[(u8, u8)]| {
        let mut edges: BTreeMap<u8, BTreeSet<u8>> = BTreeMap::new();
        for &(a, b) in pairs {
            edges.entry(a).or_default().insert(b);
            edges.entry(b).or_default();
        }
        edges
    };
    let tree = graph(&[(1, 2), (1, 3), (2, 4), (3, 4)]);
    assert_eq!(cycle(&tree), None);
    let ring = graph(&[(1, 2), (2, 3), (3, 4), (4, 2), (1, 4)]);
    assert_eq!(cycle(&ring), Some(vec![2, 3, 4, 2]));
    assert_eq!(cycle(&graph(&[(5, 5)])), Some(vec![5, 5]));
}
