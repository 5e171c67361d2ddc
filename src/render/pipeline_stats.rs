//! What the driver says of a compiled compute shader: registers, instructions, spills, shared
//! memory, whatever statistics it reports through `VK_KHR_pipeline_executable_properties`.
//!
//! wgpu exposes no pipeline statistics, so this opens a Vulkan device of its own (ash), turns the
//! composed WGSL into SPIR-V with naga as wgpu's Vulkan backend does (the same bounds-check
//! policies for the robustness features it enables, loop bounding, integer-division checks) and
//! builds the compute pipeline with `CAPTURE_STATISTICS`. It renders nothing: it is how to see
//! why one ray-casting variant runs slower per sample than another (how many registers each
//! invocation holds decides how many rays an SM keeps in flight).

use std::ffi::{CStr, CString, c_char};

use ash::vk;
use naga::back::spv;

/// Why the statistics could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PipelineStatsError {
    /// No Vulkan loader on this machine.
    #[error("no Vulkan loader: {0}")]
    Loader(String),
    /// A Vulkan call failed.
    #[error("Vulkan: {what} failed: {result}")]
    Vulkan {
        /// The call.
        what: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// No device reports pipeline statistics (the extension is missing).
    #[error(
        "no Vulkan device here reports pipeline statistics (VK_KHR_pipeline_executable_properties); devices: {0}"
    )]
    Unsupported(String),
    /// No device's name contains the one asked for.
    #[error("no Vulkan device named like {asked:?} reports pipeline statistics; devices: {found}")]
    NoSuchDevice {
        /// The name asked for.
        asked: String,
        /// The devices there are.
        found: String,
    },
    /// The WGSL did not parse, validate or translate.
    #[error("shader: {0}")]
    Shader(String),
}

/// One statistic's value, in the format the driver gives it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(untagged)]
pub enum StatValue {
    /// A yes/no.
    Bool(bool),
    /// A signed count.
    Int(i64),
    /// An unsigned count.
    Uint(u64),
    /// A measure.
    Float(f64),
}

impl std::fmt::Display for StatValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Bool(b) => write!(f, "{b}"),
            Self::Int(v) => write!(f, "{v}"),
            Self::Uint(v) => write!(f, "{v}"),
            Self::Float(v) => write!(f, "{v:.3}"),
        }
    }
}

/// One statistic of one executable.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Statistic {
    /// The driver's name for it ("Register Count", …).
    pub name: String,
    /// The driver's description.
    pub description: String,
    /// Its value.
    pub value: StatValue,
}

/// One executable of a pipeline (a compute pipeline has one; some drivers report more) and its
/// statistics.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Executable {
    /// The driver's name for it.
    pub name: String,
    /// The driver's description.
    pub description: String,
    /// The subgroup size it was compiled for.
    pub subgroup_size: u32,
    /// Its statistics, in the driver's order.
    pub statistics: Vec<Statistic>,
}

/// A Vulkan device of its own that reports pipeline statistics.
pub struct StatsDevice {
    // The loader: it must stay loaded until the instance is destroyed (fields drop after Drop).
    _entry: ash::Entry,
    instance: ash::Instance,
    device: ash::Device,
    executables: ash::khr::pipeline_executable_properties::Device,
    name: String,
    driver: String,
    options: spv::Options<'static>,
}

/// What a physical device offers that the statistics device turns on, as wgpu would.
struct Offer {
    robust_buffer_access: bool,
    robust_buffer_access2: bool,
    robust_image_access: bool,
    zero_initialize_workgroup_memory: bool,
    api_version: u32,
}

fn vk_err(what: &'static str) -> impl Fn(vk::Result) -> PipelineStatsError {
    move |result| PipelineStatsError::Vulkan { what, result }
}

