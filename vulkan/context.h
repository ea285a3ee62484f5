// Headless Vulkan 1.2 setup (DESIGN §4): instance (with the Khronos validation layer on request),
// the choice of physical device, one graphics queue, and the facts each precision mode needs.
// No window, no surface.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "core/result.h"

namespace dpoint {

struct DeviceFacts {
  uint32_t index = 0;  // position in vkEnumeratePhysicalDevices
  std::string name, type;  // type: discrete, integrated, virtual, cpu, other
  uint32_t vendor_id = 0, device_id = 0;
  uint32_t api_version = 0, driver_version = 0;
  std::string driver_name, driver_info;  // VkPhysicalDeviceDriverProperties
  bool shader_float64 = false;     // native mode, generation on the device
  bool shader_int64 = false;       // generation on the device (exact fp64 rounding)
  bool vertex_stores = false;      // vertexPipelineStoresAndAtomics: the probe
  bool large_points = false;       // --point-size > 1
  bool int64_atomics = false;      // shaderInt64 + shaderBufferInt64Atomics: the compute backend
  bool r64g64b64_vertex = false;   // native mode reads double vertex attributes (else pulls)
  bool subgroup_merge = false;     // subgroup vote and arithmetic in compute shaders: the splat merges lanes on one pixel
  uint64_t max_storage_buffer_range = 0, max_memory_allocation = 0;
  uint32_t max_image_dimension = 0;  // maxImageDimension2D: the raster backend's largest picture side
  uint32_t max_texel_buffer_elements = 0;  // maxTexelBufferElements: the shading's buffers (pixels)
  float max_point_size = 1.0f;
  uint32_t max_dispatch_groups_x = 0;  // maxComputeWorkGroupCount[0]: caps a compute chunk
  float timestamp_period_ns = 0.0f;  // 0: no timestamps on the graphics queue
  uint32_t queue_family = 0;
  bool has_graphics_queue = false;
  // A family of transfer queues alone (a GPU's copy engines), where the device has one: copies on
  // such a queue run beside the compute work of the main queue.
  std::optional<uint32_t> transfer_family;
  bool vulkan12 = false;  // apiVersion ≥ 1.2
};

// "1.3.239", and the driver version decoded as the vendor writes it (NVIDIA: 10.8.8.6 bits).
std::string formatApiVersion(uint32_t version);
std::string formatDriverVersion(uint32_t vendor_id, uint32_t version);

struct ContextOptions {
  std::string device = "auto";  // auto (a discrete GPU if any, else the best other), cpu, or an index
  bool validate = false;        // enable VK_LAYER_KHRONOS_validation and collect its messages
  uint64_t max_device_memory = 0;  // --max-device-memory: a budget for every allocation; 0: none
  // Open the transfer queue too, where the device has a transfer-only family (generation copies its
  // mesh out there); others do without it.
  bool transfer_queue = false;
  // Large host-visible buffers made in the process's own memory (2 MiB pages, touched on every
  // core) and imported with VK_EXT_external_memory_host, where the device has it: NVIDIA's driver
  // gives its own host memory at about 3.5 GB/s, one allocation at a time (a 250 MB readback
  // buffer: 65-100 ms on an H200), an import 4x faster. Unset: on wherever the device is not a CPU
  // (lavapipe's host-visible memory is the process's already).
  std::optional<bool> import_host_memory = std::nullopt;
};

// Test switches for the fault paths (issue #12), from the environment variable
// DPOINT_TEST_VULKAN_FAULT, a comma-separated list: `no-float64` and `no-int64-atomics` hide the
// feature as if the device lacked it (listDevices and create both), `device-lost` makes every
// queue submission fail with VK_ERROR_DEVICE_LOST as a reset or crashed GPU does, and
// `device-lost-wait` lets submissions through but makes the first fence wait report
// VK_ERROR_DEVICE_LOST, the way a GPU that hangs mid-work is usually seen (buffers.h,
// waitForFence). Unknown words are ignored. Read once per process.
struct VulkanFaults {
  bool no_float64 = false, no_int64_atomics = false, device_lost = false, device_lost_wait = false;
};
const VulkanFaults& vulkanFaults();

class VulkanContext {
 public:
  // Fails with kNoDevice (naming what is missing) when there is no Vulkan loader or driver, no
  // device matching `device`, or the chosen device lacks Vulkan 1.2 or a graphics queue.
  static Result<std::unique_ptr<VulkanContext>> create(const ContextOptions& options);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  // Index of a memory type allowed by `type_bits` that has all of `required`; prefers one that
  // also has `preferred`. Fails (no silent type 0) when none has `required`.
  Result<uint32_t> memoryType(uint32_t type_bits, VkMemoryPropertyFlags required,
                              VkMemoryPropertyFlags preferred = 0) const;

