//! The documentation runs: every `latvox …` example in README.md and the book (`docs/src`) is
//! run here, so that neither can drift from what latvox does; and the book builds with mdBook.
//!
//! How a page is run (the conventions the pages are written to):
//! - Only fenced blocks whose info string is `bash` hold examples. A command is a line that
//!   starts with `latvox ` (with its `\` continuation lines); other lines are shown, not run.
//!   A line starting with `latvox ` in a block of another shell language is an error (write it
//!   as `bash`, so that it runs).
//! - Each page runs in its own temporary folder, into which `docs/examples/` is copied first.
//!   Its commands run in the order they appear, through `bash -o pipefail -c`, with the latvox
//!   under test first on PATH: a later example may use what an earlier one made.
//! - A block after a `<!-- file: NAME -->` line is written to NAME when it is reached.
//! - A `bash` block after an `<!-- example: long -->` line runs in the long tier only.
//! - A command exits 0, or N where its line ends with `# exit N`; the files it names after `-o`,
//!   `--output`, `--report` or `--save-part` exist afterwards.
//! - `latvox view` serves until stopped: it is started, its first line (the URL) is read, and it
//!   is stopped.

use crate::common::tempdir;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// README.md and every page of the book, in a fixed order.
fn pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        let mut entries: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e == "md") {
                out.push(p);
            }
        }
    }
    let mut out = vec![root().join("README.md")];
    walk(&root().join("docs/src"), &mut out);
    out
}

/// What a page asks for, in order.
#[derive(Debug)]
enum Step {
    /// A file written into the page's folder.
    File { name: String, text: String },
    /// A command run there.
    Run {
        line: usize,
        command: String,
        long: bool,
        code: i32,
    },
}

/// The steps of a page's markdown `text` (`page` names it in errors).
fn steps(page: &str, text: &str) -> Vec<Step> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i].trim_start();
        let Some(info) = l.strip_prefix("```") else {
            i += 1;
            continue;
        };
        let info = info.trim().to_string();
        let marker = lines[..i]
            .iter()
            .rev()
            .find(|l| !l.trim().is_empty())
            .map(|l| l.trim())
            .unwrap_or("");
        let start = i + 1;
        let mut end = start;
        while end < lines.len() && !lines[end].trim_start().starts_with("```") {
            end += 1;
        }
        let body = &lines[start..end.min(lines.len())];
        if let Some(name) = marker
            .strip_prefix("<!-- file:")
            .and_then(|m| m.strip_suffix("-->"))
        {
            out.push(Step::File {
                name: name.trim().to_string(),
                text: body.join("\n") + "\n",
            });
        } else if info == "bash" {
            let long = marker == "<!-- example: long -->";
            let mut k = 0;
            while k < body.len() {
                let first = k;
                let mut command = body[k].trim().to_string();
                while command.ends_with('\\') && k + 1 < body.len() {
                    command.pop();
                    k += 1;
                    command.push(' ');
                    command.push_str(body[k].trim());
                }
                k += 1;
                if command.starts_with("latvox ") {
                    let code = command
                        .rsplit_once('#')
                        .and_then(|(_, c)| c.trim().strip_prefix("exit "))
                        .and_then(|n| n.trim().parse().ok())
                        .unwrap_or(0);
                    out.push(Step::Run {
                        line: start + first + 1,
                        command,
                        long,
                        code,
                    });
                }
            }
        } else if ["sh", "shell", "console", "zsh", ""].contains(&info.as_str()) {
            if let Some(l) = body.iter().find(|l| l.trim_start().starts_with("latvox ")) {
                panic!("{page}:{}: `{l}` is in a ```{info} block: write it in a ```bash block so that it runs", start + 1);
            }
        }
        i = end + 1;
    }
    out
}

/// The files a command names as its outputs.
fn outputs(command: &str) -> Vec<String> {
    let command = command.split(" #").next().unwrap_or(command);
    let words: Vec<&str> = command.split_whitespace().collect();
    let mut out = Vec::new();
    for (i, w) in words.iter().enumerate() {
        for flag in ["-o", "--output", "--report", "--save-part"] {
            if *w == flag {
                if let Some(v) = words.get(i + 1) {
                    out.push(v.trim_matches(['"', '\'']).to_string());
                }
            } else if let Some(v) = w.strip_prefix(&format!("{flag}=")) {
                out.push(v.trim_matches(['"', '\'']).to_string());
            }
        }
    }
    out
}

