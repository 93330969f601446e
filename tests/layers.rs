//! The crate's structure, kept honest: every module imports only the layers below it (the order in
//! `src/lib.rs`), only `record` names Rerun, and no source file grows past `MAX_LINES`.
//!
//! Test code (`#[cfg(test)]` blocks and `tests.rs` files) may use higher layers to build fixtures
//! the way users write them (a scenario's TOML); the rules apply to what ships.

use std::path::{Path, PathBuf};

/// Layers, lowest first; modules of one rank are peers and may not import each other.
const LAYERS: &[(&str, u32)] = &[
    ("math", 0),
    ("io", 1),
    ("model", 2),
    ("sim", 3),
    ("ins", 4),
    ("calib", 5),
    ("scenario", 6),
    ("record", 7),
    ("app", 8),
    ("cli", 9),
];

/// A source file longer than this is a god file in the making: split it by responsibility.
const MAX_LINES: usize = 700;

fn rank(module: &str) -> Option<u32> {
    LAYERS.iter().find(|(m, _)| *m == module).map(|(_, r)| *r)
}

/// The shipped part of a file: the file without each `#[cfg(test)]` item (a `mod tests;` line,
/// a `use`, or a braced block up to its matching brace). Code after a test module still counts.
fn shipped(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..i]);
        let item = &rest[i + "#[cfg(test)]".len()..];
        // The item ends at the first `;` before any `{`, else at the brace matching the first `{`.
        let (semi, brace) = (item.find(';'), item.find('{'));
        let end = match (semi, brace) {
            (Some(s), Some(b)) if s < b => s + 1,
            (Some(s), None) => s + 1,
            (_, Some(b)) => {
                let mut depth = 0usize;
                let mut end = item.len();
                for (k, c) in item[b..].char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' => {
                            depth -= 1;
                            if depth == 0 {
                                end = b + k + 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                }
                end
            }
            (None, None) => item.len(),
        };
        // Keep the line count: the item's lines become empty lines.
        out.push_str(&"\n".repeat(item[..end].matches('\n').count()));
        rest = &item[end..];
    }
    out.push_str(rest);
    out
}

/// The top-level modules a `crate::` path names, from the text right after `crate::`: one ident,
/// or each first segment of a group `{a::x, b::{y, z}}` (which may span lines).
fn crate_targets(after: &str) -> Vec<String> {
    let ident = |t: &str| t.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect::<String>();
    let Some(group) = after.strip_prefix('{') else { return vec![ident(after)] };
    let mut targets = Vec::new();
    let (mut depth, mut start) = (1usize, 0usize);
    for (k, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' | ',' if depth == 1 => {
                let t = ident(group[start..k].trim_start());
                if !t.is_empty() {
                    targets.push(t);
                }
                start = k + 1;
                if c == '}' {
                    break;
                }
            }
            '}' => depth -= 1,
            _ => {}
        }
    }
    targets
}

