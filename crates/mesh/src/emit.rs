//! Emission: the compact per-chunk vertex and index data the GPU draws.
//!
//! One vertex buffer per chunk serves all three LODs (the coarse LODs'
//! vertices are a subset of the finest's); each LOD is a range of one u16
//! index buffer. A vertex is one `u32`: see [`pack`].
//!
//! Per planar triangle: the floor (`low`, counter-clockwise seen from +z).
//! Where all three vertices are dual, also the slab top (`high`, same
//! winding) and the cave ceiling (`mid`, reversed winding, seen from below).
//! Walls (`mid` to `high`) close the slab on each edge of a slab triangle
//! whose neighbour has no slab, facing away from the slab. On a chunk-border
//! edge the neighbour lives in another chunk, so a slab triangle always gets
//! a wall there: when the other side has a slab too the wall lies inside the
//! solid slab and is hidden by it; this keeps every chunk's output a function
//! of its own samples (exact local refit). Winding: counter-clockwise seen from
//! outside the solid, in the right-handed (x, y, z-up) grid frame.

use crate::fit::LODS;
use crate::samples::ChunkSamples;
use crate::triangulation::{NONE, Triangulation};

/// Vertex kinds, stored in bits 27..28 of a packed vertex.
pub const KIND_FLOOR: u32 = 0;
pub const KIND_TOP: u32 = 1;
pub const KIND_CEILING: u32 = 2;

/// Pack a vertex: bits 0..7 local x (0..=128), 8..15 local y, 16..23
/// altitude, 24..26 terrain type, 27..28 kind. World position =
/// chunk origin + (x, y). Normals are flat: the GPU derives them per triangle.
#[inline]
pub fn pack(x: u32, y: u32, z: u8, terrain: u8, kind: u32) -> u32 {
    x | (y << 8) | (u32::from(z) << 16) | (u32::from(terrain & 7) << 24) | (kind << 27)
}

/// Inverse of [`pack`]: `(x, y, z, terrain, kind)`.
#[inline]
pub fn unpack(v: u32) -> (u32, u32, u8, u8, u32) {
    (
        v & 0xff,
        (v >> 8) & 0xff,
        (v >> 16) as u8,
        ((v >> 24) & 7) as u8,
        (v >> 27) & 3,
    )
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
    pub border_walls: u32,
}

impl LodStats {
    /// Every triangle the GPU draws for this LOD.
    pub fn emitted(&self) -> u32 {
        self.planar + self.slab + self.wall
    }
}

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ChunkStats {
    /// Vertices of the finest planar triangulation (4 corners + insertions).
    pub planar_vertices: u32,
    pub lods: [LodStats; LODS],
    /// Insertions by [`crate::fit::Cause`].
    pub causes: [u32; crate::fit::CAUSES],
}

/// One chunk's drawable data.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ChunkMesh {
    /// Packed vertices ([`pack`]), shared by all LODs.
    pub vertices: Vec<u32>,
    /// Triangle lists of all LODs, back to back.
    pub indices: Vec<u16>,
    /// `[start, end)` of each LOD's indices; LOD 0 is the finest.
    pub lods: [(u32, u32); LODS],
    pub stats: ChunkStats,
}

impl ChunkMesh {
    /// Bytes this chunk uploads to the GPU.
    pub fn gpu_bytes(&self) -> usize {
        self.vertices.len() * 4 + self.indices.len() * 2
    }

    /// The indices of one LOD.
    pub fn lod_indices(&self, lod: usize) -> &[u16] {
        let (s, e) = self.lods[lod];
        &self.indices[s as usize..e as usize]
    }
}

/// Emission scratch, reused across chunks.
#[derive(Default)]
pub struct Emitter {
    remap: Vec<u32>,
    vertices: Vec<u32>,
    indices: Vec<u16>,
    lods: [(u32, u32); LODS],
    stats: [LodStats; LODS],
}

