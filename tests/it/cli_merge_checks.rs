//! What `bench-sph merge` believes of its shards, end to end through the binary: every row as
//! `bench-sph report` checks it, plus the shard's plan (trials, rounds), and each row it leaves
//! out named with why; a shard whose `seq` reference is unusable; `meta.json` written by
//! another tool or with an edited `planned_cells`; shards of different splits; a one-part
//! split. Also the status words that `merge`, `sweep --resume` and `report` refuse, and a
//! report of a directory without `trials.csv`. Shards run one after another (never at once:
//! on this 2-core machine that would spoil the timings), timed by the hidden
//! `--fake-timings`, so nothing here is timed.

use std::path::{Path, PathBuf};

use crate::common::*;

/// The group of [`SHARDED_PLAN`], as messages name it.
const GROUP: &str = "preset seed, all-pairs, N = 60, 3 steps";

/// [`three_shards`] under `root`, alone.
fn shards(root: &Path) -> Vec<PathBuf> {
    let _alone = alone();
    three_shards(root)
}

/// Asserts that a message shows no Rust debug text of an `Option`.
fn no_debug_text(what: &str, text: &str) {
    for debug in ["Some(", "None"] {
        assert!(!text.contains(debug), "{what} holds {debug:?}:\n{text}");
    }
}

/// Merges `dirs` into `out`, expecting a refusal whose standard error holds `needles`, and no
/// files written; returns standard error.
fn merge_refused(dirs: &[PathBuf], out: &Path, needles: &[&str]) -> String {
    let o = merge(dirs, out, &[]);
    assert!(!o.status.success(), "{}", stdout(&o));
    let err = stderr(&o);
    assert!(err.starts_with("Error: "), "{err}");
    assert_holds_all("stderr", &err, needles);
    no_panic(&o);
    no_debug_text("stderr", &err);
    assert!(
        !out.join("summary.csv").exists(),
        "a refused merge wrote files"
    );
    err
}

/// A results CSV as its header and rows of fields (no field these tests touch holds a comma or
/// a quote, so lines split and join at commas).
struct Csv {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    fn read(path: &Path) -> Csv {
        let text = std::fs::read_to_string(path).unwrap();
        let mut lines = text
            .lines()
            .map(|l| l.split(',').map(str::to_owned).collect());
        Csv {
            path: path.to_path_buf(),
            header: lines.next().unwrap(),
            rows: lines.collect(),
        }
    }

    fn col(&self, name: &str) -> usize {
        self.header.iter().position(|h| h == name).unwrap()
    }

    fn get(&self, row: usize, name: &str) -> &str {
        &self.rows[row][self.col(name)]
    }

    fn set(&mut self, row: usize, name: &str, value: &str) {
        let c = self.col(name);
        self.rows[row][c] = value.to_owned();
    }

    /// The rows of `cell`.
    fn of(&self, cell: &Key) -> Vec<usize> {
        (0..self.rows.len())
            .filter(|&r| {
                self.get(r, "strategy") == cell.strategy
                    && self.get(r, "cores") == cell.cores
                    && self.get(r, "chunks") == cell.chunks
            })
            .collect()
    }

    fn write(&self) {
        let mut text = self.header.join(",") + "\n";
        for r in &self.rows {
            text.push_str(&r.join(","));
            text.push('\n');
        }
        std::fs::write(&self.path, text).unwrap();
    }
}

/// A cell by its key columns, as the CSVs write them.
#[derive(Debug, Clone)]
struct Key {
    strategy: String,
    cores: String,
    chunks: String,
}

impl Key {
    /// The first cell of `dir`'s summary.csv of `strategy`.
    fn first(dir: &Path, strategy: &str) -> Key {
        let s = Csv::read(&dir.join("summary.csv"));
        let r = (0..s.rows.len())
            .find(|&r| s.get(r, "strategy") == strategy)
            .unwrap();
        Key {
            strategy: strategy.to_owned(),
            cores: s.get(r, "cores").to_owned(),
            chunks: s.get(r, "chunks").to_owned(),
        }
    }

