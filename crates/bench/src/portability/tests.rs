use super::*;
use crate::fixtures;
use crate::results::{Failure, ViewImage};

fn input(run: RunResults, dir: &Path) -> Input {
    Input {
        path: dir.join(run.file_name()),
        run,
    }
}

fn run_on(name: &str, backend: &str) -> RunResults {
    let mut r = fixtures::run(name);
    r.adapter.backend = backend.into();
    r
}

fn cell<'a>(g: &'a ProtocolGroup, view: &str, method: &str) -> &'a CellSpread {
    g.cells
        .iter()
        .find(|c| c.view == view && c.method == method)
        .unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("strata-port-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn spread_is_max_minus_min_and_disagreements_come_first() {
    let a = run_on("gpu", "vulkan");
    let mut b = run_on("gpu", "gl");
    let mut c = run_on("cpu", "vulkan");
    // river/ray see-through 0.6 (a), 0.9 (b), 1.4 (c): spread 0.8 > 0.5.
    b.rows[0].see_through = 0.9;
    c.rows[0].see_through = 1.4;
    // spiral/mesh depth p95 1.5, 1.5, 4.5: spread 3.0 (6x tolerance): worst, so first.
    c.rows[3].depth_p95 = 4.5;
    // river/mesh coherence within tolerance: 0.1 vs 0.5.
    b.rows[1].coherence = 0.5;
    let dir = Path::new("/nonexistent");
    let inputs = vec![input(a, dir), input(b, dir), input(c, dir)];
    let p = build(&inputs, Vec::new(), dir);
    assert_eq!(p.groups.len(), 1);
    let g = &p.groups[0];
    assert_eq!(
        g.adapters,
        vec!["gpu (vulkan)", "gpu (gl)", "cpu (vulkan)"],
        "the same GPU on two backends stays two adapters"
    );
    assert_eq!(g.disagreeing_cells, 2);
    let order: Vec<(&str, &str)> = g
        .cells
        .iter()
        .map(|c| (c.view.as_str(), c.method.as_str()))
        .collect();
    assert_eq!(
        order,
        vec![
            ("spiral", "mesh"),
            ("river", "ray"),
            ("river", "mesh"),
            ("spiral", "ray")
        ]
    );
    let rr = cell(g, "river", "ray");
    let s = rr.spread.unwrap();
    assert!((s.see_through - 0.8).abs() < 1e-12, "{s:?}");
    assert_eq!(s.coherence, 0.0);
    assert_eq!(rr.disagrees, vec!["see_through"]);
    let rm = cell(g, "river", "mesh");
    assert!((rm.spread.unwrap().coherence - 0.4).abs() < 1e-12);
    assert!(rm.disagrees.is_empty());
    assert_eq!(cell(g, "spiral", "mesh").disagrees, vec!["depth_p95"]);
    // Pitch means: ray at 0° is river alone; spread of the means 0.8.
    let mean = |adapter: &str| {
        g.pitch_means
            .iter()
            .find(|m| m.adapter == adapter && m.method == "ray" && m.pitch == 0.0)
            .unwrap()
            .mean
            .see_through
    };
    assert_eq!(
        (mean("gpu (vulkan)"), mean("gpu (gl)"), mean("cpu (vulkan)")),
        (0.6, 0.9, 1.4)
    );
    let ps = g
        .pitch_spreads
        .iter()
        .find(|s| s.method == "ray" && s.pitch == 0.0)
        .unwrap();
    assert!((ps.spread.see_through - 0.8).abs() < 1e-12);

    let ray_max = g
        .method_max_spreads
        .iter()
        .find(|m| m.method == "ray")
        .unwrap();
    assert!((ray_max.max.see_through - 0.8).abs() < 1e-12);
    assert_eq!(ray_max.max.depth_p95, 0.0);
    let mesh_max = g
        .method_max_spreads
        .iter()
        .find(|m| m.method == "mesh")
        .unwrap();
    assert!((mesh_max.max.depth_p95 - 3.0).abs() < 1e-12);
    assert!((mesh_max.max.coherence - 0.4).abs() < 1e-12);
    let md = render_markdown(&p);
    assert!(
        md.contains("| mesh | 0.000 | 0.000 | 0.000 | 3.000 | 0.400 |"),
        "{md}"
    );
    let first = md.find("**spiral / mesh**").expect("spiral/mesh listed");
    let second = md.find("**river / ray**").expect("river/ray listed");
    assert!(first < second, "{md}");
    assert!(
        md.contains("### Cells that disagree across adapters (2 of 4)"),
        "{md}"
    );
    assert!(
        md.contains("| river | 0 | ray | **0.800** | 0.000 | 0.000 | 0.000 | 0.000 | 3 / 3 |"),
        "{md}"
    );
    assert!(
        md.contains("| ray / 0° | 0.60 / 0.40 | 0.90 / 0.40 | 1.40 / 0.40 | 0.80 / 0.00 |"),
        "{md}"
    );
}

