// The compute backend (DESIGN §4): one thread per point projects it with the mode's code
// (shaders/render/project.glsl, the same as the raster vertex shader) and keeps the nearest point per
// pixel with a 64-bit atomicMax into a visibility buffer; a resolve pass per pixel then fetches
// the winner's colour. No rasterizer, no depth attachment: on GPUs whose graphics front end is
// small next to their compute (H100/H200 run graphics on two TPCs) this is the fast path.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "viewer/render_internal.h"

namespace dpoint::detail {

Status createComputeTargets(const VulkanContext& context, Resources& r, uint32_t width, uint32_t height) {
  const VkDeviceSize pixels = VkDeviceSize{width} * height;
  Result<Buffer> visibility = createBuffer(context, pixels * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                           false, "visibility buffer");
  if (!visibility) return visibility.error();
  r.visibility = *visibility;
  // Every key starts at 0 (nothing drawn); from then on each frame's resolve leaves them so.
  if (Status status = submitOnce(context, [&](VkCommandBuffer commands) {
        vkCmdFillBuffer(commands, r.visibility.buffer, 0, VK_WHOLE_SIZE, 0);
      });
      !status)
    return status;
  // Also a storage texel buffer: the shading passes read it as one.
  Result<Buffer> picture = createBuffer(context, pixels * 4,
                                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT |
                                            VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                        false, "picture");
  if (!picture) return picture.error();
  r.picture = *picture;
  Result<Buffer> readback = createBuffer(context, pixels * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "picture readback");
  if (!readback) return readback.error();
  r.readback = *readback;
  return okStatus();
}

Status createComputeDescriptors(const VulkanContext& context, Resources& r, bool probe) {
  // One splat set per chunk (camera, positions, batches, probe, visibility), the resolve set
  // (visibility, colours, picture, depth) and with eye-dome lighting its set.
  const uint32_t sets = static_cast<uint32_t>(r.chunks.size()) + 1 + (r.shade.log ? 1 : 0);
  if (Status status = createDescriptorPool(context, r, sets, 5); !status) return status;
  auto whole = [](const Buffer& b) { return VkDescriptorBufferInfo{b.buffer, 0, VK_WHOLE_SIZE}; };
  auto allocate = [&](VkDescriptorSetLayout layout, VkDescriptorSet& set) -> Status {
    VkDescriptorSetAllocateInfo info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    info.descriptorPool = r.descriptor_pool;
    info.descriptorSetCount = 1;
    info.pSetLayouts = &layout;
    VK_TRY(vkAllocateDescriptorSets(context.device, &info, &set));
    return okStatus();
  };
  auto write = [&](VkDescriptorSet set, const std::vector<VkDescriptorBufferInfo>& infos, bool first_is_uniform) {
    writeBufferDescriptors(context, set, infos, first_is_uniform);
  };
  for (Chunk& chunk : r.chunks) {
    if (Status status = allocate(r.compute.splat_set, chunk.set); !status) return status;
    write(chunk.set, {whole(r.camera), whole(chunk.positions), r.batches.buffer ? whole(r.batches) : whole(r.dummy),
                      probe ? whole(chunk.probe) : whole(r.dummy), whole(r.visibility),
                      r.batch_plan.buffer ? whole(r.batch_plan) : whole(r.dummy)}, true);
  }
  if (Status status = allocate(r.compute.resolve_set, r.resolve_set); !status) return status;
  write(r.resolve_set, {whole(r.visibility), whole(r.all_colors), whole(r.picture),
                        r.log_distance.buffer ? whole(r.log_distance) : whole(r.dummy)}, false);
  return r.shade.log ? createShadeDescriptors(context, r) : okStatus();
}

void sampleSplatOrder(Chunk& chunk, const PointSet& set, size_t offset) {
  const size_t groups = (chunk.count + kSplatPointsPerGroup - 1) / kSplatPointsPerGroup;
  const size_t step = std::max<size_t>(1, (groups + kOrderSamples - 1) / kOrderSamples);
  chunk.order_samples.clear();
  for (size_t g = 0; g < groups; g += step)
    chunk.order_samples.push_back(set.positions[offset + g * kSplatPointsPerGroup]);
}

uint32_t chooseSplatEnds(Resources& r, const Camera& camera) {
  const glm::dmat4 view = camera.view();
  uint32_t reversed = 0;
  for (Chunk& chunk : r.chunks) {
    // The least-squares slope of the samples' distance in front of the eye (−z: the eye looks down
    // −z) against their place in the chunk: negative where the points come nearer along it. Only
    // its sign counts, that of n·Σkd − Σk·Σd (its denominator, n·Σk² − (Σk)², is positive).
    double n = 0.0, sum_k = 0.0, sum_d = 0.0, sum_kd = 0.0;
    for (size_t k = 0; k < chunk.order_samples.size(); ++k) {
      const double d = -(view * glm::dvec4(chunk.order_samples[k], 1.0)).z;
      if (!std::isfinite(d)) continue;
      const double x = static_cast<double>(k);
      n += 1.0, sum_k += x, sum_d += d, sum_kd += x * d;
    }
    chunk.reversed = n >= 2.0 && n * sum_kd - sum_k * sum_d < 0.0;
    reversed += chunk.reversed ? 1u : 0u;
  }
  return reversed;
}

namespace {

// A deliberately slowed build without a rebuild, for the test that `dpoint bench --baseline` flags
// one (issue #38): DPOINT_TEST_SPLAT_REPEAT=N records every frame's splat N times. The picture is
// the same (atomicMax of the same keys); only the frame's time grows.
uint32_t splatRepeats() {
  static const uint32_t repeats = [] {
    const char* text = std::getenv("DPOINT_TEST_SPLAT_REPEAT");
    const long n = text ? std::strtol(text, nullptr, 10) : 1;
    return static_cast<uint32_t>(std::clamp(n, 1L, 64L));
  }();
  return repeats;
}

}  // namespace

void recordCompute(VkCommandBuffer commands, const Resources& r, VkPipeline splat, const RenderOptions& options,
                   uint32_t width, uint32_t height, bool timed) {
  auto barrier = [&](VkPipelineStageFlags src_stage, VkAccessFlags src, VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
    VkMemoryBarrier b = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    vkCmdPipelineBarrier(commands, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
  };
  const uint32_t pixels = width * height;
  if (timed) {
    vkCmdResetQueryPool(commands, r.queries, 0, 2);
    vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, r.queries, 0);
  }
  // The keys are 0: cleared when the buffer was made, and by every earlier frame's resolve.
  barrier(VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, splat);
  const uint32_t batch_points = modeInfo(options.mode).batch_points;  // splats the plan's batch list
  static_assert(kBatchSize % kSplatPointsPerGroup == 0 && kAdaptiveBatchSize % kSplatPointsPerGroup == 0,
                "a splat workgroup lies in one batch");
  for (uint32_t repeat = 0; repeat < splatRepeats(); ++repeat) {
    for (const Chunk& chunk : r.chunks) {
      const uint32_t groups = chunk.listed ? chunk.list_count * (batch_points / kSplatPointsPerGroup)
                                           : static_cast<uint32_t>((chunk.count + kSplatPointsPerGroup - 1) / kSplatPointsPerGroup);
      if (groups == 0) continue;  // every batch of the chunk culled
      PushConstants push;
      push.point_size = options.point_size;
      push.first_index = static_cast<uint32_t>(chunk.first);
      push.width = width;
      push.height = height;
      push.count = static_cast<uint32_t>(chunk.count);
      push.list_first = chunk.list_first;
      // Bit 1: the chunk runs from its end (RenderOptions::near_end_first).
      push.listed = (chunk.listed ? 1u : 0u) | (chunk.reversed ? 2u : 0u);
      push.batch_shift = batchShift(options.mode);
      push.depth_scale = r.round_depth_scale;
      push.bulge = r.round_bulge;
      vkCmdPushConstants(commands, r.compute.splat_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
      vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.compute.splat_layout, 0, 1, &chunk.set, 0, nullptr);
      vkCmdDispatch(commands, groups, 1, 1);
    }
  }
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.compute.resolve);
  ResolvePush resolve{pixels, options.background_rgba8, r.shade_push.width, r.shade_push.padded_width,
                      r.shade_push.margin, r.shade_push.depth_scale};
  vkCmdPushConstants(commands, r.compute.resolve_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(resolve), &resolve);
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.compute.resolve_layout, 0, 1, &r.resolve_set, 0, nullptr);
  vkCmdDispatch(commands, (pixels + kComputeGroupSize - 1) / kComputeGroupSize, 1, 1);
  if (timed) vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r.queries, 1);
  // The picture is copied out by a later submission.
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_TRANSFER_READ_BIT);
}

}  // namespace dpoint::detail
