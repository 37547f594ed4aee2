// Tests only: trace given rays with the exact march (`ray_exact_core.wgsl`)
// and return what the CPU reference's `Tracer::trace` returns: hit, distance
// along the unit ray, class, and the hit column.
#include "frame.wgsl"
#include "surface.wgsl"
#include "ray_exact_core.wgsl"

struct TestRay {
    // xyz origin (world), w t_max
    origin: vec4<f32>,
    // xyz unit direction
    dir: vec4<f32>,
}

struct TestHit {
    // x distance (-1 at a miss), y class (HitClass code), z column x, w column y
    v: vec4<f32>,
}

@group(2) @binding(0) var<storage, read> rays: array<TestRay>;
@group(2) @binding(1) var<storage, read_write> hits: array<TestHit>;

@compute @workgroup_size(64, 1, 1)
fn cs_trace(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[id.x];
    let d = ray.dir.xyz;
    let seg = exact_clip(ray.origin.xyz, d, 0.0, ray.origin.w);
    var out: TestHit;
    out.v = vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    if (seg.x <= seg.y) {
        let p = ray.origin.xyz + d * seg.x;
        let base = exact_base(p.xy);
        let o = vec3<f32>(p.xy - vec2<f32>(base), p.z);
        let h = exact_march(o, base, d, 0.0, seg.y - seg.x);
        if (h.hit) {
            out.v = vec4<f32>(seg.x + h.t, f32(h.hit_class), f32(h.column.x), f32(h.column.y));
        }
    }
    hits[id.x] = out;
}
