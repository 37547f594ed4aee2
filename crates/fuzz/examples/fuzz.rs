//! The long fuzz run: every reader (or one) for a number of seconds or
//! inputs each, printing inputs per second, saving failing inputs as
//! regression files under `crates/level/tests/fuzz-regressions/`.
//!
//! `cargo run -p strata-fuzz --example fuzz -- --seconds 60 [--inputs N]
//! [--reader NAME] [--seed S]`. The dev profile keeps overflow checks on
//! (the workspace's dev profile optimises, so it is fast enough); add
//! `--release` for speed without them.

use std::time::Duration;
use strata_fuzz::alloc::{CountingAlloc, installed};
use strata_fuzz::driver::{Budget, fuzz, quiet_panics, regression_dir, save_regression};
use strata_fuzz::readers;

#[global_allocator]
static ALLOC: CountingAlloc = CountingAlloc;

fn main() {
    let mut seconds = 10.0f64;
    let mut inputs = u64::MAX;
    let mut only: Option<String> = None;
    let mut seed = 1u64;
    let mut args = std::env::args().skip(1);
    let usage = "usage: fuzz [--seconds S] [--inputs N] [--reader NAME] [--seed S]";
    while let Some(arg) = args.next() {
        let mut value = || {
            args.next().unwrap_or_else(|| {
                eprintln!("{arg} needs a value; {usage}");
                std::process::exit(2)
            })
        };
        let bad = |v: &str| -> ! {
            eprintln!("`{v}` is not a valid value; {usage}");
            std::process::exit(2)
        };
        match arg.as_str() {
            "--seconds" => {
                let v = value();
                seconds = v.parse().unwrap_or_else(|_| bad(&v));
            }
            "--inputs" => {
                let v = value();
                inputs = v.parse().unwrap_or_else(|_| bad(&v));
            }
            "--seed" => {
                let v = value();
                seed = v.parse().unwrap_or_else(|_| bad(&v));
            }
            "--reader" => only = Some(value()),
            _ => {
                eprintln!("unknown argument `{arg}`; {usage}");
                std::process::exit(2)
            }
        }
    }
    let readers = match &only {
        Some(name) => match readers::by_name(name) {
            Some(r) => vec![r],
            None => {
                eprintln!(
                    "no reader `{name}` (readers: {})",
                    readers::NAMES.join(", ")
                );
                std::process::exit(2)
            }
        },
        None => readers::all(),
    };
    assert!(installed(), "the counting allocator is not installed");
    quiet_panics();
    let budget = Budget {
        max_inputs: inputs,
        max_time: Duration::from_secs_f64(seconds),
        seed,
    };
    println!(
        "{:<14} {:>12} {:>9} {:>10} {:>12} {:>9}",
        "reader", "inputs", "accepted", "seconds", "inputs/s", "failures"
    );
    let mut failed = 0;
    for reader in &readers {
        let outcome = fuzz(reader, budget);
        println!(
            "{:<14} {:>12} {:>8.1}% {:>10.1} {:>12.0} {:>9}",
            outcome.reader,
            outcome.inputs,
            100.0 * outcome.accepted as f64 / outcome.inputs.max(1) as f64,
            outcome.seconds,
            outcome.per_second(),
            outcome.failures.len()
        );
        for f in &outcome.failures {
            failed += 1;
            match save_regression(&regression_dir(), reader.name, &f.input) {
                Ok(path) => println!("  {}: {}", path.display(), f.reason),
                Err(e) => println!("  (not saved: {e}) {}", f.reason),
            }
        }
    }
    if failed > 0 {
        std::process::exit(1);
    }
}
