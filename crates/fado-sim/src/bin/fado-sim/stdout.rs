//! Writing to stdout without ever panicking: a reader that went away (`fado-sim … | head`)
//! ends the printing silently, any other error (a full disk) is reported at exit with code 3.
//! Every command has written its files before it prints.

use std::sync::atomic::{AtomicBool, Ordering};

/// Set once writing to stdout failed: later writes are skipped.
static STDOUT_FAILED: AtomicBool = AtomicBool::new(false);
/// The first stdout error other than a closed pipe (a full disk): reported at exit.
static STDOUT_ERROR: std::sync::Mutex<Option<std::io::Error>> = std::sync::Mutex::new(None);

/// Writes `args` to stdout; see the module's documentation.
pub fn print_out(args: std::fmt::Arguments<'_>) {
    use std::io::Write;
    if STDOUT_FAILED.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        STDOUT_FAILED.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe
            && let Ok(mut slot) = STDOUT_ERROR.lock()
        {
            slot.get_or_insert(e);
        }
    }
}

/// The first stdout error other than a closed pipe, if any.
pub fn take_error() -> Option<std::io::Error> {
    STDOUT_ERROR.lock().ok().and_then(|mut s| s.take())
}

/// `println!` through [`print_out`].
macro_rules! outln {
    () => { $crate::stdout::print_out(format_args!("\n")) };
    ($($arg:tt)*) => { $crate::stdout::print_out(format_args!("{}\n", format_args!($($arg)*))) };
}

/// `print!` through [`print_out`].
macro_rules! out {
    ($($arg:tt)*) => { $crate::stdout::print_out(format_args!($($arg)*)) };
}