    /// How messages name the cell, without its group.
    fn label(&self) -> String {
        let cores = if self.cores == "1" { "core" } else { "cores" };
        match self.chunks.as_str() {
            "" => format!("{}, {} {cores}", self.strategy, self.cores),
            k => format!("{}, {} {cores}, {k} chunks", self.strategy, self.cores),
        }
    }
}

/// Edits `dir`'s `file` with `edit`, given the rows of `cell`.
fn edit(dir: &Path, file: &str, cell: &Key, edit: impl FnOnce(&mut Csv, &[usize])) {
    let mut csv = Csv::read(&dir.join(file));
    let rows = csv.of(cell);
    edit(&mut csv, &rows);
    csv.write();
}

/// Copies a results directory (its files only).
/// Three fresh shards of [`SHARDED_PLAN`], shard 2's first rayon-chunks cell, and an output path.
struct Study {
    _tmp: tempfile::TempDir,
    parts: Vec<PathBuf>,
    cell: Key,
    out: PathBuf,
}

impl Study {
    fn new() -> Study {
        let tmp = tempfile::tempdir().unwrap();
        let parts = shards(tmp.path());
        let cell = Key::first(&parts[1], "rayon-chunks");
        let out = tmp.path().join("merged");
        Study {
            _tmp: tmp,
            parts,
            cell,
            out,
        }
    }

    /// Shard 2's directory.
    fn two(&self) -> &Path {
        &self.parts[1]
    }

    /// Edits shard 2's trials.csv at its cell's rows.
    fn trials(&self, f: impl FnOnce(&mut Csv, &[usize])) {
        edit(self.two(), "trials.csv", &self.cell, f);
    }

    /// Edits shard 2's summary.csv at its cell's rows.
    fn summary(&self, f: impl FnOnce(&mut Csv, &[usize])) {
        edit(self.two(), "summary.csv", &self.cell, f);
    }

    /// Merges the three shards, expecting a refusal that names shard 2, its cell in its group
    /// (where `named` says the reason names a cell), the list of rows left out and `needles`.
    fn refused(&self, named: bool, needles: &[&str]) -> String {
        let cell = format!("{} ({GROUP})", self.cell.label());
        let mut all = vec![
            "shard-2",
            "left out of the shards, as `bench-sph report` would leave",
        ];
        if named {
            all.push(&cell);
        }
        all.extend(needles);
        merge_refused(&self.parts, &self.out, &all)
    }
}

#[test]
fn merge_refuses_a_shard_whose_seq_reference_is_unusable() {
    let study = Study::new();
    let three = &study.parts[2];
    let seq = Key::first(three, "seq");
    edit(three, "trials.csv", &seq, |t, rows| {
        t.set(rows[0], "wall_s", "NaN")
    });
    let err = merge_refused(
        &study.parts,
        &study.out,
        &[
            "(shard 3/3): its seq reference of preset seed, all-pairs, N = 60, 3 steps is \
             unusable (trial 1: wall_s = NaN is not a positive time)",
            "its 2 other cells of that group have no speedup",
            "--allow-partial",
            "bench-sph sweep --resume",
        ],
    );
    assert!(err.contains("shard-3"), "{err}");

    // An extra column in the seq row of summary.csv: unreadable, so the seq is missing too.
    let study = Study::new();
    let three = &study.parts[2];
    edit(three, "summary.csv", &seq, |s, rows| {
        s.rows[rows[0]].push("extra".to_owned())
    });
    merge_refused(
        &study.parts,
        &study.out,
        &[
            "its seq reference of preset seed, all-pairs, N = 60, 3 steps is unusable (its row \
             in summary.csv is missing or unreadable)",
            "summary.csv' line 2: not a bench-sph summary row (it has 33 fields, not 32)",
        ],
    );
}

