//! The wgpu path beside the CPU's (cargo feature `gpu`): the same frame rendered by
//! [`stereolab_gpu`] (lavapipe on a machine without a GPU) and measured against the CPU frame with
//! [`stereolab::compare`]'s metrics, as `stereolab compare SCENE` measures them, for the one output
//! shown. It runs on the viewer's worker thread, after the CPU frame of the same parameters.
//!
//! The GPU image is made as `stereolab render --backend gpu` makes it
//! ([`stereolab_gpu::output::write_all`]): the plan's passes on the GPU, then the output's WGSL
//! mirror where it has one (anaglyphs, remap, occlusion, parallax; the per-vertex SIRDS strips),
//! the CPU's effect on the GPU's framebuffers otherwise (layouts, ChromaDepth glasses, TIW).

use std::time::{Duration, Instant};

use stereolab::compare::{Metrics, compare, depth_bits_identical, framebuffer_from_image};
use stereolab::output::{Image, produce};
use stereolab::plan::Output;
use stereolab::scene::Scene;
use stereolab_core::Result;
use stereolab_gpu::sirds::GpuStrips;
use stereolab_gpu::{GpuFinalize, GpuRenderer, GpuScene};

use super::frame::Shown;

/// The GPU device and the pipelines the viewer's outputs use, made once.
pub struct GpuPath {
    r: GpuRenderer,
    fin: GpuFinalize,
    strips: Option<GpuStrips>,
}

/// One pass, CPU against GPU.
#[derive(Clone, Debug)]
pub struct PassParity {
    /// The pass (`Left Color`).
    pub name: String,
    /// Coverage, color and depth differences ([`compare`]).
    pub metrics: Metrics,
    /// `(identical, both_covered)`: depth bit for bit ([`depth_bits_identical`]).
    pub depth_identical: (usize, usize),
}

/// The GPU frame of the parameters the CPU frame was rendered with, and how they differ.
pub struct GpuShown {
    /// The adapter (`lavapipe`, or the GPU's name).
    pub adapter: String,
    /// The output image made on the GPU.
    pub image: Image,
    /// Every pass of the plan, CPU against GPU.
    pub passes: Vec<PassParity>,
    /// The output image, CPU against GPU (coverage: drawn vs background).
    pub output: Metrics,
    /// GPU passes with readback, and the output.
    pub time: Duration,
}

impl GpuPath {
    /// Opens the first Vulkan adapter and builds the effect pipelines.
    ///
    /// # Errors
    /// No Vulkan adapter (lavapipe: `mesa-vulkan-drivers`), or a pipeline fails.
    pub fn new() -> Result<GpuPath> {
        let r = GpuRenderer::new()?;
        let fin = GpuFinalize::new(&r)?;
        Ok(GpuPath {
            r,
            fin,
            strips: None,
        })
    }

    /// Renders `cpu`'s plan for `scene` (set to `cpu`'s parameters) on the GPU and compares.
    ///
    /// # Errors
    /// The scene has no GPU equivalent (e.g. other subpixel bits), or the GPU fails.
    pub fn render(&mut self, scene: &Scene, cpu: &Shown) -> Result<GpuShown> {
        let start = Instant::now();
        let r = &self.r;
        // The meshes are small and the model turns through its matrix, so they are uploaded
        // with every frame: the GPU frame is the scene as it is now.
        let frame = r.render(&GpuScene::upload(r, scene)?, &cpu.frame.plan)?;
        let output = cpu.params.output;
        let image = if output == Output::Sirds {
            if self.strips.is_none() {
                self.strips = Some(GpuStrips::new(r)?);
            }
            let strips = self.strips.as_ref().ok_or_else(|| {
                stereolab_core::Error::internal("viewer", "the GPU strips were not built")
            })?;
            Image::Rgba(
                stereolab_gpu::sirds_frame::from_frame(r, strips, &frame, scene)?.to_rgba_image(),
            )
        } else {
            match stereolab_gpu::effects::produce_wgsl(r, &self.fin, output, &frame, scene)? {
                Some(img) => Image::Rgba(img),
                None => produce(output, &frame, scene)?,
            }
        };
        let time = start.elapsed();
        let mut passes = Vec::new();
        for (e, a) in cpu.frame.passes.iter().zip(&frame.passes) {
            passes.push(PassParity {
                name: format!("{:?} {:?}", e.pass.view, e.pass.shading),
                metrics: compare(&e.framebuffer, &a.framebuffer)?,
                depth_identical: depth_bits_identical(&e.framebuffer, &a.framebuffer)?,
            });
        }
        let bg = scene.background;
        let output = compare(
            &framebuffer_from_image(&cpu.image.to_display_rgba(), bg)?,
            &framebuffer_from_image(&image.to_display_rgba(), bg)?,
        )?;
        Ok(GpuShown {
            adapter: r.short_name(),
            image,
            passes,
            output,
            time,
        })
    }
}

impl GpuShown {
    /// Depth bit for bit over all passes: `(identical, both_covered)`.
    pub fn depth_identical(&self) -> (usize, usize) {
        self.passes.iter().fold((0, 0), |(s, b), p| {
            (s + p.depth_identical.0, b + p.depth_identical.1)
        })
    }

    /// Coverage mismatches over all passes.
    pub fn coverage_mismatch(&self) -> usize {
        self.passes
            .iter()
            .map(|p| p.metrics.coverage_mismatch)
            .sum()
    }

    /// The readout: `compare`'s numbers for every pass and for the output shown.
    pub fn lines(&self) -> Vec<String> {
        let psnr = |m: &Metrics| {
            if m.psnr.is_infinite() {
                "inf".to_string()
            } else {
                format!("{:.1}", m.psnr)
            }
        };
        let mut lines = vec![format!(
            "{} frame (passes, readback, output): {:.1} ms",
            self.adapter,
            self.time.as_secs_f64() * 1e3
        )];
        for p in &self.passes {
            let (same, both) = p.depth_identical;
            lines.push(format!(
                "{:<12} coverage mismatch {} px ({:.3}%), max channel diff {}, PSNR {} dB, \
                 depth bit-identical {same}/{both} ({:.2}%)",
                p.name,
                p.metrics.coverage_mismatch,
                p.metrics.coverage_mismatch_percent(),
                p.metrics.max_channel_diff,
                psnr(&p.metrics),
                100.0 * same as f64 / both.max(1) as f64
            ));
        }
        let o = &self.output;
        lines.push(format!(
            "{:<12} coverage mismatch {} px ({:.3}%), max channel diff {}, PSNR {} dB",
            "output",
            o.coverage_mismatch,
            o.coverage_mismatch_percent(),
            o.max_channel_diff,
            psnr(o)
        ));
        lines
    }
}
