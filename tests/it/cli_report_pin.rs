//! `bench-sph report` on sweeps over placements (`sweep --pin`) and on a machine with SMT
//! siblings, end to end through the built binary. The sweeps are timed by `--fake-timings`, so
//! which intervals overlap is known; their recorded topology is replaced by a chosen one
//! (this test must not depend on the machine it runs on, and this 2-core one has no SMT).
//! No test asserts a duration.

use crate::common;

use std::path::Path;

use crate::common::*;

/// The fake sweep's trials, three per cell, in the sweep's order: seq, then per strategy,
/// per cores, `none` then `spread`. rayon-chunks: the same at 1 core, `spread` faster at 2
/// cores with intervals apart; std-static: the same everywhere.
const TIMINGS: &str = "4,4,4, \
    4,4,4, 4,4,4, 2.4,2.5,2.6, 1.9,2,2.1, \
    4,4,4, 4,4,4, 3,3,3, 3,3,3";

/// A fake-timed sweep of rayon-chunks and std-static at 1 and 2 cores, unpinned and
/// `spread`, into `dir`.
fn pinned_sweep(dir: &Path) {
    let timings = TIMINGS.replace(' ', "");
    let mut args = fake_sweep("rayon-chunks,std-static", &timings);
    args.extend(["--pin", "none,spread", "--no-plots", "--out"]);
    args.push(dir.to_str().unwrap());
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Makes the sweep in `dir` say it ran on one socket of `physical` cores of `threads`
/// threads each: `meta.json`'s topology (top level and every session) and `summary.csv`'s
/// `smt` column (more threads than physical cores, no more than logical CPUs).
fn set_topology(dir: &Path, physical: usize, threads: usize) {
    let logical = physical * threads;
    let siblings: Vec<Vec<usize>> = (0..physical)
        .map(|c| (0..threads).map(|t| c + t * physical).collect())
        .collect();
    let topology = serde_json::json!({
        "logical_cpus": logical,
        "cpus": (0..logical).collect::<Vec<_>>(),
        "physical_cores": physical,
        "threads_per_core": threads,
        "sockets": 1,
        "numa_nodes": 1,
        "siblings": siblings,
        "l1d_kib": 48,
        "l2_kib": 2048,
        "l3_kib": 32768,
        "governor": "performance",
        "turbo": null,
    });
    common::set_in_meta(dir, |m| m["machine"]["topology"] = topology.clone());

    let path = dir.join("summary.csv");
    let mut reader = csv::Reader::from_path(&path).unwrap();
    let header = reader.headers().unwrap().clone();
    let at = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (cores, smt) = (at("cores"), at("smt"));
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(&header).unwrap();
    for record in reader.records() {
        let mut fields: Vec<String> = record.unwrap().iter().map(str::to_owned).collect();
        let c: usize = fields[cores].parse().unwrap();
        fields[smt] = (physical < c && c <= logical).to_string();
        writer.write_record(&fields).unwrap();
    }
    std::fs::write(&path, writer.into_inner().unwrap()).unwrap();
}

/// Runs `report` on `dir` into `out`; returns REPORT.md.
fn report(dir: &Path, out: &Path) -> String {
    let o = run(&[
        "report",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::read_to_string(out.join("REPORT.md")).unwrap()
}

#[test]
fn a_sweep_over_placements_gets_a_line_a_table_row_and_a_comparison_per_placement() {
    let tmp = tempfile::tempdir().unwrap();
    let (dir, out) = (tmp.path().join("sweep"), tmp.path().join("report"));
    pinned_sweep(&dir);
    set_topology(&dir, 2, 1);
    let md = report(&dir, &out);

    // Charts 1–2 once per placement; charts 3–5 once, with a line per placement.
    for name in [
        "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks.png",
        "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks-pin-spread.png",
        "seed-all-pairs-n60-s3-2-cpu-vs-chunks-rayon-chunks-pin-spread.png",
        "seed-all-pairs-n60-s3-3-best-rayon-chunks.png",
        "seed-all-pairs-n60-s3-4-speedup.png",
        "seed-all-pairs-n60-s3-5-efficiency.png",
    ] {
        assert_eq!(png_size(&out.join(name)), (1000, 650), "{name}");
        assert!(md.contains(&format!("]({name})")), "{name} not embedded");
    }
    assert!(
        !out.join("seed-all-pairs-n60-s3-3-best-rayon-chunks-pin-spread.png")
            .exists()
    );
    let caption = line_containing(&md, "*Chart 4:");
    assert!(
        caption.contains("solid: unpinned (`--pin none`), dashed: pinned `spread`"),
        "{caption}"
    );
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "![Chart 1: rayon-chunks (spread)]",
            "| cores | pin | best chunks | mean time (s) [95 % CI] | median (s) | min (s) | \
             speedup (± 95 % CI) | efficiency |",
            "| 2 | none | 4 | 2.50 [2.26–2.76] | 2.50 | 2.40 |",
            "| 2 | spread | 4 | 2.00 [1.76–2.26] | 2.00 | 1.90 | 2.00 ± 0.26× | 1.00 |",
            // The fastest cell at 2 cores is named with its placement; its lead is paired.
            "At 2 cores, **rayon-chunks (spread) with 4 chunks (2.00 s [1.76–2.26])** is \
             fastest, 2.00 ± 0.26× over seq: it is 1.25 ± 0.03× faster than the runner-up \
             rayon-chunks with 4 chunks",
            "rayon-chunks, `spread` against unpinned (at each core count, the chunks value \
             fastest under either): `spread` is faster (paired rounds) at 2 cores; they are \
             not distinguishable at 1 core; the largest difference is at 2 cores with 4 \
             chunks: `spread` 2.00 ± 0.26× against unpinned 1.60 ± 0.17× over seq.",
            "std-static, `spread` against unpinned: they are not distinguishable at 1 and 2 \
             cores, where their means are equal.",
        ],
    );
    // Two physical cores of one thread: nothing is on SMT siblings.
    assert_holds_all(
        "REPORT.md",
        &md,
        &["| physical cores | 2 |", "| threads per core | 1 |"],
    );
    for absent in ["SMT siblings", "efficiency per physical core", "shaded"] {
        assert!(!md.contains(absent), "{absent}:\n{md}");
    }
}

#[test]
fn core_counts_on_smt_siblings_are_shaded_and_get_the_efficiency_per_physical_core() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("sweep");
    pinned_sweep(&dir);
    set_topology(&dir, 2, 1);
    let flat = tmp.path().join("flat");
    report(&dir, &flat);
    // The same cells on one core of two threads: 2 cores are SMT siblings.
    set_topology(&dir, 1, 2);
    let smt = tmp.path().join("smt");
    let md = report(&dir, &smt);

    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "| physical cores | 1 |",
            "| threads per core | 2 |",
            "| caches (L1d / L2 / L3, per instance) | 48 KiB / 2 MiB / 32 MiB |",
            "| frequency governor | performance |",
            "| turbo | unknown |",
            // 2 strategies × 2 placements at 2 cores.
            "4 cells ran more threads than the machine's physical cores",
            "At 2 cores the threads outnumber the machine's 1 physical core",
            "S / min(p, 1)",
            "| cores | pin | best chunks | mean time (s) [95 % CI] | median (s) | min (s) | \
             speedup (± 95 % CI) | efficiency | efficiency per physical core |",
            // Speedup 2 on 2 threads of 1 physical core: 1 per thread, 2 per core.
            "| 2 | spread | 4 | 2.00 [1.76–2.26] | 2.00 | 1.90 | 2.00 ± 0.26× | 1.00 | 2.00 |",
            "| 1 | none | 4 | 4.00 [4.00–4.00] | 4.00 | 4.00 | 1.00 ± 0.00× | 1.00 | 1.00 |",
        ],
    );
    for n in [4, 5] {
        let caption = line_containing(&md, &format!("*Chart {n}:"));
        assert!(
            caption.contains(
                "shaded: the core counts past the machine's 1 physical core that put threads \
                 on SMT siblings"
            ),
            "{caption}"
        );
    }
    // The shading changes charts 4 and 5 and nothing else.
    let bytes = |dir: &Path, name: &str| std::fs::read(dir.join(name)).unwrap();
    for (name, shaded) in [
        (
            "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks.png",
            false,
        ),
        ("seed-all-pairs-n60-s3-3-best-rayon-chunks.png", false),
        ("seed-all-pairs-n60-s3-4-speedup.png", true),
        ("seed-all-pairs-n60-s3-5-efficiency.png", true),
    ] {
        assert_eq!(bytes(&flat, name) != bytes(&smt, name), shaded, "{name}");
    }
}