#[test]
fn with_allow_partial_the_cells_of_a_shard_without_its_seq_have_no_speedup_and_say_why() {
    let study = Study::new();
    let three = &study.parts[2];
    let seq = Key::first(three, "seq");
    edit(three, "trials.csv", &seq, |t, rows| {
        t.set(rows[1], "wall_s", "-0.5")
    });
    let o = merge(&study.parts, &study.out, &["--allow-partial"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_holds_all(
        "stderr",
        &err,
        &[
            "warning: left out of the merge: ",
            "seq, 1 core (preset seed, all-pairs, N = 60, 3 steps): trial 2: wall_s = -0.5 is \
             not a positive time",
            "its 2 other cells of that group have no speedup (--allow-partial",
            "references.csv holds that seq as a failed row",
        ],
    );
    no_debug_text("stderr", &err);

    // Shard 3's cells keep their times and shard, never a speedup against another's seq.
    let summary = rows(&study.out.join("summary.csv"));
    let of_three: Vec<&Row> = summary
        .iter()
        .filter(|r| r["reference_shard"] == "3")
        .collect();
    assert_eq!(of_three.len(), 2, "{summary:?}");
    for r in &of_three {
        assert_eq!((r["speedup"].as_str(), r["efficiency"].as_str()), ("", ""));
        assert!(!r["mean_s"].is_empty());
    }
    assert!(
        summary
            .iter()
            .filter(|r| r["reference_shard"] != "3")
            .all(|r| !r["speedup"].is_empty())
    );
    // references.csv says what happened to shard 3's seq.
    let references = rows(&study.out.join("references.csv"));
    assert_eq!(references.len(), 3);
    let three_seq = references
        .iter()
        .find(|r| r["reference_shard"] == "3")
        .unwrap();
    assert_eq!(three_seq["status"], "failed");
    assert!(
        three_seq["reason"].contains("wall_s = -0.5 is not a positive time"),
        "{three_seq:?}"
    );
    let meta = read_json(&study.out.join("meta.json"));
    assert_eq!(meta["status"], "partial");
    assert_eq!(
        meta["merge"]["without_reference"].as_array().unwrap().len(),
        2
    );

    // The report says so, and shows no debug text.
    let tmp = study.out.parent().unwrap();
    succeeds(tmp, &["report", study.out.to_str().unwrap()]);
    let md = std::fs::read_to_string(study.out.join("REPORT.md")).unwrap();
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "Partial study",
            "2 cells without a speedup, their shard's `seq` reference left out as unusable",
            "its seq reference of preset seed, all-pairs, N = 60, 3 steps is unusable",
        ],
    );
    no_debug_text("REPORT.md", &md);
}

#[test]
fn merge_says_why_it_dropped_each_row() {
    let study = Study::new();
    study.trials(|t, rows| t.set(rows[1], "wall_s", "NaN"));
    let err = study.refused(true, &["trial 2: wall_s = NaN is not a positive time"]);
    // The refusal says what is missing, why, and what to do.
    assert_holds_all(
        "stderr",
        &err,
        &[
            "1 of the plan's 7 cells is missing",
            "rows of the shards left out",
            "bench-sph sweep --resume SHARD_DIR",
            "--allow-partial",
        ],
    );
}

#[test]
fn merge_names_an_infinite_a_zero_and_a_negative_time() {
    for (value, needle) in [
        ("inf", "trial 1: wall_s = inf is not a positive time"),
        ("0", "trial 1: wall_s = 0 is not a positive time"),
        ("-1", "trial 1: wall_s = -1 is not a positive time"),
    ] {
        let study = Study::new();
        study.trials(|t, rows| t.set(rows[0], "wall_s", value));
        study.refused(true, &[needle]);
    }
}

#[test]
fn merge_names_a_wrong_checksum() {
    let study = Study::new();
    study.trials(|t, rows| t.set(rows[1], "checksum", "00000000deadbeef"));
    study.refused(
        true,
        &["trial 2: checksum 00000000deadbeef differs from the cell's"],
    );
}

