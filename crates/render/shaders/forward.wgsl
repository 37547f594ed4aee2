// Shared by the object-order methods `painted` and `sliced`: the camera's
// ground footprint and the order that walks it away from the eye.
// Rust twin: `methods::forward::FootprintParams`.

struct Footprint {
    // x, y of the first sample (unwrapped texels); z 0: rows run along x,
    // 1: rows run along y
    origin: vec4<i32>,
    // rows, samples per row, the eye's row, the eye's sample within a row
    size: vec4<u32>,
    // samples drawn, then method-specific words
    count: vec4<u32>,
}

// Rank `rank` of the order that starts at `centre` and alternates outwards
// over 0..count, so lower ranks are nearer (twin of `forward::outward`).
fn outward(rank: u32, centre: u32, count: u32) -> u32 {
    let below = centre;
    let above = count - 1u - centre;
    let m = min(below, above);
    if (rank == 0u) {
        return centre;
    }
    if (rank <= 2u * m) {
        let k = (rank + 1u) / 2u;
        return select(centre - k, centre + k, (rank & 1u) == 1u);
    }
    if (above > below) {
        return centre + rank - m;
    }
    return centre - (rank - m);
}

// The texel (unwrapped world coordinates) of the footprint's `i`-th sample,
// rows nearest the eye first, and within a row nearest the eye first.
fn footprint_cell(f: Footprint, i: u32) -> vec2<i32> {
    let row = outward(i / f.size.y, f.size.z, f.size.x);
    let col = outward(i % f.size.y, f.size.w, f.size.y);
    if (f.origin.z == 0) {
        return f.origin.xy + vec2<i32>(i32(col), i32(row));
    }
    return f.origin.xy + vec2<i32>(i32(row), i32(col));
}
