//! GPU tests of `ray-exact`: the GPU pyramid against `strata_maxmip` (bit
//! for bit, before and after an edit), the march's rays against the CPU
//! reference's `Tracer::trace` (grazing a slab's underside, along tile
//! boundaries, across the wrap edge, from inside a cave, straight up under a
//! slab, and random), every generated view against the reference image, and
//! the first frame after the crater against a fresh build. Small images:
//! lavapipe is slow.

use super::bindings::{buffer_entry, core_bindings};
use super::pyramid::GpuMaxMip;
use super::*;
use crate::frame::{Shared, TerrainColors};
use crate::{MethodSettings, Renderer};
use glam::Vec3;
use strata_camera::Camera;
use strata_level::generate::{GenerateParams, generate};
use strata_level::{DirtyRect, Level, World};
use strata_reference::metrics::distance_from_depth;
use strata_reference::{HitClass, ReferenceSettings, Tracer, metrics, render_reference};

use super::super::test_common as common;

fn world(width: u32, height: u32, seed: u64) -> World {
    generate(&GenerateParams {
        seed,
        width,
        height,
    })
    .expect("generated world")
}

/// A map too small to generate (its coarse levels are narrower than a word).
fn tiny(w: u32, h: u32) -> World {
    let mut world = world(256, 256, 1);
    let n = (w * h) as usize;
    let heights = (0..n).map(|i| (i * 37 % 200) as u8).collect();
    world.level =
        Level::from_planes(w, h, heights, vec![0; n], strata_level::MidRule::Original).unwrap();
    world
}

fn dig(world: &World, level: &mut Level) -> Vec<DirtyRect> {
    let site = world.edit.clone().expect("an edit site");
    strata_level::edit::crater(level, &site)
}

fn shared_for(gpu: &crate::Gpu, level: &Level) -> Shared {
    shared_sized(gpu, level, (8, 8))
}

/// A shared frame of `level` with targets of `width` x `height`.
fn shared_sized(gpu: &crate::Gpu, level: &Level, (width, height): (u32, u32)) -> Shared {
    Shared::new(
        &gpu.device,
        &gpu.queue,
        &gpu.caps,
        level,
        &TerrainColors::test_ramps(),
        width,
        height,
    )
    .unwrap()
}

/// One ray for both tracers: f32 as the GPU takes it.
#[derive(Clone, Copy, Debug)]
struct TestRay {
    name: &'static str,
    origin: Vec3,
    dir: Vec3,
    t_max: f32,
}

/// Trace `rays` on the GPU with `ray_exact_test.wgsl`: (distance or -1, class, column).
fn gpu_trace(gpu: &crate::Gpu, level: &Level, rays: &[TestRay]) -> Vec<[f32; 4]> {
    let shared = shared_for(gpu, level);
    let device = &shared.device;
    // `ray_exact_test.wgsl` keeps the default constants: every level.
    let pyramid = GpuMaxMip::new(&shared, level, 1, true).unwrap();
    let params = shared.uniform_buffer(
        "test params",
        bytemuck::bytes_of(&exact_params(&pyramid.layout)),
    );
    let pyramid = Levels::Whole(Box::new(pyramid));
    let stats = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let data: Vec<[f32; 8]> = rays
        .iter()
        .map(|r| {
            [
                r.origin.x, r.origin.y, r.origin.z, r.t_max, r.dir.x, r.dir.y, r.dir.z, 0.0,
            ]
        })
        .collect();
    use wgpu::util::DeviceExt;
    let ray_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(&data),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let hits = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 16 * rays.len() as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let core_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &core_entries(wgpu::ShaderStages::COMPUTE, false),
    });
    let core_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &core_layout,
        entries: &core_bindings(&params, &pyramid, &stats),
    });
    let io_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[
            buffer_entry(
                0,
                wgpu::ShaderStages::COMPUTE,
                wgpu::BufferBindingType::Storage { read_only: true },
            ),
            buffer_entry(
                1,
                wgpu::ShaderStages::COMPUTE,
                wgpu::BufferBindingType::Storage { read_only: false },
            ),
        ],
    });
    let io_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &io_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: ray_buf.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: hits.as_entire_binding(),
            },
        ],
    });
    let frame_group = super::super::voxel::pyramid::build_frame_group(&shared, level).unwrap();
    let pipeline = super::super::common::compute_pipeline(
        &shared,
        "ray-exact test",
        "ray_exact_test.wgsl",
        &shared.pipeline_layout("ray-exact test", &[&core_layout, &io_layout]),
        "cs_trace",
    )
    .unwrap();
    let mut encoder = device.create_command_encoder(&Default::default());
    {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &frame_group, &[]);
        pass.set_bind_group(1, &core_group, &[]);
        pass.set_bind_group(2, &io_group, &[]);
        pass.dispatch_workgroups((rays.len() as u32).div_ceil(64), 1, 1);
    }
    shared.queue.submit([encoder.finish()]);
    let words = read_words(device, &shared.queue, &hits, "hits").unwrap();
    gpu.errors.check().unwrap();
    bytemuck::cast_slice::<u32, [f32; 4]>(&words).to_vec()
}

