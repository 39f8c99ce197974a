//! The window over a stereo pair ([`Pair`]): how it is shown and the image shift on the left,
//! the picture in the middle, the layout and the measured parallax on the right. The disparity
//! is measured once, on a worker thread (semi-global matching takes a while on a large pair);
//! every other picture is composed when a control changes ([`compose`]: milliseconds).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use eframe::egui;
use egui::Key;
use image::RgbaImage;
use stereolab::inspect::{self, Measured};
use stereolab_core::{AnaglyphKind, Error, PARALLAX_BUDGET_PERCENT, Result};

use super::ViewOptions;
use super::app::{lock, native_options, set_texture, window_error};
use super::pair::{
    Pair, PairMode, PairParams, compose, max_shift, measure, shift_to_median, shifted_percentiles,
};

/// The keys, as the help overlay lists them.
const KEYS: &[(&str, &str)] = &[
    (
        "Left / Right arrow",
        "image shift −1 / +1 px: the right view moves left / right against the left",
    ),
    ("R", "image shift 0 (the pair as read)"),
    (
        "Z",
        "the image shift that puts the measured median parallax on the screen",
    ),
    ("PageDown / PageUp", "next / previous way to show the pair"),
    (
        "1 … 4, 8, 9, 0",
        "side_by_side, anaglyph_dubois, anaglyph_color, disparity, right, left, cross_eyed",
    ),
    ("S", "screenshot: the picture shown, as PNG"),
    ("H / F1", "this help"),
    ("Q / Esc", "quit"),
];

/// The modes the digit keys choose: the scene viewer's keys where the mode is the same.
const FAVORITES: [(Key, PairMode); 7] = [
    (Key::Num1, PairMode::SideBySide),
    (Key::Num2, PairMode::Anaglyph(AnaglyphKind::DuboisRedCyan)),
    (Key::Num3, PairMode::Anaglyph(AnaglyphKind::Color)),
    (Key::Num4, PairMode::Disparity),
    (Key::Num8, PairMode::Right),
    (Key::Num9, PairMode::Left),
    (Key::Num0, PairMode::CrossEyed),
];

/// The measurement and the disparity map's picture, or why there is none.
type Measurement = std::result::Result<(Measured, RgbaImage), String>;

/// Opens the window on `pair`, first shown as `params` says, and runs until it is closed.
pub(super) fn run(pair: Pair, params: PairParams, opts: ViewOptions) -> Result<()> {
    let native = native_options(title(&pair, params.mode));
    let pair = Arc::new(pair);
    let slot: Arc<Mutex<Option<Measurement>>> = Arc::new(Mutex::new(None));
    eframe::run_native(
        "stereolab view",
        native,
        Box::new(move |cc| {
            spawn_measure(Arc::clone(&pair), Arc::clone(&slot), cc.egui_ctx.clone());
            Ok(Box::new(PairApp::new(pair, params, opts, slot)))
        }),
    )
    .map_err(window_error)
}

fn title(pair: &Pair, mode: PairMode) -> String {
    format!("stereolab view — {} — {}", pair.names(), mode.name())
}

/// The worker: measures the pair once (or takes the measurement handed over), leaves it in
/// `slot` and wakes the window.
fn spawn_measure(pair: Arc<Pair>, slot: Arc<Mutex<Option<Measurement>>>, ctx: egui::Context) {
    std::thread::spawn(move || {
        let result = measure(&pair.views, pair.measured.clone()).map_err(|e| e.to_string());
        *lock(&slot) = Some(result);
        ctx.request_repaint();
    });
}

struct PairApp {
    pair: Arc<Pair>,
    opts: ViewOptions,
    params: PairParams,
    /// Where the worker leaves the measurement.
    slot: Arc<Mutex<Option<Measurement>>>,
    /// The measurement, once it has arrived.
    measurement: Option<Measurement>,
    /// The parameters last composed (also when composing failed or waits for the map).
    composed: Option<PairParams>,
    /// The picture on screen and its parameters.
    shown: Option<(PairParams, RgbaImage)>,
    texture: Option<egui::TextureHandle>,
    /// Where the picture lies in the window, in physical pixels.
    image_rect: Option<egui::Rect>,
    /// Physical pixels per egui point.
    pixels_per_point: f32,
    /// Pictures composed and shown.
    frames: u64,
    shots: Vec<PathBuf>,
    error: Option<String>,
    status: String,
    help: bool,
}

