// `maxmip_get` over pages (swapped in for `exact_levels.wgsl`): the 256-texel
// level is the always-resident coarse level (one byte per chunk); finer levels
// live in the resident page's own pyramid, and a missing page reads as its
// chunk's top (a conservative box: see `paged.wgsl`).
#include "frame.wgsl"
#include "paged.wgsl"

fn maxmip_get(k: u32, tx: i32, ty: i32) -> f32 {
    let ux = u32(tx) & ((globals.level.x >> k) - 1u);
    let uy = u32(ty) & ((globals.level.y >> k) - 1u);
    let s = 8u - k;
    let chunk = (ux >> s) + ((uy >> s) << paged.grid.x);
    if (k >= 8u) {
        return f32(paged_chunk_top(chunk));
    }
    let e = paged_slot(chunk);
    if (e == 0u) {
        return f32(paged_chunk_top(chunk));
    }
    let side = 256u >> k;
    let local = (ux & (side - 1u)) + (uy & (side - 1u)) * side;
    let offset = paged.offsets[k >> 2u][k & 3u];
    return f32(paged_byte(paged.grid.y + (e - 1u) * paged.grid.z + offset + local));
}
