//! `ray-exact`'s uniform (the twin of `ExactParams` in
//! `ray_exact_core.wgsl`): the pyramid's level table, the iteration cap and
//! the kept shadow blocks' key.

use super::ITERATION_CAP;

/// Twin of `ExactParams` in `ray_exact_core.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ExactParams {
    pub(super) config: [u32; 4],
    pub(super) levels: [[u32; 4]; 9],
    /// x: the kept shadow blocks' key ([`super::keep::ShadowKeep`]); 0
    /// keeps none.
    pub(super) shadow_keep: [u32; 4],
}

/// The traversal's level table for `layout`.
pub(crate) fn exact_params(layout: &strata_maxmip::Layout) -> ExactParams {
    let mut table = ExactParams {
        // w: the cave pyramid's first byte, after the maxima (`GpuMaxMip`).
        config: [layout.top(), ITERATION_CAP, 0, layout.bytes],
        levels: [[0; 4]; 9],
        shadow_keep: [0; 4],
    };
    for info in &layout.levels {
        table.levels[info.log2_tile as usize] = [
            info.offset,
            info.width.trailing_zeros(),
            info.width - 1,
            info.height - 1,
        ];
    }
    table
}
