//! Nothing lost, nothing half-written: every output goes through
//! a temporary file renamed into place only when complete, a link planted in the output folder
//! is refused, every output of a render is made before any is written, and a closed or full
//! standard output ends the command cleanly instead of a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use crate::common::{asset, names, out_dir};

fn stereolab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .output()
        .expect("run stereolab")
}

fn s(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// `stereolab render` of the Wuson scene at 64×48 into `dir`, with `--set` overrides.
fn render_small(dir: &Path, sets: &[&str]) -> Output {
    let scene = s(&asset("scenes/wuson.toml"));
    let out = s(dir);
    let mut args = vec!["render", &scene, "--size", "64x48", "--out", &out];
    for set in sets {
        args.extend(["--set", set]);
    }
    stereolab(&args)
}

/// A 1×1 depth map: too narrow for any SIRDS, so `sirds --depth` fails after reading it.
fn one_pixel_depth_map(dir: &Path) -> PathBuf {
    let p = dir.join("one.pgm");
    std::fs::write(&p, b"P5\n1 1\n255\n\x80").expect("write pgm");
    p
}

#[cfg(unix)]
#[test]
fn a_link_planted_in_the_output_folder_is_refused_and_nothing_is_written() {
    let dir = out_dir("reliability-link");
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, b"keep me").expect("victim");
    // The third output's name is a link: the run fails before writing anything (not left.png
    // and right.png first, then following the link).
    std::os::unix::fs::symlink(&victim, dir.join("side_by_side.png")).expect("symlink");
    let out = render_small(&dir, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a refused output must fail the run");
    assert!(stderr.contains("symbolic link"), "{stderr}");
    assert!(!String::from_utf8_lossy(&out.stdout).contains("wrote"));
    assert_eq!(std::fs::read(&victim).expect("victim"), b"keep me");
    assert_eq!(names(&dir), ["side_by_side.png", "victim.txt"]);
}

#[cfg(unix)]
#[test]
fn a_device_as_output_is_refused_instead_of_reported_as_written() {
    let dir = out_dir("reliability-device");
    std::os::unix::fs::symlink("/dev/full", dir.join("left.png")).expect("symlink");
    let out = render_small(&dir, &[]);
    assert!(!out.status.success());
    assert!(!String::from_utf8_lossy(&out.stdout).contains("wrote"));
}

#[test]
fn a_failed_sirds_keeps_the_file_it_would_have_replaced() {
    let dir = out_dir("reliability-precious");
    let depth = one_pixel_depth_map(&dir);
    for name in ["precious.ppm", "precious.png"] {
        let precious = dir.join(name);
        std::fs::write(&precious, b"precious").expect("precious");
        let out = stereolab(&["sirds", "--depth", &s(&depth), "-o", &s(&precious)]);
        assert!(!out.status.success(), "{name}: a 1-pixel map must fail");
        assert_eq!(std::fs::read(&precious).expect("still there"), b"precious");
    }
    // Nor does a failed decode leave an empty file in place of the old one.
    let precious = dir.join("decoded.png");
    std::fs::write(&precious, b"precious").expect("precious");
    let out = stereolab(&["sirds", "--decode", &s(&depth), "-o", &s(&precious)]);
    assert!(
        !out.status.success(),
        "a 1-pixel image is no autostereogram"
    );
    assert_eq!(std::fs::read(&precious).expect("still there"), b"precious");
    assert_eq!(
        names(&dir),
        ["decoded.png", "one.pgm", "precious.png", "precious.ppm"],
        "no temporary file may stay behind"
    );
}

#[test]
fn a_successful_render_leaves_only_its_outputs() {
    let dir = out_dir("reliability-clean");
    let out = render_small(&dir, &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(names(&dir), ["left.png", "right.png", "side_by_side.png"]);
    let img = image::open(dir.join("side_by_side.png")).expect("a whole PNG");
    assert_eq!((img.width(), img.height()), (128, 48));
}

#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["info", &s(&asset("scenes/wuson.toml"))])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    // Close the reading end before the command writes (it loads the model first).
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("wait");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(0), "{stderr}");
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_standard_output_is_an_error_not_a_panic() {
    let full = std::fs::File::options()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["info", &s(&asset("scenes/wuson.toml"))])
        .stdout(full)
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("standard output"), "{stderr}");
}

