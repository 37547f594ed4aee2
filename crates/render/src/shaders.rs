//! WGSL composition: shaders live in `crates/render/shaders/*.wgsl`, embedded
//! at build time. A line `#include "name.wgsl"` is replaced by that module's
//! text, recursively; each module is included at most once per shader, so
//! modules may include their own dependencies safely. Add a new file to
//! [`SOURCES`]; `tests::every_shader_validates` checks it with naga.

/// Every WGSL file: name and text. Top-level shaders (with entry points) and
/// shared modules alike.
pub const SOURCES: &[(&str, &str)] = &[
    ("frame.wgsl", include_str!("../shaders/frame.wgsl")),
    ("surface.wgsl", include_str!("../shaders/surface.wgsl")),
    (
        "terrain_fetch.wgsl",
        include_str!("../shaders/terrain_fetch.wgsl"),
    ),
    (
        "exact_levels.wgsl",
        include_str!("../shaders/exact_levels.wgsl"),
    ),
    ("paged.wgsl", include_str!("../shaders/paged.wgsl")),
    (
        "paged_fetch.wgsl",
        include_str!("../shaders/paged_fetch.wgsl"),
    ),
    (
        "paged_levels.wgsl",
        include_str!("../shaders/paged_levels.wgsl"),
    ),
    (
        "paged_fetch_read.wgsl",
        include_str!("../shaders/paged_fetch_read.wgsl"),
    ),
    (
        "paged_stamp.wgsl",
        include_str!("../shaders/paged_stamp.wgsl"),
    ),
    (
        "mesh_paged.wgsl",
        include_str!("../shaders/mesh_paged.wgsl"),
    ),
    (
        "mesh_paged_box.wgsl",
        include_str!("../shaders/mesh_paged_box.wgsl"),
    ),
    (
        "mesh_paged_shadow.wgsl",
        include_str!("../shaders/mesh_paged_shadow.wgsl"),
    ),
    ("shading.wgsl", include_str!("../shaders/shading.wgsl")),
    (
        "column_segment.wgsl",
        include_str!("../shaders/column_segment.wgsl"),
    ),
    ("ray_core.wgsl", include_str!("../shaders/ray_core.wgsl")),
    ("ray_pixel.wgsl", include_str!("../shaders/ray_pixel.wgsl")),
    (
        "fullscreen.wgsl",
        include_str!("../shaders/fullscreen.wgsl"),
    ),
    ("ray_frag.wgsl", include_str!("../shaders/ray_frag.wgsl")),
    ("ray.wgsl", include_str!("../shaders/ray.wgsl")),
    (
        "march_beam.wgsl",
        include_str!("../shaders/march_beam.wgsl"),
    ),
    ("ray_beam.wgsl", include_str!("../shaders/ray_beam.wgsl")),
    (
        "ray_compute.wgsl",
        include_str!("../shaders/ray_compute.wgsl"),
    ),
    (
        "depth_blit.wgsl",
        include_str!("../shaders/depth_blit.wgsl"),
    ),
    (
        "depth_read.wgsl",
        include_str!("../shaders/depth_read.wgsl"),
    ),
    ("composite.wgsl", include_str!("../shaders/composite.wgsl")),
    (
        "composite_color.wgsl",
        include_str!("../shaders/composite_color.wgsl"),
    ),
    ("shadow.wgsl", include_str!("../shaders/shadow.wgsl")),
    (
        "decode_test.wgsl",
        include_str!("../shaders/decode_test.wgsl"),
    ),
    (
        "voxel_occupancy.wgsl",
        include_str!("../shaders/voxel_occupancy.wgsl"),
    ),
    (
        "voxel_core.wgsl",
        include_str!("../shaders/voxel_core.wgsl"),
    ),
    ("voxel.wgsl", include_str!("../shaders/voxel.wgsl")),
    (
        "voxel_beam.wgsl",
        include_str!("../shaders/voxel_beam.wgsl"),
    ),
    (
        "voxel_compute.wgsl",
        include_str!("../shaders/voxel_compute.wgsl"),
    ),
    (
        "voxel_build.wgsl",
        include_str!("../shaders/voxel_build.wgsl"),
    ),
    ("forward.wgsl", include_str!("../shaders/forward.wgsl")),
    ("painted.wgsl", include_str!("../shaders/painted.wgsl")),
    ("sliced.wgsl", include_str!("../shaders/sliced.wgsl")),
    (
        "sliced_walk.wgsl",
        include_str!("../shaders/sliced_walk.wgsl"),
    ),
    (
        "sliced_refine.wgsl",
        include_str!("../shaders/sliced_refine.wgsl"),
    ),
    (
        "sliced_refine_beam.wgsl",
        include_str!("../shaders/sliced_refine_beam.wgsl"),
    ),
    (
        "sliced_gaps.wgsl",
        include_str!("../shaders/sliced_gaps.wgsl"),
    ),
    (
        "sliced_gaps_beam.wgsl",
        include_str!("../shaders/sliced_gaps_beam.wgsl"),
    ),
    (
        "sliced_shade.wgsl",
        include_str!("../shaders/sliced_shade.wgsl"),
    ),
    (
        "sliced_shade_compute.wgsl",
        include_str!("../shaders/sliced_shade_compute.wgsl"),
    ),
    (
        "sliced_gap_walk.wgsl",
        include_str!("../shaders/sliced_gap_walk.wgsl"),
    ),
    (
        "sliced_shade_walk.wgsl",
        include_str!("../shaders/sliced_shade_walk.wgsl"),
    ),
    ("mesh.wgsl", include_str!("../shaders/mesh.wgsl")),
    (
        "mesh_colour.wgsl",
        include_str!("../shaders/mesh_colour.wgsl"),
    ),
    (
        "mesh_deferred.wgsl",
        include_str!("../shaders/mesh_deferred.wgsl"),
    ),
    ("scattered.wgsl", include_str!("../shaders/scattered.wgsl")),
    (
        "scattered_resolve.wgsl",
        include_str!("../shaders/scattered_resolve.wgsl"),
    ),
    (
        "ray_exact_core.wgsl",
        include_str!("../shaders/ray_exact_core.wgsl"),
    ),
    (
        "ray_exact_pixel.wgsl",
        include_str!("../shaders/ray_exact_pixel.wgsl"),
    ),
    (
        "ray_exact_beam.wgsl",
        include_str!("../shaders/ray_exact_beam.wgsl"),
    ),
    (
        "shadow_keep.wgsl",
        include_str!("../shaders/shadow_keep.wgsl"),
    ),
    (
        "paged_beam.wgsl",
        include_str!("../shaders/paged_beam.wgsl"),
    ),
    ("ray_exact.wgsl", include_str!("../shaders/ray_exact.wgsl")),
    (
        "ray_exact_fragment.wgsl",
        include_str!("../shaders/ray_exact_fragment.wgsl"),
    ),
    (
        "ray_exact_shadow.wgsl",
        include_str!("../shaders/ray_exact_shadow.wgsl"),
    ),
    (
        "ray_exact_deferred.wgsl",
        include_str!("../shaders/ray_exact_deferred.wgsl"),
    ),
    (
        "ray_exact_depth.wgsl",
        include_str!("../shaders/ray_exact_depth.wgsl"),
    ),
    (
        "ray_exact_build.wgsl",
        include_str!("../shaders/ray_exact_build.wgsl"),
    ),
    (
        "ray_exact_test.wgsl",
        include_str!("../shaders/ray_exact_test.wgsl"),
    ),
];

