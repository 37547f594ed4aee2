//! The GPU surface decode (`surface.wgsl`) against the CPU `decode_column`,
//! texel for texel, on a random multi-layer level.

mod common;

use strata_camera::Camera;
use strata_level::{Level, MidRule};
use strata_render::{MethodSettings, Renderer, TerrainColors};

/// A small deterministic generator (no extra dependency).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
}

fn pack(c: strata_level::Column) -> u32 {
    u32::from(c.low)
        | u32::from(c.mid) << 8
        | u32::from(c.high) << 16
        | u32::from(c.dual) << 24
        | u32::from(c.lower_type) << 25
        | u32::from(c.upper_type) << 28
}

fn decode_on_gpu(gpu: &strata_render::Gpu, level: &Level, positions: &[[i32; 2]]) -> Vec<u32> {
    let settings = MethodSettings {
        shadows: false,
        ..Default::default()
    };
    let mut r = Renderer::new(
        gpu,
        level,
        &TerrainColors::test_ramps(),
        "ray",
        &settings,
        8,
        8,
    )
    .unwrap();
    // A frame writes the globals (map size, layer shift, mid rule).
    let cam = Camera::new(glam::Vec3::new(1.0, 1.0, 250.0), 0.0, -90.0, 8, 8).unwrap();
    r.render_frame(&cam).unwrap();
    let shared = r.shared();
    let device = &shared.device;
    let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[storage(0, true), storage(1, false)],
    });
    let pos_bytes: &[u8] = bytemuck::cast_slice(positions);
    let pos = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: pos_bytes.len() as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    shared.queue.write_buffer(&pos, 0, pos_bytes);
    let out_size = 4 * positions.len() as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let read = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: out_size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: pos.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: out.as_entire_binding(),
            },
        ],
    });
    let module = shared.shader("decode_test.wgsl").unwrap();
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: Some(&shared.pipeline_layout("decode", &[&layout])),
        module: &module,
        entry_point: Some("cs_decode"),
        compilation_options: Default::default(),
        cache: None,
    });
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &shared.frame_group, &[]);
        pass.set_bind_group(1, &group, &[]);
        pass.dispatch_workgroups((positions.len() as u32).div_ceil(64), 1, 1);
    }
    enc.copy_buffer_to_buffer(&out, 0, &read, 0, out_size);
    shared.queue.submit([enc.finish()]);
    let raw = strata_render::gpu::read_buffer(device, &gpu.errors, &read, out_size).unwrap();
    bytemuck::cast_slice(&raw).to_vec()
}

#[test]
fn gpu_decode_matches_cpu_decode() {
    for gpu in common::gpus() {
        for (seed, rule) in [(1u64, MidRule::Original), (2, MidRule::VangeRs)] {
            // 32x8192: four texture layers, so the layer split is exercised.
            let (w, h) = (32u32, 8192u32);
            let mut rng = Lcg(seed);
            let n = (w * h) as usize;
            let heights: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
            // Half the texels flagged dual: a quarter of pairs dual, a half disagreeing.
            let metas: Vec<u8> = (0..n)
                .map(|_| (rng.next() as u8 & !0x40) | if rng.next() & 1 == 0 { 0x40 } else { 0 })
                .collect();
            let level = Level::from_planes(w, h, heights, metas, rule).unwrap();
            let positions: Vec<[i32; 2]> = (0..20_000)
                .map(|_| {
                    let x = (rng.next() % (6 * w)) as i32 - 3 * w as i32;
                    let y = (rng.next() % (3 * h)) as i32 - h as i32;
                    [x, y]
                })
                .collect();
            let got = decode_on_gpu(&gpu, &level, &positions);
            let mut mismatches = 0;
            for (p, g) in positions.iter().zip(&got) {
                let want = pack(level.column(i64::from(p[0]), i64::from(p[1])));
                if want != *g {
                    if mismatches < 5 {
                        eprintln!("({}, {}): cpu {want:08x} gpu {g:08x}", p[0], p[1]);
                    }
                    mismatches += 1;
                }
            }
            assert_eq!(
                mismatches,
                0,
                "{rule:?}: {mismatches} of {} texels decode differently",
                positions.len()
            );
        }
    }
}
