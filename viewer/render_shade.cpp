// Shading after either backend (RenderOptions::shading): the raster backend's colour and depth
// attachments are copied into buffers, the compute backend's resolve writes them there itself;
// then four passes (shaders/render/shade_common.glsl names them: hole filling, the depth smoothed
// along rows and columns, eye-dome lighting) write the shaded picture that is read back.
#include <algorithm>
#include <cmath>

#include "viewer/render_internal.h"

namespace dpoint::detail {

Status createShadeTargets(const VulkanContext& context, Resources& r, uint32_t width, uint32_t height, bool raster,
                          float point_size) {
  Result<ShadePipeline> pipeline = createShadePipeline(context, shadeRadii(point_size));
  if (!pipeline) return pipeline.error();
  r.shade = *pipeline;
  const VkDeviceSize bytes = VkDeviceSize{width} * height * 4;
  const VkBufferUsageFlags in_usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  Result<Buffer> depth = createBuffer(context, bytes, in_usage, false, "depth per pixel");
  if (!depth) return depth.error();
  r.depth_values = *depth;
  if (raster) {
    Result<Buffer> picture = createBuffer(context, bytes, in_usage, false, "picture before shading");
    if (!picture) return picture.error();
    r.picture = *picture;
  }
  Result<Buffer> shaded = createBuffer(context, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                       false, "shaded picture");
  if (!shaded) return shaded.error();
  r.shaded = *shaded;
  struct Between {
    Buffer* buffer;
    VkDeviceSize bytes;
    const char* what;
  };
  for (const Between& b : {Between{&r.filled_log, bytes, "log distance after hole filling"},
                           Between{&r.filled_picture, bytes, "picture after hole filling"},
                           Between{&r.partial, 2 * bytes, "row sums of the log distance"},
                           Between{&r.smoothed, bytes, "smoothed log distance"}}) {
    Result<Buffer> buffer = createBuffer(context, b.bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, b.what);
    if (!buffer) return buffer.error();
    *b.buffer = *buffer;
  }
  return okStatus();
}

Status createShadeDescriptors(const VulkanContext& context, Resources& r) {
  VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = r.descriptor_pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &r.shade.set_layout;
  VK_TRY(vkAllocateDescriptorSets(context.device, &allocate, &r.shade_set));
  const VkDescriptorBufferInfo infos[kShadeBindings] = {
      {r.depth_values.buffer, 0, VK_WHOLE_SIZE}, {r.picture.buffer, 0, VK_WHOLE_SIZE},
      {r.shaded.buffer, 0, VK_WHOLE_SIZE},       {r.filled_log.buffer, 0, VK_WHOLE_SIZE},
      {r.filled_picture.buffer, 0, VK_WHOLE_SIZE}, {r.partial.buffer, 0, VK_WHOLE_SIZE},
      {r.smoothed.buffer, 0, VK_WHOLE_SIZE}};
  writeBufferDescriptors(context, r.shade_set, infos);
  return okStatus();
}

EdlPush edlPush(const Camera& camera, const EdlOptions& options, float point_size) {
  EdlPush push;
  push.width = camera.width;
  push.height = camera.height;
  // Reversed-Z perspective depth is n(f − t) / (t(f − n)) at eye distance t, so
  // t = f / (1 + depth · (f − n) / n); the shader needs only (f − n) / n.
  push.depth_scale = camera.ortho ? 0.0f
                                  : static_cast<float>((camera.far_plane - camera.near_plane) / camera.near_plane);
  push.strength = options.strength;
  push.radius = options.radius;
  // Hole filling's threshold: the change in log2 eye distance over its radius across a surface at
  // 72° to the view (slope 3), so the steps within one surface never count as standing in front.
  // A pixel spans 2 / (focal · height) of the distance in perspective (focal = P[1][1] / P[2][3])
  // and 2 · P[2][2] / (|P[1][1]| · height) of the depth range in ortho.
  const glm::dmat4& p = camera.projection;
  const double pixel = camera.ortho ? 2.0 * p[2][2] / (std::abs(p[1][1]) * camera.height)
                                    : 2.0 * p[2][3] / (p[1][1] * camera.height);
  push.fill_threshold = static_cast<float>(3.0 * shadeRadii(point_size).fill * pixel / std::log(2.0));
  return push;
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
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.shade.layout, 0, 1, &r.shade_set, 0, nullptr);
  const uint32_t groups_x = (push.width + kShadeGroupSize - 1) / kShadeGroupSize;
  const uint32_t groups_y = (push.height + kShadeGroupSize - 1) / kShadeGroupSize;
  auto pass = [&](VkPipeline pipeline, uint32_t axis) {
    EdlPush p = push;
    p.axis = axis;
    vkCmdPushConstants(commands, r.shade.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(p), &p);
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdDispatch(commands, groups_x, groups_y, 1);
  };
  const auto between = [&] {
    barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
            VK_ACCESS_SHADER_READ_BIT);
  };
  pass(r.shade.fill, 0);
  between();
  pass(r.shade.smooth, 0);
  between();
  pass(r.shade.smooth, 1);
  between();
  pass(r.shade.edl, 0);
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_TRANSFER_READ_BIT);
}

}  // namespace dpoint::detail
