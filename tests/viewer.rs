//! `stereolab view` as a person uses it: a virtual X server (Xvfb), keys and mouse clicks
//! from xdotool, screenshots of the window (xwd), and what changed on screen. The viewer's
//! `--state-file` gives the readouts and where the picture lies in the window.
//!
//! Needs `Xvfb` (package xvfb), `xdotool` (xdotool), `xwd` (x11-apps) and Mesa's OpenGL
//! (libgl1-mesa-dri, libegl1); `.ci/run` installs them. A missing tool fails the test with
//! the package to install.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{asset, out_dir};

pub(crate) fn stereolab() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stereolab"))
}

/// The path of `tool` on PATH, or a failure naming the Debian package that has it.
pub(crate) fn need(tool: &str, package: &str) -> PathBuf {
    std::env::var_os("PATH")
        .and_then(|paths| {
            std::env::split_paths(&paths)
                .map(|d| d.join(tool))
                .find(|p| p.is_file())
        })
        .unwrap_or_else(|| {
            panic!("`{tool}` not found: the viewer tests need it (apt-get install {package})")
        })
}

/// A child process killed when dropped.
pub(crate) struct Killed(pub(crate) Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A virtual X server on a free display number.
pub(crate) struct Xvfb {
    server: Killed,
    pub(crate) display: String,
}

impl Drop for Xvfb {
    /// SIGTERM first: Xvfb then removes its lock file and socket (SIGKILL would leave them, and
    /// a display number with a lock file looks taken); SIGKILL after 2 s.
    fn drop(&mut self) {
        let server = &mut self.server.0;
        if let Ok(pid) = i32::try_from(server.id()) {
            // SAFETY: a plain syscall on the child this struct owns (not yet reaped).
            unsafe { libc::kill(pid, libc::SIGTERM) };
            let start = Instant::now();
            while start.elapsed() < Duration::from_secs(2) {
                if let Ok(Some(_)) = server.try_wait() {
                    return;
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    }
}

/// Display `n` is in use: its lock file names a process that is still running. (A lock whose
/// process is gone is stale; Xvfb removes it and takes the number.)
fn display_in_use(n: u32) -> bool {
    std::fs::read_to_string(format!("/tmp/.X{n}-lock"))
        .ok()
        .and_then(|text| text.trim().parse::<u32>().ok())
        .is_some_and(|pid| Path::new(&format!("/proc/{pid}")).exists())
}

pub(crate) fn start_xvfb() -> Xvfb {
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicU32, Ordering};
    // Tests in this process start their servers one at a time, each on a display number no
    // other test here has tried: two servers started at once on one free number would both
    // see the winner's socket serving, and two tests would share a screen.
    static STARTING: Mutex<()> = Mutex::new(());
    static TRIED: AtomicU32 = AtomicU32::new(0);
    let _one_at_a_time = STARTING.lock().unwrap_or_else(|e| e.into_inner());
    let xvfb = need("Xvfb", "xvfb");
    let xdotool = need("xdotool", "xdotool");
    let first = 70 + std::process::id() % 100 + TRIED.fetch_add(40, Ordering::SeqCst);
    for n in first..first + 40 {
        if display_in_use(n) {
            continue;
        }
        let server = Command::new(&xvfb)
            .args([
                &format!(":{n}"),
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("start Xvfb");
        let mut server = Killed(server);
        let socket = PathBuf::from(format!("/tmp/.X11-unix/X{n}"));
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(10) {
            // Ready means an X client completes its handshake, not only that the socket file
            // exists: in a CI run under load the viewer once found the socket but could not
            // open a connection (winit: "Failed to open connection to X server").
            let serving = || {
                Command::new(&xdotool)
                    .arg("getdisplaygeometry")
                    .env("DISPLAY", format!(":{n}"))
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .status()
                    .is_ok_and(|s| s.success())
            };
            if socket.exists() && serving() {
                return Xvfb {
                    server,
                    display: format!(":{n}"),
                };
            }
            if let Ok(Some(_)) = server.0.try_wait() {
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
    panic!("could not start Xvfb on any display :{first}..");
}

/// The viewer running under Xvfb, its window and its state file.
pub(crate) struct Viewer<'a> {
    x: &'a Xvfb,
    _child: Killed,
    pub(crate) window: String,
    state: PathBuf,
}

impl Viewer<'_> {
    /// The test's output folder (the state file's).
    fn out(&self) -> &Path {
        self.state.parent().unwrap_or(Path::new("."))
    }
}

fn json(path: &Path) -> Option<serde_json::Value> {
    serde_json::from_str(&std::fs::read_to_string(path).ok()?).ok()
}

impl Viewer<'_> {
    pub(crate) fn start<'a>(x: &'a Xvfb, out: &Path, args: &[&str]) -> Viewer<'a> {
        let state = out.join("state.json");
        let log_path = out.join("viewer.log");
        let _ = std::fs::remove_file(&log_path);
        let spawn = || {
            let log = std::fs::File::options()
                .create(true)
                .append(true)
                .open(&log_path)
                .expect("log file");
            Killed(
                stereolab()
                    .arg("view")
                    .args(args)
                    .arg("--shots")
                    .arg(out)
                    .arg("--state-file")
                    .arg(&state)
                    .env("DISPLAY", &x.display)
                    .env_remove("WAYLAND_DISPLAY")
                    .env("LIBGL_ALWAYS_SOFTWARE", "1")
                    .stdout(log.try_clone().expect("log"))
                    .stderr(log)
                    .spawn()
                    .expect("start stereolab view"),
            )
        };
        let mut child = spawn();
        let mut attempts = 1;
        let xdotool = need("xdotool", "xdotool");
        let start = Instant::now();
        let window = loop {
            let found = Command::new(&xdotool)
                .args(["search", "--name", "stereolab view"])
                .env("DISPLAY", &x.display)
                .output()
                .expect("run xdotool");
            let text = String::from_utf8_lossy(&found.stdout);
            if let Some(id) = text.lines().next().filter(|l| !l.trim().is_empty()) {
                break id.trim().to_string();
            }
            let log = std::fs::read_to_string(&log_path).unwrap_or_default();
            // A viewer that could not connect to a busy X server exits at once with the
            // error naming DISPLAY (the behaviour `missing_display` checks); the test's
            // server is up (`start_xvfb` waited for a client handshake), so try twice more
            // before calling it a failure.
            if let Ok(Some(_)) = child.0.try_wait() {
                assert!(
                    attempts < 3 && log.contains("could not open the viewer's window"),
                    "the viewer exited ({attempts} attempts); its log: {log}"
                );
                std::thread::sleep(Duration::from_secs(1));
                child = spawn();
                attempts += 1;
            }
            assert!(
                start.elapsed() < Duration::from_secs(90),
                "no viewer window after 90 s; its log: {log}"
            );
            std::thread::sleep(Duration::from_millis(100));
        };
        let v = Viewer {
            x,
            _child: child,
            window,
            state,
        };
        v.wait("the first frame", |s| {
            s["frames"].as_u64() >= Some(1) && s["image_rect"].is_array()
        });
        v
    }

    fn xdotool(&self, args: &[&str]) {
        let ok = Command::new(need("xdotool", "xdotool"))
            .args(args)
            .env("DISPLAY", &self.x.display)
            .status()
            .expect("run xdotool")
            .success();
        assert!(ok, "xdotool {args:?} failed");
    }

    /// Presses `key` (an X keysym name: KP_Add, 5, s) in the viewer's window.
    pub(crate) fn key(&self, key: &str) {
        self.xdotool(&["windowfocus", "--sync", &self.window]);
        self.xdotool(&["key", "--clearmodifiers", key]);
    }

    /// Clicks at (`x`, `y`) of the window.
    fn click(&self, x: u32, y: u32) {
        let (x, y) = (x.to_string(), y.to_string());
        self.xdotool(&["mousemove", "--window", &self.window, &x, &y]);
        std::thread::sleep(Duration::from_millis(100));
        self.xdotool(&["click", "1"]);
    }

    /// The state once `ready` holds (and the frame shown has caught up with the parameters).
    pub(crate) fn wait(
        &self,
        what: &str,
        ready: impl Fn(&serde_json::Value) -> bool,
    ) -> serde_json::Value {
        let start = Instant::now();
        loop {
            if let Some(s) = json(&self.state)
                && s["shown_output"] == s["output"]
                && ready(&s)
            {
                // The readouts belong to the frame on screen; give the window a moment to
                // draw it.
                std::thread::sleep(Duration::from_millis(300));
                return json(&self.state).unwrap_or(s);
            }
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "waited 60 s for {what}; state: {:?}",
                std::fs::read_to_string(&self.state)
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// A screenshot of the window (xwd), cut to the picture's rectangle.
    pub(crate) fn picture(&self, state: &serde_json::Value) -> image::RgbImage {
        let out = Command::new(need("xwd", "x11-apps"))
            .args(["-silent", "-id", &self.window])
            .env("DISPLAY", &self.x.display)
            .output()
            .expect("run xwd");
        assert!(out.status.success(), "xwd failed");
        let shot = parse_xwd(&out.stdout);
        let r: Vec<u32> = state["image_rect"]
            .as_array()
            .expect("image_rect")
            .iter()
            .map(|v| v.as_f64().expect("number").round() as u32)
            .collect();
        image::imageops::crop_imm(&shot, r[0], r[1], r[2] - r[0], r[3] - r[1]).to_image()
    }
}

/// An X window dump (the XWD format xwd writes: a big-endian header, the window name, a color
/// map, then ZPixmap rows) as RGB.
pub(crate) fn parse_xwd(b: &[u8]) -> image::RgbImage {
    let u = |i: usize| u32::from_be_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
    let (header, width, height) = (u(0) as usize, u(4), u(5));
    let (byte_order, bpp, stride) = (u(7), u(11) as usize, u(12) as usize);
    let masks = [u(14), u(15), u(16)];
    let ncolors = u(19) as usize;
    assert_eq!(
        bpp, 32,
        "xwd: expected 32 bits per pixel (a 24-bit Xvfb screen)"
    );
    let data = &b[header + ncolors * 12..];
    image::RgbImage::from_fn(width, height, |x, y| {
        let i = y as usize * stride + x as usize * 4;
        let p: [u8; 4] = data[i..i + 4].try_into().unwrap();
        let v = if byte_order == 0 {
            u32::from_le_bytes(p)
        } else {
            u32::from_be_bytes(p)
        };
        image::Rgb(masks.map(|m| ((v & m) >> m.trailing_zeros()) as u8))
    })
}

/// Mean x of the pixels whose channel `c` differs from the background's by more than 12.
pub(crate) fn centroid_x(img: &image::RgbImage, c: usize, background: u8) -> f64 {
    let (mut sum, mut n) = (0.0, 0.0);
    for (x, _, p) in img.enumerate_pixels() {
        if p.0[c].abs_diff(background) > 12 {
            sum += f64::from(x);
            n += 1.0;
        }
    }
    assert!(n > 50.0, "too few model pixels in channel {c}: {n}");
    sum / n
}

/// The horizontal shift between the gray anaglyph's red image (left eye) and cyan image
/// (right eye), in screen pixels: the parallax the viewer shows.
fn anaglyph_shift(img: &image::RgbImage) -> f64 {
    // The background is mid-gray (0.5) in both eyes.
    let bg = img.get_pixel(2, 2).0;
    centroid_x(img, 1, bg[1]) - centroid_x(img, 0, bg[0])
}

#[test]
fn viewer_under_xvfb_keys_mouse_and_screenshots() {
    let x = start_xvfb();
    let out = out_dir("viewer");
    let scene = asset("scenes/wuson.toml");
    let v = Viewer::start(
        &x,
        &out,
        &[
            scene.to_str().unwrap(),
            "--size",
            "320x240",
            "--output",
            "anaglyph_gray",
            // The zero-parallax plane in front of the model: all of it behind the screen,
            // so the red and cyan images lie visibly apart.
            "--set",
            "stereo.zero_parallax=3.2",
            // ChromaDepth's D1/D2 close around the model (what the sliders set), so its
            // ramp spans red to blue; F fits them to the bounding sphere instead.
            "--set",
            "chromadepth.d1=4.3",
            "--set",
            "chromadepth.d2=5.0",
        ],
    );

    // 1. The separation key widens the parallax between the red and cyan images.
    let s0 = v.wait("the anaglyph", |s| s["output"] == "anaglyph_gray");
    assert_eq!(
        s0["passes"],
        serde_json::json!(["Left Color", "Right Color"])
    );
    let pic0 = v.picture(&s0);
    pic0.save(out.join("anaglyph_before.png")).unwrap();
    let shift0 = anaglyph_shift(&pic0);
    for _ in 0..5 {
        v.key("KP_Add");
    }
    let s1 = v.wait("user offset × 1.1⁵", |s| {
        s["user_offset"].as_f64().is_some_and(|u| u > 1.6)
    });
    let pic1 = v.picture(&s1);
    pic1.save(out.join("anaglyph_after.png")).unwrap();
    let shift1 = anaglyph_shift(&pic1);
    let expected = shift0 * (1.1f64.powi(5) - 1.0);
    assert!(
        shift0 > 3.0 && shift1 - shift0 > 0.6 * expected,
        "five presses of keypad + (separation × 1.61) should widen the red/cyan shift of \
         {shift0:.2} px by about {expected:.2} px; measured {shift1:.2} px"
    );
    let max_px = |s: &serde_json::Value| s["parallax_max_px"].as_f64().unwrap();
    assert!(max_px(&s1) > max_px(&s0) * 1.5, "{s0} {s1}");
    // The growing separation takes the model's parallax past the ±3% budget.
    assert_eq!(s0["beyond_budget"], false, "{s0}");
    assert_eq!(s1["beyond_budget"], true, "{s1}");

    // 2. ChromaDepth (key 5): the red-to-blue ramp, from one center pass (no eye passes).
    v.key("5");
    let s2 = v.wait("ChromaDepth", |s| s["output"] == "chromadepth");
    assert_eq!(s2["passes"], serde_json::json!(["Center ChromaDepth"]));
    // The title names the scene and the output.
    let name = Command::new(need("xdotool", "xdotool"))
        .args(["getwindowname", &v.window])
        .env("DISPLAY", &x.display)
        .output()
        .expect("run xdotool");
    let name = String::from_utf8_lossy(&name.stdout);
    assert!(
        name.contains("wuson.toml") && name.contains("chromadepth"),
        "title: {name}"
    );
    let pic2 = v.picture(&s2);
    pic2.save(out.join("chromadepth.png")).unwrap();
    let is_red = |[r, g, b]: [u8; 3]| r > 150 && g < 110 && b < 110;
    let is_green = |[r, g, b]: [u8; 3]| g > 150 && r < 130 && b < 130;
    let is_blue = |[r, g, b]: [u8; 3]| b > 150 && r < 110 && g < 130;
    // Count and mean x of the pixels of one hue.
    let hue = |img: &image::RgbImage, f: &dyn Fn([u8; 3]) -> bool| {
        let xs: Vec<u32> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| f(p.0))
            .map(|(x, _, _)| x)
            .collect();
        let mean = xs.iter().map(|&x| f64::from(x)).sum::<f64>() / xs.len().max(1) as f64;
        (xs.len(), mean)
    };
    let ((red, red_x), (green, _), (blue, blue_x)) = (
        hue(&pic2, &is_red),
        hue(&pic2, &is_green),
        hue(&pic2, &is_blue),
    );
    assert!(
        red > 300 && green > 300 && blue > 100,
        "the ChromaDepth ramp should show red, green and blue: {red} red, {green} green, \
         {blue} blue pixels (chromadepth.png)"
    );
    // The camera looks at the model's rear (near, left) and its head (far, right): red in
    // front, blue behind, as ChromaDepth glasses need.
    assert!(
        red_x + 40.0 < blue_x,
        "red at x {red_x:.0}, blue at x {blue_x:.0}"
    );
    // F: D1/D2 fitted to the bounding sphere, whose middle the model fills: hardly any red.
    let frames = s2["frames"].as_u64().unwrap();
    v.key("f");
    let s2f = v.wait("the fitted ramp", |s| s["frames"].as_u64() > Some(frames));
    let fitted = v.picture(&s2f);
    fitted.save(out.join("chromadepth_fitted.png")).unwrap();
    let (red_fitted, _) = hue(&fitted, &is_red);
    assert!(
        red_fitted * 10 < red,
        "{red_fitted} red pixels after F, {red} before"
    );

    // 3. A click on the model (side by side, key 1) moves zero parallax to it.
    v.key("1");
    let s3 = v.wait("side by side", |s| s["output"] == "side_by_side");
    assert!(
        s3["parallax_min_px"].as_f64().unwrap() > 0.0,
        "with z0 = 3.2 the whole model lies behind the screen: {s3}"
    );
    let pic3 = v.picture(&s3);
    let bg = pic3.get_pixel(2, 2).0;
    let half = pic3.width() / 2;
    // The model pixel nearest the middle of the left image's model pixels.
    let model: Vec<(u32, u32)> = pic3
        .enumerate_pixels()
        .filter(|(x, _, p)| *x < half && p.0.iter().zip(bg).any(|(a, b)| a.abs_diff(b) > 40))
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(model.len() > 100, "no model in the left image");
    let (mx, my) = model.iter().fold((0u64, 0u64), |(a, b), &(x, y)| {
        (a + u64::from(x), b + u64::from(y))
    });
    let c = (mx / model.len() as u64, my / model.len() as u64);
    let &(px, py) = model
        .iter()
        .min_by_key(|&&(x, y)| {
            (u64::from(x).abs_diff(c.0)).pow(2) + (u64::from(y).abs_diff(c.1)).pow(2)
        })
        .unwrap();
    let r = &s3["image_rect"];
    let (wx, wy) = (
        r[0].as_f64().unwrap().round() as u32 + px,
        r[1].as_f64().unwrap().round() as u32 + py,
    );
    v.click(wx, wy);
    let s4 = v.wait("zero parallax at the clicked point", |s| {
        s["picked_parallax_px"].is_number()
    });
    let picked = s4["picked_parallax_px"].as_f64().unwrap();
    let z0 = s4["zero_parallax"].as_f64().unwrap();
    assert!(
        picked.abs() < 0.05,
        "parallax at the clicked point: {picked} px, not 0"
    );
    assert!(
        z0 > 3.5 && z0 < 7.0,
        "z0 = {z0}: not the model's distance (about 4.9)"
    );
    assert!(
        s4["parallax_min_px"].as_f64().unwrap() < 0.0
            && s4["parallax_max_px"].as_f64().unwrap() > 0.0,
        "the model now straddles the screen: {s4}"
    );

    // 4. The screenshot key writes a PNG and a TOML that `stereolab render` reproduces.
    v.key("s");
    let s5 = v.wait("the screenshot", |s| {
        s["shots"].as_array().is_some_and(|a| !a.is_empty())
    });
    let png = PathBuf::from(s5["shots"][0].as_str().unwrap());
    let toml = png.with_extension("toml");
    assert!(toml.is_file(), "no {}", toml.display());
    let render_dir = out.join("rendered");
    let r = stereolab()
        .args(["render", "--allow-outside-paths", "--out"])
        .arg(&render_dir)
        .arg(&toml)
        .output()
        .expect("run stereolab render");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let again = std::fs::read(render_dir.join("side_by_side.png")).unwrap();
    assert!(
        again == std::fs::read(&png).unwrap(),
        "`stereolab render {}` does not reproduce {} byte for byte",
        toml.display(),
        png.display()
    );
    // And the PNG is what the window showed (the picture at 1:1).
    let shown = v.picture(&s5);
    let saved = image::open(&png).unwrap().to_rgb8();
    assert_eq!(shown.dimensions(), saved.dimensions());
    let diff: u64 = shown
        .as_raw()
        .iter()
        .zip(saved.as_raw())
        .map(|(a, b)| u64::from(a.abs_diff(*b)))
        .sum();
    let mean = diff as f64 / shown.as_raw().len() as f64;
    assert!(
        mean < 2.0,
        "the window differs from the screenshot PNG by {mean:.2} per channel"
    );

    // 5. A live SIRDS (key 7) from one depth-only center pass, the model turning (T).
    v.key("7");
    let s6 = v.wait("the SIRDS", |s| s["output"] == "sirds");
    assert_eq!(s6["passes"], serde_json::json!(["Center DepthOnly"]));
    let still = v.picture(&s6);
    v.key("t");
    let frames = s6["frames"].as_u64().unwrap();
    let s7 = v.wait("the model turning", |s| {
        s["turn_degrees"].as_f64().is_some_and(|t| t > 5.0)
            && s["frames"].as_u64() > Some(frames + 2)
    });
    let turned = v.picture(&s7);
    turned.save(out.join("sirds_turning.png")).unwrap();
    assert!(
        still != turned,
        "the SIRDS did not change while the model turned"
    );
    // T again stops it: the frames compared below (the GPU's against the CPU's) hold still.
    v.key("t");

    // 6. Toe-in (M) shows vertical parallax, which off-axis never has; L switches lighting.
    v.key("1");
    let s8 = v.wait("side by side again, the model still", |s| {
        s["output"] == "side_by_side" && s["turning"] == false
    });
    assert_eq!(s8["mode"], "off-axis");
    assert!(s8["vertical_percent"].as_f64().unwrap() < 1e-3, "{s8}");
    v.key("m");
    let s9 = v.wait("toe-in", |s| {
        s["mode"] == "toe-in" && s["frames"].as_u64() > s8["frames"].as_u64()
    });
    let vertical = s9["vertical_percent"].as_f64().unwrap();
    assert!(
        vertical > 0.01,
        "toe-in's vertical parallax: {vertical}% of the height"
    );
    v.key("l");
    let s10 = v.wait("cyclopic lighting", |s| s["lighting"] == "cyclopic");

    // 7. Balance by keypad (]): × 1.1 a press up to 1.1⁷ = 1.95; the eighth press would pass
    // the StereoGraphics guide's upper limit 2.0, so it changes nothing and the readout says so.
    for _ in 0..8 {
        v.key("bracketright");
    }
    let s11 = v.wait("balance at its limit", |s| s["limit"].is_string());
    let balance = s11["user_balance"].as_f64().unwrap();
    assert!(
        (balance - 1.1f64.powi(7)).abs() < 1e-4,
        "balance after eight presses: {balance}"
    );
    let limit = s11["limit"].as_str().unwrap();
    assert!(
        limit.contains("UserBalanceAdjustment") && limit.contains("2.0"),
        "{limit}"
    );
    v.key("bracketleft");
    v.wait("balance moving again", |s| {
        s["limit"].is_null() && s["user_balance"].as_f64().unwrap() < balance - 0.1
    });

    // 8. The GPU path (G), built with --features gpu; without it G says how to get it.
    gpu_path(&v, &s10);
}

/// G shows the wgpu frame beside the CPU's with `compare`'s numbers for the current frame.
#[cfg(feature = "gpu")]
fn gpu_path(v: &Viewer, before: &serde_json::Value) {
    v.key("g");
    let s = v.wait("the GPU frame beside", |s| {
        s["gpu_view"] == "beside"
            && (s["gpu"].is_object() || s["gpu_error"].is_string())
            && s["gpu_rect"].is_array()
    });
    if let Some(e) = s["gpu_error"].as_str() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI is set but the viewer's GPU path failed: {e}"
        );
        // Straight to the process's stderr: libtest would swallow eprintln! of a passing test.
        let _ = std::io::Write::write_all(
            &mut std::io::stderr(),
            format!("skipping the viewer's GPU path: {e}\n").as_bytes(),
        );
        return;
    }
    let g = &s["gpu"];
    assert_eq!(s["output"], "side_by_side", "{s}");
    let names: Vec<&str> = g["passes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["Left Color", "Right Color"], "{g}");
    // Parity on the viewer's frame (toe-in, cyclopic lighting, zero parallax from the click):
    // the same pixels covered, colors within a step or so, depth bit for bit almost everywhere.
    for p in g["passes"].as_array().unwrap() {
        assert_eq!(p["coverage_mismatch"], 0, "{p}");
        assert!(p["max_channel_diff"].as_u64().unwrap() <= 8, "{p}");
        let psnr = &p["psnr"];
        assert!(
            psnr == "inf" || psnr.as_f64().is_some_and(|d| d > 40.0),
            "{p}"
        );
        let same = p["depth_identical"][0].as_f64().unwrap();
        let both = p["depth_identical"][1].as_f64().unwrap();
        assert!(both > 1000.0 && same >= 0.95 * both, "{p}");
    }
    assert_eq!(g["output"]["coverage_mismatch"], 0, "{g}");
    // The GPU image lies right of the CPU image and shows the same picture.
    let (cpu_rect, gpu_rect) = (&s["image_rect"], &s["gpu_rect"]);
    assert!(
        gpu_rect[0].as_f64() >= cpu_rect[2].as_f64(),
        "{cpu_rect} {gpu_rect}"
    );
    let cpu = v.picture(&s);
    let mut at_gpu = s.clone();
    at_gpu["image_rect"] = gpu_rect.clone();
    let gpu = v.picture(&at_gpu);
    gpu.save(v.out().join("gpu_beside.png")).unwrap();
    // The two rects are laid out in fractional points, so their pixel sizes may differ by one
    // (rounding); compare the common part.
    let (w, h) = (cpu.width().min(gpu.width()), cpu.height().min(gpu.height()));
    assert!(
        cpu.width().abs_diff(gpu.width()) <= 1 && cpu.height().abs_diff(gpu.height()) <= 1,
        "{:?} {:?}",
        cpu.dimensions(),
        gpu.dimensions()
    );
    let mut diff = 0u64;
    for y in 0..h {
        for x in 0..w {
            let (a, b) = (cpu.get_pixel(x, y).0, gpu.get_pixel(x, y).0);
            diff += a
                .iter()
                .zip(b)
                .map(|(a, b)| u64::from(a.abs_diff(b)))
                .sum::<u64>();
        }
    }
    let mean = diff as f64 / (u64::from(w) * u64::from(h) * 3) as f64;
    assert!(mean < 2.0, "the GPU image differs by {mean:.2} per channel");
    // G again: the GPU image alone, in the CPU image's place; then off.
    v.key("g");
    v.wait("the GPU frame alone", |s| {
        s["gpu_view"] == "only" && s["gpu_rect"].is_null() && s["gpu"].is_object()
    });
    v.key("g");
    let off = v.wait("the GPU path off", |s| s["gpu_view"] == "off");
    assert!(off["frames"].as_u64() > before["frames"].as_u64());
}

#[cfg(not(feature = "gpu"))]
fn gpu_path(v: &Viewer, _: &serde_json::Value) {
    v.key("g");
    let s = v.wait("the note on the GPU path", |s| {
        s["status"]
            .as_str()
            .is_some_and(|t| t.contains("--features gpu"))
    });
    assert_eq!(s["gpu_view"], "off", "{s}");
}

#[test]
fn viewer_without_a_display_names_display() {
    let out = stereolab()
        .args(["view"])
        .arg(asset("scenes/wuson.toml"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run stereolab view");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("DISPLAY"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn viewer_benchmark_runs_without_a_window() {
    let out = stereolab()
        .args(["view"])
        .arg(asset("scenes/wuson.toml"))
        .args([
            "--size",
            "96x64",
            "--output",
            "anaglyph_dubois",
            "--benchmark-frames",
            "4",
        ])
        .env_remove("DISPLAY")
        .output()
        .expect("run stereolab view --benchmark-frames");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("4 frames of an orbit"), "{text}");
    assert!(
        text.contains("pass Left Color") && text.contains("pass Right Color"),
        "{text}"
    );
    assert!(text.contains("frames/s"), "{text}");
}