/// Shaders with entry points (the rest are modules); the naga test validates these.
pub const ENTRY_SHADERS: &[&str] = &[
    "ray.wgsl",
    "ray_beam.wgsl",
    "ray_compute.wgsl",
    "depth_blit.wgsl",
    "depth_read.wgsl",
    "composite.wgsl",
    "composite_color.wgsl",
    "shadow.wgsl",
    "decode_test.wgsl",
    "voxel.wgsl",
    "voxel_beam.wgsl",
    "voxel_compute.wgsl",
    "voxel_build.wgsl",
    "painted.wgsl",
    "sliced.wgsl",
    "sliced_refine.wgsl",
    "sliced_refine_beam.wgsl",
    "sliced_gaps.wgsl",
    "sliced_gaps_beam.wgsl",
    "sliced_shade.wgsl",
    "sliced_shade_compute.wgsl",
    "sliced_shade_walk.wgsl",
    "mesh.wgsl",
    "mesh_deferred.wgsl",
    "scattered.wgsl",
    "scattered_resolve.wgsl",
    "ray_exact.wgsl",
    "ray_exact_fragment.wgsl",
    "ray_exact_shadow.wgsl",
    "ray_exact_deferred.wgsl",
    "ray_exact_depth.wgsl",
    "ray_exact_build.wgsl",
    "ray_exact_test.wgsl",
    "paged:ray_exact.wgsl",
    "paged:ray_exact_fragment.wgsl",
    "paged:ray_exact_shadow.wgsl",
    "paged:ray_exact_deferred.wgsl",
    "paged-read:mesh_paged.wgsl",
    "mesh_paged_box.wgsl",
    "paged:mesh_paged_shadow.wgsl",
];

