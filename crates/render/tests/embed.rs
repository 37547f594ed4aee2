//! Issue 18 (embedding): `Renderer::render_into` draws every method's frame
//! into the caller's own colour and depth views, of formats other than
//! Strata's, with the same picture and depth as Strata's own targets; and
//! refuses targets it cannot draw into with an error naming what is wrong.

mod common;

use strata_camera::Camera;
use strata_render::depth_read::DepthReader;
use strata_render::{Gpu, MethodSettings, Renderer, TargetError, TargetViews, TerrainColors};

const W: u32 = 96;
const H: u32 = 64;

fn target(
    gpu: &Gpu,
    format: wgpu::TextureFormat,
    (width, height): (u32, u32),
    samples: u32,
    usage: wgpu::TextureUsages,
) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("caller target"),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: samples,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    (texture, view)
}

fn scene() -> (strata_level::Level, Camera) {
    let level = common::synthetic_level();
    let view = common::synthetic_views()
        .into_iter()
        .find(|v| v.name == "bridge60")
        .unwrap();
    let camera = Camera::from_view(&level, &view, W, H).unwrap();
    (level, camera)
}

const USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::TEXTURE_BINDING);

#[test]
fn every_method_draws_into_bgra_srgb_and_depth24plus_as_into_its_own_targets() {
    let Some(gpu) = common::gpu() else { return };
    let (level, camera) = scene();
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let colors = TerrainColors::test_ramps();
    // Depth24Plus has no copies: read it through the pass-based reader.
    let mut caps = gpu.caps.clone();
    caps.depth_copies = false;
    let reader = DepthReader::new(&gpu.device, &caps).unwrap().unwrap();
    let (color_tex, color_view) =
        target(&gpu, wgpu::TextureFormat::Bgra8UnormSrgb, (W, H), 1, USAGE);
    let (depth_tex, depth_view) = target(&gpu, wgpu::TextureFormat::Depth24Plus, (W, H), 1, USAGE);
    let mut tested = 0;
    for name in strata_render::methods::names() {
        let mut r = match Renderer::new(&gpu, &level, &colors, name, &settings, W, H) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name}: not on this adapter ({e:#})");
                continue;
            }
        };
        r.render_frame(&camera).unwrap();
        let own_color = r.read_color().unwrap();
        let own_depth = r.read_depth().unwrap();
        r.render_into(&camera, &TargetViews::new(&color_view, &depth_view))
            .unwrap();
        gpu.wait().unwrap();
        let bgra = strata_render::gpu::read_texture(
            &gpu.device,
            &gpu.queue,
            &gpu.errors,
            &color_tex,
            wgpu::TextureAspect::All,
        )
        .unwrap();
        let depth = reader
            .read(&gpu.device, &gpu.queue, &gpu.errors, &depth_tex)
            .unwrap();
        let mut worst_color = 0u8;
        for (own, theirs) in own_color.chunks_exact(4).zip(bgra.chunks_exact(4)) {
            for (a, b) in [
                (own[0], theirs[2]),
                (own[1], theirs[1]),
                (own[2], theirs[0]),
            ] {
                worst_color = worst_color.max(a.abs_diff(b));
            }
        }
        let mut worst_depth = 0f32;
        let mut terrain = 0;
        for (a, b) in own_depth.iter().zip(&depth) {
            worst_depth = worst_depth.max((a - b).abs());
            terrain += usize::from(*a < 1.0);
        }
        println!(
            "{name}: Bgra8UnormSrgb worst channel difference {worst_color}, Depth24Plus worst \
             depth difference {worst_depth:.2e} ({terrain} terrain pixels)"
        );
        // The sRGB decode + encode round trip may move a byte by one.
        assert!(worst_color <= 1, "{name}: colour differs by {worst_color}");
        // 24-bit depth: steps of 2^-24.
        assert!(
            worst_depth <= 2e-7,
            "{name}: depth differs by {worst_depth}"
        );
        assert!(
            terrain > (W * H / 4) as usize,
            "{name}: only {terrain} terrain pixels"
        );
        let shades: std::collections::HashSet<&[u8]> = own_color.chunks_exact(4).collect();
        assert!(
            shades.len() >= 3,
            "{name}: a flat picture ({} colours)",
            shades.len()
        );
        let depths: std::collections::HashSet<u32> =
            own_depth.iter().map(|d| d.to_bits()).collect();
        assert!(
            depths.len() > 100,
            "{name}: {} distinct depths",
            depths.len()
        );
        tested += 1;
    }
    assert!(tested >= 2, "{tested} methods ran");
}

