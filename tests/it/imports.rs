//! No import circle between source files: within each crate of the workspace (and this test
//! binary), the files' `use` lines form no cycle. A file that imports another sits above it;
//! two files that import each other (directly or through others) are one piece of code split
//! in two, and belong either together or with the shared part moved below both.
//!
//! Read from the sources, not the compiler: each `use` path (`crate::`, `super::`, `self::`,
//! or a child module's name) is resolved to the deepest module file it names, test modules
//! included; paths into other crates are the layers' business (`layers.rs`). A re-export
//! (`pub use`) is a signpost, not an import: a path through it leads to the file that defines
//! the item ([`import_graph`]).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

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

/// `text` without its comments and with its string and character literals emptied, so that
/// neither a `use` nor a brace inside them counts.
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        let (kept, after) = if let Some(after) = rest.strip_prefix("//") {
            ("", after.find('\n').map_or("", |i| &after[i..]))
        } else if let Some(after) = rest.strip_prefix("/*") {
            ("", after.find("*/").map_or("", |i| &after[i + 2..]))
        } else if let Some(after) = rest.strip_prefix("r#\"") {
            ("\"\"", after.find("\"#").map_or("", |i| &after[i + 2..]))
        } else if let Some(after) = rest.strip_prefix('"') {
            ("\"\"", after_string(after))
        } else if let Some(after) = ["'\"'", "'\\''", "'\\\"'", "'{'", "'}'", "';'"]
            .iter()
            .find_map(|lit| rest.strip_prefix(lit))
        {
            ("' '", after)
        } else {
            out.push(c);
            rest = &rest[c.len_utf8()..];
            continue;
        };
        out.push_str(kept);
        rest = after;
    }
    out
}

/// What follows the string literal whose body starts `body` (escapes honoured).
fn after_string(body: &str) -> &str {
    let mut escaped = false;
    for (i, c) in body.char_indices() {
        match c {
            '\\' if !escaped => escaped = true,
            '"' if !escaped => return &body[i + 1..],
            _ => escaped = false,
        }
    }
    ""
}

/// Whether a statement's words so far open a `use` declaration (`use`, `pub use`,
/// `pub(crate) use`, after any attributes).
fn is_use(words: &str) -> bool {
    let mut rest = words;
    // Attributes first: `#[cfg(test)]`, `#[allow(a, b)]`.
    while let Some(at) = rest.find("#[") {
        rest = rest[at..].find(']').map_or("", |end| &rest[at + end + 1..]);
    }
    rest.split_whitespace()
        .find(|w| !w.starts_with("#[") && !w.starts_with("pub"))
        .is_some_and(|w| w == "use")
}

/// The inline module a statement's words open before `{` (`mod tests`), if any.
fn inline_module(words: &str) -> Option<String> {
    let mut it = words.split_whitespace().skip_while(|&w| w != "mod");
    it.next()?;
    it.next().map(str::to_owned)
}

/// A use tree's text with the spaces that do not separate words removed: `a::{b, c as d}`
/// becomes `a::{b,c as d}`.
fn tidy(tree: &str) -> String {
    let words = tree.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut out = String::new();
    for c in words.chars() {
        if c == ' ' && out.ends_with([':', '{', ',']) {
            continue;
        }
        if matches!(c, ':' | '{' | '}' | ',') && out.ends_with(' ') {
            out.pop();
        }
        out.push(c);
    }
    out
}

/// One `use` declaration: its tree, the inline modules (`mod tests { ... }`) it sits in, and
/// whether it is a re-export (`pub use`, any visibility).
struct Use {
    inline: Module,
    tree: String,
    public: bool,
}

