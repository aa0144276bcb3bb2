//! No two source modules import each other, directly or through a circle.
//!
//! Reads the sources of every crate of pada (pada-core in `shared/src`, the
//! host in `host/src`, the firmware in `firmware/src`, …) as text, takes
//! every path a module names that starts with `crate::`, `super::` or
//! `self::` (in `use` trees and in code), resolves it to the module file that defines the item (following
//! the `pub use` re-exports of a parent module), and looks for circles in
//! that graph of files. A module's use of its own parent does not count: a
//! child may use what its parent declares (the parent's use of its children
//! does).
//!
//! The circles still there are listed in [`KNOWN`], to be broken; the test
//! fails on any other circle, and on a listed one that is gone (so the list
//! stays true). Run it with `cargo test -p pada-tests --test
//! import_circles -- --nocapture` to see the graph's circles.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Circles not yet broken, each as its modules in sorted order.
const KNOWN: &[&[&str]] = &[];

/// A module: crate name and path segments (`["board", "trial"]`).
type Module = (String, Vec<String>);

fn name(m: &Module) -> String {
    if m.1.is_empty() {
        m.0.clone()
    } else {
        format!("{}::{}", m.0, m.1.join("::"))
    }
}

/// The source without comments, string literals and char literals.
fn strip(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if c == b'r' && (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#')) && !ident_byte(b, i) {
            // A raw string r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&b'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&b'"') {
                out.push(c as char);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == b'"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&b'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = j;
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    i += 1;
                }
                i += 1;
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == b'\'' {
            // A char literal ('a', '\n', '\u{..}') or a lifetime ('a).
            let end = if b.get(i + 1) == Some(&b'\\') {
                b[i + 2..].iter().position(|&x| x == b'\'').map(|p| i + 2 + p)
            } else if b.get(i + 2) == Some(&b'\'') {
                Some(i + 2)
            } else {
                // Multi-byte UTF-8 characters.
                let s = &src[i + 1..];
                s.chars().next().and_then(|ch| {
                    let l = ch.len_utf8();
                    (s.as_bytes().get(l) == Some(&b'\'')).then_some(i + 1 + l)
                })
            };
            match end {
                Some(e) => {
                    out.push_str("' '");
                    i = e + 1;
                }
                None => {
                    out.push('\'');
                    i += 1;
                }
            }
        } else {
            let ch = src[i..].chars().next().unwrap();
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// The source without its `#[cfg(test)] mod … { … }` blocks: a test's
/// imports are not the module's (and `super` there is the module itself).
fn drop_test_modules(src: &str) -> String {
    let mut out = String::with_capacity(src.len());
    let mut rest = src;
    while let Some(k) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..k]);
        let after = &rest[k + "#[cfg(test)]".len()..];
        let t = after.trim_start();
        let is_mod = t.starts_with("mod ") || t.starts_with("pub mod ") || t.starts_with("pub(crate) mod ");
        match (is_mod, t.find('{'), t.find(';')) {
            (true, Some(open), semi) if semi.is_none_or(|s| s > open) => {
                let body = &t[open..];
                let mut depth = 0;
                let mut end = body.len();
                for (i, ch) in body.char_indices() {
                    match ch {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = i + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                rest = &body[end..];
            }
            _ => rest = after,
        }
    }
    out.push_str(rest);
    out
}

fn ident_byte(b: &[u8], i: usize) -> bool {
    i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')
}

/// Expands a `use` tree (`a::{b, c::{d, e as f}}`) into (path, the name it
/// binds).
fn expand(tree: &str) -> Vec<(Vec<String>, String)> {
    fn go(prefix: &[String], tree: &str, out: &mut Vec<(Vec<String>, String)>) {
        let tree = tree.trim();
        if tree.is_empty() {
            return;
        }
        if let Some(open) = tree.find('{') {
            let head: Vec<String> = tree[..open]
                .split("::")
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(String::from)
                .collect();
            let mut p = prefix.to_vec();
            p.extend(head);
            let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
            let mut depth = 0;
            let mut start = 0;
            for (k, ch) in inner.char_indices() {
                match ch {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        go(&p, &inner[start..k], out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            go(&p, &inner[start..], out);
        } else {
            let (path, alias) = match tree.split_once(" as ") {
                Some((p, a)) => (p, Some(a.trim().to_string())),
                None => (tree, None),
            };
            let mut p = prefix.to_vec();
            p.extend(path.split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from));
            let bound = alias.unwrap_or_else(|| p.last().cloned().unwrap_or_default());
            if p.last().map(String::as_str) == Some("self") {
                p.pop();
            }
            out.push((p, bound));
        }
    }
    let mut out = Vec::new();
    go(&[], tree, &mut out);
    out
}

/// A path relative to `here` (`crate::`, `super::`, `self::`) made absolute;
/// `None` for another crate's path.
fn absolute(here: &[String], path: &[String]) -> Option<Vec<String>> {
    let first = path.first()?;
    let mut base: Vec<String>;
    let mut rest = &path[1..];
    match first.as_str() {
        "crate" => base = Vec::new(),
        "self" => base = here.to_vec(),
        "super" => {
            base = here.to_vec();
            base.pop();
            while rest.first().map(String::as_str) == Some("super") {
                base.pop();
                rest = &rest[1..];
            }
        }
        _ => return None,
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

struct Crate {
    name: String,
    /// Module path → its source, stripped.
    modules: BTreeMap<Vec<String>, String>,
}

fn load(name: &str, src: &Path) -> Crate {
    let mut modules = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().and_then(|e| e.to_str()) != Some("rs") {
                continue;
            }
            let rel: Vec<String> = path
                .strip_prefix(src)
                .unwrap()
                .with_extension("")
                .iter()
                .map(|s| s.to_string_lossy().into_owned())
                .collect();
            let mut module = rel;
            if matches!(module.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                module.pop();
            }
            let text = fs::read_to_string(&path).unwrap();
            let stripped = drop_test_modules(&strip(&text));
            modules.entry(module).and_modify(|s: &mut String| s.push_str(&stripped)).or_insert(stripped);
        }
    }
    Crate { name: name.to_string(), modules }
}

/// The paths a module names: every `use` tree and every `crate::`,
/// `super::` or `self::` path in its code, absolute.
fn paths(here: &[String], src: &str, modules: &BTreeMap<Vec<String>, String>) -> (Vec<Vec<String>>, Vec<(Vec<String>, String)>) {
    let mut named = Vec::new();
    let mut reexports = Vec::new();
    let mut bindings: BTreeMap<String, Vec<String>> = BTreeMap::new();
    // `use` statements (the tree up to the `;`).
    let mut rest = src;
    while let Some(k) = find_word(rest, "use") {
        let after = &rest[k + 3..];
        let end = after.find(';').unwrap_or(after.len());
        let tree = &after[..end];
        let public = rest[..k].trim_end().ends_with("pub") || rest[..k].trim_end().ends_with(')');
        for (mut p, bound) in expand(tree) {
            // `use child::Item` in a module names its own child.
            if let Some(first) = p.first() {
                let mut child = here.to_vec();
                child.push(first.clone());
                if !matches!(first.as_str(), "crate" | "super" | "self") && modules.contains_key(&child) {
                    p.insert(0, "self".to_string());
                }
            }
            if let Some(abs) = absolute(here, &p) {
                if bound != "*" {
                    if public {
                        reexports.push((abs.clone(), bound.clone()));
                    }
                    bindings.insert(bound, abs.clone());
                }
                named.push(abs);
            }
        }
        rest = &after[end..];
    }
    // Paths in code: `crate::…`, `super::…`, `self::…`, a name a `use`
    // bound (`commands::run::RunArgs` after `use crate::commands`), or a
    // child module (`trial::run` in its parent).
    let bytes = src.as_bytes();
    let mut at = 0;
    while let Some(k) = src[at..].find("::") {
        let colons = at + k;
        at = colons + 2;
        let mut start = colons;
        while start > 0 && (bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_') {
            start -= 1;
        }
        if start == colons || (start > 0 && bytes[start - 1] == b':') {
            continue;
        }
        let end = src[start..]
            .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .map_or(src.len(), |e| start + e);
        let mut p: Vec<String> = src[start..end].split("::").filter(|s| !s.is_empty()).map(String::from).collect();
        at = at.max(end);
        let first = p[0].clone();
        if !matches!(first.as_str(), "crate" | "super" | "self") {
            let mut child = here.to_vec();
            child.push(first.clone());
            if let Some(bound) = bindings.get(&first) {
                p.splice(0..1, bound.iter().cloned());
                named.push(p);
                continue;
            } else if modules.contains_key(&child) {
                p.insert(0, "self".to_string());
            } else {
                continue;
            }
        }
        if let Some(abs) = absolute(here, &p) {
            named.push(abs);
        }
    }
    (named, reexports)
}

fn find_word(s: &str, word: &str) -> Option<usize> {
    let b = s.as_bytes();
    let mut from = 0;
    while let Some(k) = s[from..].find(word) {
        let at = from + k;
        let before = at == 0 || !(b[at - 1].is_ascii_alphanumeric() || b[at - 1] == b'_');
        let after = b.get(at + word.len()).is_none_or(|c| c.is_ascii_whitespace());
        if before && after {
            return Some(at);
        }
        from = at + word.len();
    }
    None
}

/// The module that defines what `path` names: the longest prefix that is a
/// module, then through that module's re-exports.
fn resolve(c: &Crate, reexports: &BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>>, path: &[String]) -> Vec<String> {
    let mut path = path.to_vec();
    for _ in 0..8 {
        let mut n = path.len();
        while n > 0 && !c.modules.contains_key(&path[..n]) {
            n -= 1;
        }
        let module = path[..n].to_vec();
        let Some(item) = path.get(n).filter(|i| *i != "*") else { return module };
        match reexports.get(&module).and_then(|r| r.get(item)) {
            Some(target) if target[..] != path[..n + 1] => {
                let mut next = target.clone();
                next.extend(path[n + 1..].iter().cloned());
                path = next;
            }
            _ => return module,
        }
    }
    path
}

/// Whether `target` is `module` itself or one of its ancestors.
fn ancestor(target: &[String], module: &[String]) -> bool {
    module.starts_with(target)
}

/// The import graph of one crate's modules.
fn crate_graph(c: &Crate) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut reexports: BTreeMap<Vec<String>, BTreeMap<String, Vec<String>>> = BTreeMap::new();
    let mut named = BTreeMap::new();
    for (module, src) in &c.modules {
        let (n, r) = paths(module, src, &c.modules);
        reexports.entry(module.clone()).or_default().extend(r.into_iter().map(|(p, b)| (b, p)));
        named.insert(module.clone(), n);
    }
    let mut g = BTreeMap::new();
    for (module, paths) in named {
        let to: BTreeSet<Module> = paths
            .iter()
            .map(|p| resolve(c, &reexports, p))
            .filter(|t| !ancestor(t, &module))
            .map(|t| (c.name.clone(), t))
            .collect();
        g.insert((c.name.clone(), module), to);
    }
    g
}

/// The import graph of every module of pada's crates.
fn graph(root: &Path) -> BTreeMap<Module, BTreeSet<Module>> {
    let mut g = BTreeMap::new();
    for (name, dir) in [
        ("shared", "shared/src"),
        ("robot-file", "robot-file/src"),
        ("sim", "sim/src"),
        ("telemetry", "telemetry/src"),
        ("servos", "servos/src"),
        ("host", "host/src"),
        ("firmware", "firmware/src"),
        ("python", "python/src"),
    ] {
        g.extend(crate_graph(&load(name, &root.join(dir))));
    }
    g
}

/// Strongly connected components with more than one module (Tarjan).
fn circles(g: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<Module>> {
    struct T<'a> {
        g: &'a BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<&'a Module, usize>,
        low: BTreeMap<&'a Module, usize>,
        on: BTreeSet<&'a Module>,
        stack: Vec<&'a Module>,
        next: usize,
        out: Vec<Vec<Module>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a Module) {
        t.index.insert(v, t.next);
        t.low.insert(v, t.next);
        t.next += 1;
        t.stack.push(v);
        t.on.insert(v);
        if let Some(ws) = t.g.get(v) {
            for w in ws {
                let Some((w, _)) = t.g.get_key_value(w) else { continue };
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let l = t.low[w].min(t.low[v]);
                    t.low.insert(v, l);
                } else if t.on.contains(w) {
                    let l = t.index[w].min(t.low[v]);
                    t.low.insert(v, l);
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut scc = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                scc.push(w.clone());
                if w == v {
                    break;
                }
            }
            if scc.len() > 1 {
                scc.sort();
                t.out.push(scc);
            }
        }
    }
    let mut t = T { g, index: BTreeMap::new(), low: BTreeMap::new(), on: BTreeSet::new(), stack: Vec::new(), next: 0, out: Vec::new() };
    for v in g.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out.sort();
    t.out
}

/// The repository (or another tree with the same folders, from
/// `PADA_SOURCE_ROOT`, to check an older commit by hand).
fn repo() -> PathBuf {
    match std::env::var_os("PADA_SOURCE_ROOT") {
        Some(root) => PathBuf::from(root),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf(),
    }
}

#[test]
fn no_modules_import_each_other_except_the_known_circles() {
    let g = graph(&repo());
    assert!(g.len() > 100, "only {} modules found", g.len());
    let all = circles(&g);
    let found: Vec<Vec<String>> = all.iter().map(|c| c.iter().map(name).collect()).collect();
    for c in &found {
        println!("circle: {}", c.join(" ↔ "));
        for m in c {
            let key = g.keys().find(|k| &name(k) == m).unwrap();
            let inside: Vec<String> = g[key].iter().filter(|t| c.contains(&name(t))).map(name).collect();
            println!("  {m} → {}", inside.join(", "));
        }
    }
    let known: Vec<Vec<String>> = KNOWN.iter().map(|c| c.iter().map(|s| s.to_string()).collect()).collect();
    let new: Vec<&Vec<String>> = found.iter().filter(|c| !known.contains(c)).collect();
    let gone: Vec<&Vec<String>> = known.iter().filter(|c| !found.contains(c)).collect();
    assert!(new.is_empty(), "modules that import each other (through a circle): {new:?}");
    assert!(gone.is_empty(), "listed in KNOWN but no longer a circle (remove them): {gone:?}");
}

#[test]
fn the_check_sees_a_circle() {
    let dir = tempfile::tempdir().unwrap();
    for (f, text) in [
        ("lib.rs", "mod a; mod b; mod c; mod d; pub use d::D;"),
        ("d.rs", "use crate::c::C; pub struct D;"),
        ("a.rs", "use crate::b::B; // crate::c in a comment\npub struct A;"),
        ("b.rs", "pub struct B; fn f() -> super::a::A { crate::a::A }\n#[cfg(test)]\nmod tests { use crate::c::C; }"),
        ("c.rs", "use super::{a::A, b};\nconst S: &str = \"crate::a\"; pub struct C; fn f() -> crate::D { todo!() }"),
    ] {
        fs::write(dir.path().join(f), text).unwrap();
    }
    let g = crate_graph(&load("t", dir.path()));
    let found: Vec<Vec<String>> = circles(&g).iter().map(|c| c.iter().map(name).collect()).collect();
    // a ↔ b directly; c → the root's re-export of d::D, and d → c.
    assert_eq!(found, [vec!["t::a".to_string(), "t::b".to_string()], vec!["t::c".to_string(), "t::d".to_string()]]);
}
