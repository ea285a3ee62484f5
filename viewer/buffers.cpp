#include "viewer/buffers.h"

#include <algorithm>

#include "core/memory.h"

namespace dpoint {

Result<Buffer> createBuffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                            bool host_visible, const std::string& what) {
  assert(size > 0);
  Buffer out;
  out.size = size;
  VkBufferCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkResult result = vkCreateBuffer(context.device, &info, nullptr, &out.buffer);
  if (result != VK_SUCCESS) return vulkanError("vkCreateBuffer (" + what + ", " + formatBytes(size) + ")", result);
  VkMemoryRequirements needs{};
  vkGetBufferMemoryRequirements(context.device, out.buffer, &needs);
  Result<uint32_t> type = host_visible
      ? context.memoryType(needs.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
      : context.memoryType(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (!type) {
    vkDestroyBuffer(context.device, out.buffer, nullptr);
    return type.error();
  }
  VkMemoryAllocateInfo allocate = {VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = needs.size;
  allocate.memoryTypeIndex = *type;
  result = vkAllocateMemory(context.device, &allocate, nullptr, &out.memory);
  if (result == VK_SUCCESS) result = vkBindBufferMemory(context.device, out.buffer, out.memory, 0);
  VkMemoryPropertyFlags flags = context.memory.memoryTypes[*type].propertyFlags;
  if (result == VK_SUCCESS && (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
    out.coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    result = vkMapMemory(context.device, out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped);
  }
  if (result != VK_SUCCESS) {
    destroyBuffer(context, out);
    return vulkanError("allocating " + formatBytes(size) + " for " + what, result);
  }
  return out;
}

void destroyBuffer(const VulkanContext& context, Buffer& buffer) {
  if (buffer.buffer) vkDestroyBuffer(context.device, buffer.buffer, nullptr);
  if (buffer.memory) vkFreeMemory(context.device, buffer.memory, nullptr);  // unmaps too
  buffer = Buffer{};
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

Status submitOnce(const VulkanContext& context, const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo allocate = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = context.command_pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VK_TRY(vkAllocateCommandBuffers(context.device, &allocate, &commands));
  VkFence fence = VK_NULL_HANDLE;
  auto cleanup = [&]() {
    if (fence) vkDestroyFence(context.device, fence, nullptr);
    vkFreeCommandBuffers(context.device, context.command_pool, 1, &commands);
  };
  VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VkResult result = vkBeginCommandBuffer(commands, &begin);
  if (result == VK_SUCCESS) {
    record(commands);
    result = vkEndCommandBuffer(commands);
  }
  VkFenceCreateInfo fence_info = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  if (result == VK_SUCCESS) result = vkCreateFence(context.device, &fence_info, nullptr, &fence);
  if (result == VK_SUCCESS) {
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    result = vkQueueSubmit(context.queue, 1, &submit, fence);
  }
  if (result == VK_SUCCESS) result = vkWaitForFences(context.device, 1, &fence, VK_TRUE, UINT64_MAX);
  cleanup();
  if (result != VK_SUCCESS) return vulkanError("one-shot command submission", result);
  return okStatus();
}

Status uploadBuffer(const VulkanContext& context, Buffer& target, VkDeviceSize size,
                    const std::function<void(void* dst, VkDeviceSize offset, VkDeviceSize bytes)>& fill,
                    VkDeviceSize staging_limit) {
  assert(size <= target.size);
  if (target.mapped) {
    fill(target.mapped, 0, size);
    return flushBuffer(context, target);
  }
  VkDeviceSize piece = std::min(size, staging_limit);
  Result<Buffer> staging = createBuffer(context, piece, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "staging");
  if (!staging) return staging.error();
  Status status = okStatus();
  for (VkDeviceSize offset = 0; offset < size && status; offset += piece) {
    VkDeviceSize bytes = std::min(piece, size - offset);
    fill(staging->mapped, offset, bytes);
    status = flushBuffer(context, *staging);
    if (!status) break;
    status = submitOnce(context, [&](VkCommandBuffer commands) {
      VkBufferCopy copy{0, offset, bytes};
      vkCmdCopyBuffer(commands, staging->buffer, target.buffer, 1, &copy);
    });
  }
  destroyBuffer(context, *staging);
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
  image = GpuImage{};
}

}  // namespace dpoint