impl PairApp {
    fn new(
        pair: Arc<Pair>,
        params: PairParams,
        opts: ViewOptions,
        slot: Arc<Mutex<Option<Measurement>>>,
    ) -> PairApp {
        PairApp {
            pair,
            opts,
            params,
            slot,
            measurement: None,
            composed: None,
            shown: None,
            texture: None,
            image_rect: None,
            pixels_per_point: 1.0,
            frames: 0,
            shots: Vec::new(),
            error: None,
            status: "H for help".into(),
            help: false,
        }
    }

    fn max_shift(&self) -> i32 {
        max_shift(self.pair.width())
    }

    fn set_mode(&mut self, ctx: &egui::Context, mode: PairMode) {
        self.params.mode = mode;
        ctx.send_viewport_cmd(egui::ViewportCommand::Title(title(&self.pair, mode)));
    }

    /// Sets the image shift, stopped at ±[`max_shift`] (the status says where it stopped).
    fn set_shift(&mut self, shift: i32) {
        let max = self.max_shift();
        self.params.shift = shift.clamp(-max, max);
        if shift != self.params.shift {
            self.status = format!(
                "the image shift stops at {:+} px: ⅛ of the width, the parallax inspect searches",
                self.params.shift
            );
        }
    }

    /// Takes the measurement from the worker, once it is there.
    fn receive(&mut self) {
        if self.measurement.is_some() {
            return;
        }
        let Some(m) = lock(&self.slot).take() else {
            return;
        };
        self.measurement = Some(m);
        if self.params.mode == PairMode::Disparity {
            // The map the disparity mode was waiting for.
            self.composed = None;
        }
        self.write_state();
    }

    /// The disparity map's picture, once measured.
    fn disparity_picture(&self) -> Option<&RgbaImage> {
        match &self.measurement {
            Some(Ok((_, picture))) => Some(picture),
            _ => None,
        }
    }

    fn measured(&self) -> Option<&Measured> {
        match &self.measurement {
            Some(Ok((m, _))) => Some(m),
            _ => None,
        }
    }

    /// Composes the picture when the parameters changed since the last one.
    fn compose(&mut self, ctx: &egui::Context) {
        if self.composed == Some(self.params) {
            return;
        }
        self.composed = Some(self.params);
        match compose(&self.pair.views, &self.params, self.disparity_picture()) {
            Ok(Some(image)) => {
                let pixels = egui::ColorImage::from_rgba_unmultiplied(
                    [image.width() as usize, image.height() as usize],
                    image.as_raw(),
                );
                set_texture(ctx, &mut self.texture, "pair", pixels);
                self.shown = Some((self.params, image));
                self.frames += 1;
                self.error = None;
            }
            // The disparity map is still being measured.
            Ok(None) => {}
            Err(e) => self.error = Some(e.to_string()),
        }
        self.write_state();
    }

