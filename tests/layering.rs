//! The one-way floors of the design, checked on the source: the renderer draws plain data and
//! imports neither the simulation nor the scenes; the simulation, the cloth and the mesh know
//! nothing of graphics or windows.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;

/// Every `.rs` file under `src/<dir>`, with its text.
fn sources(dir: &str) -> Vec<(String, String)> {
    fn walk(path: &Path, out: &mut Vec<(String, String)>) {
        for entry in std::fs::read_dir(path).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                out.push((path.display().to_string(), text));
            }
        }
    }
    let mut out = Vec::new();
    walk(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(dir),
        &mut out,
    );
    assert!(!out.is_empty(), "no sources under src/{dir}");
    out
}

/// Lines of code (not comments) in `dir` that mention any of `words`.
fn offending_lines(dir: &str, words: &[&str]) -> Vec<String> {
    sources(dir)
        .into_iter()
        .flat_map(|(file, text)| {
            text.lines()
                .enumerate()
                .filter(|(_, l)| !l.trim_start().starts_with("//"))
                .filter(|(_, l)| words.iter().any(|w| l.contains(w)))
                .map(|(n, l)| format!("{file}:{}: {}", n + 1, l.trim()))
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn the_renderer_imports_neither_sim_nor_scene() {
    let bad = offending_lines(
        "render",
        &[
            "crate::sim",
            "crate::scene",
            "super::super::sim",
            "super::super::scene",
        ],
    );
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn sim_cloth_and_mesh_use_no_graphics_or_window_crate() {
    for dir in ["sim", "cloth", "mesh"] {
        let bad = offending_lines(dir, &["wgpu", "egui", "eframe", "winit"]);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
    }
}

/// The renderer and the GPU backend meet only in the device layer below them: neither
/// names the other.
#[test]
fn render_and_gpu_reach_each_other_only_through_the_device_layer() {
    for (dir, other) in [("render", "gpu"), ("gpu", "render")] {
        let words = [format!("crate::{other}"), format!("super::super::{other}")];
        let words: Vec<&str> = words.iter().map(String::as_str).collect();
        let bad = offending_lines(dir, &words);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
    }
}

/// A folder's `mod.rs` (and `lib.rs`) only declares its files and re-exports what they
/// define: code lives in a file named after what it is.
#[test]
fn module_files_only_declare_and_re_export() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut bad = Vec::new();
    for (file, text) in sources("") {
        let name = Path::new(&file).file_name().unwrap_or_default();
        if name != "mod.rs" && Path::new(&file) != root.join("lib.rs") {
            continue;
        }
        let ast = syn::parse_file(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
        for item in &ast.items {
            let allowed = match item {
                syn::Item::Mod(m) => m.content.is_none(),
                syn::Item::Use(_) => true,
                _ => false,
            };
            if !allowed {
                bad.push(format!("{file}: {}", quote_item(item)));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// What kind of item `item` is, for a message.
fn quote_item(item: &syn::Item) -> &'static str {
    match item {
        syn::Item::Fn(_) => "a function",
        syn::Item::Struct(_) | syn::Item::Enum(_) | syn::Item::Union(_) => "a type",
        syn::Item::Impl(_) => "an impl",
        syn::Item::Mod(_) => "an inline module",
        _ => "an item that is neither `mod` nor `use`",
    }
}

/// No source file is longer than 800 lines, its tests included: a longer one holds more
/// than one concept (split it, or move its tests to a sibling file).
#[test]
fn no_source_file_is_over_800_lines() {
    let long: Vec<String> = sources("")
        .into_iter()
        .map(|(file, text)| (file, text.lines().count()))
        .filter(|&(_, lines)| lines > 800)
        .map(|(file, lines)| format!("{file}: {lines} lines"))
        .collect();
    assert!(long.is_empty(), "{}", long.join("\n"));
}

/// `anyhow` is for the binary's edges (its `main` and the command line); the library returns
/// typed errors a caller can act on.
#[test]
fn only_the_command_line_uses_anyhow() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let bad: Vec<String> = offending_lines("", &["anyhow"])
        .into_iter()
        .filter(|line| {
            let file = line.split(':').next().unwrap_or_default();
            let file = Path::new(file)
                .strip_prefix(&root)
                .unwrap_or(Path::new(file));
            !(file.starts_with("cli") || file == Path::new("main.rs"))
        })
        .collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

// ------------------------------------------------------------ import cycles between files

/// Which crate a module lives in: the library, or the binary (`main.rs` and the modules it
/// declares).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Crate {
    Lib,
    Bin,
}

/// An absolute module or item path.
type Path2 = (Crate, Vec<String>);

/// One source file: where it sits, what it defines, re-exports and refers to.
struct SourceFile {
    name: String,
    module: Vec<String>,
    defs: HashSet<String>,
    /// `pub use` names → absolute targets (globs under `*`).
    reexports: Vec<(String, Path2)>,
    /// Paths used (private `use`s and paths in code), absolute where they could be made so,
    /// each with the path as written.
    refs: Vec<(Path2, String)>,
}

/// Every `.rs` file under `src`, parsed, with its crate and module path.
fn parse_sources() -> Vec<(String, Crate, Vec<String>, syn::File)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let main = syn::parse_file(&std::fs::read_to_string(root.join("main.rs")).unwrap()).unwrap();
    let bin_mods: HashSet<String> = (main.items.iter())
        .filter_map(|i| match i {
            syn::Item::Mod(m) if m.content.is_none() => Some(m.ident.to_string()),
            _ => None,
        })
        .collect();
    let mut out = Vec::new();
    for (file, text) in sources("") {
        let relative = Path::new(&file).strip_prefix(&root).unwrap().to_path_buf();
        let mut parts: Vec<String> = (relative.iter())
            .map(|p| p.to_string_lossy().into_owned())
            .collect();
        let last = parts.pop().unwrap();
        let stem = last.trim_end_matches(".rs").to_string();
        if !matches!(stem.as_str(), "mod" | "lib" | "main") {
            parts.push(stem.clone());
        }
        let krate = if stem == "main" || parts.first().is_some_and(|p| bin_mods.contains(p)) {
            Crate::Bin
        } else {
            Crate::Lib
        };
        let ast = syn::parse_file(&text).unwrap_or_else(|e| panic!("{file}: {e}"));
        out.push((relative.display().to_string(), krate, parts, ast));
    }
    out
}

/// Flattens a `use` tree into `(path, alias)` pairs (`*` for a glob).
fn use_paths(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_paths(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) if n.ident == "self" => {
            out.push((prefix.clone(), prefix.last().cloned().unwrap_or_default()))
        }
        syn::UseTree::Name(n) => {
            let mut path = prefix.clone();
            path.push(n.ident.to_string());
            out.push((path, n.ident.to_string()));
        }
        syn::UseTree::Rename(r) => {
            let mut path = prefix.clone();
            path.push(r.ident.to_string());
            out.push((path, r.rename.to_string()));
        }
        syn::UseTree::Glob(_) => out.push((prefix.clone(), "*".into())),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_paths(t, prefix, out);
            }
        }
    }
}

/// Collects a file's definitions, `use`s and paths, tracking inline modules.
struct Collector {
    /// Inline modules entered (`mod tests { … }`).
    inline: Vec<String>,
    defs: HashSet<String>,
    /// `(path as written, alias, is a re-export, inline depth)`.
    uses: Vec<(Vec<String>, String, bool, usize)>,
    /// `(path as written, inline depth)`.
    paths: Vec<(Vec<String>, usize)>,
}

impl<'a> syn::visit::Visit<'a> for Collector {
    fn visit_item(&mut self, item: &'a syn::Item) {
        if self.inline.is_empty() {
            let name = match item {
                syn::Item::Struct(i) => Some(&i.ident),
                syn::Item::Enum(i) => Some(&i.ident),
                syn::Item::Fn(i) => Some(&i.sig.ident),
                syn::Item::Trait(i) => Some(&i.ident),
                syn::Item::Type(i) => Some(&i.ident),
                syn::Item::Const(i) => Some(&i.ident),
                syn::Item::Static(i) => Some(&i.ident),
                syn::Item::Union(i) => Some(&i.ident),
                syn::Item::Macro(i) => i.ident.as_ref(),
                _ => None,
            };
            if let Some(name) = name {
                self.defs.insert(name.to_string());
            }
        }
        syn::visit::visit_item(self, item);
    }

    fn visit_item_mod(&mut self, m: &'a syn::ItemMod) {
        if m.content.is_some() {
            self.inline.push(m.ident.to_string());
            syn::visit::visit_item_mod(self, m);
            self.inline.pop();
        }
    }

    fn visit_item_use(&mut self, u: &'a syn::ItemUse) {
        let reexport = !matches!(u.vis, syn::Visibility::Inherited);
        let mut found = Vec::new();
        use_paths(&u.tree, &mut Vec::new(), &mut found);
        for (path, alias) in found {
            self.uses.push((path, alias, reexport, self.inline.len()));
        }
    }

    fn visit_path(&mut self, p: &'a syn::Path) {
        if p.leading_colon.is_none() && p.segments.len() > 1 {
            let segs = p.segments.iter().map(|s| s.ident.to_string()).collect();
            self.paths.push((segs, self.inline.len()));
        }
        syn::visit::visit_path(self, p);
    }
}

/// The module tree: module paths → file index.
struct Tree {
    files: Vec<SourceFile>,
    modules: HashMap<(Crate, Vec<String>), usize>,
}

impl Tree {
    fn load() -> Tree {
        let parsed = parse_sources();
        let modules: HashMap<(Crate, Vec<String>), usize> = (parsed.iter().enumerate())
            .map(|(i, (_, k, m, _))| ((*k, m.clone()), i))
            .collect();
        let mut files = Vec::new();
        for (name, krate, module, ast) in &parsed {
            let mut c = Collector {
                inline: Vec::new(),
                defs: HashSet::new(),
                uses: Vec::new(),
                paths: Vec::new(),
            };
            syn::visit::Visit::visit_file(&mut c, ast);
            let tree = Tree {
                files: Vec::new(),
                modules: modules.clone(),
            };
            // Aliases a file's `use`s bring in (all scopes merged).
            let mut aliases: HashMap<String, Path2> = HashMap::new();
            let mut reexports = Vec::new();
            let mut refs = Vec::new();
            for (path, alias, reexport, depth) in &c.uses {
                let Some(abs) = tree.absolute(*krate, module, *depth, path, &aliases) else {
                    continue;
                };
                if alias != "*" {
                    aliases.insert(alias.clone(), abs.clone());
                }
                if *reexport {
                    reexports.push((alias.clone(), abs));
                } else {
                    refs.push((abs, path.join("::")));
                }
            }
            for (path, depth) in &c.paths {
                if let Some(abs) = tree.absolute(*krate, module, *depth, path, &aliases) {
                    refs.push((abs, path.join("::")));
                }
            }
            files.push(SourceFile {
                name: name.clone(),
                module: module.clone(),
                defs: c.defs,
                reexports,
                refs,
            });
        }
        Tree { files, modules }
    }

    /// `path` as written in `module` (inside `depth` inline modules) made absolute; `None`
    /// for a path into another crate or a local name.
    fn absolute(
        &self,
        krate: Crate,
        module: &[String],
        depth: usize,
        path: &[String],
        aliases: &HashMap<String, Path2>,
    ) -> Option<Path2> {
        let (first, rest) = path.split_first()?;
        let mut here = module.to_vec();
        let (krate, mut base) = match first.as_str() {
            "crate" => (krate, Vec::new()),
            "clothsim" => (Crate::Lib, Vec::new()),
            "self" => (krate, here),
            "super" => {
                // Inline modules are inside the file's module: their `super` is the file.
                if depth == 0 {
                    here.pop();
                }
                (krate, here)
            }
            name if self
                .modules
                .contains_key(&(krate, [module, &[name.to_string()]].concat())) =>
            {
                (krate, [module, &[name.to_string()]].concat())
            }
            name => {
                let (k, target) = aliases.get(name)?.clone();
                (k, target)
            }
        };
        let mut rest = rest.iter().peekable();
        // Leading `super`s after the first.
        while rest.peek().is_some_and(|s| *s == "super") {
            base.pop();
            rest.next();
        }
        base.extend(rest.cloned());
        Some((krate, base))
    }

    /// The file that defines what `path` names, following re-exports.
    fn resolve(&self, path: &Path2, hops: usize) -> Option<usize> {
        let (krate, segs) = path;
        if hops > 16 {
            return None;
        }
        let mut module = *self.modules.get(&(*krate, Vec::new()))?;
        for (i, seg) in segs.iter().enumerate() {
            let deeper = [&self.files[module].module[..], std::slice::from_ref(seg)].concat();
            if let Some(&child) = self.modules.get(&(*krate, deeper)) {
                module = child;
                continue;
            }
            let file = &self.files[module];
            if file.defs.contains(seg) {
                return Some(module);
            }
            for (alias, target) in &file.reexports {
                if alias == seg {
                    let mut next = target.clone();
                    next.1.extend(segs[i + 1..].iter().cloned());
                    return self.resolve(&next, hops + 1);
                }
                if alias == "*" {
                    let mut next = target.clone();
                    next.1.extend(segs[i..].iter().cloned());
                    if let Some(found) = self.resolve(&next, hops + 1) {
                        return Some(found);
                    }
                }
            }
            return None;
        }
        Some(module)
    }

    /// File → files it depends on, each with the first path that makes it so.
    fn edges(&self) -> Vec<BTreeMap<usize, String>> {
        (0..self.files.len())
            .map(|i| {
                let mut out = BTreeMap::new();
                for (path, written) in &self.files[i].refs {
                    if let Some(target) = self.resolve(path, 0)
                        && target != i
                    {
                        out.entry(target).or_insert_with(|| written.clone());
                    }
                }
                out
            })
            .collect()
    }
}

/// Strongly connected components of more than one file (Tarjan).
fn cycles<T>(edges: &[BTreeMap<usize, T>]) -> Vec<Vec<usize>> {
    struct State<'a, T> {
        edges: &'a [BTreeMap<usize, T>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on_stack: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit<T>(s: &mut State<'_, T>, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in s.edges[v].keys() {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(i) if s.on_stack[w] => s.low[v] = s.low[v].min(i),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.out.push(component);
            }
        }
    }
    let n = edges.len();
    let mut s = State {
        edges,
        index: vec![None; n],
        low: vec![0; n],
        on_stack: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// No two files import each other, directly or around a loop: a file's `use`s, `super::`
/// paths and paths in code are followed through re-exports to the file that defines what
/// they name. (A loop makes every file in it a dependency of every other: none can be
/// understood, tested or moved alone.)
#[test]
fn no_import_cycle_between_files() {
    let tree = Tree::load();
    assert!(tree.files.len() > 100, "{} files", tree.files.len());
    let edges = tree.edges();
    // The check can fail: the detector finds a loop made on purpose.
    assert_eq!(
        cycles(&[[(1, 0)].into(), [(0, 0)].into()]),
        vec![vec![1, 0]]
    );
    let found = cycles(&edges);
    let report: Vec<String> = found
        .iter()
        .map(|component| {
            let members: HashSet<usize> = component.iter().copied().collect();
            let lines: Vec<String> = component
                .iter()
                .flat_map(|&f| {
                    let tree = &tree;
                    (edges[f].iter())
                        .filter(|(t, _)| members.contains(t))
                        .map(move |(&t, line)| {
                            format!("  {} → {} ({line})", tree.files[f].name, tree.files[t].name)
                        })
                })
                .collect();
            lines.join("\n")
        })
        .collect();
    assert!(
        found.is_empty(),
        "{} import cycles:\n{}",
        found.len(),
        report.join("\n\n")
    );
}