  // Validation messages (warnings and errors) seen so far, one line each.
  const std::vector<std::string>& validationMessages() const { return messages_; }
  void clearValidationMessages() {
    std::lock_guard<std::mutex> lock(messages_mutex_);
    messages_.clear();
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  // The transfer queue of facts.transfer_family and its command pool (resettable buffers); null
  // unless ContextOptions::transfer_queue asked for it and the device has such a family (lavapipe
  // has none).
  VkQueue transfer_queue = VK_NULL_HANDLE;
  VkCommandPool transfer_pool = VK_NULL_HANDLE;
  // Every pipeline is made through it: a device kept across renders (the Python module's
  // Renderer) compiles a pipeline it made before from the cache.
  VkPipelineCache pipeline_cache = VK_NULL_HANDLE;
  DeviceFacts facts;
  VkPhysicalDeviceMemoryProperties memory{};
  // Device memory allocated through vulkan/buffers and the budget it must stay in (0: none).
  uint64_t device_memory_budget = 0;
  // Where the budget is what --max-memory leaves beside the host's own arrays (a CPU device, whose
  // memory is the host's; set per render, viewer/render_job.cpp): how, for the refusal, which is
  // then exit 4 ("the 12.0 MiB that --max-memory 36.0 MiB leaves beside the 24.0 MiB of points
  // read"). Empty otherwise.
  std::string host_budget;
  // Where --max-device-memory is given for a CPU device, which --max-memory (given, or its default,
  // half of RAM) bounds too: the looser of the two, said in the refusal of the tighter so that one
  // raised alone is not a surprise ("--max-device-memory 64.0 MiB", or host_budget's form). Empty
  // otherwise.
  std::string next_budget;
  mutable std::atomic<uint64_t> device_memory_used{0};
  // Set once the device-lost-wait test switch has reported a loss: from then on the device stays
  // lost for every submission and wait, as a real lost device does.
  mutable std::atomic<bool> injected_loss{false};
  // Where host-visible buffers are imported (ContextOptions::import_host_memory): the pointer and
  // size alignment an import needs, and the call that says which types may hold it; 0 and null
  // where they are not.
  VkDeviceSize host_import_alignment = 0;
  PFN_vkGetMemoryHostPointerPropertiesEXT host_pointer_properties = nullptr;
  VkDeviceSize host_import_from = VkDeviceSize{4} << 20;  // the smallest buffer imported

 private:
  VulkanContext() = default;
  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* self);
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::vector<std::string> messages_;
  std::mutex messages_mutex_;  // the layer may call back from two threads (render makes pipelines beside the upload)
};

// Every physical device the loader reports, with its facts (creates and destroys an instance).
Result<std::vector<DeviceFacts>> listDevices();

// Error for a failed Vulkan call: out-of-memory results map to kResourceLimit, others to kNoDevice.
Error vulkanError(const std::string& what, VkResult result);
const char* vkResultName(VkResult result);

}  // namespace dpoint

// Every VkResult is checked: in a function returning Result/Status, returns the error naming the call.
#define VK_TRY(call)                                                      \
  do {                                                                    \
    VkResult vk_try_result_ = (call);                                     \
    if (vk_try_result_ != VK_SUCCESS) return ::dpoint::vulkanError(#call, vk_try_result_); \
  } while (0)
