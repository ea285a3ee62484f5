#include "vulkan/shader.h"

namespace dpoint {

Result<VkShaderModule> createShaderModule(const VulkanContext& context, const uint32_t* code, size_t bytes) {
  VkShaderModuleCreateInfo info = {VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = bytes;
  info.pCode = code;
  VkShaderModule module = VK_NULL_HANDLE;
  VK_TRY(vkCreateShaderModule(context.device, &info, nullptr, &module));
  return module;
}

Result<VkPipeline> createComputePipeline(const VulkanContext& context, const uint32_t* code, size_t bytes,
                                         VkPipelineLayout layout, std::span<const uint32_t> constants) {
  Result<VkShaderModule> module = createShaderModule(context, code, bytes);
  if (!module) return module.error();
  std::vector<VkSpecializationMapEntry> entries;
  for (uint32_t c = 0; c < constants.size(); ++c)
    entries.push_back({c, static_cast<uint32_t>(c * sizeof(uint32_t)), sizeof(uint32_t)});
  const VkSpecializationInfo specialization{static_cast<uint32_t>(entries.size()), entries.data(),
                                            constants.size_bytes(), constants.data()};
  VkComputePipelineCreateInfo info = {VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = *module;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = constants.empty() ? nullptr : &specialization;
  info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  const VkResult result = vkCreateComputePipelines(context.device, context.pipeline_cache, 1, &info, nullptr, &pipeline);
  vkDestroyShaderModule(context.device, *module, nullptr);
  if (result != VK_SUCCESS) return vulkanError("creating a compute pipeline", result);
  return pipeline;
}

Result<VkDescriptorSetLayout> storageSetLayout(const VulkanContext& context,
                                               const std::vector<VkDescriptorSetLayoutBinding>& bindings) {
  VkDescriptorSetLayoutCreateInfo info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  info.bindingCount = static_cast<uint32_t>(bindings.size());
  info.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  VK_TRY(vkCreateDescriptorSetLayout(context.device, &info, nullptr, &layout));
  return layout;
}

Result<VkDescriptorSet> storageSet(const VulkanContext& context, VkDescriptorSetLayout layout, uint32_t descriptors,
                                   VkDescriptorPool& pool) {
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, descriptors};
  VkDescriptorPoolCreateInfo pool_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &size;
  VK_TRY(vkCreateDescriptorPool(context.device, &pool_info, nullptr, &pool));
  VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  VK_TRY(vkAllocateDescriptorSets(context.device, &allocate, &set));
  return set;
}

Result<VkPipelineLayout> pipelineLayout(const VulkanContext& context, VkDescriptorSetLayout set, uint32_t push_bytes,
                                        VkShaderStageFlags stages) {
  VkPushConstantRange push{stages, 0, push_bytes};
  VkPipelineLayoutCreateInfo info = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  info.setLayoutCount = 1;
  info.pSetLayouts = &set;
  info.pushConstantRangeCount = 1;
  info.pPushConstantRanges = &push;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VK_TRY(vkCreatePipelineLayout(context.device, &info, nullptr, &layout));
  return layout;
}

Status computeLayouts(const VulkanContext& context, uint32_t storage_buffers, uint32_t push_bytes,
                      VkDescriptorSetLayout& set_layout, VkPipelineLayout& layout) {
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  for (uint32_t b = 0; b < storage_buffers; ++b)
    bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
  Result<VkDescriptorSetLayout> set = storageSetLayout(context, bindings);
  if (!set) return set.error();
  set_layout = *set;
  Result<VkPipelineLayout> pipeline = pipelineLayout(context, set_layout, push_bytes, VK_SHADER_STAGE_COMPUTE_BIT);
  if (!pipeline) return pipeline.error();
  layout = *pipeline;
  return okStatus();
}

void writeBufferDescriptors(const VulkanContext& context, VkDescriptorSet set,
                            std::span<const VkDescriptorBufferInfo> infos, bool first_is_uniform) {
  std::vector<VkWriteDescriptorSet> writes(infos.size());
  for (uint32_t b = 0; b < infos.size(); ++b) {
    writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = set;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = b == 0 && first_is_uniform ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  vkUpdateDescriptorSets(context.device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

}  // namespace dpoint
