//! WGSL to SPIR-V as wgpu's Vulkan backend writes it, and the descriptor set layouts of its
//! resources.

use ash::vk;
use naga::back::spv;

use super::PipelineStatsError;

/// What a physical device offers that the statistics device turns on, as wgpu would.
pub(super) struct Offer {
    /// `robustBufferAccess` (core).
    pub robust_buffer_access: bool,
    /// `robustBufferAccess2` (VK_EXT_robustness2): buffers read without bounds checks.
    pub robust_buffer_access2: bool,
    /// `robustImageAccess` (Vulkan 1.3): image loads without bounds checks.
    pub robust_image_access: bool,
    /// `shaderZeroInitializeWorkgroupMemory` (Vulkan 1.3).
    pub zero_initialize_workgroup_memory: bool,
    /// The device's Vulkan version: the SPIR-V version it takes.
    pub api_version: u32,
}

/// naga's SPIR-V options as wgpu's Vulkan backend sets them for a device offering `offer`.
pub(super) fn spirv_options(offer: &Offer) -> spv::Options<'static> {
    let lang_version = match offer.api_version {
        v if v >= vk::API_VERSION_1_3 => (1, 6),
        v if v >= vk::API_VERSION_1_2 => (1, 5),
        v if v >= vk::API_VERSION_1_1 => (1, 3),
        _ => (1, 0),
    };
    let unchecked_if = |robust: bool| {
        if robust {
            naga::proc::BoundsCheckPolicy::Unchecked
        } else {
            naga::proc::BoundsCheckPolicy::Restrict
        }
    };
    spv::Options {
        lang_version,
        flags: spv::WriterFlags::empty(),
        fake_missing_bindings: true,
        bounds_check_policies: naga::proc::BoundsCheckPolicies {
            index: naga::proc::BoundsCheckPolicy::Restrict,
            buffer: unchecked_if(offer.robust_buffer_access2),
            image_load: unchecked_if(offer.robust_image_access),
            binding_array: naga::proc::BoundsCheckPolicy::Unchecked,
        },
        zero_initialize_workgroup_memory: if offer.zero_initialize_workgroup_memory {
            spv::ZeroInitializeWorkgroupMemoryMode::Native
        } else {
            spv::ZeroInitializeWorkgroupMemoryMode::Polyfill
        },
        force_loop_bounding: true,
        emit_int_div_checks: true,
        ..spv::Options::default()
    }
}

/// The entry points of a pipeline.
#[derive(Clone, Copy, Debug)]
pub enum Stages<'a> {
    /// A compute pipeline of this entry point.
    Compute(&'a str),
    /// A graphics pipeline of these vertex and fragment entry points.
    Graphics {
        /// The vertex entry point.
        vertex: &'a str,
        /// The fragment entry point.
        fragment: &'a str,
    },
}

impl Stages<'_> {
    /// The stages a resource binding is visible to.
    fn visibility(self) -> vk::ShaderStageFlags {
        match self {
            Self::Compute(_) => vk::ShaderStageFlags::COMPUTE,
            Self::Graphics { .. } => vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
        }
    }
}

