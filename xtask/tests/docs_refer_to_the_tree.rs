//! The docs and the code comments point at things that exist: every citation
//! `docs/design/<chapter>.md §N` names a chapter that has section N, every relative link
//! of a Markdown file reaches a file, and every repository path written in backticks in
//! the docs (`contour-core/src/path/`, `tests/abi/no_alloc.rs`) is in the tree. Moving a
//! file or renumbering a section without updating its mentions fails here.

use std::fs;
use std::path::{Path, PathBuf};

/// The workspace root (xtask's parent).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

/// Folders that hold no sources of ours.
const SKIPPED: [&str; 7] = [
    ".git",
    "target",
    ".venv",
    "node_modules",
    "out",
    "corpus",
    "artifacts",
];

/// Folders that runs create (fuzzing), named in the docs but not in the tree.
const GENERATED: [&str; 2] = ["fuzz/corpus", "fuzz/artifacts"];

/// The top-level folders a path in the docs may start with.
const TOP: [&str; 15] = [
    "src/",
    "contour-core/",
    "contour-eval/",
    "contour-tune/",
    "fmu-build/",
    "xtask/",
    "tests/",
    "benches/",
    "examples/",
    "python/",
    "docs/",
    "fuzz/",
    "modelDescription/",
    "requirements/",
    "third_party/",
];

fn text_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().to_string();
        if path.is_dir() {
            if !SKIPPED.contains(&name.as_str()) {
                text_files(&path, out);
            }
        } else if [".rs", ".py", ".md", ".toml", ".sh", ".c"]
            .iter()
            .any(|e| name.ends_with(e))
            || name == "Makefile"
        {
            out.push(path);
        }
    }
}

/// The section numbers a design chapter has: `## 4. Title` gives 4, `### 4.1 Title` 4.1.
fn sections(chapter: &str) -> Vec<String> {
    chapter
        .lines()
        .filter_map(|line| {
            let rest = line
                .strip_prefix("### ")
                .or_else(|| line.strip_prefix("## "))?;
            let number: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '.')
                .collect();
            let number = number.trim_end_matches('.');
            number
                .starts_with(|c: char| c.is_ascii_digit())
                .then(|| number.to_string())
        })
        .collect()
}

/// Each `docs/design/<chapter>.md` in `text` with the section that follows it, if one
/// does (across white space and comment markers, as a citation wraps in a comment).
fn citations(text: &str) -> Vec<(String, Option<String>)> {
    let mut found = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("docs/design/") {
        rest = &rest[at + "docs/design/".len()..];
        let Some(end) = rest.find(".md") else { break };
        let chapter = &rest[..end];
        if chapter.is_empty() || !chapter.chars().all(|c| c.is_ascii_lowercase() || c == '-') {
            continue;
        }
        let after = rest[end + 3..]
            .trim_start_matches(|c: char| c.is_whitespace() || c == '/' || c == '!' || c == '#');
        let section = after.strip_prefix('§').map(|s| {
            let s = s.trim_start();
            let n: String = s
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '.')
                .collect();
            n.trim_end_matches('.').to_string()
        });
        found.push((chapter.to_string(), section));
    }
    found
}

#[test]
fn design_citations_name_existing_chapters_and_sections() {
    let root = root();
    let mut files = Vec::new();
    text_files(&root, &mut files);
    let mut problems = Vec::new();
    let mut cited = 0;
    for file in &files {
        let Ok(text) = fs::read_to_string(file) else {
            continue;
        };
        for (chapter, section) in citations(&text) {
            let path = root.join("docs/design").join(format!("{chapter}.md"));
            let Ok(doc) = fs::read_to_string(&path) else {
                problems.push(format!(
                    "{}: no chapter docs/design/{chapter}.md",
                    file.display()
                ));
                continue;
            };
            cited += 1;
            if let Some(section) = section.filter(|s| !s.is_empty()) {
                if !sections(&doc).contains(&section) {
                    problems.push(format!(
                        "{}: docs/design/{chapter}.md has no §{section}",
                        file.display()
                    ));
                }
            }
        }
    }
    assert!(
        cited > 100,
        "only {cited} citations found: is the scan broken?"
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Markdown files of ours: README.md, docs/, and the READMEs of the folders.
fn markdown_files(root: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    text_files(root, &mut files);
    files.retain(|f| f.extension().is_some_and(|e| e == "md"));
    files
}

#[test]
fn links_and_paths_in_the_docs_exist() {
    let root = root();
    let mut problems = Vec::new();
    let mut checked = 0;
    for file in markdown_files(&root) {
        let text = fs::read_to_string(&file).unwrap();
        let dir = file.parent().unwrap();
        // Relative links: [text](target) with no scheme.
        for piece in text.split("](").skip(1) {
            let Some(end) = piece.find(')') else { continue };
            let target = piece[..end].split('#').next().unwrap();
            if target.is_empty() || target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            if !dir.join(target).exists() {
                problems.push(format!(
                    "{}: link to {target} leads nowhere",
                    file.display()
                ));
            }
        }
        // Paths in backticks that start at a top-level folder of the repository.
        for (k, piece) in text.split('`').enumerate() {
            if k % 2 == 0 || piece.contains(char::is_whitespace) {
                continue;
            }
            if !TOP.iter().any(|t| piece.starts_with(t))
                || GENERATED.iter().any(|g| piece.starts_with(g))
                || piece.contains(['<', '>', '*', '…', '{', '$'])
            {
                continue;
            }
            let path = piece.split(':').next().unwrap();
            checked += 1;
            if !root.join(path).exists() {
                problems.push(format!("{}: `{piece}` is not in the tree", file.display()));
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} links and paths found: is the scan broken?"
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_scanners_read_wrapped_citations_and_numbered_headings() {
    assert_eq!(
        citations("as in docs/design/two-axis.md\n//! §4.3, and docs/design/fmi.md."),
        vec![
            ("two-axis".to_string(), Some("4.3".to_string())),
            ("fmi".to_string(), None)
        ]
    );
    assert_eq!(
        sections("## 5. Five-axis\n### 5.3a References\n## Sources\n#### 5.9 too deep"),
        vec!["5", "5.3a"]
    );
}
