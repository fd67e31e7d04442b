//! The malformed-input corpus: every file in `tests/data/bad/` must fail cleanly.
//!
//! The expectations live in `tests/data/bad/README.md` (one table row per file: the file, its
//! problem, and the substrings its error must contain), so the corpus documents itself and a
//! new file only needs a new row. Two checks run over the same table:
//!
//! - the real one: `lucent inspect FILE` exits non-zero with exactly one `lucent: error:` line
//!   on stderr that names the file and contains the substrings, and nothing panicked;
//! - in-process: `lucent::scene::inspect::inspect_file` returns the same error (and does not
//!   panic), so a failure points at the loader rather than the command line.

use std::path::{Path, PathBuf};
use std::process::Command;

/// One row of the README's table.
struct Case {
    file: String,
    expected: Vec<String>,
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad")
}

/// The texts between pairs of backticks.
fn backticked(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The table rows and the helper files listed in the README.
fn read_readme() -> (Vec<Case>, Vec<String>) {
    let readme = std::fs::read_to_string(corpus_dir().join("README.md"))
        .expect("tests/data/bad/README.md is readable");
    let (mut cases, mut helpers) = (Vec::new(), Vec::new());
    let mut in_helpers = false;
    for line in readme.lines() {
        let line = line.trim();
        if line.starts_with("## ") {
            in_helpers = line.eq_ignore_ascii_case("## helpers");
        } else if line.starts_with("| `") {
            let cells: Vec<&str> = line.trim_matches('|').split('|').collect();
            let file = backticked(cells[0]);
            let expected = backticked(cells[cells.len() - 1]);
            assert_eq!(file.len(), 1, "README row without one file name: {line}");
            assert!(
                !expected.is_empty(),
                "README row without a substring: {line}"
            );
            cases.push(Case {
                file: file[0].clone(),
                expected,
            });
        } else if in_helpers && line.starts_with("- `") {
            helpers.push(backticked(line)[0].clone());
        }
    }
    (cases, helpers)
}

#[test]
fn readme_lists_every_corpus_file() {
    let (cases, helpers) = read_readme();
    assert!(cases.len() >= 28, "only {} cases", cases.len());
    let listed: Vec<&str> = cases
        .iter()
        .map(|c| c.file.as_str())
        .chain(helpers.iter().map(String::as_str))
        .collect();
    for name in &listed {
        assert!(
            corpus_dir().join(name).is_file(),
            "README lists {name}, which is not in tests/data/bad/"
        );
        assert_eq!(
            listed.iter().filter(|n| *n == name).count(),
            1,
            "{name} is listed twice"
        );
    }
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            name == "README.md" || listed.contains(&name.as_str()),
            "tests/data/bad/{name} is not described in tests/data/bad/README.md"
        );
    }
}

/// What is wrong with `message` as the error for `case`, if anything.
fn check_message(case: &Case, message: &str) -> Option<String> {
    let missing: Vec<&String> = std::iter::once(&case.file)
        .chain(&case.expected)
        .filter(|s| !message.contains(s.as_str()))
        .collect();
    if message.contains("panicked") || message.contains("crashed") {
        return Some(format!("{}: a panic was reported: {message}", case.file));
    }
    (!missing.is_empty()).then(|| format!("{}: {missing:?} not in: {message}", case.file))
}

#[test]
fn library_reports_each_problem() {
    let (cases, _) = read_readme();
    let mut failures = Vec::new();
    for case in &cases {
        let path = corpus_dir().join(&case.file);
        let result = std::panic::catch_unwind(|| lucent::scene::inspect::inspect_file(&path));
        match result {
            Err(_) => failures.push(format!("{}: inspect_file panicked", case.file)),
            Ok(Ok(summary)) => failures.push(format!("{}: accepted:\n{summary}", case.file)),
            Ok(Err(e)) => {
                // The message's first line is what `lucent: error:` prints on its line.
                let message = e.to_string();
                let first = message.lines().next().unwrap_or("");
                failures.extend(check_message(case, first));
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn cli_reports_each_problem() {
    let (cases, _) = read_readme();
    let mut failures = Vec::new();
    for case in &cases {
        let path = corpus_dir().join(&case.file);
        let out = Command::new(env!("CARGO_BIN_EXE_lucent"))
            .arg("inspect")
            .arg(&path)
            .output()
            .expect("the lucent binary runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let errors: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("lucent: error:"))
            .collect();
        if out.status.success() {
            failures.push(format!("{}: exit status 0", case.file));
        } else if stderr.contains("panicked") {
            failures.push(format!("{}: panicked:\n{stderr}", case.file));
        } else if errors.len() != 1 {
            failures.push(format!(
                "{}: {} 'lucent: error:' lines in stderr:\n{stderr}",
                case.file,
                errors.len()
            ));
        } else {
            failures.extend(check_message(case, errors[0]));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
