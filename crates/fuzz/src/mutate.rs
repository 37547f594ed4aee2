//! Mutations of valid files, as proptest strategies: generic byte edits,
//! the `.vmc`'s row table and Huffman trees, and line / token edits of text
//! formats. A strategy yields a list of edits; applying them to a seed gives
//! the input, so proptest shrinks a failure to the fewest, smallest edits.

use proptest::prelude::*;
use proptest::sample::Index;

/// An edit of any file's bytes.
#[derive(Clone, Debug)]
pub enum ByteEdit {
    Truncate(Index),
    FlipBit(Index, u8),
    SetByte(Index, u8),
    Insert(Index, Vec<u8>),
    Delete(Index, usize),
    /// A little-endian i32 written over four bytes (sizes, offsets, links).
    WriteI32(Index, i32),
}

/// Values that break size and offset arithmetic.
pub fn extreme_i32() -> impl Strategy<Value = i32> {
    prop_oneof![
        Just(0),
        Just(-1),
        Just(1),
        Just(i32::MAX),
        Just(i32::MIN),
        Just(i32::from(i16::MAX)),
        -300..300i32,
        any::<i32>(),
    ]
}

pub fn byte_edit() -> impl Strategy<Value = ByteEdit> {
    prop_oneof![
        any::<Index>().prop_map(ByteEdit::Truncate),
        (any::<Index>(), 0..8u8).prop_map(|(i, b)| ByteEdit::FlipBit(i, b)),
        (any::<Index>(), any::<u8>()).prop_map(|(i, v)| ByteEdit::SetByte(i, v)),
        (any::<Index>(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(i, v)| ByteEdit::Insert(i, v)),
        (any::<Index>(), 1..64usize).prop_map(|(i, n)| ByteEdit::Delete(i, n)),
        (any::<Index>(), extreme_i32()).prop_map(|(i, v)| ByteEdit::WriteI32(i, v)),
    ]
}

impl ByteEdit {
    pub fn apply(&self, bytes: &mut Vec<u8>) {
        let len = bytes.len();
        // Positions index the bytes as they are now; an empty file takes
        // only inserts.
        let at = |i: &Index| if len == 0 { 0 } else { i.index(len) };
        match self {
            ByteEdit::Truncate(i) => bytes.truncate(at(i)),
            ByteEdit::FlipBit(i, bit) if len > 0 => bytes[at(i)] ^= 1 << bit,
            ByteEdit::SetByte(i, v) if len > 0 => bytes[at(i)] = *v,
            ByteEdit::Insert(i, run) => {
                let p = at(i);
                bytes.splice(p..p, run.iter().copied());
            }
            ByteEdit::Delete(i, n) if len > 0 => {
                let p = at(i);
                bytes.drain(p..(p + n).min(len));
            }
            ByteEdit::WriteI32(i, v) if len >= 4 => {
                let p = i.index(len - 3);
                bytes[p..p + 4].copy_from_slice(&v.to_le_bytes());
            }
            _ => {}
        }
    }
}

/// Where the `.vmc` structures of a seed lie.
#[derive(Clone, Copy, Debug)]
pub struct VmcLayout {
    pub rows: usize,
    /// Bytes of the row table and trees.
    pub header: usize,
    pub file_len: usize,
}

/// An edit of a `.vmc`: generic, or aimed at its row table or trees.
#[derive(Clone, Debug)]
pub enum VmcEdit {
    Bytes(ByteEdit),
    /// Row `row`'s table entry: new offset and / or size.
    RowEntry {
        row: Index,
        offset: Option<i32>,
        size: Option<i16>,
    },
    /// Two rows' table entries exchanged (rows then overlap or misorder).
    SwapRows(Index, Index),
    /// One slot of the height (`false`) or meta (`true`) decode tree.
    TreeSlot {
        meta: bool,
        slot: Index,
        value: i32,
    },
}

pub fn vmc_edit(layout: VmcLayout) -> impl Strategy<Value = VmcEdit> {
    let header = layout.header as i32;
    let file = layout.file_len as i32;
    let offset = prop_oneof![
        extreme_i32(),
        Just(header),
        Just(header - 1),
        Just(file),
        Just(file - 1),
        0..file.max(1),
    ];
    let size = prop_oneof![
        Just(0i16),
        Just(-1),
        Just(i16::MAX),
        Just(i16::MIN),
        1..64i16,
        any::<i16>(),
    ];
    // Leaves (<= 0), internal links (1..=255) and links outside the tree.
    let tree_value = prop_oneof![
        -255..=0i32,
        1..=255i32,
        Just(1),
        Just(256),
        Just(i32::MAX),
        Just(i32::MIN),
        any::<i32>(),
    ];
    prop_oneof![
        3 => byte_edit().prop_map(VmcEdit::Bytes),
        2 => (any::<Index>(), prop::option::of(offset), prop::option::of(size))
            .prop_map(|(row, offset, size)| VmcEdit::RowEntry { row, offset, size }),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| VmcEdit::SwapRows(a, b)),
        2 => (any::<bool>(), any::<Index>(), tree_value)
            .prop_map(|(meta, slot, value)| VmcEdit::TreeSlot { meta, slot, value }),
    ]
}

