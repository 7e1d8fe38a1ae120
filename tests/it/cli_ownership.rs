//! Which files a command may replace or remove in a directory: those the directory's record
//! (`bench-sph-files.json`) gives to that command, and no other — never a user's file that
//! has a chart's name and size, never another command's file, never a file of a directory
//! written before records were kept. And a report checks every file it will write before it
//! writes one.

use std::path::Path;

use crate::common::*;

/// Writes a real PNG of `width` × `height` pixels (the size of a report's charts is 1000 ×
/// 650): what the old guess took for a chart.
fn png(path: &Path, width: u32, height: u32) {
    let file = std::fs::File::create(path).unwrap();
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    let mut writer = encoder.write_header().unwrap();
    writer
        .write_image_data(&vec![200; (width * height) as usize])
        .unwrap();
}

/// Each file's bytes, to show they did not change.
fn snapshot(files: &[std::path::PathBuf]) -> Vec<Vec<u8>> {
    files.iter().map(|f| std::fs::read(f).unwrap()).collect()
}

fn no_temporary_files(dir: &Path) {
    for name in names(dir) {
        assert!(!name.ends_with(".tmp"), "a temporary file stayed: {name}");
    }
}

#[test]
fn report_never_removes_a_png_it_did_not_write() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &[]);
    let d = dir.to_str().unwrap();
    let mine: Vec<_> = ["seed-holiday.png", "wcsph-photo.png", "cpp-x.png"]
        .iter()
        .map(|n| dir.join(n))
        .collect();
    for f in &mine {
        png(f, 1000, 650);
    }
    let before = snapshot(&mine);

    let o = run(&["report", d]);
    assert!(!o.status.success(), "the report took them for its charts");
    assert_holds_all(
        "the refusal",
        &stderr(&o),
        &[
            "'cpp-x.png'",
            "'seed-holiday.png'",
            "'wcsph-photo.png'",
            "--force",
        ],
    );
    let o = run(&["report", d, "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(snapshot(&mine), before, "the user's PNGs are untouched");
    assert!(dir.join("seed-all-pairs-n60-s3-4-speedup.png").is_file());
}

#[test]
fn sweep_force_in_an_old_sweep_directory_never_removes_a_png_it_did_not_write() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &[]);
    let holiday = dir.join("seed-holiday.png");
    png(&holiday, 1000, 650);
    let before = snapshot(std::slice::from_ref(&holiday));
    let report_before = std::fs::read(dir.join("REPORT.md")).unwrap();

    swept(&dir, &["--force", "--no-plots"]);
    assert_eq!(snapshot(std::slice::from_ref(&holiday)), before);
    // The sweep's earlier results and the report drawn from them are gone, as recorded.
    assert!(!dir.join("REPORT.md").exists(), "{report_before:?}");
    assert!(!dir.join("seed-all-pairs-n60-s3-4-speedup.png").exists());
    assert!(!rows(&dir.join("summary.csv")).is_empty());
    assert_eq!(record(&dir)["summary.csv"], "sweep");
}

#[test]
fn a_report_written_before_records_is_never_replaced_even_with_force() {
    let (_tmp, dir) = scratch("old");
    swept(&dir, &[]);
    // As an older bench-sph left it: no record, no lock file.
    for f in ["bench-sph-files.json", "bench-sph.lock"] {
        let _ = std::fs::remove_file(dir.join(f)); // (none before records were kept)
    }
    let report = std::fs::read(dir.join("REPORT.md")).unwrap();
    let d = dir.to_str().unwrap();
    let o = run(&["report", d]);
    assert!(!o.status.success());
    assert_holds_all(
        "the refusal",
        &stderr(&o),
        &["'REPORT.md'", "has no bench-sph-files.json", "--force"],
    );
    let o = run(&["report", d, "--force"]);
    assert!(!o.status.success());
    assert_holds_all(
        "the refusal",
        &stderr(&o),
        &["it exists and was not written by bench-sph report (no record in"],
    );
    assert_eq!(std::fs::read(dir.join("REPORT.md")).unwrap(), report);
    assert!(record(&dir).is_empty(), "a refused report records nothing");
}

