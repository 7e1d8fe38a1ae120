//! The README and the book (`book/src`) hold together: every relative link names a file that
//! exists, every `#anchor` on a Markdown page names one of its headings, every page of the
//! book is listed in `SUMMARY.md`, and the README stays at most 200 lines.

use std::collections::BTreeSet;
use std::path::{Component, Path, PathBuf};

/// The most lines the README may have.
const README_MAX_LINES: usize = 200;

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The book's pages, `book/src`.
fn book_src() -> PathBuf {
    root().join("book").join("src")
}

/// Every `.md` file under `dir`, sorted.
fn markdown_files(dir: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        let entries =
            std::fs::read_dir(&d).unwrap_or_else(|e| panic!("cannot list '{}': {e}", d.display()));
        for entry in entries {
            let path = entry.unwrap().path();
            if path.is_dir() {
                pending.push(path);
            } else if path.extension().is_some_and(|x| x == "md") {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// The README and every page of the book.
fn documents() -> Vec<PathBuf> {
    let mut docs = vec![root().join("README.md")];
    docs.extend(markdown_files(&book_src()));
    docs
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read '{}': {e}", path.display()))
}

/// The lines of `text` outside fenced code blocks, with their 1-based numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fence: Option<&str> = None;
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let marker = ["```", "~~~"].into_iter().find(|m| trimmed.starts_with(m));
        match (fence, marker) {
            (None, Some(m)) => fence = Some(m),
            (Some(open), Some(m)) if open == m => fence = None,
            (None, None) => lines.push((i + 1, line)),
            _ => {}
        }
    }
    lines
}

/// `line` without its inline code spans (`` `…` ``), which hold no links.
fn without_code_spans(line: &str) -> String {
    let mut out = String::new();
    let mut in_code = false;
    for c in line.chars() {
        if c == '`' {
            in_code = !in_code;
        } else if !in_code {
            out.push(c);
        }
    }
    out
}

/// The targets of the Markdown links and images in `text` (`[…](target)`, `![…](target)`),
/// with their line numbers; a target's title (`"…"` after a space) is left off.
fn link_targets(text: &str) -> Vec<(usize, String)> {
    let mut targets = Vec::new();
    for (number, line) in prose_lines(text) {
        let line = without_code_spans(line);
        let mut rest = line.as_str();
        while let Some(start) = rest.find("](") {
            let after = &rest[start + 2..];
            let Some(end) = after.find(')') else { break };
            let target = after[..end].split_whitespace().next().unwrap_or("");
            let target = target.trim_start_matches('<').trim_end_matches('>');
            targets.push((number, target.to_owned()));
            rest = &after[end..];
        }
    }
    targets
}

/// A link target split into the file it names (relative, possibly empty) and its anchor.
fn split_target(target: &str) -> (&str, Option<&str>) {
    match target.split_once('#') {
        Some((path, anchor)) => (path, Some(anchor)),
        None => (target, None),
    }
}

/// Whether `target` leaves the repository (a URL or an e-mail address).
fn is_external(target: &str) -> bool {
    ["http://", "https://", "mailto:"]
        .iter()
        .any(|scheme| target.starts_with(scheme))
}

/// `path` with `.` and `..` taken out, without touching the file system.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// The file a relative link in `page` names: relative to the page's folder, `%20` as a space.
fn resolve(page: &Path, path: &str) -> PathBuf {
    let folder = page.parent().unwrap_or(Path::new("."));
    normalize(&folder.join(path.replace("%20", " ")))
}

/// The relative links of `page` (whose text is `text`) that name no existing file or folder,
/// as `page:line: target` lines.
fn broken_links(page: &Path, text: &str) -> Vec<String> {
    link_targets(text)
        .into_iter()
        .filter(|(_, target)| !is_external(target) && !target.starts_with('#'))
        .filter(|(_, target)| !resolve(page, split_target(target).0).exists())
        .map(|(line, target)| format!("{}:{line}: {target}", page.display()))
        .collect()
}

/// A heading's anchor as GitHub and mdBook make it: lower case, spaces to `-`, punctuation
/// other than `-` and `_` dropped.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The anchors of `text`'s headings (`#` to `######` outside code blocks); a repeated anchor
/// also gets GitHub's `-1`, `-2`, … form.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    for (_, line) in prose_lines(text) {
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if !(1..=6).contains(&hashes) || !line[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(line[hashes..].trim().trim_end_matches('#'));
        let mut anchor = base.clone();
        let mut n = 0;
        while seen.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        seen.insert(anchor);
    }
    seen
}

