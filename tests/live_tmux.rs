//! End to end: `rinscope live` with its slider panel in a real terminal (tmux), driven by key
//! presses and by editing the file as an editor would; the saved recording must contain the
//! reload events. Needs `tmux` (Debian: `apt-get install tmux`; `.ci/run` installs it).

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

struct Tmux {
    socket: String,
}

impl Tmux {
    fn run(&self, args: &[&str]) -> std::process::Output {
        Command::new("tmux")
            .arg("-L")
            .arg(&self.socket)
            .args(args)
            .output()
            .expect("tmux runs (install it: apt-get install tmux)")
    }

    fn screen(&self) -> String {
        String::from_utf8_lossy(&self.run(&["capture-pane", "-p", "-t", "e2e"]).stdout).into_owned()
    }

    fn wait_for(&self, what: &str) -> String {
        let deadline = Instant::now() + Duration::from_secs(15);
        loop {
            let screen = self.screen();
            if screen.contains(what) {
                return screen;
            }
            assert!(Instant::now() < deadline, "the panel never showed `{what}`; screen:\n{screen}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", "e2e"];
        args.extend_from_slice(keys);
        assert!(self.run(&args).status.success());
    }

    fn alive(&self) -> bool {
        self.run(&["has-session", "-t", "e2e"]).status.success()
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.run(&["kill-server"]);
    }
}

fn replace_in(path: &Path, from: &str, to: &str) {
    let text = std::fs::read_to_string(path).expect("read");
    assert!(text.contains(from), "{from}");
    // Truncate and write, as many editors save.
    std::fs::write(path, text.replacen(from, to, 1)).expect("write");
}

#[test]
fn sliders_and_an_editor_drive_the_same_reload_path_and_the_recording_keeps_it() {
    let dir = std::env::temp_dir().join(format!("rinscope-e2e-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let cfg = dir.join("session.toml");
    std::fs::write(&cfg, include_str!("../assets/scenarios/jiang2017-dual-axis.toml")).expect("config");
    let rrd = dir.join("session.rrd");
    let bin = env!("CARGO_BIN_EXE_rinscope");
    let command =
        format!("cd {} && {bin} live --config session.toml --no-viewer --save session.rrd --speed 5", dir.display());

    let tmux = Tmux { socket: format!("rinscope-e2e-{}", std::process::id()) };
    assert!(
        tmux.run(&["new-session", "-d", "-x", "150", "-y", "48", "-s", "e2e", &command]).status.success(),
        "tmux starts"
    );
    tmux.wait_for("parameters (write the config file)");
    tmux.wait_for("q quit"); // the help line is discoverable

    // 1. Sliders: the first control is the outer swing half-angle (600″, 10″ a step).
    tmux.keys(&["Right", "Right", "Right"]);
    tmux.wait_for("630″");
    tmux.wait_for("→ 630″");

    // 2. An editor changes the file: the panel follows.
    replace_in(&cfg, "swing_half_angle_arcsec = 300.0", "swing_half_angle_arcsec = 450.0");
    tmux.wait_for("inner swing half-angle 300″ → 450″");
    // The slider was written into the file with its comment kept.
    let text = std::fs::read_to_string(&cfg).expect("read");
    assert!(
        text.contains("swing_half_angle_arcsec = 630.0 # swing-cone half-angle α2"),
        "the slider kept the comment:\n{text}"
    );

    // 3. A bad value is reported and the session keeps running on the last good parameters.
    replace_in(&cfg, "non_orthogonality_arcsec = 20.0", "non_orthogonality_arcsec = 1e9");
    tmux.wait_for("config error");

    // 4. q ends the session; the recording is completed.
    tmux.keys(&["q"]);
    let deadline = Instant::now() + Duration::from_secs(15);
    while tmux.alive() {
        assert!(Instant::now() < deadline, "rinscope live did not exit after q");
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(rrd.exists(), "the recording was saved");
    assert!(!dir.join("session.rrd.partial").exists());

    // The recording explains its own jumps.
    let out = Command::new(bin).arg("events").arg(&rrd).output().expect("events");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let events = String::from_utf8_lossy(&out.stdout);
    assert!(
        events.contains("outer swing half-angle 600″ → 610″") || events.contains("outer swing half-angle 600″ → 630″"),
        "{events}"
    );
    assert!(events.contains("inner swing half-angle 300″ → 450″"), "{events}");
    assert!(events.contains("config error") && events.contains("non_orthogonality_arcsec"), "{events}");
    assert!(events.contains("live session ended"), "{events}");
    std::fs::remove_dir_all(&dir).ok();
}