/// A small deterministic generator.
struct Lcg(u64);
impl Lcg {
    fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The rays the issue names, on `level`, plus random ones.
fn special_rays(level: &Level) -> Vec<TestRay> {
    let (w, h) = (level.width() as i64, level.height() as i64);
    let mut rays = Vec::new();
    let ray = |name, origin: Vec3, dir: Vec3| TestRay {
        name,
        origin,
        dir: dir.normalize(),
        t_max: 700.0,
    };
    // Caves: dual columns with room under the slab.
    let mut caves = Vec::new();
    for y in (0..h).step_by(7) {
        for x in (0..w).step_by(5) {
            let c = level.column(x, y);
            if c.dual && i32::from(c.mid) - i32::from(c.low) >= 6 {
                caves.push((x, y, c));
            }
        }
    }
    assert!(
        caves.len() >= 20,
        "the test world has too few caves: {}",
        caves.len()
    );
    for &(x, y, c) in caves.iter().step_by((caves.len() / 40).max(1)) {
        let (low, mid) = (f32::from(c.low), f32::from(c.mid));
        let centre = Vec3::new(x as f32 + 0.5, y as f32 + 0.5, low + 1.0);
        rays.push(ray("straight up under a slab", centre, Vec3::Z));
        for k in 0..8 {
            let a = k as f32 * std::f32::consts::FRAC_PI_4 + 0.1;
            let flat = Vec3::new(a.cos(), a.sin(), 0.0);
            let inside = Vec3::new(centre.x, centre.y, 0.5 * (low + mid));
            rays.push(ray("from inside a cave", inside, flat + Vec3::Z * 0.05));
            rays.push(ray(
                "from inside a cave, down",
                inside,
                flat - Vec3::Z * 0.2,
            ));
            // Just under the slab's underside, rising by a hair.
            let graze = Vec3::new(centre.x, centre.y, mid - 0.01);
            rays.push(ray(
                "grazing a slab's underside",
                graze,
                flat + Vec3::Z * 0.001,
            ));
            rays.push(ray("level with a slab's underside", graze, flat));
        }
    }
    // Along tile boundaries (every level's: multiples of 256), axis-aligned and
    // through tile corners, low over the ground.
    for k in 0..12i64 {
        let bx = (k * 256) % w;
        let by = (k * 256 + 512) % h;
        let z = f32::from(level.column(bx, by).top()) + 2.0;
        let o = Vec3::new(bx as f32, by as f32 + 0.5, z);
        rays.push(ray(
            "along a tile boundary (y)",
            o,
            Vec3::new(0.0, 1.0, -0.02),
        ));
        rays.push(ray(
            "along a tile boundary (-y)",
            o,
            Vec3::new(0.0, -1.0, -0.01),
        ));
        let o = Vec3::new(bx as f32 + 0.5, by as f32, z);
        rays.push(ray(
            "along a tile boundary (x)",
            o,
            Vec3::new(1.0, 0.0, -0.02),
        ));
        let o = Vec3::new(bx as f32, by as f32, z + 10.0);
        rays.push(ray("through tile corners", o, Vec3::new(1.0, 1.0, -0.05)));
        rays.push(ray(
            "through tile corners (-)",
            o,
            Vec3::new(-1.0, -1.0, -0.03),
        ));
    }
    // Across the wrap edge, both axes and both ways.
    for k in 0..16 {
        let y = (k * 61 % h) as f32 + 0.3;
        let x = (k * 37 % w) as f32 + 0.7;
        let zx = f32::from(level.column(w - 1, y as i64).top()) + 3.0;
        rays.push(ray(
            "across the wrap edge (+x)",
            Vec3::new(w as f32 - 2.5, y, zx),
            Vec3::new(1.0, 0.1, -0.03),
        ));
        rays.push(ray(
            "across the wrap edge (-x)",
            Vec3::new(1.5, y, zx + 5.0),
            Vec3::new(-1.0, 0.2, -0.04),
        ));
        let zy = f32::from(level.column(x as i64, 0).top()) + 3.0;
        rays.push(ray(
            "across the wrap edge (-y)",
            Vec3::new(x, 0.5, zy),
            Vec3::new(0.05, -1.0, -0.03),
        ));
        rays.push(ray(
            "across the wrap edge (+y)",
            Vec3::new(x, h as f32 - 0.5, zy + 4.0),
            Vec3::new(-0.3, 1.0, -0.05),
        ));
    }
    // Random: above the ground, any direction.
    let mut rng = Lcg(99);
    for _ in 0..4000 {
        let x = rng.unit() * w as f32;
        let y = rng.unit() * h as f32;
        let top = f32::from(level.column(x.floor() as i64, y.floor() as i64).top());
        let z = (top + 0.5 + rng.unit() * 80.0).min(300.0);
        let a = rng.unit() * std::f32::consts::TAU;
        let dz = rng.unit() * 1.6 - 1.0;
        rays.push(ray(
            "random",
            Vec3::new(x, y, z),
            Vec3::new(a.cos(), a.sin(), dz),
        ));
    }
    rays
}

#[test]
fn rays_agree_with_the_reference() {
    for gpu in common::gpus() {
        let world = world(512, 1024, 11);
        let level = &world.level;
        let rays = special_rays(level);
        let got = gpu_trace(&gpu, level, &rays);
        let tracer = Tracer::new(level);
        let mut failures = Vec::new();
        let mut kinds = std::collections::BTreeMap::<&str, (usize, usize)>::new();
        for (ray, g) in rays.iter().zip(&got) {
            let want = tracer.trace(
                ray.origin.as_dvec3(),
                ray.dir.as_dvec3() / ray.dir.as_dvec3().length(),
                f64::from(ray.t_max),
                &ReferenceSettings::default(),
            );
            let entry = kinds.entry(ray.name).or_default();
            entry.0 += 1;
            let ok = match want {
                None => g[0] < 0.0,
                Some(hit) => {
                    g[0] >= 0.0
                        && (f64::from(g[0]) - hit.distance).abs() <= 1e-3 * hit.distance.max(1.0)
                        && (g[1] as u8 == hit.class.code()
                            // A hit exactly on a column's edge may be a wall
                            // or a top by a rounding: the same point.
                            || (f64::from(g[0]) - hit.distance).abs() <= 1e-4
                                && [HitClass::Wall.code(), HitClass::Floor.code(), HitClass::SlabTop.code()]
                                    .contains(&(g[1] as u8))
                                && [HitClass::Wall, HitClass::Floor, HitClass::SlabTop].contains(&hit.class))
                }
            };
            if ok {
                entry.1 += 1;
            } else if failures.len() < 20 {
                failures.push(format!("{ray:?}: GPU {g:?}, reference {want:?}"));
            }
        }
        for (name, (n, ok)) in &kinds {
            eprintln!("{name:32} {ok}/{n} agree");
        }
        let hits = got.iter().filter(|g| g[0] >= 0.0).count();
        eprintln!("{hits} of {} rays hit", rays.len());
        assert!(
            failures.is_empty(),
            "disagreements:\n{}",
            failures.join("\n")
        );
    }
}

const W: u32 = 160;
const H: u32 = 100;

#[test]
fn every_generated_view_matches_the_reference() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let colors = TerrainColors::from_world(&w);
        let mut failures = Vec::new();
        for method in ["ray-exact", "ray-exact-fragment"] {
            let mut r = Renderer::new(
                &gpu,
                &w.level,
                &colors,
                method,
                &MethodSettings::default(),
                W,
                H,
            )
            .unwrap();
            for view in &w.views {
                let camera = Camera::from_view(&w.level, view, W, H).unwrap();
                let reference = render_reference(&w.level, &camera);
                r.render_frame(&camera).unwrap();
                let distance = distance_from_depth(&camera, &r.read_depth().unwrap());
                let m = metrics::compare(&reference, &distance);
                eprintln!(
                    "{method:18} {:11} pitch {:4}: {}",
                    view.name,
                    view.pitch,
                    common::metrics_line(&m)
                );
                if m.see_through > 0.05 || m.covers_sky > 0.05 || m.depth_p95 > 0.05 {
                    failures.push(format!("{method} {}: {m:?}", view.name));
                }
            }
        }
        assert!(
            failures.is_empty(),
            "over the limits:\n{}",
            failures.join("\n")
        );
    }
}

