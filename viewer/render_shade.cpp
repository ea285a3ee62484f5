// Shading after either backend (RenderOptions::shading): the raster backend's colour and depth
// attachments are copied into buffers, the compute backend's resolve writes them there itself;
// then the passes of shaders/render/shade_common.glsl (log distance, hole filling, the depth
// smoothed along rows and columns, eye-dome lighting; the last three in one pass where the radii
// are small, ShadeRadii::fused) write the shaded picture that is read back.
//
// On lavapipe each pass over 786K pixels costs several ms before it reads anything, a
// storage-buffer load is a loop over the SIMD lanes, a log2 costs more than a load, llvmpipe runs
// every branch of every lane, and making a pipeline lowers and optimizes its shader anew: hence
// few passes, texel buffers, one log2 a pixel, margins instead of edge tests, and shaders small
// enough to make quickly (docs/rendering.md has the timings).
#include <algorithm>
#include <bit>
#include <cmath>

#include "viewer/render_internal.h"

namespace dpoint::detail {

Status createShadeTargets(const VulkanContext& context, Resources& r, const Camera& camera, const RenderOptions& options,
                          bool raster) {
  const ShadeRadii radii = shadeRadii(options.point_size, options.edl.radius, options.edl.fuse);
  const EdlPush push = edlPush(camera, options.edl, options.point_size);
  r.shade_push = push;
  const VkDeviceSize bytes = VkDeviceSize{push.width} * push.height * 4;
  const VkDeviceSize padded = VkDeviceSize{push.padded_width} * (push.height + 2 * push.margin) * 4;
  const VkBufferUsageFlags texel = VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT;
  const VkBufferUsageFlags margin = texel | VK_BUFFER_USAGE_TRANSFER_DST_BIT;  // filled once below
  // The raster backend's attachments are copied into the depth and the picture; the compute
  // backend makes the picture and its resolve writes the log distances as a storage buffer.
  const VkBufferUsageFlags in_usage = texel | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  struct Target {
    Buffer* buffer;
    VkDeviceSize bytes;
    VkBufferUsageFlags usage;
    const char* what;
  };
  for (const Target& t : {Target{raster ? &r.depth_values : nullptr, bytes, in_usage, "depth per pixel"},
                          Target{raster ? &r.picture : nullptr, bytes, in_usage, "picture before shading"},
                          Target{&r.shaded, bytes, texel | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, "shaded picture"},
                          Target{&r.log_distance, padded, margin | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "log distance"},
                          Target{&r.filled_log, padded, margin, "log distance after hole filling"},
                          // Only between the separate passes of smooth.comp and edl.comp.
                          Target{radii.fused ? nullptr : &r.partial, 2 * padded, margin, "row sums of the log distance"},
                          Target{radii.fused ? nullptr : &r.smoothed, padded, margin, "smoothed log distance"},
                          Target{&r.candidates, (kCandidateHeader + VkDeviceSize{push.width} * push.height) * 4,
                                 texel | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 "second hole filling's candidates"}}) {
    if (!t.buffer) continue;
    Result<Buffer> buffer = createBuffer(context, t.bytes, t.usage, false, t.what);
    if (!buffer) return buffer.error();
    *t.buffer = *buffer;
  }
  // The margins, once: the passes write only the picture's pixels.
  const uint32_t empty = std::bit_cast<uint32_t>(kShadeEmpty);
  return submitOnce(context, [&](VkCommandBuffer commands) {
    for (const Buffer* b : {&r.log_distance, &r.filled_log, &r.smoothed})
      if (b->buffer) vkCmdFillBuffer(commands, b->buffer, 0, VK_WHOLE_SIZE, empty);
    if (r.partial.buffer) vkCmdFillBuffer(commands, r.partial.buffer, 0, VK_WHOLE_SIZE, 0);  // (sum, count) = (0, 0)
  });
}

Status createShadeDescriptors(const VulkanContext& context, Resources& r) {
  VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = r.descriptor_pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &r.shade.set_layout;
  VK_TRY(vkAllocateDescriptorSets(context.device, &allocate, &r.shade_set));
  // In binding order (shaders/render/shade_common.glsl): one texel a pixel. After the compute
  // backend there is no depth to read, and the fused pass makes no row sums or means: their
  // bindings, which no pass then reads, show the log distances.
  const Buffer& depth = r.depth_values.buffer ? r.depth_values : r.log_distance;
  const Buffer& partial = r.partial.buffer ? r.partial : r.log_distance;
  const Buffer& smoothed = r.smoothed.buffer ? r.smoothed : r.log_distance;
  const struct {
    const Buffer& buffer;
    VkFormat format;
  } views[kShadeBindings] = {{depth, VK_FORMAT_R32_SFLOAT},           {r.picture, VK_FORMAT_R32_UINT},
                             {r.shaded, VK_FORMAT_R32_UINT},        {r.log_distance, VK_FORMAT_R32_SFLOAT},
                             {r.filled_log, VK_FORMAT_R32_SFLOAT},  {partial, VK_FORMAT_R32G32_SFLOAT},
                             {smoothed, VK_FORMAT_R32_SFLOAT},      {r.candidates, VK_FORMAT_R32_UINT}};
  VkWriteDescriptorSet writes[kShadeBindings];
  for (uint32_t b = 0; b < kShadeBindings; ++b) {
    VkBufferViewCreateInfo info = {VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    info.buffer = views[b].buffer.buffer;
    info.format = views[b].format;
    info.range = VK_WHOLE_SIZE;
    VK_TRY(vkCreateBufferView(context.device, &info, nullptr, &r.shade_views[b]));
    writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = r.shade_set;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER;
    writes[b].pTexelBufferView = &r.shade_views[b];
  }
  vkUpdateDescriptorSets(context.device, kShadeBindings, writes, 0, nullptr);
  return okStatus();
}

namespace {

// Reversed-Z perspective depth is n(f − t) / (t(f − n)) at eye distance t, so
// t = f / (1 + depth · (f − n) / n): the shaders need only (f − n) / n; 0 for ortho.
float depthScale(const Camera& camera) {
  return camera.ortho ? 0.0f : static_cast<float>((camera.far_plane - camera.near_plane) / camera.near_plane);
}

// What one pixel spans: 2 / (focal · height) of the eye distance in perspective (focal =
// P[1][1] / P[2][3]), 2 · P[2][2] / (|P[1][1]| · height) of the depth range in ortho.
double pixelDepthSpan(const Camera& camera) {
  const glm::dmat4& p = camera.projection;
  return camera.ortho ? 2.0 * p[2][2] / (std::abs(p[1][1]) * camera.height) : 2.0 * p[2][3] / (p[1][1] * camera.height);
}

}  // namespace

EdlPush edlPush(const Camera& camera, const EdlOptions& options, float point_size) {
  EdlPush push;
  push.width = camera.width;
  push.height = camera.height;
  push.depth_scale = depthScale(camera);
  push.strength = options.strength;
  const ShadeRadii radii = shadeRadii(point_size, options.radius, options.fuse);
  push.edl_axis = radii.edl_axis;
  push.edl_diagonal = radii.edl_diagonal;
  push.margin = static_cast<uint32_t>(radii.margin());
  push.padded_width = camera.width + 2 * push.margin;
  // Hole filling's threshold: the change in log2 eye distance over its radius across a surface at
  // 72° to the view (slope 3), so the steps within one surface never count as standing in front.
  push.fill_threshold = static_cast<float>(3.0 * radii.fill * pixelDepthSpan(camera) / std::log(2.0));
  return push;
}

void roundPointPush(const Camera& camera, const RenderOptions& options, float& depth_scale, float& bulge) {
  depth_scale = bulge = 0.0f;
  if (!options.round_points || options.point_size <= 1.0f) return;
  depth_scale = depthScale(camera);
  bulge = static_cast<float>(0.5 * options.point_size * pixelDepthSpan(camera));
}

void recordShade(VkCommandBuffer commands, const Resources& r, const EdlPush& push, bool raster) {
  auto barrier = [&](VkPipelineStageFlags src_stage, VkAccessFlags src, VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
    VkMemoryBarrier b = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    vkCmdPipelineBarrier(commands, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
  };
  if (raster) {  // the render pass left both attachments in TRANSFER_SRC_OPTIMAL
    VkBufferImageCopy copy{};
    copy.imageExtent = {push.width, push.height, 1};  // rows packed, 4 bytes a texel in both
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    vkCmdCopyImageToBuffer(commands, r.color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, r.picture.buffer, 1, &copy);
    copy.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    vkCmdCopyImageToBuffer(commands, r.depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, r.depth_values.buffer, 1, &copy);
    barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
            VK_ACCESS_SHADER_READ_BIT);
  } else {
    barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
            VK_ACCESS_SHADER_READ_BIT);
  }
  // No candidates yet, and no workgroups for fill_again.comp: (count, x, y, z) = (0, 0, 1, 1).
  const uint32_t no_candidates[kCandidateHeader] = {0, 0, 1, 1};
  vkCmdUpdateBuffer(commands, r.candidates.buffer, 0, sizeof no_candidates, no_candidates);
  barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.shade.layout, 0, 1, &r.shade_set, 0, nullptr);
  // A pipeline and its push constants with `axis`, for the dispatch that follows.
  auto use = [&](VkPipeline pipeline, uint32_t axis) {
    EdlPush p = push;
    p.axis = axis;
    vkCmdPushConstants(commands, r.shade.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(p), &p);
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  };
  // A pass of `group`² invocations a workgroup, each shading block_x × block_y pixels.
  auto pass = [&](VkPipeline pipeline, uint32_t axis, uint32_t group, uint32_t block_x, uint32_t block_y) {
    use(pipeline, axis);
    const uint32_t across = group * block_x, down = group * block_y;
    vkCmdDispatch(commands, (push.width + across - 1) / across, (push.height + down - 1) / down, 1);
  };
  const auto between = [&] {
    barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
            VK_ACCESS_SHADER_READ_BIT);
  };
  if (raster) {  // the compute backend's resolve wrote the log distances
    pass(r.shade.log, 0, kShadeGroupSize, 1, 1);
    between();
  }
  pass(r.shade.fill, 0, kShadeGroupSize, 1, 1);
  // The second filling over the first one's candidates (fill_again.comp): into the picture and log
  // distance the first read, then copied into what it wrote.
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
          VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
  for (uint32_t step : {0u, 1u}) {
    use(r.shade.fill_again, step);
    vkCmdDispatchIndirect(commands, r.candidates.buffer, sizeof(uint32_t));
    between();
  }
  if (r.shade.smooth_edl) {
    pass(r.shade.smooth_edl, 0, kShadeStripGroupSize, kShadeStripWidth, kShadeStripHeight);
  } else {
    pass(r.shade.smooth, 0, kShadeGroupSize, 1, 1);
    between();
    pass(r.shade.smooth, 1, kShadeGroupSize, 1, 1);
    between();
    pass(r.shade.edl, 0, kShadeGroupSize, 1, 1);
  }
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_TRANSFER_READ_BIT);
}

}  // namespace dpoint::detail
