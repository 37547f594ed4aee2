//! `.vmc`: the compressed map (DESIGN §1).
//!
//! Layout: a row table of `height` entries `(i32 LE absolute offset, i16 LE
//! byte size)`, then the decode trees `tree1[512]` (heights) and
//! `tree2[512]` (meta), i32 LE; then the rows. A row is the height stream
//! (delta-coded: `h[x] = h[x-1] + s`, `h[-1] = 0`, mod 256), then from the
//! next whole byte the meta stream (XOR-coded: `m[x] = m[x-1] ^ s`,
//! `m[-1] = 0`); the two streams fill exactly the row's byte size.
//!
//! Rows are independent: both directions run in parallel over rows, and
//! decoding writes straight into the two final planes.
//!
//! Writing back a map that was read from a `.vmc` ([`encode_vmc_reusing`])
//! keeps the file's trees and the bytes of every row that was not edited
//! where the format allows, so an unedited map is written back byte for
//! byte and an edit changes only the edited rows (and the row table).

use crate::error::LevelError;
use crate::huffman::{BitReader, BitWriter, Code, Decoder, TREE_SLOTS, Tree};
use crate::model::{Level, MidRule};
use rayon::prelude::*;
use std::path::Path;

const ENTRY_BYTES: usize = 6;
const TREES_BYTES: usize = 2 * TREE_SLOTS * 4;

/// Bytes before the first row of a map of `height` rows.
pub fn header_bytes(height: u32) -> usize {
    height as usize * ENTRY_BYTES + TREES_BYTES
}

fn read_tree(bytes: &[u8]) -> Tree {
    let mut tree = [0i32; TREE_SLOTS];
    for (t, b) in tree.iter_mut().zip(bytes.chunks_exact(4)) {
        *t = i32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    }
    tree
}

/// A `.vmc` file's row table and decoders, checked against the map size.
struct Header {
    /// Each row's bytes in the file.
    rows: Vec<std::ops::Range<usize>>,
    heights: Decoder,
    metas: Decoder,
}

/// Read and check the row table and trees of `.vmc` bytes of a `width` x
/// `height` map. Checks every row's place before anything map-sized is
/// allocated, so a world.ini naming a huge map over a small file fails here.
fn read_header(bytes: &[u8], width: u32, height: u32, path: &Path) -> Result<Header, LevelError> {
    let err = |msg: String| LevelError::format(path, msg);
    let header = header_bytes(height);
    if bytes.len() < header {
        return Err(err(format!(
            "truncated: {} bytes, but the row table and trees of {height} rows need {header}",
            bytes.len()
        )));
    }
    let table_end = height as usize * ENTRY_BYTES;
    let min_row = 2 * (width as usize).div_ceil(8);
    let mut rows = Vec::with_capacity(height as usize);
    // Rows lie apart in the file (the writers put them one after another),
    // so their sizes add up to the bytes after the header. At most twice
    // that is accepted here (a row whose size is off by a few bytes gets its
    // own row's error from the decoder); more means rows share bytes. This
    // is what bounds the map by the file: a row table whose rows all point
    // at the same few bytes would otherwise make a short file decode to any
    // declared size (2 GiB of planes for 2^15 x 2^15).
    let mut row_bytes = 0usize;
    let body = bytes.len() - header;
    for (y, e) in bytes[..table_end].chunks_exact(ENTRY_BYTES).enumerate() {
        let offset = i32::from_le_bytes([e[0], e[1], e[2], e[3]]);
        let size = i16::from_le_bytes([e[4], e[5]]);
        if offset < 0 || size < 0 {
            return Err(err(format!(
                "row {y}: negative offset {offset} or size {size} in the row table"
            )));
        }
        let (start, len) = (offset as usize, size as usize);
        // Codes are at least one bit: each stream takes at least W/8 bytes.
        if len < min_row {
            return Err(err(format!(
                "row {y}: {len} bytes cannot hold {width} heights and {width} metas (at least \
                 {min_row}): does the map size in world.ini ({width}x{height}) match the file?"
            )));
        }
        if start < header {
            return Err(err(format!(
                "row {y} starts at byte {start}, inside the row table and trees ({header} bytes for \
                 {height} rows): does the map size in world.ini ({width}x{height}) match the file?"
            )));
        }
        if start + len > bytes.len() {
            return Err(err(format!(
                "row {y}: the row table points at bytes {start}..{} past the end of the file \
                 ({} bytes; truncated?)",
                start + len,
                bytes.len()
            )));
        }
        row_bytes += len;
        if row_bytes > 2 * body {
            return Err(err(format!(
                "rows 0..={y} of the row table add up to {row_bytes} bytes, more than twice the \
                 {body} bytes after the row table and trees: rows share bytes, or the map size in \
                 world.ini ({width}x{height}) does not match the file"
            )));
        }
        rows.push(start..start + len);
    }
    let tree_err = |which: &str, e| err(format!("{which} Huffman tree: {e}"));
    let heights = Decoder::new(&read_tree(&bytes[table_end..table_end + TREES_BYTES / 2]))
        .map_err(|e| tree_err("height", e))?;
    let metas = Decoder::new(&read_tree(&bytes[table_end + TREES_BYTES / 2..header]))
        .map_err(|e| tree_err("meta", e))?;
    Ok(Header {
        rows,
        heights,
        metas,
    })
}

