//! Emission: the compact per-chunk index data the GPU draws.
//!
//! There is no vertex buffer. Every vertex is a grid sample of the chunk,
//! and its altitude and terrain type are in the decoded terrain the GPU
//! already holds, so an index names the vertex completely:
//! `index = kind * positions + y * (size_x + 1) + x`, with local `x, y` in
//! `0..=size`, `positions = (size_x + 1) * (size_y + 1)` (16 641 for
//! 128-chunks, so the largest index is 49 922) and `kind` 0 floor (`low`,
//! lower terrain type), 1 slab top (`high`, upper type), 2 cave ceiling
//! (`mid`, upper type). The vertex shader reads `@builtin(vertex_index)` (the
//! index value in an indexed draw), decodes the column at chunk origin +
//! (x, y) (wrapping) and picks the field. Normals are flat: derived per
//! triangle on the GPU. Triangle lists only (no primitive restart).
//!
//! Per planar triangle: the floor (counter-clockwise seen from +z). Where all
//! three vertices are dual, also the slab top (same winding) and the cave
//! ceiling (reversed winding, seen from below). Walls (`mid` to `high`) close
//! the slab on each edge of a slab triangle whose neighbour has no slab,
//! facing away from the slab. On a chunk-border edge the neighbour lives in
//! another chunk, so a slab triangle always gets a wall there: when the
//! other side has a slab too the wall lies inside the solid slab and is
//! hidden by it; this keeps every chunk's output a function of its own
//! samples (exact local refit). Winding: counter-clockwise seen from outside
//! the solid, in the right-handed (x, y, z-up) grid frame.
//!
//! The outline fit emits the floor of one triangulation and the slab of
//! another into the same LODs ([`Parts`]); the rules above apply to each
//! (walls close the slab triangulation's slab triangles). There a slab
//! triangle also keeps within half a texel of the slab columns
//! ([`Triangulation::is_slab`]): three dual vertices on two rims of a gap
//! do not make one.
//!
//! LODs share triangles (greedy insertion leaves untouched regions alone),
//! so the three lists are stored once, in blocks by LOD membership:
//! `[2 only][1,2][0,1,2][0,1][0 only][1 only]`. LOD 2 and LOD 0 are one range
//! each, LOD 1 is two ranges.

use crate::lod::{CAUSES, LODS};
use crate::samples::ChunkSamples;
use crate::triangulation::{NONE, Triangulation};

/// Vertex kind of the floor (`low`, lower terrain type).
pub const KIND_FLOOR: u16 = 0;
/// Vertex kind of the slab top (`high`, upper terrain type).
pub const KIND_TOP: u16 = 1;
/// Vertex kind of the cave ceiling (`mid`, the slab's underside, upper terrain type).
pub const KIND_CEILING: u16 = 2;

/// Encode a vertex index (see the module docs); `stride = size_x + 1`,
/// `positions = (size_x + 1) * (size_y + 1)`.
#[inline]
pub fn encode(x: u32, y: u32, stride: u32, positions: u32, kind: u16) -> u16 {
    (u32::from(kind) * positions + y * stride + x) as u16
}

/// Decode a vertex index: `(x, y, kind)`.
#[inline]
pub fn decode(index: u16, stride: u32, positions: u32) -> (u32, u32, u16) {
    let (kind, pos) = (u32::from(index) / positions, u32::from(index) % positions);
    (pos % stride, pos / stride, kind as u16)
}

/// Triangle counts of one LOD of a chunk.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct LodStats {
    /// Triangles of the planar triangulation (= floor triangles).
    pub planar: u32,
    /// Slab top + cave ceiling triangles.
    pub slab: u32,
    /// Wall triangles (of which `border_walls` on chunk-border edges).
    pub wall: u32,
    /// Wall triangles on the chunk's border edges (included in `wall`).
    pub border_walls: u32,
}

