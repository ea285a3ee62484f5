// Eye-dome lighting after either backend (RenderOptions::shading): the raster backend's colour
// and depth attachments are copied into buffers, the compute backend's resolve writes them
// there itself; then one pass (shaders/render/edl.comp) writes the shaded picture that is read back.
#include "viewer/render_internal.h"

namespace dpoint::detail {

Status createShadeTargets(const VulkanContext& context, Resources& r, uint32_t width, uint32_t height, bool raster) {
  Result<ShadePipeline> pipeline = createShadePipeline(context);
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
  return okStatus();
}

Status createShadeDescriptors(const VulkanContext& context, Resources& r) {
  VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = r.descriptor_pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &r.shade.set_layout;
  VK_TRY(vkAllocateDescriptorSets(context.device, &allocate, &r.shade_set));
  const VkDescriptorBufferInfo infos[3] = {{r.depth_values.buffer, 0, VK_WHOLE_SIZE},
                                           {r.picture.buffer, 0, VK_WHOLE_SIZE},
                                           {r.shaded.buffer, 0, VK_WHOLE_SIZE}};
  writeBufferDescriptors(context, r.shade_set, infos);
  return okStatus();
}

EdlPush edlPush(const Camera& camera, const EdlOptions& options) {
  EdlPush push;
  push.width = camera.width;
  push.height = camera.height;
  // Reversed-Z perspective depth is n(f − t) / (t(f − n)) at eye distance t, so
  // t = f / (1 + depth · (f − n) / n); the shader needs only (f − n) / n.
  push.depth_scale = camera.ortho ? 0.0f
                                  : static_cast<float>((camera.far_plane - camera.near_plane) / camera.near_plane);
  push.strength = options.strength;
  push.radius = options.radius;
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
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.shade.edl);
  vkCmdPushConstants(commands, r.shade.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, r.shade.layout, 0, 1, &r.shade_set, 0, nullptr);
  vkCmdDispatch(commands, (push.width + kShadeGroupSize - 1) / kShadeGroupSize,
                (push.height + kShadeGroupSize - 1) / kShadeGroupSize, 1);
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_TRANSFER_READ_BIT);
}

}  // namespace dpoint::detail
