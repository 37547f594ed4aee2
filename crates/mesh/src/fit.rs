//! The greedy fit of one chunk (Garland–Heckbert): border vertices first,
//! then the globally worst sample until every sample is within tolerance.
//! Greedy insertion never depends on the tolerance until it stops, so the
//! coarser LODs are prefixes of the finest fit: one run yields all three,
//! snapshotted when the worst error first drops to 4τ, 2τ and τ.

use std::collections::BinaryHeap;

use strata_level::Level;

use crate::border::{exceeds, fit_border, fit_border_slab};
use crate::candidate::{Candidate, barycentric, errors, scan, scan_slab};
use crate::emit::{ChunkMesh, Emitter, Parts};
pub use crate::lod::{CAUSES, Cause, LODS};
use crate::predicates::Pt;
use crate::samples::{ChunkLayout, ChunkSamples, DUAL_INTERIOR, Sample};
use crate::triangulation::Triangulation;

/// How a fit runs, besides its tolerance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub struct FitOptions {
    /// The outline fit (issue 17): the floor and the slab get a
    /// triangulation each. The floor's is fitted on `low` alone, everywhere
    /// (single samples and the floor under a slab alike: the field that is
    /// drawn as the ground). The slab's is constrained to the single/double
    /// region outline: only its slab triangles (three dual vertices, no
    /// edge across a gap between slab columns:
    /// [`Triangulation::is_slab`](crate::triangulation::Triangulation::is_slab)) are
    /// drawn, as slab top, cave ceiling and walls, and they are measured on
    /// `mid` and `high` over every sample they cover, while a dual sample
    /// that no slab triangle draws costs its whole slab. So the slab is
    /// never interpolated across the outline, single samples never drive
    /// the slab's error and the slab never drives the floor's.
    pub outline: bool,
}

/// One of the outline fit's two triangulations ([`ChunkFitter::fit_outline_part`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutlinePart {
    /// The floor, fitted on `low` alone.
    Floor,
    /// The slab, constrained to the outline.
    Slab,
}

/// What one outline part emitted, waiting for [`join_outline_parts`].
pub struct OutlinePartFit {
    emitter: Emitter,
    causes: [u32; CAUSES],
    vertices: usize,
}

/// The chunk mesh of the outline fit from its two parts (in either order):
/// the same mesh as [`ChunkFitter::fit_with`] with the outline option.
pub fn join_outline_parts(a: OutlinePartFit, b: OutlinePartFit) -> ChunkMesh {
    let mut emitter = a.emitter;
    emitter.absorb(&b.emitter);
    let mut mesh = ChunkMesh::default();
    emitter.finish(&mut mesh, (a.vertices + b.vertices) as u32);
    mesh.stats.causes = std::array::from_fn(|k| a.causes[k] + b.causes[k]);
    mesh
}

/// Which triangulation a greedy run builds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Pass {
    /// The plain fit: one triangulation for all three fields.
    #[default]
    Coupled,
    /// The outline fit's floor (on samples made single at `low`).
    Floor,
    /// The outline fit's slab, constrained to the outline.
    Slab,
}

/// Reusable scratch for fitting chunks one after another on one thread.
#[derive(Default)]
pub struct ChunkFitter {
    samples: ChunkSamples,
    /// The floor view of `samples` (outline fit).
    floor_samples: ChunkSamples,
    tr: Triangulation,
    /// The outline fit's floor triangulation (the last one fitted).
    floor_tr: Triangulation,
    pass: Pass,
    heap: BinaryHeap<Candidate>,
    stamps: Vec<u32>,
    seen: Vec<u32>,
    /// Sample index of each vertex.
    vsample: Vec<u32>,
    border: Vec<u32>,
    edge: Vec<Sample>,
    emitter: Emitter,
}

impl ChunkFitter {
    /// Fit chunk `(cx, cy)` of `level` at finest tolerance `tol` (> 0).
    pub fn fit(
        &mut self,
        level: &Level,
        layout: &ChunkLayout,
        cx: u32,
        cy: u32,
        tol: f64,
    ) -> ChunkMesh {
        self.fit_with(level, layout, cx, cy, tol, FitOptions::default())
    }

    /// [`fit`](Self::fit) with `options`.
    pub fn fit_with(
        &mut self,
        level: &Level,
        layout: &ChunkLayout,
        cx: u32,
        cy: u32,
        tol: f64,
        options: FitOptions,
    ) -> ChunkMesh {
        self.start(level, layout, cx, cy);
        let mut causes = [0u32; CAUSES];
        let vertices = if options.outline {
            self.floor_pass(tol, &mut causes) + self.slab_pass(tol, &mut causes)
        } else {
            self.greedy(tol, Pass::Coupled, &mut causes);
            self.tr.pts.len()
        };
        let mut mesh = ChunkMesh::default();
        self.emitter.finish(&mut mesh, vertices as u32);
        mesh.stats.causes = causes;
        mesh
    }

