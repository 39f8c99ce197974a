//! Scenes: the TOML file, OBJ models, procedural shapes.

mod checks;
pub mod dem;
mod file;
mod mesh;
mod messages;
mod obj;
pub mod pdb;
mod polygon;
pub mod terrain;
pub mod terrain_data;

pub use checks::{DEPTH_RESOLUTION_WARN, ORIGIN_PRECISION_WARN, depth_resolution, resolution_of};
pub(crate) use file::SceneFile;
pub use mesh::Mesh;
pub use obj::{
    load_obj, load_obj_with_notes, load_obj_within, parse_obj, parse_obj_with_notes,
    parse_obj_within,
};

use std::path::Path;

use glam::{EulerRot, Mat4, Quat, Vec3};

use crate::plan::Output;
use stereolab_core::{
    AnaglyphOptions, Camera, ChromaDepthSettings, Error, InputRoot, Light, ParallaxRig,
    RasterOptions, Result, Separation, StereoRig, ZeroParallax, check_size, fit_zero_parallax,
    to_rgba8,
};

/// One object: a mesh placed in the world with a color.
#[derive(Clone, Debug)]
pub struct Object {
    /// What the scene calls it (`mesh[i] kind`).
    pub name: String,
    /// The geometry in object space.
    pub mesh: Mesh,
    /// Object → world.
    pub model: Mat4,
    /// Material color 0..1.
    pub color: Vec3,
}

/// A validated scene, ready to render.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Clear color.
    pub background: [u8; 4],
    /// The cyclopean camera.
    pub camera: Camera,
    /// The stereo rig.
    pub rig: StereoRig,
    /// The light.
    pub light: Light,
    /// Objects.
    pub objects: Vec<Object>,
    /// Requested outputs.
    pub outputs: Vec<Output>,
    /// Black rows between the views of `above_below_squashed`.
    pub blank_interval: u32,
    /// Rasterizer options.
    pub raster: RasterOptions,
    /// ChromaDepth options (the ChromaDepth article).
    pub chromadepth: ChromaDepthSettings,
    /// Finalize-pass options from `[finalize]` (anaglyph linear light, swapped eyes).
    pub finalize: AnaglyphOptions,
    /// Autostereogram options (`[sirds]`).
    pub sirds: stereolab_core::SirdsSettings,
    /// Random-dot stereo pair options (`[rds]`).
    pub rds: stereolab_core::RdsSettings,
    /// Crosstalk options (`[ghosting]`).
    pub ghosting: stereolab_core::GhostingSettings,
    /// Frame-sequential options (`[frame_sequential]`).
    pub frame_sequential: stereolab_core::FrameSequentialSettings,
    /// Wiggle options (`[wiggle]`).
    pub wiggle: stereolab_core::WiggleSettings,
    /// Cameras on the rig's baseline for the multiview outputs (`[multiview] views`, 2 to
    /// [`MAX_VIEWS`](stereolab_core::MAX_VIEWS)); the scene's multiview outputs carry it.
    pub views: u8,
    /// What loading read in an unusual way and accepted, each naming its file and line (an
    /// OBJ coordinate such as `3.1+e2`, read as assimp reads it); `stereolab render` prints
    /// them.
    pub notes: Vec<String>,
}

/// The largest scene file accepted (a scene is a few kilobytes of TOML; models and terrain are
/// separate files with their own limits).
const MAX_SCENE_BYTES: u64 = 16 * 1024 * 1024;

/// The triangle budget a scene gets unless told otherwise: a few million triangles render in
/// well under a second and take a few hundred MB.
pub const DEFAULT_MAX_TRIANGLES: u64 = 4_000_000;

/// How a scene file is loaded: where it may read files, and its triangle budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LoadOptions {
    /// Read files outside the scene's folder tree (`--allow-outside-paths`).
    pub allow_outside_paths: bool,
    /// The most triangles all meshes together may have (`--max-triangles`).
    pub max_triangles: u64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            allow_outside_paths: false,
            max_triangles: DEFAULT_MAX_TRIANGLES,
        }
    }
}