#[test]
fn different_protocols_form_groups_that_are_not_compared() {
    let a = run_on("gpu", "vulkan");
    let mut b = run_on("lavapipe", "vulkan");
    let mut c = run_on("llvmpipe", "gl");
    for r in [&mut b, &mut c] {
        r.settings.width = 16;
        r.settings.height = 10;
        // Far off, but not compared with the 32x20 run.
        r.rows[0].see_through = 50.0;
    }
    let dir = Path::new("/nonexistent");
    let inputs = vec![input(a, dir), input(b, dir), input(c, dir)];
    let p = build(&inputs, Vec::new(), dir);
    assert_eq!(p.groups.len(), 2);
    let (ga, gb) = (&p.groups[0], &p.groups[1]);
    assert_eq!(ga.adapters, vec!["gpu (vulkan)"]);
    assert_eq!(gb.adapters, vec!["lavapipe (vulkan)", "llvmpipe (gl)"]);
    assert!(ga.separate_because.is_none());
    let why = gb.separate_because.as_deref().unwrap();
    assert!(why.contains("size 16x10"), "{why}");
    assert_eq!(p.runs[1].group, "B");
    assert_eq!(ga.disagreeing_cells, 0);
    assert!(ga.cells.iter().all(|c| c.spread.is_none()));
    assert_eq!(gb.disagreeing_cells, 0, "both 16x10 runs agree");
    let md = render_markdown(&p);
    assert!(
        md.contains("merge refuses to compare accuracy across groups"),
        "{md}"
    );
    assert!(
        md.contains("Not compared with group A: lavapipe: size 16x10"),
        "{md}"
    );
    assert!(md.contains("## Group B: 16x10"), "{md}");
    assert!(md.contains("One adapter under this protocol"), "{md}");
}

#[test]
fn refusals_are_listed_and_not_counted_as_disagreements() {
    let a = run_on("gpu", "vulkan");
    let mut b = run_on("llvmpipe", "gl");
    // mesh refused on b before any GPU work; b also lost spiral/ray (interrupted).
    b.rows
        .retain(|r| r.method != "mesh" && !(r.view == "spiral" && r.method == "ray"));
    b.failures.push(Failure {
        view: "*".into(),
        method: "mesh".into(),
        error: "mesh: needs compute shaders, which this adapter lacks".into(),
    });
    let dir = Path::new("/nonexistent");
    let p = build(&[input(a, dir), input(b, dir)], Vec::new(), dir);
    let g = &p.groups[0];
    let rm = cell(g, "river", "mesh");
    assert!(rm.disagrees.is_empty(), "{rm:?}");
    assert_eq!(rm.values.len(), 1);
    assert!(rm.spread.is_none());
    assert_eq!(
        rm.absent[0].failure.as_deref(),
        Some("mesh: needs compute shaders, which this adapter lacks")
    );
    let sr = cell(g, "spiral", "ray");
    assert_eq!(sr.disagrees, vec!["cell"]);
    assert_eq!(g.cells[0].view, "spiral", "the missing cell comes first");
    assert_eq!(g.failures.len(), 1);
    assert_eq!(g.failures[0].adapter, "llvmpipe (gl)");
    let md = render_markdown(&p);
    assert!(
        md.contains(
            "| llvmpipe (gl) | mesh | every view | mesh: needs compute shaders, which this adapter lacks |"
        ),
        "{md}"
    );
    assert!(md.contains("| llvmpipe (gl) | — | — | — | — | — | missing (run incomplete) |"));
}

