//! What the viewer lets a student change ([`Params`]), how those changes reach a [`Scene`]
//! ([`Session::apply`]), and how they are written back as a scene file that `stereolab render`
//! turns into the same bytes ([`Session::scene_toml`]).
//!
//! The viewer never keeps a second copy of the scene's meaning: a parameter is either a field
//! of the library's own types (the [`Camera`], the [`StereoRig`], the effect settings) or a
//! `[[mesh]]` placement that [`stereolab::scene::model_matrix`] turns into the object's matrix,
//! exactly as the scene loader does. The scene file written for a screenshot is the original
//! file's TOML table with those same fields overwritten.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};

use stereolab::plan::Output;
use stereolab::scene::{Scene, model_matrix};
use stereolab_core::{
    Camera, CameraMode, Error, Lighting, Result, Separation, SirdsAlgorithm, SirdsPattern,
    StereoRig, StripFilter, StripStart, ZeroParallax, project_ndc,
};

/// The StereoGraphics guide's §7 keypad step: `UserOffsetAdjustment *= 1.1` per press ("based on
/// multiplication rather than addition"), the same for the balance.
pub const KEYPAD_FACTOR: f32 = 1.1;

/// The guide's range for both user factors (§7): 1.0 default, adjustable "downward towards
/// 0.0" and "upward (2.0 is usually OK as an upper limit)" for the offset, "2.0 is once again a
/// good upper limit" for the balance. The rig refuses factors outside `0..=2`
/// ([`StereoRig::resolve`]), so a keypad press that would pass 2 changes nothing and says so.
pub const USER_FACTOR_MAX: f32 = 2.0;

/// Everything the viewer can change; a frame is a pure function of the scene and these.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// The output shown.
    pub output: Output,
    /// The cyclopean camera (orbit, pan, zoom move `eye` and `target`).
    pub camera: Camera,
    /// The rig: mode, separation, zero parallax, user offset and balance, lighting.
    pub rig: StereoRig,
    /// `[chromadepth] d1`, `d2` (`None`: fitted to the bounding sphere, the ChromaDepth article).
    pub chromadepth_d: [Option<f32>; 2],
    /// `[finalize] linear_light`.
    pub linear_light: bool,
    /// `[finalize] swap_eyes`.
    pub swap_eyes: bool,
    /// `[finalize] anti_rivalry`.
    pub anti_rivalry: bool,
    /// `[sirds] algorithm`.
    pub sirds_algorithm: SirdsAlgorithm,
    /// `[sirds] start`.
    pub sirds_start: StripStart,
    /// `[sirds] filter`.
    pub sirds_filter: StripFilter,
    /// `[sirds] seed` (ignored for a pattern image).
    pub sirds_seed: u64,
    /// Degrees every mesh is turned about its Y axis, added to its `rotate[1]` (the SIRDS
    /// paper's rotating model).
    pub turn_degrees: f32,
}

/// A `[[mesh]]`'s placement as its scene file gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Placement {
    translate: [f32; 3],
    rotate: [f32; 3],
    scale: f32,
}

/// A scene opened in the viewer: the file's TOML table (with `--set` and `--size` applied) and
/// where it lives, the parameters it started with, and each mesh's placement.
#[derive(Clone, Debug)]
pub struct Session {
    /// The scene file.
    pub path: PathBuf,
    table: toml::Table,
    placements: Vec<Placement>,
    /// The parameters the scene file gives (what "reset" returns to).
    pub initial: Params,
}

