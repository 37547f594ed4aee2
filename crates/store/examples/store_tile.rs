//! Write a large store by tiling a world (a Vangers world or a store) over
//! a bigger map, chunk by chunk in bounded memory: the source world is held
//! once, each chunk is cut from it, wrapping. Views at the same (x, y) see
//! the same terrain on both, which is what comparing the reference's time
//! on the default world with a 65536² store wants (bench/store-read).
//!
//! `cargo run --release -p strata-store --example store_tile -- SRC WxH DST`

use std::path::PathBuf;
use std::time::Instant;
use strata_level::{MidRule, WorldConfig};
use strata_store::{Chunk, DirStore, Layout, load_any};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [src, size, dst] = &args[..] else {
        eprintln!("usage: store_tile SRC WxH DST");
        std::process::exit(2);
    };
    let (w, h) = strata_level::generate::parse_size(size).unwrap_or_else(|e| {
        eprintln!("{size}: {e}");
        std::process::exit(2);
    });
    let t = Instant::now();
    let mut world = load_any(&PathBuf::from(src), MidRule::Original).unwrap_or_else(|e| {
        eprintln!("{src}: {e}");
        std::process::exit(1);
    });
    let level = std::mem::replace(
        &mut world.level,
        strata_level::Level::flat(2, 1, 0, 0).expect("2x1 is a valid map size"),
    );
    let (sw, sh) = (level.width(), level.height());
    if w % sw != 0 || h % sh != 0 {
        eprintln!("{w}x{h} is not a whole number of {sw}x{sh} tiles");
        std::process::exit(2);
    }
    world.config = WorldConfig {
        map_power_x: w.trailing_zeros(),
        map_power_y: h.trailing_zeros(),
        ..world.config
    };
    // Water levels are per row section of the source: not tiled.
    world.water = None;
    world.source = Default::default();
    world.name = format!("{}-tiled-{w}x{h}", world.name);
    let layout = Layout::default();
    let (ch, cw) = layout.chunk_for(w, h);
    let cut = |cy: u64, cx: u64| {
        let n = (ch * cw) as usize;
        let (mut heights, mut metas) = (Vec::with_capacity(n), Vec::with_capacity(n));
        let (x0, y0) = (cx as u32 * cw % sw, cy as u32 * ch % sh);
        for y in y0..y0 + ch {
            let (hr, mr) = level.row(y % sh);
            heights.extend_from_slice(&hr[x0 as usize..(x0 + cw) as usize]);
            metas.extend_from_slice(&mr[x0 as usize..(x0 + cw) as usize]);
        }
        Ok(Chunk {
            rows: ch,
            cols: cw,
            heights,
            metas,
        })
    };
    if sw % cw != 0 || sh % ch != 0 {
        eprintln!("the source's {sw}x{sh} is not a whole number of {cw}x{ch} chunks");
        std::process::exit(2);
    }
    DirStore::create_with(&PathBuf::from(dst), &world, (w, h), &layout, &cut).unwrap_or_else(|e| {
        eprintln!("{dst}: {e}");
        std::process::exit(1);
    });
    println!(
        "wrote {dst}: {w}x{h} tiled from {src} ({sw}x{sh}) in {:.1} s",
        t.elapsed().as_secs_f64()
    );
}
