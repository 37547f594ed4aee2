//! The CPU replay (`replay.rs`, `replay/beam.rs`) against the GPU: the
//! same steps, and beam starts that never pass a hit.

use super::*;

/// The CPU replay (`replay.rs`) takes the GPU's steps: on every generated
/// view its hits are the reference's (hit or miss, and the distance), and
/// the most iterations of a camera ray and of a shadow ray in the frame are
/// the GPU's own counts (`ExactStats`), up to a step or two where f32
/// rounding differs on a grazed boundary; with the descent into the texels
/// fused into the texel's iteration (the default) and not.
#[test]
fn the_replay_takes_the_gpu_steps() {
    use TexelWalk::{Plane, PlaneBeside, Terrain};
    for (search, shadow_rounds, fused_descent, caves, texel_walk) in [
        (BeamSearch::Wide, 8, true, true, Terrain),
        (BeamSearch::Wide, 8, false, true, Terrain),
        (BeamSearch::Wide, 8, false, true, Plane),
        (BeamSearch::Wide, 8, false, true, PlaneBeside),
        (BeamSearch::Wide, 8, true, false, Terrain),
        (BeamSearch::Serial, 8, true, true, Terrain),
        (BeamSearch::WidePass, 8, true, true, Terrain),
        (BeamSearch::WidePass, 1, true, true, Terrain),
    ] {
        replay_takes_the_gpu_steps(search, shadow_rounds, fused_descent, caves, texel_walk);
    }
}

/// The texel plane's walks (`EXACT_TEXEL_BLOCKS`) on paper: every view's
/// rays take the same iterations to the same hits as the terrain walk's,
/// and wait on fewer fetches (a single floor's test reads the block's
/// words, loaded once per 4x4 tile, not a terrain texel); fewer still with
/// the words loaded beside the tile's maximum.
#[test]
fn the_texel_plane_walks_take_the_same_steps_waiting_on_fewer_fetches() {
    let mut waits = Vec::new();
    for walk in [TexelWalk::Plane, TexelWalk::PlaneBeside] {
        waits.push(plane_walk_against_the_terrain_walk(walk));
    }
    assert!(waits[1] < waits[0], "{waits:?}");
}

/// The summed waits a warp of `walk`, after checking it takes the terrain
/// walk's steps to the same hits and waits less.
fn plane_walk_against_the_terrain_walk(walk: TexelWalk) -> f64 {
    use super::super::replay::{Replay, replay_frame};
    let (w, pyramid) = replay_world();
    let mut plain = Replay::new(&w.level, &pyramid);
    let mut blocks = Replay::new(&w.level, &pyramid);
    blocks.traversal.texel_walk = walk;
    let (mut waits, mut block_waits) = (0.0, 0.0);
    for view in &w.views {
        let (_, globals) = view_globals(&w.level, view, (W, H));
        let a = replay_frame(&mut plain, &globals);
        let b = replay_frame(&mut blocks, &globals);
        assert_eq!(a.hits, b.hits, "{}", view.name);
        for (name, p, q) in [
            ("march", &a.march, &b.march),
            ("shadow", &a.shadow, &b.shadow),
        ] {
            assert_eq!(p.iterations, q.iterations, "{} {name}", view.name);
            assert!(
                q.terrain_reads.total < p.terrain_reads.total,
                "{} {name}: terrain reads {} with the plane, {} without",
                view.name,
                q.terrain_reads.total,
                p.terrain_reads.total
            );
        }
        waits += a.march.warp_waits + a.shadow.warp_waits;
        block_waits += b.march.warp_waits + b.shadow.warp_waits;
        for y in (0..H).step_by(7) {
            for x in (0..W).step_by(5) {
                let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                assert_eq!(
                    plain.pixel(&globals, px, py).1.hit,
                    blocks.pixel(&globals, px, py).1.hit,
                    "{} pixel ({x}, {y})",
                    view.name
                );
            }
        }
    }
    eprintln!(
        "{walk:?}: waits a warp, march + shadow, summed over the views: {waits:.1} -> {block_waits:.1}"
    );
    assert!(
        block_waits < 0.9 * waits,
        "{walk:?}: {waits} -> {block_waits}"
    );
    block_waits
}