impl VmcEdit {
    /// Apply to a `.vmc` of `layout` (structure edits that no longer fit a
    /// shortened file are skipped).
    pub fn apply(&self, layout: VmcLayout, bytes: &mut Vec<u8>) {
        let entry = |row: usize| row * 6;
        match self {
            VmcEdit::Bytes(e) => e.apply(bytes),
            VmcEdit::RowEntry { row, offset, size } => {
                let at = entry(row.index(layout.rows));
                if let (Some(o), Some(cell)) = (offset, bytes.get_mut(at..at + 4)) {
                    cell.copy_from_slice(&o.to_le_bytes());
                }
                if let (Some(s), Some(cell)) = (size, bytes.get_mut(at + 4..at + 6)) {
                    cell.copy_from_slice(&s.to_le_bytes());
                }
            }
            VmcEdit::SwapRows(a, b) => {
                let (a, b) = (entry(a.index(layout.rows)), entry(b.index(layout.rows)));
                if a.max(b) + 6 <= bytes.len() {
                    for k in 0..6 {
                        bytes.swap(a + k, b + k);
                    }
                }
            }
            VmcEdit::TreeSlot { meta, slot, value } => {
                let trees = layout.rows * 6;
                let at = trees + usize::from(*meta) * 2048 + slot.index(512) * 4;
                if let Some(cell) = bytes.get_mut(at..at + 4) {
                    cell.copy_from_slice(&value.to_le_bytes());
                }
            }
        }
    }
}

/// Tokens that break number parsing and limits in any text format.
const EXTREME_TOKENS: &[&str] = &[
    "",
    "0",
    "-0",
    "1",
    "-1",
    "15",
    "16",
    "255",
    "256",
    "65536",
    "2147483647",
    "4294967296",
    "-9223372036854775808",
    "99999999999999999999999999",
    "1e39",
    "-1e39",
    "1e400",
    "3.4028236e38",
    "1e-45",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "0x10",
    "1.5",
    ".",
    "-",
    "null",
    "true",
    "[]",
    "{}",
    "\"\"",
    "ÿ",
    "\u{0}",
    "\u{feff}",
    "\r",
];

/// An edit of a text file: by line, by token, or by byte.
#[derive(Clone, Debug)]
pub enum TextEdit {
    DeleteLine(Index),
    DuplicateLine(Index),
    SwapLines(Index, Index),
    InsertLine(Index, String),
    /// A token (a run without whitespace or the format's punctuation)
    /// replaced.
    ReplaceToken(Index, String),
    Bytes(ByteEdit),
}

/// Text edits drawing on `words` (the format's own keywords) and extreme values.
pub fn text_edit(words: &'static [&'static str]) -> impl Strategy<Value = TextEdit> {
    let token = prop_oneof![
        prop::sample::select(EXTREME_TOKENS).prop_map(str::to_string),
        prop::sample::select(words).prop_map(str::to_string),
        "[ -~]{0,12}",
        // A long run: numbers and names far beyond any sane length.
        (
            1..2000usize,
            prop::sample::select(&['9', 'a', '[', '-'][..])
        )
            .prop_map(|(n, c)| std::iter::repeat_n(c, n).collect()),
    ];
    let separator = prop::sample::select(&[" ", "=", ",", ":", "  ", "\t"][..]);
    let line = prop::collection::vec((token.clone(), separator), 0..5)
        .prop_map(|parts| parts.into_iter().map(|(t, s)| t + s).collect::<String>());
    prop_oneof![
        1 => any::<Index>().prop_map(TextEdit::DeleteLine),
        1 => any::<Index>().prop_map(TextEdit::DuplicateLine),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| TextEdit::SwapLines(a, b)),
        1 => (any::<Index>(), line).prop_map(|(i, l)| TextEdit::InsertLine(i, l)),
        3 => (any::<Index>(), token).prop_map(|(i, t)| TextEdit::ReplaceToken(i, t)),
        2 => byte_edit().prop_map(TextEdit::Bytes),
    ]
}