impl LoadOptions {
    fn root(&self, base: &Path) -> InputRoot {
        if self.allow_outside_paths {
            InputRoot::anywhere(base)
        } else {
            InputRoot::confined(base)
        }
    }
}

impl Scene {
    /// Every object as the SIRDS strip passes take it ([`StripGeometry::new`](stereolab_core::StripGeometry::new)):
    /// its model matrix and its mesh.
    pub fn strip_objects(&self) -> Vec<stereolab_core::StripObject<'_>> {
        self.objects
            .iter()
            .map(|o| stereolab_core::StripObject {
                model: o.model,
                positions: &o.mesh.positions,
                triangles: &o.mesh.triangles,
            })
            .collect()
    }

    /// Reads a scene file, applies `--set key=value` overrides, loads its models, validates it.
    ///
    /// # Errors
    /// Any I/O, TOML, OBJ or validation error, naming the file and the field.
    pub fn load(path: &Path, sets: &[String]) -> Result<Scene> {
        Scene::load_with(path, sets, &LoadOptions::default())
    }

    /// [`Scene::load`] with explicit [`LoadOptions`] (outside paths, the triangle budget).
    ///
    /// # Errors
    /// As [`Scene::load`].
    pub fn load_with(path: &Path, sets: &[String], opts: &LoadOptions) -> Result<Scene> {
        let text = stereolab_core::read_text(path, MAX_SCENE_BYTES)?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Scene::from_toml_with(&text, path, &opts.root(&base), sets, opts.max_triangles)
    }

    /// Parses scene text; `path` is used in messages, `base_dir` resolves relative model paths.
    ///
    /// # Errors
    /// As [`Scene::load`].
    pub fn from_toml(text: &str, path: &Path, base_dir: &Path, sets: &[String]) -> Result<Scene> {
        let opts = LoadOptions::default();
        Scene::from_toml_with(text, path, &opts.root(base_dir), sets, opts.max_triangles)
    }

    fn from_toml_with(
        text: &str,
        path: &Path,
        root: &InputRoot,
        sets: &[String],
        max_triangles: u64,
    ) -> Result<Scene> {
        let mut table: toml::Table =
            toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
        apply_sets(&mut table, sets)?;
        let file: SceneFile = table
            .clone()
            .try_into()
            .map_err(|e: toml::de::Error| field_error(path, text, &table, sets, &e))?;
        Scene::from_file(file, root, max_triangles).map_err(|e| e.in_file(path))
    }

    /// Validates a parsed scene file and loads its meshes.
    ///
    /// # Errors
    /// The first invalid field.
    pub(crate) fn from_file(f: SceneFile, root: &InputRoot, max_triangles: u64) -> Result<Scene> {
        check_size(f.image.width, f.image.height)?;
        f.camera.validate()?;
        let separation = match &f.stereo.eye_separation {
            None => Separation::Auto,
            Some(file::SeparationSpec::Value(v)) => Separation::Absolute(*v),
            Some(file::SeparationSpec::Word(w)) if w == "auto" => Separation::Auto,
            Some(file::SeparationSpec::Word(w)) => {
                return Err(Error::invalid(
                    "stereo.eye_separation",
                    format!("\"{}\"", stereolab_core::excerpt(w)),
                    "must be a number or \"auto\"",
                ));
            }
        };
        let mut zero_parallax_word = None;
        let zero_parallax = match (&f.stereo.zero_parallax, f.stereo.zero_parallax_fraction) {
            (Some(_), Some(_)) => {
                return Err(Error::invalid(
                    "stereo.zero_parallax",
                    "both given",
                    "give zero_parallax or zero_parallax_fraction, not both",
                ));
            }
            (Some(file::SeparationSpec::Value(d)), None) => ZeroParallax::Distance(*d),
            // "auto": the camera target's distance along the view direction (the centre of
            // interest of the StereoGraphics guide's §7); "fit" is resolved below, once the
            // meshes are loaded.
            (Some(file::SeparationSpec::Word(w)), None) if w == "auto" || w == "fit" => {
                zero_parallax_word = Some(w.clone());
                let dir = Vec3::from(f.camera.target) - Vec3::from(f.camera.eye);
                ZeroParallax::Distance(dir.length())
            }
            (Some(file::SeparationSpec::Word(w)), None) => {
                return Err(Error::invalid(
                    "stereo.zero_parallax",
                    format!("\"{}\"", stereolab_core::excerpt(w)),
                    "must be a distance, \"auto\" (the camera target's distance) or \"fit\" \
                     (centre the scene's depth range in the parallax budget)",
                ));
            }
            (None, Some(t)) => ZeroParallax::Fraction(t),
            (None, None) => ZeroParallax::Fraction(0.5),
        };
        let mut rig = StereoRig {
            mode: f.stereo.mode,
            separation,
            zero_parallax,
            user_offset: f.stereo.user_offset,
            user_balance: f.stereo.user_balance,
            lighting: f.stereo.lighting,
            viewer: f.stereo.viewer,
        };
        // The eyes themselves: a separation can pass every range check and still overflow the
        // matrices (toe-in at 1e20 units gives NaN cameras), or shift image-shift's eyes apart
        // by the whole width.
        rig.eyes_for_image(&f.camera, f.image.width, f.image.height)?;
        check_finite("light.position", &f.light.position)?;
        checks::check_light(&f.light)?;
        check_finite("image.background", &f.image.background)?;
        let light = Light {
            position: f.light.position.into(),
            ambient: f.light.ambient,
            specular: f.light.specular,
            shininess: f.light.shininess,
        };
        // The layout needs two rows besides the blank (u64: no wrap for any u32 the file holds).
        if u64::from(f.layout.blank_interval) + 2 > u64::from(f.image.height)
            && f.outputs.iter().any(|o| o == "above_below_squashed")
        {
            return Err(Error::invalid(
                "layout.blank_interval",
                f.layout.blank_interval,
                "leaves no rows for the two views",
            ));
        }
        let views = checks::multiview_views(f.multiview.views)?;
        let outputs = f
            .outputs
            .iter()
            .map(|o| Output::parse(o).map(|o| o.with_views(views)))
            .collect::<Result<Vec<_>>>()?;
        if outputs.contains(&Output::ViewTiles(views)) {
            checks::check_view_tiles(views, f.image.width, f.image.height)?;
        }
        if outputs.iter().any(|o| o.views().is_some()) {
            // Image-shift's refusal and the outer cameras' matrices, before anything renders.
            rig.views(&f.camera, f.image.width, f.image.height, u32::from(views))?;
        }
        if outputs.is_empty() {
            return Err(Error::invalid(
                "outputs",
                "[]",
                "ask for at least one output",
            ));
        }
        f.chromadepth.validate()?;
        f.rds.validate()?;
        f.ghosting.validate()?;
        f.frame_sequential.validate()?;
        f.wiggle.validate()?;
        let mut notes = Vec::new();
        let objects = f
            .meshes
            .iter()
            .enumerate()
            .map(|(i, m)| load_object(i, m, root, max_triangles, &mut notes))
            .collect::<Result<Vec<_>>>()?;
        let triangles: u64 = objects.iter().map(|o| o.mesh.triangles.len() as u64).sum();
        if triangles > max_triangles {
            return Err(over_budget("mesh", triangles, max_triangles));
        }
        if zero_parallax_word.as_deref() == Some("fit") {
            let z0 = fit_scene_zero_parallax(&rig, &f.camera, &objects)?;
            notes.push(format!(
                "stereo.zero_parallax = \"fit\": z0 = {z0:.4} (balance × harmonic mean of the \
                 nearest and farthest visible vertex depths)"
            ));
            rig.zero_parallax = ZeroParallax::Distance(z0);
            rig.eyes_for_image(&f.camera, f.image.width, f.image.height)?;
        } else if let (Some(_), ZeroParallax::Distance(z0)) =
            (&zero_parallax_word, rig.zero_parallax)
        {
            notes.push(format!(
                "stereo.zero_parallax = \"auto\": z0 = {z0:.4} (the camera target's distance)"
            ));
        }
        let sirds = stereolab_core::SirdsSettings::from_spec(&f.sirds, root)?;
        checks::check_sirds_clip(&sirds, &f.camera)?;
        let depth = checks::depth_mode(&f.raster, &f.camera)?;
        let mut scene = Scene {
            width: f.image.width,
            height: f.image.height,
            background: to_rgba8(f.image.background.into()),
            camera: f.camera,
            rig,
            light,
            objects,
            outputs,
            blank_interval: f.layout.blank_interval,
            raster: RasterOptions {
                cull_back: f.raster.cull_back,
                depth,
                ..RasterOptions::default()
            },
            chromadepth: f.chromadepth,
            finalize: AnaglyphOptions {
                linear_light: f.finalize.linear_light,
                swap_eyes: f.finalize.swap_eyes,
                anti_rivalry: f.finalize.anti_rivalry,
            },
            sirds,
            rds: f.rds,
            ghosting: f.ghosting,
            frame_sequential: f.frame_sequential,
            wiggle: f.wiggle,
            views,
            notes,
        };
        let warnings = checks::precision_warnings(&scene)?;
        scene.notes.extend(warnings);
        Ok(scene)
    }

    /// The numbers the parallax formula `p(z)` needs, for this scene's rig at its image size.
    ///
    /// # Errors
    /// As [`ParallaxRig::new`].
    pub fn parallax_rig(&self) -> Result<ParallaxRig> {
        ParallaxRig::new(&self.rig, &self.camera, self.width, self.height)
    }

    /// Width / height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Overrides the image size (CLI `--size WxH`), checking it before anything is allocated.
    ///
    /// # Errors
    /// A zero or oversized side, or a size that leaves the rig invalid.
    pub fn set_size(&mut self, width: u32, height: u32) -> Result<()> {
        check_size(width, height)?;
        self.width = width;
        self.height = height;
        self.rig.eyes_for_image(&self.camera, width, height)?;
        if self.outputs.contains(&Output::ViewTiles(self.views)) {
            checks::check_view_tiles(self.views, width, height)?;
        }
        Ok(())
    }

    /// The zero-parallax distance `"fit"` would choose for this scene's camera and rig
    /// ([`fit_zero_parallax`] over the visible vertex depths).
    ///
    /// # Errors
    /// Parallel mode (z0 moves nothing), or no vertex inside the view.
    pub fn fitted_zero_parallax(&self) -> Result<f32> {
        fit_scene_zero_parallax(&self.rig, &self.camera, &self.objects)
    }

    /// Every object's vertices in world space.
    pub fn world_points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.objects.iter().flat_map(|o| {
            o.mesh
                .positions
                .iter()
                .map(move |p| o.model.transform_point3(*p))
        })
    }
}

