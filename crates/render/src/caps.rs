//! What an adapter can do, read once when its device is made, and what each
//! method needs of it. A method the adapter cannot run is refused before any
//! GPU work, with the missing capability named, instead of failing wgpu
//! validation halfway through a build (WebGL2 has no compute, GL has no
//! depth-texture copies, some GLES drivers no storage buffers in vertex shaders).

use serde::Serialize;
use std::fmt;

/// One thing a method may need beyond WebGL2's baseline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Capability {
    /// Compute pipelines (the shadow map, every `*-compute` method, builds).
    ComputeShaders,
    /// Write-only `r32float` / `rgba8unorm` storage textures in compute.
    StorageTextures,
    /// Storage buffers bound to fragment shaders.
    FragmentStorage,
    /// Storage buffers bound to vertex shaders.
    VertexStorage,
    /// `R32Float` as a colour attachment (the shadow map drawn by a
    /// fragment pass where compute is missing).
    Float32Targets,
}

impl Capability {
    /// Every capability, in the order `strata adapters` prints them.
    pub const ALL: [Capability; 5] = [
        Capability::ComputeShaders,
        Capability::StorageTextures,
        Capability::FragmentStorage,
        Capability::VertexStorage,
        Capability::Float32Targets,
    ];
}

impl fmt::Display for Capability {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Capability::ComputeShaders => "compute shaders",
            Capability::StorageTextures => "storage textures",
            Capability::FragmentStorage => "storage buffers in fragment shaders",
            Capability::VertexStorage => "storage buffers in vertex shaders",
            Capability::Float32Targets => "32-bit float render targets",
        })
    }
}

/// The adapter's capabilities and the device limits Strata asked for.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Capabilities {
    /// Compute shaders.
    pub compute: bool,
    /// Write-only storage textures (compute methods write colour so).
    pub storage_textures: bool,
    /// Storage buffers in fragment shaders.
    pub fragment_storage: bool,
    /// Storage buffers in vertex shaders.
    pub vertex_storage: bool,
    /// 32-bit float colour targets.
    pub float32_targets: bool,
    /// Depth textures copy to buffers; without it depth is read back
    /// through a pass into an RGBA8 target (`depth_read.rs`).
    pub depth_copies: bool,
    /// Per-pass GPU timestamps; without them frames are timed on the CPU
    /// (submit until done).
    pub timestamps: bool,
    /// A shader reads a depth texture's texels (WGSL `textureLoad` on a
    /// `texture_depth_2d`): not through wgpu's GL backend, whose GLSL has
    /// no such load.
    pub depth_loads: bool,
    /// Largest 2D texture side, texels.
    pub max_texture_2d: u32,
    /// Most layers of a texture array.
    pub max_texture_layers: u32,
    /// Largest storage buffer binding, bytes.
    pub max_storage_binding: u64,
    /// Largest buffer, bytes.
    pub max_buffer: u64,
}

impl Capabilities {
    /// Read `adapter`'s capabilities under the device `limits` and
    /// `features` that were requested for it.
    pub fn of(adapter: &wgpu::Adapter, limits: &wgpu::Limits, features: wgpu::Features) -> Self {
        let flags = adapter.get_downlevel_capabilities().flags;
        use wgpu::DownlevelFlags as D;
        let info = adapter.get_info();
        // wgpu's GL backend reports compute on a desktop GL 3.3 context
        // that has GL_ARB_compute_shader (NVIDIA's, through EGL), but writes
        // GLSL 330, which has neither compute nor storage buffers.
        let glsl_lacks_compute =
            info.backend == wgpu::Backend::Gl && !gl_version_has_compute(&info.driver_info);
        let storage_buffers =
            limits.max_storage_buffers_per_shader_stage > 0 && !glsl_lacks_compute;
        let compute = flags.contains(D::COMPUTE_SHADERS)
            && !glsl_lacks_compute
            && limits.max_compute_workgroup_size_x >= 64
            && limits.max_compute_invocations_per_workgroup >= 64;
        let r32 = adapter.get_texture_format_features(wgpu::TextureFormat::R32Float);
        let rgba8 = adapter.get_texture_format_features(wgpu::TextureFormat::Rgba8Unorm);
        let storage_textures = compute
            && limits.max_storage_textures_per_shader_stage >= 2
            && r32
                .allowed_usages
                .contains(wgpu::TextureUsages::STORAGE_BINDING)
            && rgba8
                .allowed_usages
                .contains(wgpu::TextureUsages::STORAGE_BINDING);
        Capabilities {
            compute,
            storage_textures,
            fragment_storage: storage_buffers && flags.contains(D::FRAGMENT_STORAGE),
            vertex_storage: storage_buffers && flags.contains(D::VERTEX_STORAGE),
            float32_targets: r32
                .allowed_usages
                .contains(wgpu::TextureUsages::RENDER_ATTACHMENT),
            depth_copies: flags.contains(D::DEPTH_TEXTURE_AND_BUFFER_COPIES),
            timestamps: features.contains(wgpu::Features::TIMESTAMP_QUERY),
            depth_loads: info.backend != wgpu::Backend::Gl,
            max_texture_2d: limits.max_texture_dimension_2d,
            max_texture_layers: limits.max_texture_array_layers,
            max_storage_binding: limits.max_storage_buffer_binding_size,
            max_buffer: limits.max_buffer_size,
        }
    }