/// The error `render_into` gave, as a `TargetError`.
fn refusal(r: &mut Renderer, camera: &Camera, targets: TargetViews<'_>) -> TargetError {
    let e = r
        .render_into(camera, &targets)
        .expect_err("bad targets must be refused");
    println!("refused: {e:#}");
    e.downcast_ref::<TargetError>()
        .unwrap_or_else(|| panic!("not a TargetError: {e:#}"))
        .clone()
}

#[test]
fn bad_targets_get_named_errors() {
    use wgpu::TextureFormat as F;
    let Some(gpu) = common::gpu() else { return };
    let (level, camera) = scene();
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let mut r = Renderer::new(
        &gpu,
        &level,
        &TerrainColors::test_ramps(),
        "ray",
        &settings,
        W,
        H,
    )
    .unwrap();
    let (_, color) = target(&gpu, F::Rgba8Unorm, (W, H), 1, USAGE);
    let (_, depth) = target(&gpu, F::Depth32Float, (W, H), 1, USAGE);

    let (_, unsupported) = target(&gpu, F::R8Unorm, (W, H), 1, USAGE);
    let e = refusal(&mut r, &camera, TargetViews::new(&unsupported, &depth));
    assert_eq!(e, TargetError::ColorFormat(F::R8Unorm));
    assert!(e.to_string().contains("R8Unorm"), "{e}");

    let (_, stencil) = target(&gpu, F::Stencil8, (W, H), 1, USAGE);
    let e = refusal(&mut r, &camera, TargetViews::new(&color, &stencil));
    assert_eq!(e, TargetError::DepthFormat(F::Stencil8));
    assert!(e.to_string().contains("Stencil8"), "{e}");

    let (_, small) = target(&gpu, F::Depth32Float, (W / 2, H), 1, USAGE);
    let e = refusal(&mut r, &camera, TargetViews::new(&color, &small));
    assert!(
        e.to_string().contains("48x64") && e.to_string().contains("96x64"),
        "{e}"
    );

    let (_, msaa_color) = target(
        &gpu,
        F::Rgba8Unorm,
        (W, H),
        4,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    let e = refusal(&mut r, &camera, TargetViews::new(&msaa_color, &depth));
    assert_eq!(e, TargetError::SampleCount { color: 4, depth: 1 });

    let (_, unrenderable) = target(
        &gpu,
        F::Rgba8Unorm,
        (W, H),
        1,
        wgpu::TextureUsages::COPY_SRC,
    );
    let e = refusal(&mut r, &camera, TargetViews::new(&unrenderable, &depth));
    assert!(
        matches!(
            e,
            TargetError::Usage {
                target: "colour",
                ..
            }
        ),
        "{e}"
    );

    // A view of another device (of the same adapter).
    let (other, _) = pollster::block_on(gpu.adapter.request_device(&Default::default())).unwrap();
    let foreign = other
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("other device's colour"),
            size: wgpu::Extent3d {
                width: W,
                height: H,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: F::Rgba8Unorm,
            usage: USAGE,
            view_formats: &[],
        })
        .create_view(&Default::default());
    let e = refusal(&mut r, &camera, TargetViews::new(&foreign, &depth));
    assert!(matches!(e, TargetError::OtherDevice(_)), "{e}");
    assert!(!e.to_string().contains('\n'), "one line: {e}");

    // After all that the renderer still draws, multisampled targets included.
    let (_, msaa_depth) = target(
        &gpu,
        F::Depth24PlusStencil8,
        (W, H),
        4,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
    );
    r.render_into(&camera, &TargetViews::new(&msaa_color, &msaa_depth))
        .unwrap();
    r.render_into(&camera, &TargetViews::new(&color, &depth))
        .unwrap();
    gpu.wait().unwrap();
}

/// Issue 35: targets that allow it take the frame by cheaper roads than the
/// full-screen pass (`composite_split`): colour by a compute dispatch into a
/// storage texture or by a copy, depth by a pass from a compute method's
/// depth image or by a copy. Every road stores what the pass stores, for
/// every method.
#[test]
fn every_road_stores_what_the_pass_stores() {
    // Every backend here: GL (llvmpipe) has no depth copies, so its roads differ.
    for gpu in common::gpus() {
        every_road_on(&gpu);
    }
}