#[test]
fn a_sweep_directory_without_a_record_or_a_report_is_reported_without_force() {
    let (_tmp, dir) = scratch("old");
    swept(&dir, &["--no-plots"]);
    for f in ["bench-sph-files.json", "bench-sph.lock"] {
        let _ = std::fs::remove_file(dir.join(f)); // (none before records were kept)
    }
    // Its own input files are the report's to read, not to replace.
    let o = run(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let record = record(&dir);
    assert_eq!(record["REPORT.md"], "report");
    assert!(!record.contains_key("trials.csv"), "{record:?}");
}

#[test]
fn the_record_says_which_command_wrote_each_file() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &[]);
    let record = record(&dir);
    for f in ["trials.csv", "summary.csv", "meta.json"] {
        assert_eq!(record[f], "sweep", "{record:?}");
    }
    assert_eq!(record["REPORT.md"], "report");
    assert_eq!(record["seed-all-pairs-n60-s3-4-speedup.png"], "report");
    let listed: Vec<&String> = record.keys().collect();
    let mut on_disk = names(&dir);
    on_disk.sort();
    let mut listed: Vec<String> = listed.into_iter().cloned().collect();
    listed.sort();
    assert_eq!(listed, on_disk, "every file is recorded, and only those");
}

#[test]
fn a_chart_name_taken_by_a_directory_stops_the_report_before_it_writes_anything() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let taken = dir.join("seed-all-pairs-n60-s3-4-speedup.png");
    std::fs::create_dir(&taken).unwrap();
    let before = names(&dir);
    let o = run(&["report", dir.to_str().unwrap()]);
    assert!(!o.status.success());
    no_panic(&o);
    assert_holds_all(
        "the refusal",
        &stderr(&o),
        &["seed-all-pairs-n60-s3-4-speedup.png': a directory of that name is in the way"],
    );
    assert_eq!(names(&dir), before, "no chart, REPORT.md or temporary file");
    assert!(taken.is_dir());
    no_temporary_files(&dir);
}

#[test]
fn a_trace_never_replaces_a_sweeps_meta_json_even_with_force() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let meta = std::fs::read(dir.join("meta.json")).unwrap();
    let o = run(&[
        "trace",
        "--strategy",
        "seq",
        "--n",
        "60",
        "--out",
        dir.to_str().unwrap(),
        "--force",
    ]);
    assert!(!o.status.success());
    assert_holds_all(
        "the refusal",
        &stderr(&o),
        &[
            "meta.json': it exists and was not written by bench-sph trace (the record says bench-sph sweep wrote it)",
        ],
    );
    assert_eq!(std::fs::read(dir.join("meta.json")).unwrap(), meta);
    assert!(
        !dir.join("trace.json").exists(),
        "nothing of the trace is written"
    );
}

#[test]
fn merge_never_removes_a_users_file_and_its_refusal_names_every_one() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let out = tmp.path().join("merged");
    let o = merge(&shards, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mine: Vec<_> = ["seed-holiday.png", "compare-mine.png", "notes.txt"]
        .iter()
        .map(|n| out.join(n))
        .collect();
    png(&mine[0], 1000, 650);
    png(&mine[1], 1000, 650);
    std::fs::write(&mine[2], "mine").unwrap();
    let before = snapshot(&mine);

    let o = merge(&shards, &out, &[]);
    assert!(!o.status.success());
    assert_holds_all(
        "the refusal",
        &stderr(&o),
        &["'compare-mine.png'", "'notes.txt'", "'seed-holiday.png'"],
    );
    let o = merge(&shards, &out, &["--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(snapshot(&mine), before);
    assert_eq!(record(&out)["references.csv"], "merge");
}
