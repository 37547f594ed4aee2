//! The `.vmc` Huffman code: decode trees of 512 i32 slots (DESIGN §1).
//!
//! Decoding walks `node = 1; node = tree[2 node + bit]` MSB first until a
//! value `v <= 0`, the leaf of symbol `(-v) & 0xFF`. Node indices therefore
//! run 1..=255, which holds exactly the 255 internal nodes of a full binary
//! tree over 256 symbols: any complete prefix code fits, whatever its depth.
//! Code lengths are still limited ([`MAX_CODE_LEN`]) so that the encoder's
//! bit accumulator stays small and a row's byte size stays well inside the
//! table's i16.

/// Slots in one decode tree.
pub const TREE_SLOTS: usize = 512;
/// Longest code the encoder emits.
pub const MAX_CODE_LEN: u32 = 24;
/// Bits resolved by one lookup in the decoder's table.
const LOOKUP_BITS: u32 = 12;

/// A `.vmc` decode tree as stored: slot `2 node + bit` holds the next node
/// (positive) or a leaf `-symbol` (at most 0).
pub type Tree = [i32; TREE_SLOTS];

/// A prefix code: per symbol its code (right-aligned) and length in bits (0 = unused).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Code {
    /// Each symbol's code, right-aligned.
    pub codes: [u32; 256],
    /// Each symbol's code length in bits; 0 for a symbol without a code.
    pub lengths: [u8; 256],
}

/// Huffman code lengths for the given symbol frequencies, at most `max_len`
/// bits. Symbols of frequency 0 get no code, except that at least two
/// symbols always get one (a tree's root has two children).
pub fn code_lengths(freq: &[u64; 256], max_len: u32) -> [u8; 256] {
    let mut weights: Vec<(u64, usize)> = freq
        .iter()
        .enumerate()
        .filter(|(_, f)| **f > 0)
        .map(|(s, f)| (*f, s))
        .collect();
    // Pad to two symbols with the smallest unused ones.
    let mut s = 0;
    while weights.len() < 2 {
        if !weights.iter().any(|w| w.1 == s) {
            weights.push((1, s));
        }
        s += 1;
    }
    loop {
        let lengths = huffman_lengths(&weights);
        if lengths.iter().all(|&l| u32::from(l) <= max_len) {
            return lengths;
        }
        // Too deep: flatten the distribution and rebuild. Halving with a
        // floor of 1 converges to a balanced tree (depth 8) at worst.
        for w in &mut weights {
            w.0 = (w.0 >> 1).max(1);
        }
    }
}

/// Plain Huffman (no limit) over `(weight, symbol)` with at least two entries.
fn huffman_lengths(weights: &[(u64, usize)]) -> [u8; 256] {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    // Nodes 0..n are leaves; later ones are merges. parent[i] links upwards.
    let n = weights.len();
    let mut parent = vec![usize::MAX; 2 * n];
    let mut heap: BinaryHeap<Reverse<(u64, usize)>> = weights
        .iter()
        .enumerate()
        .map(|(i, w)| Reverse((w.0, i)))
        .collect();
    let mut next = n;
    while heap.len() > 1 {
        let (Some(Reverse((wa, a))), Some(Reverse((wb, b)))) = (heap.pop(), heap.pop()) else {
            break;
        };
        parent[a] = next;
        parent[b] = next;
        heap.push(Reverse((wa + wb, next)));
        next += 1;
    }
    let mut lengths = [0u8; 256];
    for (i, w) in weights.iter().enumerate() {
        let mut depth = 0u32;
        let mut node = i;
        while parent[node] != usize::MAX {
            node = parent[node];
            depth += 1;
        }
        lengths[w.1] = depth.min(255) as u8;
    }
    lengths
}

impl Code {
    /// The canonical code of the given lengths (shorter codes first, then by symbol).
    pub fn canonical(lengths: &[u8; 256]) -> Self {
        let mut order: Vec<usize> = (0..256).filter(|&s| lengths[s] > 0).collect();
        order.sort_by_key(|&s| (lengths[s], s));
        let mut codes = [0u32; 256];
        let mut code = 0u32;
        let mut prev_len = 0u8;
        for (i, &s) in order.iter().enumerate() {
            if i > 0 {
                code += 1;
            }
            code <<= lengths[s] - prev_len;
            prev_len = lengths[s];
            codes[s] = code;
        }
        Code {
            codes,
            lengths: *lengths,
        }
    }

    /// The code of a frequency table, lengths limited to [`MAX_CODE_LEN`].
    pub fn from_frequencies(freq: &[u64; 256]) -> Self {
        Self::canonical(&code_lengths(freq, MAX_CODE_LEN))
    }

