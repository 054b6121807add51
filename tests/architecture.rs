//! The crate's layering, read from its sources: no import cycle between files, and the arrows
//! ARCHITECTURE.md says never exist. A path the code names (`crate::a::b`, `super::c`, in `use`
//! lines or inline) is an arrow from its file to the file that defines it; comments and
//! `#[cfg(test)]` code are left out (tests may reach anywhere).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The modules of `src/` by path (`sampling::linear_scan`, `pipeline`; the crate root is ""),
/// each with its code: comments and `#[cfg(test)]` items removed.
fn modules() -> BTreeMap<String, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                files.push(path);
            }
        }
    }
    let mut out = BTreeMap::new();
    let mut test_only = BTreeSet::new();
    for file in &files {
        let rel = file.strip_prefix(&root).unwrap().with_extension("");
        let mut parts: Vec<String> = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect();
        if parts[0] == "bin" {
            continue;
        }
        if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
            parts.pop();
        }
        let name = parts.join("::");
        let (code, test_children) = without_tests(&std::fs::read_to_string(file).unwrap());
        for child in test_children {
            test_only.insert(if name.is_empty() {
                child
            } else {
                format!("{name}::{child}")
            });
        }
        out.insert(name, code);
    }
    out.retain(|name, _| {
        !test_only
            .iter()
            .any(|t| name == t || name.starts_with(&format!("{t}::")))
    });
    out
}

/// `text` without comments and without the items under `#[cfg(test)]`; and the names of the
/// child modules declared there as files (`#[cfg(test)] mod tests;`).
fn without_tests(text: &str) -> (String, Vec<String>) {
    let code: Vec<String> = text.lines().map(strip_comment).collect();
    let mut out = Vec::new();
    let mut children = Vec::new();
    let mut i = 0;
    while i < code.len() {
        if code[i].trim() != "#[cfg(test)]" {
            out.push(code[i].clone());
            i += 1;
            continue;
        }
        // Skip further attributes, then the item: one line ending in `;`, or a braced block.
        i += 1;
        while i < code.len() && code[i].trim_start().starts_with("#[") {
            i += 1;
        }
        let Some(first) = code.get(i) else { break };
        let item = first.trim();
        if let Some(name) = item.strip_prefix("mod ").and_then(|m| m.strip_suffix(';')) {
            children.push(name.trim().to_string());
            i += 1;
            continue;
        }
        let mut depth = 0i64;
        let mut opened = false;
        while i < code.len() {
            let line = without_quoted(&code[i]);
            depth += line.matches('{').count() as i64 - line.matches('}').count() as i64;
            opened |= line.contains('{');
            i += 1;
            if (opened && depth <= 0) || (!opened && line.trim_end().ends_with(';')) {
                break;
            }
        }
    }
    (out.join("\n"), children)
}

/// A line without its `//` comment (outside string literals).
fn strip_comment(line: &str) -> String {
    let bytes = line.as_bytes();
    let mut in_string = false;
    let mut k = 0;
    while k < bytes.len() {
        match bytes[k] {
            b'\\' if in_string => k += 1,
            b'"' => in_string = !in_string,
            b'/' if !in_string && bytes.get(k + 1) == Some(&b'/') => return line[..k].to_string(),
            _ => {}
        }
        k += 1;
    }
    line.to_string()
}

/// A line with the contents of its string and character literals blanked (for brace counting).
fn without_quoted(line: &str) -> String {
    let mut out = String::new();
    let mut in_string = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if in_string => {
                chars.next();
            }
            '"' => in_string = !in_string,
            '\'' if !in_string => {
                // A character literal ('{', '\n') is skipped; a lifetime is kept.
                let rest: String = chars.clone().take(3).collect();
                if rest.len() >= 2 && (rest.chars().nth(1) == Some('\'') || rest.starts_with('\\'))
                {
                    for d in chars.by_ref() {
                        if d == '\'' {
                            break;
                        }
                    }
                }
            }
            _ if in_string => {}
            _ => out.push(c),
        }
    }
    out
}

/// The module paths `code` names, relative to the crate root: `crate::a::b` and `super::c`
/// (from module `name`), with each name of a `{...}` group.
fn named_paths(name: &str, code: &str) -> BTreeSet<String> {
    let parent_of = |m: &str| {
        m.rsplit_once("::")
            .map_or(String::new(), |(p, _)| p.to_string())
    };
    let mut out = BTreeSet::new();
    for (prefix, base) in [("crate::", String::new()), ("super::", parent_of(name))] {
        let mut rest = code;
        while let Some(at) = rest.find(prefix) {
            let before = rest[..at].chars().last();
            rest = &rest[at + prefix.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let mut path = base.clone();
            let mut tail = rest;
            loop {
                let ident: String = tail
                    .chars()
                    .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '_')
                    .collect();
                if ident.is_empty() || ident == "super" {
                    break;
                }
                path = if path.is_empty() {
                    ident.clone()
                } else {
                    format!("{path}::{ident}")
                };
                tail = &tail[ident.len()..];
                match tail.strip_prefix("::") {
                    Some(t) => tail = t,
                    None => break,
                }
            }
            out.insert(path.clone());
            // A group: each of its first names, under the path.
            if let Some(group) = tail.strip_prefix('{') {
                let group = &group[..group.find('}').unwrap_or(group.len())];
                for item in group.split(',') {
                    let first = item.trim().split("::").next().unwrap_or("").trim();
                    if !first.is_empty()
                        && first.chars().all(|c| c.is_ascii_lowercase() || c == '_')
                    {
                        out.insert(if path.is_empty() {
                            first.to_string()
                        } else {
                            format!("{path}::{first}")
                        });
                    }
                }
            }
        }
    }
    out
}