#[test]
fn first_frame_after_the_crater_matches_a_fresh_build() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let colors = TerrainColors::from_world(&w);
        let settings = MethodSettings::default();
        let site = w.edit.clone().unwrap();
        let mut level = w.level.clone();
        let camera = Camera::from_view(&level, &site.camera, W, H).unwrap();
        let mut r = Renderer::new(&gpu, &level, &colors, "ray-exact", &settings, W, H).unwrap();
        r.render_frame(&camera).unwrap();
        let before = r.read_depth().unwrap();
        let rects = dig(&w, &mut level);
        r.apply_edit(&level, &rects).unwrap();
        r.render_frame(&camera).unwrap();
        let edited = r.read_depth().unwrap();
        let edited_color = r.read_color().unwrap();
        let mut fresh = Renderer::new(&gpu, &level, &colors, "ray-exact", &settings, W, H).unwrap();
        fresh.render_frame(&camera).unwrap();
        assert!(
            edited == fresh.read_depth().unwrap(),
            "depth differs from a fresh build"
        );
        assert!(
            edited_color == fresh.read_color().unwrap(),
            "colour (shadows included) differs from a fresh build"
        );
        let changed = before
            .iter()
            .zip(&edited)
            .filter(|(a, b)| (*a - *b).abs() > 1e-4)
            .count();
        eprintln!(
            "pixels changed by the crater: {changed} of {}",
            before.len()
        );
        assert!(
            changed > 100,
            "the crater left (almost) no trace: {changed}"
        );
    }
}

