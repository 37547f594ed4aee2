//! A store read over HTTP, one object at a time (issue 34: the browser
//! streams worlds): the keys of its objects, its metadata checked from the
//! `zarr.json` texts, and a fetched chunk object decoded from its bytes.
//! No zarrs and no I/O here: the caller fetches (a browser's `fetch`, with
//! its own cancellation) and hands the bytes over, so this runs anywhere,
//! and a native test checks it against chunks zarrs wrote.
//!
//! The store's codec chain is fixed (crate docs): `bytes` (little endian)
//! -> `gzip` -> `crc32c`, so a chunk object is a gzip member followed by the
//! CRC-32C of those gzip bytes, 4 bytes little endian. [`check_array`]
//! refuses any other chain, so a store written otherwise is named, not
//! misread.

use crate::error::StoreError;
use crate::format::{
    ATTR, FORMAT_NAME, FORMAT_VERSION, LOD_ATTR, SUMMARY, SUMMARY_FIELDS, WorldAttrs,
};
use std::io::Read;

/// The object key of chunk `cell` of array `array` (Zarr v3's default
/// chunk key encoding with `/`): `heights/c/3/1`.
pub fn chunk_key(array: &str, cell: &[u64]) -> String {
    let mut key = format!("{array}/c");
    for c in cell {
        key.push('/');
        key.push_str(&c.to_string());
    }
    key
}

/// Decode chunk `cell` of `array` from its object's bytes: the checksum
/// checked, the gzip member inflated, its length `expected`. A truncated
/// or corrupt object is an error naming the array and chunk.
pub fn decode_chunk(
    array: &str,
    cell: &[u64],
    bytes: &[u8],
    expected: usize,
) -> Result<Vec<u8>, StoreError> {
    let fail = |msg: String| StoreError::chunk(array, cell, msg);
    if bytes.len() < 4 + 18 {
        return Err(fail(format!(
            "{} bytes: too short for a gzip member and its checksum (truncated?)",
            bytes.len()
        )));
    }
    let (body, sum) = bytes.split_at(bytes.len() - 4);
    let stored = u32::from_le_bytes([sum[0], sum[1], sum[2], sum[3]]);
    let computed = crc32c::crc32c(body);
    if stored != computed {
        return Err(fail(format!(
            "checksum mismatch (stored crc32c {stored:08x}, computed {computed:08x}): corrupt or truncated"
        )));
    }
    let mut out = Vec::with_capacity(expected);
    flate2::read::GzDecoder::new(body)
        .take(expected as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| fail(format!("gzip: {e}")))?;
    if out.len() != expected {
        return Err(fail(format!(
            "{} bytes decoded, expected {expected}",
            out.len()
        )));
    }
    Ok(out)
}

/// The world's attributes from the root `zarr.json` text (`what` names the
/// store in errors): a Strata world of a version this build reads, whose
/// sizes are powers of two.
pub fn world_attrs(what: &str, root_json: &[u8]) -> Result<WorldAttrs, StoreError> {
    let not_world = |msg: String| StoreError::NotAWorld {
        what: what.into(),
        msg,
    };
    let json: serde_json::Value = serde_json::from_slice(root_json)
        .map_err(|e| not_world(format!("its zarr.json is not JSON: {e}")))?;
    if json.get("node_type").and_then(|t| t.as_str()) != Some("group") {
        return Err(not_world("its zarr.json is not a Zarr v3 group".into()));
    }
    let raw = json
        .pointer(&format!("/attributes/{ATTR}"))
        .ok_or_else(|| {
            not_world(format!(
                "a Zarr group without a `{ATTR}` attribute: not a Strata world"
            ))
        })?;
    check_attrs(what, raw)
}

/// The world's attributes from the root group's `strata` attribute: a
/// Strata world of a version this build reads, whose map and chunk sides
/// are powers of two, chunks even and inside the map.
pub(crate) fn check_attrs(what: &str, raw: &serde_json::Value) -> Result<WorldAttrs, StoreError> {
    let not_world = |msg: String| StoreError::NotAWorld {
        what: what.into(),
        msg,
    };
    if raw.get("format").and_then(|f| f.as_str()) != Some(FORMAT_NAME) {
        return Err(not_world(format!(
            "its `{ATTR}.format` attribute is not \"{FORMAT_NAME}\": not a Strata world"
        )));
    }
    let version = raw
        .get("format_version")
        .and_then(|v| v.as_u64())
        .ok_or_else(|| not_world(format!("no `{ATTR}.format_version` attribute")))?;
    if version > u64::from(FORMAT_VERSION) {
        return Err(StoreError::NewerVersion {
            what: what.into(),
            found: u32::try_from(version).unwrap_or(u32::MAX),
            supported: FORMAT_VERSION,
        });
    }
    let attrs: WorldAttrs = serde_json::from_value(raw.clone())
        .map_err(|e| not_world(format!("its `{ATTR}` attribute is malformed: {e}")))?;
    let (w, h) = (attrs.width, attrs.height);
    let [ch, cw] = attrs.chunk;
    let ok = w.is_power_of_two()
        && h.is_power_of_two()
        && w >= 2
        && ch.is_power_of_two()
        && cw.is_power_of_two()
        && cw >= 2
        && ch <= h
        && cw <= w;
    if !ok {
        return Err(not_world(format!(
            "map {w}x{h} with chunks {cw}x{ch}: sizes must be powers of two, chunks even and inside the map"
        )));
    }
    Ok(attrs)
}

