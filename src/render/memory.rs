//! How much memory the adapter has for the volume: wgpu does not say, the Vulkan driver does.
//! A Vulkan instance of our own (ash, as `pipeline_stats` opens one) finds the adapter wgpu
//! chose by its vendor and device ids and reads its device-local heap, and with
//! `VK_EXT_memory_budget` the driver's own estimate of what this process may still allocate
//! there (`heapBudget` less `heapUsage`).

use ash::vk;

/// The adapter's device-local memory as its Vulkan driver reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DeviceMemory {
    /// Size of the largest device-local heap.
    pub heap_bytes: u64,
    /// What the driver estimates this process may still allocate in that heap
    /// (`VK_EXT_memory_budget`), where it says.
    pub available_bytes: Option<u64>,
    /// What the driver says this process held in that heap when asked (`VK_EXT_memory_budget`'s
    /// `heapUsage`): asked once the device is made, 8.6 MB on the H100 machine, where
    /// `nvidia-smi` showed more ([`DRIVER_CONTEXT`]); a budget holds both.
    pub used_bytes: Option<u64>,
}

/// What a driver that reports its heaps' usage holds for a process beside it (its context), as
/// `nvidia-smi` shows it: 54 MiB while loading, before anything was allocated, and 40-57 MB
/// beyond wgpu's allocator after (H100 machine, docs/benchmarks/nvidia-h100-bricks-stream
/// §11-§13). A budget keeps it back (at most an eighth of a small one).
pub const DRIVER_CONTEXT: u64 = 56 << 20;

/// Share of what the driver says is available that a volume takes by default: the rest is left
/// to the frame's targets, the leaping structures, the window and other programs.
pub const DEFAULT_SHARE: f64 = 0.6;

impl DeviceMemory {
    /// What a volume's `budget` keeps back for the process's memory besides its own allocations:
    /// what the driver said the process held when the device was made, and its context
    /// ([`DRIVER_CONTEXT`]); nothing where the driver does not report usage (lavapipe).
    pub(crate) fn held_besides(&self, budget: u64) -> u64 {
        self.used_bytes
            .map_or(0, |used| used + DRIVER_CONTEXT.min(budget / 8))
    }

    /// The default GPU memory budget of a volume: [`DEFAULT_SHARE`] of what the driver says is
    /// available, else of the heap.
    pub fn default_budget(&self) -> u64 {
        (self.available_bytes.unwrap_or(self.heap_bytes) as f64 * DEFAULT_SHARE) as u64
    }
}

/// The device-local memory of the Vulkan adapter `info` names, or `None` where the adapter is not
/// a Vulkan one or the loader or driver does not answer.
pub fn device_memory(info: &wgpu::AdapterInfo) -> Option<DeviceMemory> {
    if info.backend != wgpu::Backend::Vulkan {
        return None;
    }
    // SAFETY: loading the system's Vulkan loader, as wgpu does.
    let entry = unsafe { ash::Entry::load() }.ok()?;
    let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_1);
    let create = vk::InstanceCreateInfo::default().application_info(&app);
    // SAFETY: valid create info; the instance is destroyed below.
    let instance = unsafe { entry.create_instance(&create, None) }.ok()?;
    let found = memory_of(&instance, info);
    // SAFETY: nothing created from the instance outlives it.
    unsafe { instance.destroy_instance(None) };
    found
}

fn memory_of(instance: &ash::Instance, info: &wgpu::AdapterInfo) -> Option<DeviceMemory> {
    // SAFETY: the instance is valid.
    let physicals = unsafe { instance.enumerate_physical_devices() }.ok()?;
    let physical = physicals.into_iter().find(|&p| {
        // SAFETY: a physical device of this instance.
        let props = unsafe { instance.get_physical_device_properties(p) };
        props.vendor_id == info.vendor && props.device_id == info.device
    })?;
    // SAFETY: as above.
    let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }.ok()?;
    let has_budget = extensions
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::memory_budget::NAME));
    let mut budget = vk::PhysicalDeviceMemoryBudgetPropertiesEXT::default();
    let memory = {
        let mut props = vk::PhysicalDeviceMemoryProperties2::default();
        if has_budget {
            props = props.push_next(&mut budget);
        }
        // SAFETY: the chain holds only the budget structure, which the device supports.
        unsafe { instance.get_physical_device_memory_properties2(physical, &mut props) };
        props.memory_properties
    };
    let heaps = &memory.memory_heaps[..memory.memory_heap_count as usize];
    let (index, heap) = heaps
        .iter()
        .enumerate()
        .filter(|(_, h)| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
        .max_by_key(|(_, h)| h.size)?;
    let available =
        has_budget.then(|| budget.heap_budget[index].saturating_sub(budget.heap_usage[index]));
    Some(DeviceMemory {
        heap_bytes: heap.size,
        available_bytes: available.filter(|&b| b > 0),
        used_bytes: has_budget.then(|| budget.heap_usage[index]),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_budget_keeps_back_what_the_driver_holds_only_where_it_reports_usage() {
        let memory = |used| DeviceMemory {
            heap_bytes: 80 << 30,
            available_bytes: Some(79 << 30),
            used_bytes: used,
        };
        assert_eq!(memory(None).held_besides(1 << 30), 0);
        let used = 8_585_216;
        assert_eq!(
            memory(Some(used)).held_besides(1_000_000_000),
            used + DRIVER_CONTEXT
        );
        // An eighth of a small budget, not the whole context.
        assert_eq!(memory(Some(used)).held_besides(64 << 20), used + (8 << 20));
    }
}
