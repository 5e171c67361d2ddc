//! The ray caster's pipelines, all built for the device's lifetime: the bind group layouts, the
//! exit-point pass of the fragment path, the leaping structures' builders, and the ray-casting
//! variants, each compiled on first use and cached by its [`PipelineKey`].

use std::collections::HashMap;

use crate::render::shader::{ShaderError, compose, shader_module};
use crate::render::texture::OUTPUT_FORMAT;
use crate::settings::ConcretePath;

use super::layouts::Layouts;
use super::leap::LeapPipelines;
use super::targets::POSITION_FORMAT;
use super::variant::PipelineKey;

/// Every pipeline of the ray caster.
pub struct Pipelines {
    /// The bind group layouts every ray-casting pipeline shares.
    pub layouts: Layouts,
    /// Pass 1 of the fragment path: back faces → exit points.
    exit: wgpu::RenderPipeline,
    /// The min/max pyramid, emptiness and distance-field builders.
    pub leap: LeapPipelines,
    /// The label surfaces' mask builders.
    pub surfaces: crate::render::label_surface::SurfacePipelines,
    raycast: HashMap<PipelineKey, RaycastPipeline>,
}

/// A compiled ray-casting variant.
pub enum RaycastPipeline {
    /// Fragment path: drawn over the front faces and cap.
    Fragment(wgpu::RenderPipeline),
    /// Compute path: dispatched over the image.
    Compute(wgpu::ComputePipeline),
}

/// The pipelines one frame records with.
pub struct FramePipelines<'a> {
    /// The frame's ray-casting variant.
    pub raycast: &'a RaycastPipeline,
    /// The exit-point pass (used by the fragment path).
    pub exit: &'a wgpu::RenderPipeline,
}

impl Pipelines {
    /// Creates the layouts and the pipelines every frame may need; ray-casting variants come
    /// later, on first use.
    pub fn new(device: &wgpu::Device) -> Result<Self, ShaderError> {
        let layouts = Layouts::new(device);
        let source = compose("entry/proxy_passes.wgsl", &[])?;
        let module = shader_module(device, "proxy passes", source);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("proxy"),
            bind_group_layouts: &[Some(&layouts.frame)],
            immediate_size: 0,
        });
        let exit = proxy_pipeline(
            device,
            &layout,
            &module,
            ("fs_exit", POSITION_FORMAT, wgpu::Face::Front),
            "exit points",
        );
        Ok(Self {
            leap: LeapPipelines::new(device)?,
            surfaces: crate::render::label_surface::SurfacePipelines::new(device)?,
            exit,
            layouts,
            raycast: HashMap::new(),
        })
    }

    /// The pipelines of a frame rendered with variant `key`, building the variant on first use.
    pub(crate) fn for_frame(
        &mut self,
        device: &wgpu::Device,
        key: PipelineKey,
    ) -> Result<FramePipelines<'_>, ShaderError> {
        let raycast = match self.raycast.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(build(device, &self.layouts, key)?)
            }
        };
        Ok(FramePipelines {
            raycast,
            exit: &self.exit,
        })
    }

    /// Whether the variant `key` is built (a frame that needs it does not compile a shader).
    pub fn has(&self, key: &PipelineKey) -> bool {
        self.raycast.contains_key(key)
    }
}

/// A pipeline that rasterises the proxy geometry (`vs_proxy`) with one fragment entry point
/// `(entry, target format, faces culled)`.
fn proxy_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    (fragment, target, cull): (&str, wgpu::TextureFormat, wgpu::Face),
    label: &str,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(super::variant::PROXY_VERTEX_ENTRY),
            buffers: &[],
            compilation_options: Default::default(),
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            front_face: wgpu::FrontFace::Ccw,
            cull_mode: Some(cull),
            ..Default::default()
        },
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            targets: &[Some(wgpu::ColorTargetState {
                format: target,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })],
            compilation_options: Default::default(),
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Compiles variant `key`: groups 0 (frame) and 1 (the path's input or output), 2 for
/// statistics variants and 3 for leaping variants.
fn build(
    device: &wgpu::Device,
    layouts: &Layouts,
    key: PipelineKey,
) -> Result<RaycastPipeline, ShaderError> {
    let label = format!("{key:?}");
    let module = shader_module(device, &label, key.source()?);
    let io = match key.path {
        ConcretePath::Fragment => &layouts.fragment_io,
        ConcretePath::Compute => &layouts.compute_io,
    };
    let mut groups = vec![
        Some(&layouts.frame),
        Some(io),
        key.stats.then_some(&layouts.stats),
    ];
    if key.strategy.leaps() {
        groups.push(Some(&layouts.leap));
    }
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(&label),
        bind_group_layouts: &groups,
        immediate_size: 0,
    });
    Ok(match key.path {
        ConcretePath::Fragment => RaycastPipeline::Fragment(proxy_pipeline(
            device,
            &layout,
            &module,
            (
                super::variant::FRAGMENT_ENTRY,
                OUTPUT_FORMAT,
                wgpu::Face::Back,
            ),
            &label,
        )),
        ConcretePath::Compute => RaycastPipeline::Compute(device.create_compute_pipeline(
            &wgpu::ComputePipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(super::variant::COMPUTE_ENTRY),
                compilation_options: Default::default(),
                cache: None,
            },
        )),
    })
}
