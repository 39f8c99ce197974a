//! The window: controls on the left, the last finished frame in the middle, readouts on the
//! right; a worker thread renders the latest parameters.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

use eframe::egui;
use glam::Vec3;

use super::ViewOptions;
use super::frame::{Shown, display_image, render_shown};
use super::session::{
    KEYPAD_FACTOR, MODES, Params, Session, Step, USER_FACTOR_MAX, UserFactor, lighting_name,
    mode_name, next_mode,
};
use stereolab::plan::Output;
use stereolab::scene::Scene;
use stereolab_core::{
    Error, Lighting, PARALLAX_BUDGET_PERCENT, Result, Separation, SirdsAlgorithm, StripFilter,
    StripStart, ZeroParallax,
};

/// The keys, as the help overlay lists them.
const KEYS: &[(&str, &str)] = &[
    ("drag", "orbit the camera about its target"),
    ("right-drag / shift-drag", "pan"),
    ("wheel", "zoom"),
    ("click", "zero parallax at the point clicked (its depth)"),
    ("R", "reset camera and rig"),
    (
        "keypad + / =",
        "separation × 1.1 (UserOffsetAdjustment, guide §7)",
    ),
    ("keypad − / -", "separation ÷ 1.1"),
    (
        "] / [",
        "balance × 1.1 / ÷ 1.1 (UserBalanceAdjustment); both factors stop below the guide's 2.0",
    ),
    ("M", "rig mode: the next of off-axis, toe-in, parallel"),
    ("L", "lighting: per-eye or cyclopic"),
    ("PageDown / PageUp", "next / previous output"),
    (
        "1 … 9, 0",
        "side_by_side, anaglyph_dubois, anaglyph_color, parallax, chromadepth, chromadepth_anaglyph, sirds, occlusion, left, cross_eyed",
    ),
    ("F", "ChromaDepth: fit D1/D2 to the bounding sphere"),
    ("T", "turn the model (SIRDS demonstration)"),
    ("N", "SIRDS: a new dot pattern every frame, or a fixed one"),
    ("S", "screenshot: PNG + scene TOML"),
    (
        "G",
        "GPU path (built with --features gpu): beside the CPU image, alone, off; compare's numbers",
    ),
    ("H / F1", "this help"),
    ("Q / Esc", "quit"),
];

/// The outputs the digit keys choose.
const FAVORITES: [&str; 10] = [
    "cross_eyed",
    "side_by_side",
    "anaglyph_dubois",
    "anaglyph_color",
    "parallax",
    "chromadepth",
    "chromadepth_anaglyph",
    "sirds",
    "occlusion",
    "left",
];

/// The GPU frame beside the CPU's (cargo feature `gpu`).
#[cfg(feature = "gpu")]
use super::gpu::GpuShown;

/// Without the `gpu` feature there is never a GPU frame.
#[cfg(not(feature = "gpu"))]
enum GpuShown {}

#[cfg(not(feature = "gpu"))]
impl GpuShown {
    fn lines(&self) -> Vec<String> {
        match *self {}
    }
}

/// Where the GPU path's image goes (the G key steps through them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum GpuView {
    /// Not rendered.
    Off,
    /// The GPU image to the right of the CPU image.
    Beside,
    /// The GPU image in place of the CPU image (clicks still pick in the CPU frame, which has
    /// the same geometry).
    Only,
}

impl GpuView {
    fn name(self) -> &'static str {
        match self {
            GpuView::Off => "off",
            GpuView::Beside => "beside",
            GpuView::Only => "only",
        }
    }
}

/// What the worker is asked to render: the parameters, the point last clicked, and whether
/// the GPU path renders too.
type Request = (Params, Option<Vec3>, bool);

/// A GPU frame and its texture pixels, or why there is none.
type GpuDelivered = std::result::Result<(Arc<GpuShown>, egui::ColorImage), String>;

/// What the worker hands back: the frame, its texture pixels (made on the worker, so the
/// window only moves them into its texture), and the GPU frame if one was asked for.
struct Delivered {
    shown: Arc<Shown>,
    pixels: egui::ColorImage,
    /// Time spent making `pixels`.
    pixels_time: std::time::Duration,
    gpu: Option<GpuDelivered>,
}

/// What the UI hands the worker, and what it gets back.
struct Shared {
    job: Mutex<Job>,
    wake: Condvar,
    done: Mutex<Option<std::result::Result<Delivered, String>>>,
}

#[derive(Default)]
struct Job {
    next: Option<Request>,
    quit: bool,
}

/// The window's options: its title, 1280×800, OpenGL (glow).
pub(super) fn native_options(title: String) -> eframe::NativeOptions {
    eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title(title)
            .with_inner_size([1280.0, 800.0]),
        renderer: eframe::Renderer::Glow,
        ..Default::default()
    }
}