/// A fixed-size C string of Vulkan's as a Rust string.
fn text(chars: &[c_char]) -> String {
    let bytes: Vec<u8> = chars
        .iter()
        .take_while(|&&c| c != 0)
        .map(|&c| c as u8)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

impl StatsDevice {
    /// Opens the first device that reports pipeline statistics: a discrete GPU before others,
    /// or, with `name_like`, the first whose name contains it (case-insensitive).
    pub fn open(name_like: Option<&str>) -> Result<Self, PipelineStatsError> {
        // SAFETY: loading the Vulkan loader library runs its initialisers; it is the system's
        // loader, as wgpu loads it.
        let entry =
            unsafe { ash::Entry::load() }.map_err(|e| PipelineStatsError::Loader(e.to_string()))?;
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
        let info = vk::InstanceCreateInfo::default().application_info(&app);
        // SAFETY: valid create info; the instance is destroyed in Drop (or below on failure).
        let instance =
            unsafe { entry.create_instance(&info, None) }.map_err(vk_err("vkCreateInstance"))?;
        let opened =
            Self::pick(&instance, name_like).and_then(|(physical, name, driver, offer)| {
                Self::create_device(&instance, physical, &offer)
                    .map(|device| (device, name, driver, offer))
            });
        match opened {
            Ok((device, name, driver, offer)) => {
                let executables =
                    ash::khr::pipeline_executable_properties::Device::new(&instance, &device);
                Ok(Self {
                    _entry: entry,
                    instance,
                    device,
                    executables,
                    name,
                    driver,
                    options: spirv_options(&offer),
                })
            }
            Err(e) => {
                // SAFETY: nothing created from the instance outlives it here, and the loader
                // (`entry`) is still loaded.
                unsafe { instance.destroy_instance(None) };
                Err(e)
            }
        }
    }

    fn pick(
        instance: &ash::Instance,
        name_like: Option<&str>,
    ) -> Result<(vk::PhysicalDevice, String, String, Offer), PipelineStatsError> {
        // SAFETY: the instance is valid.
        let physicals = unsafe { instance.enumerate_physical_devices() }
            .map_err(vk_err("vkEnumeratePhysicalDevices"))?;
        let mut found = Vec::new();
        let mut candidates = Vec::new();
        for physical in physicals {
            // SAFETY: a physical device of this instance.
            let props = unsafe { instance.get_physical_device_properties(physical) };
            let name = text(&props.device_name);
            found.push(name.clone());
            // SAFETY: as above.
            let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }
                .map_err(vk_err("vkEnumerateDeviceExtensionProperties"))?;
            let has = |wanted: &CStr| {
                extensions
                    .iter()
                    .any(|e| e.extension_name_as_c_str() == Ok(wanted))
            };
            if !has(ash::khr::pipeline_executable_properties::NAME) {
                continue;
            }
            if let Some(like) = name_like
                && !name.to_lowercase().contains(&like.to_lowercase())
            {
                continue;
            }
            let api_version = props.api_version;
            if api_version < vk::API_VERSION_1_1 {
                // Its features can only be asked through vkGetPhysicalDeviceFeatures2 from 1.1.
                continue;
            }
            let mut robustness2 = vk::PhysicalDeviceRobustness2FeaturesEXT::default();
            let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
            let mut executable_info =
                vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default();
            let has_robustness2 = has(ash::ext::robustness2::NAME);
            {
                let mut features2 =
                    vk::PhysicalDeviceFeatures2::default().push_next(&mut executable_info);
                if has_robustness2 {
                    features2 = features2.push_next(&mut robustness2);
                }
                if api_version >= vk::API_VERSION_1_3 {
                    features2 = features2.push_next(&mut v13);
                }
                // SAFETY: a valid chain of feature structs.
                unsafe { instance.get_physical_device_features2(physical, &mut features2) };
                let robust_buffer_access = features2.features.robust_buffer_access != 0;
                if executable_info.pipeline_executable_info == 0 {
                    continue;
                }
                let offer = Offer {
                    robust_buffer_access,
                    // It needs robustBufferAccess on too.
                    robust_buffer_access2: has_robustness2
                        && robust_buffer_access
                        && robustness2.robust_buffer_access2 != 0,
                    robust_image_access: api_version >= vk::API_VERSION_1_3
                        && v13.robust_image_access != 0,
                    zero_initialize_workgroup_memory: api_version >= vk::API_VERSION_1_3
                        && v13.shader_zero_initialize_workgroup_memory != 0,
                    api_version,
                };
                let discrete = props.device_type == vk::PhysicalDeviceType::DISCRETE_GPU;
                let driver = format!(
                    "Vulkan {}.{}.{}, driver version {:#x}",
                    vk::api_version_major(api_version),
                    vk::api_version_minor(api_version),
                    vk::api_version_patch(api_version),
                    props.driver_version
                );
                candidates.push((discrete, physical, name, driver, offer));
            }
        }
        let found = found.join(", ");
        if candidates.is_empty() {
            return Err(match name_like {
                Some(asked) => PipelineStatsError::NoSuchDevice {
                    asked: asked.to_string(),
                    found,
                },
                None => PipelineStatsError::Unsupported(found),
            });
        }
        // A discrete GPU first, then in the loader's order.
        let best = candidates.iter().position(|c| c.0).unwrap_or_default();
        let (_, physical, name, driver, offer) = candidates.swap_remove(best);
        Ok((physical, name, driver, offer))
    }

    fn create_device(
        instance: &ash::Instance,
        physical: vk::PhysicalDevice,
        offer: &Offer,
    ) -> Result<ash::Device, PipelineStatsError> {
        let priorities = [1.0f32];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(0)
            .queue_priorities(&priorities)];
        let mut extensions: Vec<*const c_char> =
            vec![ash::khr::pipeline_executable_properties::NAME.as_ptr()];
        if offer.robust_buffer_access2 {
            extensions.push(ash::ext::robustness2::NAME.as_ptr());
        }
        let mut executable_info =
            vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
                .pipeline_executable_info(true);
        let mut robustness2 = vk::PhysicalDeviceRobustness2FeaturesEXT::default()
            .robust_buffer_access2(offer.robust_buffer_access2);
        let mut v13 = vk::PhysicalDeviceVulkan13Features::default()
            .robust_image_access(offer.robust_image_access)
            .shader_zero_initialize_workgroup_memory(offer.zero_initialize_workgroup_memory);
        let features =
            vk::PhysicalDeviceFeatures::default().robust_buffer_access(offer.robust_buffer_access);
        let mut info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .enabled_extension_names(&extensions)
            .enabled_features(&features)
            .push_next(&mut executable_info);
        if offer.robust_buffer_access2 {
            info = info.push_next(&mut robustness2);
        }
        if offer.api_version >= vk::API_VERSION_1_3 {
            info = info.push_next(&mut v13);
        }
        // SAFETY: the extensions and features were checked on this physical device.
        unsafe { instance.create_device(physical, &info, None) }.map_err(vk_err("vkCreateDevice"))
    }

    /// The device's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The device's Vulkan and driver versions.
    pub fn driver(&self) -> &str {
        &self.driver
    }

    /// Compiles `wgsl`'s compute entry point `entry` and returns what the driver says of it.
    pub fn compute_statistics(
        &self,
        wgsl: &str,
        entry: &str,
    ) -> Result<Vec<Executable>, PipelineStatsError> {
        let (words, layouts) = spirv_of(wgsl, entry, &self.options)?;
        let mut made = Made::new(&self.device);
        let result = self.build_and_ask(&words, &layouts, entry, &mut made);
        made.destroy();
        result
    }

    fn build_and_ask(
        &self,
        words: &[u32],
        layouts: &[Vec<vk::DescriptorSetLayoutBinding<'static>>],
        entry: &str,
        made: &mut Made<'_>,
    ) -> Result<Vec<Executable>, PipelineStatsError> {
        let device = &self.device;
        for bindings in layouts {
            let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(bindings);
            // SAFETY: valid create info; destroyed by `made`.
            let layout = unsafe { device.create_descriptor_set_layout(&info, None) }
                .map_err(vk_err("vkCreateDescriptorSetLayout"))?;
            made.set_layouts.push(layout);
        }
        let info = vk::PipelineLayoutCreateInfo::default().set_layouts(&made.set_layouts);
        // SAFETY: as above.
        made.layout = Some(
            unsafe { device.create_pipeline_layout(&info, None) }
                .map_err(vk_err("vkCreatePipelineLayout"))?,
        );
        let info = vk::ShaderModuleCreateInfo::default().code(words);
        // SAFETY: SPIR-V written and validated by naga.
        made.module = Some(
            unsafe { device.create_shader_module(&info, None) }
                .map_err(vk_err("vkCreateShaderModule"))?,
        );
        let name = CString::new(entry).map_err(|e| PipelineStatsError::Shader(e.to_string()))?;
        let (Some(module), Some(layout)) = (made.module, made.layout) else {
            return Err(PipelineStatsError::Shader("no module".into()));
        };
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(&name);
        let info = vk::ComputePipelineCreateInfo::default()
            .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR)
            .stage(stage)
            .layout(layout);
        // SAFETY: as above.
        let pipelines =
            unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) }
                .map_err(|(_, result)| PipelineStatsError::Vulkan {
                    what: "vkCreateComputePipelines",
                    result,
                })?;
        made.pipelines.extend(&pipelines);
        let pipeline = pipelines
            .first()
            .copied()
            .ok_or(PipelineStatsError::Vulkan {
                what: "vkCreateComputePipelines",
                result: vk::Result::ERROR_UNKNOWN,
            })?;
        let ask = vk::PipelineInfoKHR::default().pipeline(pipeline);
        // SAFETY: a pipeline created with CAPTURE_STATISTICS on a device with the feature on.
        let properties = unsafe { self.executables.get_pipeline_executable_properties(&ask) }
            .map_err(vk_err("vkGetPipelineExecutablePropertiesKHR"))?;
        let mut executables = Vec::with_capacity(properties.len());
        for (index, props) in properties.iter().enumerate() {
            let which = vk::PipelineExecutableInfoKHR::default()
                .pipeline(pipeline)
                .executable_index(u32::try_from(index).unwrap_or(u32::MAX));
            // SAFETY: as above; the index is one the driver listed.
            let statistics = unsafe { self.executables.get_pipeline_executable_statistics(&which) }
                .map_err(vk_err("vkGetPipelineExecutableStatisticsKHR"))?;
            executables.push(Executable {
                name: text(&props.name),
                description: text(&props.description),
                subgroup_size: props.subgroup_size,
                statistics: statistics.iter().map(statistic).collect(),
            });
        }
        Ok(executables)
    }
}

