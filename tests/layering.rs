//! The crate's modules import each other in layers and without cycles: math at the bottom,
//! then settings / layout descriptions / text, the shader library and meshes, the ECS, the
//! renderer, and the front ends (scenes, files, the viewer, the bench) on top. Edges are read
//! from `crate::` paths in the source (comments and test modules left out), resolved to the
//! longest module path that exists. Only the layout descriptions (`src/layout`) match on a
//! shadow storage.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layer of a top-level module; a module may import only its own layer or lower ones.
fn layer(module: &str) -> u32 {
    match module.split("::").next().unwrap_or("") {
        "math" => 0,
        "settings" | "layout" | "text" => 1,
        "shader" | "mesh" => 2,
        "ecs" => 3,
        "render" => 4,
        _ => 5,
    }
}

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

/// The module a source file defines (`render::shadows` for `src/render/shadows/mod.rs`).
fn module_of(src: &Path, file: &Path) -> String {
    let relative = file.strip_prefix(src).unwrap().with_extension("");
    let parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    let parts = match parts.last().map(String::as_str) {
        Some("mod") => &parts[..parts.len() - 1],
        _ => &parts[..],
    };
    parts.join("::")
}

/// The `crate::` paths named in `text` outside comments and `mod tests`.
fn crate_paths(text: &str) -> Vec<String> {
    let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    let mut out = Vec::new();
    for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
        for (i, _) in line.match_indices("crate::") {
            let path: String = line[i + 7..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            out.push(path.trim_end_matches(':').to_string());
        }
    }
    out
}

/// The import graph of `src/`: module → modules it names (not its own ancestors).
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(&src, f)).collect();
    let resolve = |path: &str| {
        let mut parts: Vec<&str> = path.split("::").collect();
        while !parts.is_empty() {
            let candidate = parts.join("::");
            if modules.contains(&candidate) {
                return Some(candidate);
            }
            parts.pop();
        }
        None
    };
    let mut graph = BTreeMap::new();
    for file in &files {
        let module = module_of(&src, file);
        let text = std::fs::read_to_string(file).unwrap();
        let targets: BTreeSet<String> = crate_paths(&text)
            .iter()
            .filter_map(|p| resolve(p))
            .filter(|t| *t != module && !module.starts_with(&format!("{t}::")))
            .collect();
        graph.insert(module, targets);
    }
    graph
}

/// The strongly connected components of more than one module (Tarjan).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, (usize, usize)>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        s.index.insert(v, (s.next, s.next));
        s.next += 1;
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph.get(v).into_iter().flatten() {
            if !s.index.contains_key(w.as_str()) {
                visit(s, w);
                let low = s.index[w.as_str()].1.min(s.index[v].1);
                s.index.get_mut(v).unwrap().1 = low;
            } else if s.on_stack.contains(w.as_str()) {
                let low = s.index[w.as_str()].0.min(s.index[v].1);
                s.index.get_mut(v).unwrap().1 = low;
            }
        }
        if s.index[v].0 == s.index[v].1 {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.out.push(component);
            }
        }
    }
    let mut state = State {
        graph,
        index: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !state.index.contains_key(v.as_str()) {
            visit(&mut state, v);
        }
    }
    state.out
}

#[test]
fn no_module_imports_a_higher_layer() {
    let graph = graph();
    let edges: usize = graph.values().map(BTreeSet::len).sum();
    let upward: Vec<_> = graph
        .iter()
        .flat_map(|(a, targets)| targets.iter().map(move |b| (a, b)))
        .filter(|(a, b)| layer(b) > layer(a))
        .collect();
    assert!(upward.is_empty(), "imports of a higher layer: {upward:?}");
    assert!(
        graph.len() > 150 && edges > 500,
        "only {} modules and {edges} edges read",
        graph.len()
    );
}

#[test]
fn the_modules_import_each_other_without_cycles() {
    let graph = graph();
    let found = cycles(&graph);
    assert!(found.is_empty(), "import cycles: {found:?}");
    let mut planted = graph.clone();
    planted.get_mut("math::aabb").unwrap().insert("math::frustum".into());
    planted.get_mut("math::frustum").unwrap().insert("math::aabb".into());
    assert_eq!(cycles(&planted).len(), 1, "a planted cycle is found");
}

/// The patterns of match arms on a shadow storage (`ShadowStorage::Spots =>`, and each of an
/// or-pattern) in `text`, outside comments and `mod tests`.
fn storage_arms(text: &str) -> usize {
    let code = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    let mut arms = 0;
    for line in code.lines().filter(|l| !l.trim_start().starts_with("//")) {
        for (i, _) in line.match_indices("ShadowStorage::") {
            let rest = line[i + 15..].trim_start_matches(|c: char| c.is_alphanumeric() || c == '_');
            let rest = rest.trim_start();
            arms += usize::from(rest.starts_with("=>") || rest.starts_with("| ShadowStorage::"));
        }
    }
    arms
}

#[test]
fn only_the_layout_descriptions_match_on_a_storage() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut outside = Vec::new();
    let mut inside = 0;
    for file in &files {
        let arms = storage_arms(&std::fs::read_to_string(file).unwrap());
        if module_of(&src, file).starts_with("layout") {
            inside += arms;
        } else if arms > 0 {
            outside.push((module_of(&src, file), arms));
        }
    }
    assert!(
        outside.is_empty(),
        "matches on ShadowStorage outside src/layout: {outside:?}"
    );
    assert!(
        inside >= 3,
        "{inside} storage arms read in src/layout (its description has one per storage)"
    );
    let planted =
        "match s {\n    ShadowStorage::Spots => 1,\n    ShadowStorage::Points | ShadowStorage::Cascades => 2,\n}";
    assert_eq!(storage_arms(planted), 3, "each pattern of a planted match is found");
}
