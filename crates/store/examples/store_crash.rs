//! The journal's fault-injection benchmark: a child process (this example,
//! re-executed with `child DIR START`) saves edit batches into a store and
//! is SIGKILLed at a random moment, TRIALS times (default 200); every
//! reopen must be the state before or after the batch in flight, by hash.
//!
//! `cargo run -p strata-store --example store_crash [-- TRIALS]`

use std::path::Path;
use std::process::Command;
use strata_store::crashtest::{child_main, run_trials};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("child") {
        let start = args[2].parse().expect("start batch");
        child_main(Path::new(&args[1]), start).expect("saving batches");
        return;
    }
    let trials = args.first().map_or(200, |t| t.parse().expect("trials"));
    let exe = std::env::current_exe().expect("own path");
    let dir = std::env::temp_dir().join(format!("strata-store-crash-bench-{}", std::process::id()));
    let command = |dir: &Path, start: u64| {
        let mut c = Command::new(&exe);
        c.arg("child").arg(dir).arg(start.to_string());
        c
    };
    let report = run_trials(&dir, trials, 0xc0ffee, &command);
    println!(
        "{} kills: {} reopened before the batch in flight, {} after; {} batches committed; {:.1} s; every reopen was one of the two states",
        report.kills, report.before, report.after, report.batches, report.seconds
    );
    let _ = std::fs::remove_dir_all(&dir);
}