/// The SPIR-V of `wgsl`'s entry points `stages` (a compute entry point alone; a graphics
/// pipeline's two in one module), and the descriptor set layouts its resources need (one per
/// group, in group order; empty where a group has none).
pub(super) fn spirv_of(
    wgsl: &str,
    stages: Stages<'_>,
    options: &spv::Options<'_>,
) -> Result<(Vec<u32>, Vec<Vec<vk::DescriptorSetLayoutBinding<'static>>>), PipelineStatsError> {
    let module = naga::front::wgsl::parse_str(wgsl)
        .map_err(|e| PipelineStatsError::Shader(e.emit_to_string(wgsl)))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| PipelineStatsError::Shader(e.emit_to_string(wgsl)))?;
    let words = match stages {
        Stages::Compute(entry) => {
            let pipeline = spv::PipelineOptions {
                shader_stage: naga::ShaderStage::Compute,
                entry_point: entry.to_string(),
            };
            spv::write_vec(&module, &info, options, Some(&pipeline))
        }
        Stages::Graphics { vertex, fragment } => {
            for (stage, name) in [
                (naga::ShaderStage::Vertex, vertex),
                (naga::ShaderStage::Fragment, fragment),
            ] {
                if !module
                    .entry_points
                    .iter()
                    .any(|e| e.stage == stage && e.name == name)
                {
                    return Err(PipelineStatsError::Shader(format!(
                        "no {stage:?} entry point {name}"
                    )));
                }
            }
            // Every entry point of the module (the proxy's vertex stage and the ray loop's
            // fragment stage), as one module.
            spv::write_vec(&module, &info, options, None)
        }
    }
    .map_err(|e| PipelineStatsError::Shader(e.to_string()))?;
    let mut layouts: Vec<Vec<vk::DescriptorSetLayoutBinding<'static>>> = Vec::new();
    for (_, var) in module.global_variables.iter() {
        let Some(binding) = &var.binding else {
            continue;
        };
        let kind = match var.space {
            naga::AddressSpace::Uniform => vk::DescriptorType::UNIFORM_BUFFER,
            naga::AddressSpace::Storage { .. } => vk::DescriptorType::STORAGE_BUFFER,
            naga::AddressSpace::Handle => match &module.types[var.ty].inner {
                naga::TypeInner::Sampler { .. } => vk::DescriptorType::SAMPLER,
                naga::TypeInner::Image {
                    class: naga::ImageClass::Storage { .. },
                    ..
                } => vk::DescriptorType::STORAGE_IMAGE,
                naga::TypeInner::Image { .. } => vk::DescriptorType::SAMPLED_IMAGE,
                other => {
                    return Err(PipelineStatsError::Shader(format!(
                        "binding {}:{} of a kind not handled here: {other:?}",
                        binding.group, binding.binding
                    )));
                }
            },
            other => {
                return Err(PipelineStatsError::Shader(format!(
                    "binding {}:{} in address space {other:?}",
                    binding.group, binding.binding
                )));
            }
        };
        let group = binding.group as usize;
        if layouts.len() <= group {
            layouts.resize_with(group + 1, Vec::new);
        }
        layouts[group].push(
            vk::DescriptorSetLayoutBinding::default()
                .binding(binding.binding)
                .descriptor_type(kind)
                .descriptor_count(1)
                .stage_flags(stages.visibility()),
        );
    }
    Ok((words, layouts))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PipelineKey;
    use crate::render::raycast::variant::{COMPUTE_ENTRY, FRAGMENT_ENTRY, PROXY_VERTEX_ENTRY};
    use crate::settings::ConcretePath;

    /// A Vulkan 1.3 device with every robustness feature wgpu turns on, and a 1.1 device
    /// without them: the two sets of options wgpu's backend chooses between.
    fn offers() -> [Offer; 2] {
        [
            Offer {
                robust_buffer_access: true,
                robust_buffer_access2: true,
                robust_image_access: true,
                zero_initialize_workgroup_memory: true,
                api_version: vk::API_VERSION_1_3,
            },
            Offer {
                robust_buffer_access: true,
                robust_buffer_access2: false,
                robust_image_access: false,
                zero_initialize_workgroup_memory: false,
                api_version: vk::API_VERSION_1_1,
            },
        ]
    }

    /// Every ray-casting variant on `path`: six modes, four strategies, statistics or not, lit
    /// or not (and split or not) give far more than 20; fewer would mean the filter lost them.
    fn variants_on(path: ConcretePath) -> Vec<PipelineKey> {
        let keys: Vec<_> = PipelineKey::all()
            .into_iter()
            .filter(|k| k.path == path)
            .collect();
        assert!(keys.len() > 20, "{path:?}: {}", keys.len());
        keys
    }

    /// Every compute ray-casting variant translates to SPIR-V with either set of options, and
    /// the layouts name every resource the shader declares with the kind the renderer binds:
    /// the frame's uniforms, the volume, sampler and table textures in group 0, the output image
    /// in group 1, the counters in group 2 (statistics variants), the leaping structures in
    /// group 3 (leaping variants).
    #[test]
    fn every_compute_variant_becomes_spirv_with_its_resources_laid_out() {
        let keys = variants_on(ConcretePath::Compute);
        for offer in offers() {
            let options = spirv_options(&offer);
            for key in &keys {
                let source = key.source().expect("composes");
                let (words, layouts) = spirv_of(&source, Stages::Compute(COMPUTE_ENTRY), &options)
                    .unwrap_or_else(|e| panic!("{key:?}: {e}"));
                assert_eq!(words.first(), Some(&0x0723_0203), "SPIR-V magic");
                // A whole ray caster: 3976 to 10320 words over these variants (naga 30); a
                // tenth of the smallest would be a module missing its loop.
                assert!(words.len() > 400, "{key:?}: {} words", words.len());
                let kind = |group: usize, binding: u32| {
                    layouts.get(group).and_then(|g| {
                        g.iter()
                            .find(|b| b.binding == binding)
                            .map(|b| b.descriptor_type)
                    })
                };
                assert_eq!(kind(0, 0), Some(vk::DescriptorType::UNIFORM_BUFFER));
                assert_eq!(kind(0, 1), Some(vk::DescriptorType::SAMPLED_IMAGE));
                assert_eq!(kind(0, 2), Some(vk::DescriptorType::SAMPLER));
                assert_eq!(kind(1, 0), Some(vk::DescriptorType::STORAGE_IMAGE));
                assert_eq!(
                    kind(2, 0),
                    key.stats.then_some(vk::DescriptorType::STORAGE_BUFFER),
                    "{key:?}"
                );
                assert_eq!(
                    kind(3, 1),
                    key.strategy
                        .leaps()
                        .then_some(vk::DescriptorType::STORAGE_BUFFER),
                    "{key:?}"
                );
            }
        }
    }

    /// Every fragment-path variant translates to one SPIR-V module holding the proxy's vertex
    /// stage and the ray loop's fragment stage, its resources visible to both stages: the
    /// frame's uniforms and textures in group 0, the exit-point texture in group 1. A stage
    /// the module lacks is an error, not a module without it.
    #[test]
    fn every_fragment_variant_becomes_a_graphics_module() {
        let keys = variants_on(ConcretePath::Fragment);
        let stages = Stages::Graphics {
            vertex: PROXY_VERTEX_ENTRY,
            fragment: FRAGMENT_ENTRY,
        };
        let graphics = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        for offer in offers() {
            let options = spirv_options(&offer);
            for key in &keys {
                let source = key.source().expect("composes");
                let (words, layouts) =
                    spirv_of(&source, stages, &options).unwrap_or_else(|e| panic!("{key:?}: {e}"));
                assert_eq!(words.first(), Some(&0x0723_0203), "SPIR-V magic");
                assert!(words.len() > 400, "{key:?}: {} words", words.len());
                let binding = |group: usize, binding: u32| {
                    layouts
                        .get(group)
                        .and_then(|g| g.iter().find(|b| b.binding == binding))
                        .map(|b| (b.descriptor_type, b.stage_flags))
                };
                assert_eq!(
                    binding(0, 0),
                    Some((vk::DescriptorType::UNIFORM_BUFFER, graphics))
                );
                assert_eq!(
                    binding(1, 0),
                    Some((vk::DescriptorType::SAMPLED_IMAGE, graphics)),
                    "{key:?}: the exit points"
                );
            }
        }
        let source = keys[0].source().expect("composes");
        let missing = Stages::Graphics {
            vertex: PROXY_VERTEX_ENTRY,
            fragment: "fs_nowhere",
        };
        let options = spirv_options(&offers()[0]);
        assert!(matches!(
            spirv_of(&source, missing, &options),
            Err(PipelineStatsError::Shader(m)) if m.contains("fs_nowhere")
        ));
    }

    /// The options follow the device as wgpu's do: SPIR-V 1.6 on Vulkan 1.3, bounds checks on
    /// buffers and image loads only where the robustness features are missing, loops bounded.
    #[test]
    fn spirv_options_follow_the_device_as_wgpu_does() {
        let [full, bare] = offers();
        let full = spirv_options(&full);
        let bare = spirv_options(&bare);
        assert_eq!(full.lang_version, (1, 6));
        assert_eq!(bare.lang_version, (1, 3));
        use naga::proc::BoundsCheckPolicy::{Restrict, Unchecked};
        assert_eq!(full.bounds_check_policies.buffer, Unchecked);
        assert_eq!(full.bounds_check_policies.image_load, Unchecked);
        assert_eq!(bare.bounds_check_policies.buffer, Restrict);
        assert_eq!(bare.bounds_check_policies.image_load, Restrict);
        for o in [&full, &bare] {
            assert_eq!(o.bounds_check_policies.index, Restrict);
            assert!(o.force_loop_bounding);
        }
    }
}
