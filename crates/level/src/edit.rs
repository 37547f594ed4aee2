//! Edits: changes to height and meta inside a rectangle, wrapping at the edges.

/// A rectangle of texels inside the map (never wrapping: an edit across the
/// map edge yields several).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DirtyRect {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}
