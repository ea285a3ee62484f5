#include "vulkan/buffers.h"

#include <sys/mman.h>

#include <algorithm>
#include <cassert>
#include <cstring>

#include "core/memory.h"
#include "core/parallel.h"

namespace dpoint {

namespace {

constexpr VkExternalMemoryHandleTypeFlagBits kHostAllocation = VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;

// Pages of the process's own that a buffer's memory is imported from (VK_EXT_external_memory_host).
struct HostPages {
  void* pages = nullptr;
  size_t bytes = 0;  // a multiple of the context's host_import_alignment
};

// A buffer of `size` bytes bound to memory of the type `pick` chooses from the buffer's allowed
// types (mapped for the buffer's life when host-visible); with `host`, memory imported from those
// pages (of the types that may hold them), which the buffer then owns, also on an error.
Result<Buffer> allocateBuffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                              const std::string& what,
                              const std::function<Result<uint32_t>(const VkMemoryRequirements&)>& pick,
                              const HostPages* host = nullptr) {
  assert(size > 0);
  Buffer out;
  out.size = size;
  if (host) {
    out.host_pages = host->pages;
    out.host_bytes = host->bytes;
  }
  auto failed = [&](Error error) {
    destroyBuffer(context, out);
    return error;
  };
  VkExternalMemoryBufferCreateInfo external = {VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
  external.handleTypes = kHostAllocation;
  VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.pNext = host ? &external : nullptr;
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkResult result = vkCreateBuffer(context.device, &info, nullptr, &out.buffer);
  if (result != VK_SUCCESS) return failed(vulkanError("vkCreateBuffer (" + what + ", " + formatBytes(size) + ")", result));
  VkMemoryRequirements needs{};
  vkGetBufferMemoryRequirements(context.device, out.buffer, &needs);
  VkImportMemoryHostPointerInfoEXT import = {VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT};
  if (host) {
    VkMemoryHostPointerPropertiesEXT pointer = {VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT};
    result = context.host_pointer_properties(context.device, kHostAllocation, host->pages, &pointer);
    if (result != VK_SUCCESS) return failed(vulkanError("vkGetMemoryHostPointerPropertiesEXT (" + what + ")", result));
    if (needs.size > host->bytes)
      return failed(Error{what + " needs more than the host pages to import", ExitCode::kNoDevice});
    needs.memoryTypeBits &= pointer.memoryTypeBits;
    needs.size = host->bytes;
    import.handleType = kHostAllocation;
    import.pHostPointer = host->pages;
  }
  Result<uint32_t> type = pick(needs);
  if (!type) return failed(type.error());
  if (Status budget = reserveDeviceMemory(context, needs.size, what); !budget) return failed(budget.error());
  out.allocated = needs.size;
  VkMemoryAllocateInfo allocate = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.pNext = host ? &import : nullptr;
  allocate.allocationSize = needs.size;
  allocate.memoryTypeIndex = *type;
  result = vkAllocateMemory(context.device, &allocate, nullptr, &out.memory);
  if (result == VK_SUCCESS) result = vkBindBufferMemory(context.device, out.buffer, out.memory, 0);
  VkMemoryPropertyFlags flags = context.memory.memoryTypes[*type].propertyFlags;
  if (result == VK_SUCCESS && (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
    out.coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    out.write_combined = !host && (flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT) == 0;
    if (host) {
      out.mapped = host->pages;
    } else {
      result = vkMapMemory(context.device, out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped);
      // A CPU device's memory is the process's own heap, which the upload writes first: in 2 MiB
      // pages it takes 512 times fewer faults (on the 2-core PVM test VM, 4,600 faults of about
      // 12 us each for the 1.55M-point Mandelbulb's fp32 positions). Only a hint.
      if (result == VK_SUCCESS && context.facts.type == "cpu" && size >= kHugeBlockBytes)
        adviseHugePages(out.mapped, size);
    }
  }
  if (result != VK_SUCCESS) return failed(vulkanError("allocating " + formatBytes(size) + " for " + what, result));
  return out;
}

// Pages of the process's own for a host-visible buffer, made present on every core: 2 MiB pages
// where the kernel gives them (the mapping aligned to 2 MiB). Null where mmap fails.
void* mapHostPages(size_t bytes) {
  constexpr size_t kHuge = size_t{2} << 20;
  auto* pages = static_cast<uint8_t*>(mapHugePages(bytes));
  if (!pages) return nullptr;
  // A child process (a Python user's fork) gets none of them: pinned pages would be copied.
  madvise(pages, bytes, MADV_DONTFORK);
  // A driver pins the pages it imports one at a time; faulted here they come from every core.
  parallelFor((bytes + kHuge - 1) / kHuge, 0, [&](size_t piece, unsigned) {
    const size_t end = std::min(bytes, (piece + 1) * kHuge);
    for (size_t at = piece * kHuge; at < end; at += 4096) pages[at] = 0;
  });
  return pages;
}

// A host-visible buffer in memory of the process's own, imported; an error where the device will
// not take it, for createBuffer to allocate instead.
Result<Buffer> importHostBuffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                                const std::string& what, const std::function<Result<uint32_t>(const VkMemoryRequirements&)>& pick) {
  VkPhysicalDeviceExternalBufferInfo query = {VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_BUFFER_INFO};
  query.usage = usage;
  query.handleType = kHostAllocation;
  VkExternalBufferProperties external = {VK_STRUCTURE_TYPE_EXTERNAL_BUFFER_PROPERTIES};
  vkGetPhysicalDeviceExternalBufferProperties(context.physical, &query, &external);
  if (!(external.externalMemoryProperties.externalMemoryFeatures & VK_EXTERNAL_MEMORY_FEATURE_IMPORTABLE_BIT))
    return Error{"host memory cannot be imported for " + what, ExitCode::kNoDevice};
  const VkDeviceSize align = std::max<VkDeviceSize>(context.host_import_alignment, 4096);
  HostPages host;
  host.bytes = static_cast<size_t>((size + align - 1) / align * align);
  host.pages = mapHostPages(host.bytes);
  if (!host.pages) return Error{"no host memory for " + what, ExitCode::kResourceLimit};
  return allocateBuffer(context, size, usage, what, pick, &host);
}

}  // namespace

Result<Buffer> createBuffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                            bool host_visible, const std::string& what) {
  auto pick = [&](const VkMemoryRequirements& needs) {
    return host_visible
        ? context.memoryType(needs.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
        : context.memoryType(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  };
  if (host_visible && context.host_import_alignment && size >= context.host_import_from) {
    // Where the import fails (this use, the budget, the host's memory), the driver's memory.
    if (Result<Buffer> imported = importHostBuffer(context, size, usage, what, pick); imported) return imported;
  }
  return allocateBuffer(context, size, usage, what, pick);
}

Status uploadStorage(const VulkanContext& context, Buffer& target, const void* data, size_t bytes,
                     const std::string& what) {
  if (target.size < bytes) {
    destroyBuffer(context, target);
    Result<Buffer> created =
        createUploadTarget(context, std::max<size_t>(bytes, 16),
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, what);
    if (!created) return created.error();
    target = *created;
  }
  return uploadBuffer(context, target, bytes, [&](void* dst, VkDeviceSize offset, VkDeviceSize size) {
    std::memcpy(dst, static_cast<const uint8_t*>(data) + offset, size);
  });
}

Result<Buffer> createUploadTarget(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                                  const std::string& what) {
  // Device-local memory the host can write (resizable BAR, unified memory, lavapipe) saves the
  // staging copy, but only where its heap holds the buffer with room to spare: the small 256 MiB
  // BAR window of a discrete GPU without resizable BAR is left to the driver.
  Result<Buffer> direct = allocateBuffer(context, size, usage, what, [&](const VkMemoryRequirements& needs) -> Result<uint32_t> {
    constexpr VkMemoryPropertyFlags kWanted = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
    for (uint32_t i = 0; i < context.memory.memoryTypeCount; ++i) {
      const VkMemoryType& type = context.memory.memoryTypes[i];
      if (!(needs.memoryTypeBits & (1u << i)) || (type.propertyFlags & kWanted) != kWanted) continue;
      if (context.memory.memoryHeaps[type.heapIndex].size / 4 >= needs.size) return i;
    }
    return Error{"no large host-visible device-local heap", ExitCode::kNoDevice};
  });
  if (direct) return direct;
  return createBuffer(context, size, usage, false, what);
}

void destroyBuffer(const VulkanContext& context, Buffer& buffer) {
  if (buffer.buffer) vkDestroyBuffer(context.device, buffer.buffer, nullptr);
  if (buffer.memory) vkFreeMemory(context.device, buffer.memory, nullptr);  // unmaps too
  if (buffer.host_pages) munmap(buffer.host_pages, buffer.host_bytes);
  releaseDeviceMemory(context, buffer.allocated);
  buffer = Buffer{};
}

Status reserveDeviceMemory(const VulkanContext& context, VkDeviceSize bytes, const std::string& what) {
  const uint64_t used = context.device_memory_used.fetch_add(bytes) + bytes;
  if (context.device_memory_budget == 0 || used <= context.device_memory_budget) return okStatus();
  context.device_memory_used.fetch_sub(bytes);
  const std::string next = context.next_budget.empty() ? "" : "past it, " + context.next_budget + " is the next limit";
  if (!context.host_budget.empty())
    return Error{"host memory: " + what + " needs " + formatBytes(bytes) + " more on the CPU device (whose memory is "
                     "the host's), " + formatBytes(used) + " in all, past " + context.host_budget +
                     (next.empty() ? "" : " (" + next + ")") +
                     "; try a smaller set, size or --mode with fewer bytes a point, or a higher --max-memory",
                 ExitCode::kResourceLimit};
  return Error{"device memory: " + what + " needs " + formatBytes(bytes) + " more, " + formatBytes(used) +
                   " in all, above the budget of " + formatBytes(context.device_memory_budget) +
                   " (--max-device-memory" + (next.empty() ? "" : "; " + next) +
                   "); try a smaller set, size or --mode with fewer bytes a point",
               ExitCode::kNoDevice};  // a Vulkan fault like a lost device (issue #12): exit 3
}

void releaseDeviceMemory(const VulkanContext& context, VkDeviceSize bytes) { context.device_memory_used.fetch_sub(bytes); }

VkResult queueSubmit(const VulkanContext& context, const VkSubmitInfo& submit, VkFence fence, VkQueue queue) {
  if (vulkanFaults().device_lost || context.injected_loss) return VK_ERROR_DEVICE_LOST;
  return vkQueueSubmit(queue ? queue : context.queue, 1, &submit, fence);
}

VkResult waitForFence(const VulkanContext& context, VkFence fence) {
  const VkResult result = vkWaitForFences(context.device, 1, &fence, VK_TRUE, UINT64_MAX);
  if (result != VK_SUCCESS || !vulkanFaults().device_lost_wait) return result;
  context.injected_loss = true;
  return VK_ERROR_DEVICE_LOST;
}

// Host caches and device memory agree already for coherent memory; otherwise one range call.
static Status syncMapped(const VulkanContext& context, const Buffer& buffer, bool device_to_host) {
  if (buffer.coherent || !buffer.mapped) return okStatus();
  VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  range.memory = buffer.memory;
  range.size = VK_WHOLE_SIZE;
  if (device_to_host) VK_TRY(vkInvalidateMappedMemoryRanges(context.device, 1, &range));
  else VK_TRY(vkFlushMappedMemoryRanges(context.device, 1, &range));
  return okStatus();
}

Status invalidateBuffer(const VulkanContext& context, const Buffer& buffer) { return syncMapped(context, buffer, true); }
static Status flushBuffer(const VulkanContext& context, const Buffer& buffer) { return syncMapped(context, buffer, false); }

Result<VkCommandBuffer> allocateCommandBuffer(const VulkanContext& context, VkCommandPool pool) {
  VkCommandBufferAllocateInfo allocate = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = pool ? pool : context.command_pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VK_TRY(vkAllocateCommandBuffers(context.device, &allocate, &commands));
  return commands;
}

Status submitOnce(const VulkanContext& context, const std::function<void(VkCommandBuffer)>& record) {
  CommandSlot slot;
  Status status = createCommandSlot(context, slot);
  if (status) status = beginCommandSlot(context, slot);
  if (status) {
    record(slot.commands);
    status = submitCommandSlot(context, slot);
  }
  if (status) status = waitCommandSlot(context, slot);
  destroyCommandSlot(context, slot);
  return status;
}

Status createCommandSlot(const VulkanContext& context, CommandSlot& slot, VkCommandPool pool) {
  Result<VkCommandBuffer> commands = allocateCommandBuffer(context, pool);
  if (!commands) return commands.error();
  slot.commands = *commands;
  slot.pool = pool ? pool : context.command_pool;
  VkFenceCreateInfo fence_info = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_TRY(vkCreateFence(context.device, &fence_info, nullptr, &slot.fence));
  return okStatus();
}

void destroyCommandSlot(const VulkanContext& context, CommandSlot& slot) {
  (void)waitCommandSlot(context, slot);
  if (slot.fence) vkDestroyFence(context.device, slot.fence, nullptr);
  if (slot.commands) vkFreeCommandBuffers(context.device, slot.pool, 1, &slot.commands);
  slot = CommandSlot{};
}

Status beginCommandSlot(const VulkanContext& context, CommandSlot& slot) {
  assert(!slot.pending);
  VK_TRY(vkResetFences(context.device, 1, &slot.fence));
  VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_TRY(vkBeginCommandBuffer(slot.commands, &begin));
  return okStatus();
}

Status submitCommandSlot(const VulkanContext& context, CommandSlot& slot, const SlotSync& sync) {
  VK_TRY(vkEndCommandBuffer(slot.commands));
  VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &slot.commands;
  if (sync.wait) {
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &sync.wait;
    submit.pWaitDstStageMask = &sync.wait_stage;
  }
  if (sync.signal) {
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &sync.signal;
  }
  VK_TRY(queueSubmit(context, submit, slot.fence, sync.queue));
  slot.pending = true;
  return okStatus();
}

Status waitCommandSlot(const VulkanContext& context, CommandSlot& slot) {
  if (!slot.pending) return okStatus();
  slot.pending = false;
  VK_TRY(waitForFence(context, slot.fence));
  return okStatus();
}

namespace {

// Calls fill on pieces of [offset, offset + bytes) from every core, each piece a multiple of
// `grain` (the last one excepted) and about 1 MiB: the pieces are disjoint, so the bytes written
// do not depend on the thread count.
//
// Into write-combined memory (`bounce`) each piece is filled 64 KiB at a time into a cached block
// and copied across whole: a fill that stores a few bytes at a time, reading its source as it
// goes, leaves the write-combining buffers part-full, and each one flushed early is a short write
// over the bus. On an H200 the float-pair fill into the BAR ran 1.6x slower that way once the
// source sat in 2 MiB pages (bench/results/2026-12-01/h200/bounce/).
void fillInParallel(const UploadFill& fill, void* dst, VkDeviceSize offset, VkDeviceSize bytes, VkDeviceSize grain,
                    bool bounce) {
  const VkDeviceSize piece = std::max<VkDeviceSize>(grain, (VkDeviceSize{1} << 20) / grain * grain);
  const VkDeviceSize block = std::max<VkDeviceSize>(grain, (VkDeviceSize{64} << 10) / grain * grain);
  const size_t pieces = static_cast<size_t>((bytes + piece - 1) / piece);
  parallelFor(pieces, pieces == 1 ? 1 : 0, [&](size_t k, unsigned) {
    const VkDeviceSize at = k * piece;
    const VkDeviceSize size = std::min(piece, bytes - at);
    uint8_t* out = static_cast<uint8_t*>(dst) + at;
    if (!bounce) return fill(out, offset + at, size);
    std::vector<uint8_t, DefaultInitAllocator<uint8_t>> cached(std::min(block, size));
    for (VkDeviceSize done = 0; done < size; done += block) {
      const VkDeviceSize n = std::min(block, size - done);
      fill(cached.data(), offset + at + done, n);
      std::memcpy(out + done, cached.data(), n);
    }
  });
}

}  // namespace

Status uploadBuffer(const VulkanContext& context, Buffer& target, VkDeviceSize size, const UploadFill& fill,
                    VkDeviceSize grain, VkDeviceSize staging_limit, VkDeviceSize at) {
  assert(at <= target.size && size <= target.size - at && grain > 0);
  if (target.mapped) {
    fillInParallel(fill, static_cast<uint8_t*>(target.mapped) + at, 0, size, grain, target.write_combined);
    return flushBuffer(context, target);
  }
  // Two staging buffers: the cores fill one while the GPU copies out of the other.
  const VkDeviceSize piece = std::min(size, std::max(grain, staging_limit / grain * grain));
  const size_t slots = size > piece ? 2 : 1;
  struct Slot {
    Buffer staging;
    CommandSlot commands;
  };
  std::vector<Slot> slot(slots);
  auto run = [&]() -> Status {
    for (Slot& s : slot) {
      Result<Buffer> staging = createBuffer(context, piece, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "staging");
      if (!staging) return staging.error();
      s.staging = *staging;
      if (Status made = createCommandSlot(context, s.commands); !made) return made;
    }
    size_t k = 0;
    for (VkDeviceSize offset = 0; offset < size; offset += piece, ++k) {
      Slot& s = slot[k % slots];
      if (Status waited = waitCommandSlot(context, s.commands); !waited) return waited;
      const VkDeviceSize bytes = std::min(piece, size - offset);
      fillInParallel(fill, s.staging.mapped, offset, bytes, grain, s.staging.write_combined);
      if (Status status = flushBuffer(context, s.staging); !status) return status;
      if (Status begun = beginCommandSlot(context, s.commands); !begun) return begun;
      VkBufferCopy copy{0, at + offset, bytes};
      vkCmdCopyBuffer(s.commands.commands, s.staging.buffer, target.buffer, 1, &copy);
      if (Status submitted = submitCommandSlot(context, s.commands); !submitted) return submitted;
    }
    for (Slot& s : slot)
      if (Status waited = waitCommandSlot(context, s.commands); !waited) return waited;
    return okStatus();
  };
  Status status = run();
  for (Slot& s : slot) {  // waits for a submission still pending (after a failure)
    destroyCommandSlot(context, s.commands);
    destroyBuffer(context, s.staging);
  }
  return status;
}

Result<GpuImage> createImage(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
                             VkImageUsageFlags usage, VkImageAspectFlags aspect) {
  GpuImage out;
  VkImageCreateInfo info = {VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_TRY(vkCreateImage(context.device, &info, nullptr, &out.image));
  VkMemoryRequirements needs{};
  vkGetImageMemoryRequirements(context.device, out.image, &needs);
  Result<uint32_t> type = context.memoryType(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (!type) {
    destroyImage(context, out);
    return type.error();
  }
  if (Status budget = reserveDeviceMemory(context, needs.size, std::to_string(width) + "x" + std::to_string(height) +
                                                                   " image");
      !budget) {
    destroyImage(context, out);
    return budget.error();
  }
  out.allocated = needs.size;
  VkMemoryAllocateInfo allocate = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = needs.size;
  allocate.memoryTypeIndex = *type;
  VkResult result = vkAllocateMemory(context.device, &allocate, nullptr, &out.memory);
  if (result == VK_SUCCESS) result = vkBindImageMemory(context.device, out.image, out.memory, 0);
  if (result == VK_SUCCESS) {
    VkImageViewCreateInfo view = {VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = out.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect, 0, 1, 0, 1};
    result = vkCreateImageView(context.device, &view, nullptr, &out.view);
  }
  if (result != VK_SUCCESS) {
    destroyImage(context, out);
    return vulkanError("creating a " + std::to_string(width) + "x" + std::to_string(height) + " image", result);
  }
  return out;
}

void destroyImage(const VulkanContext& context, GpuImage& image) {
  if (image.view) vkDestroyImageView(context.device, image.view, nullptr);
  if (image.image) vkDestroyImage(context.device, image.image, nullptr);
  if (image.memory) vkFreeMemory(context.device, image.memory, nullptr);
  releaseDeviceMemory(context, image.allocated);
  image = GpuImage{};
}

}  // namespace dpoint
