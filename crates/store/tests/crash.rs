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
    // Odd trials: killed at a random moment. Even trials: the child aborts
    // itself at an exact step of a commit (1: after the first journal
    // object, then further on: more objects, the fsyncs, the commit
    // rename, the renames into the store), so every phase is hit.
    let trial = std::cell::Cell::new(0u64);
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
        let t = trial.replace(trial.get() + 1);
        if t.is_multiple_of(2) {
            c.env("STRATA_STORE_CRASH_AT", (1 + t * 2).to_string());
        }
        c
    };
    let report = run_trials(&dir, 12, 0x51ee9, &command);
    eprintln!("{report:?}");
    assert_eq!(report.kills, 12);
    assert!(
        report.after > 0,
        "no trial reopened after a batch: {report:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