/// Byte ranges of the tokens of `text`.
fn tokens(text: &[u8]) -> Vec<std::ops::Range<usize>> {
    let punct = |b: u8| b.is_ascii_whitespace() || b"=,:[]{}#\"".contains(&b);
    let mut out = Vec::new();
    let mut start = None;
    for (i, &b) in text.iter().enumerate() {
        match (start, punct(b)) {
            (None, false) => start = Some(i),
            (Some(s), true) => {
                out.push(s..i);
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push(s..text.len());
    }
    out
}

/// Byte ranges of the lines of `text`, terminators included.
fn lines(text: &[u8]) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &b) in text.iter().enumerate() {
        if b == b'\n' {
            out.push(start..i + 1);
            start = i + 1;
        }
    }
    if start < text.len() {
        out.push(start..text.len());
    }
    out
}

impl TextEdit {
    pub fn apply(&self, text: &mut Vec<u8>) {
        let lines = lines(text);
        let line = |i: &Index| (!lines.is_empty()).then(|| lines[i.index(lines.len())].clone());
        match self {
            TextEdit::DeleteLine(i) => {
                if let Some(r) = line(i) {
                    text.drain(r);
                }
            }
            TextEdit::DuplicateLine(i) => {
                if let Some(r) = line(i) {
                    let copy = text[r.clone()].to_vec();
                    text.splice(r.start..r.start, copy);
                }
            }
            TextEdit::SwapLines(a, b) => {
                if let (Some(a), Some(b)) = (line(a), line(b)) {
                    let (first, second) = if a.start <= b.start { (a, b) } else { (b, a) };
                    if first.end <= second.start {
                        let mut out = text[..first.start].to_vec();
                        out.extend_from_slice(&text[second.clone()]);
                        out.extend_from_slice(&text[first.end..second.start]);
                        out.extend_from_slice(&text[first.clone()]);
                        out.extend_from_slice(&text[second.end..]);
                        *text = out;
                    }
                }
            }
            TextEdit::InsertLine(i, new) => {
                let at = line(i).map_or(text.len(), |r| r.start);
                let mut bytes = new.clone().into_bytes();
                bytes.push(b'\n');
                text.splice(at..at, bytes);
            }
            TextEdit::ReplaceToken(i, new) => {
                let tokens = tokens(text);
                if !tokens.is_empty() {
                    let r = tokens[i.index(tokens.len())].clone();
                    text.splice(r, new.bytes());
                }
            }
            TextEdit::Bytes(e) => e.apply(text),
        }
    }
}

/// A seed (chosen from `seeds`) with up to `max_edits` edits applied.
pub fn mutated_text(
    seeds: Vec<Vec<u8>>,
    words: &'static [&'static str],
    max_edits: usize,
) -> impl Strategy<Value = Vec<u8>> {
    (
        prop::sample::select(seeds),
        prop::collection::vec(text_edit(words), 0..=max_edits),
    )
        .prop_map(|(mut text, edits)| {
            for e in &edits {
                e.apply(&mut text);
            }
            text
        })
}

/// A binary seed with up to `max_edits` generic byte edits applied.
pub fn mutated_bytes(seeds: Vec<Vec<u8>>, max_edits: usize) -> impl Strategy<Value = Vec<u8>> {
    (
        prop::sample::select(seeds),
        prop::collection::vec(byte_edit(), 0..=max_edits),
    )
        .prop_map(|(mut bytes, edits)| {
            for e in &edits {
                e.apply(&mut bytes);
            }
            bytes
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_and_lines_split_as_expected() {
        let text = b"[Storage]\nFile Name=output\r\nx";
        let t: Vec<&[u8]> = tokens(text).into_iter().map(|r| &text[r]).collect();
        assert_eq!(t, [&b"Storage"[..], b"File", b"Name", b"output", b"x"]);
        assert_eq!(lines(text).len(), 3);
    }
}