impl Session {
    /// Opens `scene`, loaded from `path` with the `--set` overrides `sets` (and any `--size`,
    /// which `scene` already carries).
    ///
    /// # Errors
    /// The file cannot be read again, or a `--set` does not apply.
    pub fn new(scene: &Scene, path: &Path, sets: &[String]) -> Result<Session> {
        let text = stereolab_core::read_text(path, 16 * 1024 * 1024)?;
        let mut table: toml::Table =
            toml::from_str(&text).map_err(|e| Error::parse(path, None, e.message().to_string()))?;
        stereolab::scene::apply_sets(&mut table, sets)?;
        let mut image = toml::Table::new();
        if let Some(toml::Value::Table(t)) = table.get("image") {
            image = t.clone();
        }
        image.insert("width".into(), toml::Value::Integer(scene.width.into()));
        image.insert("height".into(), toml::Value::Integer(scene.height.into()));
        table.insert("image".into(), toml::Value::Table(image));
        let placements = match table.get("mesh") {
            Some(toml::Value::Array(meshes)) => meshes.iter().map(placement).collect(),
            _ => Vec::new(),
        };
        if placements.len() != scene.objects.len() {
            return Err(Error::internal(
                "viewer",
                format!(
                    "{} [[mesh]] tables for {} objects",
                    placements.len(),
                    scene.objects.len()
                ),
            ));
        }
        let output = scene.outputs.first().copied().unwrap_or(Output::SideBySide);
        let s = &scene.sirds;
        let initial = Params {
            output,
            camera: scene.camera.clone(),
            rig: scene.rig,
            chromadepth_d: [scene.chromadepth.d1, scene.chromadepth.d2],
            linear_light: scene.finalize.linear_light,
            swap_eyes: scene.finalize.swap_eyes,
            anti_rivalry: scene.finalize.anti_rivalry,
            sirds_algorithm: s.algorithm,
            sirds_start: s.per_vertex.start,
            sirds_filter: s.per_vertex.filter,
            sirds_seed: match s.pattern {
                SirdsPattern::BlackWhite { seed }
                | SirdsPattern::Gray { seed }
                | SirdsPattern::Color { seed } => seed,
                SirdsPattern::Image(_) | SirdsPattern::Textured(_) => 1,
            },
            turn_degrees: 0.0,
        };
        Ok(Session {
            path: path.to_path_buf(),
            table,
            placements,
            initial,
        })
    }

    /// Sets `scene` (the one the viewer was opened with, or one already changed by an
    /// earlier call) to `p`. Only fields change; the meshes stay where they are.
    pub fn apply(&self, p: &Params, scene: &mut Scene) {
        scene.outputs = vec![p.output];
        scene.camera = p.camera.clone();
        scene.rig = p.rig;
        scene.chromadepth.d1 = p.chromadepth_d[0];
        scene.chromadepth.d2 = p.chromadepth_d[1];
        scene.finalize.linear_light = p.linear_light;
        scene.finalize.swap_eyes = p.swap_eyes;
        scene.finalize.anti_rivalry = p.anti_rivalry;
        scene.sirds.algorithm = p.sirds_algorithm;
        scene.sirds.per_vertex.start = p.sirds_start;
        scene.sirds.per_vertex.filter = p.sirds_filter;
        if let SirdsPattern::BlackWhite { seed }
        | SirdsPattern::Gray { seed }
        | SirdsPattern::Color { seed } = &mut scene.sirds.pattern
        {
            *seed = p.sirds_seed;
        }
        for (o, m) in scene.objects.iter_mut().zip(&self.placements) {
            o.model = model_matrix(m.translate, turned(m.rotate, p.turn_degrees), m.scale);
        }
    }

