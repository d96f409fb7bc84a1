//! The layout of the core (crate docs, `lib.rs`): module groups follow the paper's
//! pipeline and dependencies point one way. This test reads the sources and checks that
//! no module imports a module that imports it back, directly or through others, and that
//! the same holds between the groups (`spline`, `boundary`, `discrete`, ...). Test
//! modules and comments (doc links) are not imports.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `boundary/fit.rs` -> `["boundary", "fit"]`, `boundary/mod.rs` -> `["boundary"]`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    if parts.last().is_some_and(|p| p == "mod" || p == "lib") {
        parts.pop();
    }
    parts
}

/// The code of a file without comments and without its `#[cfg(test)]` modules.
fn code(text: &str) -> String {
    let mut out = String::new();
    let mut skip_depth: Option<i32> = None;
    let mut depth = 0i32;
    for line in text.lines() {
        let t = line.trim_start();
        if t.starts_with("//") {
            continue;
        }
        if skip_depth.is_none() && t.starts_with("#[cfg(test)]") {
            // the next item is test code: skip it (a module or a single item)
            skip_depth = Some(depth);
            continue;
        }
        let opens = line.matches('{').count() as i32;
        let closes = line.matches('}').count() as i32;
        depth += opens - closes;
        if let Some(d) = skip_depth {
            if depth <= d && (closes > 0 || t.ends_with(';')) {
                skip_depth = None;
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Every `crate::a::b::...` and `super::a::...` path in `code`, resolved against
/// `module`, as the longest prefix that names a known module.
fn references(code: &str, module: &[String], is_mod_rs: bool, known: &BTreeSet<Vec<String>>) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    let bytes = code.as_bytes();
    for start in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(start) {
            let at = from + k;
            from = at + start.len();
            if at > 0 && (bytes[at - 1].is_ascii_alphanumeric() || bytes[at - 1] == b'_') {
                continue;
            }
            let rest = &code[at + start.len()..];
            let path: Vec<String> = rest
                .split("::")
                .map(|s| s.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect::<String>())
                .take_while(|s| !s.is_empty())
                .collect();
            let mut base: Vec<String> = if start == "crate::" {
                Vec::new()
            } else {
                // `super` of a file module is its parent; of a `mod.rs` module, the grandparent
                let mut b = module.to_vec();
                b.pop();
                if is_mod_rs {
                    b.pop();
                }
                b
            };
            let mut best = base.clone();
            for seg in path {
                base.push(seg);
                if known.contains(&base) {
                    best = base.clone();
                } else {
                    break;
                }
            }
            if !best.is_empty() && best != module {
                out.insert(best);
            }
        }
    }
    out
}

fn find_cycle<T: Ord + Clone + std::fmt::Debug>(graph: &BTreeMap<T, BTreeSet<T>>) -> Option<Vec<T>> {
    fn visit<T: Ord + Clone>(
        n: &T,
        graph: &BTreeMap<T, BTreeSet<T>>,
        state: &mut BTreeMap<T, u8>,
        stack: &mut Vec<T>,
    ) -> Option<Vec<T>> {
        state.insert(n.clone(), 1);
        stack.push(n.clone());
        for m in graph.get(n).into_iter().flatten() {
            match state.get(m).copied().unwrap_or(0) {
                1 => {
                    let at = stack.iter().position(|x| x == m).unwrap();
                    let mut cycle = stack[at..].to_vec();
                    cycle.push(m.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(m, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(n.clone(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(n, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn dependencies_point_one_way() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let known: BTreeSet<Vec<String>> = files.iter().map(|f| module_of(&src, f)).collect();
    // modules declared as `#[cfg(test)] mod name;` are test code, with their descendants
    let mut test_modules: BTreeSet<Vec<String>> = BTreeSet::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let lines: Vec<&str> = text.lines().map(str::trim).collect();
        for w in lines.windows(2) {
            let decl = w[1].strip_prefix("pub(crate) ").or_else(|| w[1].strip_prefix("pub ")).unwrap_or(w[1]);
            if let (true, Some(name)) =
                (w[0] == "#[cfg(test)]", decl.strip_prefix("mod ").and_then(|d| d.strip_suffix(';')))
            {
                let mut m = module_of(&src, f);
                m.push(name.to_string());
                test_modules.insert(m);
            }
        }
    }
    let mut modules: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for f in &files {
        let module = module_of(&src, f);
        let is_mod_rs = f.file_name().is_some_and(|n| n == "mod.rs" || n == "lib.rs");
        // a file that is itself a test module (`certificate/tests.rs`) is test code
        if module.last().is_some_and(|m| m == "tests")
            || module.first().is_some_and(|m| m == "testutil")
            || test_modules.iter().any(|t| module.starts_with(t))
        {
            continue;
        }
        let text = std::fs::read_to_string(f).unwrap();
        let refs = references(&code(&text), &module, is_mod_rs, &known);
        // a module's references to its own ancestors' items are not cycles through the
        // `mod` declarations; references to descendants are (a parent using its child)
        modules.entry(module.clone()).or_default().extend(refs.into_iter().filter(|r| !module.starts_with(r)));
    }
    assert!(modules.len() > 30, "found only {} modules under {}", modules.len(), src.display());
    if let Some(c) = find_cycle(&modules) {
        let names: Vec<String> = c.iter().map(|m| m.join("::")).collect();
        panic!("modules import each other: {}", names.join(" -> "));
    }
    let mut groups: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (m, refs) in &modules {
        let Some(g) = m.first() else { continue };
        let entry = groups.entry(g.clone()).or_default();
        entry.extend(refs.iter().filter_map(|r| r.first()).filter(|r| *r != g).cloned());
    }
    if let Some(c) = find_cycle(&groups) {
        panic!("module groups import each other: {}", c.join(" -> "));
    }
    // the pipeline order of the crate docs: nothing below imports anything above
    let order = [
        "error",
        "linalg",
        "spline",
        "boundary",
        "discrete",
        "verify",
        "methods",
        "solve",
        "multipatch",
        "domain",
        "pipeline",
        "io",
    ];
    for (g, refs) in &groups {
        let Some(i) = order.iter().position(|o| o == g) else { continue };
        for r in refs {
            let j = order.iter().position(|o| o == r);
            assert!(j.is_some_and(|j| j < i), "group {g} imports {r}, which the crate docs put above it");
        }
    }
}

/// The checker itself finds a cycle, and ignores comments and test modules.
#[test]
fn the_checker_sees_cycles_and_ignores_tests() {
    let mut g: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    g.entry("a").or_default().insert("b");
    g.entry("b").or_default().insert("c");
    assert!(find_cycle(&g).is_none());
    g.entry("c").or_default().insert("a");
    assert_eq!(find_cycle(&g).unwrap(), vec!["a", "b", "c", "a"]);
    let text = "use crate::x::y;\n/// [`crate::z`]\n#[cfg(test)]\nmod tests {\n    use crate::w;\n}\n";
    let known: BTreeSet<Vec<String>> =
        [vec!["x".to_string()], vec!["z".to_string()], vec!["w".to_string()]].into_iter().collect();
    let r = references(&code(text), &["m".to_string()], false, &known);
    assert_eq!(r, [vec!["x".to_string()]].into_iter().collect());
}