    /// The code a (checked) decode tree decodes: per symbol the shortest
    /// path to one of its leaves. Symbols without a leaf, or whose code is
    /// longer than [`MAX_CODE_LEN`] (more than the encoder's bit writer
    /// takes), get length 0: encoding with this code is possible only for
    /// the symbols it has.
    pub fn from_tree(decoder: &Decoder) -> Self {
        let tree = &decoder.tree;
        let mut code = Code {
            codes: [0; 256],
            lengths: [0; 256],
        };
        // (node, code so far, its length); the checked tree has no cycles.
        let mut stack = vec![(1usize, 0u32, 0u32)];
        while let Some((node, bits, len)) = stack.pop() {
            if len >= MAX_CODE_LEN {
                continue;
            }
            for bit in 0..2u32 {
                let v = tree[2 * node + bit as usize];
                let (bits, len) = ((bits << 1) | bit, len + 1);
                if v > 0 {
                    stack.push((v as usize, bits, len));
                    continue;
                }
                let s = usize::from(v.wrapping_neg() as u8);
                let known = u32::from(code.lengths[s]);
                if known == 0 || len < known {
                    code.codes[s] = bits;
                    code.lengths[s] = len as u8;
                }
            }
        }
        code
    }

    /// The decode tree of this code in the file's 512-slot form.
    /// Unreachable slots hold 0.
    pub fn tree(&self) -> Tree {
        // Internal child links are kept apart while building, because a
        // stored 0 also means "leaf of symbol 0".
        let mut child: [Option<i32>; TREE_SLOTS] = [None; TREE_SLOTS];
        let mut next_node = 2i32;
        for s in 0..256usize {
            let len = u32::from(self.lengths[s]);
            if len == 0 {
                continue;
            }
            let mut node = 1usize;
            for i in (0..len).rev() {
                let bit = ((self.codes[s] >> i) & 1) as usize;
                let slot = 2 * node + bit;
                if i == 0 {
                    child[slot] = Some(-(s as i32));
                } else {
                    node = match child[slot] {
                        Some(v) if v > 0 => v as usize,
                        _ => {
                            let v = next_node;
                            next_node += 1;
                            child[slot] = Some(v);
                            v as usize
                        }
                    };
                }
            }
        }
        child.map(|c| c.unwrap_or(0))
    }
}

/// Why a decode tree was refused.
#[derive(Debug, PartialEq, Eq, thiserror::Error)]
pub enum TreeError {
    /// A slot links to a node index outside `1..=255`.
    #[error("node {node} links to node {target}, outside 1..=255")]
    OutOfRange {
        /// The node whose slot is bad.
        node: usize,
        /// The value in the slot.
        target: i32,
    },
    /// A node is reachable along two paths, so the tree is not a tree.
    #[error("node {target} is reached twice (a cycle or shared subtree), from node {node}")]
    Cycle {
        /// The node linking to it the second time.
        node: usize,
        /// The node reached twice.
        target: i32,
    },
}

/// A checked decode tree plus lookup tables resolving `LOOKUP_BITS` (12) bits
/// at once: up to three whole symbols per lookup (delta-coded terrain is
/// mostly 1-3 bit codes, so this cuts the per-symbol work), and one symbol
/// per lookup for the last few symbols of a stream.
pub struct Decoder {
    tree: Tree,
    /// Per prefix: `s1 | s2 << 8 | s3 << 16 | bits << 24 | count << 28`.
    /// `count` 0: no symbol ends inside the prefix; the walk continues at node `s1`.
    multi: Vec<u32>,
    /// Per prefix: `symbol | bits << 8 | 1 << 16`, or `node` (no leaf yet).
    single: Vec<u32>,
}

/// Walk from `node` along the low `n` bits of `prefix` (MSB first).
/// Returns `(symbol, bits used)` when a leaf is reached, else `Err(node)`.
fn walk(tree: &Tree, mut node: usize, prefix: u32, n: u32) -> Result<(u8, u32), usize> {
    for i in 0..n {
        let bit = ((prefix >> (n - 1 - i)) & 1) as usize;
        let v = tree[2 * node + bit];
        if v <= 0 {
            return Ok((v.wrapping_neg() as u8, i + 1));
        }
        node = v as usize;
    }
    Err(node)
}