#[test]
fn timing_rows_stay_apart_per_adapter_and_source() {
    let a = run_on("gpu", "vulkan");
    let mut b = run_on("llvmpipe", "gl");
    b.adapter.timestamps = false;
    for r in &mut b.rows {
        *r = fixtures::row(&r.view, r.pitch, &r.method, r.see_through, r.coherence, &[]);
    }
    let dir = Path::new("/nonexistent");
    let p = build(&[input(a, dir), input(b, dir)], Vec::new(), dir);
    let g = &p.groups[0];
    let sources = |adapter: &str| {
        let mut s: Vec<TimingSource> = g
            .timing
            .iter()
            .filter(|t| t.adapter == adapter)
            .map(|t| t.source)
            .collect();
        s.dedup();
        s
    };
    assert_eq!(
        sources("gpu (vulkan)"),
        vec![TimingSource::GpuTimestamps, TimingSource::CpuSubmitWait]
    );
    assert_eq!(sources("llvmpipe (gl)"), vec![TimingSource::CpuSubmitWait]);
    let md = render_markdown(&p);
    // ray GPU: river 5, spiral 7 -> 6 over all views; CPU is GPU + 1.
    assert!(
        md.contains("| gpu (vulkan) | GPU timestamps | all views | 6.000 | 2.500 |"),
        "{md}"
    );
    assert!(md.contains("| gpu (vulkan) | CPU submit-and-wait | all views | 7.000 | 3.500 |"));
    assert!(md.contains("| llvmpipe (gl) | CPU submit-and-wait | 0° | 5.000 | 5.000 |"));
    assert!(!md.contains("| llvmpipe (gl) | GPU timestamps"));
    assert_eq!(p.runs[1].timing_sources, vec![TimingSource::CpuSubmitWait]);
}

