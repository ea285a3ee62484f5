// Buffers and images as plain structs with create/destroy pairs (one allocation each: a render
// holds a handful of them, so a sub-allocator would buy nothing), and one-shot command submission.
#pragma once

#include <functional>

#include "vulkan/context.h"

namespace dpoint {

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  VkDeviceSize allocated = 0;  // counted in the context's device_memory_used
  void* mapped = nullptr;  // set when the memory is host-visible (mapped for the buffer's life)
  bool coherent = false;
  // Host-visible but not cached: on a discrete GPU, device memory behind the BAR, which the CPU
  // writes through write-combining buffers (uploadBuffer fills it through a cached bounce).
  bool write_combined = false;
  // The process's own pages the memory was imported from (VulkanContext::host_import_alignment),
  // unmapped once the memory is freed; null otherwise.
  void* host_pages = nullptr;
  size_t host_bytes = 0;
};

// Device-local when `host_visible` is false (filled through uploadBuffer), else host-visible
// and mapped (cached preferred, for readback; imported from the process's own memory where the
// context imports, from its host_import_from on). Fails naming `what` and the size.
Result<Buffer> createBuffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                            bool host_visible, const std::string& what);
void destroyBuffer(const VulkanContext& context, Buffer& buffer);

// Makes device writes visible to the host for a mapped, non-coherent buffer.
Status invalidateBuffer(const VulkanContext& context, const Buffer& buffer);

// vkQueueSubmit on the context's queue (or `queue`: its transfer queue), or VK_ERROR_DEVICE_LOST without submitting under the
// device-lost test switch (vulkanFaults) or once device-lost-wait has fired: every submission
// goes through here.
VkResult queueSubmit(const VulkanContext& context, const VkSubmitInfo& submit, VkFence fence,
                     VkQueue queue = VK_NULL_HANDLE);

// vkWaitForFences on one fence, without a timeout. Under the device-lost-wait test switch the wait
// still happens (so no work is in flight when the caller frees what it used) and then reports
// VK_ERROR_DEVICE_LOST, and so does every later wait and submission: every fence wait goes
// through here.
VkResult waitForFence(const VulkanContext& context, VkFence fence);

// Counts `bytes` of device memory against the context's budget (--max-device-memory) before they
// are allocated: fails with kResourceLimit naming `what`, the size and the budget when they do
// not fit. releaseDeviceMemory gives them back.
Status reserveDeviceMemory(const VulkanContext& context, VkDeviceSize bytes, const std::string& what);
void releaseDeviceMemory(const VulkanContext& context, VkDeviceSize bytes);

// A primary command buffer from the context's pool, or `pool` (the caller frees it).
Result<VkCommandBuffer> allocateCommandBuffer(const VulkanContext& context, VkCommandPool pool = VK_NULL_HANDLE);

// Records with `record` into a fresh primary command buffer, submits it, waits.
Status submitOnce(const VulkanContext& context, const std::function<void(VkCommandBuffer)>& record);

// A primary command buffer recorded anew for each of its submissions, and that submission's
// fence: made once, then begun, submitted and waited for in turn (generation's slabs).
struct CommandSlot {
  VkCommandBuffer commands = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;  // the pool the command buffer came from
  bool pending = false;                 // submitted and not yet waited for
};
// The command buffer, from `pool` (else the context's), and an unsignalled fence.
Status createCommandSlot(const VulkanContext& context, CommandSlot& slot, VkCommandPool pool = VK_NULL_HANDLE);
// Waits for a pending submission, then frees both.
void destroyCommandSlot(const VulkanContext& context, CommandSlot& slot);
// Resets the fence and begins a one-time recording (after the last submission was waited for).
Status beginCommandSlot(const VulkanContext& context, CommandSlot& slot);
// Ends the recording and submits it on `queue` (null: the context's), first waiting for `wait` at
// `wait_stage` and then signalling `signal`, each where set.
struct SlotSync {
  VkQueue queue = VK_NULL_HANDLE;
  VkSemaphore wait = VK_NULL_HANDLE;
  VkPipelineStageFlags wait_stage = 0;
  VkSemaphore signal = VK_NULL_HANDLE;
};
Status submitCommandSlot(const VulkanContext& context, CommandSlot& slot, const SlotSync& sync = {});
// Waits for the slot's submission if one is pending (waitForFence).
Status waitCommandSlot(const VulkanContext& context, CommandSlot& slot);

// Device-local memory for data the host uploads once: host-visible too (mapped, written in place)
// where the device has such a heap large enough, else plain device-local (filled via staging).
Result<Buffer> createUploadTarget(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                                  const std::string& what);

// fill(dst, offset, bytes) writes bytes [offset, offset + bytes) of a buffer's contents to dst.
// uploadBuffer calls it from several threads at once on disjoint pieces.
using UploadFill = std::function<void(void* dst, VkDeviceSize offset, VkDeviceSize bytes)>;

// Fills `size` bytes of `target` from byte `at` on (usage must include TRANSFER_DST) through
// `fill`, whose offsets count from `at`, on every core, in pieces that are multiples of `grain`
// bytes (a whole element): into mapped memory directly when the target is host-visible (through a
// cached 64 KiB block where it is write-combined), else through two staging buffers of at most `staging_limit` bytes, one filled while the GPU copies
// out of the other.
Status uploadBuffer(const VulkanContext& context, Buffer& target, VkDeviceSize size, const UploadFill& fill,
                    VkDeviceSize grain = 1, VkDeviceSize staging_limit = 32u << 20, VkDeviceSize at = 0);

// Copies `bytes` from `data` into `target`, a storage buffer the device reads (createUploadTarget,
// made anew where it is smaller, its old contents dropped); `what` names it in errors.
Status uploadStorage(const VulkanContext& context, Buffer& target, const void* data, size_t bytes,
                     const std::string& what);

struct GpuImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkDeviceSize allocated = 0;  // counted in the context's device_memory_used
};
Result<GpuImage> createImage(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
                          VkImageUsageFlags usage, VkImageAspectFlags aspect);
void destroyImage(const VulkanContext& context, GpuImage& image);

}  // namespace dpoint
