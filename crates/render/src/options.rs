//! What the caller decides about how the renderer measures and draws,
//! beyond a method's settings: the measuring switches (a cached shadow map,
//! the shadow cull, the depth copy every frame, `ray-exact`'s configuration
//! and statistics) and the tests' hook that makes a build fail. The library
//! reads no environment: the CLI and the test harnesses fill these in (the
//! `strata` binary from `STRATA_*` variables) and hand them over on
//! [`crate::Gpu::options`]. [`RenderOptions::default`] is the product.

/// The renderer's measuring switches and test hooks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    /// Skip the shadow pass while the map would come out the same (off: the
    /// protocol pays for every frame's map).
    pub shadow_reuse: bool,
    /// Cast only the shadow texels the view can sample (off: the whole map,
    /// to measure the cull).
    pub shadow_cull: bool,
    /// Fill the shared depth target every frame, also for the methods that
    /// keep depth in an image of their own (to measure the copy).
    pub depth_attachment: bool,
    /// How `ray-exact` and `ray-exact-fragment` are put together.
    pub exact: ExactOptions,
    /// `ray-exact` prints its iteration statistics and GPU times to stderr
    /// when dropped.
    pub exact_stats: bool,
    /// A test hook: this method's build also asks for a buffer over the
    /// device's `max_buffer_size`, as a build too large for the GPU would.
    pub oversize_build: Option<String>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            shadow_reuse: false,
            shadow_cull: true,
            depth_attachment: false,
            exact: ExactOptions::DEFAULT,
            exact_stats: false,
            oversize_build: None,
        }
    }
}

/// How `ray-exact` is put together (H100 measurements in `bench/ray-exact.md`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExactOptions {
    /// A compute dispatch (`ray-exact`), else a fragment pass (set by the
    /// method's entry, whatever the caller passes).
    pub compute: bool,
    /// How depth reaches the shared depth target.
    pub depth: DepthMode,
    /// The shadow map by the exact march, else by the renderer's pass.
    pub exact_shadow: bool,
    /// Most levels the compute traversals climb per step (`EXACT_CLIMB`).
    pub climb: u32,
    /// log2 of the tile ratio between visited levels (`EXACT_LOG_RATIO`).
    pub log_ratio: u32,
    /// The compute variant's beam pre-pass over the whole map
    /// (`ray_exact_beam.wgsl`): camera rays start where their 8x8-pixel
    /// tile's beam may first meet the ground (the same image in fewer
    /// iterations). Off: they start at the near plane.
    pub beam: bool,
    /// How the beam is searched (with `beam` on).
    pub beam_search: BeamSearch,
    /// Most rounds of the shadow blocks' wide search, 1 to 8
    /// (`EXACT_SHADOW_ROUNDS`; the camera tiles' search takes up to 8).
    pub shadow_rounds: u32,
    /// A descent into the texels tests the texel in the same traversal
    /// iteration (`EXACT_FUSED_DESCENT`; the same hits either way). Off: the
    /// descent is an iteration of its own, as the CPU reference walks.
    pub fused_descent: bool,
    /// The compute traversals and beams skip a tile whose maximum is above
    /// the ray where the ray passes between the tile's floors and slabs
    /// (`EXACT_CAVE_SKIP`, the cave pyramid; the same hits either way). Off:
    /// they descend into it, as the CPU reference walks.
    pub cave_skip: bool,
    /// The beams test a box no wider than a texel against the (at most 2x2)
    /// texels that hold it, not the 4-texel tiles (`EXACT_BEAM_TEXELS`; the
    /// same hits, later starts). Off: the finest tiles they test are the
    /// pyramid's 4-texel ones.
    pub beam_texels: bool,
    /// How a ray walks the texels of a 4x4-texel tile it comes down into
    /// (`EXACT_TEXEL_BLOCKS`; the same hits and iterations either way).
    pub texel_walk: TexelWalk,
    /// Keep the most iterations of any camera and shadow ray
    /// (`EXACT_ITERATION_STATS`, `ExactStats::most_iterations`): a barrier
    /// and a global atomic a workgroup, so off unless asked (the renderer's
    /// `exact_stats` turns it on too). Capped rays are counted either way.
    pub iteration_stats: bool,
    /// The deferred frame keeps the shadow blocks earlier frames cast and
    /// shades in the march the pixels that read only kept blocks
    /// (`shadow_keep.wgsl`; the same pictures either way). Off casts every
    /// block a frame reads and shades in a pass of its own, for A/B.
    pub shadow_keep: bool,
    /// With [`ExactOptions::shadow_keep`]: once the kept blocks' key has held
    /// for a frame, the shadow pass casts up to this many blocks of the
    /// view's cover ahead of the march each frame, and a frame whose whole
    /// cover is cast marches and shades in one pass, with no stamps and no
    /// shadow or shading pass (`ray_exact/cover.rs`). 0: never.
    pub cover_budget: u32,
    /// The shading's fetches one after another (`SHADE_FETCH_CHAIN` in
    /// `shading.wgsl`; the same pictures): fewer registers a thread for the
    /// pipelines that shade after the march.
    pub shade_fetch_chain: bool,
    /// With [`ExactOptions::shadow_keep`]: an edit spoils only the kept
    /// blocks whose shadow rays cross the edited columns (`ray_exact/keep.rs`;
    /// the same pictures). Off, an edit forgets every kept block, for A/B.
    pub edit_keep: bool,
}