impl Decoder {
    /// Check that the tree from node 1 is a tree (no cycles, no shared nodes,
    /// links inside the 512 slots) and build the lookup table.
    pub fn new(tree: &Tree) -> Result<Self, TreeError> {
        let mut seen = [false; 256];
        seen[1] = true;
        let mut stack = vec![1usize];
        while let Some(node) = stack.pop() {
            for bit in 0..2 {
                let target = tree[2 * node + bit];
                if target <= 0 {
                    continue;
                }
                if target > 255 {
                    return Err(TreeError::OutOfRange { node, target });
                }
                let t = target as usize;
                if seen[t] {
                    return Err(TreeError::Cycle { node, target });
                }
                seen[t] = true;
                stack.push(t);
            }
        }
        // Every path now ends in a leaf within 255 steps: walks terminate.
        let single = (0..1u32 << LOOKUP_BITS)
            .map(|prefix| match walk(tree, 1, prefix, LOOKUP_BITS) {
                Ok((sym, len)) => u32::from(sym) | len << 8 | 1 << 16,
                Err(node) => node as u32,
            })
            .collect();
        let multi = (0..1u32 << LOOKUP_BITS)
            .map(|prefix| {
                let (mut entry, mut used, mut count) = (0u32, 0u32, 0u32);
                while count < 3 {
                    let rest = LOOKUP_BITS - used;
                    match walk(tree, 1, prefix & ((1u32 << rest) - 1), rest) {
                        Ok((sym, len)) => {
                            entry |= u32::from(sym) << (8 * count);
                            used += len;
                            count += 1;
                        }
                        Err(node) if count == 0 => return node as u32,
                        Err(_) => break,
                    }
                }
                entry | used << 24 | count << 28
            })
            .collect();
        Ok(Decoder {
            tree: *tree,
            multi,
            single,
        })
    }

    /// Decode `out.len()` symbols into `out`.
    #[inline]
    pub fn decode_into(&self, bits: &mut BitReader<'_>, out: &mut [u8]) {
        let n = out.len();
        let mut i = 0;
        // Bulk: three bytes are written per lookup, `count` of them are kept.
        while i + 3 <= n {
            bits.refill();
            let e = self.multi[(bits.buf >> (64 - LOOKUP_BITS)) as usize];
            let count = (e >> 28) as usize;
            if count == 0 {
                bits.consume(LOOKUP_BITS);
                out[i] = self.walk_rest((e & 0xff) as usize, bits);
                i += 1;
                continue;
            }
            bits.consume((e >> 24) & 15);
            out[i..i + 3].copy_from_slice(&e.to_le_bytes()[..3]);
            i += count;
        }
        while i < n {
            bits.refill();
            let e = self.single[(bits.buf >> (64 - LOOKUP_BITS)) as usize];
            if e >> 16 != 0 {
                bits.consume((e >> 8) & 0xff);
                out[i] = e as u8;
            } else {
                bits.consume(LOOKUP_BITS);
                out[i] = self.walk_rest((e & 0xff) as usize, bits);
            }
            i += 1;
        }
    }

    /// Decode one symbol.
    pub fn symbol(&self, bits: &mut BitReader<'_>) -> u8 {
        let mut s = [0u8];
        self.decode_into(bits, &mut s);
        s[0]
    }

    /// Rare long code: walk the rest of the (checked) tree bit by bit.
    #[cold]
    fn walk_rest(&self, mut node: usize, bits: &mut BitReader<'_>) -> u8 {
        loop {
            bits.refill();
            let bit = (bits.buf >> 63) as usize;
            bits.consume(1);
            let v = self.tree[(2 * node + bit) & (TREE_SLOTS - 1)];
            if v <= 0 {
                return v.wrapping_neg() as u8;
            }
            node = v as usize;
        }
    }
}

/// MSB-first bit reader over one row's bytes; reads past the end as zeros
/// and counts them, so callers can check that a stream stayed inside.
pub struct BitReader<'a> {
    data: &'a [u8],
    /// Next byte to load.
    byte: usize,
    /// Valid bits, MSB-aligned; bits below `count` are zero or future data.
    buf: u64,
    count: u32,
}

impl<'a> BitReader<'a> {
    /// A reader of `data` starting at byte `start_byte`, MSB first.
    pub fn new(data: &'a [u8], start_byte: usize) -> Self {
        BitReader {
            data,
            byte: start_byte,
            buf: 0,
            count: 0,
        }
    }

    /// Bits consumed from the start of `data`.
    pub fn position(&self) -> usize {
        self.byte * 8 - self.count as usize
    }

    #[inline]
    fn consume(&mut self, n: u32) {
        self.buf <<= n;
        self.count -= n;
    }

    /// Make at least 32 bits available.
    #[inline]
    fn refill(&mut self) {
        if self.count >= 32 {
            return;
        }
        if let Some(chunk) = self.data.get(self.byte..self.byte + 8) {
            let mut word = [0u8; 8];
            word.copy_from_slice(chunk);
            self.buf |= u64::from_be_bytes(word) >> self.count;
            let added = (63 - self.count) / 8;
            self.byte += added as usize;
            self.count += added * 8;
        } else {
            while self.count <= 56 {
                let b = self.data.get(self.byte).copied().unwrap_or(0);
                self.buf |= u64::from(b) << (56 - self.count);
                self.byte += 1;
                self.count += 8;
            }
        }
    }
}