impl Drop for StatsDevice {
    fn drop(&mut self) {
        // SAFETY: every object made from the device was destroyed by `Made`; the device and then
        // the instance go last.
        unsafe {
            self.device.destroy_device(None);
            self.instance.destroy_instance(None);
        }
    }
}

/// What one compilation created, destroyed together whatever happened.
struct Made<'a> {
    device: &'a ash::Device,
    set_layouts: Vec<vk::DescriptorSetLayout>,
    layout: Option<vk::PipelineLayout>,
    module: Option<vk::ShaderModule>,
    pipelines: Vec<vk::Pipeline>,
}

impl<'a> Made<'a> {
    fn new(device: &'a ash::Device) -> Self {
        Self {
            device,
            set_layouts: Vec::new(),
            layout: None,
            module: None,
            pipelines: Vec::new(),
        }
    }

    fn destroy(self) {
        // SAFETY: all were created from `device`, none is in use (nothing was submitted).
        unsafe {
            for &p in &self.pipelines {
                self.device.destroy_pipeline(p, None);
            }
            if let Some(m) = self.module {
                self.device.destroy_shader_module(m, None);
            }
            if let Some(l) = self.layout {
                self.device.destroy_pipeline_layout(l, None);
            }
            for &l in &self.set_layouts {
                self.device.destroy_descriptor_set_layout(l, None);
            }
        }
    }
}

