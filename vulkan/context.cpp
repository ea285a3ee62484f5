#include "vulkan/context.h"

#include <cstdlib>

#include <algorithm>
#include <atomic>
#include <cstring>

namespace dpoint {
namespace {

// Whether the device of the last context created is a CPU (lavapipe): a lost device's hint then
// does not send the user to --device cpu, which is what failed. One process uses one device at a
// time, and vulkanError has no context to ask.
std::atomic<bool> g_device_is_cpu{false};

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::string deviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

// auto prefers real GPUs: discrete, then integrated, virtual, and the CPU (lavapipe) last.
int typeRank(const std::string& type) {
  if (type == "discrete") return 0;
  if (type == "integrated") return 1;
  if (type == "virtual") return 2;
  if (type == "cpu") return 3;
  return 4;
}

DeviceFacts readFacts(VkPhysicalDevice physical, uint32_t index) {
  DeviceFacts facts;
  facts.index = index;
  VkPhysicalDeviceDriverProperties driver = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceProperties2 properties = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  VkPhysicalDeviceProperties basic{};
  vkGetPhysicalDeviceProperties(physical, &basic);
  facts.vulkan12 = basic.apiVersion >= VK_API_VERSION_1_2;
  if (facts.vulkan12) {
    VkPhysicalDeviceSubgroupProperties subgroup = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    driver.pNext = &subgroup;
    properties.pNext = &driver;
    vkGetPhysicalDeviceProperties2(physical, &properties);
    facts.driver_name = driver.driverName;
    facts.driver_info = driver.driverInfo;
    constexpr VkSubgroupFeatureFlags kMerge =
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_VOTE_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT;
    facts.subgroup_merge = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                           (subgroup.supportedOperations & kMerge) == kMerge;
  }
  facts.name = basic.deviceName;
  facts.type = deviceTypeName(basic.deviceType);
  facts.vendor_id = basic.vendorID;
  facts.device_id = basic.deviceID;
  facts.api_version = basic.apiVersion;
  facts.driver_version = basic.driverVersion;
  facts.max_storage_buffer_range = basic.limits.maxStorageBufferRange;
  facts.max_image_dimension = basic.limits.maxImageDimension2D;
  facts.max_texel_buffer_elements = basic.limits.maxTexelBufferElements;
  facts.max_point_size = basic.limits.pointSizeRange[1];
  facts.max_dispatch_groups_x = basic.limits.maxComputeWorkGroupCount[0];

  VkPhysicalDeviceFeatures features{};
  vkGetPhysicalDeviceFeatures(physical, &features);
  facts.shader_float64 = features.shaderFloat64 && !vulkanFaults().no_float64;
  facts.shader_int64 = features.shaderInt64;
  facts.vertex_stores = features.vertexPipelineStoresAndAtomics;
  facts.large_points = features.largePoints;

  if (facts.vulkan12) {
    VkPhysicalDeviceVulkan12Features features12 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 features2 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features2.pNext = &features12;
    vkGetPhysicalDeviceFeatures2(physical, &features2);
    facts.int64_atomics =
        features.shaderInt64 && features12.shaderBufferInt64Atomics && !vulkanFaults().no_int64_atomics;
  }
  if (facts.vulkan12) {
    VkPhysicalDeviceMaintenance3Properties maintenance3 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
    VkPhysicalDeviceProperties2 with_m3 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    with_m3.pNext = &maintenance3;
    vkGetPhysicalDeviceProperties2(physical, &with_m3);
    facts.max_memory_allocation = maintenance3.maxMemoryAllocationSize;
  }

  VkFormatProperties format{};
  vkGetPhysicalDeviceFormatProperties(physical, VK_FORMAT_R64G64B64_SFLOAT, &format);
  facts.r64g64b64_vertex = (format.bufferFeatures & VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT) != 0;

  uint32_t family_count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &family_count, nullptr);
  std::vector<VkQueueFamilyProperties> families(family_count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &family_count, families.data());
  for (uint32_t f = 0; f < family_count; ++f) {
    if (families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
      facts.has_graphics_queue = true;
      facts.queue_family = f;
      if (families[f].timestampValidBits > 0) facts.timestamp_period_ns = basic.limits.timestampPeriod;
      break;
    }
  }
  for (uint32_t f = 0; f < family_count; ++f) {
    const VkQueueFlags flags = families[f].queueFlags;
    if ((flags & VK_QUEUE_TRANSFER_BIT) && !(flags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) &&
        families[f].queueCount > 0) {
      facts.transfer_family = f;
      break;
    }
  }
  return facts;
}

bool hasLayer(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

Result<VkInstance> createInstance(bool validate, const VkDebugUtilsMessengerCreateInfoEXT* messenger_info) {
  uint32_t loader_version = 0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_2)
    return Error{"the Vulkan loader supports only " + formatApiVersion(loader_version) + "; dpoint needs 1.2",
                 ExitCode::kNoDevice};
  VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "dpoint";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo info = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  const char* layers[] = {kValidationLayer};
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  if (validate) {
    if (!hasLayer(kValidationLayer))
      return Error{std::string("--validate needs the Vulkan layer ") + kValidationLayer +
                       " (Debian package vulkan-validationlayers), which is not installed",
                   ExitCode::kNoDevice};
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = layers;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = extensions;
    info.pNext = messenger_info;  // also reports on instance creation and destruction
  }
  VkInstance instance = VK_NULL_HANDLE;
  VkResult result = vkCreateInstance(&info, nullptr, &instance);
  if (result != VK_SUCCESS) return vulkanError("vkCreateInstance", result);
  return instance;
}

Result<std::vector<VkPhysicalDevice>> physicalDevices(VkInstance instance) {
  uint32_t count = 0;
  VK_TRY(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VK_TRY(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  devices.resize(count);
  if (devices.empty())
    return Error{"no Vulkan device found (install a driver, e.g. Debian's mesa-vulkan-drivers for lavapipe)",
                 ExitCode::kNoDevice};
  return devices;
}

Result<uint32_t> chooseDevice(const std::vector<DeviceFacts>& all, const std::string& wanted) {
  auto usable = [](const DeviceFacts& f) { return f.vulkan12 && f.has_graphics_queue; };
  auto describe = [](const DeviceFacts& f) {
    return f.name + " (" + f.type + ", Vulkan " + formatApiVersion(f.api_version) + ")";
  };
  if (wanted == "auto" || wanted == "cpu") {
    const DeviceFacts* best = nullptr;
    for (const DeviceFacts& f : all) {
      if (!usable(f) || (wanted == "cpu" && f.type != "cpu")) continue;
      if (!best || typeRank(f.type) < typeRank(best->type)) best = &f;
    }
    if (!best) {
      std::string seen;
      for (const DeviceFacts& f : all) seen += (seen.empty() ? "" : "; ") + describe(f);
      return Error{"--device " + wanted + ": no " + (wanted == "cpu" ? "CPU " : "") +
                       "device with Vulkan 1.2 and a graphics queue (seen: " + seen + ")",
                   ExitCode::kNoDevice};
    }
    return best->index;
  }
  char* end = nullptr;
  unsigned long index = std::strtoul(wanted.c_str(), &end, 10);
  if (wanted.empty() || *end != '\0' || wanted[0] < '0' || wanted[0] > '9')  // strtoul takes "-1" as ULONG_MAX
    return Error{"--device " + wanted + ": must be auto, cpu or a device index", ExitCode::kUsage};
  if (index >= all.size())
    return Error{"--device " + wanted + ": only " + std::to_string(all.size()) + " device(s) (dpoint devices lists them)",
                 ExitCode::kNoDevice};
  if (!usable(all[index]))
    return Error{"--device " + wanted + ": " + describe(all[index]) + " lacks Vulkan 1.2 or a graphics queue",
                 ExitCode::kNoDevice};
  return static_cast<uint32_t>(index);
}

}  // namespace

std::string formatApiVersion(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." + std::to_string(VK_API_VERSION_MINOR(version)) + "." +
         std::to_string(VK_API_VERSION_PATCH(version));
}

std::string formatDriverVersion(uint32_t vendor_id, uint32_t version) {
  if (vendor_id == 0x10de)  // NVIDIA: 10.8.8.6 bits
    return std::to_string(version >> 22) + "." + std::to_string((version >> 14) & 0xff) + "." +
           std::to_string((version >> 6) & 0xff) + "." + std::to_string(version & 0x3f);
  return formatApiVersion(version);  // Mesa and most others use the Vulkan packing
}

const char* vkResultName(VkResult result) {
  switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_INCOMPLETE: return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED: return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    default: return "VkResult";
  }
}

const VulkanFaults& vulkanFaults() {
  static const VulkanFaults faults = [] {
    VulkanFaults f;
    const char* text = std::getenv("DPOINT_TEST_VULKAN_FAULT");
    std::string list = text ? text : "";
    for (size_t at = 0; at <= list.size();) {
      size_t end = list.find(',', at);
      if (end == std::string::npos) end = list.size();
      const std::string word = list.substr(at, end - at);
      f.no_float64 = f.no_float64 || word == "no-float64";
      f.no_int64_atomics = f.no_int64_atomics || word == "no-int64-atomics";
      f.device_lost = f.device_lost || word == "device-lost";
      f.device_lost_wait = f.device_lost_wait || word == "device-lost-wait";
      at = end + 1;
    }
    return f;
  }();
  return faults;
}

Error vulkanError(const std::string& what, VkResult result) {
  // Host memory is a resource limit (exit 4) like --max-memory; the device's is a Vulkan fault
  // (exit 3), as a budget past --max-device-memory is.
  const bool memory = result == VK_ERROR_OUT_OF_HOST_MEMORY;
  std::string hint = result == VK_ERROR_INCOMPATIBLE_DRIVER ? " (no Vulkan driver found)"
                     : result == VK_ERROR_DEVICE_LOST
                         ? (g_device_is_cpu ? " (the CPU device's driver failed; nothing was written; try again)"
                                            : " (the GPU was reset or its driver failed; nothing was written; try again, or "
                                              "--device cpu)")
                         : "";
  return Error{what + " failed: " + vkResultName(result) + " (" + std::to_string(static_cast<int>(result)) + ")" + hint,
               memory ? ExitCode::kResourceLimit : ExitCode::kNoDevice};
}

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanContext::onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* self) {
  std::string line = severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "validation error: " : "validation warning: ";
  line += data && data->pMessage ? data->pMessage : "(no message)";
  auto* context = static_cast<VulkanContext*>(self);
  std::lock_guard<std::mutex> lock(context->messages_mutex_);
  context->messages_.push_back(std::move(line));
  return VK_FALSE;
}