/// MSB-first bit writer.
#[derive(Default)]
pub struct BitWriter {
    /// The whole bytes written so far (see [`BitWriter::align`] for the rest).
    pub bytes: Vec<u8>,
    acc: u64,
    nbits: u32,
}

impl BitWriter {
    /// A writer with room for `n` bytes.
    pub fn with_capacity(n: usize) -> Self {
        BitWriter {
            bytes: Vec::with_capacity(n),
            ..Default::default()
        }
    }

    /// Append the low `len` bits of `code`, most significant first.
    #[inline]
    pub fn put(&mut self, code: u32, len: u8) {
        self.acc = (self.acc << len) | u64::from(code);
        self.nbits += u32::from(len);
        while self.nbits >= 8 {
            self.nbits -= 8;
            self.bytes.push((self.acc >> self.nbits) as u8);
        }
    }

    /// Pad the last byte with zero bits (a stream starts on a whole byte).
    pub fn align(&mut self) {
        if self.nbits > 0 {
            self.bytes.push((self.acc << (8 - self.nbits)) as u8);
            self.nbits = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skewed() -> [u64; 256] {
        let mut freq = [0u64; 256];
        for (s, f) in freq.iter_mut().enumerate() {
            *f = ((1u64 << 50) >> (s / 5)).max(1);
        }
        freq
    }

    #[test]
    fn lengths_are_limited_and_complete() {
        let freq = skewed();
        let unlimited = code_lengths(&freq, 255);
        assert!(
            unlimited.iter().any(|&l| u32::from(l) > 12),
            "the test needs a deep code"
        );
        for max in [9, 12, 24] {
            let lengths = code_lengths(&freq, max);
            assert!(lengths.iter().all(|&l| l > 0 && u32::from(l) <= max));
            // A complete prefix code: the Kraft sum is exactly 1.
            let kraft: f64 = lengths.iter().map(|&l| 0.5f64.powi(l.into())).sum();
            assert!((kraft - 1.0).abs() < 1e-12, "{kraft}");
        }
        // Not the identity code: frequent symbols get short codes.
        let lengths = code_lengths(&freq, 24);
        assert!(lengths[0] < 8 && lengths[255] > 8);
    }

    #[test]
    fn single_symbol_gets_a_two_leaf_tree() {
        let mut freq = [0u64; 256];
        freq[7] = 100;
        let code = Code::from_frequencies(&freq);
        assert_eq!(code.lengths.iter().filter(|&&l| l > 0).count(), 2);
        assert_eq!(code.lengths[7], 1);
    }

    #[test]
    fn tree_decodes_what_the_code_encodes() {
        let code = Code::from_frequencies(&skewed());
        let tree = code.tree();
        let decoder = Decoder::new(&tree).unwrap();
        let symbols: Vec<u8> = (0..5000u32).map(|i| (i * 7919 % 251) as u8).collect();
        let mut w = BitWriter::default();
        for &s in &symbols {
            w.put(code.codes[s as usize], code.lengths[s as usize]);
        }
        let bits: usize = symbols
            .iter()
            .map(|&s| usize::from(code.lengths[s as usize]))
            .sum();
        w.align();
        let mut r = BitReader::new(&w.bytes, 0);
        let decoded: Vec<u8> = symbols.iter().map(|_| decoder.symbol(&mut r)).collect();
        assert!(decoded == symbols, "decoded symbols differ");
        assert_eq!(r.position(), bits);
    }

    #[test]
    fn code_from_a_tree_is_the_code_it_was_built_from() {
        let code = Code::from_frequencies(&skewed());
        let decoder = Decoder::new(&code.tree()).unwrap();
        assert_eq!(Code::from_tree(&decoder), code);
        // A code over a few symbols: the others get no code.
        let mut freq = [0u64; 256];
        freq[3] = 10;
        freq[200] = 5;
        freq[9] = 1;
        let sparse = Code::from_frequencies(&freq);
        let back = Code::from_tree(&Decoder::new(&sparse.tree()).unwrap());
        assert_eq!(back, sparse);
        assert_eq!(back.lengths.iter().filter(|&&l| l > 0).count(), 3);
    }

    #[test]
    fn bad_trees_are_refused() {
        let mut tree = Code::from_frequencies(&skewed()).tree();
        let internal = (2..TREE_SLOTS).find(|&i| tree[i] > 1).unwrap();
        let mut cyclic = tree;
        cyclic[internal] = 1;
        assert!(matches!(
            Decoder::new(&cyclic),
            Err(TreeError::Cycle { target: 1, .. })
        ));
        tree[internal] = 300;
        assert!(matches!(
            Decoder::new(&tree),
            Err(TreeError::OutOfRange { target: 300, .. })
        ));
    }
}
