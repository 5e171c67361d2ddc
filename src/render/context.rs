//! The GPU device the renderer works with: created headless for the command line and tests, or
//! taken from eframe in the window. Knows which optional features the adapter gave us.

use std::sync::Arc;

/// Optional features LeapView uses when the adapter has them.
fn wanted_features() -> wgpu::Features {
    wgpu::Features::TIMESTAMP_QUERY
        | wgpu::Features::TEXTURE_FORMAT_16BIT_NORM
        | wgpu::Features::FLOAT32_FILTERABLE
}

/// The features and limits to ask a device for on `adapter`: the wanted features it has, and its
/// own limits (large volumes need its full 3D texture size and buffer size).
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    wgpu::DeviceDescriptor {
        label: Some("leapview"),
        required_features: adapter.features() & wanted_features(),
        required_limits: adapter.limits(),
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        // Small memory blocks: the default's (Performance: blocks of 64-256 MB, kept while any
        // allocation lives in them) held 1344 MB under a 1 GB budget on the H100, MemoryUsage's
        // (8-64 MB) 934.5 MB but up to 56 MB of it unused (docs/benchmarks/
        // nvidia-h100-bricks-stream §11-§13; lavapipe: 67.1 against 13.2 MB for 12.2 MB
        // allocated); the budget counts allocations and keeps one block back for what is unused.
        memory_hints: wgpu::MemoryHints::Manual {
            suballocated_device_memory_block_size: ALLOCATOR_BLOCK_MIN..ALLOCATOR_BLOCK,
        },
        trace: wgpu::Trace::Off,
    }
}

/// The smallest and largest blocks wgpu's allocator takes device memory in (gpu-allocator
/// clamps them to 4-256 MB): a GPU memory budget keeps the largest back for their unused parts.
const ALLOCATOR_BLOCK_MIN: u64 = 4 << 20;
/// See [`ALLOCATOR_BLOCK_MIN`].
pub(crate) const ALLOCATOR_BLOCK: u64 = 16 << 20;

/// Why no GPU device could be had.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter was found at all.
    #[error(
        "no GPU adapter found (Vulkan, GL). Install a Vulkan driver; without a GPU, Mesa's CPU \
         driver works (scripts/setup-debian.sh installs it: mesa-vulkan-drivers)"
    )]
    NoAdapter,
    /// The only adapters lack something the renderer needs.
    #[error(
        "the GPU adapter {adapter} cannot run LeapView: {reason}. Install a Vulkan driver; \
         without a GPU, Mesa's CPU driver works (scripts/setup-debian.sh installs it: \
         mesa-vulkan-drivers)"
    )]
    Unsuitable {
        /// Adapter name and backend.
        adapter: String,
        /// What it lacks.
        reason: String,
    },
    /// The adapter refused to create a device.
    #[error("the GPU adapter {adapter} could not create a device: {reason}")]
    NoDevice {
        /// Adapter name.
        adapter: String,
        /// What wgpu said.
        reason: String,
    },
}

/// A device, its queue and what the adapter supports.
#[derive(Clone)]
pub struct GpuContext {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Name, backend and driver of the adapter.
    pub adapter_info: wgpu::AdapterInfo,
    /// Features enabled on the device.
    pub features: wgpu::Features,
    /// Limits of the device.
    pub limits: wgpu::Limits,
    /// Format capabilities of the adapter, asked once per format the renderer may use.
    format_features: Arc<Vec<(wgpu::TextureFormat, wgpu::TextureFormatFeatures)>>,
    /// The adapter's device-local memory, where its Vulkan driver says.
    pub memory: Option<super::memory::DeviceMemory>,
}

/// Formats whose adapter-specific capabilities the renderer checks.
const CHECKED_FORMATS: [wgpu::TextureFormat; 5] = [
    wgpu::TextureFormat::R8Unorm,
    wgpu::TextureFormat::R16Unorm,
    wgpu::TextureFormat::R16Float,
    wgpu::TextureFormat::R32Float,
    wgpu::TextureFormat::Rgba16Float,
];

/// What `adapter` lacks of what the renderer needs, if anything: the fragment path renders exit
/// points to RGBA32F, the compute path stores its image as RGBA16F (Mesa's GL drivers, for one,
/// cannot render to RGBA32F).
pub(crate) fn unsuitable(adapter: &wgpu::Adapter) -> Option<String> {
    use wgpu::TextureUsages as U;
    let needs = [
        (
            wgpu::TextureFormat::Rgba32Float,
            U::RENDER_ATTACHMENT,
            "it cannot render to 32-bit float textures",
        ),
        (
            wgpu::TextureFormat::Rgba16Float,
            U::STORAGE_BINDING,
            "it cannot write 16-bit float images from compute shaders",
        ),
    ];
    needs
        .iter()
        .find(|(format, usage, _)| {
            !adapter
                .get_texture_format_features(*format)
                .allowed_usages
                .contains(*usage)
        })
        .map(|(_, _, why)| (*why).to_string())
}