/// The generated world and its compute pyramid, for a replay.
fn replay_world() -> (World, strata_maxmip::Pyramid) {
    let w = common::generated_world();
    let pyramid = super::super::replay::compute_pyramid(&w.level);
    (w, pyramid)
}

/// `Traversal::GPU` with the beam searched by `search` (`beam` on or off).
fn replay_traversal(search: BeamSearch, beam: bool) -> super::super::replay::Traversal {
    super::super::replay::Traversal {
        beam,
        search,
        ..super::super::replay::Traversal::GPU
    }
}

/// `caves`: the cave skip and the beams' texel test both on (the default)
/// or both off.
fn replay_takes_the_gpu_steps(
    search: BeamSearch,
    shadow_rounds: u32,
    fused_descent: bool,
    caves: bool,
    texel_walk: TexelWalk,
) {
    use super::super::replay::{Replay, replay_frame};
    let (w, pyramid) = replay_world();
    let mut replay = Replay::new(&w.level, &pyramid);
    replay.traversal = super::super::replay::Traversal {
        shadow_rounds,
        fused_descent,
        cave_skip: caves,
        beam_texels: caves,
        texel_walk,
        ..replay_traversal(search, true)
    };
    let options = ExactOptions {
        beam_search: search,
        shadow_rounds,
        fused_descent,
        cave_skip: caves,
        beam_texels: caves,
        texel_walk,
        iteration_stats: true,
        ..ExactOptions::DEFAULT
    };
    let shape = crate::frame::LevelShape::of(&w.level);
    let mut frames = Vec::new();
    for view in &w.views {
        let (camera, globals) = view_globals(&w.level, view, (W, H));
        let f = replay_frame(&mut replay, &globals);
        // Hits against the CPU reference, pixel by pixel.
        let reference = render_reference(&w.level, &camera);
        let (mut disagree, mut worst) = (0, 0.0f32);
        for y in 0..H {
            for x in 0..W {
                let (d, m) = replay.pixel(&globals, x as f32 + 0.5, y as f32 + 0.5);
                let r = reference.distance[(y * W + x) as usize];
                match (m.hit, r.is_finite()) {
                    (Some((t, _)), true) => {
                        worst = worst.max((t * d.length() - r).abs() / r.max(1.0));
                    }
                    (None, false) => {}
                    _ => disagree += 1,
                }
            }
        }
        eprintln!(
            "{search:?} {:10} replay: {} hits, march {:.1} iterations/ray (p99 {}, most {}), shadow {} rays \
             {:.1} (most {}), {} bytes; vs reference: {disagree} pixels disagree, worst relative \
             distance {worst:.2e}",
            view.name,
            f.hits,
            f.march.iterations.mean,
            f.march.iterations.p99,
            f.most_iterations,
            f.shadow.rays,
            f.shadow.iterations.mean,
            f.shadow_most_iterations,
            f.bytes(),
        );
        assert!(disagree <= 2, "{}: {disagree} pixels", view.name);
        assert!(worst < 1e-3, "{}: {worst}", view.name);
        assert!(f.march.rays == u64::from(W * H) && f.hits > 0);
        assert!(f.shadow.rays == f.shadow_blocks * 64 && f.shadow_blocks > 0);
        frames.push((camera, f));
    }
    // The GPU's counts, one fresh method per view.
    for gpu in common::gpus() {
        let colors = TerrainColors::from_world(&w);
        let r = Renderer::new(
            &gpu,
            &w.level,
            &colors,
            "ray-exact",
            &MethodSettings::default(),
            W,
            H,
        )
        .unwrap();
        let shared = r.shared_handle();
        let timer = crate::timing::PassTimer::new(&shared.device, &shared.queue, false);
        for (index, (camera, f)) in frames.iter().enumerate() {
            let mut m = build(&shared, &w.level, options).unwrap();
            let shadow = crate::shadow::ShadowFrame::fit(camera, true);
            let globals = crate::frame::Globals::new(camera, &shape, &shadow);
            record_frame(&shared, &mut m, camera, &globals, &timer, index);
            let s = m.stats().unwrap();
            eprintln!(
                "{search:?} {shadow_rounds} fused {fused_descent} caves {caves} {texel_walk:?} view {index}: most iterations GPU {} / {} (shadow), replay {} / {}",
                s.most_iterations,
                s.shadow_most_iterations,
                f.most_iterations,
                f.shadow_most_iterations
            );
            assert!(
                s.most_iterations.abs_diff(f.most_iterations) <= 2
                    && s.shadow_most_iterations.abs_diff(f.shadow_most_iterations) <= 2,
                "{search:?} view {index}: GPU {s:?}, replay {f:?}"
            );
        }
        gpu.errors.check().unwrap();
    }
}