namespace {

bool hasDeviceExtension(VkPhysicalDevice physical, const char* name) {
  uint32_t count = 0;
  if (vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> extensions(count);
  if (vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, extensions.data()) != VK_SUCCESS) return false;
  return std::any_of(extensions.begin(), extensions.end(),
                     [name](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

}  // namespace

Result<std::unique_ptr<VulkanContext>> VulkanContext::create(const ContextOptions& options) {
  std::unique_ptr<VulkanContext> context(new VulkanContext());
  VkDebugUtilsMessengerCreateInfoEXT messenger_info = {VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger_info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger_info.pfnUserCallback = &VulkanContext::onMessage;
  messenger_info.pUserData = context.get();

  Result<VkInstance> instance = createInstance(options.validate, &messenger_info);
  if (!instance) return instance.error();
  context->instance = *instance;
  if (options.validate) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(context->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create_messenger) return Error{"VK_EXT_debug_utils is not available with the validation layer", ExitCode::kNoDevice};
    VK_TRY(create_messenger(context->instance, &messenger_info, nullptr, &context->messenger_));
  }

  Result<std::vector<VkPhysicalDevice>> devices = physicalDevices(context->instance);
  if (!devices) return devices.error();
  std::vector<DeviceFacts> all;
  for (uint32_t i = 0; i < devices->size(); ++i) all.push_back(readFacts((*devices)[i], i));
  Result<uint32_t> chosen = chooseDevice(all, options.device);
  if (!chosen) return chosen.error();
  context->physical = (*devices)[*chosen];
  context->facts = all[*chosen];
  g_device_is_cpu = context->facts.type == "cpu";
  vkGetPhysicalDeviceMemoryProperties(context->physical, &context->memory);

  // Enable only what the modes use and the device has; each mode checks its own needs.
  VkPhysicalDeviceFeatures enabled{};
  enabled.shaderFloat64 = context->facts.shader_float64;
  enabled.vertexPipelineStoresAndAtomics = context->facts.vertex_stores;
  enabled.largePoints = context->facts.large_points;
  enabled.shaderInt64 = context->facts.shader_int64;
  VkPhysicalDeviceVulkan12Features enabled12 = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  enabled12.shaderBufferInt64Atomics = context->facts.int64_atomics;
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_infos[2] = {{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO},
                                            {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO}};
  queue_infos[0].queueFamilyIndex = context->facts.queue_family;
  queue_infos[0].queueCount = 1;
  queue_infos[0].pQueuePriorities = &priority;
  const bool transfer = options.transfer_queue && context->facts.transfer_family.has_value();
  const uint32_t transfer_family = context->facts.transfer_family.value_or(0);
  if (transfer) {
    queue_infos[1].queueFamilyIndex = transfer_family;
    queue_infos[1].queueCount = 1;
    queue_infos[1].pQueuePriorities = &priority;
  }
  const bool host_import = options.import_host_memory.value_or(context->facts.type != "cpu") &&
                           hasDeviceExtension(context->physical, VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
  const char* device_extensions[] = {VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME};
  VkDeviceCreateInfo device_info = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  device_info.queueCreateInfoCount = transfer ? 2 : 1;
  device_info.pQueueCreateInfos = queue_infos;
  device_info.pEnabledFeatures = &enabled;
  device_info.pNext = &enabled12;
  device_info.enabledExtensionCount = host_import ? 1 : 0;
  device_info.ppEnabledExtensionNames = device_extensions;
  VK_TRY(vkCreateDevice(context->physical, &device_info, nullptr, &context->device));
  if (host_import) {
    VkPhysicalDeviceExternalMemoryHostPropertiesEXT import_facts = {
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT};
    VkPhysicalDeviceProperties2 properties = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    properties.pNext = &import_facts;
    vkGetPhysicalDeviceProperties2(context->physical, &properties);
    context->host_pointer_properties = reinterpret_cast<PFN_vkGetMemoryHostPointerPropertiesEXT>(
        vkGetDeviceProcAddr(context->device, "vkGetMemoryHostPointerPropertiesEXT"));
    if (context->host_pointer_properties) context->host_import_alignment = import_facts.minImportedHostPointerAlignment;
  }
  vkGetDeviceQueue(context->device, context->facts.queue_family, 0, &context->queue);

  VkCommandPoolCreateInfo pool_info = {VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = context->facts.queue_family;
  VK_TRY(vkCreateCommandPool(context->device, &pool_info, nullptr, &context->command_pool));
  if (transfer) {
    vkGetDeviceQueue(context->device, transfer_family, 0, &context->transfer_queue);
    pool_info.queueFamilyIndex = transfer_family;
    VK_TRY(vkCreateCommandPool(context->device, &pool_info, nullptr, &context->transfer_pool));
  }
  VkPipelineCacheCreateInfo cache_info = {VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  VK_TRY(vkCreatePipelineCache(context->device, &cache_info, nullptr, &context->pipeline_cache));
  context->device_memory_budget = options.max_device_memory;
  return context;
}

VulkanContext::~VulkanContext() {
  if (device) {
    vkDeviceWaitIdle(device);
    if (command_pool) vkDestroyCommandPool(device, command_pool, nullptr);
    if (transfer_pool) vkDestroyCommandPool(device, transfer_pool, nullptr);
    if (pipeline_cache) vkDestroyPipelineCache(device, pipeline_cache, nullptr);
    vkDestroyDevice(device, nullptr);
  }
  if (messenger_) {
    auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy_messenger) destroy_messenger(instance, messenger_, nullptr);
  }
  if (instance) vkDestroyInstance(instance, nullptr);
}

Result<uint32_t> VulkanContext::memoryType(uint32_t type_bits, VkMemoryPropertyFlags required,
                                           VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (fallback < 0) fallback = static_cast<int>(i);
  }
  if (fallback < 0)
    return Error{"no memory type with properties 0x" + std::to_string(required) + " for this buffer on " + facts.name,
                 ExitCode::kNoDevice};
  return static_cast<uint32_t>(fallback);
}

Result<std::vector<DeviceFacts>> listDevices() {
  Result<VkInstance> instance = createInstance(false, nullptr);
  if (!instance) return instance.error();
  Result<std::vector<VkPhysicalDevice>> devices = physicalDevices(*instance);
  std::vector<DeviceFacts> all;
  if (devices)
    for (uint32_t i = 0; i < devices->size(); ++i) all.push_back(readFacts((*devices)[i], i));
  vkDestroyInstance(*instance, nullptr);
  if (!devices) return devices.error();
  return all;
}

}  // namespace dpoint
