//! SIGINT, SIGTERM and SIGHUP (a closed terminal): no command leaves a temporary file behind,
//! and `render` stops between frames.
//!
//! A thread waits for the signals. For a command that has asked to [`cooperate`] (render), the
//! first signal is only recorded: the frame loop stops after the frame it is on, the command
//! returns [`texflow::Error::Interrupted`], and the process exits with 128 + the signal (130 for
//! SIGINT, 143 for SIGTERM, 129 for SIGHUP). Any other command, or a second signal, removes the unfinished
//! temporary files and exits at once with the same code. An encoder (`--video` through ffmpeg)
//! is killed on the first signal, so that one stuck on its input or never exiting cannot hold
//! the run: it ends within a second, its partial video removed.

use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

static RECEIVED: AtomicI32 = AtomicI32::new(0);
static COOPERATIVE: AtomicBool = AtomicBool::new(false);

/// Starts the signal thread. Without it (an error here), signals keep their default action.
pub fn install() {
    let Ok(mut signals) = Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    std::thread::spawn(move || {
        for sig in signals.forever() {
            if COOPERATIVE.load(Ordering::SeqCst)
                && RECEIVED
                    .compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst)
                    .is_ok()
            {
                // An encoder that stopped reading, or never exits, would hold the frame loop
                // (blocked writing to it, or waiting for it): it is killed now, which unblocks
                // the loop, and should the loop still not end within a second (the encoder's
                // own children holding the pipe), the process ends here like a second signal.
                if texflow::output::video::kill_encoders() > 0 {
                    std::thread::spawn(move || {
                        std::thread::sleep(std::time::Duration::from_millis(900));
                        texflow::output::abandon(|| signal_hook::low_level::exit(128 + sig));
                    });
                }
                continue;
            }
            texflow::output::video::kill_encoders();
            // `_exit`, not `exit`: the main thread may be inside the GL driver, and `exit` would
            // run the driver's atexit teardown under it (seen: aborts and segfaults in Mesa).
            texflow::output::abandon(|| signal_hook::low_level::exit(128 + sig));
        }
    });
}

/// The command stops by itself between steps when [`received`] says so.
pub fn cooperate() {
    COOPERATIVE.store(true, Ordering::SeqCst);
}

/// The first signal received, if any.
pub fn received() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}
