//! What `Renderer::render_into` adds to a frame, per target format pair and
//! usage: the median GPU time of a `render_into` frame (every pass stamped,
//! `Renderer::render_into_timed`) less that of the same frame drawn into
//! Strata's own targets (`render_frame`), and, apart, the copy of the last
//! frame alone (`record_copy_into`, what showing one frame in more targets
//! costs). Timestamp queries (wall clock of a submit-and-wait where the
//! adapter has none). Each line names the road `render_into` took
//! (`strata_render::composite_split`): colour by the method's own shading,
//! by compute or by copy, depth by a pass from the method's image or by
//! copy, or the full-screen pass. The roads that read Strata's own depth
//! target (a depth copy, the pass) also make a compute method blit its depth
//! image into that target: the first line's two frame times show what that
//! blit costs.
//!
//! ```text
//! cargo run --release -p strata-render --example composite_cost -- [--size WxH] [--frames N] [--method NAME] [--shadows]
//! ```

use std::time::Instant;
use strata_camera::Camera;
use strata_render::{Gpu, MethodSettings, Renderer, TargetViews, TerrainColors};
use wgpu::TextureFormat as F;

fn main() -> anyhow::Result<()> {
    let (mut size, mut frames, mut method) = ((1280u32, 800u32), 200u32, "mesh".to_string());
    let mut shadows = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--shadows" {
            shadows = true;
            continue;
        }
        let v = args
            .next()
            .ok_or_else(|| anyhow::anyhow!("{a} needs a value"))?;
        match a.as_str() {
            "--size" => {
                size = v
                    .split_once('x')
                    .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)))
                    .ok_or_else(|| anyhow::anyhow!("--size {v:?}: expected WxH"))?
            }
            "--frames" => frames = v.parse()?,
            "--method" => method = v,
            other => anyhow::bail!("unknown argument {other:?}"),
        }
    }
    let gpu = Gpu::headless()?;
    let level = strata_level::Level::flat(256, 256, 40, 1)?;
    let camera = Camera::new(
        glam::Vec3::new(128.0, 0.0, 120.0),
        0.0,
        -40.0,
        size.0,
        size.1,
    )?;
    let settings = MethodSettings {
        shadows,
        ..Default::default()
    };
    let colors = TerrainColors::test_ramps();
    let mut r = Renderer::new(&gpu, &level, &colors, &method, &settings, size.0, size.1)?;
    let frame_ms = |r: &mut Renderer| -> anyhow::Result<f64> {
        let times: Vec<f64> = (0..frames.min(20))
            .map(|_| {
                r.render_frame(&camera)
                    .map(|t| t.gpu_ms.unwrap_or(t.cpu_ms))
            })
            .collect::<anyhow::Result<_>>()?;
        Ok(median(times))
    };
    let alone = frame_ms(&mut r)?;
    // The roads that read Strata's own depth target need it filled.
    r.set_depth_attachment(true);
    let filled = frame_ms(&mut r)?;
    println!(
        "adapter {} ({}); {method} frame at {}x{}: median {:.3} ms, {:.3} ms with Strata's depth target filled ({})",
        gpu.report.name,
        gpu.report.backend,
        size.0,
        size.1,
        alone,
        filled,
        if gpu.caps.timestamps {
            "GPU timestamps"
        } else {
            "wall clock"
        }
    );
    let queries = gpu.caps.timestamps.then(|| {
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("composite"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("composite stamps"),
            size: 16,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("composite stamps read"),
            size: 16,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        (set, resolve, read)
    });
    let period_ms = f64::from(gpu.queue.get_timestamp_period()) * 1e-6;
    use wgpu::TextureUsages as U;
    let (plain, copy) = (U::RENDER_ATTACHMENT, U::RENDER_ATTACHMENT | U::COPY_DST);
    let storage = copy | U::STORAGE_BINDING;
    for (color, depth, samples, usage) in [
        (F::Rgba8Unorm, F::Depth32Float, 1, storage),
        (F::Rgba16Float, F::Depth32Float, 1, storage),
        (F::Rgba8Unorm, F::Depth24Plus, 1, storage),
        (F::Rgba8Unorm, F::Depth32Float, 1, copy),
        (F::Rgba8UnormSrgb, F::Depth32Float, 1, copy),
        (F::Rgba8Unorm, F::Depth32Float, 1, plain),
        (F::Bgra8UnormSrgb, F::Depth24Plus, 1, plain),
        (F::Bgra8UnormSrgb, F::Depth32Float, 1, plain),
        (F::Rgba16Float, F::Depth24PlusStencil8, 1, plain),
        (F::Bgra8UnormSrgb, F::Depth24Plus, 4, plain),
    ] {
        let target = |format| {
            gpu.device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some("caller target"),
                    size: wgpu::Extent3d {
                        width: size.0,
                        height: size.1,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: samples,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    // Depth textures cannot be storage.
                    usage: match format.is_depth_stencil_format() {
                        true => usage - U::STORAGE_BINDING,
                        false => usage,
                    },
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        let (cv, dv) = (target(color), target(depth));
        let targets = TargetViews::new(&cv, &dv);
        // The copy reads Strata's own targets: a frame drawn into them.
        r.render_frame(&camera)?;
        let mut times = Vec::new();
        let mut road = None;
        for _ in 0..frames {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let writes = queries
                .as_ref()
                .map(|(set, _, _)| wgpu::RenderPassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: Some(1),
                });
            road = Some(r.record_copy_into(&mut encoder, &targets, writes)?);
            if let Some((set, resolve, read)) = &queries {
                encoder.resolve_query_set(set, 0..2, resolve, 0);
                encoder.copy_buffer_to_buffer(resolve, 0, read, 0, 16);
            }
            let start = Instant::now();
            gpu.queue.submit([encoder.finish()]);
            gpu.wait()?;
            let wall = start.elapsed().as_secs_f64() * 1e3;
            times.push(match &queries {
                Some((_, _, read)) => {
                    let raw = strata_render::gpu::read_buffer(&gpu.device, &gpu.errors, read, 16)?;
                    let t: &[u64] = bytemuck::cast_slice(&raw);
                    t[1].saturating_sub(t[0]) as f64 * period_ms
                }
                None => wall,
            });
        }
        let copy_road = road.map_or("no frames".to_string(), |r| r.to_string());
        let into: Vec<f64> = (0..frames)
            .map(|_| {
                r.render_into_timed(&camera, &targets)
                    .map(|t| t.gpu_ms.unwrap_or(t.cpu_ms))
            })
            .collect::<anyhow::Result<_>>()?;
        let road = r.last_road().map_or("none".to_string(), |r| r.to_string());
        let into = median(into);
        // The frame alone again, after the copies (the clock may have moved).
        r.set_depth_attachment(false);
        let alone_now = frame_ms(&mut r)?;
        r.set_depth_attachment(true);
        println!(
            "into {color:?} + {depth:?} x{samples} ({usage:?}): render_into frame {into:.3} ms, the frame alone {alone_now:.3}: adds {:.3} ms ({road}); the copy alone median {:.3} ms, min {:.3} over {frames} ({copy_road})",
            into - alone_now,
            median(times.clone()),
            times.iter().copied().fold(f64::INFINITY, f64::min)
        );
    }
    Ok(())
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