/// `zero_parallax = "fit"`: the eye distances of the nearest and farthest vertex inside the
/// cyclopean view (strictly between near and far) give [`fit_zero_parallax`].
fn fit_scene_zero_parallax(rig: &StereoRig, camera: &Camera, objects: &[Object]) -> Result<f32> {
    use stereolab_core::CameraMode;
    let balance = match rig.mode {
        // Image-shift: the balance before its whole-pixel rounding (z0 fixes that rounding).
        CameraMode::OffAxis | CameraMode::ImageShift => rig.user_balance,
        CameraMode::ToeIn => 1.0,
        CameraMode::Parallel => {
            return Err(Error::invalid(
                "stereo.zero_parallax",
                "\"fit\"",
                "parallel cameras put zero parallax at infinity whatever z0 is; use mode \
                 \"off-axis\" or give a distance",
            ));
        }
    };
    let view = camera.view();
    let ty = (camera.fov_y.to_radians() * 0.5).tan();
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for o in objects {
        for p in &o.mesh.positions {
            let e = view.transform_point3(o.model.transform_point3(*p));
            let z = -e.z;
            // Inside the view: depth between the clip planes, |y| within the vertical fov
            // (x is not tested: the fit is meant for the subject the camera looks at).
            if z > camera.near && z < camera.far && e.y.abs() <= ty * z {
                lo = lo.min(z);
                hi = hi.max(z);
            }
        }
    }
    if !lo.is_finite() {
        return Err(Error::invalid(
            "stereo.zero_parallax",
            "\"fit\"",
            "no vertex lies inside the view to measure; give a distance",
        ));
    }
    let z0 = fit_zero_parallax(lo, hi, balance);
    Ok(z0.clamp(
        camera.near + 1e-3 * (camera.far - camera.near),
        camera.far - 1e-3 * (camera.far - camera.near),
    ))
}