    fn keys(&mut self, ctx: &egui::Context) {
        let pressed = |k: Key| ctx.input(|i| i.key_pressed(k));
        // Every press counts, also several within one frame.
        let presses = |k: Key| ctx.input(|i| i.num_presses(k)) as i32;
        let step = presses(Key::ArrowRight) - presses(Key::ArrowLeft);
        // A focused slider moves with the arrow keys itself.
        let focused = ctx.memory(|m| m.focused().is_some());
        if step != 0 && !focused {
            self.set_shift(self.params.shift + step);
        }
        if pressed(Key::R) {
            self.set_shift(0);
        }
        if pressed(Key::Z) {
            self.shift_to_median();
        }
        let all = PairMode::all();
        let at = all.iter().position(|&m| m == self.params.mode).unwrap_or(0);
        if pressed(Key::PageDown) {
            self.set_mode(ctx, all[(at + 1) % all.len()]);
        }
        if pressed(Key::PageUp) {
            self.set_mode(ctx, all[(at + all.len() - 1) % all.len()]);
        }
        for (k, mode) in FAVORITES {
            if pressed(k) {
                self.set_mode(ctx, mode);
            }
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

    /// Z: the shift that brings the measured median parallax to the screen.
    fn shift_to_median(&mut self) {
        match self.measured().and_then(shift_to_median) {
            Some(s) => {
                self.set_shift(s);
                self.status = format!("image shift {s:+} px: the median parallax on the screen");
            }
            None => self.status = "no measured parallax yet (or nothing matched)".into(),
        }
    }

    /// Writes the picture on screen as `NAME-view-NNN.png` (NAME: the first image's), in
    /// `--shots` or beside the image. A pair has no scene, so there is no TOML to write; the
    /// status line says how the picture was made.
    fn screenshot(&mut self) -> Result<String> {
        let (params, image) = self
            .shown
            .as_ref()
            .ok_or_else(|| Error::invalid("screenshot", "no picture", "wait for the first"))?;
        let first = &self.pair.images[0];
        let beside = first
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_path_buf();
        let dir = self.opts.shots.clone().unwrap_or(beside);
        std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
        let stem = first
            .file_stem()
            .map_or("pair".into(), |s| s.to_string_lossy().into_owned());
        let png = (1..10_000)
            .map(|n| dir.join(format!("{stem}-view-{n:03}.png")))
            .find(|p| !p.exists())
            .ok_or_else(|| Error::invalid("screenshot", dir.display(), "10 000 shots already"))?;
        let mut set = stereolab_core::OutputSet::new();
        set.stage_png(&png, image)?;
        set.commit()?;
        self.shots.push(png.clone());
        Ok(format!(
            "screenshot: wrote {} ({} of {}, layout {}, image shift {:+} px{})",
            png.display(),
            params.mode.name(),
            self.pair.names(),
            self.pair.views.layout.name(),
            params.shift,
            if params.swap_eyes {
                ", eyes swapped"
            } else {
                ""
            }
        ))
    }

    /// The readouts as one JSON object (the `--state-file`).
    fn write_state(&self) {
        let Some(path) = &self.opts.state_file else {
            return;
        };
        let p = &self.params;
        let views = &self.pair.views;
        let mut v = serde_json::json!({
            "source": "images",
            "images": self.pair.images.iter().map(|i| i.display().to_string()).collect::<Vec<_>>(),
            "layout": views.layout.name(),
            "evidence": views.evidence,
            "view_size": [views.left.width(), views.left.height()],
            "frames": self.frames,
            "output": p.mode.name(),
            "shift_px": p.shift,
            "shift_max_px": self.max_shift(),
            "swap_eyes": p.swap_eyes,
            "linear_light": p.linear_light,
            "anti_rivalry": p.anti_rivalry,
            "measuring": self.measurement.is_none(),
            "error": self.error,
            "status": self.status,
            "shots": self.shots.iter().map(|s| s.display().to_string()).collect::<Vec<_>>(),
            "pixels_per_point": self.pixels_per_point,
        });
        match &self.measurement {
            Some(Ok((m, _))) => {
                v["matched"] = m.matched.into();
                v["parallax_px"] = serde_json::json!(m.percentiles);
                v["parallax_shifted_px"] = serde_json::json!(shifted_percentiles(m, p.shift));
                v["median_shift_px"] = shift_to_median(m).into();
            }
            Some(Err(e)) => v["measure_error"] = e.clone().into(),
            None => {}
        }
        if let Some(r) = self.image_rect {
            v["image_rect"] = serde_json::json!([r.min.x, r.min.y, r.max.x, r.max.y]);
        }
        if let Some((params, image)) = &self.shown {
            v["shown_output"] = params.mode.name().into();
            v["shown_shift_px"] = params.shift.into();
            v["image_size"] = serde_json::json!([image.width(), image.height()]);
        }
        let text = v.to_string();
        if let Err(e) = stereolab_core::write_bytes(path, text.as_bytes()) {
            eprintln!("state file: {e}");
        }
    }

    fn controls(&mut self, ui: &mut egui::Ui) {
        ui.heading("Show");
        let current = self.params.mode;
        let mut chosen = current;
        egui::ComboBox::from_id_salt("mode")
            .selected_text(current.name())
            .show_ui(ui, |ui| {
                for m in PairMode::all() {
                    ui.selectable_value(&mut chosen, m, m.name());
                }
            });
        if chosen != current {
            self.set_mode(ui.ctx(), chosen);
        }
        ui.checkbox(&mut self.params.swap_eyes, "swap eyes");
        ui.checkbox(&mut self.params.linear_light, "anaglyph in linear light");
        ui.checkbox(
            &mut self.params.anti_rivalry,
            "anaglyph anti-rivalry (Rendepth)",
        );
        ui.separator();
        ui.heading("Image shift");
        let max = self.max_shift();
        let mut shift = self.params.shift;
        ui.add(egui::Slider::new(&mut shift, -max..=max).text("px (arrow keys)"));
        ui.horizontal(|ui| {
            if ui.button("−1").clicked() {
                shift -= 1;
            }
            if ui.button("0 (R)").clicked() {
                shift = 0;
            }
            if ui.button("+1").clicked() {
                shift += 1;
            }
        });
        if shift != self.params.shift {
            self.set_shift(shift);
        }
        if ui
            .add_enabled(
                self.measured().is_some(),
                egui::Button::new("median parallax to the screen (Z)"),
            )
            .clicked()
        {
            self.shift_to_median();
        }
        ui.label(
            "The shift is added to every parallax: + moves the scene back behind the screen, \
             − brings it forward. The views are cut to the columns they still share.",
        );
        ui.separator();
        ui.label(
            "A pair of images has no scene: the camera, the rig, ChromaDepth and SIRDS need \
             one (stereolab view SCENE).",
        );
    }

    fn readouts(&self, ui: &mut egui::Ui) {
        let views = &self.pair.views;
        ui.heading("Pair");
        ui.label(self.pair.names());
        ui.label(format!(
            "layout: {} ({})",
            views.layout.name(),
            views.evidence
        ));
        let (w, h) = views.left.dimensions();
        ui.label(format!(
            "views: {w}×{h} each{}",
            if views.layout.gray_views() {
                ", gray (each eye's filter channels)"
            } else {
                ""
            }
        ));
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::from_rgb(255, 90, 90), e);
        }
        ui.separator();
        ui.heading("Parallax (stereolab inspect)");
        match &self.measurement {
            None => {
                ui.horizontal(|ui| {
                    ui.spinner();
                    ui.label("measuring … (semi-global matching, once)");
                });
            }
            Some(Err(e)) => {
                ui.colored_label(egui::Color32::from_rgb(255, 90, 90), e);
            }
            Some(Ok((m, _))) => {
                for line in inspect::describe(m).lines() {
                    ui.label(line.trim());
                }
                if let Some([lo, mid, hi]) = shifted_percentiles(m, self.params.shift) {
                    // The shift cuts the views: the budget is of the width shown.
                    let width = f64::from(w - self.params.shift.unsigned_abs());
                    let pct = |p: f64| 100.0 * p / width;
                    let text = format!(
                        "with the image shift {:+} px: {lo:+.1} to {hi:+.1} px, median \
                         {mid:+.1} px ({:+.2}% to {:+.2}% of the width, budget ±{}%)",
                        self.params.shift,
                        pct(lo),
                        pct(hi),
                        PARALLAX_BUDGET_PERCENT
                    );
                    let budget = f64::from(PARALLAX_BUDGET_PERCENT);
                    if pct(lo) < -budget || pct(hi) > budget {
                        ui.colored_label(
                            egui::Color32::from_rgb(255, 90, 90),
                            format!("{text}\nBEYOND THE ±{PARALLAX_BUDGET_PERCENT}% BUDGET"),
                        );
                    } else {
                        ui.label(text);
                    }
                }
                ui.label("The disparity map is of the pair as read (no shift, no swap).");
            }
        }
        ui.separator();
        if let Some((params, image)) = &self.shown {
            ui.label(format!(
                "shown: {}, {}×{}, image shift {:+} px",
                params.mode.name(),
                image.width(),
                image.height(),
                params.shift
            ));
        }
        ui.label(&self.status);
    }

