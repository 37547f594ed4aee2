//! The paged mesh's index pool: one index buffer of a fixed size (its share
//! of `--gpu-budget`), fitted chunks placed first-fit in it and evicted
//! least recently drawn first. A chunk drawn by the frame being prepared is
//! never evicted for another.

use strata_mesh::{ChunkMesh, LODS};

/// A chunk in the pool.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// First index (even).
    pub start: u32,
    /// Indices held (even).
    pub len: u32,
    /// Per LOD up to two `[start, end)` ranges, relative to `start`.
    pub lods: [[(u32, u32); 2]; LODS],
    /// Altitude range of the chunk's vertices.
    pub z: (u8, u8),
    /// The last frame stamp that drew it.
    used: u32,
}

pub struct PagedPool {
    pub buffer: wgpu::Buffer,
    /// Indices the buffer holds.
    capacity: u32,
    /// Free ranges `(start, len)`, by start, neighbours merged.
    free: Vec<(u32, u32)>,
    entries: std::collections::HashMap<u32, Entry>,
    /// Chunks evicted since creation.
    pub evictions: u64,
}

const INDEX_BYTES: u64 = 2;

impl PagedPool {
    /// A pool of `bytes` (rounded down to whole 4-byte words).
    pub fn new(device: &wgpu::Device, bytes: u64) -> Self {
        let capacity = ((bytes / INDEX_BYTES) as u32) & !1;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("paged mesh index pool"),
            size: u64::from(capacity.max(2)) * INDEX_BYTES,
            usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        PagedPool {
            buffer,
            capacity,
            free: vec![(0, capacity)],
            entries: Default::default(),
            evictions: 0,
        }
    }

    /// GPU bytes of the pool.
    pub fn gpu_bytes(&self) -> u64 {
        self.buffer.size()
    }

    /// Chunk `chunk`, if held.
    pub fn get(&self, chunk: u32) -> Option<&Entry> {
        self.entries.get(&chunk)
    }

    /// Chunk `chunk` is drawn by the frame stamped `stamp`.
    pub fn touch(&mut self, chunk: u32, stamp: u32) {
        if let Some(e) = self.entries.get_mut(&chunk) {
            e.used = stamp;
        }
    }

    /// Drop `chunk`.
    pub fn remove(&mut self, chunk: u32) {
        if let Some(e) = self.entries.remove(&chunk) {
            self.release(e.start, e.len);
        }
    }

    /// Place `mesh` as `chunk` at frame `stamp`, evicting chunks not drawn
    /// by that frame, oldest first; `false` when it cannot fit.
    pub fn insert(
        &mut self,
        queue: &wgpu::Queue,
        chunk: u32,
        mesh: &ChunkMesh,
        z: (u8, u8),
        stamp: u32,
    ) -> bool {
        self.remove(chunk);
        let mut data = mesh.indices.clone();
        if data.len() % 2 == 1 {
            data.push(0);
        }
        let need = data.len() as u32;
        if need > self.capacity {
            return false;
        }
        let start = loop {
            if let Some(start) = self.allocate(need) {
                break start;
            }
            let oldest = self
                .entries
                .iter()
                .filter(|(_, e)| e.used != stamp)
                .max_by_key(|(c, e)| (stamp.wrapping_sub(e.used), **c))
                .map(|(c, _)| *c);
            let Some(old) = oldest else {
                return false;
            };
            self.remove(old);
            self.evictions += 1;
        };
        if !data.is_empty() {
            queue.write_buffer(
                &self.buffer,
                u64::from(start) * INDEX_BYTES,
                bytemuck::cast_slice(&data),
            );
        }
        self.entries.insert(
            chunk,
            Entry {
                start,
                len: need,
                lods: mesh.lods,
                z,
                used: stamp,
            },
        );
        true
    }

    /// First fit of `need` indices.
    fn allocate(&mut self, need: u32) -> Option<u32> {
        if need == 0 {
            return Some(0);
        }
        let k = self.free.iter().position(|&(_, len)| len >= need)?;
        let (start, len) = self.free[k];
        if len == need {
            self.free.remove(k);
        } else {
            self.free[k] = (start + need, len - need);
        }
        Some(start)
    }

    fn release(&mut self, start: u32, len: u32) {
        if len == 0 {
            return;
        }
        let k = self.free.partition_point(|&(s, _)| s < start);
        self.free.insert(k, (start, len));
        // Merge with the next, then with the previous.
        if k + 1 < self.free.len() && self.free[k].0 + self.free[k].1 == self.free[k + 1].0 {
            self.free[k].1 += self.free[k + 1].1;
            self.free.remove(k + 1);
        }
        if k > 0 && self.free[k - 1].0 + self.free[k - 1].1 == self.free[k].0 {
            self.free[k - 1].1 += self.free[k].1;
            self.free.remove(k);
        }
    }
}
