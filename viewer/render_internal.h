// Internals shared by the two backends of viewer/render.cpp (raster) and
// viewer/render_compute.cpp (compute). Not part of the library's interface.
#pragma once

#include <vector>

#include "vulkan/buffers.h"
#include "viewer/pipelines.h"
#include "viewer/render.h"

namespace dpoint::detail {

// RenderOptions::near_end_first: the most points a chunk keeps to decide which of its ends is nearer.
inline constexpr size_t kOrderSamples = 4096;

struct Chunk {
  size_t first = 0, count = 0;
  // Compute backend, per-batch modes: the chunk's entries of the batch list (batches it overlaps
  // that the plan did not cull).
  bool listed = false;  // false: every batch of the chunk splatted, a workgroup per 1024 points (no list)
  uint32_t list_first = 0, list_count = 0;
  // With RenderOptions::near_end_first: the first point of every step-th group of
  // kSplatPointsPerGroup points (at most kOrderSamples), whose depths along their order decide
  // `reversed` for each view (chooseSplatEnds).
  std::vector<glm::dvec3> order_samples;
  bool reversed = false;
  Buffer positions, colors, probe;
  VkDescriptorSet set = VK_NULL_HANDLE;
};

// Everything one render creates, destroyed in reverse on every path out.
struct Resources {
  explicit Resources(const VulkanContext& c) : context(c) {}
  ~Resources() {
    VkDevice device = context.device;
    vkDeviceWaitIdle(device);
    if (fence) vkDestroyFence(device, fence, nullptr);
    if (frame_commands) vkFreeCommandBuffers(device, context.command_pool, 1, &frame_commands);
    if (queries) vkDestroyQueryPool(device, queries, nullptr);
    if (framebuffer) vkDestroyFramebuffer(device, framebuffer, nullptr);
    if (descriptor_pool) vkDestroyDescriptorPool(device, descriptor_pool, nullptr);
    for (Chunk& chunk : chunks) {
      destroyBuffer(context, chunk.positions);
      destroyBuffer(context, chunk.colors);
      destroyBuffer(context, chunk.probe);
    }
    destroyBuffer(context, camera);
    destroyBuffer(context, batches);
    destroyBuffer(context, batch_plan);
    destroyBuffer(context, dummy);
    destroyBuffer(context, readback);
    destroyBuffer(context, all_colors);
    destroyBuffer(context, visibility);
    destroyBuffer(context, picture);
    for (VkBufferView view : shade_views)
      if (view) vkDestroyBufferView(device, view, nullptr);
    destroyBuffer(context, depth_values);
    destroyBuffer(context, shaded);
    destroyBuffer(context, log_distance);
    destroyBuffer(context, filled_log);
    destroyBuffer(context, partial);
    destroyBuffer(context, smoothed);
    destroyBuffer(context, candidates);
    destroyShadePipeline(context, shade);
    destroyImage(context, color);
    destroyImage(context, depth);
    destroyPointPipelines(context, pipelines);
    destroyComputePipelines(context, compute);
  }
  const VulkanContext& context;
  PointPipelines pipelines;
  Buffer camera, batches, batch_plan, dummy, readback;
  GpuImage color, depth;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  VkQueryPool queries = VK_NULL_HANDLE;
  VkCommandBuffer frame_commands = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  std::vector<Chunk> chunks;
  // Compute backend: one colour buffer for the resolve, the per-pixel keys, the RGBA8 picture.
  ComputePipelines compute;
  Buffer all_colors, visibility, picture;
  VkDescriptorSet resolve_set = VK_NULL_HANDLE;
  // Shading: each pixel's depth (from the depth attachment or the resolve), the shaded picture the
  // readback takes instead of the plain one, and (raster) `picture` holds the plain one; the
  // buffers between the passes (with the second hole filling's candidates, also its indirect
  // dispatch), and a texel-buffer view of each (in binding order).
  ShadePipeline shade;
  EdlPush shade_push;  // also where the compute backend's resolve writes the log distances
  Buffer depth_values, shaded, log_distance, filled_log, partial, smoothed, candidates;
  VkBufferView shade_views[kShadeBindings] = {};
  VkDescriptorSet shade_set = VK_NULL_HANDLE;
  // Round points: PushConstants' depth_scale and bulge for this camera (roundPointPush).
  float round_depth_scale = 0.0f, round_bulge = 0.0f;
};

// The render's descriptor pool: `sets` sets of one uniform and `storage_per_set` storage buffers.
Status createDescriptorPool(const VulkanContext& context, Resources& r, uint32_t sets, uint32_t storage_per_set);

// Compute backend pieces (viewer/render_compute.cpp).
Status createComputeTargets(const VulkanContext& context, Resources& r, uint32_t width, uint32_t height);
Status createComputeDescriptors(const VulkanContext& context, Resources& r, bool probe);
// RenderOptions::near_end_first: keeps the chunk's order samples from its points, which are set's
// from `offset` on; then, once the view is known, sets each chunk's `reversed` and returns how
// many are.
void sampleSplatOrder(Chunk& chunk, const PointSet& set, size_t offset);
uint32_t chooseSplatEnds(Resources& r, const Camera& camera);
// Clears the visibility buffer, splats every chunk with `splat`, resolves into the picture.
void recordCompute(VkCommandBuffer commands, const Resources& r, VkPipeline splat, const RenderOptions& options,
                   uint32_t width, uint32_t height, bool timed);

// Shading pieces (viewer/render_shade.cpp). createShadeTargets makes the depth, shaded (and for
// raster, plain picture) buffers and those between the passes, margins set, once r.shade is made
// (createShadePipeline); call before the descriptor pool is made, which holds one more set for it. recordShade copies the raster attachments into buffers when
// `raster`, then shades; the picture to read back is then `shaded`.
Status createShadeTargets(const VulkanContext& context, Resources& r, const Camera& camera, const RenderOptions& options,
                          bool raster);
Status createShadeDescriptors(const VulkanContext& context, Resources& r);
EdlPush edlPush(const Camera& camera, const EdlOptions& options, float point_size);
// PushConstants' depth_scale and bulge: a disc of point_size pixels is the front of a paraboloid
// as deep as the sphere of its radius at its depth (0, 0 for square points).
void roundPointPush(const Camera& camera, const RenderOptions& options, float& depth_scale, float& bulge);
void recordShade(VkCommandBuffer commands, const Resources& r, const EdlPush& push, bool raster);

}  // namespace dpoint::detail
