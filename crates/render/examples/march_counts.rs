//! `ray`'s samples per pixel on paper, with and without its tiles' beam
//! (issue 36 item 2): `cargo run -p strata-render --example march_counts --
//! [--size WxH] [--steps N]` over the built-in world's twelve views.
//!
//! Each pixel's hit comes from the GPU (`ray` drawn with the beam: the
//! images are the same either way, `tests/march_beam.rs`), its tile's start
//! from the CPU twin of the beam pre-pass (`Replay::tile_beam`), the
//! highest top from the map. The march takes one column decode per sample
//! from its first sample to the flagged one (the hit's step, or the last
//! sample of a miss): before, from sample 1 (plus the near point); with the
//! beam, from the last sample at or before its tile's start, and a rising
//! ray's march ends above the highest top. Printed per view: the mean
//! samples a pixel, and the mean over 8x4-pixel blocks (a 32-lane warp) of
//! their most, which is what a SIMD machine pays. The refinement after the
//! flagged step is the same work in both and not counted.
//!
//! `voxel` (4,8,2/100) by a CPU twin of its traversal over the occupancy
//! pyramid: DDA iterations and column decodes (leaf samples and
//! bisections), before (from the near end at the pyramid's top, a decode
//! per point) and now (from the tile's start at its leaf, a decode per
//! texel the leaf's points visit in a row).

use anyhow::Context;
use glam::Vec3;
use strata_camera::Camera;
use strata_render::frame::{Globals, LevelShape};
use strata_render::methods::ray_exact::replay::{BEAM_TILE, Replay, camera_ray, compute_pyramid};
use strata_render::shadow::ShadowFrame;
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

const MAX_ALTITUDE: f32 = 255.0;

/// `clip_to_altitudes` of `ray_core.wgsl`.
fn clip(o: Vec3, d: Vec3, t0: f32, t1: f32) -> (f32, f32) {
    if d.z.abs() < 1e-9 {
        return if o.z > MAX_ALTITUDE {
            (1.0, 0.0)
        } else {
            (t0, t1)
        };
    }
    let ta = (0.0 - o.z) / d.z;
    let tb = (MAX_ALTITUDE - o.z) / d.z;
    (t0.max(ta.min(tb)), t1.min(ta.max(tb)))
}

/// Samples one pixel's march decodes: (before, with the beam).
fn samples(
    (o, d): (Vec3, Vec3),
    (t0, t1): (f32, f32),
    steps: u32,
    hit: Option<f32>,
    start: f32,
    top: f32,
) -> (u32, u32) {
    if t1 <= t0 {
        return (0, 0);
    }
    let n = steps;
    let dt = (t1 - t0) / n as f32;
    // The flagged sample: the hit's step, or the last one.
    let flagged = |last: u32| match hit {
        Some(t) => (((t - t0) / dt).ceil().max(0.0) as u32).clamp(0, n),
        None => last,
    };
    let before = 1 + flagged(n);
    let mut last = n;
    if d.z > 0.0 && top < MAX_ALTITUDE {
        let t_top = (top + 1.0 - o.z) / d.z;
        last = ((((t_top - t0) / dt).floor()).clamp(0.0, n as f32) as u32 + 1).min(n);
    }
    let mut first = 0;
    if start > t0 {
        first = (((start - t0) / dt).floor()).min(n as f32) as u32;
        if first > 0 && t0 + dt * first as f32 > start {
            first -= 1;
        }
    }
    let end = flagged(last).min(last);
    let after = if first == 0 {
        1 + end
    } else {
        (end + 1).saturating_sub(first)
    };
    (before, after)
}

/// The voxel traversal's work for one ray: DDA iterations and column
/// decodes (leaf samples, bisections), a twin of `voxel_core.wgsl`'s
/// `voxel_march_from` (f32 as there; for counting) as it sampled a leaf
/// before the exact texel walk replaced the points (`voxel_leaf`): the
/// record of `bench/issue36-frag/`'s counts; with `cached` false, of the
/// leaf sampling before its column cache.
struct VoxelTwin<'a> {
    level: &'a strata_level::Level,
    pyramid: &'a strata_occupancy::Pyramid,
    steps: u32,
    /// One decode per texel the leaf's points visit in a row (the GPU's
    /// `voxel_leaf` since the cache), else one per point (before).
    cached: bool,
}

