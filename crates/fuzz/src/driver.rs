//! Running a reader over many inputs: each input under `catch_unwind` with
//! its allocation peak measured, batches of inputs through proptest's runner
//! (which shrinks a failing input before it is reported), and failing
//! inputs kept as regression files that a test replays.

use crate::alloc::peak_during;
use crate::readers::{self, Reader};
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};
use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Most bytes a reader may allocate for an input of `len` bytes: a generous
/// multiple of the input (text readers keep a line table), never the
/// megabytes or gigabytes a declared size could ask for.
pub fn alloc_bound(len: usize) -> usize {
    256 * len + (1 << 20)
}

/// The last panic's message and place, from any thread (rayon's workers
/// decode `.vmc` rows), kept by the hook [`quiet_panics`] installs.
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);

/// Keep panic messages for the report instead of printing each one (a
/// failing input is tried many times while it is shrunk).
pub fn quiet_panics() {
    std::panic::set_hook(Box::new(|info| {
        if let Ok(mut last) = LAST_PANIC.lock() {
            *last = Some(info.to_string());
        }
    }));
}

/// Run one input: whether the reader accepted it, or `Err` when it
/// panicked, allocated more than [`alloc_bound`], or failed its check.
pub fn try_input(reader: &Reader, input: &[u8]) -> Result<bool, String> {
    let run = catch_unwind(AssertUnwindSafe(|| peak_during(|| (reader.check)(input))));
    match run {
        Ok((checked, peak)) => {
            let accepted = checked?;
            let bound = alloc_bound(input.len());
            if peak > bound {
                return Err(format!(
                    "allocated {peak} bytes for a {}-byte input (bound {bound})",
                    input.len()
                ));
            }
            Ok(accepted)
        }
        Err(payload) => {
            let hooked = LAST_PANIC.lock().ok().and_then(|mut p| p.take());
            let message = hooked.unwrap_or_else(|| {
                payload
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "(no message)".into())
            });
            Err(format!("panicked: {message}"))
        }
    }
}

/// When to stop fuzzing one reader: whichever comes first.
#[derive(Clone, Copy, Debug)]
pub struct Budget {
    pub max_inputs: u64,
    pub max_time: Duration,
    /// Seeds the input generator: the same seed gives the same inputs.
    pub seed: u64,
}

/// A failing input, shrunk, and why it failed.
#[derive(Clone, Debug)]
pub struct Failure {
    pub input: Vec<u8>,
    pub reason: String,
}

/// What fuzzing one reader found.
#[derive(Debug)]
pub struct Outcome {
    pub reader: &'static str,
    /// Inputs run, shrinking steps included.
    pub inputs: u64,
    /// Inputs the reader accepted (the rest it refused with an error).
    pub accepted: u64,
    pub seconds: f64,
    pub failures: Vec<Failure>,
}

impl Outcome {
    pub fn per_second(&self) -> f64 {
        self.inputs as f64 / self.seconds.max(1e-9)
    }
}

/// Inputs per proptest runner: small enough that the time budget is
/// checked often, large enough that a runner's setup does not count.
const BATCH: u32 = 2000;

/// Fuzz `reader` within `budget`.
pub fn fuzz(reader: &Reader, budget: Budget) -> Outcome {
    let start = Instant::now();
    let count = Cell::new(0u64);
    let accepted = Cell::new(0u64);
    let mut failures = Vec::new();
    let mut batch = 0u64;
    while count.get() < budget.max_inputs && start.elapsed() < budget.max_time {
        let cases = (budget.max_inputs - count.get()).min(u64::from(BATCH)) as u32;
        let config = Config {
            cases,
            failure_persistence: None,
            max_shrink_iters: 4096,
            ..Config::default()
        };
        let mut seed = [0u8; 32];
        seed[..8].copy_from_slice(&budget.seed.to_le_bytes());
        seed[8..16].copy_from_slice(&batch.to_le_bytes());
        seed[16..24].copy_from_slice(reader.name.len().to_le_bytes().as_slice());
        let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &seed);
        let mut runner = TestRunner::new_with_rng(config, rng);
        let result = runner.run(&reader.inputs, |input| {
            count.set(count.get() + 1);
            let ok = try_input(reader, &input).map_err(TestCaseError::fail)?;
            accepted.set(accepted.get() + u64::from(ok));
            Ok(())
        });
        match result {
            Ok(()) => {}
            Err(TestError::Fail(reason, input)) => failures.push(Failure {
                input,
                reason: reason.to_string(),
            }),
            Err(TestError::Abort(reason)) => failures.push(Failure {
                input: Vec::new(),
                reason: format!("the runner gave up: {reason}"),
            }),
        }
        batch += 1;
    }
    Outcome {
        reader: reader.name,
        inputs: count.get(),
        accepted: accepted.get(),
        seconds: start.elapsed().as_secs_f64(),
        failures,
    }
}

/// Where regression inputs live: `crates/level/tests/fuzz-regressions/<reader>/`.
pub fn regression_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../level/tests/fuzz-regressions")
}

/// A stable name for an input (FNV-1a of its bytes).
fn input_name(input: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in input {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}.bin")
}

/// Keep a failing input as a regression file; returns its path.
pub fn save_regression(dir: &Path, reader: &str, input: &[u8]) -> std::io::Result<PathBuf> {
    let dir = dir.join(reader);
    std::fs::create_dir_all(&dir)?;
    let path = dir.join(input_name(input));
    std::fs::write(&path, input)?;
    Ok(path)
}

/// A regression file and what its reader did with it.
pub type Replayed = (PathBuf, Result<bool, String>);

/// Every regression file under `dir` run through its reader: the files
/// found and the outcome of each. A directory not named after a reader is
/// an error.
pub fn replay(dir: &Path) -> Result<Vec<Replayed>, String> {
    let mut out = Vec::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(out);
    };
    let mut dirs: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    dirs.sort();
    for sub in dirs.into_iter().filter(|p| p.is_dir()) {
        let name = sub.file_name().map(|n| n.to_string_lossy().into_owned());
        let reader = name
            .as_deref()
            .and_then(readers::by_name)
            .ok_or_else(|| format!("{}: no reader of that name", sub.display()))?;
        let mut files: Vec<PathBuf> = std::fs::read_dir(&sub)
            .map_err(|e| format!("{}: {e}", sub.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "bin"))
            .collect();
        files.sort();
        for file in files {
            let input = std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            out.push((file, try_input(&reader, &input)));
        }
    }
    Ok(out)
}
