//! The readers under test: each a name, a strategy of inputs (mutated
//! seeds) and a check that runs the reader on one input.
//!
//! A map reader's input is 4 bytes of declared sizes (`Map Power X`, `Map
//! Power Y`, `GeoNet Power`, `Section Size Power`, as `world.ini` gives
//! them, each already in the range `WorldConfig` accepts) followed by the
//! file; every other input is the file alone. Regression files hold inputs
//! exactly so.

use crate::mutate::{self, VmcLayout};
use crate::seeds::{self, Declared};
use proptest::prelude::*;
use proptest::strategy::{BoxedStrategy, Union};
use std::path::Path;
use strata_level::model::MidRule;
use strata_level::views::parse_views;
use strata_level::vpr::{VprLayout, parse_vpr};
use strata_level::{EditSite, LevelError, Palette, WorldConfig, vmc, vmp};

/// Most edits applied to one seed.
const MAX_EDITS: usize = 6;

/// Runs the reader on one input: whether the reader accepted it (a
/// measure of how deep the mutations reach), or how it misbehaved short of
/// panicking.
pub type Check = fn(&[u8]) -> Result<bool, String>;

pub struct Reader {
    /// Also the regression directory's name.
    pub name: &'static str,
    pub inputs: BoxedStrategy<Vec<u8>>,
    pub check: Check,
}

/// Every reader's name, in the order [`all`] gives them.
pub const NAMES: [&str; 9] = [
    "world-ini",
    "vmc",
    "vmp",
    "pal",
    "vpr",
    "views",
    "edit",
    "results-json",
    "script",
];

pub fn all() -> Vec<Reader> {
    NAMES.iter().filter_map(|n| by_name(n)).collect()
}

pub fn by_name(name: &str) -> Option<Reader> {
    let (inputs, check): (BoxedStrategy<Vec<u8>>, Check) = match name {
        "world-ini" => (text(seeds::world_ini(), INI_WORDS), check_ini),
        "vmc" => (vmc_inputs(), check_vmc),
        "vmp" => (map_inputs(seeds::vmp()), check_vmp),
        "pal" => (
            mutate::mutated_bytes(seeds::palette(), MAX_EDITS).boxed(),
            check_palette,
        ),
        "vpr" => (map_inputs(seeds::vpr()), check_vpr),
        "views" => (text(seeds::views(), VIEW_WORDS), check_views),
        "edit" => (text(seeds::edit(), VIEW_WORDS), check_edit),
        "results-json" => (text(seeds::results_json(), JSON_WORDS), check_results),
        "script" => (text(seeds::script(), SCRIPT_WORDS), check_script),
        _ => return None,
    };
    let name = NAMES.into_iter().find(|n| *n == name)?;
    Some(Reader {
        name,
        inputs,
        check,
    })
}

const INI_WORDS: &[&str] = &[
    "[Global Parameters]",
    "[Storage]",
    "[Rendering Parameters]",
    "Map Power X",
    "Map Power Y",
    "GeoNet Power",
    "Section Size Power",
    "Compressed Format Using",
    "File Name",
    "Palette File",
    "Begin Colors",
    "End Colors",
    "..",
    "a/b",
];
const VIEW_WORDS: &[&str] = &["under", "crater", "camera", "#", "90", "-90", "90.0001"];
const JSON_WORDS: &[&str] = &[
    "gpu-timestamps",
    "cpu-submit-wait",
    "original",
    "vange-rs",
    "*",
];
const SCRIPT_WORDS: &[&str] = &[
    "view",
    "method",
    "split",
    "off",
    "on",
    "fly",
    "goto",
    "turn",
    "frames",
    "dig",
    "undo",
    "set",
    "ray-steps",
    "overlay",
    "window",
    "screenshot",
    "copy-view",
    "score",
    "quit",
];

fn text(seeds: Vec<Vec<u8>>, words: &'static [&'static str]) -> BoxedStrategy<Vec<u8>> {
    mutate::mutated_text(seeds, words, MAX_EDITS).boxed()
}

/// The declared sizes: mostly the seed's own, else any that `world.ini`
/// accepts (up to 2^15 x 2^15, far more than any seed holds).
fn declared(own: Declared) -> impl Strategy<Value = Declared> {
    prop_oneof![
        3 => Just(own),
        1 => (1..=15u8, 1..=15u8, 0..=15u8, 0..=15u8).prop_map(|(x, y, g, s)| Declared {
            power_x: x,
            power_y: y,
            geo_net_power: g,
            section_size_power: s,
        }),
    ]
}

fn with_declared(d: Declared, file: &[u8]) -> Vec<u8> {
    let mut out = vec![d.power_x, d.power_y, d.geo_net_power, d.section_size_power];
    out.extend_from_slice(file);
    out
}

/// The declared sizes and file of a map reader's input, or `None` for an
/// input too short to be one (a regression file cut by hand).
fn split_declared(input: &[u8]) -> Option<(Declared, &[u8])> {
    let (head, file) = input.split_at_checked(4)?;
    let power = |b: u8| u32::from(b).clamp(1, 15) as u8;
    Some((
        Declared {
            power_x: power(head[0]),
            power_y: power(head[1]),
            geo_net_power: head[2].min(15),
            section_size_power: head[3].min(15),
        },
        file,
    ))
}