impl GpuContext {
    /// Bytes of a storage buffer holding `bytes_per_pixel` for each pixel of an image of `size`,
    /// or `None` when that is empty or more than a shader can bind whole (the smaller of the
    /// binding and buffer limits).
    pub(crate) fn per_pixel_storage_bytes(
        &self,
        size: [u32; 2],
        bytes_per_pixel: u64,
    ) -> Option<u64> {
        let bytes = u64::from(size[0]) * u64::from(size[1]) * bytes_per_pixel;
        (bytes > 0 && bytes <= self.largest_binding()).then_some(bytes)
    }

    /// The most bytes a shader can bind as one storage buffer (the smaller of the binding and
    /// buffer limits).
    pub(crate) fn largest_binding(&self) -> u64 {
        (self.limits.max_storage_buffer_binding_size).min(self.limits.max_buffer_size)
    }

    /// Creates a device without a window. Prefers Vulkan (on data-centre GPUs the GL backend
    /// fails or renders nothing, see docs/benchmarks/README.md); falls back to GL where there is no Vulkan driver.
    /// `LEAPVIEW_BACKEND=vulkan|gl` forces one.
    pub fn headless() -> Result<Self, GpuError> {
        // Try Vulkan first and GL only when Vulkan has no adapter: probing GL where it is not
        // usable logs EGL errors and can take seconds.
        let order: &[wgpu::Backends] = match std::env::var("LEAPVIEW_BACKEND").as_deref() {
            Ok("gl") => &[wgpu::Backends::GL],
            Ok("vulkan") => &[wgpu::Backends::VULKAN],
            _ => &[wgpu::Backends::VULKAN, wgpu::Backends::GL],
        };
        let mut refused = None;
        let adapter = order
            .iter()
            .find_map(|&backends| {
                let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
                desc.backends = backends;
                let instance = wgpu::Instance::new(desc);
                let adapters = pollster::block_on(instance.enumerate_adapters(backends));
                // Discrete before integrated before virtual before CPU, of those that can.
                adapters
                    .into_iter()
                    .filter(|a| match unsuitable(a) {
                        Some(reason) => {
                            let info = a.get_info();
                            refused.get_or_insert(GpuError::Unsuitable {
                                adapter: format!("{} ({:?})", info.name, info.backend),
                                reason,
                            });
                            false
                        }
                        None => true,
                    })
                    .min_by_key(|a| match a.get_info().device_type {
                        wgpu::DeviceType::DiscreteGpu => 0,
                        wgpu::DeviceType::IntegratedGpu => 1,
                        wgpu::DeviceType::VirtualGpu => 2,
                        wgpu::DeviceType::Cpu => 3,
                        wgpu::DeviceType::Other => 4,
                    })
            })
            .ok_or_else(|| refused.unwrap_or(GpuError::NoAdapter))?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(
            adapter.request_device(&device_descriptor(&adapter)),
        )
        .map_err(|e| GpuError::NoDevice {
            adapter: info.name.clone(),
            reason: e.to_string(),
        })?;
        Ok(Self::new(&adapter, device, queue))
    }

    /// Wraps a device created elsewhere (eframe) from `adapter`.
    pub fn new(adapter: &wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        // wgpu's default handler panics on errors no error scope caught; log them instead, so a
        // driver problem in the window becomes a message, not a crash. Every operation that can
        // fail on bad input is wrapped in an error scope by the renderer.
        device.on_uncaptured_error(Arc::new(|e| log::error!("GPU error: {e}")));
        let format_features = CHECKED_FORMATS
            .iter()
            .map(|&f| (f, adapter.get_texture_format_features(f)))
            .collect();
        let adapter_info = adapter.get_info();
        let memory = super::memory::device_memory(&adapter_info);
        log::info!("{}: device-local memory {memory:?}", adapter_info.name);
        Self {
            features: device.features(),
            limits: device.limits(),
            memory,
            adapter_info,
            device,
            queue,
            format_features: Arc::new(format_features),
        }
    }

    /// The GPU memory a volume may take when no budget is given: a share of what the driver
    /// says is available ([`super::memory::DEFAULT_SHARE`]); `None` where it does not say.
    pub fn default_gpu_budget(&self) -> Option<u64> {
        self.memory.map(|m| m.default_budget())
    }

    /// Whether `format` can be sampled with linear filtering on this adapter.
    pub(crate) fn is_filterable(&self, format: wgpu::TextureFormat) -> bool {
        let needs_feature = match format {
            wgpu::TextureFormat::R16Unorm => self
                .features
                .contains(wgpu::Features::TEXTURE_FORMAT_16BIT_NORM),
            wgpu::TextureFormat::R32Float => {
                self.features.contains(wgpu::Features::FLOAT32_FILTERABLE)
            }
            _ => true,
        };
        needs_feature
            && self.format_features.iter().any(|(f, ff)| {
                *f == format
                    && ff
                        .flags
                        .contains(wgpu::TextureFormatFeatureFlags::FILTERABLE)
            })
    }

    /// Whether GPU timestamps can be taken around passes.
    pub fn has_timestamps(&self) -> bool {
        self.features.contains(wgpu::Features::TIMESTAMP_QUERY)
    }

    /// One line naming the adapter, its type, backend and driver.
    pub fn adapter_summary(&self) -> String {
        let i = &self.adapter_info;
        format!(
            "{} | {:?} | {:?} | {} {}",
            i.name, i.device_type, i.backend, i.driver, i.driver_info
        )
    }
}
