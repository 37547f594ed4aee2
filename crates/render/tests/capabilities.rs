//! What an adapter lacks is a refusal naming it, before any GPU work; and
//! the fallbacks for missing capabilities (depth read back through a pass,
//! the shadow map as a fragment pass) draw what the direct paths draw.

mod common;

use strata_render::caps::ShadowPassKind;
use strata_render::{Gpu, MethodSettings, Renderer, TerrainColors};

const W: u32 = 96;
const H: u32 = 60;

fn renderer(gpu: &Gpu, level: &strata_level::Level, method: &str) -> anyhow::Result<Renderer> {
    Renderer::new(
        gpu,
        level,
        &TerrainColors::test_ramps(),
        method,
        &MethodSettings::default(),
        W,
        H,
    )
}

#[test]
fn a_method_the_adapter_cannot_run_is_refused_with_the_capability_named() {
    for mut gpu in common::gpus() {
        let level = common::synthetic_level();
        // Pretend the adapter is WebGL2-like: no compute, no storage.
        gpu.caps.compute = false;
        gpu.caps.storage_textures = false;
        gpu.caps.fragment_storage = false;
        gpu.caps.vertex_storage = false;
        for (method, want) in [
            (
                "voxel-compute",
                "voxel-compute: needs compute shaders and storage textures, which this adapter lacks",
            ),
            (
                "mesh",
                "mesh: needs storage buffers in vertex shaders, which this adapter lacks",
            ),
            (
                "scattered",
                "scattered: needs compute shaders and storage buffers in fragment shaders, \
                 which this adapter lacks",
            ),
        ] {
            let error = match renderer(&gpu, &level, method) {
                Ok(_) => panic!("{method} was built on an adapter without compute"),
                Err(e) => format!("{e:#}"),
            };
            assert_eq!(error, want);
        }
        // Refused before any GPU work: nothing reached wgpu's validation.
        gpu.errors.check().unwrap();
        // The methods WebGL2 can run still build and draw, with the shadow
        // map from a fragment pass (where R32Float is renderable: not on
        // wgpu's desktop GL, which has compute instead).
        if !gpu.caps.float32_targets {
            let error = format!("{:#}", renderer(&gpu, &level, "ray").err().unwrap());
            assert!(error.contains("32-bit float render targets"), "{error}");
            continue;
        }
        for method in ["ray", "painted", "sliced"] {
            let mut r = renderer(&gpu, &level, method).unwrap();
            let camera =
                strata_camera::Camera::from_view(&level, &common::synthetic_views()[4], W, H)
                    .unwrap();
            r.render_frame(&camera).unwrap();
            let depth = r.read_depth().unwrap();
            assert!(depth.iter().any(|&d| d < 1.0), "{method} drew nothing");
        }
    }
}

/// Depth through the read-back pass is bit-identical to a depth copy, and
/// the fragment shadow pass gives the compute pass's picture.
#[test]
fn fallbacks_match_the_direct_paths() {
    for gpu in common::gpus() {
        if !gpu.caps.depth_copies || !gpu.caps.compute || !gpu.caps.float32_targets {
            eprintln!("{}: no direct path to compare with", gpu.report.backend);
            continue;
        }
        let level = common::synthetic_level();
        let views = common::synthetic_views();
        let mut direct = renderer(&gpu, &level, "ray").unwrap();
        let mut fallback_gpu = Gpu::open(&strata_render::AdapterChoice {
            backend: gpu.report.backend.parse().unwrap(),
            index: None,
            name: None,
        })
        .unwrap();
        fallback_gpu.caps.depth_copies = false;
        fallback_gpu.caps.compute = false;
        fallback_gpu.caps.storage_textures = false;
        assert_eq!(
            fallback_gpu.caps.shadow_pass(),
            Some(ShadowPassKind::Fragment)
        );
        let mut fallback = renderer(&fallback_gpu, &level, "ray").unwrap();
        for view in [&views[1], &views[5], &views[8]] {
            let camera = strata_camera::Camera::from_view(&level, view, W, H).unwrap();
            direct.render_frame(&camera).unwrap();
            fallback.render_frame(&camera).unwrap();
            let (a, b) = (direct.read_depth().unwrap(), fallback.read_depth().unwrap());
            assert_eq!(
                a, b,
                "{}: depth differs through the read-back pass",
                view.name
            );
            // Colour: the same shadow map from a fragment pass (compute and
            // fragment may round the march differently by an ulp).
            let (ca, cb) = (direct.read_color().unwrap(), fallback.read_color().unwrap());
            let off = ca
                .iter()
                .zip(&cb)
                .filter(|(x, y)| x.abs_diff(**y) > 2)
                .count();
            assert!(
                off * 1000 <= ca.len(),
                "{}: {off} of {} colour channels differ with the fragment shadow pass",
                view.name,
                ca.len()
            );
        }
        fallback_gpu.errors.check().unwrap();
    }
}