/// Check an array's `zarr.json` text: its data type, shape, regular chunk
/// shape, and the codec chain this module decodes.
pub fn check_array(
    name: &str,
    json: &[u8],
    dtype: &str,
    shape: &[u64],
    chunk: &[u64],
) -> Result<(), StoreError> {
    let json: serde_json::Value = serde_json::from_slice(json)
        .map_err(|e| StoreError::array(name, format!("its zarr.json is not JSON: {e}")))?;
    let found = json
        .get("data_type")
        .and_then(|d| d.as_str())
        .unwrap_or("?");
    if found != dtype {
        return Err(StoreError::array(
            name,
            format!("data type {found}, expected {dtype}"),
        ));
    }
    let got = |pointer: &str| {
        json.pointer(pointer)
            .and_then(|s| serde_json::from_value::<Vec<u64>>(s.clone()).ok())
    };
    if got("/shape").as_deref() != Some(shape) {
        return Err(StoreError::array(
            name,
            format!("shape {:?}, expected {shape:?}", got("/shape")),
        ));
    }
    let grid = got("/chunk_grid/configuration/chunk_shape");
    if grid.as_deref() != Some(chunk) {
        return Err(StoreError::array(
            name,
            format!("chunk shape {grid:?}, expected {chunk:?} (a regular grid)"),
        ));
    }
    let separator = json
        .pointer("/chunk_key_encoding/configuration/separator")
        .and_then(|s| s.as_str());
    let default_keys = json
        .pointer("/chunk_key_encoding/name")
        .and_then(|s| s.as_str())
        == Some("default");
    if !default_keys || separator != Some("/") {
        return Err(StoreError::array(
            name,
            "chunk keys are not Zarr v3's default `c/…` with `/`",
        ));
    }
    let codecs: Vec<String> = json
        .get("codecs")
        .and_then(|c| c.as_array())
        .map(|c| {
            c.iter()
                .map(|c| {
                    let name = c.get("name").and_then(|n| n.as_str()).unwrap_or("?");
                    let endian = c
                        .pointer("/configuration/endian")
                        .and_then(|e| e.as_str())
                        .unwrap_or("little");
                    if name == "bytes" && endian != "little" {
                        format!("bytes ({endian} endian)")
                    } else {
                        name.to_string()
                    }
                })
                .collect()
        })
        .unwrap_or_default();
    if codecs != ["bytes", "gzip", "crc32c"] {
        return Err(StoreError::array(
            name,
            format!(
                "codecs {codecs:?}; a store read over HTTP needs bytes (little endian), gzip, crc32c"
            ),
        ));
    }
    Ok(())
}

/// The summary array's shape and chunk shape for a grid of `gy` x `gx`
/// chunks (as [`crate::WorldStore`] writes them).
pub fn summary_shape(gy: u64, gx: u64) -> ([u64; 3], [u64; 3]) {
    let f = SUMMARY_FIELDS as u64;
    ([gy, gx, f], [gy.min(64), gx.min(64), f])
}

/// The summary array's chunk cells, row-major.
pub fn summary_cells(gy: u64, gx: u64) -> Vec<[u64; 3]> {
    let (_, [sy, sx, _]) = summary_shape(gy, gx);
    let mut cells = Vec::new();
    for by in 0..gy.div_ceil(sy) {
        for bx in 0..gx.div_ceil(sx) {
            cells.push([by, bx, 0]);
        }
    }
    cells
}

/// Every chunk's highest top (`top_max`, row-major over the grid: the
/// paged renderer's coarse level) from the summary array's chunk objects,
/// `objects[i]` being [`summary_cells`]`[i]`'s bytes.
pub fn chunk_tops(gy: u64, gx: u64, objects: &[Vec<u8>]) -> Result<Vec<u8>, StoreError> {
    let cells = summary_cells(gy, gx);
    if objects.len() != cells.len() {
        return Err(StoreError::array(
            SUMMARY,
            format!("{} chunk objects for {} chunks", objects.len(), cells.len()),
        ));
    }
    let (_, [sy, sx, f]) = summary_shape(gy, gx);
    let mut tops = vec![0u8; (gy * gx) as usize];
    for (cell, bytes) in cells.iter().zip(objects) {
        let raw = decode_chunk(SUMMARY, cell, bytes, (sy * sx * f * 4) as usize)?;
        for y in 0..sy {
            for x in 0..sx {
                let (cy, cx) = (cell[0] * sy + y, cell[1] * sx + x);
                if cy >= gy || cx >= gx {
                    continue;
                }
                let at = (((y * sx + x) * f + 3) * 4) as usize;
                let top = u32::from_le_bytes([raw[at], raw[at + 1], raw[at + 2], raw[at + 3]]);
                tops[(cy * gx + cx) as usize] = u8::try_from(top).map_err(|_| {
                    StoreError::chunk(
                        SUMMARY,
                        cell,
                        format!("top of chunk ({cx}, {cy}) is {top}, above 255"),
                    )
                })?;
            }
        }
    }
    Ok(tops)
}

