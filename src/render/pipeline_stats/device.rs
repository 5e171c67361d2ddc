//! The Vulkan device of [`super`]: opened beside wgpu's, asked for the statistics of each
//! pipeline it compiles.

use std::ffi::{CStr, CString, c_char};

use ash::vk;
use naga::back::spv;

use super::spirv::{Offer, Stages, spirv_of, spirv_options};
use super::{Executable, PipelineStatsError, StatValue, Statistic};

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

/// A colour format of wgpu's as Vulkan names it (the renderer's output format among them: the
/// colour attachment a fragment ray-casting pipeline is compiled for).
fn vk_format(format: wgpu::TextureFormat) -> Option<vk::Format> {
    match format {
        wgpu::TextureFormat::Rgba16Float => Some(vk::Format::R16G16B16A16_SFLOAT),
        wgpu::TextureFormat::Rgba32Float => Some(vk::Format::R32G32B32A32_SFLOAT),
        wgpu::TextureFormat::Rgba8Unorm => Some(vk::Format::R8G8B8A8_UNORM),
        _ => None,
    }
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

    /// Compiles `wgsl`'s entry points `stages` into a pipeline (a graphics pipeline drawing
    /// triangles without vertex buffers into one colour attachment of the renderer's output
    /// format, as the fragment ray-casting path does) and returns what the driver says of each of
    /// its executables.
    pub fn statistics(
        &self,
        wgsl: &str,
        stages: Stages<'_>,
    ) -> Result<Vec<Executable>, PipelineStatsError> {
        let output = crate::render::texture::OUTPUT_FORMAT;
        let color = vk_format(output).ok_or_else(|| {
            PipelineStatsError::Shader(format!(
                "the output format {output:?} has no Vulkan name here"
            ))
        })?;
        let (words, layouts) = spirv_of(wgsl, stages, &self.options)?;
        let mut made = Made::new(&self.device);
        let result = self
            .build(&words, &layouts, stages, color, &mut made)
            .and_then(|pipeline| self.ask(pipeline));
        made.destroy();
        result
    }

    /// Creates the layouts, the module and the pipeline (all owned by `made`).
    fn build(
        &self,
        words: &[u32],
        layouts: &[Vec<vk::DescriptorSetLayoutBinding<'static>>],
        stages: Stages<'_>,
        color: vk::Format,
        made: &mut Made<'_>,
    ) -> Result<vk::Pipeline, PipelineStatsError> {
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
        let layout = unsafe { device.create_pipeline_layout(&info, None) }
            .map_err(vk_err("vkCreatePipelineLayout"))?;
        made.layout = Some(layout);
        let info = vk::ShaderModuleCreateInfo::default().code(words);
        // SAFETY: SPIR-V written and validated by naga.
        let module = unsafe { device.create_shader_module(&info, None) }
            .map_err(vk_err("vkCreateShaderModule"))?;
        made.module = Some(module);
        let c_name =
            |name: &str| CString::new(name).map_err(|e| PipelineStatsError::Shader(e.to_string()));
        let pipelines = match stages {
            Stages::Compute(entry) => {
                let name = c_name(entry)?;
                let stage = vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::COMPUTE)
                    .module(module)
                    .name(&name);
                let info = vk::ComputePipelineCreateInfo::default()
                    .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR)
                    .stage(stage)
                    .layout(layout);
                // SAFETY: as above.
                unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) }
                    .map_err(|(_, result)| PipelineStatsError::Vulkan {
                        what: "vkCreateComputePipelines",
                        result,
                    })?
            }
            Stages::Graphics { vertex, fragment } => {
                let render_pass = self.render_pass(color)?;
                made.render_pass = Some(render_pass);
                let (vertex, fragment) = (c_name(vertex)?, c_name(fragment)?);
                let shader_stages = [
                    vk::PipelineShaderStageCreateInfo::default()
                        .stage(vk::ShaderStageFlags::VERTEX)
                        .module(module)
                        .name(&vertex),
                    vk::PipelineShaderStageCreateInfo::default()
                        .stage(vk::ShaderStageFlags::FRAGMENT)
                        .module(module)
                        .name(&fragment),
                ];
                let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
                let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
                    .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
                let viewport = vk::PipelineViewportStateCreateInfo::default()
                    .viewport_count(1)
                    .scissor_count(1);
                // As the renderer's proxy pipelines: counter-clockwise front faces, back faces
                // culled for the ray-casting pass (`raycast/pipelines.rs`).
                let raster = vk::PipelineRasterizationStateCreateInfo::default()
                    .polygon_mode(vk::PolygonMode::FILL)
                    .cull_mode(vk::CullModeFlags::BACK)
                    .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
                    .line_width(1.0);
                let multisample = vk::PipelineMultisampleStateCreateInfo::default()
                    .rasterization_samples(vk::SampleCountFlags::TYPE_1);
                let attachments = [vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA)];
                let blend =
                    vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
                let dynamic = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
                let dynamic =
                    vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic);
                let info = vk::GraphicsPipelineCreateInfo::default()
                    .flags(vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR)
                    .stages(&shader_stages)
                    .vertex_input_state(&vertex_input)
                    .input_assembly_state(&assembly)
                    .viewport_state(&viewport)
                    .rasterization_state(&raster)
                    .multisample_state(&multisample)
                    .color_blend_state(&blend)
                    .dynamic_state(&dynamic)
                    .layout(layout)
                    .render_pass(render_pass)
                    .subpass(0);
                // SAFETY: as above; the render pass is compatible (one colour attachment).
                unsafe {
                    device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
                }
                .map_err(|(_, result)| PipelineStatsError::Vulkan {
                    what: "vkCreateGraphicsPipelines",
                    result,
                })?
            }
        };
        made.pipelines.extend(&pipelines);
        pipelines
            .first()
            .copied()
            .ok_or(PipelineStatsError::Vulkan {
                what: "vkCreate*Pipelines",
                result: vk::Result::ERROR_UNKNOWN,
            })
    }

    /// A render pass of one colour attachment of `color`, the frame a graphics pipeline is
    /// compiled against.
    fn render_pass(&self, color: vk::Format) -> Result<vk::RenderPass, PipelineStatsError> {
        let attachments = [vk::AttachmentDescription::default()
            .format(color)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
        let refs = [vk::AttachmentReference::default()
            .attachment(0)
            .layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
        let subpasses = [vk::SubpassDescription::default()
            .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
            .color_attachments(&refs)];
        let info = vk::RenderPassCreateInfo::default()
            .attachments(&attachments)
            .subpasses(&subpasses);
        // SAFETY: valid create info; destroyed by the caller's `Made`.
        unsafe { self.device.create_render_pass(&info, None) }.map_err(vk_err("vkCreateRenderPass"))
    }

    /// What the driver says of each executable of `pipeline`.
    fn ask(&self, pipeline: vk::Pipeline) -> Result<Vec<Executable>, PipelineStatsError> {
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
    render_pass: Option<vk::RenderPass>,
    pipelines: Vec<vk::Pipeline>,
}

impl<'a> Made<'a> {
    fn new(device: &'a ash::Device) -> Self {
        Self {
            device,
            set_layouts: Vec::new(),
            layout: None,
            module: None,
            render_pass: None,
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
            if let Some(r) = self.render_pass {
                self.device.destroy_render_pass(r, None);
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
