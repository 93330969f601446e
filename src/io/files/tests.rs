use super::*;

#[cfg(unix)]
#[test]
fn a_device_or_a_fifo_is_not_replaced_by_an_output() {
    let e = check_output_path(Path::new("/dev/null")).expect_err("a device");
    assert!(e.to_string().contains("/dev/null: is a device, not a regular file"), "{e}");
    let d = scratch("fifo");
    let fifo = d.join("out.json");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
    if made {
        let e = write_atomically(&fifo, b"{}").expect_err("a FIFO");
        assert!(e.to_string().contains("FIFO"), "{e}");
        assert!(
            std::fs::symlink_metadata(&fifo).is_ok_and(|m| special_kind(&m.file_type()).is_some()),
            "the FIFO is still there"
        );
    }
    std::fs::remove_dir_all(&d).ok();
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rinscope-files-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&d).ok();
    std::fs::create_dir_all(&d).expect("scratch dir");
    d
}

#[test]
fn the_partial_file_sits_beside_the_final_one() {
    assert_eq!(partial_path(Path::new("out/x.rrd")), PathBuf::from("out/x.rrd.partial"));
    assert_eq!(partial_path(Path::new("x.json")), PathBuf::from("x.json.partial"));
}

#[test]
fn a_symlink_at_the_partial_is_not_followed() {
    let d = scratch("symlink");
    let victim = d.join("victim.txt");
    std::fs::write(&victim, "precious").expect("victim");
    std::os::unix::fs::symlink(&victim, d.join("out.json.partial")).expect("symlink");
    let e = write_atomically(&d.join("out.json"), b"{}").expect_err("must refuse");
    assert!(matches!(e, OutputError::NotAFile { problem: "is a symlink", .. }), "{e}");
    assert_eq!(std::fs::read_to_string(&victim).expect("victim"), "precious");
    assert!(!d.join("out.json").exists());
}

#[test]
fn a_second_writer_is_refused_and_an_abandoned_one_leaves_the_old_file() {
    let d = scratch("lock");
    let path = d.join("x.rrd");
    std::fs::write(&path, "old good file").expect("old");
    let first = PartialFile::create(&path).expect("first writer");
    let e = PartialFile::create(&path).expect_err("second writer");
    assert!(matches!(e, OutputError::Busy { .. }), "{e}");
    first.file().write_all(b"half").expect("write");
    drop(first); // abandoned
    assert!(!partial_path(&path).exists(), "partial removed");
    assert_eq!(std::fs::read_to_string(&path).expect("old"), "old good file");
    // A stale (unlocked) partial is reused; a committed write replaces the file.
    std::fs::write(partial_path(&path), "stale bytes from a crash").expect("stale");
    write_atomically(&path, b"new").expect("write");
    assert_eq!(std::fs::read_to_string(&path).expect("new"), "new");
}

#[test]
fn directories_and_missing_directories_are_refused_up_front() {
    let d = scratch("dirs");
    assert!(matches!(check_output_path(&d), Err(OutputError::IsDirectory(_))));
    assert!(matches!(check_output_path(Path::new("new/")), Err(OutputError::IsDirectory(_))));
    assert!(matches!(check_output_path(&d.join("missing/x.json")), Err(OutputError::NoDirectory { .. })));
    assert!(check_output_path(&d.join("x.json")).is_ok());
}

/// A folder no one may write to: a 0o555 folder, or /sys for root (who writes anywhere else).
fn read_only_dir(d: &Path) -> PathBuf {
    use std::os::unix::fs::PermissionsExt as _;
    let ro = d.join("ro");
    std::fs::create_dir_all(&ro).expect("ro");
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).expect("chmod");
    if std::fs::write(ro.join("probe"), "").is_ok() { PathBuf::from("/sys") } else { ro }
}

