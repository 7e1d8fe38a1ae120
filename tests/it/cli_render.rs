//! `bench-sph render` driven through the built binary: the GIF and the PNG frames it writes
//! (decoded and measured), the frame-count rule, and a clear `Error: ...` with a non-zero exit
//! for each kind of bad input.

use std::path::Path;

use crate::common::{
    DIVERGING_INIT, assert_file_holds, bench_sph, fails_with_in, names, run_in, stderr, succeeds,
    wait_until,
};

/// The image size the render reports: "… of W × H px …".
fn reported_size(out: &str) -> (u32, u32) {
    let (_, rest) = out.split_once(" frames of ").expect("a summary line");
    let mut words = rest.split_whitespace();
    let width = words.next().unwrap().parse().unwrap();
    assert_eq!(words.next(), Some("×"));
    let height = words.next().unwrap().parse().unwrap();
    (width, height)
}

/// What a GIF holds, as far as these tests look.
struct Gif {
    /// Screen width and height.
    size: (u16, u16),
    /// Each frame's left, top, width and height.
    frames: Vec<[u16; 4]>,
}

fn decode_gif(path: &Path) -> Gif {
    let file = std::fs::File::open(path).expect("the GIF exists");
    let mut decoder = gif::DecodeOptions::new()
        .read_info(std::io::BufReader::new(file))
        .expect("a GIF header");
    let size = (decoder.width(), decoder.height());
    let mut frames = Vec::new();
    while let Some(f) = decoder.read_next_frame().expect("a valid frame") {
        frames.push([f.left, f.top, f.width, f.height]);
    }
    Gif { size, frames }
}

const SMALL: [&str; 8] = [
    "--n", "100", "--steps", "40", "--every", "20", "--width", "400",
];

#[test]
fn three_frames_at_n_100_decode_to_a_gif_of_three_frames_of_the_set_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(
        dir.path(),
        &[&["render", "--out", "small.gif"][..], &SMALL].concat(),
    );
    assert!(out.contains("3 frames"), "{out}");
    let (width, height) = reported_size(&out);
    assert_eq!(width, 400);

    let gif = decode_gif(&dir.path().join("small.gif"));
    assert_eq!(gif.size, (400, height as u16));
    assert_eq!(gif.frames.len(), 3);
    for frame in gif.frames {
        assert_eq!(frame, [0, 0, 400, height as u16]);
    }
    // The tank's aspect ratio (1200 × 900) sets the height: more than half the width.
    assert!(height > 200 && height < 400, "{height}");
}

#[test]
fn png_frames_are_written_one_per_frame_with_the_set_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(
        dir.path(),
        &[
            &["render", "--frames", "shots/run1", "--color", "density"][..],
            &SMALL,
        ]
        .concat(),
    );
    let size = reported_size(&out);
    let shots = dir.path().join("shots/run1");
    let names = names(&shots);
    assert_eq!(
        names,
        ["frame_00000.png", "frame_00001.png", "frame_00002.png"]
    );
    for name in names {
        let file = std::io::BufReader::new(std::fs::File::open(shots.join(&name)).unwrap());
        let reader = png::Decoder::new(file).read_info().expect("a PNG");
        let info = reader.info();
        assert_eq!((info.width, info.height), size, "{name}");
        assert_eq!(info.color_type, png::ColorType::Rgb, "{name}");
    }
}

#[test]
fn steps_past_the_last_whole_interval_make_no_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = succeeds(
        dir.path(),
        &[
            "render", "--n", "30", "--steps", "50", "--every", "20", "--out", "a.gif",
        ],
    );
    assert!(out.contains("3 frames"), "{out}");
    assert!(out.contains("steps 0 to 40"), "{out}");
    assert_eq!(decode_gif(&dir.path().join("a.gif")).frames.len(), 3);
}