/// Decode `.vmc` bytes of a `width` x `height` map. `path` names the file in errors.
pub fn decode_vmc(
    bytes: &[u8],
    width: u32,
    height: u32,
    mid_rule: MidRule,
    path: &Path,
) -> Result<Level, LevelError> {
    let err = |msg: String| LevelError::format(path, msg);
    let header = read_header(bytes, width, height, path)?;
    let w = width as usize;
    let n = w * height as usize;
    let mut heights = vec![0u8; n];
    let mut metas = vec![0u8; n];
    heights
        .par_chunks_mut(w)
        .zip(metas.par_chunks_mut(w))
        .zip(header.rows.par_iter())
        .enumerate()
        .try_for_each(|(y, ((h_row, m_row), range))| {
            decode_row(
                &bytes[range.clone()],
                &header.heights,
                &header.metas,
                h_row,
                m_row,
            )
            .map_err(|msg| err(format!("row {y}: {msg}")))
        })?;
    Level::from_planes(width, height, heights, metas, mid_rule).map_err(|e| err(e.to_string()))
}

fn decode_row(
    data: &[u8],
    heights_dec: &Decoder,
    metas_dec: &Decoder,
    h_row: &mut [u8],
    m_row: &mut [u8],
) -> Result<(), String> {
    let size_bits = data.len() * 8;
    let mut bits = BitReader::new(data, 0);
    // Symbols first, then undo the delta / XOR coding in place.
    heights_dec.decode_into(&mut bits, h_row);
    let mut h = 0u8;
    for v in h_row.iter_mut() {
        h = h.wrapping_add(*v);
        *v = h;
    }
    let h_bits = bits.position();
    if h_bits > size_bits {
        return Err(format!(
            "the height stream needs {h_bits} bits, more than the row's {} bytes",
            data.len()
        ));
    }
    let meta_start = h_bits.div_ceil(8);
    let mut bits = BitReader::new(data, meta_start);
    metas_dec.decode_into(&mut bits, m_row);
    let mut m = 0u8;
    for v in m_row.iter_mut() {
        m ^= *v;
        *v = m;
    }
    let used = bits.position().div_ceil(8);
    match used.cmp(&data.len()) {
        std::cmp::Ordering::Equal => Ok(()),
        std::cmp::Ordering::Greater => Err(format!(
            "the meta stream runs past the row's {} bytes (needs {used})",
            data.len()
        )),
        std::cmp::Ordering::Less => Err(format!(
            "the two streams fill only {used} of the row's {} bytes",
            data.len()
        )),
    }
}

