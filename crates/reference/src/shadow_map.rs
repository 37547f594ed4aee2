//! The CPU twin of the shared 1024² shadow map: the same texels
//! ([`ShadowFrame`]), each cast along the light by the exact tracer instead of
//! the GPU's 128-step march. The colour reference samples it exactly as
//! `shading.wgsl` samples the GPU map.

use crate::ReferenceSettings;
use crate::raycast::Tracer;
use rayon::prelude::*;
use strata_camera::light::{SHADOW_SIZE, ShadowFrame};

/// What `shadow.wgsl` stores where its march finds nothing.
pub const SHADOW_MISS: f32 = 1e9;

/// Distance along the light from the map's plane to the first solid point,
/// per texel, row-major (`side` x `side`).
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowMap {
    /// Where the map lies (plane, axes, texel size).
    pub frame: ShadowFrame,
    /// Texels per side ([`SHADOW_SIZE`]).
    pub side: u32,
    /// World units along the light per texel, [`SHADOW_MISS`] where nothing is hit.
    pub depth: Vec<f32>,
}

impl ShadowMap {
    /// Cast every texel of `frame` that its view can sample
    /// ([`ShadowFrame::casts`]) with the exact tracer (parallel over rows).
    pub fn cast(tracer: &Tracer, frame: &ShadowFrame) -> Self {
        let side = SHADOW_SIZE;
        let mut depth = vec![SHADOW_MISS; (side * side) as usize];
        let light = frame.light.as_dvec3().normalize();
        depth
            .par_chunks_mut(side as usize)
            .enumerate()
            .for_each(|(j, row)| {
                let mut state = tracer.ray_state();
                for (i, texel) in row.iter_mut().enumerate() {
                    // Texels no visible point samples hold a miss, as on the GPU.
                    if !frame.casts(i as u32, j as u32) {
                        continue;
                    }
                    // The texel centre as the GPU computes it (f32), then exact.
                    let o = frame.texel_centre(i as u32, j as u32);
                    let hit = tracer.trace_in(
                        &mut state,
                        o.as_dvec3(),
                        light,
                        1e6,
                        &ReferenceSettings::default(),
                    );
                    if let Some(hit) = hit {
                        *texel = hit.distance as f32;
                    }
                }
            });
        ShadowMap {
            frame: *frame,
            side,
            depth,
        }
    }

    /// The blocker distance at texel (i, j), `None` outside the map.
    pub fn get(&self, i: i32, j: i32) -> Option<f32> {
        let side = self.side as i32;
        ((0..side).contains(&i) && (0..side).contains(&j))
            .then(|| self.depth[(j * side + i) as usize])
    }
}
