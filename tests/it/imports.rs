//! No import circle between source files: within each crate of the workspace (and this test
//! binary), the files' `use` lines form no cycle. A file that imports another sits above it;
//! two files that import each other (directly or through others) are one piece of code split
//! in two, and belong either together or with the shared part moved below both.
//!
//! Read from the sources (parsed with `syn`), not the compiler: each `use` path (`crate::`,
//! `super::`, `self::`, or a child module's name) is resolved to the deepest module file it
//! names, test modules included; paths into other crates are the layers' business
//! (`layers.rs`, where the compiler keeps the direction). A re-export
//! (`pub use`) is a signpost, not an import: a path through it leads to the file that defines
//! the item ([`import_graph`]).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use syn::visit::{self, Visit};
use syn::{ItemMod, ItemUse, UseTree, Visibility};

/// A module, as the path of names from its crate's root.
type Module = Vec<String>;

/// The module of `file` in the crate rooted at `dir` (`lib.rs`, `main.rs` and `mod.rs` name
/// their directory's module).
fn module_of(dir: &Path, file: &Path) -> Module {
    let rel = file.strip_prefix(dir).expect("under the crate's directory");
    let mut names: Module = rel
        .with_extension("")
        .iter()
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    let last = names.last().map(String::as_str);
    if matches!(last, Some("mod")) || (names.len() == 1 && matches!(last, Some("lib" | "main"))) {
        names.pop();
    }
    names
}

