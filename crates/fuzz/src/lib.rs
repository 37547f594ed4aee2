//! Structure-aware fuzzing of every reader a user's file reaches (issue 20).
//!
//! Each [`readers::Reader`] starts from valid files ([`seeds`]) and mutates
//! them with proptest strategies ([`mutate`]): truncation, bit flips, byte
//! runs inserted or deleted, and per format the structures that matter (the
//! `.vmc` row table and Huffman trees, declared map sizes, text lines and
//! tokens replaced by extreme values). A reader passes an input when it
//! returns `Ok` or an error naming the file, without panicking, and
//! without allocating more than a small multiple of the input
//! ([`alloc`]). [`driver`] runs a reader for a number of inputs or seconds
//! and keeps failing inputs as regression files.

pub mod alloc;
pub mod driver;
pub mod mutate;
pub mod readers;
pub mod seeds;
