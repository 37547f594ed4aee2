//! Not a check: prints the generated world's figures and writes preview
//! pictures (PPM) for a person to look at.
//! `cargo test -p strata-level --release --test generate_look -- --ignored --nocapture`

use strata_level::generate::{GenerateParams, generate, preview};

fn lap_figures(level: &strata_level::Level) -> (f64, f64) {
    let (w, h) = (level.width() as i64, level.height() as i64);
    let (mut low, mut comp) = (0f64, 0f64);
    let cols: Vec<_> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| level.column(x, y))
        .collect();
    let at = |x: i64, y: i64| cols[(y.rem_euclid(h) * w + x.rem_euclid(w)) as usize];
    for y in 0..h {
        for x in 0..w {
            let c = at(x, y);
            let n = [at(x - 1, y), at(x + 1, y), at(x, y - 1), at(x, y + 1)];
            let lap = |f: &dyn Fn(&strata_level::Column) -> u8| {
                (n.iter().map(|c| i32::from(f(c))).sum::<i32>() - 4 * i32::from(f(&c))).abs() as f64
            };
            let l = lap(&|c| c.low);
            low += l;
            comp += (l + lap(&|c| c.mid) + lap(&|c| c.high)) / 3.0;
        }
    }
    let n = (w * h) as f64;
    (low / n, comp / n)
}

#[test]
#[ignore]
fn look() {
    let size = std::env::var("LOOK_SIZE").unwrap_or("512x2048".into());
    let (w, h) = strata_level::generate::parse_size(&size).unwrap();
    let t = std::time::Instant::now();
    let world = generate(&GenerateParams {
        seed: 1997,
        width: w,
        height: h,
    })
    .unwrap();
    println!("generated {w}x{h} in {:.2} s", t.elapsed().as_secs_f64());
    let level = &world.level;
    let dual = level.dual_texel_count() as f64 / (w as f64 * h as f64);
    let (low, comp) = lap_figures(level);
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