fn every_road_on(gpu: &Gpu) {
    use strata_render::composite_split::{ColorRoute, CompositeRoute, DepthRoute};
    use wgpu::TextureFormat as F;
    use wgpu::TextureUsages as U;
    let (level, camera) = scene();
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let colors = TerrainColors::test_ramps();
    let reader = DepthReader::new(&gpu.device, &gpu.caps).unwrap();
    let read = |texture: &wgpu::Texture| -> Vec<u8> {
        let aspect = match texture.format().is_depth_stencil_format() {
            true => wgpu::TextureAspect::DepthOnly,
            false => wgpu::TextureAspect::All,
        };
        match (&reader, aspect) {
            (Some(reader), wgpu::TextureAspect::DepthOnly) => bytemuck::cast_slice(
                &reader
                    .read(&gpu.device, &gpu.queue, &gpu.errors, texture)
                    .unwrap(),
            )
            .to_vec(),
            _ => strata_render::gpu::read_texture(
                &gpu.device,
                &gpu.queue,
                &gpu.errors,
                texture,
                aspect,
            )
            .unwrap(),
        }
    };
    let copy_usage = USAGE | U::COPY_DST;
    let storage_usage = copy_usage | U::STORAGE_BINDING;
    let (mut tested, mut roads, mut directs) = (0, Vec::new(), Vec::new());
    for name in strata_render::methods::names() {
        let mut r = match Renderer::new(gpu, &level, &colors, name, &settings, W, H) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{name}: not on this adapter ({e:#})");
                continue;
            }
        };
        for color_format in [F::Rgba8Unorm, F::Rgba8UnormSrgb, F::Rgba16Float] {
            let mut images = Vec::new();
            for usage in [USAGE, copy_usage, storage_usage] {
                if usage == storage_usage && color_format == F::Rgba8UnormSrgb {
                    continue; // sRGB textures cannot be storage
                }
                let (color_tex, color_view) = target(gpu, color_format, (W, H), 1, usage);
                let depth_usage = usage - U::STORAGE_BINDING;
                let (depth_tex, depth_view) = target(gpu, F::Depth32Float, (W, H), 1, depth_usage);
                let targets = TargetViews::new(&color_view, &depth_view);
                r.render_into(&camera, &targets).unwrap();
                gpu.wait().unwrap();
                images.push((read(&color_tex), read(&depth_tex)));
                let taken = r.last_road().unwrap();
                if let CompositeRoute::Split { color, depth } = taken {
                    // Only Strata's own formats take the frame itself.
                    let direct_color = color == ColorRoute::Direct;
                    assert!(
                        !direct_color || color_format == F::Rgba8Unorm,
                        "{name} {taken}"
                    );
                    // Strata's targets missed what went straight to the
                    // caller's: no stale read.
                    if direct_color {
                        let refused = r.read_color().unwrap_err().to_string();
                        assert!(refused.contains("render_into"), "{refused}");
                    }
                    if depth == DepthRoute::Direct {
                        let refused = r.read_depth().unwrap_err().to_string();
                        assert!(refused.contains("render_into"), "{refused}");
                    }
                    directs.push((name, color, depth));
                }
                // The copy-only call's road (after a frame that also fills
                // Strata's depth target).
                r.set_depth_attachment(true);
                r.render_frame(&camera).unwrap();
                r.set_depth_attachment(false);
                if color_format == F::Rgba8Unorm {
                    // The frame's colour is back in Strata's target, as the
                    // first road stored it.
                    assert_eq!(r.read_color().unwrap(), images[0].0, "{name} {usage:?}");
                }
                // And its depth, as every road stored it into the caller's
                // Depth32Float (each road's own check, not only against the
                // first road's).
                let own_depth = r.read_depth().unwrap();
                let stored = &images.last().unwrap().1;
                assert_eq!(stored.len(), 4 * own_depth.len(), "{name}");
                let differ = stored
                    .chunks_exact(4)
                    .zip(&own_depth)
                    .filter(|(a, b)| **a != b.to_le_bytes())
                    .count();
                assert_eq!(
                    differ, 0,
                    "{name} {color_format:?} {usage:?}: depths differ from read_depth"
                );
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                let road = r.record_copy_into(&mut encoder, &targets, None).unwrap();
                gpu.queue.submit([encoder.finish()]);
                gpu.wait().unwrap();
                let expected_color = match usage {
                    u if u == storage_usage && gpu.caps.compute => Some(ColorRoute::Storage {
                        linear: color_format == F::Rgba16Float,
                    }),
                    u if u != USAGE && color_format != F::Rgba16Float => Some(ColorRoute::Copy),
                    _ => None,
                };
                match (road, expected_color) {
                    (CompositeRoute::Split { color, depth }, Some(expected)) => {
                        assert_eq!(color, expected, "{name} {color_format:?} {usage:?}");
                        // `render_into` took the same road, or let a compute
                        // method's shading store the colour itself.
                        let CompositeRoute::Split {
                            color: into_color,
                            depth: into_depth,
                        } = taken
                        else {
                            panic!("{name} {color_format:?} {usage:?}: render_into took {taken}");
                        };
                        // The same road, or the method drew into the target itself.
                        assert!(
                            (into_color == color || into_color == ColorRoute::Direct)
                                && (into_depth == depth || into_depth == DepthRoute::Direct),
                            "{name} {color_format:?} {usage:?}: {taken}"
                        );
                        roads.push((name, color, depth));
                    }
                    (CompositeRoute::Pass, None) => {}
                    // No depth copies (GL): a fragment method's depth takes the pass.
                    (CompositeRoute::Pass, Some(_)) if !gpu.caps.depth_copies => {}
                    (road, expected) => panic!(
                        "{name} {color_format:?} {usage:?}: took {road}, expected colour {expected:?}"
                    ),
                }
            }
            let (pass_color, pass_depth) = &images[0];
            for (i, (color, depth)) in images.iter().enumerate().skip(1) {
                // 8-bit targets: the very bytes (the sRGB twin: the pass's
                // decode + encode round trip may move a byte by one); the
                // float target: within one half-float step.
                let worst = match color_format {
                    F::Rgba16Float => bytemuck::cast_slice::<u8, u16>(pass_color)
                        .iter()
                        .zip(bytemuck::cast_slice::<u8, u16>(color))
                        .map(|(a, b)| a.abs_diff(*b))
                        .max()
                        .unwrap_or(0),
                    _ => pass_color
                        .iter()
                        .zip(color)
                        .map(|(a, b)| u16::from(a.abs_diff(*b)))
                        .max()
                        .unwrap_or(0),
                };
                let depths_differ = pass_depth
                    .chunks_exact(4)
                    .zip(depth.chunks_exact(4))
                    .filter(|(a, b)| a != b)
                    .count();
                let terrain = bytemuck::cast_slice::<u8, f32>(depth)
                    .iter()
                    .filter(|d| **d < 1.0)
                    .count();
                println!(
                    "{name} into {color_format:?} (road {i}) vs the pass: worst channel difference \
                     {worst}, {depths_differ} depths differ, {terrain} terrain pixels"
                );
                let allowed = u16::from(color_format != F::Rgba8Unorm);
                assert!(
                    worst <= allowed,
                    "{name} {color_format:?} road {i}: {worst}"
                );
                assert_eq!(depths_differ, 0, "{name} {color_format:?} road {i}");
                assert!(terrain > (W * H / 4) as usize, "{name}: {terrain}");
            }
        }
        tested += 1;
    }
    assert!(tested >= 2, "{tested} methods ran");
    // A rasterising method into a colour format it cannot draw drew its
    // depth itself and took the colour-only pass.
    assert!(
        directs
            .iter()
            .any(|(_, c, d)| *c == ColorRoute::Pass && *d == DepthRoute::Direct),
        "{directs:?}"
    );
    // A rasterising method into a colour format it cannot draw drew its
    // depth itself and took the colour-only pass.
    assert!(
        directs
            .iter()
            .any(|(_, c, d)| *c == ColorRoute::Pass && *d == DepthRoute::Direct),
        "{directs:?}"
    );
    if gpu.caps.compute {
        // The roads this test exists for were taken at least once each (an
        // 8-bit storage dispatch by a fragment method, which needs depth
        // copies: the compute methods store that colour themselves).
        let storage_8bit =
            |c: &ColorRoute, _: &DepthRoute| matches!(c, ColorRoute::Storage { linear: false });
        if gpu.caps.depth_copies {
            assert!(
                roads.iter().any(|(_, c, d)| storage_8bit(c, d)),
                "{roads:?}"
            );
        }
        for wanted in [
            |c: &ColorRoute, _: &DepthRoute| matches!(c, ColorRoute::Storage { linear: true }),
            |_: &ColorRoute, d: &DepthRoute| *d == DepthRoute::FromImage,
        ] {
            assert!(roads.iter().any(|(_, c, d)| wanted(c, d)), "{roads:?}");
        }
        // Every method that took a split road drew its colour into the
        // caller's texture itself at least once; every rasterising one drew
        // its depth too.
        for (name, _, _) in &directs {
            let direct = |c: &ColorRoute, d: Option<DepthRoute>| {
                directs
                    .iter()
                    .any(|(n, cc, dd)| n == name && c == cc && d.is_none_or(|d| d == *dd))
            };
            assert!(direct(&ColorRoute::Direct, None), "{name}: {directs:?}");
            let compute = ["ray-compute", "voxel-compute", "ray-exact"].contains(name);
            assert!(
                compute || direct(&ColorRoute::Direct, Some(DepthRoute::Direct)),
                "{name}: {directs:?}"
            );
        }
    }
}