/// The arrows between files: module → the modules (files) it names, apart from itself, its own
/// submodules and the modules it is part of (a `mod.rs` and its children use each other).
fn arrows() -> BTreeMap<String, BTreeSet<String>> {
    let mods = modules();
    let mut out = BTreeMap::new();
    for (name, code) in &mods {
        let mut to = BTreeSet::new();
        for path in named_paths(name, code) {
            // The longest module the path starts with.
            let mut target = path.as_str();
            while !mods.contains_key(target) {
                match target.rsplit_once("::") {
                    Some((p, _)) => target = p,
                    None => {
                        target = "";
                        break;
                    }
                }
            }
            let related =
                |a: &str, b: &str| a.is_empty() || a == b || b.starts_with(&format!("{a}::"));
            if !target.is_empty() && !related(name, target) && !related(target, name) {
                to.insert(target.to_string());
            }
        }
        out.insert(name.clone(), to);
    }
    out
}

fn top(module: &str) -> &str {
    module.split("::").next().unwrap()
}

#[test]
fn the_reader_sees_the_known_arrows() {
    // The reading itself: arrows that exist are found, so the checks below are not vacuous.
    let a = arrows();
    assert!(a.len() > 80, "{} modules", a.len());
    for (from, to) in [
        ("pipeline::scan", "sampling::linear_scan"),
        ("pipeline::finish", "finish::untangle"),
        ("pipeline::points", "pipeline::finish"),
        ("sampling::features", "sampling::curves"),
        ("surface::front_regions", "surface::winding_number"),
        ("finish::optimize", "mesh::edit"),
        ("finish::optimize::relax", "triangulate::flip"),
    ] {
        assert!(
            a[from].contains(to),
            "{from} -> {to} not found: {:?}",
            a[from]
        );
    }
    // Test code is not read.
    let (code, _) =
        without_tests("use crate::a;\n#[cfg(test)]\nmod tests {\n    use crate::b;\n}\n");
    assert!(
        code.contains("crate::a") && !code.contains("crate::b"),
        "{code}"
    );
    let (code, children) = without_tests("#[cfg(test)]\nmod tests;\nfn f() { let c = '{'; }\n");
    assert_eq!(children, ["tests"]);
    assert!(code.contains("fn f()"));
}

#[test]
fn no_file_imports_a_file_that_imports_it() {
    let a = arrows();
    // Depth-first search for a cycle, reported as its path.
    fn visit(
        v: &str,
        a: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(v.to_string(), 1);
        path.push(v.to_string());
        for w in a.get(v).into_iter().flatten() {
            match state.get(w.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == w).unwrap();
                    let mut cycle = path[start..].to_vec();
                    cycle.push(w.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(w, a, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(v.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for v in a.keys() {
        if state.get(v.as_str()).copied().unwrap_or(0) == 0 {
            if let Some(cycle) = visit(v, &a, &mut state, &mut Vec::new()) {
                panic!("an import cycle: {}", cycle.join(" -> "));
            }
        }
    }
}

#[test]
fn the_never_arrows_do_not_exist() {
    // (from, to, why): no module of the first group names one of the second.
    let pipeline = ["pipeline", "sampling", "triangulate", "finish", "app"];
    let stages = [
        "geometry",
        "spatial",
        "mesh",
        "io",
        "surface",
        "sampling",
        "triangulate",
        "finish",
        "points",
        "manifold",
        "measure",
        "kernel",
    ];
    let analysis = ["check", "report"];
    let rules: [(&[&str], &[&str], &str); 6] = [
        (
            &["geometry", "spatial", "mesh", "io"],
            &pipeline,
            "the foundations know nothing of the pipeline",
        ),
        (
            &["surface", "check", "report"],
            &["sampling", "triangulate", "finish", "pipeline", "app"],
            "the input surface and the analysis never reach into the stages that use them",
        ),
        (
            &["sampling"],
            &["triangulate", "finish"],
            "sampling never imports triangulate or finish",
        ),
        (
            &["triangulate"],
            &["finish"],
            "the triangulation never imports the finishing stage that runs after it",
        ),
        (&stages, &["pipeline", "app"], "no stage knows what runs it"),
        (&stages, &analysis, "check and report feed no stage"),
    ];
    let mut broken = Vec::new();
    for (from, to) in arrows() {
        for t in &to {
            for (group, never, why) in &rules {
                if group.contains(&top(&from)) && never.contains(&top(t)) && top(&from) != top(t) {
                    broken.push(format!("{from} -> {t} ({why})"));
                }
            }
        }
    }
    assert!(
        broken.is_empty(),
        "arrows that must not exist:\n{}",
        broken.join("\n")
    );
}