/// The name prefix that composes a shader over paged terrain (`paged/`).
pub const PAGED: &str = "paged:";

/// What a paged shader reads instead: the modules that fetch texel pairs and
/// pyramid levels from the whole map, and their page-table twins.
const PAGED_SWAPS: &[(&str, &str)] = &[
    ("terrain_fetch.wgsl", "paged_fetch.wgsl"),
    ("exact_levels.wgsl", "paged_levels.wgsl"),
    // `ray-exact`'s beam pre-pass reads the whole map's pyramid: none over pages.
    ("ray_exact_beam.wgsl", "paged_beam.wgsl"),
];

/// The name prefix that composes a shader over paged terrain read without
/// feedback (the paged mesh's vertex and fragment stages: a vertex stage
/// cannot write storage; the CPU places those draws only over resident
/// pages and asks for pages itself).
pub const PAGED_READ: &str = "paged-read:";

/// [`PAGED_SWAPS`] for [`PAGED_READ`]: texel pairs through the page table,
/// no feedback written.
const PAGED_READ_SWAPS: &[(&str, &str)] = &[
    ("terrain_fetch.wgsl", "paged_fetch_read.wgsl"),
    ("exact_levels.wgsl", "paged_levels.wgsl"),
];

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ShaderError {
    #[error("unknown WGSL module `{0}` (add it to shaders::SOURCES)")]
    Unknown(String),
    #[error("{file}:{line}: malformed include (expected `#include \"name.wgsl\"`)")]
    BadInclude { file: String, line: usize },
}

fn source(name: &str) -> Result<&'static str, ShaderError> {
    SOURCES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
        .ok_or_else(|| ShaderError::Unknown(name.to_string()))
}

/// The full WGSL text of shader `name`, includes resolved. A name with the
/// [`PAGED`] prefix composes the same shader over paged terrain: each module
/// of `PAGED_SWAPS` is replaced by its paged twin (a link-time choice, so the
/// march and shading stay one source).
pub fn compose(name: &str) -> Result<String, ShaderError> {
    let mut out = String::new();
    let mut seen = Vec::new();
    let (name, swaps) = match (name.strip_prefix(PAGED), name.strip_prefix(PAGED_READ)) {
        (Some(rest), _) => (rest, PAGED_SWAPS),
        (_, Some(rest)) => (rest, PAGED_READ_SWAPS),
        _ => (name, &[][..]),
    };
    compose_into(name, swaps, &mut out, &mut seen)?;
    Ok(out)
}