impl VoxelTwin<'_> {
    fn occupied(&self, lod: usize, c: [i32; 3]) -> bool {
        let info = &self.pyramid.layout.levels[lod];
        if c[2] < 0 {
            return true;
        }
        if c[2] as u32 >= info.dims[2] {
            return false;
        }
        let x = (c[0] as u32) & (info.dims[0] - 1);
        let y = (c[1] as u32) & (info.dims[1] - 1);
        self.pyramid.occupied(lod, x, y, c[2] as u32)
    }

    fn solid(&self, p: Vec3) -> bool {
        let c = self.level.column(p.x.floor() as i64, p.y.floor() as i64);
        let z = p.z;
        z <= f32::from(c.low) || (c.dual && f32::from(c.mid) <= z && z <= f32::from(c.high))
    }

    fn size(&self, lod: usize) -> Vec3 {
        let c = self.pyramid.layout.levels[lod].cell;
        Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)
    }

    /// (iterations, decodes).
    fn count(&self, o: Vec3, d: Vec3, (t0, t1): (f32, f32), start: f32) -> (u32, u32) {
        if t1 <= t0 || start >= t1 {
            return (0, 0);
        }
        let top = self.pyramid.layout.levels.len() - 1;
        let pos = [d.x > 0.0, d.y > 0.0, d.z > 0.0];
        let still = [d.x.abs() < 1e-12, d.y.abs() < 1e-12, d.z.abs() < 1e-12];
        let inv = Vec3::new(
            if still[0] { 3e38 } else { 1.0 / d.x },
            if still[1] { 3e38 } else { 1.0 / d.y },
            if still[2] { 3e38 } else { 1.0 / d.z },
        );
        let mut t = t0;
        if start > t0 {
            let s0 = self.size(0);
            let leaf = ((o + d * start) / s0).floor();
            let mut tn = f32::MIN;
            for a in 0..3 {
                if !still[a] {
                    let near = (leaf[a] + if pos[a] { 0.0 } else { 1.0 }) * s0[a];
                    tn = tn.max((near - o[a]) * inv[a]);
                }
            }
            t = t0.max(start.min(tn));
        }
        let mut decodes = 0;
        if t == t0 {
            decodes += 1;
            if self.solid(o + d * t0) {
                return (0, decodes);
            }
        }
        let mut lod = if t > t0 { 0 } else { top };
        let mut size = self.size(lod);
        let f = ((o + d * t) / size).floor();
        let mut cell = [f.x as i32, f.y as i32, (f.z as i32).max(0)];
        let mut iterations = 0;
        for _ in 0..self.steps {
            if t > t1 {
                break;
            }
            iterations += 1;
            let occupied = self.occupied(lod, cell);
            if occupied && lod > 0 {
                lod -= 1;
                size = self.size(lod);
                let f = ((o + d * t) / size).floor();
                for a in 0..3 {
                    cell[a] = (f[a] as i32).clamp(cell[a] * 2, cell[a] * 2 + 1);
                }
                continue;
            }
            let mut te = [0f32; 3];
            for a in 0..3 {
                let far = (cell[a] as f32 + if pos[a] { 1.0 } else { 0.0 }) * size[a];
                te[a] = (far - o[a]) * inv[a];
            }
            let t_exit = te[0].min(te[1]).min(te[2]);
            if occupied {
                let (ta, tb) = (t, t_exit.min(t1));
                if tb > ta {
                    let len = (tb - ta) * d.length();
                    let n = ((len / 0.5).ceil() as u32).clamp(1, 32);
                    let dt = (tb - ta) / n as f32;
                    let mut last = (i64::MIN, i64::MIN);
                    let mut decode = |p: Vec3, decodes: &mut u32| {
                        let texel = (p.x.floor() as i64, p.y.floor() as i64);
                        if !self.cached || texel != last {
                            *decodes += 1;
                        }
                        last = texel;
                    };
                    let mut a = ta;
                    for i in 1..=n {
                        let t = ta + dt * i as f32;
                        let p = o + d * t;
                        decode(p, &mut decodes);
                        if self.solid(p) {
                            let mut b = t;
                            for _ in 0..5 {
                                let m = 0.5 * (a + b);
                                decode(o + d * m, &mut decodes);
                                if self.solid(o + d * m) {
                                    b = m;
                                } else {
                                    a = m;
                                }
                            }
                            return (iterations, decodes);
                        }
                        a = t;
                    }
                }
            }
            t = t.max(t_exit);
            let axis = if te[0] <= te[1] && te[0] <= te[2] {
                0
            } else if te[1] <= te[2] {
                1
            } else {
                2
            };
            let mut old = cell[axis];
            let mut new = old + if pos[axis] { 1 } else { -1 };
            cell[axis] = new;
            while lod < top && (new >> 1) != (old >> 1) {
                cell = [cell[0] >> 1, cell[1] >> 1, cell[2] >> 1];
                old >>= 1;
                new >>= 1;
                lod += 1;
            }
            size = self.size(lod);
        }
        (iterations, decodes)
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut size, mut steps) = ((1280u32, 800u32), 128u32);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--size" => {
                let s = args.next().context("--size WxH")?;
                let (w, h) = s.split_once('x').context("WxH")?;
                size = (w.parse()?, h.parse()?);
            }
            "--steps" => steps = args.next().context("--steps N")?.parse()?,
            other => anyhow::bail!("unknown argument {other}"),
        }
    }
    let (w, h) = size;
    let world = strata_level::generate::generate(&Default::default())?;
    let top = f32::from(world.level.heights().iter().copied().max().unwrap_or(0));
    let gpu = Gpu::headless()?;
    eprintln!(
        "adapter {} ({}); highest top {top}",
        gpu.report.name, gpu.report.backend
    );
    let settings = MethodSettings {
        shadows: false,
        ray_steps: steps,
        ..Default::default()
    };
    let [vx, vy, vz] = settings.voxel_size;
    let occupancy = strata_occupancy::Pyramid::build(
        &world.level,
        strata_occupancy::VoxelSize {
            x: vx,
            y: vy,
            z: vz,
        },
    )?;
    let before = VoxelTwin {
        level: &world.level,
        pyramid: &occupancy,
        steps: settings.voxel_steps,
        cached: false,
    };
    let now = VoxelTwin {
        cached: true,
        ..before
    };
    let colors = TerrainColors::from_world(&world);
    let mut r = Renderer::new(&gpu, &world.level, &colors, "ray", &settings, w, h)?;
    let pyramid = compute_pyramid(&world.level);
    let mut replay = Replay::new(&world.level, &pyramid);
    let shape = LevelShape::of(&world.level);
    // Per pixel: ray samples, voxel iterations, voxel decodes; each before
    // and with the beam.
    const COLUMNS: [&str; 6] = [
        "ray samples",
        "ray samples, beam",
        "voxel iterations",
        "voxel iterations, beam",
        "voxel decodes",
        "voxel decodes, beam + cache",
    ];
    println!(
        "Per pixel mean (a 32-lane warp's most, 8x4 pixels), {w}x{h}, ray:{steps}, voxel:{vx},{vy},{vz}/{}\n",
        settings.voxel_steps
    );
    println!("| view | pitch | {} |", COLUMNS.join(" | "));
    println!("|---|---:|{}", "---:|".repeat(COLUMNS.len()));
    let mut sums = [[0f64; 2]; 6];
    let mut exhausted = 0u64;
    for view in &world.views {
        let camera = Camera::from_view(&world.level, view, w, h)?;
        r.render_frame(&camera)?;
        let depth = r.read_depth()?;
        let g = Globals::new(&camera, &shape, &ShadowFrame::fit(&camera, false));
        let eye = Vec3::from_slice(&g.eye[..3]);
        let (focal, near, far) = (g.eye[3], g.forward[3], g.right[3]);
        let tiles_across = w.div_ceil(BEAM_TILE);
        let starts: Vec<f32> = (0..h.div_ceil(BEAM_TILE))
            .flat_map(|ty| (0..tiles_across).map(move |tx| (tx, ty)))
            .map(|(tx, ty)| replay.tile_beam(&g, tx, ty).t)
            .collect();
        let mut per_pixel = vec![[0u32; 6]; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let d = camera_ray(&g, x as f32 + 0.5, y as f32 + 0.5);
                let seg = clip(eye, d, near / focal, far / focal);
                let z = depth[(y * w + x) as usize];
                // Invert `view_z_to_depth`: depth 1 is the sky.
                let hit = (z < 1.0).then(|| near / (1.0 - z * (far - near) / far) / focal);
                let start = starts[((y / BEAM_TILE) * tiles_across + x / BEAM_TILE) as usize];
                let (a, b) = samples((eye, d), seg, steps, hit, start, top);
                let (vi0, vd0) = before.count(eye, d, seg, seg.0);
                let (vi1, vd1) = now.count(eye, d, seg, start);
                per_pixel[(y * w + x) as usize] = [a, b, vi0, vi1, vd0, vd1];
                // Rays whose old traversal spent its whole budget: where the
                // beam may let them go further (a different image).
                exhausted += u64::from(vi0 >= settings.voxel_steps);
            }
        }
        let n = per_pixel.len() as f64;
        let mut cells = Vec::new();
        for (k, sum) in sums.iter_mut().enumerate() {
            let mean = per_pixel.iter().map(|p| f64::from(p[k])).sum::<f64>() / n;
            let (mut most, mut warps) = (0.0, 0.0);
            for by in (0..h).step_by(4) {
                for bx in (0..w).step_by(8) {
                    most += f64::from(
                        (by..(by + 4).min(h))
                            .flat_map(|y| (bx..(bx + 8).min(w)).map(move |x| (x, y)))
                            .map(|(x, y)| per_pixel[(y * w + x) as usize][k])
                            .max()
                            .unwrap_or(0),
                    );
                    warps += 1.0;
                }
            }
            let warp = most / warps;
            sum[0] += mean;
            sum[1] += warp;
            cells.push(format!("{mean:.1} ({warp:.1})"));
        }
        println!("| {} | {} | {} |", view.name, view.pitch, cells.join(" | "));
    }
    let k = world.views.len() as f64;
    let means: Vec<String> = sums
        .iter()
        .map(|s| format!("{:.1} ({:.1})", s[0] / k, s[1] / k))
        .collect();
    println!("| **mean** | | {} |", means.join(" | "));
    println!(
        "\nvoxel rays that spent the whole budget of {} steps before the beam (over all views): {exhausted}",
        settings.voxel_steps
    );
    Ok(())
}
