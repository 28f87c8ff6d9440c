//! The documents a newcomer reads: the README stays short, every relative link and picture in the
//! README, BENCHMARKS.md and the user guide resolves (files and #anchors, as mdBook names headings),
//! every chapter is in the guide's SUMMARY.md, and no document speaks of work sessions.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn guide_chapters() -> Vec<PathBuf> {
    let mut chapters: Vec<PathBuf> = std::fs::read_dir(root().join("docs/src"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    chapters.sort();
    chapters
}

/// A chapter as mdBook sees it: its `{{#include FILE}}` lines replaced by the file.
fn read_expanded(path: &Path) -> String {
    read(path)
        .lines()
        .map(|line| match line.trim().strip_prefix("{{#include ").and_then(|l| l.strip_suffix("}}")) {
            Some(included) => read(&path.parent().unwrap().join(included.trim())),
            None => format!("{line}\n"),
        })
        .collect()
}

/// The lines of a Markdown text outside its fenced code blocks.
fn prose_lines(markdown: &str) -> impl Iterator<Item = &str> {
    let mut in_code = false;
    markdown.lines().filter(move |line| {
        let fence = line.trim_start().starts_with("```");
        if fence {
            in_code = !in_code;
        }
        !fence && !in_code
    })
}

/// The id mdBook gives a heading: its text (code spans and link texts as text), lower case, spaces as
/// dashes, alphanumerics, `-` and `_` kept, everything else dropped; a repeated id gets `-1`, `-2`, ….
fn heading_ids(markdown: &str) -> BTreeSet<String> {
    let mut ids = BTreeSet::new();
    for line in prose_lines(markdown) {
        if let Some(text) = line.strip_prefix('#').map(|t| t.trim_start_matches('#').trim()) {
            let text = strip_links(text);
            let id: String = text
                .chars()
                .filter_map(|c| match c {
                    ' ' => Some('-'),
                    c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c.to_lowercase().next().unwrap()),
                    _ => None,
                })
                .collect();
            let mut unique = id.clone();
            let mut n = 1;
            while ids.contains(&unique) {
                unique = format!("{id}-{n}");
                n += 1;
            }
            ids.insert(unique);
        }
        // explicit anchors
        let mut rest = line;
        while let Some(at) = rest.find("<a id=\"") {
            let after = &rest[at + 7..];
            let end = after.find('"').unwrap();
            ids.insert(after[..end].to_string());
            rest = &after[end..];
        }
    }
    ids
}

/// `[text](url)` → `text`.
fn strip_links(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        out.push_str(&rest[..open]);
        let after = &rest[open + 1..];
        match (after.find("]("), after.find(')')) {
            (Some(close), Some(paren)) if close < paren => {
                out.push_str(&after[..close]);
                rest = &after[paren + 1..];
            }
            _ => {
                out.push('[');
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Every `](target)` of a Markdown text outside code blocks.
fn links(markdown: &str) -> Vec<String> {
    let mut found = Vec::new();
    for line in prose_lines(markdown) {
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            found.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    found
}

fn check_links(file: &Path, broken: &mut Vec<String>) {
    let text = read(file);
    for link in links(&text) {
        if link.contains("://") || link.starts_with("mailto:") {
            continue;
        }
        let (path, fragment) = match link.split_once('#') {
            Some((p, f)) => (p, Some(f)),
            None => (link.as_str(), None),
        };
        let target = if path.is_empty() { file.to_path_buf() } else { file.parent().unwrap().join(path) };
        if !target.exists() {
            broken.push(format!("{}: {link}: no such file", file.display()));
            continue;
        }
        if let Some(fragment) = fragment
            && target.extension().is_some_and(|e| e == "md")
            && !heading_ids(&read_expanded(&target)).contains(fragment)
        {
            broken.push(format!("{}: {link}: no heading with id '{fragment}' in {}", file.display(), target.display()));
        }
    }
}

#[test]
fn the_readme_is_at_most_250_lines() {
    let lines = read(&root().join("README.md")).lines().count();
    assert!(lines <= 250, "README.md has {lines} lines; the guide in docs/ holds the rest");
}

#[test]
fn every_relative_link_and_picture_resolves() {
    let mut broken = Vec::new();
    let mut files = vec![root().join("README.md"), root().join("BENCHMARKS.md")];
    files.extend(guide_chapters());
    for file in &files {
        check_links(file, &mut broken);
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn every_chapter_is_in_the_summary_and_every_summary_entry_exists() {
    let summary = read(&root().join("docs/src/SUMMARY.md"));
    let listed: BTreeSet<String> = links(&summary).into_iter().collect();
    for chapter in guide_chapters() {
        let name = chapter.file_name().unwrap().to_string_lossy().to_string();
        if name != "SUMMARY.md" {
            assert!(listed.contains(&name), "docs/src/{name} is not in SUMMARY.md");
        }
    }
    for entry in &listed {
        assert!(root().join("docs/src").join(entry).exists(), "SUMMARY.md lists {entry}, which does not exist");
    }
}

#[test]
fn mdbook_heading_ids_are_derived_as_mdbook_derives_them() {
    let ids = heading_ids("# Read the recordings: Rerun, Foxglove, ROS 2\n## `armscope run`\n## Any arm: the default experiment\n## Any arm: the default experiment\n<a id=\"x-y\"></a>");
    for id in ["read-the-recordings-rerun-foxglove-ros-2", "armscope-run", "any-arm-the-default-experiment", "any-arm-the-default-experiment-1", "x-y"] {
        assert!(ids.contains(id), "{id} in {ids:?}");
    }
}

/// The documents speak of the software, not of how it was made: no work sessions, and no dated
/// measurements (history lives in git).
#[test]
fn no_document_speaks_of_work_sessions() {
    let mut offending = Vec::new();
    let mut stack = vec![root()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if path.is_dir() {
                if !matches!(name.as_str(), "target" | ".git" | "recordings" | "book") {
                    stack.push(path);
                }
                continue;
            }
            let Ok(text) = std::fs::read_to_string(&path) else { continue };
            for (number, line) in text.lines().enumerate() {
                let lower = line.to_lowercase();
                // the test's own words are the one place the word may stand
                if lower.contains("session") && !path.ends_with("tests/docs.rs") {
                    offending.push(format!("{}:{}: {line}", path.display(), number + 1));
                }
            }
        }
    }
    assert!(offending.is_empty(), "documents that speak of sessions:\n{}", offending.join("\n"));
}