fn compose_into(
    name: &str,
    swaps: &[(&str, &str)],
    out: &mut String,
    seen: &mut Vec<String>,
) -> Result<(), ShaderError> {
    let name = swaps
        .iter()
        .find(|(from, _)| *from == name)
        .map_or(name, |(_, to)| *to);
    if seen.iter().any(|s| s == name) {
        return Ok(());
    }
    seen.push(name.to_string());
    let text = source(name)?;
    for (i, line) in text.lines().enumerate() {
        if let Some(rest) = line.trim_start().strip_prefix("#include") {
            let inner = rest
                .trim()
                .strip_prefix('"')
                .and_then(|r| r.strip_suffix('"'))
                .ok_or_else(|| ShaderError::BadInclude {
                    file: name.to_string(),
                    line: i + 1,
                })?;
            compose_into(inner, swaps, out, seen)?;
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    Ok(())
}

/// The runtime checks wgpu's shader translation adds to Strata's own
/// shaders: all of them (bounds checks where the driver has no robust
/// access, integer division guards) except naga's forced loop bounding,
/// unless `STRATA_SHADER_LOOP_BOUNDING=on` asks for it back.
///
/// Why: the bounding puts a 64-bit counter and an exit test into every loop
/// iteration, and the exact march is bound by the instructions it issues
/// per iteration: on the H100 it made `ray-exact`'s frame 14 % slower
/// (`bench/issue36-loop-bounding/`). It guards against loops that never end,
/// which a driver may treat as unreachable; every loop in these sources ends
/// by construction, and `tests::every_shader_loop_is_bounded` keeps it so.
pub fn runtime_checks() -> wgpu::ShaderRuntimeChecks {
    let mut checks = wgpu::ShaderRuntimeChecks::checked();
    checks.force_loop_bounding =
        loop_bounding_requested(std::env::var("STRATA_SHADER_LOOP_BOUNDING").ok().as_deref());
    checks
}

/// Whether `STRATA_SHADER_LOOP_BOUNDING`'s value turns naga's loop bounding
/// back on (for measuring it, or for a driver suspected of miscompiling).
fn loop_bounding_requested(value: Option<&str>) -> bool {
    matches!(value, Some("on" | "1" | "true"))
}

/// Compose and create a shader module, turning a WGSL or validation error
/// into an `Err` (wgpu would otherwise report it asynchronously).
pub fn create_module(device: &wgpu::Device, name: &str) -> anyhow::Result<wgpu::ShaderModule> {
    let text = compose(name)?;
    let descriptor = wgpu::ShaderModuleDescriptor {
        label: Some(name),
        source: wgpu::ShaderSource::Wgsl(text.into()),
    };
    // In a browser a bad shader reaches the device's error sink instead
    // (checked after each frame).
    let (module, error) = crate::gpu::catching(device, wgpu::ErrorFilter::Validation, || {
        // SAFETY: the one check `runtime_checks` leaves out is the loop
        // bounding, whose contract is that no loop of the shader runs
        // forever. Every loop in `SOURCES` either counts towards a bound it
        // cannot overflow or says in a `// Bounded:` comment why it ends
        // (the iteration caps of the exact march and the beam, the step
        // limits of the sampled march); `every_shader_loop_is_bounded`
        // fails on a loop that does neither. Bounds checks stay on.
        unsafe { device.create_shader_module_trusted(descriptor, runtime_checks()) }
    });
    if let Some(err) = error {
        anyhow::bail!("shader `{name}` failed to compile: {err}");
    }
    Ok(module)
}

/// The loops of WGSL `text` that neither count up by one towards a strict
/// bound (`for (var i = ..; i < n; i = i + 1u)`, `i++`, `i += 1`) nor carry
/// a `// Bounded:` comment in the comment lines just above them saying why
/// they end: their line numbers (1-based). What [`runtime_checks`] relies on.
#[cfg(test)]
fn unexplained_loops(text: &str) -> Vec<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let code = line.split("//").next().unwrap_or("").trim();
        let is_loop = code.starts_with("loop {")
            || code.starts_with("loop{")
            || code.starts_with("while ")
            || code.starts_with("while(")
            || code.starts_with("for ")
            || code.starts_with("for(");
        if !is_loop || counts_up_to_a_strict_bound(code) {
            continue;
        }
        let explained = lines[..i]
            .iter()
            .rev()
            .map(|l| l.trim())
            .take_while(|l| l.starts_with("//"))
            .any(|l| l.contains("Bounded:"));
        if !explained {
            found.push(i + 1);
        }
    }
    found
}