/// The world without its map (a 2x1 stand-in level, as
/// `WorldStore::world_shell`) from its attributes; water levels
/// from the attributes (the `.vpr` bytes are not fetched).
pub fn world_shell(what: &str, attrs: &WorldAttrs) -> Result<strata_level::World, StoreError> {
    let stand_in = strata_level::Level::flat(2, 1, 0, 0).expect("2x1 is a valid map size");
    crate::format::world_from_attrs(what, attrs, stand_in, None)
}

/// Complete level-of-detail levels from the `lod` group's `zarr.json` text
/// (`None`: no such group, which means none).
pub fn lod_levels(lod_json: Option<&[u8]>) -> u32 {
    lod_json
        .and_then(|j| serde_json::from_slice::<serde_json::Value>(j).ok())
        .and_then(|j| {
            j.pointer(&format!("/attributes/{LOD_ATTR}/levels"))
                .and_then(|l| l.as_u64())
        })
        .map_or(0, |l| l.min(u64::from(strata_level::lod::MAX_LOD)) as u32)
}

#[cfg(all(test, feature = "fs"))]
mod tests {
    use super::*;
    use crate::DirStore;
    use crate::format::{HEIGHTS, METAS};

    #[test]
    fn fetched_objects_decode_to_what_zarrs_reads() {
        let world = strata_level::generate::generate(&strata_level::generate::GenerateParams {
            seed: 9,
            width: 512,
            height: 1024,
        })
        .unwrap();
        let dir = std::env::temp_dir().join(format!("strata-http-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let store = DirStore::create(&dir, &world, &crate::Layout::default()).unwrap();
        let s = store.store();
        let root = std::fs::read(dir.join("zarr.json")).unwrap();
        let attrs = world_attrs("test", &root).unwrap();
        assert_eq!((attrs.width, attrs.height), (512, 1024));
        let shell = world_shell("test", &attrs).unwrap();
        let native = s.world_shell().unwrap();
        assert_eq!(shell.views, native.views);
        assert_eq!(shell.edit, native.edit);
        assert_eq!(shell.water, native.water);
        assert_eq!(shell.palette.colors, native.palette.colors);
        for name in [HEIGHTS, METAS] {
            let json = std::fs::read(dir.join(name).join("zarr.json")).unwrap();
            check_array(name, &json, "uint8", &[1024, 512], &[256, 256]).unwrap();
            assert!(check_array(name, &json, "uint8", &[1024, 512], &[128, 256]).is_err());
        }
        for (cy, cx) in [(0u64, 0u64), (3, 1)] {
            let chunk = s.read_chunk(cy, cx).unwrap();
            for (name, plane) in [(HEIGHTS, &chunk.heights), (METAS, &chunk.metas)] {
                let bytes = std::fs::read(dir.join(chunk_key(name, &[cy, cx]))).unwrap();
                let decoded = decode_chunk(name, &[cy, cx], &bytes, 256 * 256).unwrap();
                assert_eq!(&decoded, plane, "{name} ({cy}, {cx})");
                // Truncated, and one byte flipped: clear errors, no panic.
                let cut = decode_chunk(name, &[cy, cx], &bytes[..bytes.len() / 2], 65536);
                assert!(cut.unwrap_err().to_string().contains("checksum"));
                let mut bad = bytes.clone();
                bad[bytes.len() / 3] ^= 0x10;
                let e = decode_chunk(name, &[cy, cx], &bad, 65536).unwrap_err();
                assert!(
                    e.to_string().contains(&format!("chunk [{cy}, {cx}]")),
                    "{e}"
                );
                assert!(decode_chunk(name, &[cy, cx], &bytes[..3], 65536).is_err());
            }
        }
        let (gy, gx) = s.grid();
        let objects: Vec<Vec<u8>> = summary_cells(gy, gx)
            .iter()
            .map(|c| std::fs::read(dir.join(chunk_key(SUMMARY, c))).unwrap())
            .collect();
        let tops = chunk_tops(gy, gx, &objects).unwrap();
        let want: Vec<u8> = s.summaries().unwrap().iter().map(|s| s.top_max).collect();
        assert_eq!(tops, want);
        assert!(world_attrs("test", b"{}").is_err());
        assert!(world_attrs("test", b"not json").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