/// A window that could not open, said with what to check.
pub(super) fn window_error(e: eframe::Error) -> Error {
    Error::invalid(
        "DISPLAY",
        std::env::var("DISPLAY").unwrap_or_default(),
        format!(
            "could not open the viewer's window: {e} (is the X server running, and does \
             Mesa's OpenGL driver exist: apt-get install libgl1-mesa-dri libegl1)"
        ),
    )
}

pub(super) fn run(scene: Scene, session: Session, opts: ViewOptions) -> Result<()> {
    let native = native_options(title(&session.path, session.initial.output));
    let shared = Arc::new(Shared {
        job: Mutex::new(Job::default()),
        wake: Condvar::new(),
        done: Mutex::new(None),
    });
    let result = eframe::run_native(
        "stereolab view",
        native,
        Box::new({
            let shared = Arc::clone(&shared);
            move |cc| {
                let aspect = scene.aspect();
                let worker = spawn_worker(
                    scene,
                    session.clone(),
                    Arc::clone(&shared),
                    cc.egui_ctx.clone(),
                );
                Ok(Box::new(App::new(aspect, session, opts, shared, worker)))
            }
        }),
    );
    {
        let mut job = lock(&shared.job);
        job.quit = true;
        shared.wake.notify_all();
    }
    result.map_err(window_error)
}

pub(super) fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn title(path: &Path, output: Output) -> String {
    format!("stereolab view — {} — {}", path.display(), output.name())
}

/// The worker: waits for parameters, renders the newest, hands the result over, repeats.
fn spawn_worker(
    mut scene: Scene,
    session: Session,
    shared: Arc<Shared>,
    ctx: egui::Context,
) -> std::thread::JoinHandle<()> {
    std::thread::spawn(move || {
        #[cfg(feature = "gpu")]
        let mut gpu: Option<std::result::Result<super::gpu::GpuPath, String>> = None;
        #[cfg(not(feature = "gpu"))]
        let mut gpu: Option<()> = None;
        loop {
            let (params, picked, want_gpu) = {
                let mut job = lock(&shared.job);
                loop {
                    if job.quit {
                        return;
                    }
                    if let Some(next) = job.next.take() {
                        break next;
                    }
                    job = shared.wake.wait(job).unwrap_or_else(|e| e.into_inner());
                }
            };
            session.apply(&params, &mut scene);
            let result = render_shown(&scene, &params, picked)
                .map(|shown| {
                    let start = Instant::now();
                    let pixels = display_image(&shown.image);
                    let pixels_time = start.elapsed();
                    let gpu = want_gpu
                        .then(|| gpu_frame(&mut gpu, &scene, &shown))
                        .flatten();
                    Delivered {
                        shown: Arc::new(shown),
                        pixels,
                        pixels_time,
                        gpu,
                    }
                })
                .map_err(|e| e.to_string());
            *lock(&shared.done) = Some(result);
            ctx.request_repaint();
        }
    })
}

/// The GPU frame of `shown`'s parameters (the device is opened at the first one).
#[cfg(feature = "gpu")]
fn gpu_frame(
    path: &mut Option<std::result::Result<super::gpu::GpuPath, String>>,
    scene: &Scene,
    shown: &Shown,
) -> Option<GpuDelivered> {
    let path = path.get_or_insert_with(|| super::gpu::GpuPath::new().map_err(|e| e.to_string()));
    Some(match path {
        Ok(p) => p
            .render(scene, shown)
            .map(|g| {
                let pixels = display_image(&g.image);
                (Arc::new(g), pixels)
            })
            .map_err(|e| e.to_string()),
        Err(e) => Err(e.clone()),
    })
}

/// Built without the `gpu` feature: no GPU frame.
#[cfg(not(feature = "gpu"))]
fn gpu_frame(_: &mut Option<()>, _: &Scene, _: &Shown) -> Option<GpuDelivered> {
    None
}

struct App {
    session: Session,
    opts: ViewOptions,
    shared: Arc<Shared>,
    _worker: std::thread::JoinHandle<()>,
    params: Params,
    sent: Option<Request>,
    picked: Option<Vec3>,
    shown: Option<Arc<Shown>>,
    texture: Option<egui::TextureHandle>,
    /// Where the GPU image goes (G).
    gpu_view: GpuView,
    /// The GPU frame delivered with `shown`, or why there is none.
    gpu: Option<std::result::Result<Arc<GpuShown>, String>>,
    gpu_texture: Option<egui::TextureHandle>,
    /// Where the GPU image lies in the window, in physical pixels (beside the CPU image).
    gpu_rect: Option<egui::Rect>,
    /// The last keypad press that could not move a user factor, and why.
    limit: Option<String>,
    /// The window's own time for its last frame (layout, texture upload, paint).
    window_time: Option<f32>,
    /// When the last frames arrived (frames on screen per second).
    arrivals: std::collections::VecDeque<Instant>,
    /// Time the worker spent making the last frame's texture pixels.
    pixels_time: std::time::Duration,
    image_rect: Option<egui::Rect>,
    error: Option<String>,
    status: String,
    help: bool,
    turning: bool,
    new_dots: bool,
    frames: u64,
    shots: Vec<PathBuf>,
    last_turn: Instant,
    /// The automatic separation at the start (the slider spans 0 to 4 times it).
    auto_separation: f32,
    /// The scene's width / height.
    aspect: f32,
    /// Physical pixels per egui point (`image_rect` is in physical pixels).
    pixels_per_point: f32,
}

