// Shader modules, descriptor-set and pipeline layouts, and descriptor writes: the pieces of a
// pipeline that the renderer (viewer/pipelines.h), the GPU generators (generators/gpu_generate.h)
// and the bench's copy kernel build the same way. Every VkResult is checked (VK_TRY).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/result.h"
#include "vulkan/context.h"

namespace dpoint {

// Creates a shader module from SPIR-V words.
Result<VkShaderModule> createShaderModule(const VulkanContext& context, const uint32_t* code, size_t bytes);

// A descriptor set layout of these bindings, and a pipeline layout of one set and push_bytes of
// push constants from offset 0 for `stages`.
Result<VkDescriptorSetLayout> storageSetLayout(const VulkanContext& context,
                                               const std::vector<VkDescriptorSetLayoutBinding>& bindings);
Result<VkPipelineLayout> pipelineLayout(const VulkanContext& context, VkDescriptorSetLayout set, uint32_t push_bytes,
                                        VkShaderStageFlags stages);

// Both for a compute shader of `storage_buffers` storage buffers (bindings 0, 1, …) and push_bytes
// of push constants, into `set_layout` and `layout` (which the caller destroys, also on an error).
Status computeLayouts(const VulkanContext& context, uint32_t storage_buffers, uint32_t push_bytes,
                      VkDescriptorSetLayout& set_layout, VkPipelineLayout& layout);

// A descriptor pool for one set of `descriptors` storage buffers (into `pool`, which the caller
// destroys, also when the set cannot be allocated), and that set of `layout`.
Result<VkDescriptorSet> storageSet(const VulkanContext& context, VkDescriptorSetLayout layout, uint32_t descriptors,
                                   VkDescriptorPool& pool);

// A compute pipeline of the SPIR-V `code` (entry point main) with `layout`, and the 32-bit
// specialization constants 0, 1, … given (none: the shader's defaults).
Result<VkPipeline> createComputePipeline(const VulkanContext& context, const uint32_t* code, size_t bytes,
                                         VkPipelineLayout layout, std::span<const uint32_t> constants = {});

// Points bindings 0, 1, … of `set` at whole buffers (`infos`, in binding order): storage buffers,
// but binding 0 a uniform buffer when `first_is_uniform`.
void writeBufferDescriptors(const VulkanContext& context, VkDescriptorSet set,
                            std::span<const VkDescriptorBufferInfo> infos, bool first_is_uniform = false);

}  // namespace dpoint