/// The camera of `view` at `size` and its frame's globals, shadows on.
fn view_globals(
    level: &Level,
    view: &strata_level::ViewSpec,
    (width, height): (u32, u32),
) -> (Camera, crate::frame::Globals) {
    let camera = Camera::from_view(level, view, width, height).unwrap();
    let shadow = crate::shadow::ShadowFrame::fit(&camera, true);
    let globals =
        crate::frame::Globals::new(&camera, &crate::frame::LevelShape::of(level), &shadow);
    (camera, globals)
}

/// One frame of `m` recorded by hand (the renderer owns its methods): the
/// globals written, the exact shadow map cast, the march.
fn record_frame(
    shared: &Shared,
    m: &mut RayExact,
    camera: &Camera,
    globals: &crate::frame::Globals,
    timer: &crate::timing::PassTimer,
    index: usize,
) {
    shared
        .queue
        .write_buffer(&shared.globals, 0, bytemuck::bytes_of(globals));
    m.prepare(shared, camera).unwrap();
    let frame = super::super::Frame {
        camera,
        timer,
        index: index as u64,
        depth_attachment: true,
        targets: Default::default(),
    };
    let mut encoder = shared.device.create_command_encoder(&Default::default());
    assert!(m.record_shadow_map(shared, &frame, &mut encoder));
    m.record(shared, &frame, &mut encoder);
    shared.queue.submit([encoder.finish()]);
}

#[test]
fn hits_fit_webgpu_default_limits_up_to_16_7_million_pixels() {
    let limits = wgpu::Limits::default();
    // 128 MiB binding, 8 bytes a pixel.
    assert!(deferred::hits_fit_in(4096, 4096, &limits));
    assert!(deferred::hits_fit_in(5120, 2880, &limits));
    assert!(!deferred::hits_fit_in(4097, 4096, &limits));
    assert!(!deferred::hits_fit_in(7680, 4320, &limits));
}