impl App {
    fn new(
        aspect: f32,
        session: Session,
        opts: ViewOptions,
        shared: Arc<Shared>,
        worker: std::thread::JoinHandle<()>,
    ) -> App {
        let params = session.initial.clone();
        let auto_separation = {
            let mut rig = params.rig;
            rig.separation = Separation::Auto;
            rig.user_offset = 1.0;
            rig.resolve(&params.camera, aspect)
                .map_or(0.1, |r| r.eye_separation)
        };
        App {
            auto_separation,
            aspect,
            pixels_per_point: 1.0,
            session,
            opts,
            shared,
            _worker: worker,
            params,
            sent: None,
            picked: None,
            shown: None,
            texture: None,
            gpu_view: GpuView::Off,
            gpu: None,
            gpu_texture: None,
            gpu_rect: None,
            limit: None,
            window_time: None,
            arrivals: std::collections::VecDeque::new(),
            pixels_time: std::time::Duration::ZERO,
            image_rect: None,
            error: None,
            status: "H for help".into(),
            help: false,
            turning: false,
            new_dots: false,
            frames: 0,
            shots: Vec::new(),
            last_turn: Instant::now(),
        }
    }

    /// Hands the current parameters to the worker when they differ from the last sent.
    fn send(&mut self) {
        let job = (
            self.params.clone(),
            self.picked,
            self.gpu_view != GpuView::Off,
        );
        if self.sent.as_ref() != Some(&job) {
            let mut j = lock(&self.shared.job);
            j.next = Some(job.clone());
            self.shared.wake.notify_all();
            self.sent = Some(job);
        }
    }

    fn set_output(&mut self, ctx: &egui::Context, o: Output) {
        self.params.output = o;
        ctx.send_viewport_cmd(egui::ViewportCommand::Title(title(&self.session.path, o)));
    }