    /// Whether the adapter has `capability`.
    pub fn has(&self, capability: Capability) -> bool {
        match capability {
            Capability::ComputeShaders => self.compute,
            Capability::StorageTextures => self.storage_textures,
            Capability::FragmentStorage => self.fragment_storage,
            Capability::VertexStorage => self.vertex_storage,
            Capability::Float32Targets => self.float32_targets,
        }
    }

    /// The capabilities in `needs` this adapter lacks, in order.
    pub fn missing(&self, needs: &[Capability]) -> Vec<Capability> {
        needs.iter().copied().filter(|c| !self.has(*c)).collect()
    }

    /// How the shared shadow map is drawn here: a compute pass where the
    /// adapter has compute and storage textures, else a fragment pass into
    /// an `R32Float` target; `None` when neither is possible.
    pub fn shadow_pass(&self) -> Option<ShadowPassKind> {
        if self.compute && self.storage_textures {
            Some(ShadowPassKind::Compute)
        } else if self.float32_targets {
            Some(ShadowPassKind::Fragment)
        } else {
            None
        }
    }

    /// Everything a WebGPU adapter has (for tests that need no device).
    pub fn full() -> Self {
        let limits = wgpu::Limits::default();
        Capabilities {
            compute: true,
            storage_textures: true,
            fragment_storage: true,
            vertex_storage: true,
            float32_targets: true,
            depth_copies: true,
            timestamps: true,
            depth_loads: true,
            max_texture_2d: limits.max_texture_dimension_2d,
            max_texture_layers: limits.max_texture_array_layers,
            max_storage_binding: limits.max_storage_buffer_binding_size,
            max_buffer: limits.max_buffer_size,
        }
    }

    /// What WebGL2 offers (for tests that need no device): no compute, no
    /// storage of any kind, no depth copies, no timestamps.
    pub fn webgl2() -> Self {
        let limits = wgpu::Limits::downlevel_webgl2_defaults();
        Capabilities {
            compute: false,
            storage_textures: false,
            fragment_storage: false,
            vertex_storage: false,
            float32_targets: true,
            depth_copies: false,
            timestamps: false,
            depth_loads: false,
            max_texture_2d: limits.max_texture_dimension_2d,
            max_texture_layers: limits.max_texture_array_layers,
            max_storage_binding: 0,
            max_buffer: limits.max_buffer_size,
        }
    }
}

/// Whether a GL context of this version string (wgpu's `driver_info` on the
/// GL backend: `4.5 (Core Profile) Mesa …`, `3.3.0 NVIDIA …`, `OpenGL ES 3.2
/// …`) has compute shaders and storage buffers in its GLSL: desktop 4.3 or
/// ES 3.1 and up. An unparsable string counts as having them (wgpu decides).
pub fn gl_version_has_compute(version: &str) -> bool {
    let (es, rest) = match version.find("OpenGL ES") {
        Some(i) => (true, &version[i + "OpenGL ES".len()..]),
        None => (false, version),
    };
    let Some(number) = rest.split_whitespace().next() else {
        return true;
    };
    let mut parts = number.split('.').map(|p| p.parse::<u32>());
    let (Some(Ok(major)), Some(Ok(minor))) = (parts.next(), parts.next()) else {
        return true;
    };
    if es {
        (major, minor) >= (3, 1)
    } else {
        (major, minor) >= (4, 3)
    }
}

/// How the shadow map is drawn (see [`Capabilities::shadow_pass`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowPassKind {
    /// A compute pass writes the map.
    Compute,
    /// A fragment pass writes the map (no storage textures).
    Fragment,
}

/// Why a method cannot run on an adapter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// The method refused.
    pub method: String,
    /// What the adapter lacks for it.
    pub missing: Vec<Capability>,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<String> = self.missing.iter().map(|c| c.to_string()).collect();
        write!(
            f,
            "{}: needs {}, which this adapter lacks",
            self.method,
            names.join(" and ")
        )
    }
}

impl std::error::Error for Refusal {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gl_versions_with_and_without_compute() {
        assert!(gl_version_has_compute("4.5 (Core Profile) Mesa 22.3.6"));
        assert!(!gl_version_has_compute("3.3.0 NVIDIA 580.159.04"));
        assert!(gl_version_has_compute("OpenGL ES 3.2 NVIDIA 580.159.04"));
        assert!(!gl_version_has_compute("OpenGL ES 3.0 Mesa"));
        assert!(gl_version_has_compute("4.3.0 NVIDIA"));
        assert!(gl_version_has_compute(""));
    }
}
