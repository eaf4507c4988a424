//! Temporary outputs are removed when SIGINT, SIGTERM or SIGHUP ends the
//! process (Ctrl-C, `timeout`, a closed terminal): the old target stays as
//! it was, and no half-written file is left beside it. A process killed
//! outright (SIGKILL) cannot clean up; the next run writing the same target
//! removes what it left (`output`).

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, Once, PoisonError};

/// Temporary files and directories not yet committed.
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static WATCH: Once = Once::new();

fn live() -> MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Makes a temporary file or directory with `make`, to be removed (a
/// directory with its contents) if a signal ends the process before
/// [`untrack`]; there is no moment at which a signal could leave it behind.
///
/// # Errors
/// Those of `make`.
pub fn make_tracked<T>(
    make: impl FnOnce() -> std::io::Result<T>,
    path_of: impl FnOnce(&T) -> &Path,
) -> std::io::Result<T> {
    WATCH.call_once(watch);
    // Held while the file is made: a signal's clean-up waits for it.
    let mut live = live();
    let made = make()?;
    live.push(path_of(&made).to_path_buf());
    Ok(made)
}

/// `path` was committed or removed: a signal leaves it alone now.
pub fn untrack(path: &Path) {
    let mut live = live();
    if let Some(i) = live.iter().position(|p| p == path) {
        live.swap_remove(i);
    }
}

/// Starts the thread that waits for a terminating signal, removes what is
/// tracked, and ends the process as the signal would have.
#[cfg(unix)]
fn watch() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
        return;
    };
    let _ = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                // Held to the end: nothing new is tracked meanwhile.
                let live = live();
                for path in live.iter() {
                    remove(path);
                }
                let _ = signal_hook::low_level::emulate_default_handler(signal);
                std::process::exit(128 + signal);
            }
        });
}

#[cfg(not(unix))]
fn watch() {}

/// Attempts at removing a temporary directory that a worker still adds to.
const REMOVE_ATTEMPTS: usize = 20;

/// Removes the temporary file or directory at `path`. A worker thread may
/// still make a folder in a temporary directory while it goes (only new
/// files wait for the lock the clean-up holds), which makes one removal
/// fail with "directory not empty": it is tried again until it is gone.
fn remove(path: &Path) {
    for _ in 0..REMOVE_ATTEMPTS {
        let result = if path.is_dir() {
            std::fs::remove_dir_all(path)
        } else {
            std::fs::remove_file(path)
        };
        match result {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            _ => return,
        }
    }
}