/// The beam pre-pass (`ray_exact_beam.wgsl`, its replay `Replay::beam`)
/// never starts a tile past a hit of any of its rays, and a ray marched from
/// its tile's start finds the very hit (t and column, bit for bit) it finds
/// from the near plane (shadow rays from their block's beam likewise, at
/// 160x100), on every generated view at 160x100 and 640x400
/// (every tile, every pixel); and it saves iterations.
#[test]
fn the_beam_never_passes_a_hit() {
    for search in [BeamSearch::Wide, BeamSearch::Serial] {
        beam_never_passes_a_hit(search);
    }
}

fn beam_never_passes_a_hit(search: BeamSearch) {
    use super::super::replay::{BEAM_CAP, BEAM_TILE, Replay, WIDE_ROUNDS};
    let (w, pyramid) = replay_world();
    let mut replay = Replay::new(&w.level, &pyramid);
    replay.traversal = replay_traversal(search, false);
    // Most iterations (rounds) of a beam, and the invocations each takes:
    // the wide search's rounds are an interval test by every pixel.
    let (cap, lanes) = match search {
        BeamSearch::Serial => (BEAM_CAP, 1),
        BeamSearch::Wide | BeamSearch::WidePass => {
            (WIDE_ROUNDS, u64::from(super::super::replay::WIDE_LANES))
        }
    };
    for (width, height) in [(W, H), (640, 400)] {
        let (mut before, mut after, mut beams, mut tiles_hit) = (0u64, 0u64, 0u64, 0u64);
        for view in &w.views {
            let (_, g) = view_globals(&w.level, view, (width, height));
            for ty in 0..height.div_ceil(BEAM_TILE) {
                for tx in 0..width.div_ceil(BEAM_TILE) {
                    let b = replay.tile_start(&g, tx, ty);
                    beams += u64::from(b.iterations) * lanes;
                    assert!(b.t.is_finite() && b.iterations <= cap);
                    let mut any = false;
                    for y in ty * BEAM_TILE..((ty + 1) * BEAM_TILE).min(height) {
                        for x in tx * BEAM_TILE..((tx + 1) * BEAM_TILE).min(width) {
                            let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                            let (_, old) = replay.pixel(&g, px, py);
                            let (_, new) = replay.pixel_from(&g, px, py, Some(b.t));
                            before += u64::from(old.iterations);
                            after += u64::from(new.iterations);
                            if let Some((t, _)) = old.hit {
                                any = true;
                                assert!(
                                    t >= b.t,
                                    "{search:?} {} {width}x{height} pixel ({x}, {y}): hit at {t}, its tile starts at {}",
                                    view.name,
                                    b.t
                                );
                            }
                            assert!(
                                old.hit.map(|(t, c)| (t.to_bits(), c))
                                    == new.hit.map(|(t, c)| (t.to_bits(), c)),
                                "{search:?} {} {width}x{height} pixel ({x}, {y}): {:?} from the near plane, {:?} from the beam",
                                view.name,
                                old.hit,
                                new.hit
                            );
                        }
                    }
                    tiles_hit += u64::from(any);
                }
            }
            // Shadow rays too (and the pixels again): every texel of the
            // blocks the hits stamp, from 255 and from its block's beam.
            if width == W {
                let (differ, early) = super::super::replay::beam_disagreements(&mut replay, &g);
                assert_eq!(
                    (differ, early),
                    (0, 0),
                    "{search:?} {}: shadow beams",
                    view.name
                );
            }
        }
        let pixels = u64::from(width * height) * w.views.len() as u64;
        eprintln!(
            "{search:?} {width}x{height}: march iterations a pixel {:.2} from the near plane, {:.2} from the beam; \
             beam {:.3} a pixel; {tiles_hit} tiles with hits",
            before as f64 / pixels as f64,
            after as f64 / pixels as f64,
            beams as f64 / pixels as f64
        );
        assert!(tiles_hit > 0);
        assert!(
            after + beams < before,
            "the beam saved nothing: {before} -> {after} + {beams}"
        );
    }
}