/// Every `.rs` file under `dir`, but the roots of other crates named in `skip`.
fn rust_files(dir: &Path, skip: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in fs::read_dir(&d).expect("a readable source directory") {
            let path = entry.expect("a directory entry").path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs")
                && !skip.iter().any(|s| path == dir.join(s))
            {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// One `use` declaration: the paths it imports (`a::{b, c as d}` gives `a::b` and `a::c`),
/// the inline modules (`mod tests { ... }`) it sits in, and whether it is a re-export
/// (`pub use`, any visibility).
struct Use {
    inline: Module,
    paths: Vec<String>,
    public: bool,
}

/// The `use` declarations of a file's syntax tree, inline modules and function bodies
/// included.
#[derive(Default)]
struct Uses {
    inline: Module,
    found: Vec<Use>,
}

impl<'ast> Visit<'ast> for Uses {
    fn visit_item_mod(&mut self, m: &'ast ItemMod) {
        self.inline.push(m.ident.to_string());
        visit::visit_item_mod(self, m);
        self.inline.pop();
    }

    fn visit_item_use(&mut self, u: &'ast ItemUse) {
        let mut paths = Vec::new();
        flatten(&u.tree, String::new(), &mut paths);
        self.found.push(Use {
            inline: self.inline.clone(),
            paths,
            public: !matches!(u.vis, Visibility::Inherited),
        });
    }
}

/// The paths of a use tree, each under `prefix`; a rename imports its original name, a glob
/// ends in `*`.
fn flatten(tree: &UseTree, prefix: String, out: &mut Vec<String>) {
    let joined = |name: &dyn std::fmt::Display| {
        if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}::{name}")
        }
    };
    match tree {
        UseTree::Path(p) => flatten(&p.tree, joined(&p.ident), out),
        UseTree::Name(n) => out.push(joined(&n.ident)),
        UseTree::Rename(r) => out.push(joined(&r.ident)),
        UseTree::Glob(_) => out.push(joined(&"*")),
        UseTree::Group(g) => g.items.iter().for_each(|t| flatten(t, prefix.clone(), out)),
    }
}

/// The `use` declarations of the source file `file`.
fn uses_of(file: &Path) -> Vec<Use> {
    let text = fs::read_to_string(file).expect("a readable source file");
    let tree = syn::parse_file(&text)
        .unwrap_or_else(|e| panic!("{}: not Rust syn can parse: {e}", file.display()));
    let mut uses = Uses::default();
    uses.visit_file(&tree);
    uses.found
}

/// The module file a use path in module `at` names, if it is in this crate, with the name
/// it imports from there (`None` where the path ends at the module itself).
fn resolve(
    modules: &BTreeSet<Module>,
    at: &Module,
    path: &str,
) -> Option<(Module, Option<String>)> {
    let mut segments = path.split("::").peekable();
    let mut base: Module = match *segments.peek()? {
        "crate" => {
            segments.next();
            Vec::new()
        }
        "self" | "super" => {
            let mut m = at.clone();
            while let Some(&s) = segments.peek() {
                match s {
                    "self" => {}
                    "super" => {
                        m.pop()?;
                    }
                    _ => break,
                }
                segments.next();
            }
            m
        }
        first => {
            let mut child = at.clone();
            child.push(first.to_owned());
            if !modules.contains(&child) {
                return None; // another crate, or the standard library
            }
            at.clone()
        }
    };
    // The deepest existing module file on the way down (an inline module is its file's).
    while !modules.contains(&base) {
        base.pop()?;
    }
    for s in segments {
        base.push(s.to_owned());
        if !modules.contains(&base) {
            base.pop();
            let item = (s != "self" && s != "*").then(|| s.to_owned());
            return Some((base, item));
        }
    }
    Some((base, None))
}

/// Each file's imports of other files of the crate rooted at `dir`, as module paths.
///
/// A re-export (`pub use`) is a signpost, not an import: a module root that re-exports its
/// children's items does not depend on them for that, and a path through the signpost
/// (`use super::Pin` where the parent re-exports `order::Pin`) imports the file that defines
/// the item.
fn import_graph(dir: &Path, skip: &[&str]) -> BTreeMap<Module, BTreeSet<Module>> {
    let files: Vec<(Module, Vec<Use>)> = rust_files(dir, skip)
        .into_iter()
        .map(|f| (module_of(dir, &f), uses_of(&f)))
        .collect();
    let modules: BTreeSet<Module> = files.iter().map(|(m, _)| m.clone()).collect();
    // Each use's paths, resolved from where it sits.
    let resolved = |module: &Module, u: &Use| -> Vec<(Module, Option<String>)> {
        let at: Module = module.iter().chain(&u.inline).cloned().collect();
        u.paths
            .iter()
            .filter_map(|p| resolve(&modules, &at, p))
            .collect()
    };
    // (module, name) -> where a `pub use` of that module leads.
    let mut signposts: BTreeMap<(Module, String), (Module, Option<String>)> = BTreeMap::new();
    for (module, uses) in &files {
        for u in uses.iter().filter(|u| u.public && u.inline.is_empty()) {
            for target in resolved(module, u) {
                if let Some(name) = target.1.clone() {
                    signposts.insert((module.clone(), name), target);
                }
            }
        }
    }
    let follow = |mut target: (Module, Option<String>)| -> Module {
        // Bounded: re-exports of re-exports are few, and a loop of them must not hang.
        for _ in 0..8 {
            let Some(next) = target
                .1
                .as_ref()
                .and_then(|name| signposts.get(&(target.0.clone(), name.clone())))
            else {
                break;
            };
            target = next.clone();
        }
        target.0
    };
    files
        .iter()
        .map(|(module, uses)| {
            let imports = uses
                .iter()
                .filter(|u| !u.public)
                .flat_map(|u| resolved(module, u))
                .map(follow)
                .filter(|m| m != module)
                .collect();
            (module.clone(), imports)
        })
        .collect()
}

/// One cycle of `graph`, as the files along it, if it has one.
fn a_cycle(graph: &BTreeMap<Module, BTreeSet<Module>>) -> Option<Vec<Module>> {
    // Depth-first, colouring: on the stack (grey) or finished (black).
    fn visit(
        graph: &BTreeMap<Module, BTreeSet<Module>>,
        node: &Module,
        stack: &mut Vec<Module>,
        done: &mut BTreeSet<Module>,
    ) -> Option<Vec<Module>> {
        if let Some(at) = stack.iter().position(|m| m == node) {
            return Some(stack[at..].to_vec());
        }
        if done.contains(node) {
            return None;
        }
        stack.push(node.clone());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(cycle) = visit(graph, next, stack, done) {
                return Some(cycle);
            }
        }
        stack.pop();
        done.insert(node.clone());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|start| visit(graph, start, &mut Vec::new(), &mut done))
}