/// `for (var X = ..; X < ..; X = X + 1)` (or `X++`, `X += 1`, with or
/// without a `u`): X rises by one each pass and stops below a bound it
/// cannot overflow past.
#[cfg(test)]
fn counts_up_to_a_strict_bound(code: &str) -> bool {
    let Some(inner) = code
        .strip_prefix("for")
        .map(str::trim_start)
        .and_then(|r| r.strip_prefix('('))
        .and_then(|r| r.rsplit_once(')'))
        .map(|(header, _)| header)
    else {
        return false;
    };
    let parts: Vec<&str> = inner.split(';').map(str::trim).collect();
    let [init, cond, update] = parts[..] else {
        return false;
    };
    let Some(var) = init
        .strip_prefix("var ")
        .and_then(|r| r.split('=').next())
        .map(|v| v.split(':').next().unwrap_or("").trim())
        .filter(|v| !v.is_empty())
    else {
        return false;
    };
    let strict = cond
        .strip_prefix(var)
        .map(str::trim_start)
        .is_some_and(|r| r.starts_with('<') && !r.starts_with("<="));
    let one = |r: &str| matches!(r.trim(), "1" | "1u" | "1i");
    let by_one = update == format!("{var}++")
        || update
            .strip_prefix(var)
            .and_then(|r| r.trim_start().strip_prefix("+="))
            .is_some_and(one)
        || update
            .strip_prefix(var)
            .and_then(|r| r.trim_start().strip_prefix('='))
            .and_then(|r| r.trim_start().strip_prefix(var))
            .and_then(|r| r.trim_start().strip_prefix('+'))
            .is_some_and(one);
    strict && by_one
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shader_loop_is_bounded() {
        let mut missing = Vec::new();
        for (name, text) in SOURCES {
            for line in unexplained_loops(text) {
                missing.push(format!("{name}:{line}"));
            }
        }
        assert!(
            missing.is_empty(),
            "loops that neither count up to a strict bound nor say `// Bounded:` why they end \
             (shaders are created without naga's loop bounding, see `runtime_checks`): {missing:?}"
        );
    }

    #[test]
    fn the_loop_lint_tells_bounded_loops_from_the_rest() {
        let counted = "for (var i = 0u; i < n; i = i + 1u) {\nfor (var k = 0u; k < 6u; k++) {\nfor (var j: u32 = 2u; j < m; j += 1u) {";
        assert!(unexplained_loops(counted).is_empty());
        let text = "fn f() {\n    loop {\n    }\n    // Why it ends.\n    while (a < b) {\n    }\n    \
                    for (var i = 0u; i <= n; i = i + 1u) {\n    for (var i = 0u; i < n; i = i + 2u) {\n    \
                    for (; i < n; i = i + 1u) {\n    for (var i = n; i > 0u; i = i - 1u) {\n    \
                    // Bounded: n is at most 8.\n    // (more words)\n    loop {\n}";
        assert_eq!(unexplained_loops(text), vec![2, 5, 7, 8, 9, 10]);
    }

    #[test]
    fn loop_bounding_is_off_unless_asked_for() {
        assert!(!loop_bounding_requested(None));
        assert!(!loop_bounding_requested(Some("off")));
        assert!(loop_bounding_requested(Some("on")));
        assert!(loop_bounding_requested(Some("1")));
    }

    #[test]
    fn every_shader_validates() {
        for name in ENTRY_SHADERS {
            let text = compose(name).unwrap();
            let module = naga::front::wgsl::parse_str(&text)
                .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&text)));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::default(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{name}: {e:?}"));
        }
    }

    #[test]
    fn includes_resolve_once() {
        let text = compose("ray.wgsl").unwrap();
        assert_eq!(text.matches("struct Globals").count(), 1);
        assert!(!text.contains("#include"));
    }

    #[test]
    fn paged_shaders_swap_the_fetch_modules() {
        let whole = compose("ray_exact.wgsl").unwrap();
        let paged = compose("paged:ray_exact.wgsl").unwrap();
        assert!(whole.contains("textureLoad(terrain, vec2<u32>(px, row)"));
        assert!(!whole.contains("page_table"));
        assert!(paged.contains("page_table"));
        assert!(!paged.contains("textureLoad(terrain, vec2<u32>(px, row)"));
    }

    #[test]
    fn unknown_module_is_an_error() {
        assert_eq!(
            compose("nope.wgsl"),
            Err(ShaderError::Unknown("nope.wgsl".into()))
        );
    }
}
