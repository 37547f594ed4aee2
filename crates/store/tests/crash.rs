//! Fault injection: a child process (this test binary, re-executed) saves
//! edit batches into a store and is SIGKILLed at random moments; every
//! reopen is the state before or after the batch in flight, by hash. The
//! `store_crash` example does the same 200+ times.

use std::path::Path;
use std::process::Command;
use strata_store::crashtest::{child_main, run_trials};

const CHILD_DIR: &str = "STRATA_CRASH_CHILD_DIR";
const CHILD_START: &str = "STRATA_CRASH_CHILD_START";

/// The child's body: runs only when re-executed by the parent below.
#[test]
fn crash_child() {
    let Some(dir) = std::env::var_os(CHILD_DIR) else {
        return;
    };
    let start = std::env::var(CHILD_START).unwrap().parse().unwrap();
    child_main(Path::new(&dir), start).unwrap();
}

#[test]
fn killed_saves_leave_the_state_before_or_after_the_batch() {
    let dir = std::env::temp_dir().join(format!("strata-store-crash-{}", std::process::id()));
    let exe = std::env::current_exe().unwrap();
    let command = |dir: &Path, start: u64| {
        let mut c = Command::new(&exe);
        c.args([
            "--exact",
            "crash_child",
            "--nocapture",
            "--test-threads",
            "1",
        ])
        .env(CHILD_DIR, dir)
        .env(CHILD_START, start.to_string());
        c
    };
    let report = run_trials(&dir, 6, 0x51ee9, &command);
    eprintln!("{report:?}");
    assert_eq!(report.kills, 6);
    let _ = std::fs::remove_dir_all(&dir);
}