/// The words of `command` that name files: not options, with an extension.
fn file_words(command: &str) -> Vec<String> {
    let command = command.split(" #").next().unwrap_or(command);
    command
        .split_whitespace()
        .flat_map(|w| w.split(['=', ',', ':']))
        .map(|w| w.trim_matches(['"', '\'']))
        .filter(|w| {
            !w.starts_with('-')
                && w.rsplit_once('.').is_some_and(|(a, e)| {
                    !a.is_empty() && e.chars().any(|c| c.is_ascii_alphabetic())
                })
        })
        .map(str::to_string)
        .collect()
}

/// The steps the long examples need: the files, the long examples, and every earlier example
/// that names a file a later needed one names (an input it makes), unless the file is one of
/// `examples`' own (which every page starts with). Every command runs in its folder, so an
/// example that makes a later one's input without naming it is not expected.
fn needed_by_long(steps: Vec<Step>, examples: &Path) -> Vec<Step> {
    let mut wanted: std::collections::HashSet<String> = std::collections::HashSet::new();
    let mut keep = vec![false; steps.len()];
    for (i, s) in steps.iter().enumerate().rev() {
        match s {
            Step::File { .. } => keep[i] = true,
            Step::Run { command, long, .. } => {
                let words = file_words(command);
                let makes = words
                    .iter()
                    .any(|w| wanted.contains(w) && !examples.join(w).exists());
                if *long || makes {
                    keep[i] = true;
                    wanted.extend(words);
                }
            }
        }
    }
    steps
        .into_iter()
        .zip(keep)
        .filter_map(|(s, k)| k.then_some(s))
        .collect()
}