fn named(cycle: &[Module]) -> String {
    let mut names: Vec<String> = cycle
        .iter()
        .map(|m| {
            if m.is_empty() {
                "(root)".to_owned()
            } else {
                m.join("::")
            }
        })
        .collect();
    names.push(names[0].clone());
    names.join(" -> ")
}

#[test]
fn no_source_file_of_any_crate_imports_one_that_imports_it_back() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (dir, skip) in [
        ("src", &["main.rs"][..]),
        ("solver/src", &[][..]),
        ("strategies/src", &[][..]),
        ("harness/src", &[][..]),
        ("reporting/src", &[][..]),
        ("tests/it", &[][..]),
    ] {
        let graph = import_graph(&root.join(dir), skip);
        assert!(graph.len() > 1, "{dir} has source files");
        if let Some(cycle) = a_cycle(&graph) {
            panic!("an import circle in {dir}: {}", named(&cycle));
        }
    }
}

#[test]
fn the_check_finds_a_circle_through_super_a_child_module_and_a_test_module() {
    let dir = tempfile::tempdir().unwrap();
    let src = dir.path();
    fs::create_dir(src.join("report")).unwrap();
    fs::write(src.join("lib.rs"), "pub mod report;\n").unwrap();
    fs::write(
        src.join("report/mod.rs"),
        "pub mod a;\npub mod b;\nuse a::Thing;\n",
    )
    .unwrap();
    // `a` imports `b`; `b`'s tests import `a` back, through a braced, renamed path.
    fs::write(
        src.join("report/a.rs"),
        "// use super::mod_b; (a comment, not an import)\nuse super::b::{self, Other as O};\npub struct Thing;\n",
    )
    .unwrap();
    fs::write(
        src.join("report/b.rs"),
        "pub struct Other;\n#[cfg(test)]\nmod tests {\n    use super::super::{a::Thing, b};\n}\n",
    )
    .unwrap();
    let graph = import_graph(src, &[]);
    let report = |m: &str| vec!["report".to_owned(), m.to_owned()];
    assert_eq!(
        graph[&vec!["report".to_owned()]],
        BTreeSet::from([report("a")])
    );
    assert_eq!(graph[&report("a")], BTreeSet::from([report("b")]));
    assert_eq!(graph[&report("b")], BTreeSet::from([report("a")]));
    let cycle = a_cycle(&graph).expect("a and b import each other");
    assert_eq!(named(&cycle), "report::a -> report::b -> report::a");
    // Without the test module's import, nothing circles.
    fs::write(src.join("report/b.rs"), "pub struct Other;\n").unwrap();
    assert_eq!(a_cycle(&import_graph(src, &[])), None);
    // A parent that re-exports `a`'s item and a child `c` that imports it through the parent:
    // `c` imports `a`, and the parent imports nothing for the signpost.
    fs::write(
        src.join("report/mod.rs"),
        "pub mod a;\npub mod b;\npub mod c;\npub use a::Thing;\npub struct Shared;\n",
    )
    .unwrap();
    fs::write(src.join("report/c.rs"), "use super::{Shared, Thing};\n").unwrap();
    let graph = import_graph(src, &[]);
    assert_eq!(graph[&vec!["report".to_owned()]], BTreeSet::new());
    assert_eq!(
        graph[&report("c")],
        BTreeSet::from([vec!["report".to_owned()], report("a")])
    );
    assert_eq!(a_cycle(&graph), None);
}