/// Per-symbol counts of the delta-coded heights and XOR-coded metas.
fn symbol_frequencies(level: &Level) -> ([u64; 256], [u64; 256]) {
    let w = level.width() as usize;
    level
        .heights()
        .par_chunks(w)
        .zip(level.metas().par_chunks(w))
        .fold(
            || ([0u64; 256], [0u64; 256]),
            |(mut fh, mut fm), (hr, mr)| {
                let (mut ph, mut pm) = (0u8, 0u8);
                for (&h, &m) in hr.iter().zip(mr) {
                    fh[usize::from(h.wrapping_sub(ph))] += 1;
                    fm[usize::from(m ^ pm)] += 1;
                    (ph, pm) = (h, m);
                }
                (fh, fm)
            },
        )
        .reduce(
            || ([0u64; 256], [0u64; 256]),
            |(mut a, mut b), (c, d)| {
                a.iter_mut().zip(c).for_each(|(x, y)| *x += y);
                b.iter_mut().zip(d).for_each(|(x, y)| *x += y);
                (a, b)
            },
        )
}

/// A row's bytes under the given codes; `None` when a symbol it needs has
/// no code (possible only for a code read from a file's trees).
fn encode_row(hr: &[u8], mr: &[u8], hc: &Code, mc: &Code) -> Option<Vec<u8>> {
    let mut w = BitWriter::with_capacity(hr.len());
    let mut p = 0u8;
    for &h in hr {
        let s = usize::from(h.wrapping_sub(p));
        if hc.lengths[s] == 0 {
            return None;
        }
        w.put(hc.codes[s], hc.lengths[s]);
        p = h;
    }
    w.align();
    let mut p = 0u8;
    for &m in mr {
        let s = usize::from(m ^ p);
        if mc.lengths[s] == 0 {
            return None;
        }
        w.put(mc.codes[s], mc.lengths[s]);
        p = m;
    }
    w.align();
    Some(w.bytes)
}

/// The file: row table (rows in order, one after another), the two trees
/// (`trees`: their 2 x 512 i32 LE as they go in the file), the rows.
fn assemble<R: AsRef<[u8]>>(rows: &[R], trees: &[u8], path: &Path) -> Result<Vec<u8>, LevelError> {
    let header = rows.len() * ENTRY_BYTES + TREES_BYTES;
    let total = header + rows.iter().map(|r| r.as_ref().len()).sum::<usize>();
    if total > i32::MAX as usize {
        return Err(LevelError::format(
            path,
            format!("{total} bytes exceed the format's i32 offsets"),
        ));
    }
    let mut out = Vec::with_capacity(total);
    let mut offset = header;
    for (y, row) in rows.iter().enumerate() {
        let len = row.as_ref().len();
        let size = i16::try_from(len).map_err(|_| {
            LevelError::format(
                path,
                format!("row {y} encodes to {len} bytes, over the format's i16 row size"),
            )
        })?;
        out.extend_from_slice(&(offset as i32).to_le_bytes());
        out.extend_from_slice(&size.to_le_bytes());
        offset += len;
    }
    out.extend_from_slice(trees);
    for row in rows {
        out.extend_from_slice(row.as_ref());
    }
    Ok(out)
}

/// Encode a level as `.vmc` bytes with Huffman codes built from its own
/// symbol statistics (one code for heights, one for meta).
pub fn encode_vmc(level: &Level, path: &Path) -> Result<Vec<u8>, LevelError> {
    let (fh, fm) = symbol_frequencies(level);
    let (hc, mc) = (Code::from_frequencies(&fh), Code::from_frequencies(&fm));
    let w = level.width() as usize;
    // Codes built from the level's own symbols cover every row.
    let rows: Option<Vec<Vec<u8>>> = level
        .heights()
        .par_chunks(w)
        .zip(level.metas().par_chunks(w))
        .map(|(hr, mr)| encode_row(hr, mr, &hc, &mc))
        .collect();
    let rows = rows.ok_or_else(|| {
        LevelError::format(path, "internal: a symbol of the map has no Huffman code")
    })?;
    let trees: Vec<u8> = [hc.tree(), mc.tree()]
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    assemble(&rows, &trees, path)
}

