//! The mesh method's GPU index pool: every chunk's three LODs (the mesh
//! crate's compact u16 indices, LOD ranges by membership blocks) in one
//! index buffer, one slot per chunk. A refitted chunk is written back into
//! its slot when it fits, else into a freed slot or the free tail; only when
//! the tail is exhausted does the buffer grow, by a GPU-side copy.

use strata_mesh::{ChunkMesh, LODS};

/// Where one chunk's indices live and what to draw of each LOD.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Slot {
    /// First index of the slot in the pool (even: 4-byte aligned writes).
    pub start: u32,
    /// Indices the slot can hold (even).
    pub capacity: u32,
    /// Per LOD up to two `[start, end)` ranges, relative to `start`.
    pub lods: [[(u32, u32); 2]; LODS],
    /// Altitude range of the chunk's vertices (for culling and LOD distance).
    pub z: (u8, u8),
}

pub struct IndexPool {
    pub buffer: wgpu::Buffer,
    /// Indices the buffer holds.
    capacity: u32,
    /// First index past the last slot.
    tail: u32,
    /// Freed slots `(start, capacity)`, reused first-fit.
    free: Vec<(u32, u32)>,
}

const INDEX_BYTES: u64 = 2;

/// A fitted chunk and the altitude range of its vertices.
pub type Fitted = (ChunkMesh, (u8, u8));

fn even(n: u32) -> u32 {
    n + (n & 1)
}

fn create_buffer(device: &wgpu::Device, indices: u32) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("mesh index pool"),
        size: u64::from(indices.max(2)) * INDEX_BYTES,
        usage: wgpu::BufferUsages::INDEX
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

/// The chunk's indices padded to an even count (write_buffer needs whole
/// 4-byte words).
fn padded(mesh: &ChunkMesh) -> Vec<u16> {
    let mut data = mesh.indices.clone();
    if data.len() % 2 == 1 {
        data.push(0);
    }
    data
}

impl IndexPool {
    /// Upload every chunk into one buffer with `headroom` spare indices at
    /// the tail for refits that grow. Returns the pool and the slots.
    pub fn build(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        chunks: &[Fitted],
        headroom: u32,
    ) -> anyhow::Result<(Self, Vec<Slot>)> {
        let mut slots = Vec::with_capacity(chunks.len());
        let mut total: u64 = 0;
        for (mesh, z) in chunks {
            let capacity = even(mesh.indices.len() as u32);
            slots.push(Slot {
                start: total as u32,
                capacity,
                lods: mesh.lods,
                z: *z,
            });
            total += u64::from(capacity);
        }
        let capacity = total + u64::from(headroom);
        let max = device.limits().max_buffer_size / INDEX_BYTES;
        if capacity > max.min(u64::from(u32::MAX)) {
            anyhow::bail!(
                "the mesh needs {capacity} indices ({} MiB), over this adapter's {} MiB buffer limit; lower --mesh-quality",
                (capacity * INDEX_BYTES) >> 20,
                device.limits().max_buffer_size >> 20
            );
        }
        let mut pool = IndexPool {
            buffer: create_buffer(device, capacity as u32),
            capacity: capacity as u32,
            tail: total as u32,
            free: Vec::new(),
        };
        // One staging copy for the whole level, not one write per chunk.
        let mut all = Vec::with_capacity(total as usize);
        for (mesh, _) in chunks {
            all.extend_from_slice(&padded(mesh));
        }
        if !all.is_empty() {
            queue.write_buffer(&pool.buffer, 0, bytemuck::cast_slice(&all));
        }
        pool.free.shrink_to_fit();
        Ok((pool, slots))
    }

    /// Replace `slot`'s data with `mesh`, in place when it fits.
    pub fn replace(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        slot: &mut Slot,
        mesh: &ChunkMesh,
        z: (u8, u8),
    ) {
        let data = padded(mesh);
        let need = data.len() as u32;
        if need > slot.capacity {
            self.free.push((slot.start, slot.capacity));
            let (start, capacity) = self.allocate(device, queue, need);
            slot.start = start;
            slot.capacity = capacity;
        }
        if !data.is_empty() {
            queue.write_buffer(
                &self.buffer,
                u64::from(slot.start) * INDEX_BYTES,
                bytemuck::cast_slice(&data),
            );
        }
        slot.lods = mesh.lods;
        slot.z = z;
    }

    /// A free range of at least `need` (even) indices.
    fn allocate(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, need: u32) -> (u32, u32) {
        if let Some(k) = self.free.iter().position(|&(_, c)| c >= need) {
            return self.free.swap_remove(k);
        }
        if self.capacity - self.tail < need {
            // Tail exhausted: grow by half (at least `need`), copying on the
            // GPU; the CPU re-uploads nothing.
            let grown = self.capacity + (self.capacity / 2).max(need);
            let buffer = create_buffer(device, grown);
            let mut encoder = device.create_command_encoder(&Default::default());
            encoder.copy_buffer_to_buffer(
                &self.buffer,
                0,
                &buffer,
                0,
                u64::from(self.tail) * INDEX_BYTES,
            );
            queue.submit([encoder.finish()]);
            self.buffer = buffer;
            self.capacity = grown;
        }
        let start = self.tail;
        self.tail += need;
        (start, need)
    }

    pub fn gpu_bytes(&self) -> u64 {
        self.buffer.size()
    }

    pub fn cpu_bytes(&self) -> u64 {
        (self.free.capacity() * std::mem::size_of::<(u32, u32)>()) as u64
    }
}