fn check_finite(field: &str, v: &[f32]) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::invalid(field, format!("{v:?}"), "must be finite"))
    }
}

/// Builds one `[[mesh]]` entry.
/// The triangle budget's error: what the scene asks for, the limit, and the flag that moves it.
fn over_budget(field: &str, triangles: u64, max: u64) -> Error {
    Error::invalid(
        field,
        format!("{triangles} triangles"),
        format!(
            "over the scene's budget of {max} triangles (lower the detail or count, or raise \
             the budget with --max-triangles)"
        ),
    )
}

fn load_object(
    i: usize,
    m: &file::MeshSpec,
    root: &InputRoot,
    max_triangles: u64,
    notes: &mut Vec<String>,
) -> Result<Object> {
    let field = |f: &str| format!("mesh[{i}].{f}");
    let positive = |name: &str, v: Option<f32>, default: f32| -> Result<f32> {
        let v = v.unwrap_or(default);
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(Error::invalid(
                field(name),
                v,
                "must be a finite number > 0",
            ))
        }
    };
    let detail = m.detail.unwrap_or(32);
    if !(3..=4096).contains(&detail) {
        return Err(Error::invalid(
            field("detail"),
            detail,
            "must lie in 3..=4096",
        ));
    }
    // Generated meshes are checked against the budget before they are built.
    let planned: u64 = match m.kind.as_str() {
        "sphere" | "torus" => 2 * u64::from(detail) * u64::from(detail / 2),
        "plane" => 2 * u64::from(detail.min(512)).pow(2),
        "triangles" => u64::from(m.count.unwrap_or(1000)),
        _ => 0,
    };
    if planned > max_triangles {
        return Err(over_budget(
            &field(if m.kind == "triangles" {
                "count"
            } else {
                "detail"
            }),
            planned,
            max_triangles,
        ));
    }
    let mesh = match m.kind.as_str() {
        "obj" => {
            let p = m.path.as_ref().ok_or_else(|| {
                Error::invalid(field("path"), "missing", "an obj mesh needs a path")
            })?;
            let (mesh, obj_notes) =
                load_obj_within(&root.resolve(&field("path"), p)?, max_triangles)?;
            notes.extend(obj_notes);
            mesh
        }
        "sphere" => Mesh::sphere(positive("size", m.size, 1.0)?, detail, detail / 2),
        "cube" => Mesh::cube(positive("size", m.size, 1.0)?),
        "torus" => Mesh::torus(
            positive("size", m.size, 1.0)?,
            positive("minor", m.minor, 0.3)?,
            detail,
            detail / 2,
        ),
        "terrain" => {
            let p = m.path.as_ref().ok_or_else(|| {
                Error::invalid(field("path"), "missing", "a terrain mesh needs a CSV path")
            })?;
            terrain::load_terrain_csv_within(&root.resolve(&field("path"), p)?, max_triangles)?.mesh
        }
        "dem" => load_dem_mesh(&field, m, root, max_triangles)?,
        "pdb" => {
            let p = m.path.as_ref().ok_or_else(|| {
                Error::invalid(field("path"), "missing", "a pdb mesh needs a PDB file path")
            })?;
            let detail = m.detail.unwrap_or(12);
            let atoms = pdb::load_pdb(&root.resolve(&field("path"), p)?)?;
            let planned = pdb::planned_triangles(atoms.len(), detail);
            if planned > max_triangles {
                return Err(over_budget(&field("detail"), planned, max_triangles));
            }
            pdb::atoms_mesh(&atoms, detail, positive("size", m.size, 1.0)?)
        }
        "plane" => Mesh::plane(positive("size", m.size, 1.0)?, detail.min(512)),
        "triangles" => {
            let n = m.count.unwrap_or(1000);
            if !(1..=10_000_000).contains(&n) {
                return Err(Error::invalid(
                    field("count"),
                    n,
                    "must lie in 1..=10000000",
                ));
            }
            Mesh::triangle_grid(n)
        }
        other => {
            return Err(Error::invalid(
                field("kind"),
                format!("\"{}\"", stereolab_core::excerpt(other)),
                "known kinds: obj, sphere, cube, torus, plane, triangles, terrain, dem, pdb",
            ));
        }
    };
    check_finite(&field("translate"), &m.translate)?;
    check_finite(&field("rotate"), &m.rotate)?;
    check_finite(&field("color"), &m.color)?;
    if !(m.scale > 0.0 && m.scale.is_finite()) {
        return Err(Error::invalid(
            field("scale"),
            m.scale,
            "must be a finite number > 0",
        ));
    }
    Ok(Object {
        name: format!("mesh[{i}] {}", m.kind),
        mesh,
        model: model_matrix(m.translate, m.rotate, m.scale),
        color: m.color.into(),
    })
}

