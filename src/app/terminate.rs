//! One termination policy for every command: the first Ctrl-C asks the running command to stop at
//! its next check and finish what it has (a complete recording of what was simulated, a command
//! that says it was cut short); a second one ends the process at once with exit code 130.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// The process-wide stop flag, with the signal handler installed on first use.
#[must_use]
pub fn stop_flag() -> Arc<AtomicBool> {
    Arc::clone(STOP.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        // A handler that cannot be installed (none in this environment) leaves Ctrl-C's default:
        // the process ends, which is what a second Ctrl-C does anyway.
        let _ = ctrlc::set_handler(move || {
            if flag.swap(true, Ordering::SeqCst) {
                std::process::exit(130);
            }
        });
        stop
    }))
}
