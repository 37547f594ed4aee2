// Paged terrain (`paged/`): the world lives in fixed-size pages of 256x256
// texels, a few of them resident in the terrain texture (the atlas) at a time.
// Shared by `paged_fetch.wgsl` and `paged_levels.wgsl`, which a paged shader
// puts in place of `terrain_fetch.wgsl` and `exact_levels.wgsl`. Needs
// `ray_exact_core.wgsl` (xparams: the frame's stamp) and `frame.wgsl`.
//
// A chunk that is not resident reads as its coarse-level box: every column as
// high as the chunk's highest top (`paged_chunk_top`), so a ray can stop on it
// but never passes through terrain it has not seen: no sky through a missing
// page. A ray that goes down into such a chunk marks the pixel pending and
// asks for the page (once per chunk and frame).
#include "frame.wgsl"

// Twin of `paged::gpu::PagedParams`.
struct PagedParams {
    // x log2 chunks across, y first byte of the slot pyramids in `maxmip`
    // (after the chunk tops), z bytes per slot pyramid, w request list length
    grid: vec4<u32>,
    // x log2 pages across an atlas layer, y log2 pages per layer, z first word
    // of the slot stamps in `page_feedback`, w first word of the chunk stamps
    atlas: vec4<u32>,
    // first byte of page pyramid level k within a slot's pyramid, at
    // [k / 4][k % 4]
    offsets: array<vec4<u32>, 2>,
    // level of detail: x pixels of footprint per unit of a camera ray's t
    // (1 / the LOD's pixel tolerance; 0: off), y the same per shadow-map
    // texel, z/w unused
    lod: vec4<f32>,
    // the first page id of level k, at [k / 4][k % 4] (level 0: the chunks);
    // [2].w: the coarsest level kept
    lod_pages: array<vec4<u32>, 3>,
}

// Per page (the chunks, then each coarser level's pages): its slot + 1, 0
// while not resident.
@group(1) @binding(9) var<storage, read> page_table: array<u32>;
// [0] pending pixels, [1] requests, [2] pending shadow texels, [3 ..) the
// requested pages, then one
// stamp per slot (the last frame that read it) and one per page (the last
// frame that asked for it).
@group(1) @binding(10) var<storage, read_write> page_feedback: array<atomic<u32>>;
// A storage buffer, not a uniform: lavapipe (Mesa 22.3) specialises shaders
// on the values of small uniform buffers that steer their control flow, and
// the march over pages took it to a crash there (every GPU reads it as
// cheaply either way).
@group(1) @binding(11) var<storage, read> paged: PagedParams;
// The coarse level and the slot pyramids, bytes in words.
@group(1) @binding(1) var<storage, read> maxmip: array<u32>;

// The level of detail the exact march reads columns at now
// (`paged_levels.wgsl`'s `exact_leaf`; 0: the map's texels).
var<private> page_lod: u32 = 0u;

// Whether this invocation read a chunk that was not resident.
var<private> page_missed: bool;
// The last chunk this invocation looked up and its table entry: a ray reads
// one chunk many times in a row (every level and column inside it), and the
// table read and slot stamp are then paid once per chunk, not per fetch.
// (On the H100 class, the default world's views drew in 1.84x the
// whole-world time with a lookup per fetch.)
var<private> page_cached_chunk: u32 = 0xffffffffu;
var<private> page_cached_entry: u32 = 0u;

fn page_pixel_begin() {
    page_missed = false;
}

fn page_pixel_missed() -> bool {
    return page_missed;
}

fn paged_byte(i: u32) -> u32 {
    return (maxmip[i >> 2u] >> ((i & 3u) << 3u)) & 0xffu;
}

// The highest top of `chunk` (always resident).
fn paged_chunk_top(chunk: u32) -> u32 {
    return paged_byte(chunk);
}

// The page of level `level` holding its texel (bx, by) (already wrapped to
// the level's size: the map's halved `level` times).
fn paged_page(level: u32, bx: u32, by: u32) -> u32 {
    let first = paged.lod_pages[level >> 2u][level & 3u];
    return first + (bx >> 8u) + ((by >> 8u) << (paged.grid.x - level));
}

// The pair texel of slot `slot` holding texel (bx, by) of its page: slot s
// of the atlas is page (s mod across, s / across) of layer s / per-layer,
// 128 pair texels x 256 rows.
fn paged_atlas_texel(slot: u32, bx: u32, by: u32) -> vec4<u32> {
    let layer = slot >> paged.atlas.y;
    let in_layer = slot & ((1u << paged.atlas.y) - 1u);
    let page = vec2<u32>(in_layer & ((1u << paged.atlas.x) - 1u), in_layer >> paged.atlas.x);
    let local = vec2<u32>((bx & 255u) >> 1u, by & 255u);
    return textureLoad(terrain, page * vec2<u32>(128u, 256u) + local, layer, 0);
}

// The chunk (level-0 page) holding texel (bx, by) of level `level` (<= 8).
fn paged_chunk_of(level: u32, bx: u32, by: u32) -> u32 {
    let s = 8u - level;
    return (bx >> s) + ((by >> s) << paged.grid.x);
}

// Page `chunk`'s slot + 1 (a chunk's, or a coarser level's page), or 0
// after asking for it.
fn paged_slot(chunk: u32) -> u32 {
    if (chunk == page_cached_chunk) {
        if (page_cached_entry == 0u) {
            page_missed = true;
        }
        return page_cached_entry;
    }
    let e = page_table[chunk];
    page_cached_chunk = chunk;
    page_cached_entry = e;
    let stamp = xparams.config.z;
    if (e == 0u) {
        page_missed = true;
        let s = paged.atlas.w + chunk;
        // Most rays find it asked for already: read before the exchange.
        if (atomicLoad(&page_feedback[s]) != stamp && atomicExchange(&page_feedback[s], stamp) != stamp) {
            let n = atomicAdd(&page_feedback[1], 1u);
            if (n < paged.grid.w) {
                atomicStore(&page_feedback[3u + n], chunk);
            }
        }
    } else {
        let u = paged.atlas.z + e - 1u;
        if (atomicLoad(&page_feedback[u]) != stamp) {
            atomicStore(&page_feedback[u], stamp);
        }
    }
    return e;
}

// Count the pixel as pending when it read a missing chunk.
fn page_pixel_end(missed: bool) {
    if (missed) {
        atomicAdd(&page_feedback[0], 1u);
    }
}

// Count a shadow-map texel cast through a missing chunk (the pixels that
// sample it are not marked: the frame is not converged while any is).
fn page_shadow_end(missed: bool) {
    if (missed) {
        atomicAdd(&page_feedback[2], 1u);
    }
}