/// Scattered points a `dem` mesh is sampled at unless `count` says otherwise.
pub const DEFAULT_DEM_POINTS: u32 = 20_000;

/// A `kind = "dem"` mesh: the elevation image at `path`, its `extent` and `heights` (both
/// required: an image does not say how large its ground is), `count` scattered points
/// ([`DEFAULT_DEM_POINTS`]), `seed`.
fn load_dem_mesh(
    field: &dyn Fn(&str) -> String,
    m: &file::MeshSpec,
    root: &InputRoot,
    max_triangles: u64,
) -> Result<Mesh> {
    let p = m.path.as_ref().ok_or_else(|| {
        Error::invalid(
            field("path"),
            "missing",
            "a dem mesh needs the path of a grayscale elevation image",
        )
    })?;
    let extent = m.extent.ok_or_else(|| {
        Error::invalid(
            field("extent"),
            "missing",
            "a dem mesh needs extent = [east, north], the ground the image covers, in scene units",
        )
    })?;
    let heights = m.heights.ok_or_else(|| {
        Error::invalid(
            field("heights"),
            "missing",
            "a dem mesh needs heights = [at gray 0, at full-scale white], in scene units",
        )
    })?;
    let opts = dem::DemOptions {
        extent,
        heights,
        points: m.count.unwrap_or(DEFAULT_DEM_POINTS),
        seed: m.seed.unwrap_or(0),
    };
    let prefix = field("");
    let prefix = prefix.trim_end_matches('.');
    dem::check_options(prefix, &opts)?;
    dem::check_budget(prefix, opts.points, max_triangles)?;
    Ok(dem::load_dem(&root.resolve(&field("path"), p)?, &opts, max_triangles)?.mesh)
}