fn map_inputs(seeds: Vec<(Declared, Vec<u8>)>) -> BoxedStrategy<Vec<u8>> {
    let per_seed = seeds.into_iter().map(|(own, bytes)| {
        (
            declared(own),
            prop::collection::vec(mutate::byte_edit(), 0..=MAX_EDITS),
        )
            .prop_map(move |(d, edits)| {
                let mut file = bytes.clone();
                for e in &edits {
                    e.apply(&mut file);
                }
                with_declared(d, &file)
            })
            .boxed()
    });
    Union::new(per_seed).boxed()
}

fn vmc_inputs() -> BoxedStrategy<Vec<u8>> {
    let per_seed = seeds::vmc().into_iter().map(|(own, bytes)| {
        let layout = VmcLayout {
            rows: own.height() as usize,
            header: vmc::header_bytes(own.height()),
            file_len: bytes.len(),
        };
        (
            declared(own),
            prop::collection::vec(mutate::vmc_edit(layout), 0..=MAX_EDITS),
        )
            .prop_map(move |(d, edits)| {
                let mut file = bytes.clone();
                for e in &edits {
                    e.apply(layout, &mut file);
                }
                with_declared(d, &file)
            })
            .boxed()
    });
    Union::new(per_seed).boxed()
}

/// A reader's error must name the file it is about.
fn names_file<T>(result: Result<T, LevelError>, path: &Path) -> Result<bool, String> {
    match result {
        Ok(_) => Ok(true),
        Err(e) if e.to_string().starts_with(&format!("{}: ", path.display())) => Ok(false),
        Err(e) => Err(format!("the error does not name {}: {e}", path.display())),
    }
}

fn check_ini(input: &[u8]) -> Result<bool, String> {
    let path = Path::new("fuzz/world.ini");
    let parsed = WorldConfig::parse_bytes(input, path);
    if let Ok(config) = &parsed {
        // What a parsed config promises its users: sizes and layouts compute.
        let layout = VprLayout::of(config);
        std::hint::black_box((config.width(), config.height(), layout.file_size()));
        // And the file written back parses to the same config.
        let again = WorldConfig::parse_bytes(&config.to_ini_bytes(), path)
            .map_err(|e| format!("a parsed world.ini written back does not parse: {e}"))?;
        if again != *config {
            return Err("a parsed world.ini written back parses differently".into());
        }
    }
    names_file(parsed, path)
}

fn check_vmc(input: &[u8]) -> Result<bool, String> {
    let Some((d, file)) = split_declared(input) else {
        return Ok(false);
    };
    let path = Path::new("fuzz/output.vmc");
    let decoded = vmc::decode_vmc(file, d.width(), d.height(), MidRule::Original, path);
    names_file(decoded, path)
}

fn check_vmp(input: &[u8]) -> Result<bool, String> {
    let Some((d, file)) = split_declared(input) else {
        return Ok(false);
    };
    let path = Path::new("fuzz/output.vmp");
    let decoded = vmp::decode_vmp(file, d.width(), d.height(), MidRule::VangeRs, path);
    names_file(decoded, path)
}

fn check_palette(input: &[u8]) -> Result<bool, String> {
    let path = Path::new("fuzz/harmony.pal");
    names_file(Palette::from_bytes(input, path), path)
}

fn check_vpr(input: &[u8]) -> Result<bool, String> {
    let Some((d, file)) = split_declared(input) else {
        return Ok(false);
    };
    let layout = VprLayout {
        width: d.width(),
        height: d.height(),
        geo_net_power: u32::from(d.geo_net_power),
        section_size_power: u32::from(d.section_size_power),
    };
    let path = Path::new("fuzz/output.vpr");
    let parsed = parse_vpr(file, &layout, path);
    if let Ok((levels, _)) = &parsed
        && levels.len() != layout.sections()
    {
        return Err(format!(
            "{} water levels read for {} sections",
            levels.len(),
            layout.sections()
        ));
    }
    names_file(parsed, path)
}

/// Text files are read as the world loader reads them (lossy UTF-8).
fn lossy(input: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(input)
}

fn check_views(input: &[u8]) -> Result<bool, String> {
    Ok(parse_views(&lossy(input)).is_ok())
}

fn check_edit(input: &[u8]) -> Result<bool, String> {
    Ok(EditSite::parse(&lossy(input)).is_ok())
}

/// `strata merge`'s path: parse, check two runs against each other, report.
fn check_results(input: &[u8]) -> Result<bool, String> {
    match strata_results::RunResults::from_json(&lossy(input)) {
        Ok(run) => Ok(strata_results::merge::merge(&[run.clone(), run]).is_ok()),
        Err(_) => Ok(false),
    }
}

fn check_script(input: &[u8]) -> Result<bool, String> {
    // Any `set` name parses here (the viewer checks names against its knobs).
    Ok(strata_script::Script::<String>::parse(&lossy(input)).is_ok())
}