fn statistic(s: &vk::PipelineExecutableStatisticKHR<'_>) -> Statistic {
    // SAFETY: the union member read is the one `format` names.
    let value = unsafe {
        match s.format {
            vk::PipelineExecutableStatisticFormatKHR::BOOL32 => StatValue::Bool(s.value.b32 != 0),
            vk::PipelineExecutableStatisticFormatKHR::INT64 => StatValue::Int(s.value.i64),
            vk::PipelineExecutableStatisticFormatKHR::FLOAT64 => StatValue::Float(s.value.f64),
            _ => StatValue::Uint(s.value.u64),
        }
    };
    Statistic {
        name: text(&s.name),
        description: text(&s.description),
        value,
    }
}

/// naga's SPIR-V options as wgpu's Vulkan backend sets them for a device offering `offer`.
fn spirv_options(offer: &Offer) -> spv::Options<'static> {
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

/// The SPIR-V of `wgsl`'s compute entry point `entry`, and the descriptor set layouts its
/// resources need (one per group, in group order; empty where a group has none).
fn spirv_of(
    wgsl: &str,
    entry: &str,
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
    let pipeline = spv::PipelineOptions {
        shader_stage: naga::ShaderStage::Compute,
        entry_point: entry.to_string(),
    };
    let words = spv::write_vec(&module, &info, options, Some(&pipeline))
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
                .stage_flags(vk::ShaderStageFlags::COMPUTE),
        );
    }
    Ok((words, layouts))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PipelineKey;
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

    /// Every compute ray-casting variant translates to SPIR-V with either set of options, and
    /// the layouts name every resource the shader declares with the kind the renderer binds:
    /// the frame's uniforms, the volume, sampler and table textures in group 0, the output image
    /// in group 1, the counters in group 2 (statistics variants), the leaping structures in
    /// group 3 (leaping variants).
    #[test]
    fn every_compute_variant_becomes_spirv_with_its_resources_laid_out() {
        let keys: Vec<_> = PipelineKey::all()
            .into_iter()
            .filter(|k| k.path == ConcretePath::Compute)
            .collect();
        assert!(keys.len() > 20, "{}", keys.len());
        for offer in offers() {
            let options = spirv_options(&offer);
            for key in &keys {
                let source = key.source().expect("composes");
                let (words, layouts) = spirv_of(&source, "cs_raycast", &options)
                    .unwrap_or_else(|e| panic!("{key:?}: {e}"));
                assert_eq!(words.first(), Some(&0x0723_0203), "SPIR-V magic");
                assert!(words.len() > 1000, "{key:?}: {} words", words.len());
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
