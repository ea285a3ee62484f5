#include "bench/bandwidth.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "core/memory.h"
#include "shaders/copy.comp.h"
#include "vulkan/buffers.h"
#include "viewer/pipelines.h"

namespace dpoint {
namespace {

// Everything the measurement creates, released on every path out.
struct CopyScratch {
  const VulkanContext& context;
  Buffer source, target;
  VkQueryPool queries = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;
  ~CopyScratch() {
    if (pool) vkDestroyDescriptorPool(context.device, pool, nullptr);
    if (pipeline) vkDestroyPipeline(context.device, pipeline, nullptr);
    if (layout) vkDestroyPipelineLayout(context.device, layout, nullptr);
    if (set_layout) vkDestroyDescriptorSetLayout(context.device, set_layout, nullptr);
    if (queries) vkDestroyQueryPool(context.device, queries, nullptr);
    destroyBuffer(context, target);
    destroyBuffer(context, source);
  }
};

// Earlier transfers (the fill, the previous copy, in this or an earlier submission) before the next
// copy reads the source and writes the target again.
// (The structs here start from {} and get their sType after: the bench library, unlike viewer/,
// keeps -Wmissing-field-initializers, which `= {VK_STRUCTURE_TYPE_...}` trips.)
void accessBarrier(VkCommandBuffer commands) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT |
                          VK_ACCESS_SHADER_WRITE_BIT;
  constexpr VkPipelineStageFlags kStages = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  vkCmdPipelineBarrier(commands, kStages, kStages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

// shaders/bench/copy.comp bound to the scratch buffers: layout, pipeline and descriptor set.
Status createShaderCopy(const VulkanContext& context, CopyScratch& s) {
  VkDescriptorSetLayoutBinding bindings[2] = {
      {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr}};
  VkDescriptorSetLayoutCreateInfo set_info{};
  set_info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  set_info.bindingCount = 2;
  set_info.pBindings = bindings;
  VK_TRY(vkCreateDescriptorSetLayout(context.device, &set_info, nullptr, &s.set_layout));
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(uint32_t)};
  VkPipelineLayoutCreateInfo layout_info{};
  layout_info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &s.set_layout;
  layout_info.pushConstantRangeCount = 1;
  layout_info.pPushConstantRanges = &push;
  VK_TRY(vkCreatePipelineLayout(context.device, &layout_info, nullptr, &s.layout));
  Result<VkShaderModule> module = createShaderModule(context, kCopyComp, sizeof(kCopyComp));
  if (!module) return module.error();
  VkComputePipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = *module;
  info.stage.pName = "main";
  info.layout = s.layout;
  VkResult result = vkCreateComputePipelines(context.device, context.pipeline_cache, 1, &info, nullptr, &s.pipeline);
  vkDestroyShaderModule(context.device, *module, nullptr);
  VK_TRY(result);
  Result<VkDescriptorSet> set = storageSet(context, s.set_layout, 2, s.pool);
  if (!set) return set.error();
  s.set = *set;
  VkDescriptorBufferInfo infos[2] = {{s.source.buffer, 0, VK_WHOLE_SIZE}, {s.target.buffer, 0, VK_WHOLE_SIZE}};
  writeBufferDescriptors(context, s.set, infos);
  return okStatus();
}

}  // namespace

uint64_t defaultCopyBytes(const VulkanContext& context) {
  uint64_t bytes = context.facts.type == "cpu" ? 256ull << 20 : 1ull << 30;
  if (context.facts.max_memory_allocation) bytes = std::min(bytes, context.facts.max_memory_allocation);
  uint64_t heap = 0;
  for (uint32_t h = 0; h < context.memory.memoryHeapCount; ++h)
    if (context.memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      heap = std::max<uint64_t>(heap, context.memory.memoryHeaps[h].size);
  if (heap) bytes = std::min(bytes, heap / 4);
  const uint64_t mib = 1ull << 20;
  return bytes >= mib ? bytes / mib * mib : bytes;
}

Result<CopyBandwidth> measureCopyBandwidth(const VulkanContext& context, const CopyBandwidthOptions& options) {
  assert(options.copies >= 1);
  const uint64_t bytes = options.bytes ? options.bytes : defaultCopyBytes(context);
  if (bytes == 0) return Error{"copy bandwidth: the device has no device-local memory to copy", ExitCode::kNoDevice};
  if (context.facts.max_memory_allocation && bytes > context.facts.max_memory_allocation)
    return Error{"copy bandwidth: a copy of " + formatBytes(bytes) + " is above the device's maxMemoryAllocationSize (" +
                     formatBytes(context.facts.max_memory_allocation) + ")",
                 ExitCode::kResourceLimit};
  CopyScratch s{context, {}, {}, VK_NULL_HANDLE};
  Result<Buffer> source = createBuffer(context, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "copy bandwidth source");
  if (!source) return source.error();
  s.source = *source;
  Result<Buffer> target = createBuffer(context, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                       false, "copy bandwidth target");
  if (!target) return target.error();
  s.target = *target;
  const bool timestamps = context.facts.timestamp_period_ns > 0.0f;
  if (timestamps) {
    VkQueryPoolCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = 2;
    VK_TRY(vkCreateQueryPool(context.device, &info, nullptr, &s.queries));
  }
  // A non-zero pattern in both buffers: every page written once before anything is timed.
  Status filled = submitOnce(context, [&](VkCommandBuffer commands) {
    vkCmdFillBuffer(commands, s.source.buffer, 0, VK_WHOLE_SIZE, 0x5a5a5a5au);
    vkCmdFillBuffer(commands, s.target.buffer, 0, VK_WHOLE_SIZE, 0xa5a5a5a5u);
  });
  if (!filled) return filled.error();

  // Median time of `record` over options.copies submissions after options.warmup, each after a
  // barrier on every earlier transfer and shader access to the two buffers.
  auto time = [&](const std::function<void(VkCommandBuffer)>& record) -> Result<double> {
    std::vector<double> ms;
    for (uint32_t i = 0; i < options.warmup + options.copies; ++i) {
      const auto start = std::chrono::steady_clock::now();
      Status copied = submitOnce(context, [&](VkCommandBuffer commands) {
        accessBarrier(commands);
        if (timestamps) {
          vkCmdResetQueryPool(commands, s.queries, 0, 2);
          vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, s.queries, 0);
        }
        record(commands);
        if (timestamps) vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries, 1);
      });
      if (!copied) return copied.error();
      const double wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      if (i < options.warmup) continue;
      if (!timestamps) {
        ms.push_back(wall_ms);
        continue;
      }
      uint64_t ticks[2] = {0, 0};
      VK_TRY(vkGetQueryPoolResults(context.device, s.queries, 0, 2, sizeof(ticks), ticks, sizeof(uint64_t),
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
      ms.push_back(static_cast<double>(ticks[1] - ticks[0]) * context.facts.timestamp_period_ns * 1e-6);
    }
    return medianOf(ms);
  };
  const VkBufferCopy region{0, 0, bytes};
  Result<double> copy_ms = time([&](VkCommandBuffer commands) {
    vkCmdCopyBuffer(commands, s.source.buffer, s.target.buffer, 1, &region);
  });
  if (!copy_ms) return copy_ms.error();
  if (Status status = createShaderCopy(context, s); !status) return status.error();
  const uint32_t words = static_cast<uint32_t>(bytes / 16);
  const uint32_t groups = std::min<uint32_t>(context.facts.max_dispatch_groups_x, (words + 255) / 256);
  Result<double> shader_ms = time([&](VkCommandBuffer commands) {
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, s.pipeline);
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, s.layout, 0, 1, &s.set, 0, nullptr);
    vkCmdPushConstants(commands, s.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(words), &words);
    vkCmdDispatch(commands, groups, 1, 1);
  });
  if (!shader_ms) return shader_ms.error();
  CopyBandwidth out;
  out.bytes = bytes;
  out.copies = options.copies;
  out.gpu_timestamps = timestamps;
  out.copy_ms_median = *copy_ms;
  if (!(out.copy_ms_median > 0.0) || !(*shader_ms > 0.0))
    return Error{"copy bandwidth: a copy of " + formatBytes(bytes) + " took " + std::to_string(out.copy_ms_median) +
                     " ms (median), no time to divide by",
                 ExitCode::kNoDevice};
  out.shader_copy_ms_median = *shader_ms;
  out.shader_read_write_gb_per_s = 2.0 * static_cast<double>(words) * 16.0 / (*shader_ms * 1e6);
  out.copy_gb_per_s = static_cast<double>(bytes) / (out.copy_ms_median * 1e6);
  out.read_write_gb_per_s = 2.0 * out.copy_gb_per_s;
  return out;
}