#[test]
fn without_out_or_frames_the_gif_goes_to_dambreak_gif() {
    let dir = tempfile::tempdir().unwrap();
    succeeds(
        dir.path(),
        &["render", "--n", "20", "--steps", "2", "--every", "1"],
    );
    assert_eq!(decode_gif(&dir.path().join("dambreak.gif")).frames.len(), 3);
}

#[test]
fn every_strategy_renders_the_same_gif() {
    let dir = tempfile::tempdir().unwrap();
    let render = |strategy: &str| {
        let name = format!("{strategy}.gif");
        succeeds(
            dir.path(),
            &[
                "render",
                "--n",
                "60",
                "--steps",
                "30",
                "--every",
                "10",
                "--cores",
                "2",
                "--chunks",
                "3",
                "--strategy",
                strategy,
                "--out",
                &name,
            ],
        );
        std::fs::read(dir.path().join(name)).unwrap()
    };
    let seq = render("seq");
    for strategy in ["rayon-chunks", "std-static"] {
        assert!(render(strategy) == seq, "{strategy} drew different frames");
    }
}

#[test]
fn a_diverging_run_is_an_error_and_keeps_the_frames_before_it() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("boom.csv"), DIVERGING_INIT).unwrap();
    fails_with_in(
        dir.path(),
        &[
            "render", "--init", "boom.csv", "--steps", "5", "--every", "1", "--out", "b.gif",
        ],
        &[
            "Error:",
            "diverged at step 1",
            "frames up to step 0",
            "b.gif",
        ],
    );
    assert_eq!(decode_gif(&dir.path().join("b.gif")).frames.len(), 1);
}

#[test]
fn zero_counts_and_bad_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fails_with_in(
        d,
        &["render", "--every", "0"],
        &["--every", "between 1 and"],
    );
    fails_with_in(
        d,
        &["render", "--steps", "0"],
        &["--steps", "between 1 and"],
    );
    fails_with_in(d, &["render", "--n", "0"], &["--n", "between 1 and"]);
    fails_with_in(d, &["render", "--width", "10"], &["--width"]);
    fails_with_in(d, &["render", "--fps", "0"], &["--fps"]);
    fails_with_in(d, &["render", "--color", "pressure"], &["--color"]);
    assert!(!d.join("dambreak.gif").exists());
}

#[test]
fn out_and_frames_together_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    fails_with_in(
        dir.path(),
        &["render", "--out", "a.gif", "--frames", "f"],
        &["--out", "--frames", "cannot be used with"],
    );
    assert!(!dir.path().join("a.gif").exists());
    assert!(!dir.path().join("f").exists());
}

#[test]
fn an_unwritable_output_fails_before_anything_is_simulated() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("plain-file"), "not a folder").unwrap();
    // A long render: were it simulated before the path is checked, this test would crawl.
    let long = ["--n", "1000", "--steps", "20000", "--every", "1"];
    fails_with_in(
        d,
        &[&["render", "--out", "no/such/dir/a.gif"][..], &long].concat(),
        &["Error:", "cannot write 'no/such/dir/a.gif'"],
    );
    fails_with_in(
        d,
        &[&["render", "--frames", "plain-file/frames"][..], &long].concat(),
        &["Error:", "cannot create directory 'plain-file/frames'"],
    );
}

#[test]
fn a_missing_init_file_is_one_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    fails_with_in(
        dir.path(),
        &["render", "--init", "nope.csv"],
        &["Error:", "cannot read init file 'nope.csv'"],
    );
    assert!(!dir.path().join("dambreak.gif").exists());
}

fn frames(count: usize) -> Vec<String> {
    (0..count).map(|k| format!("frame_{k:05}.png")).collect()
}

#[test]
fn fewer_frames_into_the_folder_of_a_longer_render_leave_only_the_new_frames() {
    let dir = tempfile::tempdir().unwrap();
    let tiny = [
        "--n", "20", "--every", "1", "--width", "360", "--frames", "f",
    ];
    succeeds(
        dir.path(),
        &[&["render", "--steps", "10"][..], &tiny].concat(),
    );
    assert_eq!(names(&dir.path().join("f")), frames(11));
    succeeds(
        dir.path(),
        &[&["render", "--steps", "2"][..], &tiny].concat(),
    );
    assert_eq!(names(&dir.path().join("f")), frames(3));
}