/// A `[[mesh]]`'s object → world matrix from its `translate`, `rotate` (degrees about X, then
/// Y, then Z) and uniform `scale`, as the scene file defines it. `stereolab view` turns a model
/// by changing `rotate` and calling this, so a turned model saved as TOML loads the same.
pub fn model_matrix(translate: [f32; 3], rotate_degrees: [f32; 3], scale: f32) -> Mat4 {
    let r = rotate_degrees.map(f32::to_radians);
    Mat4::from_scale_rotation_translation(
        Vec3::splat(scale),
        Quat::from_euler(EulerRot::ZYX, r[2], r[1], r[0]),
        translate.into(),
    )
}

/// A TOML error with the line it points at (or, for text that is UTF-16 without a byte-order
/// mark, which TOML reads as keys with no value, that encoding).
fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> Error {
    if stereolab_core::looks_like_utf16(text.as_bytes()) {
        return Error::parse(path, None, stereolab_core::UTF16_WITHOUT_BOM);
    }
    Error::parse(path, line_of(text, e), e.message().to_string())
}

/// The 1-based line `e`'s span starts on.
fn line_of(text: &str, e: &toml::de::Error) -> Option<usize> {
    e.span().map(|s| {
        text.get(..s.start.min(text.len()))
            .map_or(0, |t| t.matches('\n').count())
            + 1
    })
}