std::string rateText(double gb_per_s) {
  char text[32];
  if (gb_per_s >= 1000.0) std::snprintf(text, sizeof text, "%.3g TB/s", gb_per_s / 1000.0);
  else std::snprintf(text, sizeof text, "%.3g GB/s", gb_per_s);
  return text;
}

std::string copyBandwidthText(const CopyBandwidth& copy) {
  return rateText(copy.read_write_gb_per_s) + " read+write, " + rateText(copy.copy_gb_per_s) + " copied (" +
         formatBytes(copy.bytes) + " vkCmdCopyBuffer, median of " + std::to_string(copy.copies) + ", " +
         (copy.gpu_timestamps ? "GPU timestamps" : "host wall time: the queue has no timestamps") +
         "); compute-shader copy " + rateText(copy.shader_read_write_gb_per_s) + " read+write";
}

FrameTraffic frameTraffic(Backend backend, PrecisionMode mode, uint64_t points, uint32_t width, uint32_t height,
                          std::optional<double> plan_bytes_per_point) {
  const ModeInfo& info = modeInfo(mode);
  FrameTraffic out;
  out.splat_bytes_per_point = info.position_bytes;
  const bool follows_plan = info.batch_points && (backend == Backend::kCompute || info.shaders.attribute_count == 0);
  // A whole layout per point is counted in integers; a plan's bytes per point is its whole-set
  // total (a multiple of 4) divided by the points, which the rounding gives back.
  std::optional<uint64_t> position_bytes;
  if (!follows_plan) {
    out.loaded_bytes_per_point = info.position_bytes;
    position_bytes = points * info.position_bytes;
  } else if (plan_bytes_per_point) {
    out.loaded_bytes_per_point = *plan_bytes_per_point;
    position_bytes = static_cast<uint64_t>(std::llround(static_cast<double>(points) * *plan_bytes_per_point));
  }
  if (backend != Backend::kCompute || !position_bytes) return out;
  const uint64_t pixels = uint64_t{width} * height;
  constexpr uint64_t kClear = 8, kKeyRead = 8, kPictureWrite = 4, kColorRead = 4;
  out.bytes_per_frame =
      *position_bytes + pixels * (kClear + kKeyRead + kPictureWrite) + std::min(points, pixels) * kColorRead;
  return out;
}

double bandwidthBoundMs(uint64_t bytes, double read_write_gb_per_s) {
  assert(read_write_gb_per_s > 0.0);
  return static_cast<double>(bytes) / (read_write_gb_per_s * 1e6);
}

}  // namespace dpoint
