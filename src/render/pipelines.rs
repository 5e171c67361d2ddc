//! Pipeline variants: one per key {mode, strategy, path, stats}, composed from the shared WGSL
//! modules, created on first use and cached; plus the two proxy pipelines that rasterise ray
//! entry and exit points.

use std::collections::HashMap;

use super::effects::{GradientScheme, MipColor, Shading};
use super::settings::{Mode, RenderSettings, Strategy};
use super::shader::{ShaderError, compose};

/// Format of the exit- and entry-point textures: box coordinates need f32 (f16 would put them
/// an eighth of a voxel off in a 256³ volume).
pub const POSITION_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Format of the rendered image: blendable, filterable (for the window) and a storage format.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Compute workgroup edge (must match `@workgroup_size` in raycast_compute.wgsl).
pub const WORKGROUP: u32 = 8;
/// Number of 64-bit counters in the statistics buffer (see shaders/stats.wgsl).
pub const COUNTERS: usize = 5;

/// Where the ray loop runs, once `auto` has been resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ConcretePath {
    /// In the fragment shader of the front faces.
    Fragment,
    /// In a compute shader, one invocation per pixel, each intersecting its ray with the box.
    Compute,
}

/// Identifies one ray-casting pipeline variant. Build it with [`PipelineKey::new`], which drops
/// what a mode does not use (lighting outside DVR and isosurfaces, MIP colouring outside MIP), so
/// equal scenes share one pipeline and no variant carries code it cannot run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PipelineKey {
    /// Visual effect.
    pub mode: Mode,
    /// Work-saving strategy.
    pub strategy: Strategy,
    /// Fragment or compute.
    pub path: ConcretePath,
    /// Whether the variant counts samples (atomics); normal variants carry no counting code.
    pub stats: bool,
    /// Lighting (always `Off` for modes that cannot light).
    pub shading: Shading,
    /// Gradient estimator (always `Central` when unlit).
    pub gradient: GradientScheme,
    /// MIP/MinIP colouring (always `Window` in other modes).
    pub mip_color: MipColor,
    /// Pre-integrated classification (DVR only).
    pub preintegrated: bool,
}

impl PipelineKey {
    /// The variant for `settings` on `path`.
    pub fn new(settings: &RenderSettings, path: ConcretePath, stats: bool) -> Self {
        let shading = if settings.mode.can_shade() {
            settings.shading
        } else {
            Shading::Off
        };
        Self {
            mode: settings.mode,
            strategy: settings.strategy.for_mode(settings.mode),
            path,
            stats,
            shading,
            gradient: if shading == Shading::Phong {
                settings.gradient
            } else {
                GradientScheme::Central
            },
            mip_color: if matches!(settings.mode, Mode::Mip | Mode::MinIp) {
                settings.mip_color
            } else {
                MipColor::Window
            },
            preintegrated: settings.preintegrated && settings.mode == Mode::Dvr,
        }
    }

    /// Every distinct variant, for validation tests.
    pub fn all() -> Vec<Self> {
        let mut keys = Vec::new();
        for mode in Mode::ALL {
            for strategy in Strategy::ALL {
                for path in [ConcretePath::Fragment, ConcretePath::Compute] {
                    for stats in [false, true] {
                        for shading in [Shading::Off, Shading::Phong] {
                            for gradient in [GradientScheme::Central, GradientScheme::FourthOrder] {
                                for (mip_color, preintegrated) in [
                                    (MipColor::Window, false),
                                    (MipColor::Tf, false),
                                    (MipColor::Window, true),
                                ] {
                                    let settings = RenderSettings {
                                        mode,
                                        strategy,
                                        shading,
                                        gradient,
                                        mip_color,
                                        preintegrated,
                                        ..RenderSettings::default()
                                    };
                                    if settings.validate().is_err() {
                                        continue;
                                    }
                                    let key = Self::new(&settings, path, stats);
                                    if !keys.contains(&key) {
                                        keys.push(key);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        keys
    }

    /// The preprocessor symbols this variant is compiled with.
    pub fn defines(&self) -> Vec<&'static str> {
        let mut defines = Vec::new();
        defines.push(match self.mode {
            Mode::Dvr => "MODE_DVR",
            Mode::Iso => "MODE_ISO",
            Mode::Mip => "MODE_MIP",
            Mode::MinIp => "MODE_MINIP",
            Mode::Xray => "MODE_XRAY",
            Mode::XrayAttenuation => "MODE_XRAY_ATTENUATION",
        });
        if self.shading == Shading::Phong {
            defines.push("SHADING");
        }
        if self.gradient == GradientScheme::FourthOrder {
            defines.push("GRADIENT_FOURTH_ORDER");
        }
        if self.mip_color == MipColor::Tf {
            defines.push("MIP_TF_COLOR");
        }
        if self.strategy.terminates_early() {
            defines.push("EARLY_TERMINATION");
        }
        if self.strategy.leaps() {
            defines.push("LEAP");
        }
        if self.strategy == Strategy::RcSDistance {
            defines.push("LEAP_DISTANCE");
        }
        if self.stats {
            defines.push("STATS");
        }
        if self.preintegrated {
            defines.push("PREINTEGRATED");
        }
        defines
    }

    /// The composed WGSL of this variant.
    pub fn source(&self) -> Result<String, ShaderError> {
        let entry = match self.path {
            ConcretePath::Fragment => "raycast_fragment.wgsl",
            ConcretePath::Compute => "raycast_compute.wgsl",
        };
        compose(entry, &self.defines())
    }
}

/// The bind group layouts shared by all pipelines.
pub struct Layouts {
    /// Group 0: frame uniforms, volume, sampler, transfer-function table, pre-integration table.
    pub frame: wgpu::BindGroupLayout,
    /// Group 1 of the fragment path: the exit-point texture.
    pub fragment_io: wgpu::BindGroupLayout,
    /// Group 1 of the compute path: the output image.
    pub compute_io: wgpu::BindGroupLayout,
    /// Group 2 of statistics variants: the counters.
    pub stats: wgpu::BindGroupLayout,
    /// Group 3 of leaping variants: pyramid levels, node flags, distances.
    pub leap: wgpu::BindGroupLayout,
}

fn texture_entry(
    binding: u32,
    dim: wgpu::TextureViewDimension,
    filterable: bool,
    visibility: wgpu::ShaderStages,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable },
            view_dimension: dim,
            multisampled: false,
        },
        count: None,
    }
}

impl Layouts {
    /// Creates the layouts.
    pub fn new(device: &wgpu::Device) -> Self {
        use wgpu::ShaderStages as S;
        let shading = S::FRAGMENT | S::COMPUTE;
        let frame = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: S::VERTEX | shading,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture_entry(1, wgpu::TextureViewDimension::D3, true, shading),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: shading,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                texture_entry(3, wgpu::TextureViewDimension::D2, true, shading),
                texture_entry(4, wgpu::TextureViewDimension::D2, false, shading),
            ],
        });
        let fragment_io = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("fragment io"),
            entries: &[texture_entry(
                0,
                wgpu::TextureViewDimension::D2,
                false,
                S::FRAGMENT,
            )],
        });
        let compute_io = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compute io"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: S::COMPUTE,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: OUTPUT_FORMAT,
                    view_dimension: wgpu::TextureViewDimension::D2,
                },
                count: None,
            }],
        });
        let stats = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("stats"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: shading,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: false },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let storage = |binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: shading,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: true },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let leap = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("leap"),
            entries: &[storage(0), storage(1), storage(2), storage(3)],
        });
        Self {
            frame,
            fragment_io,
            compute_io,
            stats,
            leap,
        }
    }
}