#[test]
fn written_report_has_side_by_side_pictures_and_round_trips() {
    let root = tmp("write");
    let mut runs = [run_on("gpu", "vulkan"), run_on("gpu", "gl")];
    runs[1].rows[0].see_through = 3.0; // river/ray disagrees
    let mut paths = Vec::new();
    for (k, run) in runs.iter_mut().enumerate() {
        let dir = root.join(adapter_dir_name(&run.adapter.name, &run.adapter.backend));
        std::fs::create_dir_all(dir.join("cells")).unwrap();
        run.reference_images = vec![ViewImage {
            view: "river".into(),
            image: "cells/river-reference.png".into(),
        }];
        let shade = 100 * k as u8;
        for rel in run
            .rows
            .iter()
            .map(|r| r.image.clone())
            .chain(["cells/river-reference.png".to_string()])
        {
            RgbaImage::from_pixel(32, 20, image::Rgba([shade, 50, 50, 255]))
                .save(dir.join(rel))
                .unwrap();
        }
        paths.push(run.write(&dir).unwrap());
    }
    assert!(paths[1].starts_with(root.join("gpu-gl")), "{:?}", paths[1]);
    let (p, md_path, json_path) = merge_files(&paths, &root).unwrap();
    let g = &p.groups[0];
    let c = &g.cells[0];
    assert_eq!((c.view.as_str(), c.method.as_str()), ("river", "ray"));
    assert_eq!(
        c.reference_picture.as_deref(),
        Some("gpu-vulkan/cells/river-reference.png")
    );
    assert_eq!(
        c.values[1].picture.as_deref(),
        Some("gpu-gl/cells/river-ray.png")
    );
    let sbs = c.side_by_side.as_deref().unwrap();
    assert_eq!(sbs, "disagreements/a-river-ray.png");
    let img = image::open(root.join(sbs)).unwrap().to_rgba8();
    // Three 32-wide pictures (reference, two adapters) plus labels.
    assert!(
        img.width() > 3 * 32 && img.height() > 20,
        "{:?}",
        img.dimensions()
    );
    assert!(g.cells[1..].iter().all(|c| c.side_by_side.is_none()));
    assert_eq!(p.runs[0].results, "gpu-vulkan/results-gpu.json");
    let md = std::fs::read_to_string(md_path).unwrap();
    assert!(
        md.contains("![river ray: reference, then each adapter](disagreements/a-river-ray.png)")
    );
    assert!(md.contains("[png](gpu-gl/cells/river-ray.png)"), "{md}");
    let back: Portability =
        serde_json::from_str(&std::fs::read_to_string(json_path).unwrap()).unwrap();
    assert_eq!(back, p);
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn earlier_batches_merge_with_their_runs_and_skipped_adapters() {
    let root = tmp("batches");
    let gpu = root.join("gpu");
    let run_dir = gpu.join("gpu-vulkan");
    std::fs::create_dir_all(&run_dir).unwrap();
    let results = run_on("gpu", "vulkan").write(&run_dir).unwrap();
    let skipped = vec![SkippedAdapter {
        adapter: "gpu".into(),
        backend: "gl".into(),
        error: "refused a device".into(),
    }];
    let inputs = read_inputs(&[results]).unwrap();
    write(&inputs, skipped.clone(), &gpu).unwrap();
    let cpu_dir = root.join("cpu");
    std::fs::create_dir_all(&cpu_dir).unwrap();
    let mut cpu = run_on("cpu", "gl");
    cpu.settings.width = 16;
    let cpu_results = cpu.write(&cpu_dir).unwrap();
    let merged = root.join("merged");
    let (p, _, _) = merge_files(&[gpu.join("portability.json"), cpu_results], &merged).unwrap();
    assert_eq!(p.skipped, skipped);
    let labels: Vec<&str> = p.runs.iter().map(|r| r.label.as_str()).collect();
    assert_eq!(labels, vec!["gpu (vulkan)", "cpu (gl)"]);
    assert_eq!(p.runs[0].results, "../gpu/gpu-vulkan/results-gpu.json");
    assert_eq!(p.groups.len(), 2);
    let md = render_markdown(&p);
    assert!(md.contains("- gpu (gl): refused a device"), "{md}");
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn bad_inputs_are_errors() {
    let root = tmp("bad");
    assert!(
        merge_files(&[], &root)
            .unwrap_err()
            .to_string()
            .contains("no results")
    );
    let missing = root.join("missing.json");
    let err = merge_files(&[missing], &root).unwrap_err();
    assert!(format!("{err:#}").contains("missing.json"), "{err:#}");
    let bad = root.join("bad.json");
    std::fs::write(&bad, "[1, 2]").unwrap();
    let err = merge_files(&[bad], &root).unwrap_err();
    assert!(
        format!("{err:#}").contains("not a strata results file"),
        "{err:#}"
    );
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn results_written_before_reference_images_still_load() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../bench/results-nvidia-h100-80gb-hbm3.json");
    let run = crate::merge::read_run(&path).unwrap();
    assert!(run.reference_images.is_empty());
    assert!(!run.rows.is_empty());
}

#[test]
fn relative_paths() {
    assert_eq!(
        relative_to(Path::new("/a/b/c.png"), Path::new("/a")),
        "b/c.png"
    );
    assert_eq!(
        relative_to(Path::new("/a/b/c.png"), Path::new("/a/d")),
        "../b/c.png"
    );
    assert_eq!(
        relative_to(Path::new("/a/./b/../c.png"), Path::new("/a")),
        "c.png"
    );
    assert_eq!(
        adapter_dir_name("NVIDIA H100 80GB HBM3", "gl"),
        "nvidia-h100-80gb-hbm3-gl"
    );
}
