//! Wavefront OBJ: `v x y z r g b` (the vertex-colour extension Blender,
//! MeshLab and most importers read), then `f` lines (1-based).

use crate::soup::TerrainSoup;
use std::io::{BufWriter, Write};

pub fn write(soup: &TerrainSoup, out: &mut impl Write) -> std::io::Result<()> {
    let mut w = BufWriter::new(out);
    writeln!(
        w,
        "# Strata terrain export: {} vertices, {} triangles, max error {}",
        soup.positions.len(),
        soup.triangles.len(),
        soup.max_error
    )?;
    writeln!(
        w,
        "# y-up: (x, altitude, -y) of the texel frame, colours 0..1"
    )?;
    for (p, c) in soup.positions.iter().zip(&soup.colors) {
        writeln!(
            w,
            "v {} {} {} {:.4} {:.4} {:.4}",
            p[0],
            p[2],
            -p[1],
            f32::from(c[0]) / 255.0,
            f32::from(c[1]) / 255.0,
            f32::from(c[2]) / 255.0
        )?;
    }
    for t in &soup.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}
