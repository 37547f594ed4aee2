//! The bounded fuzz run (a few thousand inputs per reader) and the replay of
//! every kept regression input. The long run is `examples/fuzz.rs`.

use std::time::Duration;
use strata_fuzz::alloc::{CountingAlloc, installed, peak_during};
use strata_fuzz::driver::{Budget, fuzz, quiet_panics, regression_dir, replay, try_input};
use strata_fuzz::readers;

#[global_allocator]
static ALLOC: CountingAlloc = CountingAlloc;

/// The allocation counters are global: a test that frees memory while
/// another measures its peak makes that peak read short (`installed()` then
/// failed now and again). The tests of this binary measure one at a time.
static MEASURING: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn measuring() -> std::sync::MutexGuard<'static, ()> {
    // A test that failed while holding it leaves it poisoned; the counters
    // are still fine.
    MEASURING.lock().unwrap_or_else(|e| e.into_inner())
}

#[test]
fn every_reader_survives_mutated_files() {
    let _one_at_a_time = measuring();
    assert!(installed(), "the counting allocator is not installed");
    quiet_panics();
    let mut report = Vec::new();
    for reader in readers::all() {
        let outcome = fuzz(
            &reader,
            Budget {
                max_inputs: 1500,
                max_time: Duration::from_secs(2),
                seed: 20,
            },
        );
        eprintln!(
            "{}: {} inputs, {} accepted, {:.0}/s",
            outcome.reader,
            outcome.inputs,
            outcome.accepted,
            outcome.per_second()
        );
        // Each reader ran: a time budget running out on a slow machine still
        // leaves hundreds of inputs.
        assert!(
            outcome.inputs >= 100,
            "{}: {} inputs",
            outcome.reader,
            outcome.inputs
        );
        // The mutations reach both sides: some inputs still read (the
        // reader's deeper code runs), the rest are refused.
        assert!(
            outcome.accepted > 0 && outcome.accepted < outcome.inputs,
            "{}: {} of {} inputs accepted",
            outcome.reader,
            outcome.accepted,
            outcome.inputs
        );
        for f in outcome.failures {
            report.push(format!(
                "{}: {} (input {:?})",
                outcome.reader, f.reason, f.input
            ));
        }
    }
    assert!(report.is_empty(), "{}", report.join("\n"));
}

#[test]
fn kept_regression_inputs_pass() {
    let _one_at_a_time = measuring();
    quiet_panics();
    let results = replay(&regression_dir()).unwrap();
    assert!(
        !results.is_empty(),
        "no regression files under {}",
        regression_dir().display()
    );
    let failed: Vec<String> = results
        .iter()
        .filter_map(|(p, r)| r.as_ref().err().map(|e| format!("{}: {e}", p.display())))
        .collect();
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// A `.vmc` input: declared powers, then the file.
fn vmc_input(power_x: u8, power_y: u8, file: &[u8]) -> Vec<u8> {
    let mut input = vec![power_x, power_y, 5, 7];
    input.extend_from_slice(file);
    input
}

#[test]
fn huge_declared_map_fails_before_allocating_it() {
    let _one_at_a_time = measuring();
    assert!(installed());
    let vmc = readers::by_name("vmc").unwrap();
    // A 2^15 x 2^15 map (2 GiB of planes) over files far too short for it:
    // just past the row table and trees, with every row pointing at the
    // same few bytes, or cut short inside the table.
    let (w, h) = (1usize << 15, 1usize << 15);
    let header = strata_level::vmc::header_bytes(h as u32);
    let row = 2 * w / 8;
    let mut shared = vec![0u8; header + row];
    for y in 0..h {
        shared[y * 6..y * 6 + 4].copy_from_slice(&(header as i32).to_le_bytes());
        shared[y * 6 + 4..y * 6 + 6].copy_from_slice(&(row as i16).to_le_bytes());
    }
    for file in [&shared[..], &shared[..header / 2]] {
        let input = vmc_input(15, 15, file);
        let (result, peak) = peak_during(|| try_input(&vmc, &input));
        assert_eq!(result, Ok(false), "the file must be refused");
        assert!(
            peak < 4 * input.len() + (1 << 20),
            "{peak} bytes allocated for a {}-byte file",
            file.len()
        );
    }
}