    /// The scene file for `p`: the opened file's table with every viewer parameter written
    /// into its field. Relative paths (models, terrain, pattern image) are kept when the file
    /// is written into the scene's own folder (`dir`), and made absolute otherwise (then
    /// `stereolab render` needs `--allow-outside-paths` to read them).
    ///
    /// # Errors
    /// A model path that cannot be made absolute.
    pub fn scene_toml(&self, p: &Params, dir: &Path) -> Result<String> {
        use toml::Value;
        let mut t = self.table.clone();
        let num = |v: f32| Value::Float(readable(v));
        let vec3 = |v: [f32; 3]| Value::Array(v.iter().map(|&x| num(x)).collect());
        let word = |s: &str| Value::String(s.to_string());
        let mut set = |table: &str, key: &str, v: Option<Value>| {
            let entry = t
                .entry(table)
                .or_insert_with(|| Value::Table(toml::Table::new()));
            if let Value::Table(sub) = entry {
                match v {
                    Some(v) => sub.insert(key.into(), v),
                    None => sub.remove(key),
                };
            }
        };
        let c = &p.camera;
        set("camera", "eye", Some(vec3(c.eye)));
        set("camera", "target", Some(vec3(c.target)));
        set("camera", "up", Some(vec3(c.up)));
        set("camera", "fov_y", Some(num(c.fov_y)));
        set("camera", "near", Some(num(c.near)));
        set("camera", "far", Some(num(c.far)));
        let r = &p.rig;
        set("stereo", "mode", Some(word(&mode_name(r.mode))));
        set(
            "stereo",
            "eye_separation",
            Some(match r.separation {
                Separation::Auto => word("auto"),
                Separation::Absolute(d) => num(d),
            }),
        );
        let (z, zf) = match r.zero_parallax {
            ZeroParallax::Distance(z) => (Some(num(z)), None),
            ZeroParallax::Fraction(f) => (None, Some(num(f))),
        };
        set("stereo", "zero_parallax", z);
        set("stereo", "zero_parallax_fraction", zf);
        set("stereo", "user_offset", Some(num(r.user_offset)));
        set("stereo", "user_balance", Some(num(r.user_balance)));
        set("stereo", "lighting", Some(word(lighting_name(r.lighting))));
        set("chromadepth", "d1", p.chromadepth_d[0].map(num));
        set("chromadepth", "d2", p.chromadepth_d[1].map(num));
        set(
            "finalize",
            "linear_light",
            Some(Value::Boolean(p.linear_light)),
        );
        set("finalize", "swap_eyes", Some(Value::Boolean(p.swap_eyes)));
        set(
            "finalize",
            "anti_rivalry",
            Some(Value::Boolean(p.anti_rivalry)),
        );
        let algorithm = match p.sirds_algorithm {
            SirdsAlgorithm::PerVertex => "per-vertex",
            SirdsAlgorithm::PerPixel => "per-pixel",
        };
        set("sirds", "algorithm", Some(word(algorithm)));
        let start = match p.sirds_start {
            StripStart::Left => "left",
            StripStart::Center => "center",
        };
        set("sirds", "start", Some(word(start)));
        let filter = match p.sirds_filter {
            StripFilter::Nearest => "nearest",
            StripFilter::Bilinear => "bilinear",
        };
        set("sirds", "filter", Some(word(filter)));
        let seed = i64::try_from(p.sirds_seed)
            .map_err(|_| Error::invalid("sirds.seed", p.sirds_seed, "must fit in 63 bits"))?;
        set("sirds", "seed", Some(Value::Integer(seed)));
        t.insert("outputs".into(), Value::Array(vec![word(p.output.name())]));
        let base = self.path.parent().unwrap_or(Path::new(""));
        let same_folder = same_dir(base, dir);
        if let Some(Value::Array(meshes)) = t.get_mut("mesh") {
            for (m, place) in meshes.iter_mut().zip(&self.placements) {
                if let Value::Table(m) = m {
                    m.insert("rotate".into(), vec3(turned(place.rotate, p.turn_degrees)));
                    if !same_folder {
                        absolute_path(m, "path", base)?;
                    }
                }
            }
        }
        if !same_folder && let Some(Value::Table(s)) = t.get_mut("sirds") {
            absolute_path(s, "pattern_image", base)?;
        }
        let mut text = format!(
            "# Written by `stereolab view {}`: the scene as the viewer showed it.\n",
            self.path.display()
        );
        text.push_str(
            &toml::to_string(&t)
                .map_err(|e| Error::internal("viewer", format!("scene to TOML: {e}")))?,
        );
        Ok(text)
    }
}

/// `v` as the f64 a TOML reader turns back into `v` exactly (it reads an f64 and rounds it to
/// f32): the shortest decimal that names `v` (`4.6`, not `4.599999904632568`) where that
/// rounds back to `v`, else `v` itself widened.
fn readable(v: f32) -> f64 {
    match v.to_string().parse::<f64>() {
        Ok(short) if short as f32 == v => short,
        _ => f64::from(v),
    }
}

/// `rotate` with `degrees` added about Y.
fn turned(rotate: [f32; 3], degrees: f32) -> [f32; 3] {
    [rotate[0], rotate[1] + degrees, rotate[2]]
}

fn placement(v: &toml::Value) -> Placement {
    let f = |v: &toml::Value| match v {
        toml::Value::Float(f) => Some(*f as f32),
        toml::Value::Integer(i) => Some(*i as f32),
        _ => None,
    };
    let vec3 = |key: &str, default: [f32; 3]| {
        match v.get(key) {
            Some(toml::Value::Array(a)) if a.len() == 3 => {
                let xs: Vec<f32> = a.iter().filter_map(f).collect();
                <[f32; 3]>::try_from(xs).ok()
            }
            _ => None,
        }
        .unwrap_or(default)
    };
    Placement {
        translate: vec3("translate", [0.0; 3]),
        rotate: vec3("rotate", [0.0; 3]),
        scale: v.get("scale").and_then(f).unwrap_or(1.0),
    }
}

