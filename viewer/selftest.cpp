#include "viewer/selftest.h"

#include <cstring>

#include "vulkan/buffers.h"
#include "viewer/pipelines.h"
#include "vulkan/shader.h"

#include "shaders/selftest.comp.h"

namespace dpoint {

Result<SelfTest> runPrecisionSelfTest(const VulkanContext& context) {
  // Inputs: a = 1, b = 2^-30, c = 1 + 2^-12, splitter = 2^12 + 1. Exact answers:
  // two-sum(a, b) = (1, 2^-30); two-prod(c, c) = (1 + 2^-11, 2^-24) since c² = 1 + 2^-11 + 2^-24
  // and the float product rounds the last term away (a tie, to even); df add = (1, 2^-30).
  const float inputs[4] = {1.0f, 0x1p-30f, 1.0f + 0x1p-12f, 4097.0f};
  const float expected[6] = {1.0f, 0x1p-30f, 1.0f + 0x1p-11f, 0x1p-24f, 1.0f, 0x1p-30f};
  constexpr VkDeviceSize kBytes = 12 * sizeof(float);

  Result<Buffer> data = createBuffer(context, kBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "self-test data");
  if (!data) return data.error();
  std::memset(data->mapped, 0, kBytes);
  std::memcpy(data->mapped, inputs, sizeof(inputs));
  VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  range.memory = data->memory;
  range.size = VK_WHOLE_SIZE;
  if (!data->coherent) vkFlushMappedMemoryRanges(context.device, 1, &range);

  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkShaderModule module = VK_NULL_HANDLE;
  auto cleanup = [&]() {
    if (pool) vkDestroyDescriptorPool(context.device, pool, nullptr);
    if (pipeline) vkDestroyPipeline(context.device, pipeline, nullptr);
    if (layout) vkDestroyPipelineLayout(context.device, layout, nullptr);
    if (set_layout) vkDestroyDescriptorSetLayout(context.device, set_layout, nullptr);
    if (module) vkDestroyShaderModule(context.device, module, nullptr);
    destroyBuffer(context, *data);
  };
  auto run = [&]() -> Status {
    Result<VkShaderModule> shader = createShaderModule(context, kSelftestComp, sizeof(kSelftestComp));
    if (!shader) return shader.error();
    module = *shader;
    VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo set_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.bindingCount = 1;
    set_info.pBindings = &binding;
    VK_TRY(vkCreateDescriptorSetLayout(context.device, &set_info, nullptr, &set_layout));
    VkPipelineLayoutCreateInfo layout_info = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout;
    VK_TRY(vkCreatePipelineLayout(context.device, &layout_info, nullptr, &layout));
    VkComputePipelineCreateInfo pipeline_info = {VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pipeline_info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeline_info.stage.module = module;
    pipeline_info.stage.pName = "main";
    pipeline_info.layout = layout;
    VK_TRY(vkCreateComputePipelines(context.device, context.pipeline_cache, 1, &pipeline_info, nullptr, &pipeline));
    Result<VkDescriptorSet> set = storageSet(context, set_layout, 1, pool);
    if (!set) return set.error();
    const VkDescriptorBufferInfo buffer_info[1] = {{data->buffer, 0, VK_WHOLE_SIZE}};
    writeBufferDescriptors(context, *set, buffer_info);
    return submitOnce(context, [&](VkCommandBuffer commands) {
      vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
      vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &*set, 0, nullptr);
      vkCmdDispatch(commands, 1, 1, 1);
      VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier,
                           0, nullptr, 0, nullptr);
    });
  };
  Status status = run();
  if (status) status = invalidateBuffer(context, *data);
  SelfTest out;
  if (status) {
    float results[6];
    std::memcpy(results, static_cast<const float*>(data->mapped) + 4, sizeof(results));
    out.low_parts_survive = std::memcmp(results, expected, sizeof(expected)) == 0;
    char text[256];
    std::snprintf(text, sizeof(text), "two-sum (%a, %a), two-prod (%a, %a), df add (%a, %a)", results[0], results[1],
                  results[2], results[3], results[4], results[5]);
    out.detail = text;
  }
  cleanup();
  if (!status) return status.error();
  return out;
}

Status modeUsable(const VulkanContext& context, PrecisionMode mode, const SelfTest& self_test, bool probe) {
  const DeviceFacts& f = context.facts;
  const ModeInfo& info = modeInfo(mode);
  std::string name(info.name);
  if (info.needs_shader_float64 && !f.shader_float64)
    return Error{"--mode " + name + " needs shaderFloat64, which " + f.name + " lacks", ExitCode::kNoDevice};
  if (info.needs_self_test && !self_test.low_parts_survive)
    return Error{"--mode " + name + " is unusable on " + f.name +
                     ": its shader compiler folds away the low parts of exact sums despite `precise` (self-test: " +
                     self_test.detail + ")",
                 ExitCode::kNoDevice};
  if (probe && !f.vertex_stores)
    return Error{"--error needs vertexPipelineStoresAndAtomics, which " + f.name + " lacks", ExitCode::kNoDevice};
  return okStatus();
}

}  // namespace dpoint