#[test]
fn a_frames_folder_with_other_files_is_refused_and_force_writes_beside_them() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("f");
    std::fs::create_dir(&f).unwrap();
    std::fs::write(f.join("notes.txt"), "mine").unwrap();
    let args = [
        "render", "--n", "20", "--steps", "1", "--every", "1", "--frames", "f",
    ];
    fails_with_in(
        dir.path(),
        &args,
        &[
            "Error:",
            "--frames 'f' holds files that bench-sph render did not write ('notes.txt')",
            "--force",
        ],
    );
    assert_eq!(names(&f), ["notes.txt"]);
    succeeds(dir.path(), &[&args[..], &["--force"]].concat());
    assert_eq!(
        names(&f),
        ["frame_00000.png", "frame_00001.png", "notes.txt"]
    );
    assert_file_holds(&f.join("notes.txt"), "mine");
    fails_with_in(dir.path(), &["render", "--force"], &["--frames"]);
}

#[test]
fn an_interrupted_render_leaves_the_earlier_gif_untouched() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.gif"), "earlier").unwrap();
    let mut child = bench_sph()
        .args([
            "render", "--n", "400", "--steps", "1000000", "--every", "1", "--out", "a.gif",
        ])
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait until frames are being written (the temporary file has grown), then kill it.
    let writing = || {
        std::fs::read_dir(dir.path()).unwrap().any(|e| {
            let e = e.unwrap();
            e.file_name().to_string_lossy().ends_with(".tmp")
                && e.metadata().unwrap().len() > 20_000
        })
    };
    wait_until("no frames written", writing);
    child.kill().unwrap();
    child.wait().unwrap();
    assert_file_holds(&dir.path().join("a.gif"), "earlier");
}

#[test]
fn a_gif_that_cannot_be_written_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let full = "/dev/full";
    let args = [
        "render", "--n", "20", "--steps", "2", "--every", "1", "--out", full,
    ];
    let o = run_in(dir.path(), &args);
    assert!(!o.status.success());
    assert_eq!(
        stderr(&o),
        "Error: cannot write GIF file '/dev/full': No space left on device (os error 28)\n"
    );
    assert!(
        !std::fs::metadata("/dev/full").unwrap().is_file(),
        "the device stays a device"
    );
}

#[test]
fn a_render_larger_than_the_available_memory_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let o = bench_sph()
        .args(["render", "--n", "100000"])
        .current_dir(dir.path())
        .env("BENCH_SPH_FAKE_MEM_AVAILABLE", "1000000")
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert_eq!(
        stderr(&o),
        "Error: --n 100000 needs about 23 MB of memory (all-pairs search); \
         this machine has 1.0 MB available\n"
    );
    assert!(names(dir.path()).is_empty());
}

/// `render --preset wcsph --resolution 8` (128 fluid particles) with `more` arguments, in `dir`.
fn wcsph_render(dir: &Path, more: &[&str]) -> String {
    let base = [
        "render",
        "--preset",
        "wcsph",
        "--resolution",
        "8",
        "--width",
        "400",
    ];
    succeeds(dir, &[&base[..], more].concat())
}

#[test]
fn wcsph_renders_three_frames_to_a_gif_of_the_reported_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = wcsph_render(
        dir.path(),
        &["--steps", "40", "--every", "20", "--out", "w.gif"],
    );
    assert!(out.contains("3 frames"), "{out}");
    assert!(out.contains("steps 0 to 40, one every 20"), "{out}");
    assert!(out.contains("simulated time 0 to 0.0"), "{out}");
    let (width, height) = reported_size(&out);
    assert_eq!(width, 400);
    let gif = decode_gif(&dir.path().join("w.gif"));
    assert_eq!(gif.size, (400, height as u16));
    assert_eq!(gif.frames.len(), 3);
    // The tank with its walls, 5.75 m × 2.875 m at R = 8, sets the height.
    assert!(height > 200 && height < 400, "{height}");
}

