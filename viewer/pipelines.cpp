#include "viewer/pipelines.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <optional>
#include <span>
#include <vector>

#include "shaders/points.frag.h"
#include "shaders/points_round.frag.h"
#include "shaders/edl.comp.h"
#include "shaders/fill.comp.h"
#include "shaders/fill_again.comp.h"
#include "shaders/log.comp.h"
#include "shaders/smooth.comp.h"
#include "shaders/smooth_edl.comp.h"
#include "shaders/points_resolve.comp.h"

namespace dpoint {
namespace {

// The raster vertex shader of the mode: the pull variant where asked for and the mode has one.
Spirv vertexShader(PrecisionMode mode, bool pull) {
  const ModeShaders& shaders = modeInfo(mode).shaders;
  return pull && shaders.vertex_pull.code ? shaders.vertex_pull : shaders.vertex;
}

// 32-bit specialization constants 0, 1, …: the splat's 0 kProbe, 1 kEarlyDepth, 2 kSubgroupMerge, 3 kPairMerge, 4 kLargePoints, 5 kRound and 6 kNearEndFirst, the resolve's
// 0 kWriteDepth, the shading passes' radii (fill.comp's 0, smooth.comp's 0, smooth_edl.comp's 0-2).
Result<VkPipeline> computePipeline(const VulkanContext& context, Spirv code, VkPipelineLayout layout,
                                   std::span<const uint32_t> constants) {
  return createComputePipeline(context, code.code, code.bytes, layout, constants);
}

Result<VkPipeline> computePipeline(const VulkanContext& context, Spirv code, VkPipelineLayout layout, bool probe,
                                   const SplatVariant& v) {
  const uint32_t constants[7] = {probe ? VK_TRUE : VK_FALSE, v.early_depth ? VK_TRUE : VK_FALSE,
                                 v.subgroup_merge ? VK_TRUE : VK_FALSE, v.pair_merge ? VK_TRUE : VK_FALSE,
                                 v.large_points ? VK_TRUE : VK_FALSE, v.large_points && v.round ? VK_TRUE : VK_FALSE,
                                 v.near_end_first ? VK_TRUE : VK_FALSE};
  return computePipeline(context, code, layout, constants);
}

// keep_depth: the depth attachment is stored and left in TRANSFER_SRC_OPTIMAL for the eye-dome
// pass to copy; otherwise it is discarded.
Result<VkRenderPass> createRenderPass(const VulkanContext& context, bool keep_depth) {
  VkAttachmentDescription attachments[2] = {};
  attachments[0].format = kColorFormat;
  attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
  attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  attachments[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  attachments[1] = attachments[0];
  attachments[1].format = kDepthFormat;
  attachments[1].storeOp = keep_depth ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[1].finalLayout = keep_depth ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  VkAttachmentReference color_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &color_ref;
  subpass.pDepthStencilAttachment = &depth_ref;
  // Frames follow one another on the same attachments, and the colour is copied out after.
  VkSubpassDependency dependencies[2] = {};
  dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  dependencies[0].dstSubpass = 0;
  dependencies[0].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                                 VK_PIPELINE_STAGE_TRANSFER_BIT;
  dependencies[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT;
  dependencies[0].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                                  VK_ACCESS_TRANSFER_READ_BIT;
  dependencies[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                                  VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
  dependencies[1].srcSubpass = 0;
  dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  dependencies[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                 (keep_depth ? VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT : 0);
  dependencies[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dependencies[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                                  (keep_depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT : 0);
  dependencies[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo info = {VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 2;
  info.pAttachments = attachments;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = dependencies;
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VK_TRY(vkCreateRenderPass(context.device, &info, nullptr, &render_pass));
  return render_pass;
}

Result<VkPipeline> createPipeline(const VulkanContext& context, const PointPipelines& p, PrecisionMode mode, bool pull,
                                  bool probe, uint32_t width, uint32_t height, bool round) {
  Spirv vertex_code = vertexShader(mode, pull);
  Result<VkShaderModule> vertex = createShaderModule(context, vertex_code.code, vertex_code.bytes);
  if (!vertex) return vertex.error();
  // Round points write their depth (gl_FragDepth) in a shader of their own, so the square one keeps
  // the early depth test.
  Result<VkShaderModule> fragment = round ? createShaderModule(context, kPointsRoundFrag, sizeof(kPointsRoundFrag))
                                          : createShaderModule(context, kPointsFrag, sizeof(kPointsFrag));
  if (!fragment) {
    vkDestroyShaderModule(context.device, *vertex, nullptr);
    return fragment.error();
  }
  VkBool32 probe_value = probe ? VK_TRUE : VK_FALSE;
  VkSpecializationMapEntry entry{0, 0, sizeof(VkBool32)};
  VkSpecializationInfo specialization{1, &entry, sizeof(probe_value), &probe_value};
  VkPipelineShaderStageCreateInfo stages[2] = {{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO},
                                               {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO}};
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = *vertex;
  stages[0].pName = "main";
  stages[0].pSpecializationInfo = &specialization;
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = *fragment;
  stages[1].pName = "main";

  // Binding 0: positions in the mode's layout; binding 1: RGBA8 colours (location 2).
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attributes;
  if (!p.pulls_positions) bindings.push_back({0, positionBytes(mode), VK_VERTEX_INPUT_RATE_VERTEX});
  bindings.push_back({1, 4, VK_VERTEX_INPUT_RATE_VERTEX});
  if (!p.pulls_positions) {
    const ModeShaders& shaders = modeInfo(mode).shaders;
    for (uint32_t a = 0; a < shaders.attribute_count; ++a)
      attributes.push_back({shaders.attributes[a].location, 0, shaders.attributes[a].format, shaders.attributes[a].offset});
  }
  attributes.push_back({2, 1, VK_FORMAT_R8G8B8A8_UNORM, 0});
  VkPipelineVertexInputStateCreateInfo vertex_input = {VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  vertex_input.vertexBindingDescriptionCount = static_cast<uint32_t>(bindings.size());
  vertex_input.pVertexBindingDescriptions = bindings.data();
  vertex_input.vertexAttributeDescriptionCount = static_cast<uint32_t>(attributes.size());
  vertex_input.pVertexAttributeDescriptions = attributes.data();

  VkPipelineInputAssemblyStateCreateInfo assembly = {VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
  VkViewport viewport{0.0f, 0.0f, static_cast<float>(width), static_cast<float>(height), 0.0f, 1.0f};
  VkRect2D scissor{{0, 0}, {width, height}};
  VkPipelineViewportStateCreateInfo viewport_state = {VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  viewport_state.viewportCount = 1;
  viewport_state.pViewports = &viewport;
  viewport_state.scissorCount = 1;
  viewport_state.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo raster = {VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = VK_CULL_MODE_NONE;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  raster.lineWidth = 1.0f;
  VkPipelineMultisampleStateCreateInfo multisample = {VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  // Reversed Z: cleared to 0, nearer is greater; on a tie the point drawn first stays.
  VkPipelineDepthStencilStateCreateInfo depth = {VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  depth.depthTestEnable = VK_TRUE;
  depth.depthWriteEnable = VK_TRUE;
  depth.depthCompareOp = VK_COMPARE_OP_GREATER;
  VkPipelineColorBlendAttachmentState blend_attachment{};
  blend_attachment.colorWriteMask =
      VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  VkPipelineColorBlendStateCreateInfo blend = {VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  blend.attachmentCount = 1;
  blend.pAttachments = &blend_attachment;

  VkGraphicsPipelineCreateInfo info = {VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &vertex_input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &viewport_state;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &multisample;
  info.pDepthStencilState = &depth;
  info.pColorBlendState = &blend;
  info.layout = p.layout;
  info.renderPass = p.render_pass;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkResult result = vkCreateGraphicsPipelines(context.device, context.pipeline_cache, 1, &info, nullptr, &pipeline);
  vkDestroyShaderModule(context.device, *vertex, nullptr);
  vkDestroyShaderModule(context.device, *fragment, nullptr);
  if (result != VK_SUCCESS)
    return vulkanError("creating the " + std::string(modeName(mode)) + (probe ? " probe" : "") + " pipeline", result);
  return pipeline;
}

}  // namespace

Result<PointPipelines> createPointPipelines(const VulkanContext& context, PrecisionMode mode, bool pull,
                                            bool with_probe, uint32_t width, uint32_t height, bool keep_depth,
                                            bool round) {
  PointPipelines p;
  p.pulls_positions = pull && modeInfo(mode).shaders.vertex_pull.code != nullptr;
  auto fail = [&](const Error& error) -> Result<PointPipelines> {
    destroyPointPipelines(context, p);
    return error;
  };
  Result<VkRenderPass> render_pass = createRenderPass(context, keep_depth);
  if (!render_pass) return fail(render_pass.error());
  p.render_pass = *render_pass;

  // Binding 4 is the compute backend's visibility buffer: unused here, kept so the bindings run
  // 0 to 5 as in the compute set (descriptors are written in binding order).
  VkDescriptorSetLayoutBinding bindings[6] = {
      {kBindingCamera, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {kBindingPositions, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {kBindingBatches, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {kBindingProbe, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {kBindingVisibility, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
      {kBindingBatchPlan, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr},
  };
  VkDescriptorSetLayoutCreateInfo set_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_info.bindingCount = 6;
  set_info.pBindings = bindings;
  VkResult result = vkCreateDescriptorSetLayout(context.device, &set_info, nullptr, &p.set_layout);
  if (result != VK_SUCCESS) return fail(vulkanError("vkCreateDescriptorSetLayout", result));
  VkPushConstantRange push{kPointPushStages, 0, sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo layout_info = {VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &p.set_layout;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  result = vkCreatePipelineLayout(context.device, &layout_info, nullptr, &p.layout);
  if (result != VK_SUCCESS) return fail(vulkanError("vkCreatePipelineLayout", result));

  Result<VkPipeline> draw = createPipeline(context, p, mode, pull, false, width, height, round);
  if (!draw) return fail(draw.error());
  p.draw = *draw;
  if (with_probe) {
    Result<VkPipeline> probe = createPipeline(context, p, mode, pull, true, width, height, round);
    if (!probe) return fail(probe.error());
    p.probe = *probe;
  }
  return p;
}

Result<ComputePipelines> createComputePipelines(const VulkanContext& context, PrecisionMode mode, bool with_probe,
                                                SplatVariant variant, bool write_log) {
  ComputePipelines p;
  auto fail = [&](const Error& error) -> Result<ComputePipelines> {
    destroyComputePipelines(context, p);
    return error;
  };
  auto storage = [](uint32_t binding) {
    return VkDescriptorSetLayoutBinding{binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  };
  Result<VkDescriptorSetLayout> splat_set = storageSetLayout(context, {
      {kBindingCamera, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      storage(kBindingPositions), storage(kBindingBatches), storage(kBindingProbe), storage(kBindingVisibility),
      storage(kBindingBatchPlan)});
  if (!splat_set) return fail(splat_set.error());
  p.splat_set = *splat_set;
  Result<VkPipelineLayout> splat_layout = pipelineLayout(context, p.splat_set, sizeof(PushConstants), VK_SHADER_STAGE_COMPUTE_BIT);
  if (!splat_layout) return fail(splat_layout.error());
  p.splat_layout = *splat_layout;
  if (Status s = computeLayouts(context, 4, sizeof(ResolvePush), p.resolve_set, p.resolve_layout); !s) return fail(s.error());
  // The merges only where early depth is on (the plain path the tests compare with keeps an
  // atomic per point).
  variant.subgroup_merge = variant.early_depth && variant.subgroup_merge && context.facts.subgroup_merge;
  variant.pair_merge = variant.early_depth && variant.pair_merge;
  Result<VkPipeline> splat = computePipeline(context, modeInfo(mode).shaders.splat, p.splat_layout, false, variant);
  if (!splat) return fail(splat.error());
  p.splat = *splat;
  if (with_probe) {
    Result<VkPipeline> probe = computePipeline(context, modeInfo(mode).shaders.splat, p.splat_layout, true, variant);
    if (!probe) return fail(probe.error());
    p.probe = *probe;
  }
  const uint32_t resolve_constants[1] = {write_log ? VK_TRUE : VK_FALSE};
  Result<VkPipeline> resolve = computePipeline(context, {kPointsResolveComp, sizeof(kPointsResolveComp)}, p.resolve_layout,
                                                 resolve_constants);
  if (!resolve) return fail(resolve.error());
  p.resolve = *resolve;
  return p;
}

void destroyComputePipelines(const VulkanContext& context, ComputePipelines& p) {
  for (VkPipeline pipeline : {p.splat, p.probe, p.resolve})
    if (pipeline) vkDestroyPipeline(context.device, pipeline, nullptr);
  for (VkPipelineLayout layout : {p.splat_layout, p.resolve_layout})
    if (layout) vkDestroyPipelineLayout(context.device, layout, nullptr);
  for (VkDescriptorSetLayout set : {p.splat_set, p.resolve_set})
    if (set) vkDestroyDescriptorSetLayout(context.device, set, nullptr);
  p = ComputePipelines{};
}

// The radii follow the point size up to 8 px: larger points are a sparse set's round ones (up to
// 64 px), which overlap and leave no staircase or gap as wide as themselves; following them made
// the shaders' loops (unrolled) long and a 1,065-point survey's default render 2x slower on lavapipe.
ShadeRadii shadeRadii(float point_size, float edl_radius, bool fuse) {
  const int size = static_cast<int>(std::ceil(std::clamp(point_size, 1.0f, 8.0f)));
  ShadeRadii radii;
  radii.fill = (size + 1) / 2 + 1;
  radii.smooth = size - 1;
  // The 8 neighbours on a circle of the radius, to the nearest pixel, in float as the shader
  // rounded them before: along the axes and along the diagonals.
  radii.edl_axis = static_cast<int>(std::round(edl_radius));
  radii.edl_diagonal = static_cast<int>(std::round(edl_radius * 0.70710678f));
  radii.fused = fuse && radii.smooth <= kMaxFusedSmooth && std::max(radii.edl_axis, radii.edl_diagonal) <= kMaxFusedReach;
  return radii;
}

int ShadeRadii::margin() const {
  const int reach = std::max(edl_axis, edl_diagonal);
  // smooth_edl.comp reads reach + smooth pixels around each strip, the last strips reaching up to
  // kShadeStripHeight − 1 pixels past the picture.
  return std::max({fill, fused ? int{kShadeStripHeight} - 1 + smooth + reach : std::max(smooth, reach)});
}

Result<ShadePipeline> createShadePipeline(const VulkanContext& context, ShadeRadii radii) {
  ShadePipeline p;
  auto fail = [&](const Error& error) -> Result<ShadePipeline> {
    destroyShadePipeline(context, p);
    return error;
  };
  std::vector<VkDescriptorSetLayoutBinding> bindings;
  for (uint32_t b = 0; b < kShadeBindings; ++b)
    bindings.push_back({b, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
  Result<VkDescriptorSetLayout> set = storageSetLayout(context, bindings);
  if (!set) return fail(set.error());
  p.set_layout = *set;
  Result<VkPipelineLayout> layout = pipelineLayout(context, p.set_layout, sizeof(EdlPush), VK_SHADER_STAGE_COMPUTE_BIT);
  if (!layout) return fail(layout.error());
  p.layout = *layout;
  struct Stage {
    VkPipeline* pipeline;
    Spirv code;
    std::vector<uint32_t> constants;
  };
  const auto u = [](int v) { return static_cast<uint32_t>(v); };
  const Stage stages[] = {
      {&p.log, {kLogComp, sizeof(kLogComp)}, {}},
      {&p.fill, {kFillComp, sizeof(kFillComp)}, {u(radii.fill)}},
      {&p.fill_again, {kFillAgainComp, sizeof(kFillAgainComp)}, {u(radii.fill)}},
      {radii.fused ? &p.smooth_edl : &p.smooth,
       radii.fused ? Spirv{kSmoothEdlComp, sizeof(kSmoothEdlComp)} : Spirv{kSmoothComp, sizeof(kSmoothComp)},
       {u(radii.smooth), u(radii.edl_axis), u(radii.edl_diagonal)}},
      {radii.fused ? nullptr : &p.edl, {kEdlComp, sizeof(kEdlComp)}, {}}};
  // Each on a thread of its own: lavapipe lowers and optimizes a shader's NIR whenever a pipeline
  // is made (only the machine code is cached on disk), 3-4 ms for fill.comp and 7-16 ms for
  // smooth_edl.comp, which the threads spread over the cores.
  std::vector<std::future<Result<VkPipeline>>> made;
  for (const Stage& stage : stages)
    if (stage.pipeline)
      made.push_back(std::async(std::launch::async, [&context, &stage, layout = p.layout] {
        return computePipeline(context, stage.code, layout, stage.constants);
      }));
  std::optional<Error> failed;
  size_t next = 0;
  for (const Stage& stage : stages) {
    if (!stage.pipeline) continue;
    Result<VkPipeline> pipeline = made[next++].get();
    if (pipeline) *stage.pipeline = *pipeline;
    else if (!failed) failed = pipeline.error();
  }
  if (failed) return fail(*failed);
  return p;
}

void destroyShadePipeline(const VulkanContext& context, ShadePipeline& p) {
  if (p.edl) vkDestroyPipeline(context.device, p.edl, nullptr);
  if (p.log) vkDestroyPipeline(context.device, p.log, nullptr);
  if (p.fill) vkDestroyPipeline(context.device, p.fill, nullptr);
  if (p.fill_again) vkDestroyPipeline(context.device, p.fill_again, nullptr);
  if (p.smooth_edl) vkDestroyPipeline(context.device, p.smooth_edl, nullptr);
  if (p.smooth) vkDestroyPipeline(context.device, p.smooth, nullptr);
  if (p.layout) vkDestroyPipelineLayout(context.device, p.layout, nullptr);
  if (p.set_layout) vkDestroyDescriptorSetLayout(context.device, p.set_layout, nullptr);
  p = ShadePipeline{};
}

void destroyPointPipelines(const VulkanContext& context, PointPipelines& p) {
  if (p.probe) vkDestroyPipeline(context.device, p.probe, nullptr);
  if (p.draw) vkDestroyPipeline(context.device, p.draw, nullptr);
  if (p.layout) vkDestroyPipelineLayout(context.device, p.layout, nullptr);
  if (p.set_layout) vkDestroyDescriptorSetLayout(context.device, p.set_layout, nullptr);
  if (p.render_pass) vkDestroyRenderPass(context.device, p.render_pass, nullptr);
  p = PointPipelines{};
}

}  // namespace dpoint
