//! What the replay counts: per ray ([`super::MarchCount`] gathered into
//! [`PassCount`]s: spreads, warps' longest chains, bytes) and per frame
//! ([`FrameCount`]).

use super::{MarchCount, PYRAMID_WORD_BYTES, TERRAIN_TEXEL_BYTES};

/// Per-ray figures of one pass: mean, 99th percentile and most.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Spread {
    /// Mean per ray.
    pub mean: f64,
    /// 99th percentile per ray (nearest rank).
    pub p99: u32,
    /// Most of any ray.
    pub max: u32,
    /// Sum over the pass.
    pub total: u64,
}

impl Spread {
    pub(super) fn of(mut v: Vec<u32>) -> Self {
        if v.is_empty() {
            return Spread::default();
        }
        let total: u64 = v.iter().map(|&x| u64::from(x)).sum();
        v.sort_unstable();
        let rank = ((0.99 * v.len() as f64).ceil() as usize).clamp(1, v.len());
        Spread {
            mean: total as f64 / v.len() as f64,
            p99: v[rank - 1],
            max: v[v.len() - 1],
            total,
        }
    }
}

/// One pass of the frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct PassCount {
    /// Rays (invocations that march or shade).
    pub rays: u64,
    /// Traversal iterations per ray (0 in the shading pass).
    pub iterations: Spread,
    /// Pyramid words read per ray.
    pub pyramid_reads: Spread,
    /// Terrain texels read per ray.
    pub terrain_reads: Spread,
    /// Descents per ray (mean).
    pub descents: f64,
    /// Levels climbed per ray (mean).
    pub climbs: f64,
    /// Shadow-map texels read per ray (the shading pass).
    pub shadow_reads: u64,
    /// Mean over 32-lane warps (8x4 pixels or texels of an 8x8 workgroup) of
    /// the most iterations of a lane: a warp steps as long as its longest ray.
    pub warp_iterations: f64,
    /// Waits per ray ([`MarchCount::waits`]).
    pub waits: Spread,
    /// Mean over warps of the most waits of a lane: the warp's chain of
    /// dependent fetches, if a lane's iterations without a fetch cost
    /// nothing beside them.
    pub warp_waits: f64,
    /// Iterations over warp steps x 32: the share of lanes doing work.
    pub simd_efficiency: f64,
    /// Bytes read, all requests (terrain, pyramid, shadow map, the pass's
    /// own images).
    pub bytes_read: u64,
    /// Bytes written (images, stamps, lists).
    pub bytes_written: u64,
}

/// The replayed frame of one view.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct FrameCount {
    /// Image width and height.
    pub size: [u32; 2],
    /// Pixels whose ray hit.
    pub hits: u64,
    /// The beams (one per 8x8-pixel tile; empty without them): per tile,
    /// the serial search's iterations or the wide search's rounds.
    pub beam: PassCount,
    /// Invocations per beam: 1 (serial) or [`super::WIDE_LANES`] (wide, every
    /// invocation of the tile's workgroup tests an interval each round).
    pub beam_lanes: u32,
    /// The camera march.
    pub march: PassCount,
    /// The shadow casts of the stamped blocks (empty with shadows off).
    pub shadow: PassCount,
    /// Iterations of the shadow blocks' beams, all blocks together (one per
    /// block: its 64 invocations search at once).
    pub shadow_beam_iterations: u64,
    /// The shading of the hits.
    pub shade: PassCount,
    /// Shadow blocks stamped (8x8 texels each).
    pub shadow_blocks: u64,
    /// Distinct terrain bytes read over the frame.
    pub terrain_bytes_touched: u64,
    /// Distinct pyramid bytes read over the frame.
    pub pyramid_bytes_touched: u64,
    /// The march's most iterations of a camera ray (`ExactStats`'s twin).
    pub most_iterations: u32,
    /// The most iterations of a shadow ray.
    pub shadow_most_iterations: u32,
}

impl FrameCount {
    /// Bytes read and written by the three passes together.
    pub fn bytes(&self) -> u64 {
        [self.beam, self.march, self.shadow, self.shade]
            .iter()
            .map(|p| p.bytes_read + p.bytes_written)
            .sum()
    }
}

/// Per-ray counts of a pass into a [`PassCount`].
#[derive(Default)]
pub(super) struct PassAcc {
    descents: u64,
    climbs: u64,
    iterations: Vec<u32>,
    pyramid: Vec<u32>,
    terrain: Vec<u32>,
    waits: Vec<u32>,
}

impl PassAcc {
    /// Rays added so far.
    pub(super) fn rays(&self) -> usize {
        self.iterations.len()
    }

    pub(super) fn add(&mut self, m: &MarchCount) {
        self.descents += u64::from(m.descents);
        self.climbs += u64::from(m.climbs);
        self.iterations.push(m.iterations);
        self.pyramid.push(m.pyramid_reads);
        self.terrain.push(m.terrain_reads);
        self.waits.push(m.waits);
    }

    /// `warps`: the lanes of each warp, as indices into the rays.
    pub(super) fn finish(self, warps: impl Iterator<Item = Vec<usize>>) -> PassCount {
        let rays = self.iterations.len() as u64;
        let (mut count, mut steps, mut waits) = (0u64, 0u64, 0u64);
        for lanes in warps {
            let most = lanes.iter().map(|&i| self.iterations[i]).max().unwrap_or(0);
            count += 1;
            steps += u64::from(most);
            waits += u64::from(lanes.iter().map(|&i| self.waits[i]).max().unwrap_or(0));
        }
        let work: u64 = self.iterations.iter().map(|&x| u64::from(x)).sum();
        let pyramid = Spread::of(self.pyramid);
        let terrain = Spread::of(self.terrain);
        PassCount {
            rays,
            bytes_read: pyramid.total * PYRAMID_WORD_BYTES + terrain.total * TERRAIN_TEXEL_BYTES,
            descents: self.descents as f64 / rays.max(1) as f64,
            climbs: self.climbs as f64 / rays.max(1) as f64,
            warp_iterations: steps as f64 / count.max(1) as f64,
            warp_waits: waits as f64 / count.max(1) as f64,
            waits: Spread::of(self.waits),
            simd_efficiency: work as f64 / (steps * 32).max(1) as f64,
            iterations: Spread::of(self.iterations),
            pyramid_reads: pyramid,
            terrain_reads: terrain,
            ..PassCount::default()
        }
    }
}
