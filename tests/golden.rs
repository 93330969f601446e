//! Nothing a user reads changes when the program's structure does: every command's documents
//! (--summary-json / --json) on every preset and on log sets, against the ones the program wrote
//! before its commands were given one owner each in `app/` (tests/golden/expected, written by
//! tests/golden/capture.sh; wall times, memory and paths left out). These are regression values,
//! not physics: the physics is checked against the papers elsewhere.

mod common;
use common::scratch;
use std::path::Path;
use std::process::Command;

#[test]
fn every_command_writes_the_same_documents_as_before() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    let out = scratch("documents");
    let status = Command::new("bash")
        .arg(here.join("capture.sh"))
        .arg(env!("CARGO_BIN_EXE_rinscope"))
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .output()
        .expect("bash runs tests/golden/capture.sh");
    assert!(status.status.success(), "capture.sh failed:\n{}", String::from_utf8_lossy(&status.stderr));
    let mut expected: Vec<_> = std::fs::read_dir(here.join("expected")).unwrap().map(|e| e.unwrap().path()).collect();
    expected.sort();
    assert!(expected.len() >= 28, "tests/golden/expected holds {} documents", expected.len());
    let mut differ = Vec::new();
    for want in &expected {
        let name = want.file_name().unwrap();
        let got = out.join(name);
        let (want_text, got_text) =
            (std::fs::read_to_string(want).unwrap(), std::fs::read_to_string(&got).unwrap_or_default());
        if want_text != got_text {
            let first = want_text.lines().zip(got_text.lines()).enumerate().find(|(_, (a, b))| a != b);
            differ.push(match first {
                Some((i, (a, b))) => format!("{}: line {}: was {a:?}, now {b:?}", name.to_string_lossy(), i + 1),
                None => format!(
                    "{}: {} lines, now {}",
                    name.to_string_lossy(),
                    want_text.lines().count(),
                    got_text.lines().count()
                ),
            });
        }
    }
    assert!(differ.is_empty(), "{} of {} documents changed:\n{}", differ.len(), expected.len(), differ.join("\n"));
}
