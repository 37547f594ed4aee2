//! glTF 2.0: one mesh, one primitive with `POSITION` (f32), `COLOR_0`
//! (normalised RGBA8) and u32 indices, in one buffer; written as binary GLB
//! (`.glb`: the JSON and the buffer in one container) or as `.gltf` JSON
//! with the buffer embedded as a base64 data URI (one self-contained file).

use crate::soup::TerrainSoup;
use serde_json::json;
use std::io::Write;

/// y-up: the texel frame's (x, y, z) as (x, z, -y).
fn y_up(p: [f32; 3]) -> [f32; 3] {
    [p[0], p[2], -p[1]]
}

fn pad4(v: &mut Vec<u8>, byte: u8) {
    while !v.len().is_multiple_of(4) {
        v.push(byte);
    }
}

/// The glTF document (its buffer's `uri` left out) and the binary buffer.
fn document(soup: &TerrainSoup) -> (serde_json::Value, Vec<u8>) {
    let n = soup.positions.len();
    let mut bin: Vec<u8> = Vec::with_capacity(n * 16 + soup.triangles.len() * 12);
    let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
    for &p in &soup.positions {
        let q = y_up(p);
        for k in 0..3 {
            lo[k] = lo[k].min(q[k]);
            hi[k] = hi[k].max(q[k]);
            bin.extend_from_slice(&q[k].to_le_bytes());
        }
    }
    let colors_at = bin.len();
    for c in &soup.colors {
        bin.extend_from_slice(c);
    }
    let indices_at = bin.len();
    for t in &soup.triangles {
        for i in t {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    let bin_len = bin.len();
    pad4(&mut bin, 0);
    let doc = json!({
        "asset": { "version": "2.0", "generator": "strata export" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0, "name": "terrain" }],
        "meshes": [{
            "name": "terrain",
            "primitives": [{
                "attributes": { "POSITION": 0, "COLOR_0": 1 },
                "indices": 2,
                "mode": 4
            }]
        }],
        "buffers": [{ "byteLength": bin_len }],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": colors_at, "target": 34962 },
            { "buffer": 0, "byteOffset": colors_at, "byteLength": indices_at - colors_at, "target": 34962 },
            { "buffer": 0, "byteOffset": indices_at, "byteLength": bin_len - indices_at, "target": 34963 }
        ],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi },
            { "bufferView": 1, "componentType": 5121, "normalized": true, "count": n, "type": "VEC4" },
            { "bufferView": 2, "componentType": 5125, "count": soup.triangles.len() * 3, "type": "SCALAR" }
        ],
        "extras": { "max_error": soup.max_error, "frame": "x east, y up (altitude), z = -north; 1 unit = 1 texel" }
    });
    (doc, bin)
}

/// `.gltf`: the JSON document with the buffer as a base64 data URI.
pub fn write_json(soup: &TerrainSoup, out: &mut impl Write) -> std::io::Result<()> {
    use base64::Engine as _;
    let (mut doc, bin) = document(soup);
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bin)
    );
    doc["buffers"][0]["uri"] = json!(uri);
    serde_json::to_writer(&mut *out, &doc).map_err(std::io::Error::other)?;
    out.flush()
}

/// `.glb`: the binary container (JSON chunk, BIN chunk).
pub fn write_binary(soup: &TerrainSoup, out: &mut impl Write) -> std::io::Result<()> {
    let (doc, bin) = document(soup);
    let mut json_bytes = serde_json::to_vec(&doc).map_err(std::io::Error::other)?;
    pad4(&mut json_bytes, b' ');
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let total = u32::try_from(total)
        .map_err(|_| std::io::Error::other("the mesh exceeds glTF's 4 GiB binary limit"))?;
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json_bytes.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&json_bytes)?;
    out.write_all(&(bin.len() as u32).to_le_bytes())?;
    out.write_all(b"BIN\0")?;
    out.write_all(&bin)?;
    out.flush()
}
