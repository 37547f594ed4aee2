//! What the colour error found (issue 16 item 3), held to the CPU colour
//! reference: the marched ray shades the exact entry inside its last step
//! interval, and the mesh takes its colour from the surface the eye's ray
//! meets near the TIN, not from the column under a wall's ramp.

mod common;

use strata_camera::Camera;
use strata_level::{Level, ViewSpec};
use strata_reference::{TerrainRamps, Tracer, render_color};
use strata_render::{MethodSettings, Renderer, TerrainColors};

fn ramps(colors: &TerrainColors) -> TerrainRamps {
    TerrainRamps {
        palette: colors.palette,
        begin: colors.begin,
        end: colors.end,
    }
}

/// Mean ꟻLIP of `test` (RGBA8) against `reference` (RGB8), both w x h.
fn mean_flip(reference: &[u8], test_rgba: &[u8], (w, h): (u32, u32)) -> f32 {
    let test: Vec<u8> = test_rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, reference),
        nv_flip::FlipImageRgb8::with_data(w, h, &test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec();
    map.iter().sum::<f32>() / map.len() as f32
}

#[test]
fn marched_ray_colour_is_near_the_cpu_reference_on_a_generated_world() {
    let Some(gpu) = common::gpu() else { return };
    const SIZE: (u32, u32) = (320, 200);
    let world = common::generated_world();
    let colors = TerrainColors::from_world(&world);
    let ramps = ramps(&colors);
    let tracer = Tracer::new(&world.level);
    // The first view at each pitch (0, -30, -60, -90).
    let mut views: Vec<&ViewSpec> = Vec::new();
    for v in &world.views {
        if views.iter().all(|u| u.pitch != v.pitch) {
            views.push(v);
        }
    }
    assert_eq!(views.len(), 4, "one view per pitch");
    let settings = MethodSettings::default();
    let mut ray = Renderer::new(
        &gpu,
        &world.level,
        &colors,
        "ray",
        &settings,
        SIZE.0,
        SIZE.1,
    )
    .unwrap();
    let mut total = 0.0;
    for view in &views {
        let camera = Camera::from_view(&world.level, view, SIZE.0, SIZE.1).unwrap();
        let reference = render_color(&tracer, &ramps, &camera, true);
        ray.render_frame(&camera).unwrap();
        let mean = mean_flip(&reference.rgb, &ray.read_color().unwrap(), SIZE);
        eprintln!(
            "{} ({}°): ray FLIP vs the CPU colour reference {mean:.4}",
            view.name, view.pitch
        );
        total += mean;
    }
    let mean = total / views.len() as f32;
    eprintln!("ray: mean FLIP over the four pitches {mean:.4}");
    // Measured on lavapipe: 0.0341 (0.038 / 0.023 / 0.051 / 0.025 by pitch)
    // with the segment step test for the camera ray (`ray_core.wgsl::march`:
    // a step is flagged when the ray's piece of it in the column under
    // either of its samples meets that column's floor or slab) and the
    // paper's point test for the shared shadow map; 0.0245 with the segment
    // test in both (not kept: the shadow pass cost 75 % more on the H100);
    // 0.0409 (0.041 / 0.023 / 0.063 / 0.037) with the point test in both,
    // and 0.0503 with that and the paper's four bisections, whose hit lay up
    // to 1/16 of a step inside the solid. What remains is the columns
    // strictly between two samples, in the image and in the marched shadow
    // map. The bound fails the point test.
    assert!(mean < 0.038, "ray mean FLIP {mean}");
    gpu.errors.check().unwrap();
}

/// Type `t` owns palette entries 32 t .. 32 t + 31, and entry i's red is i:
/// a pixel's terrain type is its red / 32 (no fog in the test views).
fn type_coded_colors() -> TerrainColors {
    TerrainColors {
        palette: std::array::from_fn(|i| [i as u8, 128, 255 - i as u8]),
        begin: std::array::from_fn(|t| (t * 32) as u8),
        end: std::array::from_fn(|t| (t * 32 + 31) as u8),
    }
}

#[test]
fn mesh_colours_a_road_beside_a_wall_with_the_road() {
    let Some(gpu) = common::gpu() else { return };
    const SIZE: (u32, u32) = (160, 100);
    const ROAD: u8 = 2;
    // Flat ground (type 1, height 10); a block (type 3, height 70) over
    // x 40..64; a two-texel road (type 2) at x 64, 65 along its foot. The
    // fitted wall is a ramp between texel centres 63.5 and 64.5, half over
    // the road's first texel.
    let mut level = Level::flat(128, 128, 10, 1).unwrap();
    let (heights, metas) = level.planes_mut();
    for y in 0..128 {
        for x in 40..66 {
            let i = y * 128 + x;
            let (h, t) = if x < 64 { (70, 3u8) } else { (10, ROAD) };
            heights[i] = h;
            metas[i] = t << strata_level::model::META_TERRAIN_SHIFT;
        }
    }
    let colors = type_coded_colors();
    let ramps = ramps(&colors);
    let tracer = Tracer::new(&level);
    let settings = MethodSettings::default();
    let mut mesh = Renderer::new(&gpu, &level, &colors, "mesh", &settings, SIZE.0, SIZE.1).unwrap();
    // Straight down over the road, and over the ground beside it (off-axis
    // rays towards the wall).
    for spec in ["64,64:0:100", "72,40:0:60"] {
        let pitch = -90.0;
        let view = ViewSpec::parse("road", spec, pitch).unwrap();
        let camera = Camera::from_view(&level, &view, SIZE.0, SIZE.1).unwrap();
        let reference = render_color(&tracer, &ramps, &camera, true);
        mesh.render_frame(&camera).unwrap();
        let picture = mesh.read_color().unwrap();
        let (mut road, mut wrong) = (0usize, 0usize);
        for (r, m) in reference.rgb.chunks_exact(3).zip(picture.chunks_exact(4)) {
            if r[0] / 32 == ROAD {
                road += 1;
                wrong += usize::from(m[0] / 32 != ROAD);
            }
        }
        let pct = 100.0 * wrong as f64 / road.max(1) as f64;
        eprintln!(
            "{spec} {pitch}°: {pct:.2} % of {road} road pixels not road-coloured by the mesh"
        );
        assert!(road > 200, "{spec}: the road is in view ({road} pixels)");
        // Measured on lavapipe: 0.0 % in both views. Colouring the ramp from
        // half a texel inwards (the old rule) gave the block's colour to the
        // road half under it: 30 % in the first view.
        assert!(
            pct < 3.0,
            "{spec}: {pct} % of the road in the block's colour"
        );
    }
    gpu.errors.check().unwrap();
}