impl LodStats {
    /// Every triangle the GPU draws for this LOD.
    pub fn emitted(&self) -> u32 {
        self.planar + self.slab + self.wall
    }
}

/// What one chunk's fit produced: counts and the content hash.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ChunkStats {
    /// Vertices of the finest planar triangulation (4 corners + insertions).
    pub planar_vertices: u32,
    /// Length of the index list (kept when the list itself is released).
    pub indices: u32,
    /// FNV-1a of the index list and LOD ranges: how a refit tells whether a
    /// chunk changed once its CPU copy is gone.
    pub hash: u64,
    /// Triangle counts per LOD (0 the finest).
    pub lods: [LodStats; LODS],
    /// Insertions by [`crate::lod::Cause`].
    pub causes: [u32; CAUSES],
}

/// One chunk's drawable data.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ChunkMesh {
    /// Encoded vertex indices ([`encode`]) of all LODs' triangle lists.
    pub indices: Vec<u16>,
    /// Up to two `[start, end)` index ranges per LOD (LOD 0 the finest);
    /// an unused range is empty.
    pub lods: [[(u32, u32); 2]; LODS],
    /// Counts and hash; they stay after [`crate::LevelMesh::release_indices`].
    pub stats: ChunkStats,
}

impl ChunkMesh {
    /// Bytes this chunk uploads to the GPU.
    pub fn gpu_bytes(&self) -> usize {
        self.indices.len() * 2
    }

    /// The triangles (index triples) of one LOD.
    pub fn lod_triangles(&self, lod: usize) -> impl Iterator<Item = [u16; 3]> + '_ {
        self.lods[lod]
            .iter()
            .flat_map(|&(s, e)| self.indices[s as usize..e as usize].chunks_exact(3))
            .map(|t| [t[0], t[1], t[2]])
    }
}

/// Which parts of a triangulation [`Emitter::emit_lod_parts`] adds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parts {
    /// The floor of every triangle and the slab of the slab triangles.
    Both,
    /// The floor of every triangle only.
    Floor,
    /// The slab (top, ceiling, walls) of the slab triangles only.
    Slab,
}

/// Emission scratch, reused across chunks.
#[derive(Default)]
pub struct Emitter {
    stride: u32,
    positions: u32,
    /// Each LOD's triangles as keys (three indices, smallest first).
    lists: [Vec<u64>; LODS],
    blocks: [Vec<u64>; 8],
    scratch: Vec<u64>,
    stats: [LodStats; LODS],
    /// Per triangle of the LOD being emitted: a slab triangle?
    slab: Vec<bool>,
}

#[inline]
fn key(t: [u16; 3]) -> u64 {
    // Rotate the smallest index first (keeps the winding) so that the same
    // triangle has the same key in every LOD.
    let r = if t[0] <= t[1] && t[0] <= t[2] {
        t
    } else if t[1] <= t[2] {
        [t[1], t[2], t[0]]
    } else {
        [t[2], t[0], t[1]]
    };
    u64::from(r[0]) | u64::from(r[1]) << 16 | u64::from(r[2]) << 32
}

impl Emitter {
    /// Start a chunk of `size_x x size_y` texels (its index stride and
    /// position count), clearing the previous chunk's lists.
    pub fn begin(&mut self, size_x: u32, size_y: u32) {
        self.stride = size_x + 1;
        self.positions = (size_x + 1) * (size_y + 1);
        for l in &mut self.lists {
            l.clear();
        }
        self.stats = [LodStats::default(); LODS];
    }

    /// Emit LOD `lod` from the current state of the triangulation: the
    /// floor of every triangle and the slab (top, ceiling, walls) of every
    /// slab triangle.
    pub fn emit_lod(
        &mut self,
        lod: usize,
        tr: &Triangulation,
        vsample: &[u32],
        samples: &ChunkSamples,
    ) {
        self.emit_lod_parts(lod, tr, vsample, samples, Parts::Both);
    }

