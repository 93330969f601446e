//! One termination policy for every command. The first SIGINT (Ctrl-C), SIGTERM or SIGHUP asks the
//! running command to stop at its next check and finish what it has: a complete, verified
//! recording of what was simulated, and a command that says it was cut short and exits with
//! 128 + the signal (130, 143, 129). A second signal ends the process at once, removing every
//! partial file it was writing.
//!
//! The signals reach a thread through signal-hook's self-pipe: nothing runs inside a signal
//! handler but signal-hook's own async-signal-safe write. That thread must outlive anything that
//! can happen to the terminal: it writes to stderr with `errln!`, which drops a message stderr
//! cannot take (a pipe whose reader went away, a terminal that hung up) — `eprintln!` panicked
//! there, ending the thread, after which SIGTERM and SIGINT were caught and ignored.
//!
//! The first signal is answered at the command's next check, so nothing a command waits on may
//! block for ever: every input is opened without blocking and must be a regular file
//! (`io::files::open_input`).

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};
use std::sync::{Arc, OnceLock};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};

static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The first signal received (0: none).
static FIRST_SIGNAL: AtomicI32 = AtomicI32::new(0);

fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "Ctrl-C (SIGINT)",
        SIGTERM => "SIGTERM",
        SIGHUP => "SIGHUP",
        _ => "a signal",
    }
}

/// The process-wide stop flag, with the signal thread started on first use.
#[must_use]
pub fn stop_flag() -> Arc<AtomicBool> {
    Arc::clone(STOP.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        match signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
            Ok(mut signals) => {
                let spawned = std::thread::Builder::new().name("signals".into()).spawn(move || {
                    for signal in signals.forever() {
                        if FIRST_SIGNAL.compare_exchange(0, signal, Ordering::SeqCst, Ordering::SeqCst).is_ok() {
                            flag.store(true, Ordering::SeqCst);
                            errln!("\nrinscope: {}: finishing what was simulated (send it again to stop at once)", name(signal));
                        } else {
                            crate::io::files::remove_unfinished();
                            errln!("\nrinscope: {} again: stopped at once; unfinished files removed", name(signal));
                            std::process::exit(128 + signal);
                        }
                    }
                });
                if let Err(e) = spawned {
                    errln!("rinscope: cannot watch for signals ({e}); Ctrl-C ends the process without finishing the recording");
                }
            }
            Err(e) => errln!("rinscope: cannot watch for signals ({e}); Ctrl-C ends the process without finishing the recording"),
        }
        stop
    }))
}

/// What stopped the run, for messages: "Ctrl-C (SIGINT)", "SIGTERM", "SIGHUP", or `None`.
#[must_use]
pub fn stop_reason() -> Option<&'static str> {
    match FIRST_SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        s => Some(name(s)),
    }
}

/// The exit code of a command cut short: 128 + the first signal (130 when stopped otherwise).
#[must_use]
pub fn interrupted_exit_code() -> u8 {
    match FIRST_SIGNAL.load(Ordering::SeqCst) {
        0 => 130,
        s => u8::try_from(128 + s).unwrap_or(130),
    }
}

/// Writes a command's output to stdout. A reader that went away (a closed pipe: `rinscope scenarios
/// | head -5`) ends the process quietly with 141 (128 + SIGPIPE), as a command-line tool does; any
/// other write error is reported once on stderr.
pub fn write_stdout(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            crate::io::files::remove_unfinished();
            std::process::exit(141);
        }
        static REPORTED: AtomicBool = AtomicBool::new(false);
        if !REPORTED.swap(true, Ordering::Relaxed) {
            errln!("rinscope: cannot write to stdout: {e}");
        }
    }
}