/// The `#anchor`s of `page`'s links into Markdown pages that name no heading there, as
/// `page:line: target` lines: `#a` is looked up in `text` itself, `other.md#a` in that file
/// as it is on disk. Links to missing files are [`broken_links`]'s to report.
fn broken_anchors(page: &Path, text: &str) -> Vec<String> {
    link_targets(text)
        .into_iter()
        .filter(|(_, target)| !is_external(target))
        .filter_map(|(line, target)| {
            let (path, anchor) = split_target(&target);
            let anchor = anchor?;
            let headings = if path.is_empty() {
                anchors(text)
            } else {
                let file = resolve(page, path);
                if !(file.extension().is_some_and(|x| x == "md") && file.is_file()) {
                    return None;
                }
                anchors(&read(&file))
            };
            (!headings.contains(anchor)).then(|| format!("{}:{line}: {target}", page.display()))
        })
        .collect()
}

/// Runs `check` on the README and every page of the book and fails, listing what it found,
/// unless it found nothing.
fn assert_every_document_passes(check: fn(&Path, &str) -> Vec<String>, what: &str) {
    let found: Vec<String> = documents()
        .iter()
        .flat_map(|page| check(page, &read(page)))
        .collect();
    assert!(found.is_empty(), "{what}:\n{}", found.join("\n"));
}

#[test]
fn every_relative_link_in_the_readme_and_the_book_names_a_file_that_exists() {
    assert_every_document_passes(broken_links, "links to nothing");
}

#[test]
fn every_anchor_of_a_link_into_a_markdown_page_names_one_of_its_headings() {
    assert_every_document_passes(broken_anchors, "anchors without a heading");
}

#[test]
fn every_page_of_the_book_is_listed_in_summary_md() {
    let src = book_src();
    let summary = src.join("SUMMARY.md");
    let listed: BTreeSet<PathBuf> = link_targets(&read(&summary))
        .into_iter()
        .filter(|(_, target)| !is_external(target))
        .map(|(_, target)| resolve(&summary, split_target(&target).0))
        .collect();
    let unlisted: Vec<String> = markdown_files(&src)
        .into_iter()
        .filter(|page| *page != summary && !listed.contains(page))
        .map(|page| page.display().to_string())
        .collect();
    assert!(
        unlisted.is_empty(),
        "pages SUMMARY.md does not list:\n{}",
        unlisted.join("\n")
    );
}

#[test]
fn the_readme_has_at_most_200_lines() {
    let lines = read(&root().join("README.md")).lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines; the most is {README_MAX_LINES}: move the rest into the book"
    );
}

#[test]
fn the_checks_find_a_missing_file_a_missing_heading_and_skip_urls_and_code() {
    let page = root().join("README.md");
    let text = "# Title\n\
                [ok](Cargo.toml) [gone](no-such-file.md) [web](https://example.org/x)\n\
                `[code](not-a-link.md)` [top](#title) [nowhere](#no-such-heading)\n\
                ```\n[fenced](also-not-a-link.md)\n```\n";
    let missing = broken_links(&page, text);
    assert_eq!(missing.len(), 1, "{missing:?}");
    assert!(missing[0].ends_with(":2: no-such-file.md"), "{missing:?}");
    let nowhere = broken_anchors(&page, text);
    assert_eq!(nowhere.len(), 1, "{nowhere:?}");
    assert!(nowhere[0].ends_with(":3: #no-such-heading"), "{nowhere:?}");
    assert_eq!(slug("`bench-sph sweep`"), "bench-sph-sweep");
    assert_eq!(slug("On 16 cores (4 December)"), "on-16-cores-4-december");
    assert_eq!(slug("meta.json"), "metajson");
    let headings = anchors("# A\n## A\n```\n# Not a heading\n```\n");
    let expected: BTreeSet<String> = ["a", "a-1"].iter().map(|s| s.to_string()).collect();
    assert_eq!(headings, expected);
}