    /// The picture, scaled to fit (never up); "measuring" while the disparity map is not there.
    fn picture(&mut self, ui: &mut egui::Ui) {
        let waiting = self
            .shown
            .as_ref()
            .is_none_or(|(p, _)| p.mode != self.params.mode);
        let Some(tex) = self.texture.as_ref().filter(|_| !waiting) else {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(if self.params.mode == PairMode::Disparity {
                    "measuring the disparity …"
                } else {
                    "composing …"
                });
            });
            return;
        };
        let size = tex.size_vec2();
        let avail = ui.available_size();
        let scale = (avail.x / size.x).min(avail.y / size.y).min(1.0);
        let (rect, _) = ui.allocate_exact_size(size * scale, egui::Sense::hover());
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        ui.painter().image(tex.id(), rect, uv, egui::Color32::WHITE);
        let ppp = ui.ctx().pixels_per_point();
        self.pixels_per_point = ppp;
        let physical = egui::Rect::from_min_max(
            (rect.min.to_vec2() * ppp).to_pos2(),
            (rect.max.to_vec2() * ppp).to_pos2(),
        );
        if self.image_rect != Some(physical) {
            self.image_rect = Some(physical);
            self.write_state();
        }
    }
}

impl eframe::App for PairApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.receive();
        self.keys(&ctx);
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
        // After the controls, so a change shows in this frame.
        self.compose(&ctx);
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
    }
}