fn same_dir(a: &Path, b: &Path) -> bool {
    let dot = |p: &Path| {
        if p.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            p.to_path_buf()
        }
    };
    match (dot(a).canonicalize(), dot(b).canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

fn absolute_path(t: &mut toml::Table, key: &str, base: &Path) -> Result<()> {
    if let Some(toml::Value::String(p)) = t.get(key) {
        let joined = base.join(p);
        let abs = std::path::absolute(&joined).map_err(|e| Error::io(&joined, e))?;
        t.insert(
            key.into(),
            toml::Value::String(abs.to_string_lossy().into_owned()),
        );
    }
    Ok(())
}

/// The rig modes the viewer offers, in the order the M key steps through them.
///
/// To offer a new [`CameraMode`], add it here (and to `_every_mode_listed` below, which stops
/// compiling until a new variant is handled); the radio buttons, the M key and the scene file's
/// word ([`mode_name`], from the scene file's own serde name) follow from this list.
pub const MODES: &[CameraMode] = &[
    CameraMode::OffAxis,
    CameraMode::ToeIn,
    CameraMode::Parallel,
    CameraMode::ImageShift,
];

/// Fails to compile when `CameraMode` gains a variant: add the new mode to [`MODES`] too.
const fn _every_mode_listed(m: CameraMode) {
    match m {
        CameraMode::OffAxis | CameraMode::ToeIn | CameraMode::Parallel | CameraMode::ImageShift => {
        }
    }
}

/// The mode after `m` in [`MODES`] (the M key).
pub fn next_mode(m: CameraMode) -> CameraMode {
    let at = MODES.iter().position(|&x| x == m).unwrap_or(0);
    MODES[(at + 1) % MODES.len()]
}

/// The scene-file word for a camera mode (`stereo.mode`), as the scene file's reader spells it.
pub fn mode_name(m: CameraMode) -> String {
    match serde_json::to_value(m) {
        Ok(serde_json::Value::String(s)) => s,
        _ => format!("{m:?}"),
    }
}

/// The scene-file word for a lighting variant.
pub fn lighting_name(l: Lighting) -> &'static str {
    match l {
        Lighting::PerEye => "per-eye",
        Lighting::Cyclopic => "cyclopic",
    }
}

/// Which of the StereoGraphics guide's two user factors a keypad press changes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UserFactor {
    /// `UserOffsetAdjustment` (the separation).
    Offset,
    /// `UserBalanceAdjustment` (the frustum asymmetry).
    Balance,
}

impl UserFactor {
    /// The name the guide gives it, and the scene file's field.
    pub fn names(self) -> (&'static str, &'static str) {
        match self {
            UserFactor::Offset => ("UserOffsetAdjustment", "stereo.user_offset"),
            UserFactor::Balance => ("UserBalanceAdjustment", "stereo.user_balance"),
        }
    }
}

/// What one keypad press did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// The factor is now this value.
    Moved(f32),
    /// The press would have taken the factor from the first value to the second, past the
    /// guide's upper limit [`USER_FACTOR_MAX`]; the factor stays where it was.
    AtLimit(f32, f32),
    /// The factor is 0, which multiplying cannot leave (the guide's "no stereo effect at all"
    /// for the offset, "no frustum asymmetry" for the balance): the slider moves it.
    AtZero,
}

impl Params {
    /// One keypad press on a user factor: `factor` × `by` (the guide's §7: "adjusted based on
    /// multiplication (i.e.: UserOffsetAdjustment *= 1.1) rather than addition"), unless that
    /// passes the guide's upper limit 2.0 ("2.0 is usually OK as an upper limit"; for the
    /// balance "2.0 is once again a good upper limit"), which the rig refuses
    /// ([`StereoRig::resolve`]). Such a press changes nothing and says so ([`Step::AtLimit`]),
    /// so presses stay on the 1.1ⁿ ladder and as many ÷ presses as × presses return to the
    /// start. Downward the guide's range is "towards 0.0", which multiplying never reaches.
    pub fn step_user_factor(&mut self, which: UserFactor, by: f32) -> Step {
        let v = match which {
            UserFactor::Offset => &mut self.rig.user_offset,
            UserFactor::Balance => &mut self.rig.user_balance,
        };
        let next = *v * by;
        if *v == 0.0 {
            Step::AtZero
        } else if next > USER_FACTOR_MAX {
            Step::AtLimit(*v, next)
        } else {
            *v = next;
            Step::Moved(next)
        }
    }

