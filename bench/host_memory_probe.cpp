// How long a GPU's driver takes to give host-visible memory (issue #38 item 4: the rows path's
// two readback buffers, 250 MB each at res 2048, took 65-100 ms apiece on an H200, on the
// critical path). Measures, for one size:
//   alloc      vkAllocateMemory of HOST_VISIBLE|HOST_CACHED memory, then vkMapMemory
//   alloc x2   two such allocations at once, from two threads
//   import     anonymous memory (2 MiB pages advised, touched on all cores) imported with
//              VK_EXT_external_memory_host
// Usage: host_memory_probe [MB=256] [rounds=3]. Prints one line a measurement.
#include <sys/mman.h>
#include <vulkan/vulkan.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

namespace {

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

#define CHECK(x)                                                          \
  do {                                                                    \
    VkResult r_ = (x);                                                    \
    if (r_ != VK_SUCCESS) {                                               \
      std::fprintf(stderr, "%s failed: %d\n", #x, static_cast<int>(r_)); \
      std::exit(1);                                                       \
    }                                                                     \
  } while (0)

}  // namespace

int main(int argc, char** argv) {
  const VkDeviceSize bytes = VkDeviceSize(argc > 1 ? std::atoi(argv[1]) : 256) << 20;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  auto t0 = std::chrono::steady_clock::now();
  VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo ici = {VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  VkInstance instance;
  CHECK(vkCreateInstance(&ici, nullptr, &instance));
  uint32_t n = 1;
  VkPhysicalDevice physical;
  vkEnumeratePhysicalDevices(instance, &n, &physical);
  if (n == 0) return 1;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physical, &props);
  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(physical, nullptr, &count, extensions.data());
  bool host_import = false;
  for (const auto& e : extensions) host_import |= std::strcmp(e.extensionName, VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME) == 0;
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  const char* names[] = {VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME};
  VkDeviceCreateInfo dci = {VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &queue;
  dci.enabledExtensionCount = host_import ? 1 : 0;
  dci.ppEnabledExtensionNames = names;
  VkDevice device;
  CHECK(vkCreateDevice(physical, &dci, nullptr, &device));
  std::printf("device %s, made in %.1f ms, host import %s\n", props.deviceName, msSince(t0), host_import ? "yes" : "no");
  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(physical, &memory);
  uint32_t cached = UINT32_MAX;
  for (uint32_t i = 0; i < memory.memoryTypeCount && cached == UINT32_MAX; ++i) {
    const VkMemoryPropertyFlags f = memory.memoryTypes[i].propertyFlags;
    if ((f & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) && (f & VK_MEMORY_PROPERTY_HOST_CACHED_BIT)) cached = i;
  }
  auto allocate = [&](VkDeviceMemory& out) {
    VkMemoryAllocateInfo info = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.allocationSize = bytes;
    info.memoryTypeIndex = cached;
    CHECK(vkAllocateMemory(device, &info, nullptr, &out));
    void* mapped;
    CHECK(vkMapMemory(device, out, 0, VK_WHOLE_SIZE, 0, &mapped));
  };
  const double mb = static_cast<double>(bytes) / 1e6;
  for (int r = 0; r < rounds; ++r) {
    VkDeviceMemory a, b;
    auto t = std::chrono::steady_clock::now();
    allocate(a);
    std::printf("alloc     %.0f MB: %.1f ms\n", mb, msSince(t));
    t = std::chrono::steady_clock::now();
    vkFreeMemory(device, a, nullptr);
    std::printf("free      %.0f MB: %.1f ms\n", mb, msSince(t));
    t = std::chrono::steady_clock::now();
    std::thread other([&] { allocate(b); });
    allocate(a);
    other.join();
    std::printf("alloc x2  %.0f MB each, two threads: %.1f ms\n", mb, msSince(t));
    vkFreeMemory(device, a, nullptr);
    vkFreeMemory(device, b, nullptr);
    if (!host_import) continue;
    auto getProps = reinterpret_cast<PFN_vkGetMemoryHostPointerPropertiesEXT>(
        vkGetDeviceProcAddr(device, "vkGetMemoryHostPointerPropertiesEXT"));
    t = std::chrono::steady_clock::now();
    void* host = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    madvise(host, bytes, MADV_HUGEPAGE);
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> touch;
    for (unsigned k = 0; k < threads; ++k)
      touch.emplace_back([&, k] {
        const VkDeviceSize piece = bytes / threads;
        std::memset(static_cast<char*>(host) + k * piece, 0, k + 1 == threads ? bytes - k * piece : piece);
      });
    for (auto& th : touch) th.join();
    const double touched = msSince(t);
    VkMemoryHostPointerPropertiesEXT hp = {VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT};
    CHECK(getProps(device, VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT, host, &hp));
    uint32_t type = UINT32_MAX;
    for (uint32_t i = 0; i < memory.memoryTypeCount && type == UINT32_MAX; ++i)
      if ((hp.memoryTypeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT)) type = i;
    for (uint32_t i = 0; i < memory.memoryTypeCount && type == UINT32_MAX; ++i)
      if (hp.memoryTypeBits & (1u << i)) type = i;
    VkImportMemoryHostPointerInfoEXT import = {VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT};
    import.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    import.pHostPointer = host;
    VkMemoryAllocateInfo info = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.pNext = &import;
    info.allocationSize = bytes;
    info.memoryTypeIndex = type;
    VkDeviceMemory imported;
    CHECK(vkAllocateMemory(device, &info, nullptr, &imported));
    std::printf("import    %.0f MB: %.1f ms (touched on %u cores in %.1f ms; type %u flags 0x%x)\n", mb, msSince(t),
                threads, touched, type, memory.memoryTypes[type].propertyFlags);
    vkFreeMemory(device, imported, nullptr);
    munmap(host, bytes);
  }
  vkDestroyDevice(device, nullptr);
  vkDestroyInstance(instance, nullptr);
  return 0;
}