/// How `ray-exact`'s march walks the texels of a 4x4-texel tile it comes
/// down into (`EXACT_TEXEL_BLOCKS`; the same hits and iterations either
/// way). The plane (`strata_maxmip::TexelTops`: a byte per texel after the
/// pyramids, a map's area in GPU bytes) holds each column's top where it is
/// a single floor, so only columns with a slab wait on a terrain fetch.
/// Whole maps only (pages keep no plane), and only where the plane fits a
/// storage binding; else the terrain walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelWalk {
    /// A terrain fetch per texel, as the CPU reference walks.
    Terrain,
    /// From the texel plane: the tile's four row words, loaded side by side
    /// once the ray comes down into it (one more wait per tile).
    Plane,
    /// From the texel plane, its words loaded beside the tile's maximum at
    /// every step over a 4x4 tile (no wait of their own, four more loads
    /// a step).
    PlaneBeside,
}

impl TexelWalk {
    /// `EXACT_TEXEL_BLOCKS`: 0, 1 or 2.
    pub fn constant(self) -> u32 {
        match self {
            TexelWalk::Terrain => 0,
            TexelWalk::Plane => 1,
            TexelWalk::PlaneBeside => 2,
        }
    }

    /// Whether the walk reads the texel plane.
    pub fn reads_plane(self) -> bool {
        self != TexelWalk::Terrain
    }
}

/// How `ray-exact`'s beam finds where a tile's rays start
/// (`ray_exact_beam.wgsl`; the same image either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeamSearch {
    /// A pre-pass of its own, one invocation per 8x8-pixel tile walking the
    /// beam (intervals doubling while clear, halving where not); shadow
    /// blocks test 64 intervals of the light's path at once, one round.
    Serial,
    /// In the march itself: the tile's 64 invocations test 64 slices of the
    /// beam's depth range at once, then 64 sub-slices of the first slice
    /// that may hold ground (a few rounds, no pre-pass); shadow blocks
    /// likewise.
    Wide,
    /// The wide search in a pre-pass of its own (one 8x8 workgroup per tile
    /// writes the tile's start, which the march reads): the march keeps no
    /// barrier, which some compilers (llvmpipe's) pay for over the whole
    /// march. Shadow blocks as `Wide`.
    WidePass,
}

impl BeamSearch {
    /// Whether the search is the wide one (in the march or a pre-pass).
    pub fn is_wide(self) -> bool {
        matches!(self, BeamSearch::Wide | BeamSearch::WidePass)
    }
}

/// How the compute variant moves its depth image into the shared depth target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthMode {
    /// The full-screen blit (`depth_blit.wgsl`, frag_depth), clearing first.
    Blit,
    /// One point per pixel through a depth-only pipeline (no fragment shader).
    Points,
    /// The blit loading the old depth instead of clearing it first (the same
    /// image: it writes every pixel).
    BlitLoad,
}

impl ExactOptions {
    /// The chosen configuration.
    pub const DEFAULT: ExactOptions = ExactOptions {
        compute: true,
        depth: DepthMode::BlitLoad,
        exact_shadow: true,
        climb: 1,
        // Every other level (4^l tiles, as the CPU reference visits them):
        // the same image in fewer descents. On the H100 with the deferred
        // frame: 0.198 ms mean against 0.202 visiting every level.
        log_ratio: 2,
        beam: true,
        // Wide, in the march: on the H100 (one call, `bench/issue36-beam/`)
        // 0.1855 ms a frame against 0.1944 as a pre-pass (`WidePass`),
        // 0.1893 serial and 0.1966 without the beam. llvmpipe pays for the
        // barriers over the whole march (1.2-1.5x); the images are the same.
        beam_search: BeamSearch::Wide,
        shadow_rounds: 8,
        // Off: 20 % fewer iterations on paper and 10 % less march on
        // lavapipe (640x400: 31.3 -> 28.1 ms, `bench/issue36-fused-descent/`),
        // but on the H100 the fused walk is slower: in one call 0.1660 ms a
        // frame unfused against 0.1811 fused (march 0.1128 against 0.1227,
        // shadow 0.0346 against 0.0397; cave skip and texel beam off), and in
        // the next 0.1607 against 0.1738 with both on
        // (`bench/issue36-cave-skip/`).
        fused_descent: false,
        // The cave skip and the texel beam: on the H100 (unfused, one call,
        // twice each) 0.1607 ms a frame with both against 0.1663 with
        // neither and 0.1622 with the cave skip alone; march 0.1060 against
        // 0.1131 (`bench/issue36-cave-skip/`). On paper (`strata
        // exact-counts`, the twelve views, 1280x800, unfused): 9.05 -> 5.89
        // march iterations a pixel, 11.26 -> 7.99 a warp.
        cave_skip: true,
        beam_texels: true,
        // The terrain walk: on paper the plane's walks wait on fewer
        // fetches, but on the H100 they are slower (frame 0.1557 ms against
        // 0.1621 `Plane` and 0.1639 `PlaneBeside` in one call; the shadow
        // pass 22 % slower; `bench/issue36-texel-blocks/`), and they cost a
        // map's area in GPU bytes.
        texel_walk: TexelWalk::Terrain,
        // Off: on the H100 the statistic cost 0.0019 ms of a 0.1591 ms frame
        // (`bench/issue36-floors/`).
        iteration_stats: false,
        shadow_keep: true,
        // A still view's cover (4,000-14,000 blocks at 1280x800) is whole
        // within a few dozen frames; a moving one casts at most this much
        // more a frame (~0.006 ms on the H100).
        cover_budget: 256,
        shade_fetch_chain: false,
        edit_keep: true,
    };

    /// Which pyramid levels to keep: only those the traversals visit. The
    /// compute pipelines take `log_ratio` as a constant; the fragment
    /// variant's pipeline keeps the shader's default (every level).
    pub fn pyramid_step(&self) -> u32 {
        if self.compute { self.log_ratio } else { 1 }
    }
}