    /// One of the outline fit's two triangulations of chunk `(cx, cy)`, to
    /// be joined with the other by [`join_outline_parts`]: the two are
    /// independent, so an edit's refit can run them on two threads. The
    /// join equals [`fit_with`](Self::fit_with) with the outline option.
    pub fn fit_outline_part(
        &mut self,
        level: &Level,
        layout: &ChunkLayout,
        (cx, cy): (u32, u32),
        tol: f64,
        part: OutlinePart,
    ) -> OutlinePartFit {
        self.start(level, layout, cx, cy);
        let mut causes = [0u32; CAUSES];
        let vertices = match part {
            OutlinePart::Floor => self.floor_pass(tol, &mut causes),
            OutlinePart::Slab => self.slab_pass(tol, &mut causes),
        };
        OutlinePartFit {
            emitter: std::mem::take(&mut self.emitter),
            causes,
            vertices,
        }
    }

    /// Load chunk `(cx, cy)` and start its emission.
    fn start(&mut self, level: &Level, layout: &ChunkLayout, cx: u32, cy: u32) {
        self.samples.load(level, layout, cx, cy);
        self.emitter.begin(self.samples.size_x, self.samples.size_y);
    }

    /// The outline fit's floor: fitted on `low` alone (the floor view of
    /// the samples), left in `floor_tr`. Returns its vertex count.
    fn floor_pass(&mut self, tol: f64, causes: &mut [u32; CAUSES]) -> usize {
        self.floor_samples.floor_of(&self.samples);
        std::mem::swap(&mut self.samples, &mut self.floor_samples);
        self.greedy(tol, Pass::Floor, causes);
        std::mem::swap(&mut self.samples, &mut self.floor_samples);
        std::mem::swap(&mut self.tr, &mut self.floor_tr);
        self.floor_tr.pts.len()
    }

    /// The outline fit's slab triangulation, where the chunk has a slab.
    /// Returns its vertex count (0 without a slab).
    fn slab_pass(&mut self, tol: f64, causes: &mut [u32; CAUSES]) -> usize {
        let (sx, sy) = (self.samples.size_x as i32, self.samples.size_y as i32);
        if self.samples.duals_in(0, 0, sx, sy) > 0 {
            self.greedy(tol, Pass::Slab, causes);
            self.tr.pts.len()
        } else {
            self.tr.reset(sx, sy);
            self.tr.outline = true;
            0
        }
    }