/// The pipeline that rasterises the back faces into exit points (pass 1 of the fragment path;
/// the compute path intersects each ray with the box itself).
pub struct ProxyPipelines {
    /// Pass 1 of the fragment path.
    pub exit: wgpu::RenderPipeline,
}

fn proxy_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fragment: &str,
    target: wgpu::TextureFormat,
    cull: wgpu::Face,
    label: &str,
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_proxy"),
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

impl ProxyPipelines {
    /// Creates the proxy pipeline.
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Result<Self, ShaderError> {
        let source = compose("proxy_passes.wgsl", &[])?;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("proxy passes"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("proxy"),
            bind_group_layouts: &[Some(&layouts.frame)],
            immediate_size: 0,
        });
        Ok(Self {
            exit: proxy_pipeline(
                device,
                &layout,
                &module,
                "fs_exit",
                POSITION_FORMAT,
                wgpu::Face::Front,
                "exit points",
            ),
        })
    }
}

/// A compiled ray-casting variant.
pub enum RaycastPipeline {
    /// Fragment path: drawn over the front faces and cap.
    Fragment(wgpu::RenderPipeline),
    /// Compute path: dispatched over the image.
    Compute(wgpu::ComputePipeline),
}

/// Lazily built ray-casting pipelines, by key.
#[derive(Default)]
pub struct PipelineCache {
    pipelines: HashMap<PipelineKey, RaycastPipeline>,
}

impl PipelineCache {
    /// The pipeline for `key`, building it on first use.
    pub fn get(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        key: PipelineKey,
    ) -> Result<&RaycastPipeline, ShaderError> {
        Ok(match self.pipelines.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => e.insert(build(device, layouts, key)?),
        })
    }

    /// Number of pipelines built so far.
    pub fn len(&self) -> usize {
        self.pipelines.len()
    }

    /// Whether no pipeline has been built yet.
    pub fn is_empty(&self) -> bool {
        self.pipelines.is_empty()
    }
}

fn build(
    device: &wgpu::Device,
    layouts: &Layouts,
    key: PipelineKey,
) -> Result<RaycastPipeline, ShaderError> {
    let label = format!("{key:?}");
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(&label),
        source: wgpu::ShaderSource::Wgsl(key.source()?.into()),
    });
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
        ConcretePath::Fragment => RaycastPipeline::Fragment(device.create_render_pipeline(
            &wgpu::RenderPipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_proxy"),
                    buffers: &[],
                    compilation_options: Default::default(),
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: Some(wgpu::Face::Back),
                    ..Default::default()
                },
                depth_stencil: None,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_raycast"),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: OUTPUT_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                    compilation_options: Default::default(),
                }),
                multiview_mask: None,
                cache: None,
            },
        )),
        ConcretePath::Compute => RaycastPipeline::Compute(device.create_compute_pipeline(
            &wgpu::ComputePipelineDescriptor {
                label: Some(&label),
                layout: Some(&layout),
                module: &module,
                entry_point: Some("cs_raycast"),
                compilation_options: Default::default(),
                cache: None,
            },
        )),
    })
}
