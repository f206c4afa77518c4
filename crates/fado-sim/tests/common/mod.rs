//! Helpers of the CLI output tests (`cli_outputs.rs`, `cli_commission.rs`).

use std::path::Path;
use std::process::{Command, Stdio};

/// True when no temporary output file (`.NAME.tmp-PID`) is left in `out`.
pub fn no_temporaries(out: &Path) -> bool {
    std::fs::read_dir(out)
        .unwrap()
        .all(|e| !e.unwrap().file_name().to_string_lossy().contains(".tmp-"))
}

/// Runs `test` with a tmpfs of `size` (`mount -o size=…`) mounted on `out`, unmounts it and
/// re-raises a failure of `test`. Needs root (CAP_SYS_ADMIN) and a kernel with tmpfs; without
/// them says SKIPPED and returns false.
pub fn on_small_tmpfs(
    out: &Path,
    size: &str,
    test: impl FnOnce() + std::panic::UnwindSafe,
) -> bool {
    std::fs::create_dir_all(out).unwrap();
    let mounted = Command::new("mount")
        .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
        .arg(out)
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        eprintln!("SKIPPED: cannot mount a small tmpfs here (not root, or no CAP_SYS_ADMIN)");
        return false;
    }
    let result = std::panic::catch_unwind(test);
    let unmounted = Command::new("umount").arg(out).status().unwrap();
    assert!(unmounted.success());
    if let Err(panic) = result {
        std::panic::resume_unwind(panic);
    }
    true
}