    /// Multiplies the user offset (separation) by `factor` ([`Params::step_user_factor`]).
    pub fn scale_offset(&mut self, factor: f32) -> Step {
        self.step_user_factor(UserFactor::Offset, factor)
    }

    /// Multiplies the user balance by `factor` ([`Params::step_user_factor`]).
    pub fn scale_balance(&mut self, factor: f32) -> Step {
        self.step_user_factor(UserFactor::Balance, factor)
    }

    /// The camera's unit view direction, right and up vectors.
    fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let (eye, target) = (Vec3::from(self.camera.eye), Vec3::from(self.camera.target));
        let f = (target - eye).normalize_or(Vec3::NEG_Z);
        let r = f.cross(Vec3::from(self.camera.up)).normalize_or(Vec3::X);
        (f, r, r.cross(f))
    }

    /// Orbits the eye about the target: `yaw` degrees about the camera's up axis, `pitch`
    /// degrees about its right axis (kept 5° away from the poles, where look-at has no up).
    pub fn orbit(&mut self, yaw: f32, pitch: f32) {
        let (eye, target) = (Vec3::from(self.camera.eye), Vec3::from(self.camera.target));
        let up = Vec3::from(self.camera.up).normalize_or(Vec3::Y);
        let offset = eye - target;
        let yawed = glam::Quat::from_axis_angle(up, yaw.to_radians()) * offset;
        let elevation = yawed.normalize_or(Vec3::Z).dot(up).clamp(-1.0, 1.0).acos();
        let limit = 5f32.to_radians();
        let p = (-pitch.to_radians())
            .clamp(limit - elevation, std::f32::consts::PI - limit - elevation);
        let right = yawed.cross(up).normalize_or(Vec3::X);
        let pitched = glam::Quat::from_axis_angle(right, -p) * yawed;
        self.camera.eye = (target + pitched).to_array();
    }

    /// Moves eye and target together by `dx`, `dy` times the eye's distance to the target
    /// (right and up on screen).
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let (_, r, u) = self.basis();
        let dist = (Vec3::from(self.camera.eye) - Vec3::from(self.camera.target)).length();
        let shift = (r * -dx + u * dy) * dist;
        self.camera.eye = (Vec3::from(self.camera.eye) + shift).to_array();
        self.camera.target = (Vec3::from(self.camera.target) + shift).to_array();
    }

    /// Moves the eye towards the target (`factor` < 1) or away (> 1); the distance stays
    /// between 1.05 × near and 0.9 × far.
    pub fn zoom(&mut self, factor: f32) {
        let (eye, target) = (Vec3::from(self.camera.eye), Vec3::from(self.camera.target));
        let d = (eye - target).length();
        let new = (d * factor).clamp(self.camera.near * 1.05, self.camera.far * 0.9);
        if d > 0.0 {
            self.camera.eye = (target + (eye - target) * (new / d)).to_array();
        }
    }

    /// The distance along the view direction of world point `p` (the rig's zero-parallax
    /// distance is measured this way, as eye-space −z).
    pub fn view_distance(&self, p: Vec3) -> f32 {
        let (f, _, _) = self.basis();
        (p - Vec3::from(self.camera.eye)).dot(f)
    }

    /// Makes `p` the zero-parallax point: `zero_parallax = ` its distance along the view
    /// direction (the SGI notes' fusion distance, moved to what the viewer looks at).
    ///
    /// # Errors
    /// The point lies outside `near .. far`.
    pub fn set_zero_parallax_at(&mut self, p: Vec3) -> Result<f32> {
        let z = self.view_distance(p);
        if !(z > self.camera.near && z < self.camera.far) {
            return Err(Error::invalid(
                "stereo.zero_parallax",
                z,
                "the clicked point lies outside camera.near .. camera.far",
            ));
        }
        self.rig.zero_parallax = ZeroParallax::Distance(z);
        Ok(z)
    }
}

/// Horizontal screen parallax of world point `p` in pixels of a `width`-pixel image: where
/// the right eye sees it minus where the left eye does, `(x_r − x_l)/2 · W` in NDC; `None`
/// behind either eye.
pub fn point_parallax_pixels(
    eyes: &[stereolab_core::EyeMatrices; 2],
    p: Vec3,
    width: u32,
) -> Option<f32> {
    let l = project_ndc(&eyes[0].mvp, p)?;
    let r = project_ndc(&eyes[1].mvp, p)?;
    Some((r.x - l.x) * 0.5 * width as f32)
}