/// The `use` declarations of `text`.
fn use_trees(text: &str) -> Vec<Use> {
    let text = code_only(text);
    let mut out = Vec::new();
    // The inline modules open here, with the brace depth inside each.
    let mut inline: Vec<(String, usize)> = Vec::new();
    let mut depth = 0usize;
    let mut words = String::new();
    // Braces open inside the use tree being read, once one is.
    let mut in_use: Option<usize> = None;
    for c in text.chars() {
        if let Some(open) = in_use.as_mut() {
            match c {
                '{' => *open += 1,
                '}' => *open -= 1,
                ';' if *open == 0 => {
                    let (before, tree) = words.split_once("use ").unwrap_or(("", ""));
                    out.push(Use {
                        inline: inline.iter().map(|(n, _)| n.clone()).collect(),
                        tree: tidy(tree),
                        public: before.split_whitespace().any(|w| w.starts_with("pub")),
                    });
                    words.clear();
                    in_use = None;
                    continue;
                }
                _ => {}
            }
            words.push(c);
            continue;
        }
        match c {
            '{' | '}' | ';' => {
                if c == '{' {
                    depth += 1;
                    if let Some(name) = inline_module(&words) {
                        inline.push((name, depth));
                    }
                } else if c == '}' {
                    if inline.last().is_some_and(|&(_, d)| d == depth) {
                        inline.pop();
                    }
                    depth = depth.saturating_sub(1);
                }
                words.clear();
            }
            _ => {
                words.push(c);
                if c.is_whitespace() && is_use(&words) {
                    in_use = Some(0);
                }
            }
        }
    }
    out
}

/// The paths of a use tree: `a::{b, c::{d, e}}` gives `a::b`, `a::c::d`, `a::c::e`.
fn paths(tree: &str) -> Vec<String> {
    let Some(open) = tree.find('{') else {
        return vec![tree.split(" as ").next().unwrap_or(tree).to_owned()];
    };
    let (prefix, inner) = (&tree[..open], &tree[open + 1..tree.len() - 1]);
    let mut parts = Vec::new();
    let (mut level, mut start) = (0usize, 0usize);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => level += 1,
            '}' => level -= 1,
            ',' if level == 0 => {
                parts.push(&inner[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&inner[start..]);
    parts
        .into_iter()
        .filter(|p| !p.is_empty())
        .flat_map(|p| paths(&format!("{prefix}{p}")))
        .collect()
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
        .map(|f| {
            let text = fs::read_to_string(&f).expect("a readable source file");
            (module_of(dir, &f), use_trees(&text))
        })
        .collect();
    let modules: BTreeSet<Module> = files.iter().map(|(m, _)| m.clone()).collect();
    // Each use's paths, resolved from where it sits.
    let resolved = |module: &Module, u: &Use| -> Vec<(Module, Option<String>)> {
        let at: Module = module.iter().chain(&u.inline).cloned().collect();
        paths(&u.tree)
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
        ("tests/it", &[][..]),
    ] {
        let graph = import_graph(&root.join(dir), skip);
        assert!(graph.len() > 1, "{dir} has source files");
        if let Some(cycle) = a_cycle(&graph) {
            panic!("an import circle in {dir}: {}", named(&cycle));
        }
    }
}

/// The root package's modules that measure and store (the harness), and those above them that
/// word, draw and parse the command line.
const HARNESS: [&str; 14] = [
    "clock",
    "contention",
    "io",
    "limits",
    "merge",
    "output",
    "placement",
    "results",
    "run",
    "signals",
    "sweep",
    "topology",
    "trace",
    "validate",
];
const ABOVE_THE_HARNESS: [&str; 5] = ["cli", "plot", "render", "report", "viewer"];

#[test]
fn the_harness_imports_nothing_of_the_report_the_drawing_or_the_command_line() {
    let graph = import_graph(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        &["main.rs"],
    );
    let top = |m: &Module| m.first().cloned().unwrap_or_default();
    let known: BTreeSet<String> = graph.keys().map(top).filter(|t| !t.is_empty()).collect();
    // Every top-level module is placed on one side, so a new one cannot slip past the rule.
    let placed: BTreeSet<String> = HARNESS
        .iter()
        .chain(&ABOVE_THE_HARNESS)
        .map(|s| (*s).to_owned())
        .collect();
    assert_eq!(
        known, placed,
        "place each top-level module in HARNESS or ABOVE_THE_HARNESS"
    );
    let upward: Vec<String> = graph
        .iter()
        .filter(|(m, _)| HARNESS.contains(&top(m).as_str()))
        .flat_map(|(m, imports)| {
            imports
                .iter()
                .filter(|i| ABOVE_THE_HARNESS.contains(&top(i).as_str()))
                .map(move |i| format!("{} -> {}", m.join("::"), i.join("::")))
        })
        .collect();
    assert!(
        upward.is_empty(),
        "the harness reaches above itself: {upward:#?}"
    );
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
