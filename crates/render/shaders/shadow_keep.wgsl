// `ray-exact`'s shadow blocks kept across frames. The map's texels lie on a
// lattice fixed to the light (`frame.wgsl`'s `shadow_texel_centre`), stored
// at their lattice index wrapped to the map's side (`shadow_slot`), and the
// map's square moves over the lattice in whole 8x8-texel blocks. So an 8x8
// block the shadow pass cast in an earlier frame holds what casting it now
// would store, as long as the texture's slot still holds that lattice block,
// the texel size and the plane are the same, and neither the terrain nor
// anything else that writes the map has changed it. The shadow pass tags
// each block it casts with its lattice block and the frame's key; the CPU
// changes the key whenever one of those conditions breaks
// (`ray_exact::ShadowKeep`), and a key of 0 keeps nothing. A march then
// lists only the blocks its pixels read that are not kept.
//
// The tags follow the list in `shadow_blocks` (the includer's binding, the
// march's and the shadow pass's): three words per slot block (key, lattice
// block x, lattice block y), slot blocks row by row.

// This frame's map block `b`'s lattice block (the lattice origin is a
// multiple of 8, so the division is exact).
fn shadow_lattice_block(b: vec2<i32>) -> vec2<i32> {
    return b + globals.shadow_lattice.xy / 8;
}

// The first word of the tag of the slot block that holds lattice block `lb`.
fn shadow_keep_tag(lb: vec2<i32>) -> u32 {
    let blocks = u32(globals.shadow_u.w) / 8u;
    let slot = vec2<u32>(lb & vec2<i32>(i32(blocks) - 1));
    return blocks * blocks + 3u * (slot.y * blocks + slot.x);
}

// Whether map block `b` (8x8 texels) holds what this frame would cast there.
fn shadow_block_kept(b: vec2<i32>) -> bool {
    let key = xparams.shadow_keep.x;
    if (key == 0u) {
        return false;
    }
    let lb = shadow_lattice_block(b);
    let tag = shadow_keep_tag(lb);
    return shadow_blocks[tag] == key && shadow_blocks[tag + 1u] == u32(lb.x)
        && shadow_blocks[tag + 2u] == u32(lb.y);
}

// Tag map block `b` as cast this frame.
fn shadow_block_keep(b: vec2<u32>) {
    let lb = shadow_lattice_block(vec2<i32>(b));
    let tag = shadow_keep_tag(lb);
    shadow_blocks[tag] = xparams.shadow_keep.x;
    shadow_blocks[tag + 1u] = u32(lb.x);
    shadow_blocks[tag + 2u] = u32(lb.y);
}