/// The world point a pixel of a framebuffer rendered with `mvp` shows: its center and its
/// window depth `depth` (0..1) taken back through `mvp⁻¹` (NDC z = 2·depth − 1, OpenGL).
pub fn unproject(mvp: &Mat4, x: u32, y: u32, depth: f32, width: u32, height: u32) -> Vec3 {
    let ndc = Vec3::new(
        2.0 * (x as f32 + 0.5) / width as f32 - 1.0,
        1.0 - 2.0 * (y as f32 + 0.5) / height as f32,
        2.0 * depth - 1.0,
    );
    mvp.inverse().project_point3(ndc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render_shown;
    use stereolab::output::Image;
    use stereolab::scene::LoadOptions;
    use stereolab_core::AnaglyphKind;

    fn raw(i: &Image) -> Vec<u8> {
        match i {
            Image::Rgba(i) => i.as_raw().clone(),
            Image::Gray16(i) | Image::WindowDepth(i) => {
                i.as_raw().iter().flat_map(|v| v.to_le_bytes()).collect()
            }
            Image::Stereo(p) => [p.left.as_raw().as_slice(), p.right.as_raw()].concat(),
            Image::Sequence(_) => i.to_display_rgba().into_raw(),
        }
    }

    /// Every parameter moved, for four outputs: the scene file the viewer writes loads into a
    /// scene that renders the same bytes as the viewer's frame, with the file written into
    /// another folder (absolute model paths) and into the scene's own (relative paths).
    #[test]
    fn a_saved_scene_renders_what_the_viewer_showed() {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/wuson.toml");
        let sets = ["stereo.zero_parallax=4.0".to_string()];
        let mut scene = Scene::load(&path, &sets).unwrap();
        scene.set_size(128, 96).unwrap();
        let session = Session::new(&scene, &path, &sets).unwrap();
        let mut p = session.initial.clone();
        p.orbit(37.0, 12.0);
        p.pan(0.1, -0.05);
        p.zoom(0.8);
        p.scale_offset(KEYPAD_FACTOR);
        p.scale_balance(1.0 / KEYPAD_FACTOR);
        p.rig.mode = CameraMode::ToeIn;
        p.rig.lighting = Lighting::Cyclopic;
        p.turn_degrees = 33.3;
        p.sirds_seed = 7;
        p.sirds_start = StripStart::Left;
        p.chromadepth_d = [Some(3.0), None];
        let elsewhere = std::env::temp_dir().join(format!("stereolab-view-{}", std::process::id()));
        std::fs::create_dir_all(&elsewhere).unwrap();
        for output in [
            Output::Anaglyph(AnaglyphKind::DuboisRedCyan),
            Output::ChromaDepth,
            Output::Sirds,
            Output::SideBySide,
            Output::ViewTiles(2),
            Output::WiggleApng,
        ] {
            p.output = output;
            session.apply(&p, &mut scene);
            let shown = render_shown(&scene, &p, None).unwrap();
            // Another folder: absolute paths, read with --allow-outside-paths.
            let text = session.scene_toml(&p, &elsewhere).unwrap();
            let file = elsewhere.join("shot.toml");
            std::fs::write(&file, &text).unwrap();
            let opts = LoadOptions {
                allow_outside_paths: true,
                ..LoadOptions::default()
            };
            let back = Scene::load_with(&file, &[], &opts).unwrap();
            let again = render_shown(&back, &p, None).unwrap();
            assert_eq!(raw(&shown.image), raw(&again.image), "{}", output.name());
            // The scene's own folder: the relative model path stays.
            let dir = path.parent().unwrap();
            let text = session.scene_toml(&p, dir).unwrap();
            assert!(text.contains("path = \"models/WusonOBJ.obj\""), "{text}");
            let back = Scene::from_toml(&text, &path, dir, &[]).unwrap();
            let again = render_shown(&back, &p, None).unwrap();
            assert_eq!(raw(&shown.image), raw(&again.image), "{}", output.name());
        }
        let _ = std::fs::remove_dir_all(&elsewhere);
    }

    #[test]
    fn every_mode_is_listed_once_and_named_as_the_scene_file_reads_it() {
        for (i, &m) in MODES.iter().enumerate() {
            assert!(!MODES[..i].contains(&m), "{m:?} twice");
            let text = format!("mode = \"{}\"", mode_name(m));
            #[derive(serde::Deserialize)]
            struct S {
                mode: CameraMode,
            }
            let back: S = toml::from_str(&text).unwrap();
            assert_eq!(back.mode, m, "{text}");
            assert_eq!(next_mode(MODES[(i + MODES.len() - 1) % MODES.len()]), m);
        }
    }

    #[test]
    fn keypad_steps_multiply_and_stay_in_the_guides_range() {
        let mut p = Params {
            output: Output::SideBySide,
            camera: Camera {
                eye: [0.0, 0.0, 5.0],
                target: [0.0; 3],
                up: [0.0, 1.0, 0.0],
                fov_y: 50.0,
                near: 1.0,
                far: 20.0,
            },
            rig: StereoRig::default(),
            chromadepth_d: [None, None],
            linear_light: false,
            swap_eyes: false,
            anti_rivalry: false,
            sirds_algorithm: SirdsAlgorithm::PerVertex,
            sirds_start: StripStart::Center,
            sirds_filter: StripFilter::Bilinear,
            sirds_seed: 1,
            turn_degrees: 0.0,
        };
        p.scale_offset(KEYPAD_FACTOR);
        p.scale_offset(KEYPAD_FACTOR);
        assert!((p.rig.user_offset - 1.21).abs() < 1e-6);
        // Up to 1.1⁷ = 1.95 for both factors; the eighth press (2.14) would pass the guide's
        // upper limit 2.0: it changes nothing and says so, for the balance as for the offset.
        p.rig.user_offset = 1.0;
        for which in [UserFactor::Offset, UserFactor::Balance] {
            let steps: Vec<Step> = (0..9)
                .map(|_| p.step_user_factor(which, KEYPAD_FACTOR))
                .collect();
            assert!(
                steps[..7].iter().all(|s| matches!(s, Step::Moved(_))),
                "{steps:?}"
            );
            let top = 1.1f32.powi(7);
            match steps[7] {
                Step::AtLimit(at, would) => {
                    assert!(
                        (at - top).abs() < 1e-5 && would > USER_FACTOR_MAX,
                        "{at} {would}"
                    );
                }
                other => panic!("{which:?}: {other:?}"),
            }
            assert!(matches!(steps[8], Step::AtLimit(..)));
            // Seven presses down return to 1.0 (the ladder was kept).
            for _ in 0..7 {
                p.step_user_factor(which, 1.0 / KEYPAD_FACTOR);
            }
            let v = match which {
                UserFactor::Offset => p.rig.user_offset,
                UserFactor::Balance => p.rig.user_balance,
            };
            assert!((v - 1.0).abs() < 1e-5, "{which:?}: {v}");
            // The rig accepts every value the keypad reaches.
            assert!(p.rig.resolve(&p.camera, 4.0 / 3.0).is_ok());
        }
        // Down towards 0, never reaching it; at 0 (the slider) a press says why it cannot move.
        for _ in 0..20 {
            p.scale_balance(1.0 / KEYPAD_FACTOR);
        }
        assert!(p.rig.user_balance > 0.0 && p.rig.user_balance < 0.2);
        p.rig.user_offset = 0.0;
        assert_eq!(p.scale_offset(KEYPAD_FACTOR), Step::AtZero);
        p.rig.user_offset = 1.0;
        // Zero parallax at a clicked point: its distance along the view direction.
        let z = p.set_zero_parallax_at(Vec3::new(0.3, -0.2, 1.0)).unwrap();
        assert!((z - 4.0).abs() < 1e-5, "{z}");
        let eyes = p.rig.eyes(&p.camera, 4.0 / 3.0).unwrap();
        let at = point_parallax_pixels(&eyes, Vec3::new(0.3, -0.2, 1.0), 640).unwrap();
        // Balance < 1 leaves the point off zero; balance 1 puts it on zero exactly.
        assert!(at.abs() > 0.1, "{at}");
        p.rig.user_balance = 1.0;
        let eyes = p.rig.eyes(&p.camera, 4.0 / 3.0).unwrap();
        let at = point_parallax_pixels(&eyes, Vec3::new(0.3, -0.2, 1.0), 640).unwrap();
        assert!(at.abs() < 1e-3, "{at}");
        assert!(p.set_zero_parallax_at(Vec3::new(0.0, 0.0, 30.0)).is_err());
    }
}