/// How [`encode_vmc_reusing`] made the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VmcReuse {
    /// No row changed: the source file, byte for byte.
    Whole,
    /// The source's trees and its unchanged rows' bytes; `changed` rows
    /// encoded with the source's codes.
    Rows {
        /// Rows re-encoded.
        changed: usize,
    },
    /// A fresh [`encode_vmc`]: the source does not fit the map, or a changed
    /// row needs a symbol its trees lack a code for.
    Fresh,
}

/// Encode `level` keeping what it can of `source` (the `.vmc` bytes it was
/// read from): a row whose decoded content is unchanged keeps its bytes, and
/// the file keeps its trees, as long as the trees' codes cover the changed
/// rows (else every row is re-encoded with new codes, since the trees are
/// shared by all rows). `path` names the file in errors.
pub fn encode_vmc_reusing(
    level: &Level,
    source: &[u8],
    path: &Path,
) -> Result<(Vec<u8>, VmcReuse), LevelError> {
    let (width, height) = (level.width(), level.height());
    let fresh = || encode_vmc(level, path).map(|b| (b, VmcReuse::Fresh));
    let Ok(header) = read_header(source, width, height, path) else {
        return fresh();
    };
    let w = width as usize;
    // Per row: unchanged (decodes to the level's row) or not.
    let unchanged: Vec<bool> = level
        .heights()
        .par_chunks(w)
        .zip(level.metas().par_chunks(w))
        .zip(header.rows.par_iter())
        .map_init(
            || (vec![0u8; w], vec![0u8; w]),
            |(h, m), ((hr, mr), range)| {
                decode_row(&source[range.clone()], &header.heights, &header.metas, h, m).is_ok()
                    && h.as_slice() == hr
                    && m.as_slice() == mr
            },
        )
        .collect();
    let changed = unchanged.iter().filter(|u| !**u).count();
    if changed == 0 {
        return Ok((source.to_vec(), VmcReuse::Whole));
    }
    let (hc, mc) = (
        Code::from_tree(&header.heights),
        Code::from_tree(&header.metas),
    );
    let rows: Option<Vec<std::borrow::Cow<'_, [u8]>>> = level
        .heights()
        .par_chunks(w)
        .zip(level.metas().par_chunks(w))
        .zip(header.rows.par_iter().zip(unchanged.par_iter()))
        .map(|((hr, mr), (range, &same))| {
            if same {
                Some(std::borrow::Cow::Borrowed(&source[range.clone()]))
            } else {
                encode_row(hr, mr, &hc, &mc).map(std::borrow::Cow::Owned)
            }
        })
        .collect();
    let Some(rows) = rows else {
        return fresh();
    };
    let table_end = height as usize * ENTRY_BYTES;
    match assemble(&rows, &source[table_end..table_end + TREES_BYTES], path) {
        Ok(bytes) => Ok((bytes, VmcReuse::Rows { changed })),
        // A row the source's codes make too long for the table: new codes.
        Err(_) => fresh(),
    }
}

/// Read and decode a `.vmc` of a `width x height` map (sizes from `world.ini`).
pub fn read_vmc(
    path: &Path,
    width: u32,
    height: u32,
    mid_rule: MidRule,
) -> Result<Level, LevelError> {
    let bytes = crate::error::read_file(path)?;
    decode_vmc(&bytes, width, height, mid_rule, path)
}

/// Encode `level` with fresh Huffman trees and write it as a `.vmc`.
pub fn write_vmc(path: &Path, level: &Level) -> Result<(), LevelError> {
    crate::error::write_file(path, &encode_vmc(level, path)?)
}