    /// [`emit_lod`](Self::emit_lod), adding only `parts` of the
    /// triangulation to the LOD (the outline fit emits its floor and its
    /// slab from two triangulations into the same LOD).
    pub fn emit_lod_parts(
        &mut self,
        lod: usize,
        tr: &Triangulation,
        vsample: &[u32],
        samples: &ChunkSamples,
        parts: Parts,
    ) {
        let positions = self.positions;
        let sample = |v: u32| &samples.samples[vsample[v as usize] as usize];
        self.slab.clear();
        if parts != Parts::Floor {
            self.slab
                .extend((0..tr.tris.len() as u32).map(|t| tr.is_slab(t)));
        }
        let slab_of = &self.slab;
        let slab = |t: u32| slab_of[t as usize];
        // A vertex's sample index is its grid position `y * stride + x`.
        let idx = |v: u32, kind: u16| (u32::from(kind) * positions + vsample[v as usize]) as u16;
        let out = &mut self.lists[lod];
        let mut st = LodStats::default();
        for t in 0..tr.tris.len() as u32 {
            let tri = tr.tris[t as usize];
            let [a, b, c] = tri.v;
            if parts != Parts::Slab {
                out.push(key([a, b, c].map(|v| idx(v, KIND_FLOOR))));
                st.planar += 1;
            }
            if parts == Parts::Floor || !slab(t) {
                continue;
            }
            out.push(key([a, b, c].map(|v| idx(v, KIND_TOP))));
            out.push(key([a, c, b].map(|v| idx(v, KIND_CEILING))));
            st.slab += 2;
            for i in 0..3 {
                let nb = tri.n[i];
                if nb != NONE && slab(nb) {
                    continue;
                }
                let (ea, eb) = (tri.v[(i + 1) % 3], tri.v[(i + 2) % 3]);
                let (za, zb) = (sample(ea).z, sample(eb).z);
                let (am, ah) = (idx(ea, KIND_CEILING), idx(ea, KIND_TOP));
                let (bm, bh) = (idx(eb, KIND_CEILING), idx(eb, KIND_TOP));
                let mut n = 0;
                // Skip the half of the quad that is degenerate where the
                // slab has no thickness (mid == high).
                if zb[1] != zb[2] {
                    out.push(key([am, bm, bh]));
                    n += 1;
                }
                if za[1] != za[2] {
                    out.push(key([am, bh, ah]));
                    n += 1;
                }
                st.wall += n;
                if nb == NONE {
                    st.border_walls += n;
                }
            }
        }
        let acc = &mut self.stats[lod];
        acc.planar += st.planar;
        acc.slab += st.slab;
        acc.wall += st.wall;
        acc.border_walls += st.border_walls;
    }

    /// Add `other`'s emitted triangles and counts (the other part of an
    /// outline fit of the same chunk) to this one's.
    pub fn absorb(&mut self, other: &Emitter) {
        for (l, o) in self.lists.iter_mut().zip(&other.lists) {
            l.extend_from_slice(o);
        }
        for (s, o) in self.stats.iter_mut().zip(&other.stats) {
            s.planar += o.planar;
            s.slab += o.slab;
            s.wall += o.wall;
            s.border_walls += o.border_walls;
        }
    }