#[test]
fn merge_names_a_duplicated_and_a_deleted_trial_row() {
    let study = Study::new();
    study.trials(|t, rows| {
        let copy = t.rows[rows[1]].clone();
        t.rows.push(copy);
    });
    study.refused(
        true,
        &["the summary counts 2 trials but trials.csv holds 3"],
    );

    let study = Study::new();
    study.trials(|t, rows| {
        t.rows.remove(rows[1]);
    });
    study.refused(
        true,
        &["the summary counts 2 trials but trials.csv holds 1"],
    );
}

#[test]
fn merge_names_a_deleted_summary_row() {
    let study = Study::new();
    study.summary(|s, rows| {
        s.rows.remove(rows[0]);
    });
    study.refused(
        true,
        &["summary.csv has no row of it, though trials.csv holds 2 trial rows of its grid phase"],
    );
}

#[test]
fn merge_names_a_duplicated_summary_row_and_merges_the_first() {
    let study = Study::new();
    study.summary(|s, rows| {
        let copy = s.rows[rows[0]].clone();
        s.rows.push(copy);
    });
    let o = merge(&study.parts, &study.out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let needle = format!(
        "warning: left out of the merge: '{}': {} ({GROUP}): a second summary row of the same \
         cell",
        study.two().display(),
        study.cell.label()
    );
    assert!(stderr(&o).contains(&needle), "{}", stderr(&o));
    let meta = std::fs::read_to_string(study.out.join("meta.json")).unwrap();
    assert!(
        meta.contains("a second summary row of the same cell"),
        "{meta}"
    );
    let tmp = study.out.parent().unwrap();
    succeeds(tmp, &["report", study.out.to_str().unwrap()]);
    let md = std::fs::read_to_string(study.out.join("REPORT.md")).unwrap();
    assert!(md.contains("a second summary row of the same cell"), "{md}");
}

#[test]
fn merge_names_a_truncated_trials_file() {
    let study = Study::new();
    let path = study.two().join("trials.csv");
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() - 12]).unwrap();
    study.refused(false, &["trials.csv' line", "not a bench-sph trial row"]);
}

#[test]
fn merge_names_a_trial_row_whose_pin_was_changed() {
    let study = Study::new();
    study.trials(|t, rows| t.set(rows[1], "pin", "spread"));
    study.refused(
        true,
        &[
            "the summary counts 2 trials but trials.csv holds 1",
            "pin spread (preset seed, all-pairs, N = 60, 3 steps): summary.csv has no row of it",
        ],
    );
}

#[test]
fn merge_names_edited_statistics() {
    let study = Study::new();
    study.summary(|s, rows| {
        for column in ["mean_s", "min_s", "median_s", "max_s"] {
            let v: f64 = s.get(rows[0], column).parse().unwrap();
            s.set(rows[0], column, &(v / 10.0).to_string());
        }
    });
    study.refused(true, &["disagrees with its trial rows"]);
}

#[test]
fn merge_refuses_renumbered_trials_and_rounds_outside_its_plan() {
    let study = Study::new();
    study.trials(|t, rows| t.set(rows[1], "trial", "5"));
    study.refused(
        true,
        &["its trials are numbered 1, 5, not 1 to 2 (renumbered, repeated or missing rows)"],
    );

    let study = Study::new();
    study.trials(|t, rows| t.set(rows[1], "round", "7"));
    study.refused(
        true,
        &["trial 2: round 7 is not one of its plan's rounds 1 to 2"],
    );

    let study = Study::new();
    study.trials(|t, rows| {
        t.set(rows[0], "round", "2");
        t.set(rows[1], "round", "1");
    });
    study.refused(
        true,
        &["trial 2: round 1 does not come after the round of trial 1 (2)"],
    );
}