/// serde's error for the scene's table as a message naming the field, the value as written and
/// what it accepts ([`messages::describe`]); a field a `--set` wrote is named by that `--set`.
fn field_error(
    path: &Path,
    text: &str,
    table: &toml::Table,
    sets: &[String],
    e: &toml::de::Error,
) -> Error {
    let d = messages::describe(table, e);
    let from_set = sets.iter().rev().find_map(|set| {
        let (key, raw) = set.split_once('=')?;
        let parts: Vec<&str> = key.trim().split('.').collect();
        let n = parts.len().min(d.path.len());
        (parts[..n]
            .iter()
            .zip(&d.path[..n])
            .all(|(a, b)| *a == b.as_str()))
        .then_some((key.trim(), raw))
    });
    if let Some((key, raw)) = from_set {
        let reason = match (d.field() == key, raw.trim().is_empty()) {
            (true, true) => format!("the value is empty; it {}", d.reason),
            (true, false) => d.reason.clone(),
            (false, _) => format!("{}: {}", d.field(), d.reason),
        };
        return Error::invalid(format!("--set {key}"), set_value(raw), reason);
    }
    // The table has no spans; the text's own error points at the line when no --set moved it.
    let line = match toml::from_str::<SceneFile>(text) {
        Err(orig) if sets.is_empty() => line_of(text, &orig),
        _ => None,
    };
    Error::parse(path, line, d.message())
}

/// A `--set` value as a message quotes it: escaped, cut to an excerpt, `""` when empty.
fn set_value(raw: &str) -> String {
    if raw.trim().is_empty() {
        "\"\"".to_string()
    } else {
        stereolab_core::excerpt(raw)
    }
}

/// `[sirds]` settings from `--set sirds.key=value` alone, without a scene (`stereolab sirds
/// --depth`, `--decode`): each key must name a `[sirds]` field, and errors speak as a scene's
/// do (the `--set`, the value as typed, what the field accepts).
///
/// # Errors
/// `Invalid` naming the `--set` that does not apply.
pub fn sirds_settings_from_sets(sets: &[String]) -> Result<stereolab_core::SirdsSettings> {
    /// A scene file with nothing but its `[sirds]` table.
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct SirdsOnly {
        #[serde(default)]
        sirds: stereolab_core::SirdsSpec,
    }
    for set in sets {
        let (key, raw) = set.split_once('=').unwrap_or((set.as_str(), ""));
        let key = key.trim();
        if !key.starts_with("sirds.") {
            return Err(Error::invalid(
                format!("--set {}", stereolab_core::excerpt(key)),
                set_value(raw),
                "without a scene, --set sets [sirds] fields only (e.g. sirds.dpi=100); give a \
                 scene to set its other fields",
            ));
        }
    }
    let mut table = toml::Table::new();
    apply_sets(&mut table, sets)?;
    let only: SirdsOnly = toml::Value::Table(table.clone())
        .try_into()
        .map_err(|e| field_error(Path::new("--set"), "", &table, sets, &e))?;
    // Paths typed on the command line are the user's own: not confined.
    stereolab_core::SirdsSettings::from_spec(
        &only.sirds,
        &stereolab_core::InputRoot::anywhere(Path::new(".")),
    )
}