    /// One greedy fit of `self.samples` into `self.tr` (border vertices,
    /// then the worst sample until within `tol`), emitting each LOD's part
    /// of the pass as the worst error drops under its tolerance.
    fn greedy(&mut self, tol: f64, pass: Pass, causes: &mut [u32; CAUSES]) {
        self.pass = pass;
        let (sx, sy) = (self.samples.size_x as i32, self.samples.size_y as i32);
        let stride = self.samples.stride();
        self.tr.reset(sx, sy);
        self.tr.outline = pass == Pass::Slab;
        if self.tr.outline {
            self.tr.gaps.load(&self.samples);
        }
        self.vsample.clear();
        let mut corners = [false; 4];
        for (v, dual) in corners.iter_mut().enumerate() {
            let p = self.tr.pts[v];
            let i = p[1] as usize * stride + p[0] as usize;
            self.vsample.push(i as u32);
            *dual = self.samples.samples[i].dual();
        }
        self.tr.classify_corners(corners);

        // Borders: the four edges, each fitted in 1D from its own samples.
        let edges: [(Pt, Pt, i32); 4] = [
            ([0, 0], [1, 0], sx),
            ([0, sy], [1, 0], sx),
            ([0, 0], [0, 1], sy),
            ([sx, 0], [0, 1], sy),
        ];
        for (start, step, len) in edges {
            self.edge.clear();
            for k in 0..=len {
                let p = [start[0] + step[0] * k, start[1] + step[1] * k];
                self.edge.push(*self.samples.at(p[0], p[1]));
            }
            if pass == Pass::Slab {
                fit_border_slab(&self.edge, tol, &mut self.border);
            } else {
                fit_border(&self.edge, tol, &mut self.border);
            }
            for &k in &self.border {
                let p = [start[0] + step[0] * k as i32, start[1] + step[1] * k as i32];
                let Some((t, _)) = self.tr.locate_scan(p) else {
                    continue;
                };
                let dual = self.samples.at(p[0], p[1]).dual();
                if self.tr.insert_classed(t, p, dual).is_some() {
                    self.vsample
                        .push((p[1] as usize * stride + p[0] as usize) as u32);
                    causes[Cause::Border as usize] += 1;
                }
            }
        }

        // Candidates of every triangle.
        self.heap.clear();
        self.stamps.clear();
        self.seen.clear();
        for t in 0..self.tr.tris.len() as u32 {
            self.stamps.push(0);
            self.seen.push(0);
            self.push_candidate(t, tol);
        }

        let parts = match pass {
            Pass::Coupled => Parts::Both,
            Pass::Floor => Parts::Floor,
            Pass::Slab => Parts::Slab,
        };
        let lod_tols: [f64; LODS] = [tol, tol * 2.0, tol * 4.0];
        let mut next_lod = LODS; // coarsest first: LOD 2, then 1, then 0
        let mut epoch = 0u32;
        loop {
            while let Some(top) = self.heap.peek() {
                if self.stamps[top.tri() as usize] == top.stamp() {
                    break;
                }
                self.heap.pop();
            }
            let top = self.heap.peek().copied();
            while next_lod > 0 && top.is_none_or(|c| c.error() <= lod_tols[next_lod - 1]) {
                next_lod -= 1;
                self.emitter.emit_lod_parts(
                    next_lod,
                    &self.tr,
                    &self.vsample,
                    &self.samples,
                    parts,
                );
            }
            let Some(c) = top else { break };
            if next_lod == 0 {
                break;
            }
            self.heap.pop();
            let stride = stride as u32;
            let p = [(c.sample() % stride) as i32, (c.sample() / stride) as i32];
            causes[self.cause(c.tri(), p) as usize] += 1;
            let dual = self.samples.samples[c.sample() as usize].dual();
            if self.tr.insert_classed(c.tri(), p, dual).is_none() {
                // Cannot happen for a candidate of a live triangle; drop it.
                continue;
            }
            self.vsample.push(c.sample());
            epoch += 1;
            while self.stamps.len() < self.tr.tris.len() {
                self.stamps.push(0);
                self.seen.push(0);
            }
            for i in 0..self.tr.touched.len() {
                let t = self.tr.touched[i];
                if self.seen[t as usize] == epoch {
                    continue;
                }
                self.seen[t as usize] = epoch;
                self.stamps[t as usize] = self.stamps[t as usize].wrapping_add(1);
                self.push_candidate(t, tol);
            }
        }
    }

    fn push_candidate(&mut self, t: u32, tol: f64) {
        let tri = self.tr.tris[t as usize];
        let pts = tri.v.map(|v| self.tr.pt(v));
        let zs = tri
            .v
            .map(|v| self.samples.samples[self.vsample[v as usize] as usize].z);
        let (num, den, sample) = if self.pass == Pass::Slab {
            let covered = self.tr.slab_edges(t);
            scan_slab(pts, zs, self.tr.is_slab(t), covered, &self.samples)
        } else {
            scan(pts, zs, &self.samples)
        };
        if num > 0 && exceeds(num, den, tol) {
            self.heap
                .push(Candidate::new(num, den, sample, t, self.stamps[t as usize]));
        }
    }

    /// The cause of inserting grid point `p` of triangle `t`.
    fn cause(&self, t: u32, p: Pt) -> Cause {
        let tri = self.tr.tris[t as usize];
        let s = self.samples.at(p[0], p[1]);
        let all_dual = tri
            .v
            .iter()
            .all(|&v| self.samples.samples[self.vsample[v as usize] as usize].dual());
        match self.pass {
            Pass::Floor => return Cause::Floor,
            // The slab's own relief, or the outline: a single sample under
            // a slab triangle, a dual sample that no slab triangle draws.
            Pass::Slab => {
                return if self.tr.is_slab(t) && s.dual() {
                    Cause::SlabInterior
                } else {
                    Cause::Boundary
                };
            }
            Pass::Coupled => {}
        }
        let [a, b, c] = tri.v.map(|v| self.tr.pt(v));
        let zs = tri
            .v
            .map(|v| self.samples.samples[self.vsample[v as usize] as usize].z);
        let den = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
        let e = errors(barycentric(a, b, c, p), den, zs, s.z);
        if e[0] >= e[1] && e[0] >= e[2] {
            Cause::Floor
        } else if all_dual && s.flags & DUAL_INTERIOR != 0 {
            Cause::SlabInterior
        } else {
            Cause::Boundary
        }
    }

    /// The outline fit's floor triangulation, of the last chunk fitted with
    /// the outline option (tests inspect it).
    pub fn floor_triangulation(&self) -> &Triangulation {
        &self.floor_tr
    }

    /// The working triangulation of the last fit (tests inspect it): with
    /// the outline option, the slab's.
    pub fn triangulation(&self) -> &Triangulation {
        &self.tr
    }

    /// The samples of the last fitted chunk.
    pub fn samples(&self) -> &ChunkSamples {
        &self.samples
    }
}
