//! The ray caster's bind group layouts, each beside the constructor of its bind groups, so a
//! group's entries are written once, next to the layout they must match (the WGSL declarations
//! are in `shaders/shared/common.wgsl`, `shaders/entry/`, `shaders/shared/stats.wgsl` and
//! `shaders/leap/leap.wgsl`).

use wgpu::ShaderStages as S;

use crate::render::texture::OUTPUT_FORMAT;
use crate::render::volume_texture::VolumeView;

/// The bind group layouts shared by all ray-casting pipelines.
pub struct Layouts {
    /// Group 0: frame uniforms, volume, sampler, transfer-function table, pre-integration table,
    /// the volume's page table and geometry, its labels and their colours.
    pub frame: wgpu::BindGroupLayout,
    /// Group 1 of the fragment path: the exit-point texture.
    pub fragment_io: wgpu::BindGroupLayout,
    /// Group 1 of the compute path: the output image.
    pub compute_io: wgpu::BindGroupLayout,
    /// Group 2 of statistics variants: the counters.
    pub stats: wgpu::BindGroupLayout,
    /// Group 3 of leaping variants: pyramid levels, node flags, distances, node min/max, nodes
    /// holding a shown label.
    pub leap: wgpu::BindGroupLayout,
}

/// What group 0 binds: resources of the renderer (uniforms, sampler, the transfer function's
/// tables) and of the volume.
pub struct FrameResources<'a> {
    /// The frame uniforms.
    pub uniforms: &'a wgpu::Buffer,
    /// The volume (its texels, page table and geometry).
    pub volume: &'a VolumeView,
    /// The linear clamp-to-edge sampler.
    pub sampler: &'a wgpu::Sampler,
    /// The transfer function's lookup table.
    pub lut: &'a wgpu::TextureView,
    /// The pre-integration table.
    pub integrals: &'a wgpu::TextureView,
    /// The labels on the volume's grid, each label's colour, the label surfaces' mask and each
    /// label's class (its channel of the mask) (a 1³ texture of none, a 1 × 1 table, a 1³ mask
    /// and a 1 × 1 table without a segmentation or surfaces).
    pub labels: (
        &'a wgpu::TextureView,
        &'a wgpu::TextureView,
        &'a wgpu::TextureView,
        &'a wgpu::TextureView,
    ),
}

/// What group 3 binds: the leaping structures of one volume.
pub struct LeapResources<'a> {
    /// The pyramid's levels (`LevelInfo` per level).
    pub levels: &'a wgpu::Buffer,
    /// Per-node emptiness flags.
    pub node_empty: &'a wgpu::Buffer,
    /// The distance field over the leaf blocks.
    pub distance: &'a wgpu::Buffer,
    /// Per-node (min, max).
    pub minmax: &'a wgpu::Buffer,
    /// Per node, 1 where it holds a shown label (read by views cut to the shown labels).
    pub node_shown: &'a wgpu::Buffer,
}

/// The stages that run the ray loop.
const RAY_LOOP: S = S::FRAGMENT.union(S::COMPUTE);

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

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: RAY_LOOP,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries,
    })
}

fn group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource<'_>],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry<'_>> = resources
        .iter()
        .enumerate()
        .map(|(binding, resource)| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: resource.clone(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

impl Layouts {
    /// Creates the layouts.
    pub fn new(device: &wgpu::Device) -> Self {
        use wgpu::TextureViewDimension::{D2, D3};
        let frame = layout(
            device,
            "frame",
            &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: S::VERTEX | RAY_LOOP,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture_entry(1, D3, true, RAY_LOOP),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: RAY_LOOP,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                texture_entry(3, D2, true, RAY_LOOP),
                texture_entry(4, D2, false, RAY_LOOP),
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: RAY_LOOP,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: true },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 6,
                    visibility: RAY_LOOP,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 7,
                    visibility: RAY_LOOP,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: D3,
                        multisampled: false,
                    },
                    count: None,
                },
                texture_entry(8, D2, false, RAY_LOOP),
                texture_entry(9, D3, true, RAY_LOOP),
                wgpu::BindGroupLayoutEntry {
                    binding: 10,
                    visibility: RAY_LOOP,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        );
        let fragment_io = layout(
            device,
            "fragment io",
            &[texture_entry(0, D2, false, S::FRAGMENT)],
        );
        let compute_io = layout(
            device,
            "compute io",
            &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: S::COMPUTE,
                ty: wgpu::BindingType::StorageTexture {
                    access: wgpu::StorageTextureAccess::WriteOnly,
                    format: OUTPUT_FORMAT,
                    view_dimension: D2,
                },
                count: None,
            }],
        );
        let stats = layout(device, "stats", &[storage_entry(0, false)]);
        let leap = layout(
            device,
            "leap",
            &[0, 1, 2, 3, 4].map(|binding| storage_entry(binding, true)),
        );
        Self {
            frame,
            fragment_io,
            compute_io,
            stats,
            leap,
        }
    }

    /// Group 0 for one volume.
    pub(crate) fn frame_group(
        &self,
        device: &wgpu::Device,
        r: &FrameResources<'_>,
    ) -> wgpu::BindGroup {
        use wgpu::BindingResource::{Sampler, TextureView};
        group(
            device,
            "frame",
            &self.frame,
            &[
                r.uniforms.as_entire_binding(),
                TextureView(&r.volume.texels),
                Sampler(r.sampler),
                TextureView(r.lut),
                TextureView(r.integrals),
                r.volume.pages.as_entire_binding(),
                r.volume.geometry.as_entire_binding(),
                TextureView(r.labels.0),
                TextureView(r.labels.1),
                TextureView(r.labels.2),
                TextureView(r.labels.3),
            ],
        )
    }

    /// Group 1 of the fragment path: the exit points of one image size.
    pub(crate) fn fragment_io_group(
        &self,
        device: &wgpu::Device,
        exit: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        let exit = wgpu::BindingResource::TextureView(exit);
        group(device, "fragment io", &self.fragment_io, &[exit])
    }

    /// Group 1 of the compute path: the output image of one image size.
    pub(crate) fn compute_io_group(
        &self,
        device: &wgpu::Device,
        output: &wgpu::TextureView,
    ) -> wgpu::BindGroup {
        let output = wgpu::BindingResource::TextureView(output);
        group(device, "compute io", &self.compute_io, &[output])
    }

    /// Group 2: the statistics counters.
    pub(crate) fn stats_group(
        &self,
        device: &wgpu::Device,
        counters: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        group(
            device,
            "stats",
            &self.stats,
            &[counters.as_entire_binding()],
        )
    }

    /// Group 3: one volume's leaping structures.
    pub(crate) fn leap_group(
        &self,
        device: &wgpu::Device,
        r: &LeapResources<'_>,
    ) -> wgpu::BindGroup {
        group(
            device,
            "leap",
            &self.leap,
            &[
                r.levels.as_entire_binding(),
                r.node_empty.as_entire_binding(),
                r.distance.as_entire_binding(),
                r.minmax.as_entire_binding(),
                r.node_shown.as_entire_binding(),
            ],
        )
    }
}