#[test]
fn one_output_rule_for_files_and_folders() {
    // Issue 31: --export or --figures onto a FIFO or a file said only "File exists (os error
    // 17)"; --json into a read-only folder was refused only after the whole run.
    let d = scratch("rule");
    let fifo = d.join("fifo");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()));
    let file = d.join("file.txt");
    std::fs::write(&file, "x").expect("file");
    let link = d.join("link");
    std::os::unix::fs::symlink(&file, &link).expect("symlink");
    let ro = read_only_dir(&d);
    use OutputKind::{File as F, Folder as D};
    for (flag, path, kind, says) in [
        ("--export", fifo.clone(), D, "is a FIFO"),
        ("--figures", file.clone(), D, "is a file; give a folder"),
        ("--figures", link.clone(), D, "is a symlink"),
        ("--json", link.clone(), F, "is a symlink"),
        ("--json", fifo.clone(), F, "is a FIFO"),
        ("--summary-json", d.clone(), F, "is a directory"),
        ("--save", Path::new("/dev/null").to_path_buf(), F, "is a device"),
        ("--export", d.join("missing/sub"), D, "does not exist"),
        ("--json", d.join("missing/x.json"), F, "does not exist"),
        ("--json", ro.join("x.json"), F, "cannot be written"),
        ("--export", ro.join("new"), D, "cannot be written"),
    ] {
        let e = check_output(flag, &path, kind).expect_err(says).to_string();
        assert!(e.starts_with(flag) && e.contains(says), "{flag} {}: {e}", path.display());
    }
    assert!(
        check_output("--export", &d.join("new"), D).is_ok() && !d.join("new").exists(),
        "a new folder in a writable one; nothing left"
    );
    assert!(check_output("--export", &d, D).is_ok());
    assert!(check_output("--json", &d.join("x.json"), F).is_ok());
    assert_eq!(std::fs::read_dir(&d).expect("dir").count(), 4, "no probe left behind");
    create_output_dir("--figures", &d.join("figs")).expect("made");
    create_output_dir("--figures", &d.join("figs")).expect("an existing folder is used");
    assert!(create_output_dir("--figures", &d.join("a/b")).is_err(), "no tree is created");
}

#[test]
fn a_partial_folder_is_locked_and_a_dead_runs_one_is_taken_over() {
    let d = scratch("dir");
    let out = d.join("logset");
    let partial = partial_path(&out);
    // A folder a killed export left, with a file in it: taken over, emptied.
    std::fs::create_dir(&partial).expect("stale");
    std::fs::write(partial.join("imu.csv"), "half").expect("stale file");
    let held = create_partial_dir(&out).expect("a dead run's folder is taken over");
    assert_eq!(std::fs::read_dir(&partial).expect("dir").count(), 0, "started afresh");
    // While held, a second writer is refused.
    let e = create_partial_dir(&out).expect_err("second writer");
    assert!(matches!(e, OutputError::Busy { .. }), "{e}");
    drop(held);
    assert!(create_partial_dir(&out).is_ok(), "free again once the first lets go");
    // A symlink at the partial's name is not followed.
    let other = d.join("other");
    std::fs::create_dir(&other).expect("victim dir");
    std::fs::write(other.join("keep"), "precious").expect("victim");
    std::os::unix::fs::symlink(&other, partial_path(&d.join("x"))).expect("symlink");
    let e = create_partial_dir(&d.join("x")).expect_err("symlink");
    assert!(matches!(e, OutputError::NotAFile { .. }), "{e}");
    assert!(other.join("keep").exists());
}

#[test]
fn inputs_that_are_not_regular_files_are_refused_at_once() {
    let d = scratch("inputs");
    let fifo = d.join("imu.csv");
    let status = std::process::Command::new("mkfifo").arg(&fifo).status().expect("mkfifo (coreutils) runs");
    assert!(status.success(), "mkfifo {}", fifo.display());
    // No writer: a blocking open would never return.
    for (p, what) in [(fifo.as_path(), "FIFO"), (Path::new("/dev/zero"), "device"), (d.as_path(), "directory")] {
        let e = open_input(p).expect_err("refused");
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput, "{}", p.display());
        assert!(e.to_string().contains("not a regular file") && e.to_string().contains(what), "{e}");
    }
    let file = d.join("ok.csv");
    std::fs::write(&file, "t_s\n0\n").expect("file");
    let mut text = String::new();
    std::io::Read::read_to_string(&mut open_input(&file).expect("a regular file opens"), &mut text).expect("reads");
    assert_eq!(text, "t_s\n0\n");
    assert_eq!(open_input(&d.join("missing")).expect_err("missing").kind(), std::io::ErrorKind::NotFound);
}

#[test]
fn a_fifo_at_the_partial_does_not_block() {
    let d = scratch("fifo-partial");
    let fifo = d.join("x.json.partial");
    let status = std::process::Command::new("mkfifo").arg(&fifo).status().expect("mkfifo (coreutils) runs");
    assert!(status.success(), "mkfifo {}", fifo.display());
    let e = write_atomically(&d.join("x.json"), b"{}").expect_err("must refuse");
    assert!(matches!(e, OutputError::NotAFile { .. }), "{e}");
}