    fn keys(&mut self, ctx: &egui::Context) {
        use egui::Key;
        let pressed = |k: Key| ctx.input(|i| i.key_pressed(k));
        // Every press counts, also several within one frame.
        let presses = |k: Key| ctx.input(|i| i.num_presses(k));
        let steps = [
            (
                presses(Key::Plus) + presses(Key::Equals),
                UserFactor::Offset,
                KEYPAD_FACTOR,
            ),
            (presses(Key::Minus), UserFactor::Offset, 1.0 / KEYPAD_FACTOR),
            (
                presses(Key::CloseBracket),
                UserFactor::Balance,
                KEYPAD_FACTOR,
            ),
            (
                presses(Key::OpenBracket),
                UserFactor::Balance,
                1.0 / KEYPAD_FACTOR,
            ),
        ];
        let limit_before = self.limit.clone();
        for (n, which, by) in steps {
            for _ in 0..n {
                let step = self.params.step_user_factor(which, by);
                self.keypad_step(which, step);
            }
        }
        if self.limit != limit_before {
            // A press at the limit renders no new frame: the readout changes all the same.
            self.write_state();
        }
        if pressed(Key::M) {
            self.params.rig.mode = next_mode(self.params.rig.mode);
        }
        if pressed(Key::G) {
            self.toggle_gpu();
        }
        if pressed(Key::L) {
            self.params.rig.lighting = match self.params.rig.lighting {
                Lighting::PerEye => Lighting::Cyclopic,
                Lighting::Cyclopic => Lighting::PerEye,
            };
        }
        if pressed(Key::R) {
            let output = self.params.output;
            self.params = self.session.initial.clone();
            self.params.output = output;
            self.picked = None;
        }
        let all = Output::ALL;
        let at = all
            .iter()
            .position(|&o| o == self.params.output)
            .unwrap_or(0);
        if pressed(Key::PageDown) {
            self.set_output(ctx, all[(at + 1) % all.len()]);
        }
        if pressed(Key::PageUp) {
            self.set_output(ctx, all[(at + all.len() - 1) % all.len()]);
        }
        let digits = [
            Key::Num0,
            Key::Num1,
            Key::Num2,
            Key::Num3,
            Key::Num4,
            Key::Num5,
            Key::Num6,
            Key::Num7,
            Key::Num8,
            Key::Num9,
        ];
        for (k, name) in digits.into_iter().zip(FAVORITES) {
            if pressed(k)
                && let Ok(o) = Output::parse(name)
            {
                self.set_output(ctx, o);
            }
        }
        if pressed(Key::F) {
            self.params.chromadepth_d = [None, None];
        }
        if pressed(Key::T) {
            self.turning = !self.turning;
            self.last_turn = Instant::now();
        }
        if pressed(Key::N) {
            self.new_dots = !self.new_dots;
        }
        if pressed(Key::H) || pressed(Key::F1) {
            self.help = !self.help;
        }
        if pressed(Key::S) {
            self.status = match self.screenshot() {
                Ok(s) => s,
                Err(e) => format!("screenshot failed: {e}"),
            };
            println!("{}", self.status);
            self.write_state();
        }
        if pressed(Key::Q) || pressed(Key::Escape) {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    /// Says what a keypad press did: a press that stopped at a limit is shown until the next
    /// press that moves a factor.
    fn keypad_step(&mut self, which: UserFactor, step: Step) {
        let (guide, field) = which.names();
        match step {
            Step::Moved(_) => self.limit = None,
            Step::AtLimit(at, would) => {
                self.limit = Some(format!(
                    "{guide} stays at {at:.3}: ×1.1 would make it {would:.3}, past the guide's \
                     upper limit {USER_FACTOR_MAX:.1} ({field} must lie in 0..2)"
                ));
            }
            Step::AtZero => {
                self.limit = Some(format!(
                    "{guide} is 0: the keypad multiplies, so it cannot leave 0; move the slider"
                ));
            }
        }
        if let Some(l) = &self.limit {
            self.status.clone_from(l);
        }
    }

    /// G: the GPU image beside the CPU image, alone, or off. Built without the `gpu`
    /// feature, says how to get it.
    fn toggle_gpu(&mut self) {
        if cfg!(feature = "gpu") {
            self.gpu_view = match self.gpu_view {
                GpuView::Off => GpuView::Beside,
                GpuView::Beside => GpuView::Only,
                GpuView::Only => GpuView::Off,
            };
            self.status = format!("GPU path: {}", self.gpu_view.name());
        } else {
            self.status = "the GPU path needs a build with it: cargo run --release \
                           --features gpu -- view SCENE"
                .into();
        }
        self.write_state();
    }

    /// Writes the frame on screen as `NAME-NNN.png` and its scene as `NAME-NNN.toml`.
    fn screenshot(&mut self) -> Result<String> {
        let shown = self
            .shown
            .clone()
            .ok_or_else(|| Error::invalid("screenshot", "no frame", "wait for the first frame"))?;
        let scene_dir = self
            .session
            .path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf();
        let dir = self.opts.shots.clone().unwrap_or(scene_dir);
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        let stem = self
            .session
            .path
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        let base = (1..10_000)
            .map(|n| dir.join(format!("{stem}-view-{n:03}")))
            .find(|b| !b.with_extension("png").exists() && !b.with_extension("toml").exists())
            .ok_or_else(|| Error::invalid("screenshot", dir.display(), "10 000 shots already"))?;
        let (png, toml) = (base.with_extension("png"), base.with_extension("toml"));
        let text = self.session.scene_toml(&shown.params, &dir)?;
        // The picture and the scene that remakes it: both written, or neither.
        let mut set = stereolab_core::OutputSet::new();
        set.stage_bytes(&toml, text.as_bytes())?;
        shown.image.stage(&mut set, &png)?;
        set.commit()?;
        self.shots.push(png.clone());
        let outside = text.contains("path = \"/") || text.contains("pattern_image = \"/");
        Ok(format!(
            "screenshot: wrote {} and {}; `stereolab render{} {} --out DIR` writes DIR/{}.png, the same bytes",
            png.display(),
            toml.display(),
            if outside {
                " --allow-outside-paths"
            } else {
                ""
            },
            toml.display(),
            shown.params.output.name()
        ))
    }

    /// Takes a finished frame from the worker, if one is ready.
    fn receive(&mut self, ctx: &egui::Context) {
        let Some(done) = lock(&self.shared.done).take() else {
            return;
        };
        match done {
            Ok(Delivered {
                shown,
                pixels,
                pixels_time,
                gpu,
            }) => {
                set_texture(ctx, &mut self.texture, "frame", pixels);
                self.gpu = gpu.map(|g| {
                    g.map(|(g, pixels)| {
                        set_texture(ctx, &mut self.gpu_texture, "gpu frame", pixels);
                        g
                    })
                });
                self.pixels_time = pixels_time;
                let now = Instant::now();
                self.arrivals.push_back(now);
                while self
                    .arrivals
                    .front()
                    .is_some_and(|t| now.duration_since(*t).as_secs_f32() > 1.0)
                {
                    self.arrivals.pop_front();
                }
                self.shown = Some(shown);
                self.error = None;
                self.frames += 1;
                if self.new_dots {
                    self.params.sirds_seed = self.params.sirds_seed.wrapping_add(1) % (1 << 62);
                }
            }
            Err(e) => self.error = Some(e),
        }
        self.write_state();
    }

    /// Frames that reached the window in the last second.
    fn frames_per_second(&self) -> usize {
        self.arrivals
            .iter()
            .filter(|t| t.elapsed().as_secs_f32() <= 1.0)
            .count()
    }

    /// The readouts as one JSON object (the `--state-file`).
    fn write_state(&self) {
        let Some(path) = &self.opts.state_file else {
            return;
        };
        let p = &self.params;
        let mut v = serde_json::json!({
            "source": "scene",
            "frames": self.frames,
            "output": p.output.name(),
            "mode": mode_name(p.rig.mode),
            "lighting": lighting_name(p.rig.lighting),
            "user_offset": p.rig.user_offset,
            "user_balance": p.rig.user_balance,
            "turn_degrees": p.turn_degrees,
            "turning": self.turning,
            "error": self.error,
            "status": self.status,
            "shots": self.shots.iter().map(|s| s.display().to_string()).collect::<Vec<_>>(),
            "pixels_per_point": self.pixels_per_point,
            "limit": self.limit,
            "gpu_view": self.gpu_view.name(),
            "window_ms": self.window_time.map(|t| f64::from(t) * 1e3),
            "frames_per_second": self.frames_per_second(),
        });
        if let Some(r) = self.gpu_rect {
            v["gpu_rect"] = serde_json::json!([r.min.x, r.min.y, r.max.x, r.max.y]);
        }
        match &self.gpu {
            Some(Err(e)) => v["gpu_error"] = e.clone().into(),
            Some(Ok(g)) => v["gpu"] = gpu_json(g),
            None => {}
        }
        if let Some(r) = self.image_rect {
            v["image_rect"] = serde_json::json!([r.min.x, r.min.y, r.max.x, r.max.y]);
        }
        if let Some(s) = &self.shown {
            let w = s.width as f32;
            v["shown_output"] = s.params.output.name().into();
            v["passes"] = s.passes.iter().map(|(n, _)| n.clone()).collect();
            v["frame_ms"] = (s.total.as_secs_f64() * 1e3).into();
            v["readouts_ms"] = (s.readouts.as_secs_f64() * 1e3).into();
            v["pixels_ms"] = (self.pixels_time.as_secs_f64() * 1e3).into();
            v["parallax_min_px"] = (s.range.min_percent * w / 100.0).into();
            v["parallax_max_px"] = (s.range.max_percent * w / 100.0).into();
            v["parallax_min_percent"] = s.range.min_percent.into();
            v["parallax_max_percent"] = s.range.max_percent.into();
            v["vertical_percent"] = s.range.max_vertical_percent.into();
            v["beyond_budget"] = beyond(s).into();
            v["window_violations"] = serde_json::json!(s.window_violations);
            v["picked_parallax_px"] = s.picked_parallax.into();
            v["zero_parallax"] = match s.params.rig.zero_parallax {
                ZeroParallax::Distance(z) => z.into(),
                ZeroParallax::Fraction(_) => serde_json::Value::Null,
            };
            v["image_size"] = serde_json::json!([s.image_width(), s.image_height()]);
        }
        let text = v.to_string();
        if let Err(e) = stereolab_core::write_bytes(path, text.as_bytes()) {
            eprintln!("state file: {e}");
        }
    }

    fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("Output");
        let current = self.params.output;
        let mut chosen = current;
        egui::ComboBox::from_id_salt("output")
            .selected_text(current.name())
            .show_ui(ui, |ui| {
                for &o in Output::ALL {
                    ui.selectable_value(&mut chosen, o, o.name());
                }
            });
        if chosen != current {
            self.set_output(ui.ctx(), chosen);
        }
        ui.checkbox(&mut self.params.linear_light, "anaglyph in linear light");
        ui.checkbox(&mut self.params.swap_eyes, "swap eyes");
        ui.checkbox(
            &mut self.params.anti_rivalry,
            "anaglyph anti-rivalry (Rendepth)",
        );
        ui.separator();
        ui.heading("Rig");
        let rig = &mut self.params.rig;
        ui.horizontal(|ui| {
            for &m in MODES {
                ui.radio_value(&mut rig.mode, m, mode_name(m));
            }
        });
        ui.horizontal(|ui| {
            for l in [Lighting::PerEye, Lighting::Cyclopic] {
                ui.radio_value(
                    &mut rig.lighting,
                    l,
                    format!("{} lighting", lighting_name(l)),
                );
            }
        });
        ui.add(
            egui::Slider::new(&mut rig.user_offset, 0.0..=2.0)
                .text("separation (user offset)")
                .logarithmic(false),
        );
        ui.add(egui::Slider::new(&mut rig.user_balance, 0.0..=2.0).text("balance"));
        // The separation itself (before the user offset): "auto" (the guide's 3.5% of the
        // view width at z0) until the slider moves it, then an absolute distance.
        let auto = self.auto_separation;
        let mut d = match rig.separation {
            Separation::Absolute(d) => d,
            Separation::Auto => rig
                .resolve(&self.params.camera, self.aspect)
                .map_or(auto, |r| r.eye_separation / rig.user_offset.max(1e-6)),
        };
        let label = match rig.separation {
            Separation::Auto => "eye separation (auto)",
            Separation::Absolute(_) => "eye separation",
        };
        if ui
            .add(egui::Slider::new(&mut d, 0.0..=4.0 * auto).text(label))
            .changed()
        {
            rig.separation = Separation::Absolute(d);
        }
        let cam = self.params.camera.clone();
        let (lo, hi) = (cam.near * 1.001, cam.far * 0.999);
        let mut z0 = match rig.zero_parallax {
            ZeroParallax::Distance(z) => z,
            ZeroParallax::Fraction(t) => cam.near + t * (cam.far - cam.near),
        };
        let before = z0;
        ui.add(
            egui::Slider::new(&mut z0, lo..=hi)
                .logarithmic(true)
                .text("zero parallax z0"),
        );
        if z0 != before {
            rig.zero_parallax = ZeroParallax::Distance(z0);
            self.picked = None;
        }
        if ui.button("reset camera and rig (R)").clicked() {
            let output = self.params.output;
            self.params = self.session.initial.clone();
            self.params.output = output;
            self.picked = None;
        }
        ui.separator();
        ui.heading("ChromaDepth");
        for (i, name) in ["D1 (red)", "D2 (blue)"].into_iter().enumerate() {
            let (n, f) = (self.params.camera.near, self.params.camera.far);
            let resolved = self
                .shown
                .as_ref()
                .and_then(|s| s.chromadepth_range())
                .map(|r| r[i]);
            let Some(mut v) = self.params.chromadepth_d[i].or(resolved) else {
                ui.label(format!("{name}: no range fits the scene"));
                continue;
            };
            let fitted = if self.params.chromadepth_d[i].is_none() {
                " (fitted)"
            } else {
                ""
            };
            if ui
                .add(
                    egui::Slider::new(&mut v, n..=f)
                        .logarithmic(true)
                        .text(format!("{name}{fitted}")),
                )
                .changed()
            {
                self.params.chromadepth_d[i] = Some(v);
            }
        }
        if ui.button("fit to bounding sphere (F)").clicked() {
            self.params.chromadepth_d = [None, None];
        }
        ui.separator();
        ui.heading("SIRDS");
        ui.horizontal(|ui| {
            ui.radio_value(
                &mut self.params.sirds_algorithm,
                SirdsAlgorithm::PerVertex,
                "per-vertex",
            );
            ui.radio_value(
                &mut self.params.sirds_algorithm,
                SirdsAlgorithm::PerPixel,
                "TIW",
            );
        });
        ui.horizontal(|ui| {
            ui.label("start");
            ui.radio_value(&mut self.params.sirds_start, StripStart::Left, "left");
            ui.radio_value(&mut self.params.sirds_start, StripStart::Center, "center");
        });
        ui.horizontal(|ui| {
            ui.label("filter");
            ui.radio_value(
                &mut self.params.sirds_filter,
                StripFilter::Nearest,
                "nearest",
            );
            ui.radio_value(
                &mut self.params.sirds_filter,
                StripFilter::Bilinear,
                "bilinear",
            );
        });
        ui.checkbox(&mut self.turning, "turn the model (T)");
        ui.checkbox(&mut self.new_dots, "new dots every frame (N)");
    }

    fn readouts(&self, ui: &mut egui::Ui) {
        ui.heading("Readouts");
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::from_rgb(255, 90, 90), e);
        }
        let Some(s) = &self.shown else {
            ui.label("rendering the first frame …");
            return;
        };
        let w = s.width as f32;
        let r = &s.range;
        ui.label(format!("output: {}", s.params.output.name()));
        ui.label(format!(
            "rig: {}, {} lighting",
            mode_name(s.params.rig.mode),
            lighting_name(s.params.rig.lighting)
        ));
        ui.label(format!(
            "user offset {:.3}, balance {:.3} (keypad ×/÷ 1.1, range 0..{USER_FACTOR_MAX})",
            s.params.rig.user_offset, s.params.rig.user_balance
        ));
        if let Some(l) = &self.limit {
            ui.colored_label(egui::Color32::from_rgb(255, 170, 60), l);
        }
        if let Ok(rig) = s.params.rig.resolve(&s.params.camera, s.aspect()) {
            ui.label(format!(
                "d = {:.4}, z0 = {:.3}",
                rig.eye_separation, rig.zero_parallax_distance
            ));
        }
        ui.separator();
        ui.label("parallax (vertices seen by both eyes):");
        if r.vertices == 0 {
            ui.label("  no vertex inside both frusta");
        } else {
            let text = format!(
                "{:+.1} .. {:+.1} px\n{:+.2}% .. {:+.2}% of width (budget ±{}%)",
                r.min_percent * w / 100.0,
                r.max_percent * w / 100.0,
                r.min_percent,
                r.max_percent,
                PARALLAX_BUDGET_PERCENT
            );
            if beyond(s) {
                ui.colored_label(
                    egui::Color32::from_rgb(255, 90, 90),
                    format!("{text}\nBEYOND THE ±{PARALLAX_BUDGET_PERCENT}% BUDGET"),
                );
            } else {
                ui.label(text);
            }
            if r.max_vertical_percent > 0.01 {
                ui.colored_label(
                    egui::Color32::from_rgb(255, 170, 60),
                    format!(
                        "vertical parallax {:.2}% of height (toe-in)",
                        r.max_vertical_percent
                    ),
                );
            }
        }
        if let Some(sides) = s.window_violations {
            let v = sides.iter().sum::<usize>();
            let text = format!(
                "window violations: {v} border px (left {}, right {}, top {}, bottom {})",
                sides[0], sides[1], sides[2], sides[3]
            );
            if v > 0 {
                ui.colored_label(egui::Color32::from_rgb(255, 170, 60), text);
            } else {
                ui.label(text);
            }
        }
        if let Some(p) = s.picked_parallax {
            ui.label(format!("clicked point: parallax {p:+.2} px"));
        }
        if let Some([d1, d2]) = s.chromadepth_range() {
            ui.label(format!("ChromaDepth D1 = {d1:.3}, D2 = {d2:.3}"));
        }
        ui.separator();
        ui.label(format!("passes run: {}", s.passes.len()));
        for line in s.timing_lines() {
            ui.monospace(line);
        }
        ui.monospace(format!(
            "texture pixels: {:.1} ms",
            self.pixels_time.as_secs_f64() * 1e3
        ));
        if let Some(t) = self.window_time {
            ui.monospace(format!("window (layout, upload, paint): {:.1} ms", t * 1e3));
        }
        ui.monospace(format!("frames on screen: {}/s", self.frames_per_second()));

