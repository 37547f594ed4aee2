//! The bindings both GPU pyramid builds share (the voxel occupancy pyramid
//! and the ray-exact max pyramid): the storage buffer the build writes
//! (binding 1) and a ring of uniform parameter slots, one per dispatch of a
//! submission, read at a dynamic offset (binding 0).

/// The pyramid buffer, its parameter slots and their bind group.
pub(crate) struct BuildBindings {
    pub buffer: wgpu::Buffer,
    pub slots: wgpu::Buffer,
    /// Bytes between slots: the parameters rounded up to the uniform offset alignment.
    pub slot_stride: u64,
    pub group_layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
}

impl BuildBindings {
    /// `bytes` of pyramid (`buffer_label`) and `slot_count` slots of
    /// `params_size` bytes; `label` names the slots, layout and group.
    pub fn new(
        device: &wgpu::Device,
        buffer_label: &str,
        label: &str,
        bytes: u64,
        params_size: u64,
        slot_count: usize,
    ) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(buffer_label),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let slot_stride = params_size.next_multiple_of(u64::from(
            device.limits().min_uniform_buffer_offset_alignment,
        ));
        let slots = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{label} params")),
            size: slot_stride * slot_count as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(params_size),
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
            ],
        });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &group_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &slots,
                        offset: 0,
                        size: wgpu::BufferSize::new(params_size),
                    }),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: buffer.as_entire_binding(),
                },
            ],
        });
        BuildBindings {
            buffer,
            slots,
            slot_stride,
            group_layout,
            group,
        }
    }
}