/// The violations in one file of top-level module `module` (None: the crate root or the binary).
fn violations(file: &str, module: Option<&str>, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let code = shipped(text);
    let code = code.as_str();
    let lines = text.lines().count();
    if lines > MAX_LINES {
        out.push(format!("{file}: {lines} lines (at most {MAX_LINES}); split it by responsibility"));
    }
    if module != Some("record") {
        for (n, line) in code.lines().enumerate() {
            let l = line.trim_start();
            if l.starts_with("//") {
                continue;
            }
            if l.contains("rerun::") || l.starts_with("use rerun") {
                out.push(format!("{file}:{}: names Rerun outside `record`: {l}", n + 1));
            }
        }
    }
    let Some(module) = module else { return out };
    let Some(own) = rank(module) else {
        out.push(format!("{file}: top-level module `{module}` has no layer in tests/layers.rs"));
        return out;
    };
    // Comments out, line numbers kept; a group may span lines, so the text is searched whole.
    let uncommented: String =
        code.lines().map(|l| if l.trim_start().starts_with("//") { "" } else { l }).collect::<Vec<_>>().join("\n");
    let mut from = 0;
    while let Some(i) = uncommented[from..].find("crate::") {
        let at = from + i;
        from = at + "crate::".len();
        let n = uncommented[..at].matches('\n').count();
        let l = uncommented.lines().nth(n).unwrap_or("").trim_start();
        for target in crate_targets(&uncommented[from..]) {
            if target == module || target.is_empty() {
                continue;
            }
            match rank(&target) {
                Some(r) if r < own => {}
                Some(r) => {
                    out.push(format!("{file}:{}: `{module}` (layer {own}) imports `{target}` (layer {r}): {l}", n + 1))
                }
                None => out.push(format!("{file}:{}: unknown module `{target}`", n + 1)),
            }
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

#[test]
fn every_module_imports_only_the_layers_below_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    assert!(files.len() > 30, "found the sources: {}", files.len());
    let mut all = Vec::new();
    for path in &files {
        let rel = path.strip_prefix(&src).expect("under src").to_string_lossy().replace('\\', "/");
        let text = std::fs::read_to_string(path).expect("readable");
        // Whole test files only build fixtures; their length still counts.
        let is_test_file = rel.ends_with("/tests.rs");
        let module = rel.split_once('/').map(|(m, _)| m);
        let checked = if is_test_file { "" } else { text.as_str() };
        let mut v = violations(&rel, module, checked);
        if is_test_file && text.lines().count() > MAX_LINES {
            v.push(format!("{rel}: {} lines (at most {MAX_LINES})", text.lines().count()));
        }
        all.extend(v);
    }
    assert!(all.is_empty(), "layering violations:\n{}", all.join("\n"));
}

#[test]
fn the_checker_sees_what_it_must_refuse() {
    // The rules above are only evidence if they can fail: an import upward, a peer import, Rerun
    // outside `record` and a long file are each reported; test code and comments are not.
    assert_eq!(violations("model/x.rs", Some("model"), "use crate::sim::Model;\n").len(), 1);
    assert_eq!(violations("ins/x.rs", Some("ins"), "use crate::calib::Data;\n").len(), 1, "peers");
    assert_eq!(violations("app/x.rs", Some("app"), "use crate::record::Recorder;\nuse crate::math::units;\n").len(), 0);
    assert_eq!(violations("app/x.rs", Some("app"), "let s: rerun::RecordingStream;\n").len(), 1);
    assert_eq!(violations("record/x.rs", Some("record"), "use rerun::Color;\n").len(), 0);
    assert_eq!(
        violations("sim/x.rs", Some("sim"), "// crate::app is above\n#[cfg(test)]\nuse crate::scenario::presets;\n")
            .len(),
        0
    );
    // Grouped imports, on one line or several, name each module they import.
    assert_eq!(violations("model/x.rs", Some("model"), "use crate::{math::units, sim::Model};\n").len(), 1, "grouped");
    assert_eq!(
        violations(
            "model/x.rs",
            Some("model"),
            "use crate::{\n    math::{units, frames},\n    app::run,\n    record::Recorder,\n};\n"
        )
        .len(),
        2,
        "grouped over lines"
    );
    // Code after a test module is shipped code.
    assert_eq!(
        violations("sim/x.rs", Some("sim"), "#[cfg(test)]\nmod tests;\nuse crate::app::run;\n").len(),
        1,
        "after mod tests;"
    );
    assert_eq!(violations("sim/x.rs", Some("sim"), "#[cfg(test)]\nmod tests {\n    use crate::app::run;\n    fn f() { if true { } }\n}\nuse crate::record::Recorder;\n").len(), 1, "after a test block");
    let long = "let x = 1;\n".repeat(MAX_LINES + 1);
    assert_eq!(violations("math/x.rs", Some("math"), &long).len(), 1);
}

/// Files allowed to open a file without `io::files::open_input`: the function itself (and the
/// output side), the recording writer reading back its own partial, the benchmarks' own scratch
/// files and /proc.
const OPENS_ALLOWED: &[&str] = &["io/files/", "record/sink/file.rs", "app/bench/"];

/// Ways of opening a file for reading that bypass the opening rule.
const RAW_OPENS: &[&str] = &["File::open(", "fs::read_to_string(", "fs::read(", "OpenOptions::new()"];

/// Issue 20: every input a command reads is opened by `io::files::open_input` (no blocking open,
/// regular files only), and stderr is written with `errln!` (a closed pipe or a hung-up terminal
/// must not panic the signal thread); the places that did otherwise hung or died.
fn opening_violations(file: &str, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let allowed = OPENS_ALLOWED.iter().any(|a| file.starts_with(a));
    for (n, line) in shipped(text).lines().enumerate() {
        let l = line.trim_start();
        if l.starts_with("//") {
            continue;
        }
        if !allowed && let Some(p) = RAW_OPENS.iter().find(|p| l.contains(**p)) {
            out.push(format!("{file}:{}: opens a file with {p}: inputs go through io::files::open_input: {l}", n + 1));
        }
        if l.contains("eprintln!(") || l.contains("eprint!(") {
            out.push(format!("{file}:{}: eprintln! panics when stderr is gone: use errln!: {l}", n + 1));
        }
    }
    out
}

#[test]
fn every_input_is_opened_by_one_function_and_stderr_never_panics() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut all = Vec::new();
    for path in &files {
        let rel = path.strip_prefix(&src).expect("under src").to_string_lossy().replace('\\', "/");
        if rel.ends_with("/tests.rs") || rel == "lib.rs" {
            continue;
        }
        all.extend(opening_violations(&rel, &std::fs::read_to_string(path).expect("readable")));
    }
    assert!(all.is_empty(), "{}", all.join("\n"));
    // The check can fail: a raw open and an eprintln! are each reported, test code is not.
    assert_eq!(opening_violations("io/text.rs", "let f = File::open(path)?;\n").len(), 1);
    assert_eq!(opening_violations("cli/x.rs", "eprintln!(\"x\");\n").len(), 1);
    assert_eq!(opening_violations("io/files/mod.rs", "let d = File::open(dir);\n").len(), 0);
    assert_eq!(opening_violations("io/text.rs", "#[cfg(test)]\nlet f = File::open(path)?;\n").len(), 0);
}
