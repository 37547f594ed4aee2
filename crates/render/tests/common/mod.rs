//! Shared by the GPU tests: the adapter (or a loud skip) and a hand-built level.
#![allow(dead_code)]

use strata_level::model::{META_DOUBLE_LEVEL, META_TERRAIN_SHIFT};
use strata_level::{Level, MidRule, ViewSpec};
use strata_render::Gpu;

/// The GPU, or `None` after printing a loud skip notice.
pub fn gpu() -> Option<Gpu> {
    match Gpu::headless() {
        Ok(gpu) => {
            eprintln!(
                "adapter: {} ({}, {})",
                gpu.report.name, gpu.report.backend, gpu.report.driver
            );
            Some(gpu)
        }
        Err(e) => {
            eprintln!("SKIPPED: no GPU adapter ({e:#})");
            None
        }
    }
}

/// 256x256: terraces with cliffs, a water basin, a bridge slab and a cave.
pub fn synthetic_level() -> Level {
    let (w, h) = (256usize, 256usize);
    let mut heights = vec![0u8; w * h];
    let mut metas = vec![0u8; w * h];
    let tau = std::f32::consts::TAU;
    let base = |x: usize, y: usize| -> (u8, u8) {
        let (xf, yf) = (x as f32, y as f32);
        let f = 70.0
            + 45.0 * (tau * xf / 128.0).sin() * (tau * yf / 128.0).cos()
            + 20.0 * (tau * (xf + yf) / 64.0).sin();
        if f < 45.0 {
            return (8, 0); // water
        }
        // Terraces of 20 with a gentle slope on each.
        let h = 20.0 * (f / 20.0).floor() + 0.3 * (f % 20.0);
        let t = 1 + ((h / 40.0) as u8).min(6);
        (h.clamp(0.0, 220.0) as u8, t)
    };
    for y in 0..h {
        for x in 0..w {
            let (hh, t) = base(x, y);
            heights[y * w + x] = hh;
            metas[y * w + x] = t << META_TERRAIN_SHIFT;
        }
    }
    // Dual regions: (x range, y range, gap code, slab top above the floor, slab type).
    let regions = [
        ((96, 160), (120, 136), 3u8, 60u32, 7u8),
        ((20, 80), (170, 230), 7u8, 84u32, 5u8),
    ];
    for ((x0, x1), (y0, y1), code, above, slab_type) in regions {
        for y in y0..y1 {
            for x in (x0..x1).step_by(2) {
                let i = y * w + x;
                let low = heights[i].min(heights[i + 1]);
                heights[i] = low;
                heights[i + 1] = (u32::from(low) + above).min(255) as u8;
                let lower_type = metas[i] >> META_TERRAIN_SHIFT;
                metas[i] =
                    META_DOUBLE_LEVEL | (lower_type << META_TERRAIN_SHIFT) | ((code >> 2) & 3);
                metas[i + 1] = META_DOUBLE_LEVEL | (slab_type << META_TERRAIN_SHIFT) | (code & 3);
            }
        }
    }
    Level::from_planes(w as u32, h as u32, heights, metas, MidRule::Original).unwrap()
}

/// Views over the synthetic level at 0, -30, -60 and -90 degrees.
pub fn synthetic_views() -> Vec<ViewSpec> {
    [
        ("horizon", "128,40:0:30", 0.0),
        ("horizon-b", "200,200:135:15", 0.0),
        ("cave", "50,200:90:10:under", 0.0),
        ("high", "200,60:300:70", 0.0),
        ("down30", "128,100:10:60", -30.0),
        ("bridge30", "128,175:180:40", -30.0),
        ("down60", "60,60:45:80", -60.0),
        ("bridge60", "128,160:200:70", -60.0),
        ("down90", "128,128:0:100", -90.0),
        ("cave90", "50,200:0:60", -90.0),
    ]
    .into_iter()
    .map(|(n, s, p)| ViewSpec::parse(n, s, p).unwrap())
    .collect()
}