        ui.separator();
        ui.label(&self.status);
    }
}

/// Hands `pixels` to the texture in `slot` (made on first use); the window uploads it when it
/// paints.
pub(super) fn set_texture(
    ctx: &egui::Context,
    slot: &mut Option<egui::TextureHandle>,
    name: &str,
    pixels: egui::ColorImage,
) {
    match slot {
        Some(t) => t.set(pixels, egui::TextureOptions::LINEAR),
        None => *slot = Some(ctx.load_texture(name, pixels, egui::TextureOptions::LINEAR)),
    }
}

/// The GPU readouts for the state file.
#[cfg(feature = "gpu")]
fn gpu_json(g: &GpuShown) -> serde_json::Value {
    use serde_json::json;
    // JSON has no infinity: identical images have PSNR "inf".
    let psnr = |x: f64| {
        if x.is_finite() {
            json!(x)
        } else {
            json!("inf")
        }
    };
    let metrics = |m: &stereolab::compare::Metrics| {
        json!({
            "coverage_mismatch": m.coverage_mismatch,
            "max_channel_diff": m.max_channel_diff,
            "psnr": psnr(m.psnr),
            "pixels": m.pixels,
        })
    };
    let (same, both) = g.depth_identical();
    json!({
        "adapter": g.adapter,
        "frame_ms": g.time.as_secs_f64() * 1e3,
        "coverage_mismatch": g.coverage_mismatch(),
        "depth_identical": [same, both],
        "passes": g.passes.iter().map(|p| {
            let mut v = metrics(&p.metrics);
            v["name"] = json!(p.name);
            v["depth_identical"] = json!([p.depth_identical.0, p.depth_identical.1]);
            v
        }).collect::<Vec<_>>(),
        "output": metrics(&g.output),
    })
}