#[test]
fn wcsph_renders_png_frames_coloured_by_speed_with_grey_walls() {
    let dir = tempfile::tempdir().unwrap();
    let out = wcsph_render(
        dir.path(),
        &["--steps", "40", "--every", "20", "--frames", "f"],
    );
    let size = reported_size(&out);
    assert_eq!(
        names(&dir.path().join("f")),
        ["frame_00000.png", "frame_00001.png", "frame_00002.png"]
    );
    let decode = |name: &str| {
        let file =
            std::io::BufReader::new(std::fs::File::open(dir.path().join("f").join(name)).unwrap());
        let mut reader = png::Decoder::new(file).read_info().expect("a PNG");
        let info = reader.info();
        assert_eq!((info.width, info.height), size, "{name}");
        let mut pixels = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut pixels).unwrap();
        pixels
    };
    // Viridis' lowest colour: the fluid at rest (and the legend bar's first columns).
    let still = |pixels: &[u8]| pixels.chunks_exact(3).filter(|p| *p == [68, 1, 84]).count();
    let first = decode("frame_00000.png");
    let last = decode("frame_00002.png");
    assert!(
        first.chunks_exact(3).any(|p| p == [168, 168, 168]),
        "the wall particles are grey"
    );
    // At rest the whole fluid is the lowest colour; 40 steps later it falls, faster.
    let (at_rest, falling) = (still(&first), still(&last));
    assert!(
        at_rest > 1000 && falling < at_rest / 2,
        "{at_rest} → {falling}"
    );
}

#[test]
fn wcsph_renders_until_a_simulated_time_and_the_frame_count_follows() {
    let dir = tempfile::tempdir().unwrap();
    let out = wcsph_render(
        dir.path(),
        &["--t-end", "0.01", "--every", "4", "--out", "t.gif"],
    );
    // R = 8: dt = 0.25 h / (c0 + v) ≈ 0.65 ms, so about 16 steps reach 10 ms: frames at 0, 4,
    // …, and at the step that reaches it.
    let frames: usize = out.split_whitespace().next().unwrap().parse().unwrap();
    let steps: usize = out
        .split_once("steps 0 to ")
        .and_then(|(_, rest)| rest.split(',').next())
        .unwrap()
        .parse()
        .unwrap();
    assert!((15..40).contains(&steps), "{out}");
    assert_eq!(frames, steps.div_ceil(4) + 1, "{out}");
    assert_eq!(decode_gif(&dir.path().join("t.gif")).frames.len(), frames);
    let simulated: f64 = out
        .split_once("simulated time 0 to ")
        .and_then(|(_, rest)| rest.split_whitespace().next())
        .unwrap()
        .parse()
        .unwrap();
    assert!((0.01..0.0107).contains(&simulated), "{out}");
}

#[test]
fn t_end_renders_the_mueller_presets_at_their_fixed_time_step() {
    let dir = tempfile::tempdir().unwrap();
    // seed: dt = 0.0009 s, so the 10th step is the first past 0.0085 s: frames at 0, 5, 10.
    let out = succeeds(
        dir.path(),
        &[
            "render", "--n", "30", "--t-end", "0.0085", "--every", "5", "--out", "m.gif",
        ],
    );
    assert!(out.contains("3 frames"), "{out}");
    assert!(out.contains("steps 0 to 10,"), "{out}");
    assert_eq!(decode_gif(&dir.path().join("m.gif")).frames.len(), 3);
    fails_with_in(
        dir.path(),
        &["render", "--t-end", "1", "--steps", "10"],
        &["--t-end", "--steps", "cannot be used with"],
    );
    fails_with_in(dir.path(), &["render", "--t-end", "0"], &["--t-end"]);
}