#[test]
fn merge_refuses_a_failed_trial_in_an_ok_cell_naming_the_row() {
    let study = Study::new();
    // `ok,` with an empty reason becomes `failed,boom`: as many fields as before.
    study.trials(|t, rows| {
        t.set(rows[1], "status", "failed");
        t.set(rows[1], "reason", "boom");
    });
    study.refused(
        true,
        &["trial 2 is marked failed (boom) in a cell marked ok"],
    );
}

#[test]
fn merge_names_a_row_with_an_extra_field() {
    let study = Study::new();
    // `failed,boom` written into the status field alone: one field more than the header.
    study.trials(|t, rows| t.set(rows[1], "status", "failed,boom"));
    study.refused(
        true,
        &[
            "not a bench-sph trial row (it has 24 fields, not 23)",
            "the summary counts 2 trials but trials.csv holds 1",
        ],
    );
}

#[test]
fn merge_names_a_nan_in_the_summary() {
    let study = Study::new();
    study.summary(|s, rows| s.set(rows[0], "speedup", "NaN"));
    study.refused(true, &["speedup = NaN is not a finite positive number"]);
}

#[test]
fn merge_refuses_a_meta_json_written_by_another_tool() {
    let study = Study::new();
    set_top_level(study.two(), "tool", "bench-sph trace".into());
    merge_refused(
        &study.parts,
        &study.out,
        &[
            "shard-2' was written by `bench-sph trace`, not by `bench-sph sweep`",
            "only the directories of `bench-sph sweep --shard I/K` merge",
        ],
    );
}

#[test]
fn merge_refuses_an_edited_planned_cells() {
    let study = Study::new();
    set_top_level(study.two(), "planned_cells", 9.into());
    merge_refused(
        &study.parts,
        &study.out,
        &[
            "shard-2': its meta.json says planned_cells = 9 but its parameters plan 3 cells",
            "was it edited?",
        ],
    );
}

/// Sets `key` of `dir/meta.json`'s top level (not its sessions').
fn set_top_level(dir: &Path, key: &str, value: serde_json::Value) {
    let path = dir.join("meta.json");
    let mut meta = read_json(&path);
    meta[key] = value;
    std::fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
}

#[test]
fn an_edited_reference_shard_is_named_without_rust_debug_text() {
    let study = Study::new();
    study.summary(|s, rows| s.set(rows[0], "reference_shard", "1"));
    merge_refused(
        &study.parts,
        &study.out,
        &["has reference_shard 1, not 2: was summary.csv edited?"],
    );
    let study = Study::new();
    study.summary(|s, rows| s.set(rows[0], "reference_shard", ""));
    merge_refused(
        &study.parts,
        &study.out,
        &["has reference_shard empty, not 2"],
    );
}

#[test]
fn shards_of_different_splits_are_named_as_such_not_as_a_repeat() {
    let study = Study::new();
    let half = study.out.parent().unwrap().join("half");
    {
        let _alone = alone();
        sweep_plan(&half, "--shard 2/2");
    }
    let err = merge_refused(
        &[study.parts[1].clone(), half],
        &study.out,
        &[
            "are shards of different splits (2 of 2 and 2 of 3)",
            "--shard I/3",
        ],
    );
    assert!(!err.contains("given twice"), "{err}");
}

#[test]
fn a_one_part_shard_says_it_holds_the_whole_plan() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("one");
    let o = {
        let _alone = alone();
        sweep_plan(&dir, "--shard 1/1")
    };
    let out = stdout(&o);
    assert!(out.contains("shard 1/1 holds the whole plan"), "{out}");
    assert!(!out.contains("once every shard is done"), "{out}");
    succeeds(tmp.path(), &["report", dir.to_str().unwrap()]);
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("it holds every cell of the plan"), "{md}");
    assert!(!md.contains("only its part"), "{md}");
    let merged = tmp.path().join("merged");
    let o = merge(&[dir], &merged, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("7 of the plan's 7 cells"),
        "{}",
        stdout(&o)
    );
}