#[cfg(not(feature = "gpu"))]
fn gpu_json(g: &GpuShown) -> serde_json::Value {
    match *g {}
}

/// Whether the frame's parallax leaves the StereoGraphics guide's ±3% budget.
fn beyond(s: &Shown) -> bool {
    s.range.vertices > 0
        && (s.range.min_percent < -PARALLAX_BUDGET_PERCENT
            || s.range.max_percent > PARALLAX_BUDGET_PERCENT)
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.window_time = frame.info().cpu_usage;
        self.receive(&ctx);
        self.keys(&ctx);
        if self.turning {
            let now = Instant::now();
            let dt = now.duration_since(self.last_turn).as_secs_f32();
            self.last_turn = now;
            self.params.turn_degrees = (self.params.turn_degrees + 30.0 * dt) % 360.0;
            ctx.request_repaint_after(std::time::Duration::from_millis(30));
        }
        egui::Panel::left("controls")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.controls(ui));
            });
        egui::Panel::right("readouts")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| self.readouts(ui));
            });
        egui::CentralPanel::default().show(ui, |ui| self.picture(ui));
        if self.help {
            egui::Window::new("Keys")
                .collapsible(false)
                .show(&ctx, |ui| {
                    egui::Grid::new("keys").striped(true).show(ui, |ui| {
                        for (k, what) in KEYS {
                            ui.monospace(*k);
                            ui.label(*what);
                            ui.end_row();
                        }
                    });
                });
        }
        self.send();
    }
}