#[test]
fn a_frame_whose_hits_do_not_fit_takes_the_one_pass_route_to_the_same_picture() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let colors = TerrainColors::from_world(&w);
        let settings = MethodSettings::default();
        let mut r = Renderer::new(&gpu, &w.level, &colors, "ray-exact", &settings, W, H).unwrap();
        let mut pictures = Vec::new();
        for fits in [true, false] {
            let mut m = build(&r.shared_handle(), &w.level, ExactOptions::DEFAULT).unwrap();
            assert!(m.defers());
            if let Variant::Compute {
                deferred: Some(d), ..
            } = &mut m.variant
            {
                // As `resize` finds a frame past the device's binding.
                d.fits = fits;
            }
            assert_eq!(m.defers(), fits);
            assert_eq!(m.shadow_map_is_partial(), fits);
            r.insert_method(Box::new(m), settings.clone());
            let mut per_view = Vec::new();
            for view in w.views.iter().take(4) {
                let camera = Camera::from_view(&w.level, view, W, H).unwrap();
                r.render_frame(&camera).unwrap();
                per_view.push((r.read_depth().unwrap(), r.read_color().unwrap()));
            }
            pictures.push(per_view);
        }
        for (v, (a, b)) in pictures[0].iter().zip(&pictures[1]).enumerate() {
            assert!(
                a.0 == b.0 && a.1 == b.1,
                "view {v}: the one-pass route changed the picture"
            );
        }
        gpu.errors.check().unwrap();
    }
}