/// Sets trial 2 of `cell` in `dir` to `status` (and `reason`).
fn set_status(dir: &Path, cell: &Key, status: &str, reason: &str) {
    edit(dir, "trials.csv", cell, |t, rows| {
        t.set(rows[1], "status", status);
        t.set(rows[1], "reason", reason);
    });
}

#[test]
fn an_unknown_status_word_is_refused_by_merge_resume_and_report() {
    for (status, reason, why) in [
        (
            "boom",
            "",
            "not a bench-sph trial row (status 'boom' is neither ok nor failed)",
        ),
        (
            "failed",
            "boom",
            "trial 2 is marked failed (boom) in a cell marked ok",
        ),
    ] {
        let study = Study::new();
        set_status(study.two(), &study.cell, status, reason);
        let kept = study.out.parent().unwrap().join("kept");
        copy_dir(study.two(), &kept);

        // merge
        study.refused(false, &[why]);

        // report
        let tmp = study.out.parent().unwrap();
        let o = run(&["report", kept.to_str().unwrap()]);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains("row left out of the report") && err.contains(why),
            "{err}"
        );
        let md = std::fs::read_to_string(kept.join("REPORT.md")).unwrap();
        assert!(md.contains(why), "{md}");
        no_debug_text("REPORT.md", &md);

        // sweep --resume: dropped, saying why, and measured again; then the shards merge.
        let o = {
            let _alone = alone();
            run(&["sweep", "--resume", study.two().to_str().unwrap()])
        };
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains("dropped, will run again: "), "{err}");
        let resume_why = why.replace("bench-sph trial row", "bench-sph row");
        assert!(err.contains(&resume_why), "{err}");
        let trials = std::fs::read_to_string(study.two().join("trials.csv")).unwrap();
        assert!(!trials.contains("boom"), "{trials}");
        let o = merge(&study.parts, &study.out, &[]);
        assert!(o.status.success(), "{}", stderr(&o));
        let _ = tmp;
    }
}

#[test]
fn report_without_trials_csv_says_the_statistics_were_not_checked() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("sweep");
    {
        let _alone = alone();
        let o = sweep_into(
            &dir,
            "--n 60 --steps 3 --trials 3 --warmup 0 --cores 1..2 --chunks 2,4 \
             --strategies rayon-chunks,std-static --fake-timings 1,1.1,0.9 --no-plots",
        );
        assert!(o.status.success(), "{}", stderr(&o));
    }
    std::fs::remove_file(dir.join("trials.csv")).unwrap();
    // Every rayon-chunks time divided by 10, consistently: only the runs could tell.
    let mut s = Csv::read(&dir.join("summary.csv"));
    for r in 0..s.rows.len() {
        if s.get(r, "strategy") != "rayon-chunks" {
            continue;
        }
        let scale = |s: &mut Csv, column: &str, by: f64| {
            if let Ok(v) = s.get(r, column).parse::<f64>() {
                s.set(r, column, &(v * by).to_string());
            }
        };
        for column in [
            "mean_s",
            "stddev_s",
            "min_s",
            "median_s",
            "max_s",
            "mean_ci_low_s",
            "mean_ci_high_s",
        ] {
            scale(&mut s, column, 0.1);
        }
        for column in ["speedup", "efficiency", "speedup_ci_low", "speedup_ci_high"] {
            scale(&mut s, column, 10.0);
        }
    }
    s.write();

    let o = run(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_holds_all(
        "stderr",
        &stderr(&o),
        &[
            "has no trials.csv: the statistics in its summary.csv could not be checked against \
             the runs (they are taken on trust) and its findings are withheld",
        ],
    );
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "> ⚠ **Statistics not checked**",
            "has no trials.csv, so the statistics in its summary.csv could not be checked",
            "Findings withheld: this group's directory has no trials.csv",
        ],
    );
    no_debug_text("REPORT.md", &md);
}