impl Emitter {
    pub fn begin(&mut self, _sx: u32, _sy: u32) {
        self.remap.clear();
        self.vertices.clear();
        self.indices.clear();
        self.lods = [(0, 0); LODS];
        self.stats = [LodStats::default(); LODS];
    }

    #[inline]
    fn vertex(
        &mut self,
        v: u32,
        kind: u32,
        tr: &Triangulation,
        vsample: &[u32],
        samples: &ChunkSamples,
    ) -> u16 {
        let slot = v as usize * 3 + kind as usize;
        if self.remap[slot] == NONE {
            let p = tr.pt(v);
            let s = &samples.samples[vsample[v as usize] as usize];
            let (z, ty) = match kind {
                KIND_FLOOR => (s.z[0], s.lower_type),
                KIND_TOP => (s.z[2], s.upper_type),
                _ => (s.z[1], s.upper_type),
            };
            self.remap[slot] = self.vertices.len() as u32;
            self.vertices
                .push(pack(p[0] as u32, p[1] as u32, z, ty, kind));
        }
        self.remap[slot] as u16
    }

    /// Emit LOD `lod` from the current state of the triangulation.
    pub fn emit_lod(
        &mut self,
        lod: usize,
        tr: &Triangulation,
        vsample: &[u32],
        samples: &ChunkSamples,
    ) {
        self.remap.resize(tr.pts.len() * 3, NONE);
        let start = self.indices.len() as u32;
        let dual = |v: u32| samples.samples[vsample[v as usize] as usize].dual();
        let slab = |t: u32| tr.tris[t as usize].v.iter().all(|&v| dual(v));
        let mut st = LodStats::default();
        for t in 0..tr.tris.len() as u32 {
            let tri = tr.tris[t as usize];
            let [a, b, c] = tri.v;
            for v in [a, b, c] {
                let i = self.vertex(v, KIND_FLOOR, tr, vsample, samples);
                self.indices.push(i);
            }
            st.planar += 1;
            if !slab(t) {
                continue;
            }
            for v in [a, b, c] {
                let i = self.vertex(v, KIND_TOP, tr, vsample, samples);
                self.indices.push(i);
            }
            for v in [a, c, b] {
                let i = self.vertex(v, KIND_CEILING, tr, vsample, samples);
                self.indices.push(i);
            }
            st.slab += 2;
            for i in 0..3 {
                let nb = tri.n[i];
                if nb != NONE && slab(nb) {
                    continue;
                }
                let (ea, eb) = (tri.v[(i + 1) % 3], tri.v[(i + 2) % 3]);
                let za = samples.samples[vsample[ea as usize] as usize].z;
                let zb = samples.samples[vsample[eb as usize] as usize].z;
                let am = self.vertex(ea, KIND_CEILING, tr, vsample, samples);
                let ah = self.vertex(ea, KIND_TOP, tr, vsample, samples);
                let bm = self.vertex(eb, KIND_CEILING, tr, vsample, samples);
                let bh = self.vertex(eb, KIND_TOP, tr, vsample, samples);
                let mut n = 0;
                if zb[1] != zb[2] {
                    self.indices.extend([am, bm, bh]);
                    n += 1;
                }
                if za[1] != za[2] {
                    self.indices.extend([am, bh, ah]);
                    n += 1;
                }
                st.wall += n;
                if nb == NONE {
                    st.border_walls += n;
                }
            }
        }
        self.lods[lod] = (start, self.indices.len() as u32);
        self.stats[lod] = st;
    }

    /// Move the emitted data into `mesh`.
    pub fn finish(
        &mut self,
        mesh: &mut ChunkMesh,
        tr: &Triangulation,
        _vsample: &[u32],
        _samples: &ChunkSamples,
    ) {
        mesh.vertices = std::mem::take(&mut self.vertices);
        mesh.vertices.shrink_to_fit();
        mesh.indices = std::mem::take(&mut self.indices);
        mesh.indices.shrink_to_fit();
        mesh.lods = self.lods;
        mesh.stats.lods = self.stats;
        mesh.stats.planar_vertices = tr.pts.len() as u32;
    }
}
