//! `results merge`: shard folders (`results --shard K/N`) joined into one run, identical on every
//! deterministic column to an unsharded run; the CSV reading it needs.

use super::*;

/// One CSV line's cells (the quoting [`Csv::write`] writes: `"` around cells with `,` or
/// `"`, doubled quotes inside).
pub(super) fn csv_cells(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => cells.push(std::mem::take(&mut cur)),
            c => cur.push(c),
        }
    }
    cells.push(cur);
    cells
}

/// A CSV file's header and rows of cells.
pub(super) type CsvRows = (Vec<String>, Vec<Vec<String>>);

/// A CSV file as header + rows of cells (`None` when absent).
pub(super) fn read_csv_rows(path: &std::path::Path) -> anyhow::Result<Option<CsvRows>> {
    if !path.is_file() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text.lines().filter(|l| !l.is_empty());
    let header = lines.next().map(csv_cells).unwrap_or_default();
    Ok(Some((header, lines.map(csv_cells).collect())))
}

/// Every file under `dir`, relative to it, sorted.
pub(super) fn files_under(dir: &std::path::Path) -> anyhow::Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::new()];
    while let Some(rel) = stack.pop() {
        let abs = dir.join(&rel);
        for e in std::fs::read_dir(&abs).with_context(|| format!("cannot read {}", abs.display()))? {
            let e = e?;
            let r = rel.join(e.file_name());
            if e.file_type()?.is_dir() {
                stack.push(r);
            } else {
                out.push(r);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The shards' run.json, in shard order, and their N: the same options (all but the shard,
/// the output and the times), each K once, none missing.
fn read_shards(m: &MergeArgs) -> anyhow::Result<(Vec<(PathBuf, serde_json::Value)>, u32)> {
    let mut runs: Vec<(PathBuf, serde_json::Value)> = Vec::new();
    for d in &m.shards {
        let p = d.join("run.json");
        let text = std::fs::read_to_string(&p)
            .with_context(|| format!("{} is not a results folder (no run.json)", d.display()))?;
        let v: serde_json::Value =
            serde_json::from_str(&text).with_context(|| format!("bad {}", p.display()))?;
        runs.push((d.clone(), v));
    }
    let shard_of =
        |v: &serde_json::Value| -> Option<Shard> { serde_json::from_value(v["shard"].clone()).ok() };
    // Every option but the shard and the output (`options_key`).
    let options = |v: &serde_json::Value| v["options"].clone();
    // In shard order.
    runs.sort_by_key(|(_, v)| shard_of(v).map_or(0, |s| s.k));
    let (first_dir, first) = &runs[0];
    let n = shard_of(first)
        .ok_or_else(|| {
            anyhow!(
                "{} is not a shard (its run.json has no shard)",
                first_dir.display()
            )
        })?
        .n;
    let mut seen = vec![false; n as usize];
    for (d, v) in &runs {
        let s = shard_of(v)
            .ok_or_else(|| anyhow!("{} is not a shard (its run.json has no shard)", d.display()))?;
        if s.n != n || s.k == 0 || s.k > s.n {
            bail!("{} is shard {}/{}, the others are of {n}", d.display(), s.k, s.n);
        }
        if std::mem::replace(&mut seen[(s.k - 1) as usize], true) {
            bail!("shard {}/{n} is given twice ({})", s.k, d.display());
        }
        if options(v).is_null() || options(v) != options(first) {
            bail!(
                "{} and {} were run with different options (compare their run.json)",
                first_dir.display(),
                d.display()
            );
        }
    }
    let missing: Vec<String> = (1..=n)
        .filter(|k| !seen[(k - 1) as usize])
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        bail!("shard(s) {} missing: a merge needs all {n}", missing.join(", "));
    }
    Ok((runs, n))
}

/// Copies every figure's files of every shard into `out` (a file two shards both wrote, a
/// shared image, must be the same); returns how many.
fn copy_figure_files(runs: &[(PathBuf, serde_json::Value)], out: &std::path::Path) -> anyhow::Result<usize> {
    let merged_names = |rel: &std::path::Path| {
        rel == std::path::Path::new("run.json")
            || rel == std::path::Path::new("checks.csv")
            || rel.file_name().is_some_and(|n| n == "timing_agreement.csv")
    };
    let mut copied = 0usize;
    for (d, _) in runs {
        for rel in files_under(d)? {
            if merged_names(&rel) {
                continue;
            }
            let src = d.join(&rel);
            let dst = out.join(&rel);
            let bytes = std::fs::read(&src).with_context(|| format!("cannot read {}", src.display()))?;
            if dst.exists() {
                if std::fs::read(&dst)? != bytes {
                    bail!(
                        "{} differs between shards (one of them wrote it differently)",
                        rel.display()
                    );
                }
                continue;
            }
            if let Some(p) = dst.parent() {
                std::fs::create_dir_all(p)?;
            }
            std::fs::write(&dst, bytes).with_context(|| format!("cannot write {}", dst.display()))?;
            copied += 1;
        }
    }

    Ok(copied)
}

/// The units (scene/figure) of all shards, checked to be the sweep's, each once, in the order
/// of an unsharded run.
fn merged_units(
    first: &serde_json::Value,
    runs: &[(PathBuf, serde_json::Value)],
    scene_order: &[String],
) -> anyhow::Result<Vec<String>> {
    // Every unit of the sweep exactly once.
    let mut expected: Vec<String> = Vec::new();
    for s in scene_order {
        for f in first["figures"].as_array().into_iter().flatten() {
            expected.push(format!("{s}/{}", f.as_str().unwrap_or_default()));
        }
    }
    let mut units: Vec<String> = runs
        .iter()
        .flat_map(|(_, v)| v["units"].as_array().cloned().unwrap_or_default())
        .filter_map(|u| u.as_str().map(str::to_string))
        .collect();
    let unit_pos = |u: &String| expected.iter().position(|e| e == u).unwrap_or(usize::MAX);
    units.sort_by_key(unit_pos);
    if units != expected {
        bail!(
            "the shards' units ({}) are not the sweep's ({}): shards of different sweeps?",
            units.join(", "),
            expected.join(", ")
        );
    }
    Ok(units)
}

/// Every shard's scenes of run.json, one entry per scene (its figure times joined in a run's
/// order).
fn merged_scenes(runs: &[(PathBuf, serde_json::Value)]) -> Vec<serde_json::Value> {
    let mut scenes: Vec<serde_json::Value> = Vec::new();
    for (_, v) in runs {
        for sc in v["scenes"].as_array().into_iter().flatten() {
            match scenes.iter_mut().find(|s| s["scene"] == sc["scene"]) {
                Some(s) => {
                    let mut times = s["figure_times"].as_array().cloned().unwrap_or_default();
                    times.extend(sc["figure_times"].as_array().cloned().unwrap_or_default());
                    let pos = |t: &serde_json::Value| figure_rank(t["figure"].as_str().unwrap_or_default());
                    times.sort_by_key(pos);
                    s["figure_times"] = serde_json::Value::Array(times);
                }
                None => scenes.push(sc.clone()),
            }
        }
    }
    scenes
}

/// Per scene, its timing_agreement.csv rewritten over every shard's figures into `out`, and
/// the agreement checks recomputed over them.
fn merged_agreement(
    runs: &[(PathBuf, serde_json::Value)],
    scenes: &[serde_json::Value],
    out: &std::path::Path,
) -> anyhow::Result<Vec<Check>> {
    let mut agreement: Vec<Check> = Vec::new();
    for sc in scenes {
        let label = sc["scene"].as_str().unwrap_or_default();
        let mut rows: Vec<crate::harness::BaseTiming> = Vec::new();
        let mut header = None;
        for (d, _) in runs {
            let Some((h, rs)) = read_csv_rows(&d.join(label).join("timing_agreement.csv"))? else {
                continue;
            };
            let col = |name: &str| h.iter().position(|c| c == name);
            for r in rs {
                let cell = |name: &str| col(name).and_then(|i| r.get(i)).cloned().unwrap_or_default();
                let t = crate::harness::BaseTiming {
                    figure: cell("figure"),
                    size: (0, 0),
                    sample_ms_min: cell("sample_ms_min").parse().unwrap_or(f64::NAN),
                    sample_ms_median: cell("sample_ms_median").parse().unwrap_or(f64::NAN),
                    timed_passes: cell("timed_passes"),
                    frame_passes: cell("frame_passes"),
                    frame_kind: cell("frame_kind"),
                    timed_frames: cell("timed_frames").parse().unwrap_or(0),
                };
                if !rows.iter().any(|x| x.figure == t.figure) {
                    rows.push(t);
                }
            }
            header.get_or_insert(h);
        }
        if let Some(h) = header {
            let pos = |t: &crate::harness::BaseTiming| figure_rank(&t.figure);
            rows.sort_by_key(pos);
            let mut text = h.join(",");
            text.push('\n');
            for r in &rows {
                text.push_str(&crate::harness::csv_line(&[
                    label.to_string(),
                    r.figure.clone(),
                    num(r.sample_ms_min),
                    num(r.sample_ms_median),
                    r.timed_passes.clone(),
                    r.frame_passes.clone(),
                    r.frame_kind.clone(),
                    r.timed_frames.to_string(),
                ]));
                text.push('\n');
            }
            let p = out.join(label).join("timing_agreement.csv");
            std::fs::write(&p, text).with_context(|| format!("cannot write {}", p.display()))?;
            let refs: Vec<&crate::harness::BaseTiming> = rows.iter().collect();
            agreement.extend(agreement_checks(
                label,
                sc["adapter"].as_str().unwrap_or_default(),
                &refs,
            ));
        }
    }

    Ok(agreement)
}

/// `results merge`: joins shard folders into one, as an unsharded run writes it.
pub fn merge(m: &MergeArgs) -> anyhow::Result<()> {
    let (runs, n) = read_shards(m)?;
    let first = &runs[0].1;
    if m.out.join("run.json").exists() {
        bail!(
            "{} already holds a results run: merge into a new folder",
            m.out.display()
        );
    }
    std::fs::create_dir_all(&m.out).with_context(|| format!("cannot create {}", m.out.display()))?;

    let copied = copy_figure_files(&runs, &m.out)?;

    // Per scene, the timing agreement over every shard's figures, and its checks.
    // The scenes in the order of the run's --scenes, the figures in the order a run makes them.
    let scene_order: Vec<String> = first["scene_order"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|s| s.as_str().map(str::to_string))
        .collect();
    let scene_pos = |s: &str| scene_order.iter().position(|x| x == s).unwrap_or(usize::MAX);
    let figure_pos = |f: &str| {
        Some(figure_rank(f))
            .filter(|&r| r != usize::MAX)
            .unwrap_or(if f == AGREEMENT_FIGURE {
                usize::MAX - 1
            } else {
                usize::MAX
            })
    };
    let units = merged_units(first, &runs, &scene_order)?;
    let mut scenes = merged_scenes(&runs);
    scenes.sort_by_key(|s| scene_pos(s["scene"].as_str().unwrap_or_default()));
    let agreement = merged_agreement(&runs, &scenes, &m.out)?;

    // checks.csv: every shard's checks in the order one run writes them (by scene, then by
    // figure), each scene's timing agreement recomputed over all shards at its end.
    let mut rows: Vec<Vec<String>> = Vec::new();
    for (d, _) in &runs {
        if let Some((h, rs)) = read_csv_rows(&d.join("checks.csv"))? {
            if h != CHECKS_HEADER {
                bail!(
                    "{}: checks.csv is not this version's ({})",
                    d.display(),
                    h.join(",")
                );
            }
            rows.extend(
                rs.into_iter()
                    .filter(|r| r.get(1).is_none_or(|f| f != AGREEMENT_FIGURE)),
            );
        }
    }
    rows.extend(agreement.iter().map(|c| check_row(AGREEMENT_FIGURE, c)));
    // A stable sort: within a figure, its checks keep their order.
    rows.sort_by_key(|r| {
        (
            scene_pos(r.first().map_or("", |s| s.as_str())),
            figure_pos(r.get(1).map_or("", |s| s.as_str())),
        )
    });
    let mut csv = Csv::new(&CHECKS_HEADER);
    for r in rows {
        csv.row(r);
    }
    if !csv.rows.is_empty() {
        csv.write(&m.out.join("checks.csv"))?;
    }

    // run.json: the shared options, every shard's scenes and units, the summed time.
    let mut info = first.clone();
    let seconds: f64 = runs
        .iter()
        .map(|(_, v)| v["seconds"].as_f64().unwrap_or(0.0))
        .sum();
    let units: Vec<serde_json::Value> = units.into_iter().map(serde_json::Value::from).collect();
    if let Some(map) = info.as_object_mut() {
        map.remove("shard");
        map.insert("seconds".into(), seconds.into());
        map.insert("scenes".into(), serde_json::Value::Array(scenes.clone()));
        map.insert("units".into(), serde_json::Value::Array(units));
        map.insert("merged_shards".into(), n.into());
    }
    let p = m.out.join("run.json");
    std::fs::write(&p, serde_json::to_string_pretty(&info)?)
        .with_context(|| format!("cannot write {}", p.display()))?;
    println!(
        "merged {n} shard(s) into {}: {copied} file(s), {} scene(s), {} check(s)",
        m.out.display(),
        scenes.len(),
        csv.rows.len()
    );
    Ok(())
}
