//! Fault injection for the edit journal, shared by the crate's test and
//! the `store_crash` benchmark example: a child process saves edit batches
//! into a store and is killed (SIGKILL) at a random moment; every reopen
//! must be the state before or after the batch it was saving, by hash.
//! Public for those two; not a stable API.

use crate::error::StoreError;
use crate::format::Layout;
use crate::fs::DirStore;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use strata_level::edit::{DirtyRect, EditRect, crater, fill_single};
use strata_level::{EditSite, Level, MidRule, ViewSpec, World};

/// A small deterministic generator (splitmix64).
#[derive(Clone, Debug)]
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// A number in `0..n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n.max(1)
    }
}

/// Edit batch `i` (the same for every caller): one to three craters and
/// raised blocks at random places, some across the map's edges.
pub fn batch(level: &mut Level, i: u64) -> Vec<DirtyRect> {
    let mut rng = Rng(i.wrapping_mul(7_919) ^ 0x5eed);
    let (w, h) = (u64::from(level.width()), u64::from(level.height()));
    let mut dirty = Vec::new();
    for _ in 0..1 + rng.below(3) {
        if rng.below(2) == 0 {
            let site = EditSite {
                centre_x: rng.below(w) as i64,
                centre_y: rng.below(h) as i64,
                radius: 3 + rng.below(20) as u32,
                depth: 5.0 + rng.below(60) as f32,
                camera: ViewSpec::parse("edit", "0,0:0:10", 0.0).expect("a view"),
            };
            dirty.extend(crater(level, &site));
        } else {
            let rect = EditRect {
                x: rng.below(w) as i64 - 8,
                y: rng.below(h) as i64 - 8,
                width: 1 + rng.below(40) as u32,
                height: 1 + rng.below(40) as u32,
            };
            dirty.extend(fill_single(
                level,
                rect,
                rng.below(256) as u8,
                rng.below(8) as u8,
            ));
        }
    }
    dirty
}

/// The world the trials start from.
pub fn start_world() -> World {
    strata_level::generate::generate(&strata_level::generate::GenerateParams {
        seed: 11,
        width: 256,
        height: 256,
    })
    .expect("a small world")
}

/// The layout the trials use: 64² chunks, so a batch touches several.
pub fn layout() -> Layout {
    Layout {
        chunk_height: 64,
        chunk_width: 64,
        gzip_level: 1,
    }
}

/// The child: open the store and save batches `start..`, printing
/// `done I` after each commit, until killed (or 10,000 batches).
pub fn child_main(dir: &Path, start: u64) -> Result<(), StoreError> {
    use std::io::Write;
    let store = DirStore::open(dir)?;
    let mut level = store.store().read_level(MidRule::Original)?;
    let mut out = std::io::stdout().lock();
    for i in start..start + 10_000 {
        let dirty = batch(&mut level, i);
        store.commit_rects(&level, &dirty)?;
        let _ = writeln!(out, "done {i}");
        let _ = out.flush();
    }
    Ok(())
}

/// What the trials saw.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Report {
    /// Children killed.
    pub kills: u64,
    /// Reopens that found the state before the batch in flight.
    pub before: u64,
    /// Reopens that found the state after it.
    pub after: u64,
    /// Batches committed over all trials.
    pub batches: u64,
    /// Seconds, all trials.
    pub seconds: f64,
}

/// Run `trials` kills: `command(dir, start)` builds the child's command
/// (which must end in [`child_main`]). Panics with a message on a torn or
/// unreadable store.
pub fn run_trials(
    dir: &Path,
    trials: u64,
    seed: u64,
    command: &dyn Fn(&Path, u64) -> Command,
) -> Report {
    let t = Instant::now();
    let _ = std::fs::remove_dir_all(dir);
    let world = start_world();
    DirStore::create(dir, &world, &layout()).expect("creating the store");
    // States by number of batches applied: hashes, extended as needed.
    let mut level = world.level.clone();
    let mut hashes = vec![level.content_hash()];
    let mut extend = |upto: u64, hashes: &mut Vec<String>| {
        while hashes.len() as u64 <= upto {
            let i = hashes.len() as u64 - 1;
            batch(&mut level, i);
            hashes.push(level.content_hash());
        }
    };
    let mut rng = Rng(seed);
    let mut state = 0u64; // batches in the store now
    let mut report = Report::default();
    for trial in 0..trials {
        let mut child = command(dir, state)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawning the child");
        let stdout = child.stdout.take().expect("piped");
        let reader = std::thread::spawn(move || {
            let mut last = None;
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                // (Anywhere in the line: a test harness may print its
                // "test NAME ... " on the same line first.)
                if let Some(n) = line.split("done ").nth(1) {
                    last = n.trim().parse::<u64>().ok();
                }
            }
            last
        });
        // The child starts in ~10-20 ms, then saves a batch every few ms.
        std::thread::sleep(Duration::from_micros(2_000 + rng.below(150_000)));
        let _ = child.kill();
        let status = child.wait().expect("waiting for the child");
        let last = reader.join().expect("reader");
        if status.success() {
            let mut err = String::new();
            if let Some(mut e) = child.stderr.take() {
                let _ = std::io::Read::read_to_string(&mut e, &mut err);
            }
            panic!("trial {trial}: the child exited before the kill: {err}");
        }
        report.kills += 1;
        // Committed at least up to `last`; the one after may be in flight.
        let low = last.map_or(state, |l| l + 1);
        extend(low + 1, &mut hashes);
        let store =
            DirStore::open(dir).unwrap_or_else(|e| panic!("trial {trial}: reopen failed: {e}"));
        let got = store
            .store()
            .read_level(MidRule::Original)
            .unwrap_or_else(|e| panic!("trial {trial}: reading the store failed: {e}"))
            .content_hash();
        state = if got == hashes[low as usize] {
            report.before += 1;
            low
        } else if got == hashes[low as usize + 1] {
            report.after += 1;
            low + 1
        } else {
            extend(low + 8, &mut hashes);
            let found = hashes.iter().position(|h| *h == got);
            let mut err = String::new();
            if let Some(mut e) = child.stderr.take() {
                let _ = std::io::Read::read_to_string(&mut e, &mut err);
            }
            panic!(
                "trial {trial}: the store after the kill is neither the state after {low} batches nor after {} (it is the state after {found:?}; child said {last:?}, {status}: {err})",
                low + 1
            )
        };
        report.batches = state;
        assert!(
            !dir.join(crate::fs::JOURNAL).exists(),
            "reopen left a journal"
        );
    }
    report.seconds = t.elapsed().as_secs_f64();
    report
}