/// Runs stereolab, killing it after `secs`: `None` when it had to be killed (it hung).
fn stereolab_within(args: &[&str], secs: u64) -> Option<Output> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let start = std::time::Instant::now();
    while start.elapsed().as_secs() < secs {
        if child.try_wait().expect("wait").is_some() {
            return Some(child.wait_with_output().expect("output"));
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

/// A FIFO would block forever and `/dev/zero` would grow past 6 GB; both are refused
/// before a byte is read.
#[cfg(target_os = "linux")]
#[test]
fn fifos_and_devices_as_inputs_are_refused_at_once() {
    let dir = out_dir("reliability-special");
    let fifo = dir.join("scene.toml");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success(), "mkfifo failed");
    let wuson = s(&asset("scenes/wuson.toml"));
    let cases: Vec<Vec<String>> = vec![
        vec!["info".into(), s(&fifo)],
        vec!["info".into(), "/dev/zero".into()],
        vec![
            "render".into(),
            wuson.clone(),
            "--set".into(),
            "mesh.0.path=\"/dev/zero\"".into(),
            "--allow-outside-paths".into(),
            "--out".into(),
            s(&dir),
        ],
        vec!["sirds".into(), "--depth".into(), "/dev/urandom".into()],
        vec!["compare".into(), "/dev/zero".into(), s(&fifo)],
    ];
    for args in cases {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = stereolab_within(&argv, 20)
            .unwrap_or_else(|| panic!("{argv:?} hung and was killed after 20 s"));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{argv:?} must fail");
        assert!(stderr.contains("refusing to read"), "{argv:?}: {stderr}");
    }
}

/// `layout.blank_interval = 4294967295` must not wrap past the check (or panic in a debug
/// build): it is refused, naming the field.
#[test]
fn a_huge_blank_interval_is_refused_not_wrapped() {
    let dir = out_dir("reliability-blank");
    for blank in ["4294967295", "2147483647", "767"] {
        let out = render_small(
            &dir,
            &[
                "outputs=[\"above_below_squashed\"]",
                &format!("layout.blank_interval={blank}"),
            ],
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stderr.contains("panicked"), "{blank}: {stderr}");
        assert!(!out.status.success(), "{blank}: must be refused");
        assert!(
            stderr.contains("layout.blank_interval"),
            "{blank}: {stderr}"
        );
    }
    let ok = render_small(
        &dir,
        &[
            "outputs=[\"above_below_squashed\"]",
            "layout.blank_interval=46",
        ],
    );
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

/// No GIF under a PNG name (`--frames 3 -o x.png`) and no PAM under a PPM name (`--decode …
/// -o x.ppm`): an animation must be named .gif; a decoded depth map is a real PPM (P6)
/// or, for .pgm, a 16-bit PGM (P5).
#[test]
fn each_output_gets_the_container_its_name_says() {
    let dir = out_dir("reliability-container");
    let scene = s(&asset("scenes/sirds_sphere.toml"));
    let png = dir.join("anim.png");
    let out = stereolab(&["sirds", &scene, "--frames", "2", "-o", &s(&png)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "a GIF named .png must be refused");
    assert!(
        stderr.contains("--out") && stderr.contains(".gif"),
        "{stderr}"
    );
    assert!(!png.exists());
    let sirds = dir.join("s.png");
    assert!(
        stereolab(&["sirds", &scene, "-o", &s(&sirds)])
            .status
            .success()
    );
    for (name, magic) in [
        ("d.ppm", &b"P6\n"[..]),
        ("d.pgm", &b"P5\n512 256\n65535\n"[..]),
    ] {
        let path = dir.join(name);
        let out = stereolab(&["sirds", "--decode", &s(&sirds), "-o", &s(&path)]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&path).expect("decoded");
        assert!(bytes.starts_with(magic), "{name}: {:?}", &bytes[..16]);
        let img = image::open(&path).expect("netpbm readers can open it");
        assert_eq!((img.width(), img.height()), (512, 256));
    }
}

/// A PNG that claims `width`×`height` 8-bit gray pixels and holds no image data (an empty IDAT):
/// 57 bytes that a decoder would have to allocate the whole image for.
fn png_header_only(width: u32, height: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(width.to_be_bytes());
    ihdr.extend(height.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]); // 8 bits, grayscale, deflate, no filter, no interlace
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for chunk in [&ihdr[..], b"IDAT", b"IEND"] {
        png.extend((chunk.len() as u32 - 4).to_be_bytes());
        png.extend(chunk);
        png.extend(crc32(chunk).to_be_bytes());
    }
    png
}

/// A 20000×20000 PNG of 388 KB would take `sirds --decode` past 4.6 GB and `compare` of two
/// such images to 15.3 GB. The size is read from the header and refused before decoding; `--frames` has a limit.
#[test]
fn oversized_images_are_refused_from_their_header() {
    let dir = out_dir("reliability-huge");
    let huge = dir.join("huge.png");
    std::fs::write(&huge, png_header_only(20_000, 20_000)).expect("png");
    let cases: Vec<Vec<String>> = vec![
        vec![
            "sirds".into(),
            "--decode".into(),
            s(&huge),
            "-o".into(),
            s(&dir.join("d.png")),
        ],
        vec![
            "sirds".into(),
            "--depth".into(),
            s(&huge),
            "-o".into(),
            s(&dir.join("s.png")),
        ],
        vec!["compare".into(), s(&huge), s(&huge)],
    ];
    for args in cases {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = stereolab_within(&argv, 20).unwrap_or_else(|| panic!("{argv:?} hung"));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{argv:?} must fail");
        assert!(stderr.contains("20000x20000"), "{argv:?}: {stderr}");
    }
    let out = stereolab(&[
        "sirds",
        &s(&asset("scenes/sirds_sphere.toml")),
        "--frames",
        "100000",
        "-o",
        &s(&dir.join("a.gif")),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("--frames"),
        "{stderr}"
    );
}

/// A scene in `dir` whose one mesh is `kind` read from `path` (and an optional extra line).
fn scene_reading(dir: &Path, kind: &str, path: &str, extra: &str) -> PathBuf {
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "outputs = [\"left\"]\n{extra}\n[image]\nwidth = 32\nheight = 24\n[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n[[mesh]]\nkind = \"{kind}\"\npath = \"{path}\"\n"
        ),
    )
    .unwrap();
    scene
}

/// A scene reads only files in its own folder tree unless
/// `--allow-outside-paths` is given (absolute paths, `..`, links out of the tree, pattern
/// images), and what an error quotes of a file is short and escaped.
#[cfg(unix)]
#[test]
fn scenes_read_only_their_own_folder_tree_and_errors_quote_little() {
    let dir = out_dir("reliability-confined");
    let secret = out_dir("reliability-confined-outside").join("secret.csv");
    let secret_line = format!("x;y;height;{}\x1b[31m\n", "SECRET".repeat(20));
    std::fs::write(&secret, &secret_line).unwrap();
    std::os::unix::fs::symlink(&secret, dir.join("link.csv")).unwrap();
    let wuson = std::fs::read_to_string(asset("scenes/models/WusonOBJ.obj")).unwrap();
    std::fs::create_dir_all(dir.join("models")).unwrap();
    std::fs::write(dir.join("models/inside.obj"), wuson).unwrap();
    let cases = [
        ("terrain", s(&secret), ""),
        (
            "terrain",
            "../reliability-confined-outside/secret.csv".to_string(),
            "",
        ),
        ("terrain", "link.csv".to_string(), ""),
        (
            "obj",
            "models/inside.obj".to_string(),
            &*format!("[sirds]\npattern_image = \"{}\"", s(&secret)),
        ),
    ];
    for (kind, path, extra) in cases {
        let scene = s(&scene_reading(&dir, kind, &path, extra));
        let out = stereolab(&["info", &scene]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{path}: {err}");
        assert!(
            err.contains("names no file inside the scene's folder")
                && err.contains("--allow-outside-paths"),
            "{path}: {err}"
        );
        assert!(!err.contains("SECRET"), "{path} leaked the file: {err}");
    }
    // Whether a file outside exists cannot be told from the error: the same words, absolute,
    // by `..` or through a link (dangling or not), for a file that exists and one that does not.
    let missing = secret.with_file_name("missing.csv");
    std::os::unix::fs::symlink(&missing, dir.join("dangling.csv")).unwrap();
    let message = |path: &str| {
        let scene = s(&scene_reading(&dir, "terrain", path, ""));
        let err = String::from_utf8_lossy(&stereolab(&["info", &scene]).stderr).into_owned();
        // The message quotes at most 40 characters of the path.
        err.replace(&path.chars().take(40).collect::<String>(), "PATH")
    };
    for (exists, absent) in [
        (s(&secret), s(&missing)),
        (
            "../reliability-confined-outside/secret.csv".to_string(),
            "../reliability-confined-outside/missing.csv".to_string(),
        ),
        ("link.csv".to_string(), "dangling.csv".to_string()),
    ] {
        assert_eq!(message(&exists), message(&absent), "{exists} / {absent}");
    }
    // A file missing inside the tree is said to be missing.
    let err = message("models/none.obj");
    assert!(err.contains("No such file"), "{err}");
    // Inside the tree, the same scene loads.
    let inside = s(&scene_reading(&dir, "obj", "models/inside.obj", ""));
    assert!(stereolab(&["info", &inside]).status.success());
    // With the flag the file is read, and the error quotes at most a short escaped excerpt.
    let scene = s(&scene_reading(&dir, "terrain", &s(&secret), ""));
    let out = stereolab(&["info", &scene, "--allow-outside-paths"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("SECRET"), "the excerpt: {err}");
    assert!(err.matches("SECRET").count() <= 7, "quotes too much: {err}");
    assert!(
        !err.contains('\x1b'),
        "control characters must be escaped: {err}"
    );
}

/// A small scene asking for millions of triangles is refused before anything
/// is built, naming the field, the count, the budget and the flag; the flag moves the budget.
#[test]
fn a_scene_over_its_triangle_budget_is_refused_before_it_is_built() {
    let dir = out_dir("reliability-budget");
    for (mesh, field) in [
        ("kind = \"sphere\"\ndetail = 4096", "mesh[0].detail"),
        ("kind = \"triangles\"\ncount = 10000000", "mesh[0].count"),
    ] {
        let scene = dir.join("big.toml");
        std::fs::write(
            &scene,
            format!("outputs = [\"left\"]\n[image]\nwidth = 64\nheight = 48\n[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n[[mesh]]\n{mesh}\n"),
        )
        .unwrap();
        let out = stereolab(&["info", &s(&scene)]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains(field)
                && err.contains("budget of 4000000")
                && err.contains("--max-triangles"),
            "{err}"
        );
    }
    let out = stereolab(&["info", &s(&dir.join("big.toml")), "--max-triangles", "10"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("budget of 10"));
}

/// 16-bit images (depth maps) are compared at 16 bits: two maps 100 levels apart would
/// compare as identical after a reduction to 8 bits.
#[test]
fn sixteen_bit_images_are_compared_at_their_own_depth() {
    let dir = out_dir("reliability-16bit");
    let map = |name: &str, offset: u16| {
        let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(32, 16, |x, y| {
            image::Luma([1000 + 1000 * x as u16 + 10 * y as u16 + offset])
        });
        let p = dir.join(name);
        img.save(&p).expect("write 16-bit png");
        s(&p)
    };
    let (a, b, same) = (map("a.png", 0), map("b.png", 100), map("c.png", 0));
    let out = stereolab(&["compare", &a, &b]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("compared at 16 bits: max diff 100 of 65535 levels"),
        "{stdout}"
    );
    assert!(
        !stdout.contains(" inf "),
        "a difference must show in the PSNR: {stdout}"
    );
    let out = stereolab(&["compare", &a, &same]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    assert!(stdout.contains("max diff 0 of 65535 levels"), "{stdout}");
}

/// Messages name the input, the field or flag, the value and
/// the remedy.
#[test]
fn misleading_messages_name_the_real_problem() {
    let dir = out_dir("reliability-messages");
    let wuson = s(&asset("scenes/wuson.toml"));
    let afile = dir.join("afile");
    std::fs::write(&afile, "").unwrap();
    let image = s(&asset("readme/side_by_side.png"));
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec![
                "info".into(),
                wuson.clone(),
                "--set".into(),
                "camera.eye=[0,0,1e30]".into(),
            ],
            "camera.eye = [0.0, 0.0, 1e30]: lies 1.000e30 from the origin",
        ),
        (
            vec!["render".into(), wuson.clone(), "--out".into(), s(&afile)],
            "--out = ",
        ),
        (
            vec![
                "render".into(),
                wuson.clone(),
                "--size".into(),
                "0x0".into(),
                "--out".into(),
                s(&dir),
            ],
            "--size = 0x0: width and height must be at least 1 pixel",
        ),
        (vec!["compare".into(), image], "takes two images"),
    ];
    for (args, says) in cases {
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = stereolab(&argv);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{argv:?}: {err}");
        assert!(err.contains(says), "{argv:?}: {err}");
    }
    // A byte-order mark (as Windows editors write) is no part of the first word.
    let scene = |kind: &str, file: &str| {
        let p = dir.join(format!("{kind}.toml"));
        std::fs::write(
            &p,
            format!("outputs = [\"left\"]\n[image]\nwidth = 32\nheight = 24\n[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\nnear = 1\nfar = 10\n[[mesh]]\nkind = \"{kind}\"\npath = \"{file}\"\n"),
        )
        .unwrap();
        s(&p)
    };
    std::fs::write(
        dir.join("bom.obj"),
        "\u{feff}v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("bom.csv"),
        "\u{feff}x,y,height\n0,0,0\n1,0,0\n0,1,1\n",
    )
    .unwrap();
    for p in [scene("obj", "bom.obj"), scene("terrain", "bom.csv")] {
        let out = stereolab(&["info", &p]);
        assert!(
            out.status.success(),
            "{p}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// A GPU run that succeeds prints nothing on stderr, not even Mesa's "XDG_RUNTIME_DIR is
/// invalid or not set" when the variable is missing.
#[cfg(feature = "gpu")]
#[test]
fn a_successful_gpu_run_prints_no_errors_without_a_runtime_dir() {
    let dir = out_dir("reliability-gpu-quiet");
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args([
            "render",
            &s(&asset("scenes/wuson.toml")),
            "--backend",
            "gpu",
        ])
        .args(["--size", "64x48", "--out", &s(&dir)])
        .env_remove("XDG_RUNTIME_DIR")
        .output()
        .expect("run stereolab");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.trim().is_empty(), "stderr of a successful run: {err}");
}

/// `stereolab` with standard output closed in the child (`>&-`), not redirected anywhere.
#[cfg(unix)]
fn stereolab_with_stdout_closed(args: &[&str]) -> Output {
    use std::os::unix::process::CommandExt as _;
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_stereolab"));
    cmd.args(args).stderr(Stdio::piped());
    // SAFETY: close(2) is async-signal-safe; the child closes its own descriptor 1 before exec.
    unsafe {
        cmd.pre_exec(|| {
            libc::close(1);
            Ok(())
        });
    }
    cmd.output().expect("run stereolab")
}

/// The first bytes of each container, to tell which one a file holds.
fn container_of(bytes: &[u8]) -> &'static str {
    match bytes {
        [0x89, b'P', b'N', b'G', ..] => "png",
        [0xff, 0xd8, 0xff, ..] => "jpeg",
        [b'G', b'I', b'F', b'8', ..] => "gif",
        [b'P', b'5', ..] => "pgm",
        [b'P', b'6', ..] => "ppm",
        [b'P', b'7', ..] => "pam",
        _ => "unknown",
    }
}

/// Every name `sirds` writes an image under gets the container its extension names (case
/// ignored), or is refused before any work with the argument, the extension and the accepted
/// extensions, and nothing is written.
#[test]
fn an_image_is_written_in_the_format_its_name_says_or_refused_before_any_work() {
    let dir = out_dir("reliability-formats");
    let scene = s(&asset("scenes/sirds_sphere.toml"));
    for (name, container) in [
        ("s.PNG", "png"),
        ("s.jpg", "jpeg"),
        ("s.JPEG", "jpeg"),
        ("s.gif", "gif"),
        ("s.ppm", "ppm"),
        ("s.pgm", "pgm"),
    ] {
        let path = dir.join(name);
        let out = stereolab(&["sirds", &scene, "-o", &s(&path)]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&path).expect("written");
        assert_eq!(container_of(&bytes), container, "{name}");
        let img = image::load_from_memory(&bytes).expect("a whole image");
        assert_eq!((img.width(), img.height()), (512, 256), "{name}");
    }
    // The decoded depth map: .pam is PAM (16-bit gray), .jpg an 8-bit gray JPEG.
    let sirds = s(&dir.join("s.PNG"));
    for (name, container) in [("d.pam", "pam"), ("d.jpg", "jpeg")] {
        let path = dir.join(name);
        let out = stereolab(&["sirds", "--decode", &sirds, "-o", &s(&path)]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let bytes = std::fs::read(&path).expect("written");
        assert_eq!(container_of(&bytes), container, "{name}");
        let img = image::load_from_memory(&bytes).expect("a whole image");
        assert_eq!((img.width(), img.height()), (512, 256), "{name}");
    }
    let before = names(&dir);
    // Refused before any work: the inputs named here do not exist, and the error is still the
    // name's, not the missing input's.
    let missing = s(&dir.join("missing.toml"));
    let missing_image = s(&dir.join("missing.png"));
    let cases: Vec<(Vec<String>, &str, &str)> = vec![
        (
            vec![missing.clone()],
            "x.bmp",
            ".png, .ppm, .pnm, .pgm, .jpg, .jpeg, .gif",
        ),
        (vec![missing.clone()], "x.tiff", ".jpg"),
        (vec![missing.clone()], "x.WebP", ".gif"),
        (vec![missing.clone()], "x.txt", ".png"),
        (vec![missing], "x", ".png"),
        (
            vec!["--depth".into(), missing_image.clone()],
            "x.webp",
            ".ppm",
        ),
        (
            vec!["--decode".into(), missing_image.clone()],
            "x.gif",
            ".png, .pgm, .ppm, .pnm, .pam, .jpg, .jpeg",
        ),
        (vec!["--decode".into(), missing_image], "x.bmp", ".pam"),
    ];
    for (input, name, accepted) in cases {
        let path = dir.join(name);
        let mut argv = vec!["sirds".to_string()];
        argv.extend(input);
        argv.extend(["-o".into(), s(&path)]);
        let argv: Vec<&str> = argv.iter().map(String::as_str).collect();
        let out = stereolab(&argv);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{argv:?}: {err}");
        let ext = match name.rsplit_once('.') {
            Some((_, ext)) => format!("unsupported extension .{ext}"),
            None => "no extension".into(),
        };
        assert!(
            err.contains("--out") && err.contains(&ext) && err.contains(accepted),
            "{argv:?}: {err}"
        );
        assert!(!path.exists(), "{name} was written");
    }
    assert_eq!(names(&dir), before, "a refused name leaves nothing behind");
}

/// Two 32×32 images: black, and black with a white 8×8 square (6.25% of the pixels).
fn square_and_blank(dir: &Path) -> (String, String) {
    let square = image::RgbImage::from_fn(32, 32, |x, y| {
        if (8..16).contains(&x) && (8..16).contains(&y) {
            image::Rgb([255, 255, 255])
        } else {
            image::Rgb([0, 0, 0])
        }
    });
    let (a, b) = (dir.join("square.png"), dir.join("blank.png"));
    square.save(&a).expect("png");
    image::RgbImage::new(32, 32).save(&b).expect("png");
    (s(&a), s(&b))
}

/// A failed `compare` says which limits were exceeded and by how much, in sentences, not a
/// count dressed as a threshold value.
#[test]
fn a_failed_compare_names_each_exceeded_limit_and_by_how_much() {
    let dir = out_dir("reliability-compare-words");
    let (square, blank) = square_and_blank(&dir);
    let out = stereolab(&["compare", &square, &blank]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("--threshold = "), "{err}");
    assert!(err.contains("blank.png: 3 limits exceeded"), "{err}");
    assert!(
        err.contains(
            "coverage differs on 6.25000% of the pixels (drawn in one image, background in the \
             other), 6.15000 points over the limit of 0.1% (coverage=)"
        ),
        "{err}"
    );
    assert!(
        err.contains("the color channels differ by") && err.contains("over the limit of 1 (mean=)"),
        "{err}"
    );
    assert!(
        err.contains("dB under the least allowed 30 dB (psnr=)"),
        "{err}"
    );
    let out = stereolab(&[
        "compare",
        &square,
        &blank,
        "--threshold",
        "coverage=10",
        "--threshold",
        "mean=100",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("1 limit exceeded"), "{err}");
    assert!(
        err.contains("(psnr=)") && !err.contains("(coverage=)"),
        "{err}"
    );
    // Without --out no strip is written, and the failure says how to get one; with it, it is.
    assert!(err.contains("add --out DIR"), "{err}");
    let strips = dir.join("strips");
    let out = stereolab(&["compare", &square, &blank, "--out", &s(&strips)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("add --out DIR"), "{err}");
    assert!(strips.join("blank-diff.png").is_file(), "{err}");
}

/// `--near` says which values of a depth map are near: without `--depth` there is no map, and
/// the flag is refused instead of ignored.
#[test]
fn near_without_a_depth_map_is_refused() {
    let dir = out_dir("reliability-near");
    let scene = s(&asset("scenes/sirds_sphere.toml"));
    let out_png = s(&dir.join("s.png"));
    for near in ["black", "white"] {
        for input in [vec![scene.as_str()], vec!["--decode", out_png.as_str()]] {
            let mut argv = vec!["sirds"];
            argv.extend(&input);
            argv.extend(["--near", near, "-o", &out_png]);
            let out = stereolab(&argv);
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(!out.status.success(), "{argv:?}: {err}");
            assert!(
                err.contains("--near") && err.contains("--depth"),
                "{argv:?}: {err}"
            );
        }
    }
    assert!(names(&dir).is_empty(), "nothing is written");
}

/// A closed standard output (`>&-`) is not a closed pipe: what the command would print is
/// lost, so it fails with a message on standard error.
#[cfg(target_os = "linux")]
#[test]
fn a_closed_standard_output_is_an_error() {
    let out = stereolab_with_stdout_closed(&["info", &s(&asset("scenes/wuson.toml"))]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("standard output") && err.contains("closed"),
        "{err}"
    );
    // The same command with standard output on /dev/null (written, then discarded) succeeds.
    let out = Command::new(env!("CARGO_BIN_EXE_stereolab"))
        .args(["info", &s(&asset("scenes/wuson.toml"))])
        .stdout(Stdio::null())
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Images that are no autostereogram are refused by `sirds --decode`, with the share of pixels
/// that matched, and nothing is written: a photo-like gradient, noise, a flat image and a
/// rendered eye view.
#[test]
fn decoding_an_image_that_is_no_autostereogram_is_refused_and_writes_nothing() {
    let dir = out_dir("reliability-not-sirds");
    let (w, h) = (256u32, 192u32);
    let gradient = image::RgbImage::from_fn(w, h, |x, y| {
        let (fx, fy) = (x as f32 / w as f32, y as f32 / h as f32);
        let v = |a: f32| (255.0 * a.clamp(0.0, 1.0)) as u8;
        image::Rgb([
            v(0.5 + 0.5 * (6.0 * fx).sin() * fy),
            v(fx * 0.8 + 0.2 * (9.0 * fy).cos()),
            v(1.0 - fy),
        ])
    });
    gradient.save(dir.join("gradient.png")).expect("png");
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let noise = image::RgbImage::from_fn(w, h, |_, _| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let b = state.to_le_bytes();
        image::Rgb([b[0], b[1], b[2]])
    });
    noise.save(dir.join("noise.png")).expect("png");
    image::RgbImage::from_pixel(w, h, image::Rgb([90, 120, 150]))
        .save(dir.join("flat.png"))
        .expect("png");
    let rendered = out_dir("reliability-not-sirds-render");
    let out = stereolab(&[
        "render",
        &s(&asset("scenes/wuson.toml")),
        "--size",
        "256x192",
        "--out",
        &s(&rendered),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::copy(rendered.join("left.png"), dir.join("left.png")).expect("copy");
    let scene = s(&asset("scenes/sirds_sphere.toml"));
    for name in ["gradient.png", "noise.png", "flat.png", "left.png"] {
        let input = s(&dir.join(name));
        let depth = dir.join(format!("depth-{name}"));
        // Untold (the separations searched for) and told the set-up (by the scene).
        for told in [false, true] {
            let mut argv = vec!["sirds"];
            if told {
                argv.push(&scene);
            }
            let depth_s = s(&depth);
            argv.extend(["--decode", &input, "-o", &depth_s]);
            let out = stereolab(&argv);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{argv:?}: {err}");
            assert!(
                err.contains("not an autostereogram") && err.contains("nothing written"),
                "{argv:?}: {err}"
            );
            assert!(err.contains("% of the"), "the share measured: {err}");
            assert!(!depth.exists(), "{argv:?} wrote {}", depth.display());
        }
    }
}

/// A small scene with `extra` lines appended (after `[camera]`, so bare keys land there unless
/// `extra` opens a table), written to `dir/name`.
fn small_scene(dir: &Path, name: &str, outputs: &str, extra: &str) -> String {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            "outputs = {outputs}\n[image]\nwidth = 32\nheight = 24\n[camera]\neye = [0, 0, 5]\n\
             target = [0, 0, 0]\nnear = 1\nfar = 10\n{extra}"
        ),
    )
    .expect("write scene");
    s(&p)
}

/// What no message may say: serde's and Rust's own words.
const RUST_WORDS: [&str; 8] = [
    "untagged",
    "SeparationSpec",
    "struct",
    "Camera",
    "wanted",
    "f32",
    "u32",
    "invalid type",
];

fn refused_with(args: &[&str], says: &[&str]) {
    let out = stereolab(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    for s in says {
        assert!(err.contains(s), "{args:?}: wanted {s:?} in {err}");
    }
    for w in RUST_WORDS {
        assert!(!err.contains(w), "{args:?}: {w:?} in {err}");
    }
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn scene_type_errors_name_the_field_the_value_and_what_is_accepted() {
    let dir = out_dir("reliability-field-errors");
    let left = "[\"left\"]";
    let cases: [(&str, &str, &[&str]); 7] = [
        (
            left,
            "[stereo]\neye_separation = true\n",
            &[
                "stereo.eye_separation = true",
                "a number (world units) or \"auto\"",
            ],
        ),
        (
            left,
            "[stereo]\nzero_parallax = [1]\n",
            &["stereo.zero_parallax = [1]", "\"auto\"", "\"fit\""],
        ),
        (
            left,
            "[stereo]\nmode = 3\n",
            &["stereo.mode = 3", "one of \"off-axis\"", "\"toe-in\""],
        ),
        (
            left,
            "[[mesh]]\nkind = \"sphere\"\n[[mesh]]\nkind = \"cube\"\ncolor = \"red\"\n",
            &["mesh[1].color = \"red\"", "a list of 3 numbers"],
        ),
        (
            left,
            "fov_y = \"wide\"\n",
            &["camera.fov_y = \"wide\"", "must be a number"],
        ),
        (
            left,
            "fovy = 40\n",
            &["camera.fovy", "no such field in [camera]", "fov_y"],
        ),
        (
            "\"left\"",
            "",
            &["outputs = \"left\"", "a list of output names"],
        ),
    ];
    for (i, (outputs, extra, says)) in cases.iter().enumerate() {
        let scene = small_scene(&dir, &format!("s{i}.toml"), outputs, extra);
        refused_with(&["info", &scene], says);
    }
    // A table given as a number.
    let p = dir.join("camera.toml");
    std::fs::write(
        &p,
        "outputs = [\"left\"]\ncamera = 5\n[image]\nwidth = 32\nheight = 24\n",
    )
    .unwrap();
    refused_with(&["info", &s(&p)], &["camera = 5", "must be a table"]);
    // A long value is quoted in part.
    let long = format!("fov_y = \"{}\"\n", "w".repeat(200));
    let scene = small_scene(&dir, "long.toml", left, &long);
    let out = stereolab(&["info", &scene]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(&format!("\"{}…\"", "w".repeat(40))), "{err}");
    assert!(!err.contains(&"w".repeat(41)), "{err}");
}

/// `--set` without a scene (`sirds --depth`, `--decode`) speaks as a scene's `--set` does, and
/// a dots-per-inch past single precision is named, not reported as a NaN separation.
#[test]
fn sirds_sets_without_a_scene_name_the_key_the_value_and_what_is_accepted() {
    let dir = out_dir("reliability-sirds-sets");
    let map = dir.join("ramp.pgm");
    let mut pgm = b"P5\n64 32\n255\n".to_vec();
    pgm.extend((0..64 * 32).map(|i| (i % 64 * 4) as u8));
    std::fs::write(&map, pgm).expect("pgm");
    let (map, out) = (s(&map), s(&dir.join("o.png")));
    let cases: [(&str, &[&str]); 6] = [
        (
            "sirds.dpi=abc",
            &["--set sirds.dpi = abc: must be a number"],
        ),
        (
            "sirds.dpi=",
            &["--set sirds.dpi = \"\"", "empty", "must be a number"],
        ),
        (
            "sirds.dpi=[1,2",
            &["--set sirds.dpi = [1,2", "not a complete TOML value"],
        ),
        (
            "sirds.nosuch=1",
            &["--set sirds.nosuch = 1", "no such field in [sirds]", "dpi"],
        ),
        (
            "camera.fov_y=40",
            &["--set camera.fov_y = 40", "[sirds] fields only"],
        ),
        (
            "sirds.dpi=1e38",
            &["sirds.dpi = 1e38", "beyond single precision", "72 to 2400"],
        ),
    ];
    for (set, says) in cases {
        refused_with(&["sirds", "--depth", &map, "--set", set, "-o", &out], says);
    }
    assert!(!dir.join("o.png").exists());
}

#[test]
fn set_errors_name_the_key_the_value_and_what_is_accepted() {
    let wuson = s(&asset("scenes/wuson.toml"));
    let cases: [(&str, &[&str]); 7] = [
        (
            "camera.fov_y=abc",
            &["--set camera.fov_y = abc: must be a number"],
        ),
        (
            "image.width=64.5",
            &["--set image.width = 64.5: must be a whole number"],
        ),
        (
            "camera.near=",
            &["--set camera.near = \"\": the value is empty; it must be a number"],
        ),
        (
            "mesh.0.color=[1,0,0",
            &[
                "--set mesh.0.color = [1,0,0: not a complete TOML value",
                "[1, 0, 0]",
            ],
        ),
        (
            "nosuch.table=1",
            &[
                "--set nosuch.table = 1: nosuch: no such table or field",
                "camera",
            ],
        ),
        (
            "mesh.3.color=[1,0,0]",
            &["--set mesh.3.color", "mesh has 1 entry (index 0)"],
        ),
        (
            "camera.fov_y.x=1",
            &["--set camera.fov_y.x = 1", "fov_y is a value, not a table"],
        ),
    ];
    for (set, says) in cases {
        refused_with(&["info", &wuson, "--set", set], says);
    }
}

#[test]
fn control_characters_from_a_scene_never_reach_the_terminal() {
    let dir = out_dir("reliability-control");
    let evil = "\\u001b]0;owned\\u0007\\u001b[2J\\u0001";
    let cases = [
        small_scene(&dir, "output.toml", &format!("[\"{evil}\"]"), ""),
        small_scene(
            &dir,
            "kind.toml",
            "[\"left\"]",
            &format!("[[mesh]]\nkind = \"{evil}\"\n"),
        ),
        small_scene(
            &dir,
            "separation.toml",
            "[\"left\"]",
            &format!("[stereo]\neye_separation = \"{evil}\"\n"),
        ),
        small_scene(
            &dir,
            "field.toml",
            "[\"left\"]",
            &format!("\"{evil}\" = 1\n"),
        ),
    ];
    for scene in cases {
        let out = stereolab(&["info", &scene]);
        assert_eq!(out.status.code(), Some(1), "{scene}");
        let raw = &out.stderr;
        for byte in [0x1b, 0x07, 0x01] {
            assert!(
                !raw.contains(&byte),
                "{scene}: raw byte {byte:#x} in {}",
                String::from_utf8_lossy(raw).escape_debug()
            );
        }
        let err = String::from_utf8_lossy(raw);
        assert!(err.contains("\\u{1b}]0;owned\\u{7}"), "{scene}: {err}");
    }
}

#[test]
fn a_utf16_scene_without_a_byte_order_mark_is_named() {
    let dir = out_dir("reliability-utf16");
    let text = "outputs = [\"left\"]\n[image]\nwidth = 32\nheight = 24\n";
    for (name, bytes) in [
        (
            "le.toml",
            text.encode_utf16()
                .flat_map(u16::to_le_bytes)
                .collect::<Vec<u8>>(),
        ),
        (
            "be.toml",
            text.encode_utf16().flat_map(u16::to_be_bytes).collect(),
        ),
        (
            "le-accent.toml",
            "# é\n"
                .encode_utf16()
                .chain(text.encode_utf16())
                .flat_map(u16::to_le_bytes)
                .collect(),
        ),
    ] {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let out = stereolab(&["info", &s(&p)]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(
            err.contains("UTF-16 without a byte-order mark"),
            "{name}: {err}"
        );
        assert!(!err.contains("key with no value"), "{name}: {err}");
    }
}

/// A model file is held to the triangle budget while it is read: the line or row that passes
/// it is named with the budget and the flag, whatever the rest of the file holds; a malformed
/// OBJ line is named and quoted.
#[test]
fn model_files_are_refused_at_the_line_that_passes_the_budget_or_breaks_the_format() {
    let dir = out_dir("reliability-reading");
    let square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
    let faces = "f 1 2 3\n".repeat(11);
    let cases: [(&str, &str, String, &[&str], &str); 6] = [
        (
            "obj",
            "over.obj",
            // The 11th face passes a budget of 10; line 16 is never read.
            format!("{square}{faces}f 1 2 99\n"),
            &["--max-triangles", "10"],
            "over.obj:15: the faces so far make 11 triangles, more than the scene's budget of \
             10: simplify the model, or raise the budget with --max-triangles",
        ),
        (
            "obj",
            "vertices.obj",
            "v 0 0 0\n".repeat(31),
            &["--max-triangles", "10"],
            "vertices.obj:31: more than 30 'v' lines, 3 per triangle of the scene's budget of 10 \
             triangles",
        ),
        (
            "obj",
            "seven.obj",
            format!("{square}v 1 2 3 4 5 6 7\nf 1 2 3\n"),
            &[],
            "seven.obj:5: 'v' needs 3 coordinates (4 with a weight w, 6 with a color r g b), \
             found more: 'v 1 2 3 4 5 6 7'",
        ),
        (
            "obj",
            "corner.obj",
            format!("{square}vt 0 0\nvn 0 0 1\nf 1/1/1/1 2/1/1 3/1/1\n"),
            &[],
            "corner.obj:7: face corner '1/1/1/1' has 4 parts: a corner is v, v/vt, v//vn or \
             v/vt/vn",
        ),
        (
            "terrain",
            "over.csv",
            "x,y,height\n0,0,0\n1,0,0\n0,1,0\n1,1,0\n1,2,0\n2,2,x\n".to_string(),
            &["--max-triangles", "8"],
            "over.csv:6: more than 4 points, which could make more than the scene's budget of 8 \
             triangles (up to 2 per point): thin the data, or raise the budget with \
             --max-triangles",
        ),
        (
            "obj",
            "fine.obj",
            format!("{square}{faces}"),
            &["--max-triangles", "11"],
            "",
        ),
    ];
    for (kind, name, text, flags, says) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let scene = s(&scene_reading(&dir, kind, name, ""));
        let mut args = vec!["info", &scene];
        args.extend(flags);
        let out = stereolab(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        if says.is_empty() {
            assert!(out.status.success(), "{name}: {err}");
            continue;
        }
        assert_eq!(out.status.code(), Some(1), "{name}: {err}");
        assert!(err.contains(says), "{name}: {err}");
    }
}

/// The largest DEM count is accepted with the budget its refusal names, and the default budget
/// names the largest count it takes.
#[test]
fn the_largest_dem_count_names_the_budget_it_needs() {
    let dir = out_dir("reliability-dem");
    image::GrayImage::from_fn(4, 3, |x, _| image::Luma([(x * 80) as u8]))
        .save(dir.join("ramp.png"))
        .unwrap();
    let extra = "";
    let scene = scene_reading(&dir, "dem", "ramp.png", extra);
    let text = std::fs::read_to_string(&scene).unwrap()
        + "extent = [1, 1]\nheights = [0, 1]\ncount = 2000000\n";
    std::fs::write(&scene, text).unwrap();
    let out = stereolab(&["info", &s(&scene)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("mesh[0].count")
            && err.contains("up to 4005658 triangles")
            && err.contains("the budget takes count = 1997173 at most")
            && err.contains("--max-triangles 4005658"),
        "{err}"
    );
}
