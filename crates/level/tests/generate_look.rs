//! Not a check: prints the generated world's figures and writes preview
//! pictures (PPM) for a person to look at.
//! `cargo test -p strata-level --release --test generate_look -- --ignored --nocapture`

use strata_level::generate::{GenerateParams, generate, preview};

/// CPU seconds (user + system) this process has used, from /proc (Linux).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

#[test]
#[ignore]
fn look() {
    let size = std::env::var("LOOK_SIZE").unwrap_or("512x2048".into());
    let (w, h) = strata_level::generate::parse_size(&size).unwrap();
    let (t, cpu) = (std::time::Instant::now(), cpu_seconds());
    let world = generate(&GenerateParams {
        seed: 1997,
        width: w,
        height: h,
    })
    .unwrap();
    println!(
        "generated {w}x{h} in {:.2} s wall, {:.2} s CPU",
        t.elapsed().as_secs_f64(),
        cpu_seconds() - cpu
    );
    let level = &world.level;
    let stats = strata_level::stats::LevelStats::compute(level);
    let dual = stats.dual_percent / 100.0;
    let (low, comp) = (stats.roughness_floor, stats.roughness_surface);
    let mut types = [0u64; 8];
    for &m in level.metas() {
        types[usize::from((m >> 3) & 7)] += 1;
    }
    println!(
        "dual {:.2} %  lap low {low:.2}  composite {comp:.2}  ratio {:.2}",
        dual * 100.0,
        comp / low
    );
    println!("types {types:?}");
    for v in &world.views {
        println!("{v}");
    }
    println!("edit {:?}", world.edit);
    let out = std::env::var("LOOK_OUT").unwrap_or("/tmp/strata-look".into());
    std::fs::create_dir_all(&out).unwrap();
    let mut regions = vec![("overview", 0i64, 0i64, w.min(512), h.min(1024))];
    for v in world.views.iter().take(12) {
        regions.push((
            Box::leak(v.name.clone().into_boxed_str()),
            v.x as i64 - 128,
            v.y as i64 - 128,
            256,
            256,
        ));
    }
    for (name, x, y, rw, rh) in regions {
        let r = preview::Region {
            x,
            y,
            width: rw,
            height: rh,
        };
        let rgb = preview::shade(level, &world.palette, &world.config, r);
        let mut ppm = format!("P6 {rw} {rh} 255\n").into_bytes();
        ppm.extend_from_slice(&rgb);
        std::fs::write(format!("{out}/{name}.ppm"), ppm).unwrap();
    }
}
