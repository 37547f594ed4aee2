//! Valid files the mutations start from: small, so that many inputs a
//! second reach the readers, and covering what each format can hold (a
//! map with caves, both `.vpr` layouts, every script command).

use std::path::Path;
use std::sync::OnceLock;
use strata_level::generate::{GenerateParams, generate};
use strata_level::model::MidRule;
use strata_level::views::format_views;
use strata_level::vpr::{OLD_STRATA_MAGIC, VprLayout, vpr_bytes};
use strata_level::{EditSite, Level, World, WorldConfig, io, vmc, vmp};

/// The declared sizes a map seed was written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Declared {
    pub power_x: u8,
    pub power_y: u8,
    pub geo_net_power: u8,
    pub section_size_power: u8,
}

impl Declared {
    pub fn width(&self) -> u32 {
        1 << self.power_x
    }
    pub fn height(&self) -> u32 {
        1 << self.power_y
    }
}

/// The smallest generated world: its palette and `world.ini` are seeds.
fn world() -> &'static World {
    static WORLD: OnceLock<World> = OnceLock::new();
    WORLD.get_or_init(|| {
        generate(&GenerateParams {
            seed: 20,
            width: 256,
            height: 256,
        })
        .expect("a 256x256 world generates")
    })
}

/// Small crops of a generated world (terraces, caves, slabs): the maps the
/// `.vmc` and `.vmp` seeds hold.
pub fn levels() -> &'static [Level] {
    static LEVELS: OnceLock<Vec<Level>> = OnceLock::new();
    LEVELS.get_or_init(|| {
        let level = &world().level;
        let crop = |x0: usize, y0: usize, w: usize, h: usize| {
            let (mut hs, mut ms) = (Vec::new(), Vec::new());
            for y in y0..y0 + h {
                let row = y * level.width() as usize + x0;
                hs.extend_from_slice(&level.heights()[row..row + w]);
                ms.extend_from_slice(&level.metas()[row..row + w]);
            }
            Level::from_planes(w as u32, h as u32, hs, ms, MidRule::Original)
                .expect("a crop of a level is a level")
        };
        // Where the generated world's caves are denser, and a tiny map.
        vec![
            crop(96, 96, 32, 16),
            crop(0, 200, 16, 8),
            crop(5 * 16, 0, 4, 2),
        ]
    })
}

fn declared(level: &Level) -> Declared {
    Declared {
        power_x: level.width().trailing_zeros() as u8,
        power_y: level.height().trailing_zeros() as u8,
        geo_net_power: 1,
        section_size_power: 1,
    }
}

pub fn vmc() -> Vec<(Declared, Vec<u8>)> {
    levels()
        .iter()
        .map(|l| {
            let bytes = vmc::encode_vmc(l, Path::new("seed.vmc")).expect("a seed encodes");
            (declared(l), bytes)
        })
        .collect()
}

pub fn vmp() -> Vec<(Declared, Vec<u8>)> {
    levels()
        .iter()
        .map(|l| (declared(l), vmp::encode_vmp(l)))
        .collect()
}

/// `.vpr` seeds in the game's layout and in Strata's older one.
pub fn vpr() -> Vec<(Declared, Vec<u8>)> {
    let mut out = Vec::new();
    for l in levels() {
        let d = declared(l);
        let layout = VprLayout {
            width: d.width(),
            height: d.height(),
            geo_net_power: u32::from(d.geo_net_power),
            section_size_power: u32::from(d.section_size_power),
        };
        let levels: Vec<i32> = (0..layout.sections() as i32).map(|i| 70 + i).collect();
        let game = vpr_bytes(&levels, &layout, None, Path::new("seed.vpr")).expect("vpr");
        out.push((d, game));
        let mut old = OLD_STRATA_MAGIC.to_vec();
        old.extend_from_slice(&(levels.len() as u32).to_le_bytes());
        old.extend_from_slice(&(1u32 << layout.section_size_power).to_le_bytes());
        for l in &levels {
            old.extend_from_slice(&l.to_le_bytes());
        }
        out.push((d, old));
    }
    out
}

pub fn palette() -> Vec<Vec<u8>> {
    vec![world().palette.to_bytes()]
}

/// A generated world's `world.ini`, a new one, and a Latin-1 CRLF file
/// with comments and keys Strata does not read.
pub fn world_ini() -> Vec<Vec<u8>> {
    let mut latin1 = b"; Vangers world \xe9t\xe9\r\n".to_vec();
    latin1.extend(
        WorldConfig::default()
            .to_ini_text()
            .replace('\n', "\r\n")
            .bytes(),
    );
    vec![
        world().config.to_ini_text().into_bytes(),
        WorldConfig::default().to_ini_text().into_bytes(),
        latin1,
    ]
}

pub fn views() -> Vec<Vec<u8>> {
    let mut text = format_views(&io::fostral_views());
    text.push_str("cave 10.5,20:90:3:under -30 # inside\n\n");
    vec![text.into_bytes()]
}

pub fn edit() -> Vec<Vec<u8>> {
    vec![EditSite::fostral().format().into_bytes()]
}

pub fn results_json() -> Vec<Vec<u8>> {
    vec![include_bytes!("../seeds/results.json").to_vec()]
}

/// Every command the viewer's scripts know.
pub fn script() -> Vec<Vec<u8>> {
    vec![
        b"# a flight\nview hangar\nmethod mesh  # switch\nsplit ray\nsplit off\n\
          fly 10 -2 3 5\ngoto 100 2000\nturn 15 -5\nframes 4\ndig 0.5 0.25\nundo\n\
          set ray-steps 64\noverlay off\nwindow 640 480\nscreenshot out/a.png\ncopy-view\n\
          score\nquit\n"
            .to_vec(),
    ]
}