/// The cave skip (`EXACT_CAVE_SKIP`, the cave pyramid) and the beams' texel
/// test (`EXACT_BEAM_TEXELS`) change no hit (t and column, bit for bit,
/// every pixel of every generated view at 320x200, marched from the near
/// plane and from the tile's beam) and save iterations on those views, whose
/// rays pass under slabs.
#[test]
fn the_cave_skip_and_the_texel_beam_keep_every_hit() {
    use super::super::replay::{BEAM_TILE, Replay, Traversal};
    let (w, pyramid) = replay_world();
    let mut on = Replay::new(&w.level, &pyramid);
    let mut off = Replay::new(&w.level, &pyramid);
    off.traversal = Traversal {
        cave_skip: false,
        beam_texels: false,
        ..Traversal::GPU
    };
    assert!(on.traversal.cave_skip && on.traversal.beam_texels);
    let (width, height) = (320, 200);
    let bits = |h: Option<(f32, glam::IVec2)>| h.map(|(t, c)| (t.to_bits(), c));
    let (mut iter_on, mut iter_off, mut hits) = (0u64, 0u64, 0u64);
    for view in &w.views {
        let (_, g) = view_globals(&w.level, view, (width, height));
        for ty in 0..height.div_ceil(BEAM_TILE) {
            for tx in 0..width.div_ceil(BEAM_TILE) {
                let (b_on, b_off) = (on.tile_start(&g, tx, ty).t, off.tile_start(&g, tx, ty).t);
                for y in ty * BEAM_TILE..((ty + 1) * BEAM_TILE).min(height) {
                    for x in tx * BEAM_TILE..((tx + 1) * BEAM_TILE).min(width) {
                        let (px, py) = (x as f32 + 0.5, y as f32 + 0.5);
                        let reference = off.pixel(&g, px, py).1;
                        let near = on.pixel(&g, px, py).1;
                        let (beam_on, beam_off) = (
                            on.pixel_from(&g, px, py, Some(b_on)).1,
                            off.pixel_from(&g, px, py, Some(b_off)).1,
                        );
                        for (what, m) in [
                            ("from the near plane", near),
                            ("from its beam", beam_on),
                            ("off, from its beam", beam_off),
                        ] {
                            assert!(
                                bits(m.hit) == bits(reference.hit),
                                "{} pixel ({x}, {y}) {what}: {:?}, without the skip {:?}",
                                view.name,
                                m.hit,
                                reference.hit
                            );
                        }
                        hits += u64::from(reference.hit.is_some());
                        iter_on += u64::from(beam_on.iterations);
                        iter_off += u64::from(beam_off.iterations);
                    }
                }
            }
        }
    }
    eprintln!(
        "cave skip and texel beam: {iter_on} march iterations against {iter_off} without, {hits} hits"
    );
    assert!(hits > 0);
    assert!(
        (iter_on as f64) < 0.9 * iter_off as f64,
        "{iter_on} iterations with the skip, {iter_off} without"
    );
}