fn copy_dir(from: &Path, to: &Path) {
    let Ok(entries) = std::fs::read_dir(from) else {
        return;
    };
    for e in entries {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            std::fs::create_dir_all(&dest).unwrap();
            copy_dir(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

/// Runs the examples of `page` (the long tier's too when `long`); returns how many ran and the
/// failures.
fn run_page(page: &Path, long: bool) -> (usize, Vec<String>) {
    let name = page
        .strip_prefix(root())
        .unwrap_or(page)
        .display()
        .to_string();
    let text = std::fs::read_to_string(page).unwrap();
    let mut steps = steps(&name, &text);
    if !steps.iter().any(|s| matches!(s, Step::Run { .. })) {
        return (0, Vec::new());
    }
    // The long tier runs the pages that have long examples: those examples, and the earlier
    // ones that make their inputs; the main tier has run the rest.
    if long {
        if !steps
            .iter()
            .any(|s| matches!(s, Step::Run { long: true, .. }))
        {
            return (0, Vec::new());
        }
        steps = needed_by_long(steps, &root().join("docs/examples"));
    }
    let dir = tempdir();
    copy_dir(&root().join("docs/examples"), dir.path());
    let bin = Path::new(env!("CARGO_BIN_EXE_latvox")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let (mut ran, mut failures) = (0, Vec::new());
    for step in steps {
        match step {
            Step::File { name, text } => {
                let p = dir.path().join(&name);
                if let Some(parent) = p.parent() {
                    std::fs::create_dir_all(parent).unwrap();
                }
                std::fs::write(p, text).unwrap();
            }
            Step::Run {
                line,
                command,
                long: only_long,
                code,
            } => {
                if only_long && !long {
                    continue;
                }
                ran += 1;
                let at = format!("{name}:{line}: `{command}`");
                let mut cmd = Command::new("bash");
                cmd.args(["-o", "pipefail", "-c"])
                    .current_dir(dir.path())
                    .env("PATH", &path);
                let started = Instant::now();
                if command.starts_with("latvox view ") {
                    let mut child = cmd
                        .arg(format!("exec {command}"))
                        .stdout(Stdio::piped())
                        .stderr(Stdio::piped())
                        .spawn()
                        .unwrap();
                    let mut first = String::new();
                    let _ = BufReader::new(child.stdout.take().unwrap()).read_line(&mut first);
                    let _ = child.kill();
                    let status = child.wait().unwrap();
                    if !first.starts_with("http://127.0.0.1:") {
                        let mut err = String::new();
                        let _ = std::io::Read::read_to_string(
                            &mut child.stderr.take().unwrap(),
                            &mut err,
                        );
                        failures.push(format!(
                            "{at}: printed no URL ({status}): {first}{}",
                            err.trim()
                        ));
                    }
                    continue;
                }
                let o = cmd.arg(&command).output().unwrap();
                let seconds = started.elapsed().as_secs_f64();
                if o.status.code() != Some(code) {
                    failures.push(format!(
                        "{at}: exit {:?}, expected {code}: {}",
                        o.status.code(),
                        String::from_utf8_lossy(&o.stderr).trim()
                    ));
                    continue;
                }
                for f in outputs(&command) {
                    if !dir.path().join(&f).exists() {
                        failures.push(format!("{at}: wrote no {f}"));
                    }
                }
                if !long && seconds > 8.0 {
                    eprintln!("{at}: {seconds:.1} s (mark its block <!-- example: long -->)");
                } else {
                    eprintln!("{at}: {seconds:.1} s");
                }
            }
        }
    }
    (ran, failures)
}

fn run_all(long: bool) {
    let mut failures = Vec::new();
    let mut ran = 0;
    for page in pages() {
        let (n, f) = run_page(&page, long);
        ran += n;
        failures.extend(f);
    }
    assert!(ran > 0, "no examples found");
    assert!(
        failures.is_empty(),
        "{} of {ran} examples failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn every_example_in_the_readme_and_the_book_runs() {
    run_all(false);
}

#[test]
#[ignore = "long: the book's long examples (large parts)"]
fn every_long_example_in_the_book_runs() {
    run_all(true);
}

#[test]
fn the_conventions_read_pages_as_written() {
    let page = "intro\n\n<!-- file: jobs.toml -->\n```toml\n[[job]]\n```\n\n```bash\n# a comment\n\
                latvox tpms --type d \\\n    -o d.stl --report=d.json\nlatvox check broken.stl  # exit 1\n\
                sbatch run.sh\n```\n\n<!-- example: long -->\n```bash\nlatvox tpms --cells 30 -o big.stl\n```\n";
    let s = steps("page.md", page);
    assert_eq!(s.len(), 4, "{s:?}");
    assert!(
        matches!(&s[0], Step::File { name, text } if name == "jobs.toml" && text == "[[job]]\n")
    );
    assert!(
        matches!(&s[1], Step::Run { command, long: false, code: 0, line: 10 } if command == "latvox tpms --type d  -o d.stl --report=d.json"),
        "{:?}",
        s[1]
    );
    assert!(matches!(&s[2], Step::Run { code: 1, .. }));
    assert!(matches!(&s[3], Step::Run { long: true, .. }));
    assert_eq!(
        outputs("latvox tpms --type d  -o d.stl --report=d.json"),
        ["d.stl", "d.json"]
    );
    // The long tier keeps the long examples and what makes their inputs.
    let page = "```bash\nlatvox topopt -o c.npy\nlatvox tpms --type d -o d.stl\n\
                latvox check broken.stl  # exit 1\n```\n\n<!-- example: long -->\n```bash\n\
                latvox interpret c.npy --images=s -o c.stl\n```\n";
    let kept: Vec<String> = needed_by_long(steps("page.md", page), &root().join("docs/examples"))
        .into_iter()
        .map(|s| match s {
            Step::Run { command, .. } => command,
            Step::File { name, .. } => name,
        })
        .collect();
    assert_eq!(
        kept,
        [
            "latvox topopt -o c.npy",
            "latvox interpret c.npy --images=s -o c.stl"
        ]
    );
    let wrong = std::panic::catch_unwind(|| steps("p.md", "```sh\nlatvox tpms -o a.stl\n```\n"));
    assert!(wrong.is_err(), "a latvox line in a sh block is refused");
}

#[test]
fn the_book_builds() {
    let out = tempdir();
    // On PATH, or where `cargo install` put it.
    let cargo_bin = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cargo")))
        .map(|c| c.join("bin/mdbook"))
        .filter(|p| p.exists());
    let o = Command::new(cargo_bin.unwrap_or_else(|| PathBuf::from("mdbook")))
        .arg("build")
        .arg(root().join("docs"))
        .arg("-d")
        .arg(out.path())
        .output()
        .expect("mdbook (scripts/install-deps.sh --tests installs it)");
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "mdbook build failed:\n{log}");
    assert!(!log.contains("WARN") && !log.contains("ERROR"), "{log}");
    assert!(out.path().join("index.html").exists());
}
