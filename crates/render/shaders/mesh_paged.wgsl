// `mesh` over paged terrain (`methods/mesh/paged.rs`), composed `paged-read:`:
// the vertex and fragment stages of `mesh.wgsl`, texels read through the page
// table. The CPU draws a chunk copy this way only when its fit is in the
// index pool and every page its vertices and colour window read is resident,
// so nothing here is pending (the stand-ins are `mesh_paged_box.wgsl`).
#include "mesh.wgsl"
#include "paged_stamp.wgsl"