    /// Lay the three LODs out by membership blocks and move them into
    /// `mesh`; `vertices`: the finest LOD's vertex count (of every
    /// triangulation emitted).
    pub fn finish(&mut self, mesh: &mut ChunkMesh, vertices: u32) {
        for l in &mut self.lists {
            radix_sort(l, &mut self.scratch);
        }
        // Blocks by LOD membership mask, from a three-way merge of the sorted
        // lists; inside a block triangles are in key order (by their lowest
        // vertex index, which keeps neighbours close for the vertex cache).
        const ORDER: [u8; 6] = [0b100, 0b110, 0b111, 0b011, 0b001, 0b010];
        let blocks = &mut self.blocks;
        for b in blocks.iter_mut() {
            b.clear();
        }
        let lists = &self.lists;
        let mut at = [0usize; LODS];
        loop {
            let head = |l: usize| lists[l].get(at[l]).copied().unwrap_or(u64::MAX);
            let k = head(0).min(head(1)).min(head(2));
            if k == u64::MAX {
                break;
            }
            let mut m = 0u8;
            for (l, a) in at.iter_mut().enumerate() {
                if lists[l].get(*a) == Some(&k) {
                    m |= 1 << l;
                    *a += 1;
                }
            }
            if m == 0b101 {
                // In LODs 0 and 2 but not 1 (rare): stored twice.
                blocks[0b001].push(k);
                blocks[0b100].push(k);
            } else {
                blocks[m as usize].push(k);
            }
        }
        let mut indices = Vec::with_capacity(blocks.iter().map(|b| b.len() * 3).sum());
        let mut range = [(0u32, 0u32); 8];
        for m in ORDER {
            let start = indices.len() as u32;
            for &k in &blocks[m as usize] {
                indices.extend([k as u16, (k >> 16) as u16, (k >> 32) as u16]);
            }
            range[m as usize] = (start, indices.len() as u32);
        }
        mesh.lods = [
            [(range[0b111].0, range[0b001].1), (0, 0)],
            [(range[0b110].0, range[0b011].1), range[0b010]],
            [(range[0b100].0, range[0b111].1), (0, 0)],
        ];
        mesh.stats.indices = indices.len() as u32;
        mesh.stats.hash = content_hash(&indices, &mesh.lods);
        mesh.indices = indices;
        mesh.stats.lods = self.stats;
        mesh.stats.planar_vertices = vertices;
    }
}

/// Sort 48-bit keys (three u16 indices) by LSD radix, 12 bits a pass (four
/// passes, histograms counted in one read), skipping passes whose digit is
/// the same for every key. Faster than a comparison sort for the few
/// thousand keys of a chunk LOD.
fn radix_sort(keys: &mut Vec<u64>, scratch: &mut Vec<u64>) {
    const BITS: u32 = 12;
    const BUCKETS: usize = 1 << BITS;
    const PASSES: usize = 4;
    const MASK: u64 = BUCKETS as u64 - 1;
    scratch.clear();
    scratch.resize(keys.len(), 0);
    let mut count = vec![[0u32; BUCKETS]; PASSES];
    for &k in keys.iter() {
        for (pass, c) in count.iter_mut().enumerate() {
            c[((k >> (pass as u32 * BITS)) & MASK) as usize] += 1;
        }
    }
    let n = keys.len() as u32;
    for (pass, c) in count.iter_mut().enumerate() {
        if c.contains(&n) {
            continue;
        }
        let shift = pass as u32 * BITS;
        let mut sum = 0;
        for v in c.iter_mut() {
            let x = *v;
            *v = sum;
            sum += x;
        }
        for &k in keys.iter() {
            let d = ((k >> shift) & MASK) as usize;
            scratch[c[d] as usize] = k;
            c[d] += 1;
        }
        std::mem::swap(keys, scratch);
    }
}

/// FNV-1a over the indices and the LOD ranges.
pub fn content_hash(indices: &[u16], lods: &[[(u32, u32); 2]; LODS]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |v: u64| {
        h ^= v;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    };
    for &i in indices {
        eat(u64::from(i));
    }
    for r in lods.iter().flatten() {
        eat(u64::from(r.0) << 32 | u64::from(r.1));
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radix_sort_sorts() {
        let mut keys: Vec<u64> = (0..5000u64)
            .map(|i| (i * 2_654_435_761) & 0xffff_ffff_ffff)
            .collect();
        let mut expected = keys.clone();
        expected.sort_unstable();
        radix_sort(&mut keys, &mut Vec::new());
        assert_eq!(keys, expected);
        let mut same = vec![7u64; 10];
        radix_sort(&mut same, &mut Vec::new());
        assert_eq!(same, vec![7u64; 10]);
    }
}
