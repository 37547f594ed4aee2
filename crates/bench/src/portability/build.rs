//! One protocol group of the portability report, section by section: the
//! protocol, pitch means and their spread, every cell's spread (disagreeing
//! cells first), the largest spread per method, refusals, edit agreement
//! and timing.

use super::*;

pub(super) fn build_group(
    id: String,
    members: &[Member<'_>],
    separate_because: Option<String>,
    out: &Path,
) -> ProtocolGroup {
    let base = members[0].run;
    let methods = &base.settings.methods;
    let pitches = crate::report::pitches(base);
    let (pitch_means, pitch_spreads) = pitch_accuracy(members, methods, &pitches);
    let cells = cells(members, base, out);
    ProtocolGroup {
        id,
        protocol: protocol(base),
        adapters: members.iter().map(|m| m.label.to_string()).collect(),
        separate_because,
        pitch_means,
        pitch_spreads,
        method_max_spreads: method_max_spreads(methods, &cells),
        disagreeing_cells: cells.iter().filter(|c| !c.disagrees.is_empty()).count(),
        cells,
        failures: failures(members),
        edits: edit_agreement(members, methods),
        timing: timing(members, methods, &pitches),
    }
}

/// What the group's runs share (read off its first run).
fn protocol(base: &RunResults) -> ProtocolSummary {
    let s = &base.settings;
    ProtocolSummary {
        protocol_version: base.protocol_version,
        level: base.level.name.clone(),
        level_hash: base.level.hash.clone(),
        width: s.width,
        height: s.height,
        far: s.far,
        frames: s.frames,
        shadows: s.shadows,
        edits: s.edits,
        mid_rule: s.mid_rule.clone(),
        methods: s.methods.clone(),
        views: s.views.iter().map(|v| v.name.clone()).collect(),
    }
}

/// Per adapter, method and pitch the mean over the views; per method and
/// pitch the spread of those means across adapters.
fn pitch_accuracy(
    members: &[Member<'_>],
    methods: &[String],
    pitches: &[f32],
) -> (Vec<PitchMean>, Vec<PitchSpread>) {
    let mut pitch_means = Vec::new();
    let mut pitch_spreads = Vec::new();
    for m in methods {
        for &p in pitches {
            let mut means = Vec::new();
            for mem in members {
                let rows: Vec<Accuracy> = mem
                    .run
                    .rows
                    .iter()
                    .filter(|r| r.method == *m && r.pitch == p)
                    .map(Accuracy::of)
                    .collect();
                if rows.is_empty() {
                    continue;
                }
                let mean = Accuracy::mean(&rows);
                means.push(mean);
                pitch_means.push(PitchMean {
                    adapter: mem.label.to_string(),
                    method: m.clone(),
                    pitch: p,
                    views: rows.len(),
                    mean,
                });
            }
            if let Some(spread) = Accuracy::spread(&means) {
                pitch_spreads.push(PitchSpread {
                    method: m.clone(),
                    pitch: p,
                    spread,
                });
            }
        }
    }
    (pitch_means, pitch_spreads)
}

/// Every (view, method) cell across the adapters; disagreeing cells first,
/// the worst first, the rest in view x method order.
fn cells(members: &[Member<'_>], base: &RunResults, out: &Path) -> Vec<CellSpread> {
    let s = &base.settings;
    let mut cells = Vec::new();
    for view in &s.views {
        for m in &s.methods {
            cells.push(cell(members, view, m, out));
        }
    }
    cells.sort_by(|a, b| {
        let (da, db) = (!a.disagrees.is_empty(), !b.disagrees.is_empty());
        db.cmp(&da).then_with(|| {
            if da {
                b.excess().total_cmp(&a.excess())
            } else {
                std::cmp::Ordering::Equal
            }
        })
    });
    cells
}

fn cell(
    members: &[Member<'_>],
    view: &strata_level::ViewSpec,
    method: &str,
    out: &Path,
) -> CellSpread {
    let mut values = Vec::new();
    let mut absent = Vec::new();
    for mem in members {
        match mem
            .run
            .rows
            .iter()
            .find(|r| r.view == view.name && r.method == method)
        {
            Some(r) => values.push(CellValue {
                adapter: mem.label.to_string(),
                accuracy: Accuracy::of(r),
                picture: mem.picture(&r.image, out),
            }),
            None => absent.push(CellAbsence {
                adapter: mem.label.to_string(),
                failure: mem.failure_for(&view.name, method).map(|f| f.error.clone()),
            }),
        }
    }
    let accs: Vec<Accuracy> = values.iter().map(|v| v.accuracy).collect();
    let spread = Accuracy::spread(&accs);
    let mut disagrees: Vec<String> = fields_with_tolerance()
        .filter(|((name, _), tol)| spread.is_some_and(|sp| sp.get(name).is_some_and(|v| v > *tol)))
        .map(|((name, _), _)| name.to_string())
        .collect();
    // A lacking cell only disagrees when it is not explained by a
    // recorded failure, and only in a group of several adapters.
    if members.len() > 1 && absent.iter().any(|a| a.failure.is_none()) {
        disagrees.push("cell".to_string());
    }
    let reference_picture = members.iter().find_map(|mem| {
        mem.run
            .reference_images
            .iter()
            .find(|r| r.view == view.name)
            .and_then(|r| mem.picture(&r.image, out))
    });
    CellSpread {
        view: view.name.clone(),
        pitch: view.pitch,
        method: method.to_string(),
        values,
        absent,
        spread,
        disagrees,
        reference_picture,
        side_by_side: None,
    }
}

/// Per method: the field-wise largest spread over its cells.
fn method_max_spreads(methods: &[String], cells: &[CellSpread]) -> Vec<MethodSpread> {
    methods
        .iter()
        .filter_map(|m| {
            let spreads: Vec<Accuracy> = cells
                .iter()
                .filter(|c| c.method == *m)
                .filter_map(|c| c.spread)
                .collect();
            Some(MethodSpread {
                method: m.clone(),
                max: Accuracy::max(&spreads)?,
            })
        })
        .collect()
}

fn failures(members: &[Member<'_>]) -> Vec<AdapterFailure> {
    members
        .iter()
        .flat_map(|mem| {
            mem.run.failures.iter().map(|f| AdapterFailure {
                adapter: mem.label.to_string(),
                view: f.view.clone(),
                method: f.method.clone(),
                error: f.error.clone(),
            })
        })
        .collect()
}

/// Per method with edit rows: post-edit frames until consistent on each
/// adapter, and whether they agree.
fn edit_agreement(members: &[Member<'_>], methods: &[String]) -> Vec<EditAgreement> {
    let mut edits = Vec::new();
    for m in methods {
        let per: Vec<(String, Option<u32>)> = members
            .iter()
            .filter_map(|mem| {
                mem.run
                    .edit_rows
                    .iter()
                    .find(|e| e.method == *m)
                    .map(|e| (mem.label.to_string(), e.consistent_after_frames))
            })
            .collect();
        if per.is_empty() {
            continue;
        }
        let agrees = per.iter().all(|(_, n)| *n == per[0].1);
        edits.push(EditAgreement {
            method: m.clone(),
            consistent_after_frames: per,
            agrees,
        });
    }
    edits
}

/// Mean frame times apart per adapter and timing source, per pitch and
/// over every view.
fn timing(members: &[Member<'_>], methods: &[String], pitches: &[f32]) -> Vec<TimingRow> {
    let mut timing = Vec::new();
    for mem in members {
        for source in [TimingSource::GpuTimestamps, TimingSource::CpuSubmitWait] {
            // CPU submit-and-wait is measured on every row; GPU time only
            // where the row's frames all carried timestamps.
            let time = |r: &Row| match source {
                TimingSource::GpuTimestamps => r.gpu_ms_mean,
                TimingSource::CpuSubmitWait => Some(r.cpu_ms_mean),
            };
            if !mem.run.rows.iter().any(|r| time(r).is_some()) {
                continue;
            }
            for m in methods {
                let pitch_sets = pitches.iter().map(|&p| Some(p)).chain([None]);
                for p in pitch_sets {
                    let xs: Vec<f64> = mem
                        .run
                        .rows
                        .iter()
                        .filter(|r| r.method == *m && p.is_none_or(|p| r.pitch == p))
                        .filter_map(time)
                        .collect();
                    if let Some(mean) = stats::mean(&xs) {
                        timing.push(TimingRow {
                            adapter: mem.label.to_string(),
                            source,
                            method: m.clone(),
                            pitch: p,
                            views: xs.len(),
                            mean_ms: mean,
                        });
                    }
                }
            }
        }
    }
    timing
}