/// Applies `--set key=value` overrides to a scene file's table, in order (what
/// [`Scene::load`] does before it reads the table; `stereolab view` writes the result back).
///
/// # Errors
/// `Invalid` naming the `--set` that does not apply.
pub fn apply_sets(table: &mut toml::Table, sets: &[String]) -> Result<()> {
    sets.iter().try_for_each(|s| apply_set(table, s))
}

/// Applies one `key.path=value` override; the value is read as TOML (`0.3`, `"auto"`, `[1,2,3]`)
/// or, failing that, as a bare string. Numeric segments index arrays (`mesh.0.color`).
fn apply_set(table: &mut toml::Table, set: &str) -> Result<()> {
    let (key, raw) = set.split_once('=').ok_or_else(|| {
        Error::invalid(
            "--set",
            stereolab_core::excerpt(set),
            "expected key=value, e.g. camera.fov_y=40",
        )
    })?;
    let key = key.trim();
    let field = format!("--set {}", stereolab_core::excerpt(key));
    let value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
        Ok(mut t) => t.remove("v"),
        // A value that opens a list, a table or a quoted string must be TOML, not a bare word.
        Err(e) if raw.trim_start().starts_with(['[', '{', '"', '\'']) => {
            return Err(Error::invalid(
                field,
                set_value(raw),
                format!(
                    "not a complete TOML value ({}); write a number, true or false, \"text\" \
                     or a list such as [1, 0, 0]",
                    e.message().trim()
                ),
            ));
        }
        Err(_) => None,
    }
    .unwrap_or_else(|| toml::Value::String(raw.to_string()));
    let parts: Vec<&str> = key.split('.').collect();
    set_path(table, &parts, value).map_err(|reason| Error::invalid(field, set_value(raw), reason))
}

/// Walks `parts` down from `cur`, creating tables as needed, and sets the last one.
fn set_path(
    cur: &mut toml::Table,
    parts: &[&str],
    value: toml::Value,
) -> std::result::Result<(), String> {
    let (first, rest) = parts.split_first().ok_or("empty key")?;
    if first.is_empty() {
        return Err("a key has an empty part; write e.g. camera.fov_y=40".to_string());
    }
    if rest.is_empty() {
        cur.insert(first.to_string(), value);
        return Ok(());
    }
    // The key as messages quote it.
    let name = stereolab_core::excerpt(first);
    match cur
        .entry(first.to_string())
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
    {
        toml::Value::Table(t) => set_path(t, rest, value),
        toml::Value::Array(a) => {
            let len = a.len();
            let idx: usize = rest[0]
                .parse()
                .map_err(|_| format!("{name} is a list: give an index, e.g. {name}.0"))?;
            match a.get_mut(idx) {
                Some(toml::Value::Table(t)) if rest.len() > 1 => set_path(t, &rest[1..], value),
                Some(_) => Err(format!("{name}.{idx} is not a table with that field")),
                None if len == 0 => Err(format!("{name} has no entries")),
                None if len == 1 => Err(format!("{name} has 1 entry (index 0)")),
                None => Err(format!(
                    "{name} has {len} entries (indices 0 to {})",
                    len - 1
                )),
            }
        }
        _ => Err(format!(
            "{name} is a value, not a table: no field can be set inside it"
        )),
    }
}