#[test]
fn depth_and_shadow_variants_agree_and_the_cap_is_never_hit() {
    for gpu in common::gpus() {
        let w = common::generated_world();
        let colors = TerrainColors::from_world(&w);
        let settings = MethodSettings::default();
        let mut r = Renderer::new(&gpu, &w.level, &colors, "ray-exact", &settings, W, H).unwrap();
        let d = ExactOptions::DEFAULT;
        let variants = [
            ExactOptions {
                depth: DepthMode::Points,
                ..d
            },
            d,
            ExactOptions {
                exact_shadow: false,
                ..d
            },
            ExactOptions { climb: 8, ..d },
            ExactOptions { log_ratio: 2, ..d },
            ExactOptions {
                depth: DepthMode::Blit,
                ..d
            },
            ExactOptions { beam: false, ..d },
            ExactOptions {
                beam: false,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                beam_search: BeamSearch::Serial,
                ..d
            },
            ExactOptions {
                beam_search: BeamSearch::Serial,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                beam_search: BeamSearch::WidePass,
                ..d
            },
            ExactOptions {
                beam_search: BeamSearch::WidePass,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                shadow_rounds: 1,
                ..d
            },
            ExactOptions {
                fused_descent: true,
                ..d
            },
            ExactOptions {
                fused_descent: true,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                cave_skip: false,
                ..d
            },
            ExactOptions {
                beam_texels: false,
                ..d
            },
            ExactOptions {
                cave_skip: false,
                beam_texels: false,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                texel_walk: TexelWalk::Plane,
                ..d
            },
            ExactOptions {
                texel_walk: TexelWalk::Plane,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                texel_walk: TexelWalk::PlaneBeside,
                ..d
            },
            ExactOptions {
                texel_walk: TexelWalk::PlaneBeside,
                exact_shadow: false,
                ..d
            },
            ExactOptions {
                shadow_keep: false,
                ..d
            },
            ExactOptions {
                shade_fetch_chain: true,
                ..d
            },
            ExactOptions {
                shade_fetch_chain: true,
                exact_shadow: false,
                ..d
            },
        ];
        assert_eq!(d.beam_search, BeamSearch::Wide);
        assert!(
            !d.fused_descent && d.cave_skip && d.beam_texels && d.texel_walk == TexelWalk::Terrain
        );
        let mut images = Vec::new();
        for options in variants {
            let m = build(&r.shared_handle(), &w.level, options).unwrap();
            r.insert_method(Box::new(m), settings.clone());
            let mut per_view = Vec::new();
            for view in &w.views {
                let camera = Camera::from_view(&w.level, view, W, H).unwrap();
                r.render_frame(&camera).unwrap();
                per_view.push((r.read_depth().unwrap(), r.read_color().unwrap()));
            }
            images.push(per_view);
        }
        // Points and the blit write the same depth.
        for (v, (a, b)) in images[0].iter().zip(&images[1]).enumerate() {
            assert!(
                a.0 == b.0,
                "view {v}: depth by points differs from the blit"
            );
            assert!(a.1 == b.1, "view {v}: colour differs");
        }
        // Climbing as far as a step allows, visiting every other level,
        // loading depth instead of clearing it, or starting every ray at the
        // near plane instead of its tile's beam, or searching the beam
        // serially or wide in the march instead of wide in a pre-pass, or
        // a descent into the texels fused with the texel's test, or no tile
        // skipped between floors and slabs, or the beams' finest test on
        // 4-texel tiles, or a 4x4 tile's texels walked from the texel
        // plane, or keeping no shadow block from earlier frames, or the
        // shading's fetches chained, changes nothing but the work.
        for other in [3, 4, 5, 6, 8, 10, 12, 13, 15, 16, 18, 20, 22, 23] {
            for (v, (a, b)) in images[1].iter().zip(&images[other]).enumerate() {
                assert!(
                    a.0 == b.0 && a.1 == b.1,
                    "view {v}: variant {other} changed the image"
                );
            }
        }
        // The one-pass frame (the renderer's shadow map) with the wide
        // beam in a pre-pass, without a beam, with the serial one and with
        // the wide one in the march, with the fused descent, and without
        // the cave skip and the beams' texel test, and with the texel
        // plane, and with the shading's fetches chained: the same image.
        for other in [7, 9, 11, 14, 17, 19, 21, 24] {
            for (v, (a, b)) in images[2].iter().zip(&images[other]).enumerate() {
                assert!(
                    a.0 == b.0 && a.1 == b.1,
                    "view {v}: variant {other} changed the one-pass frame's image"
                );
            }
        }
        // The exact shadow map and the 128-step one shade nearly alike.
        for (v, (a, b)) in images[1].iter().zip(&images[2]).enumerate() {
            assert!(a.0 == b.0, "view {v}: the shadow map changed depth");
            if let Some(dir) = common::test_out_dir() {
                let dir = dir.as_path();
                std::fs::create_dir_all(dir).unwrap();
                let exact = dir.join(format!("exact-shadow-{v}.png"));
                crate::report::write_png(&exact, W, H, &a.1).unwrap();
                let marched = dir.join(format!("marched-shadow-{v}.png"));
                crate::report::write_png(&marched, W, H, &b.1).unwrap();
            }
            let differ =
                a.1.chunks(4)
                    .zip(b.1.chunks(4))
                    .filter(|(x, y)| x != y)
                    .count();
            let pct = 100.0 * differ as f64 / (W * H) as f64;
            eprintln!(
                "view {v}: exact vs marched shadow map: {pct:.2} % of pixels differ in colour"
            );
            // Shadow edges on terraces move by the 128-step march's error (seen: up to
            // 10.4 % of pixels on a -90° view of terraces, 0 on others).
            assert!(pct < 15.0, "view {v}: {pct} % of pixels differ");
        }
        // Statistics of a fresh method over every view, frames recorded by
        // hand (the renderer owns its methods): the cap is never hit.
        let shared = r.shared_handle();
        let counting = ExactOptions {
            iteration_stats: true,
            ..d
        };
        let mut m = build(&shared, &w.level, counting).unwrap();
        assert_eq!(m.stats().unwrap(), ExactStats::default());
        let timer = crate::timing::PassTimer::new(&shared.device, &shared.queue, false);
        for (index, view) in w.views.iter().enumerate() {
            let (camera, globals) = view_globals(&w.level, view, (W, H));
            record_frame(&shared, &mut m, &camera, &globals, &timer, index);
        }
        let stats = m.stats().unwrap();
        eprintln!("over every view: {stats:?}");
        assert_eq!((stats.cap_hits, stats.shadow_cap_hits), (0, 0));
        assert!(
            stats.most_iterations > 8 && stats.shadow_most_iterations > 8,
            "{stats:?}"
        );
        assert!(
            stats.most_iterations < ITERATION_CAP && stats.shadow_most_iterations < ITERATION_CAP
        );
        m.reset_stats();
        assert_eq!(m.stats().unwrap(), ExactStats::default());
        // The default keeps no most-iterations statistic (and caps no ray).
        let mut plain = build(&shared, &w.level, d).unwrap();
        let (camera, globals) = view_globals(&w.level, &w.views[0], (W, H));
        record_frame(&shared, &mut plain, &camera, &globals, &timer, 0);
        assert_eq!(plain.stats().unwrap(), ExactStats::default());
        gpu.errors.check().unwrap();
    }
}

mod keep;
mod pyramid;
mod replay;