impl App {
    /// The frame, scaled to fit (never up), with the mouse: orbit, pan, zoom, click. With the
    /// GPU path beside, both images share the width; alone, the GPU image takes the CPU
    /// image's place.
    fn picture(&mut self, ui: &mut egui::Ui) {
        let (Some(tex), Some(shown)) = (&self.texture, self.shown.clone()) else {
            ui.label("rendering …");
            return;
        };
        let gpu_tex = match (&self.gpu, &self.gpu_texture) {
            (Some(Ok(_)), Some(t)) => Some(t.id()),
            _ => None,
        };
        let beside = self.gpu_view == GpuView::Beside;
        let size = tex.size_vec2();
        let gap = 8.0;
        let avail = ui.available_size();
        let across = if beside { 2.0 * size.x + gap } else { size.x };
        let scale = (avail.x / across).min(avail.y / size.y).min(1.0);
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        let (rect, response, gpu_rect) = ui
            .horizontal_top(|ui| {
                ui.spacing_mut().item_spacing.x = gap;
                let (rect, response) =
                    ui.allocate_exact_size(size * scale, egui::Sense::click_and_drag());
                let shown_tex = match (self.gpu_view, gpu_tex) {
                    (GpuView::Only, Some(g)) => g,
                    _ => tex.id(),
                };
                ui.painter()
                    .image(shown_tex, rect, uv, egui::Color32::WHITE);
                let gpu_rect = beside.then(|| {
                    let (r, _) = ui.allocate_exact_size(size * scale, egui::Sense::hover());
                    match gpu_tex {
                        Some(g) => {
                            ui.painter().image(g, r, uv, egui::Color32::WHITE);
                        }
                        None => {
                            ui.painter()
                                .rect_filled(r, 0.0, egui::Color32::from_gray(40));
                        }
                    }
                    r
                });
                (rect, response, gpu_rect)
            })
            .inner;
        if self.gpu_view != GpuView::Off {
            // Which image is which, under the pictures (never over them: the test compares
            // the pictures' pixels).
            ui.label(match (self.gpu_view, gpu_tex) {
                (GpuView::Beside, _) => "left: CPU, right: GPU (wgpu)",
                (GpuView::Only, Some(_)) => "GPU (wgpu); clicks pick in the CPU frame",
                _ => "CPU (the GPU frame is not ready)",
            });
            ui.label("GPU path against the CPU, this frame (stereolab compare's numbers):");
            match &self.gpu {
                Some(Ok(g)) => {
                    for line in g.lines() {
                        ui.monospace(line);
                    }
                }
                Some(Err(e)) => {
                    ui.colored_label(egui::Color32::from_rgb(255, 90, 90), e);
                }
                None => {
                    ui.label("rendering on the GPU …");
                }
            }
        }
        let ppp = ui.ctx().pixels_per_point();
        let gpu_physical = gpu_rect.map(|r| {
            egui::Rect::from_min_max(
                (r.min.to_vec2() * ppp).to_pos2(),
                (r.max.to_vec2() * ppp).to_pos2(),
            )
        });
        if self.gpu_rect != gpu_physical {
            self.gpu_rect = gpu_physical;
            self.write_state();
        }
        self.pixels_per_point = ppp;
        let physical = egui::Rect::from_min_max(
            (rect.min.to_vec2() * ppp).to_pos2(),
            (rect.max.to_vec2() * ppp).to_pos2(),
        );
        if self.image_rect != Some(physical) {
            self.image_rect = Some(physical);
            self.write_state();
        }
        let shift = ui.input(|i| i.modifiers.shift);
        if response.dragged_by(egui::PointerButton::Secondary)
            || (shift && response.dragged_by(egui::PointerButton::Primary))
        {
            let d = response.drag_delta() / rect.height().max(1.0);
            self.params.pan(d.x, d.y);
        } else if response.dragged_by(egui::PointerButton::Primary) {
            let d = response.drag_delta();
            self.params.orbit(-d.x * 0.4, -d.y * 0.4);
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.params.zoom(0.9f32.powf(scroll / 50.0));
            }
        }
        if response.clicked()
            && let Some(pos) = response.interact_pointer_pos()
        {
            let rel = (pos - rect.min) / scale;
            let (x, y) = (rel.x.max(0.0) as u32, rel.y.max(0.0) as u32);
            self.status = match shown.pick(x, y) {
                Some(p) => match self.params.set_zero_parallax_at(p) {
                    Ok(z) => {
                        self.picked = Some(p);
                        format!("zero parallax at the clicked point: z0 = {z:.3}")
                    }
                    Err(e) => e.to_string(),
                },
                None => "no model under the cursor".into(),
            };
        }
    }
}
