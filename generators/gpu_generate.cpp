#include "generators/gpu_generate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <type_traits>
#include <utility>

#include "core/parallel.h"
#include "generators/escape_grid.h"
#include "vulkan/shader.h"

#include "shaders/escape.comp.h"
#include "shaders/escape_refine.comp.h"
#include "shaders/perturbation.comp.h"

namespace dpoint {
namespace {

constexpr uint32_t kGroupSize = 256;  // local_size_x of both shaders

// Push constants of shaders/generate/escape.comp (std430 offsets: dvec4 at 0, doubles at 32, 40, 48).
struct EscapePush {
  double c[4];
  double threshold;
  double axis_rho2;
  double trap_c2;
  uint32_t res, first_row, count, limit, bits, word_offset;
};
static_assert(sizeof(EscapePush) == 80);

// escape.comp's ESCAPE_REFINE push constants: EscapePush's, then the cap.
struct EscapeRefinePush {
  EscapePush escape;
  uint32_t cap;
};
static_assert(offsetof(EscapeRefinePush, cap) == 80);

// Threads of escape_refine's second pass, which stride over the listed points.
constexpr uint32_t kRefineGroups = 1024;

// Push constants of shaders/generate/perturbation.comp (std430: the double at 0, then the uints).
struct PerturbationPush {
  double tail_radius2;
  uint32_t cols, first_row, count, max_iter, last, tail_steps;
};
static_assert(sizeof(PerturbationPush) == 32);

// Copies `count` values of type From out of mapped memory as To (the same type, or lavapipe's
// uint32 counts narrowed) on several threads: one thread copies at a fraction of the host's
// bandwidth, and this copy is on the critical path of the thread that feeds the meshing workers.
template <typename To, typename From>
void copyOut(void* to, const void* from, uint64_t count) {
  constexpr uint64_t kPiece = (uint64_t{4} << 20) / sizeof(From);  // 4 MiB read a piece
  parallelFor((count + kPiece - 1) / kPiece, std::min(8u, resolveThreads(0)), [&](size_t i, unsigned) {
    const uint64_t at = i * kPiece, end = std::min(at + kPiece, count);
    const From* source = static_cast<const From*>(from);
    if constexpr (std::is_same_v<To, From>)
      std::copy(source + at, source + end, static_cast<To*>(to) + at);  // a memmove
    else
      std::transform(source + at, source + end, static_cast<To*>(to) + at, [](From v) { return static_cast<To>(v); });
  });
}

// Points the set's bindings 0, 1, … at the whole buffers, in order (vulkan/shader's
// writeBufferDescriptors).
void writeSet(const VulkanContext& context, VkDescriptorSet set, const std::vector<const Buffer*>& buffers) {
  std::vector<VkDescriptorBufferInfo> infos;
  for (const Buffer* b : buffers) infos.push_back({b->buffer, 0, VK_WHOLE_SIZE});
  writeBufferDescriptors(context, set, infos);
}

uint64_t squaredResolution(int res) { return static_cast<uint64_t>(res) * static_cast<uint64_t>(res); }

}  // namespace

Status gpuGenerateUsable(const DeviceFacts& facts) {
  if (!facts.shader_float64)
    return Error{facts.name + " lacks shaderFloat64, which generation on the device needs", ExitCode::kNoDevice};
  if (!facts.shader_int64)
    return Error{facts.name + " lacks shaderInt64, which the exact fp64 rounding on the device needs",
                 ExitCode::kNoDevice};
  return okStatus();
}

Result<std::unique_ptr<GpuEscape>> GpuEscape::create(const VulkanContext& context, std::optional<bool> pack_counts) {
  if (Status s = gpuGenerateUsable(context.facts); !s) return s.error();
  // lavapipe writes them whole: shaders/generate/escape.comp says why.
  std::unique_ptr<GpuEscape> gpu(new GpuEscape(context, pack_counts.value_or(context.facts.type != "cpu")));
  if (Status s = gpu->init(); !s) return s.error();
  return gpu;
}

Status GpuEscape::init() {
  if (context_.facts.timestamp_period_ns > 0.0f) {
    VkQueryPoolCreateInfo query_info = {VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = 4;
    VK_TRY(vkCreateQueryPool(context_.device, &query_info, nullptr, &queries_));
  }
  if (Status s = computeLayouts(context_, 2, sizeof(EscapePush), escape_set_layout_, escape_layout_); !s) return s;
  if (Status s = computeLayouts(context_, 5, sizeof(PerturbationPush), perturbation_set_layout_, perturbation_layout_); !s)
    return s;
  // exact_fp64.glsl's square root and reciprocal in their bit-level form on a GPU, scaled on a
  // CPU device (lavapipe), each the faster there; the same counts.
  const uint32_t exact_bits = context_.facts.type == "cpu" ? 0u : 1u;
  refine_counts_ = context_.facts.type != "cpu";
  for (uint32_t kind = 0; kind < 2; ++kind) {
    const uint32_t constants[3] = {kind, packed_counts_ ? 1u : 0u, exact_bits};
    Result<VkPipeline> p = createComputePipeline(context_, kEscapeComp, sizeof(kEscapeComp), escape_layout_, constants);
    if (!p) return p.error();
    escape_[kind] = *p;
  }
  Result<VkPipeline> p =
      createComputePipeline(context_, kPerturbationComp, sizeof(kPerturbationComp), perturbation_layout_);
  if (!p) return p.error();
  perturbation_ = *p;

  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 25};  // per slot 2 + 5 + 2 + 2, refine 3
  VkDescriptorPoolCreateInfo pool_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 9;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  VK_TRY(vkCreateDescriptorPool(context_.device, &pool_info, nullptr, &pool_));
  for (Slot& slot : slots_) {
    const VkDescriptorSetLayout layouts[4] = {escape_set_layout_, perturbation_set_layout_, escape_set_layout_,
                                              escape_set_layout_};
    VkDescriptorSet sets[4] = {};
    VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    allocate.descriptorPool = pool_;
    allocate.descriptorSetCount = 4;
    allocate.pSetLayouts = layouts;
    VK_TRY(vkAllocateDescriptorSets(context_.device, &allocate, sets));
    slot.escape_set = sets[0];
    slot.perturbation_set = sets[1];
    slot.arena_set = sets[2];
    slot.target_set = sets[3];
    if (Status s = createCommandSlot(context_, slot.submission); !s) return s;
  }
  return okStatus();
}

GpuEscape::~GpuEscape() {
  const VkDevice device = context_.device;
  for (Slot& slot : slots_) {
    destroyCommandSlot(context_, slot.submission);  // waits for a dispatch in flight
    destroyBuffer(context_, slot.counts);
    destroyBuffer(context_, slot.tails);
  }
  for (Buffer* b : {&axis_, &orbit_, &dcx_, &dcy_, &arena_, &refine_list_}) destroyBuffer(context_, *b);
  if (pool_) vkDestroyDescriptorPool(device, pool_, nullptr);  // frees the sets
  if (queries_) vkDestroyQueryPool(device, queries_, nullptr);
  for (VkPipeline p : {escape_[0], escape_[1], perturbation_, refine_[0][0], refine_[0][1], refine_[1][0], refine_[1][1]})
    if (p) vkDestroyPipeline(device, p, nullptr);
  for (VkPipelineLayout l : {escape_layout_, perturbation_layout_, refine_layout_})
    if (l) vkDestroyPipelineLayout(device, l, nullptr);
  for (VkDescriptorSetLayout l : {escape_set_layout_, perturbation_set_layout_, refine_set_layout_})
    if (l) vkDestroyDescriptorSetLayout(device, l, nullptr);
}

Status GpuEscape::finish(Slot& slot) {
  if (!slot.points) return okStatus();
  const auto start = std::chrono::steady_clock::now();
  if (Status s = waitCommandSlot(context_, slot.submission); !s) return s;
  const auto waited = std::chrono::steady_clock::now();
  const uint64_t points = slot.points;
  slot.points = 0;
  if (!slot.destination) {  // written in place
    if (Status s = invalidateBuffer(context_, arena_); !s) return s;
  } else {
    if (Status s = invalidateBuffer(context_, slot.counts); !s) return s;
    if (slot.device_bytes == slot.count_bytes)
      copyOut<uint8_t, uint8_t>(slot.destination, slot.counts.mapped, points * slot.count_bytes);
    else if (slot.count_bytes == 1)
      copyOut<uint8_t, uint32_t>(slot.destination, slot.counts.mapped, points);
    else
      copyOut<uint16_t, uint32_t>(slot.destination, slot.counts.mapped, points);
  }
  if (slot.tail_destination) {
    if (Status s = invalidateBuffer(context_, slot.tails); !s) return s;
    copyOut<EscapeTail, EscapeTail>(slot.tail_destination, slot.tails.mapped, points);
  }
  const auto copied = std::chrono::steady_clock::now();
  wait_ms_ += std::chrono::duration<double, std::milli>(waited - start).count();
  copy_ms_ += std::chrono::duration<double, std::milli>(copied - waited).count();
  points_done_ += points;
  if (queries_) {
    const uint32_t first = 2 * static_cast<uint32_t>(&slot - slots_);
    uint64_t ticks[2] = {0, 0};
    VK_TRY(vkGetQueryPoolResults(context_.device, queries_, first, 2, sizeof(ticks), ticks, sizeof(uint64_t),
                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    gpu_ms_ += static_cast<double>(ticks[1] - ticks[0]) * context_.facts.timestamp_period_ns * 1e-6;
  }
  return okStatus();
}

Status GpuEscape::finishAll() {
  Status status = okStatus();
  for (Slot& slot : slots_)
    if (Status s = finish(slot); !s && status) status = s;
  return status;
}

void GpuEscape::stampStart(VkCommandBuffer commands, uint32_t query) const {
  if (!queries_) return;
  vkCmdResetQueryPool(commands, queries_, query, 2);
  vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, query);
}

void GpuEscape::recordPoints(VkCommandBuffer commands, VkPipelineLayout layout, const void* push, uint32_t push_bytes,
                             uint64_t points) const {
  vkCmdPushConstants(commands, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes, push);
  // Groups in two dimensions, x at most the device's limit; the shaders skip points past count.
  const uint64_t groups = (points + kGroupSize - 1) / kGroupSize;
  const uint64_t x = std::min<uint64_t>(groups, std::max<uint32_t>(context_.facts.max_dispatch_groups_x, 1));
  vkCmdDispatch(commands, static_cast<uint32_t>(x), static_cast<uint32_t>((groups + x - 1) / x), 1);
}

Status GpuEscape::dispatch(size_t s, VkPipeline pipeline, VkPipelineLayout layout, VkDescriptorSet set, const void* push,
                           uint32_t push_bytes, uint64_t points, void* destination, uint32_t count_bytes,
                           uint32_t device_bytes, EscapeTail* tail_destination) {
  assert(points > 0 && points <= (tail_destination ? kGpuPerturbationChunkPoints : kGpuChunkPoints));
  Slot& slot = slots_[s];
  if (Status st = finish(slot); !st) return st;
  if (Status st = beginCommandSlot(context_, slot.submission); !st) return st;
  const VkCommandBuffer commands = slot.submission.commands;
  const uint32_t query = 2 * static_cast<uint32_t>(s);
  stampStart(commands, query);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
  recordPoints(commands, layout, push, push_bytes, points);
  if (queries_) vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, query + 1);
  VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                       nullptr, 0, nullptr);
  if (Status st = submitCommandSlot(context_, slot.submission); !st) return st;
  slot.points = points;
  slot.destination = destination;
  slot.count_bytes = count_bytes;
  slot.device_bytes = device_bytes;
  slot.tail_destination = tail_destination;
  return okStatus();
}

Status GpuEscape::useAxis(const std::vector<double>& axis) {
  if (axis == axis_values_) return okStatus();
  if (Status s = uploadStorage(context_, axis_, axis.data(), axis.size() * sizeof(double), "grid axis"); !s) return s;
  axis_values_ = axis;
  for (Slot& slot : slots_)
    if (slot.counts.buffer) writeSet(context_, slot.escape_set, {&axis_, &slot.counts});
  arena_sets_stale_ = true;
  return okStatus();
}

Status GpuEscape::makeCounts() {
  for (Slot& slot : slots_) {
    if (slot.counts.buffer) continue;
    Result<Buffer> counts = createBuffer(context_, kGpuChunkPoints * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                         true, "escape counts");
    if (!counts) return counts.error();
    slot.counts = *counts;
    if (axis_.buffer) writeSet(context_, slot.escape_set, {&axis_, &slot.counts});
  }
  return okStatus();
}

uint32_t GpuEscape::deviceBits(int limit) const {
  return packed_counts_ ? 8 * static_cast<uint32_t>(escapeGridBytesPerCount(limit)) : 32;
}

Status GpuEscape::escapePlanes(const EscapeKernelParams& kernel, const std::vector<double>& axis, int first,
                               int planes, int limit, uint8_t* counts) {
  const uint64_t res = axis.size();
  assert(res >= 2 && first >= 0 && planes > 0 && static_cast<uint64_t>(first + planes) <= res && limit >= 0);
  if (Status s = finishAll(); !s) return s;
  if (Status s = useAxis(axis); !s) return s;
  const uint32_t count_bytes = static_cast<uint32_t>(escapeGridBytesPerCount(limit));
  // In the arena, with every row whole words (so no dispatch writes a word another one does).
  const uint64_t total = static_cast<uint64_t>(planes) * res * res * count_bytes;
  const uintptr_t arena = reinterpret_cast<uintptr_t>(arena_.mapped), at = reinterpret_cast<uintptr_t>(counts);
  const bool in_place = packed_counts_ && arena != 0 && at >= arena && at - arena + total <= arena_.size &&
                        (at - arena) % 4 == 0 && res * count_bytes % 4 == 0;
  if (!in_place)
    if (Status s = makeCounts(); !s) return s;
  if (in_place && arena_sets_stale_) {
    for (Slot& slot : slots_) writeSet(context_, slot.arena_set, {&axis_, &arena_});
    arena_sets_stale_ = false;
  }
  return escapeRows(kernel, res, first, planes, limit, in_place ? Target::kArena : Target::kHost,
                    in_place ? (at - arena) / 4 : 0, counts);
}

Status GpuEscape::escapeInto(const EscapeKernelParams& kernel, const std::vector<double>& axis, int first, int planes,
                             int limit, const Buffer& target, int cap) {
  const uint64_t res = axis.size();
  assert(res >= 2 && first >= 0 && planes > 0 && static_cast<uint64_t>(first + planes) <= res && limit >= 0);
  assert(target.size * 8 >= static_cast<uint64_t>(planes) * res * res * deviceBits(limit));
  if (Status s = finishAll(); !s) return s;
  if (Status s = useAxis(axis); !s) return s;
  // Every call: a buffer made after another was destroyed may have its handle (NVIDIA's driver
  // reuses them), so the handle cannot tell whether the set is current; no dispatch is in flight
  // after finishAll. One submission, slot 0's (escapeRows).
  writeSet(context_, slots_[0].target_set, {&axis_, &target});
  bool refine = cap >= 0 && cap < limit;
  if (refine) {
    // The list holds every point of the slab at most, after its length. Where the device has no
    // room for it, every count goes to the limit, now and for the rest of the run.
    if (Status s = makeRefine(4 + static_cast<uint64_t>(planes) * res * res * 4); !s) {
      if (s.error().code != ExitCode::kNoDevice) return s;
      refine = refine_counts_ = false;
    } else {
      writeSet(context_, refine_set_, {&axis_, &target, &refine_list_});
    }
  }
  return escapeRows(kernel, res, first, planes, limit, Target::kDevice, 0, nullptr, refine ? cap : -1);
}

Status GpuEscape::makeRefine(uint64_t list_bytes) {
  if (!refine_layout_) {
    if (Status s = computeLayouts(context_, 3, sizeof(EscapeRefinePush), refine_set_layout_, refine_layout_); !s)
      return s;
    const uint32_t exact_bits = context_.facts.type == "cpu" ? 0u : 1u;  // as escape_'s
    for (uint32_t kind = 0; kind < 2; ++kind)
      for (uint32_t pass = 0; pass < 2; ++pass) {
        const uint32_t constants[4] = {kind, packed_counts_ ? 1u : 0u, exact_bits, pass};
        Result<VkPipeline> p =
            createComputePipeline(context_, kEscapeRefineComp, sizeof(kEscapeRefineComp), refine_layout_, constants);
        if (!p) return p.error();
        refine_[kind][pass] = *p;
      }
    VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    allocate.descriptorPool = pool_;
    allocate.descriptorSetCount = 1;
    allocate.pSetLayouts = &refine_set_layout_;
    VK_TRY(vkAllocateDescriptorSets(context_.device, &allocate, &refine_set_));
  }
  if (refine_list_.size >= list_bytes) return okStatus();
  destroyBuffer(context_, refine_list_);  // no dispatch in flight (escapeInto's finishAll)
  Result<Buffer> list = createBuffer(context_, list_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                     false, "points whose counts the mesh needs past the cap");
  if (!list) return list.error();
  refine_list_ = *list;
  return okStatus();
}

void GpuEscape::recordRefine(VkCommandBuffer commands, uint32_t kernel, const void* push, uint64_t points) const {
  auto barrier = [&](VkPipelineStageFlags src_stage, VkAccessFlags src, VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
    VkMemoryBarrier b = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = src;
    b.dstAccessMask = dst;
    vkCmdPipelineBarrier(commands, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
  };
  constexpr VkAccessFlags kShaderRw = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  // The list's length to 0, once an earlier slab's passes have read it; the counts written.
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kShaderRw, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
  vkCmdFillBuffer(commands, refine_list_.buffer, 0, 4, 0);
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kShaderRw);
  vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, refine_layout_, 0, 1, &refine_set_, 0, nullptr);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, refine_[kernel][0]);
  recordPoints(commands, refine_layout_, push, sizeof(EscapeRefinePush), points);
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kShaderRw, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kShaderRw);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, refine_[kernel][1]);
  vkCmdDispatch(commands, kRefineGroups, 1, 1);
}

Status GpuEscape::escapeRows(const EscapeKernelParams& kernel, uint64_t res, int first, int planes, int limit,
                             Target target, uint64_t word_offset, uint8_t* counts, int cap) {
  assert(cap < 0 || (target == Target::kDevice && cap < limit));
  const uint32_t count_bytes = static_cast<uint32_t>(escapeGridBytesPerCount(limit));
  EscapePush push{};
  for (int d = 0; d < 4; ++d) push.c[d] = kernel.c[d];
  push.threshold = kernel.julia_threshold;
  push.axis_rho2 = kernel.axis_rho2;
  push.trap_c2 = kernel.trap_c2;
  push.res = static_cast<uint32_t>(res);
  push.limit = static_cast<uint32_t>(cap >= 0 ? cap : limit);
  // A GPU packs them (a quarter of the bytes to write and copy); lavapipe writes them whole and
  // they are narrowed as they are copied.
  const uint32_t device_bytes = packed_counts_ ? count_bytes : 4;
  push.bits = 8 * device_bytes;
  // Rows (plane·res + j) go out in chunks of whole rows; the row index stays below res² ≤ 2^32.
  // Into device memory, a multiple of 4 rows a chunk: each chunk starts at a whole word whatever
  // res is, so no two dispatches write one word.
  uint64_t rows_per_chunk = std::max<uint64_t>(1, kGpuChunkPoints / res);
  if (target == Target::kDevice) rows_per_chunk = std::max<uint64_t>(4, rows_per_chunk / 4 * 4);
  const uint64_t first_row = static_cast<uint64_t>(first) * res, end_row = first_row + static_cast<uint64_t>(planes) * res;
  const VkPipeline pipeline = escape_[static_cast<uint32_t>(kernel.kernel)];
  // Into device memory, every chunk in one submission of slot 0's: nothing waits on the host
  // between them (the chunks write words of their own), and the host is free once it is submitted.
  Slot& device_slot = slots_[0];
  const VkCommandBuffer device_commands = device_slot.submission.commands;
  if (target == Target::kDevice) {
    if (Status st = beginCommandSlot(context_, device_slot.submission); !st) return st;
    stampStart(device_commands, 0);
    vkCmdBindPipeline(device_commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(device_commands, VK_PIPELINE_BIND_POINT_COMPUTE, escape_layout_, 0, 1,
                            &device_slot.target_set, 0, nullptr);
  }
  size_t s = 0;
  for (uint64_t row = first_row; row < end_row; row += rows_per_chunk, s ^= 1) {
    const uint64_t rows = std::min(rows_per_chunk, end_row - row);
    push.first_row = static_cast<uint32_t>(row);
    push.count = static_cast<uint32_t>(rows * res);
    const uint64_t bytes_before = (row - first_row) * res * device_bytes;
    push.word_offset = target == Target::kHost ? 0 : static_cast<uint32_t>(word_offset + bytes_before / 4);
    if (target == Target::kDevice) {
      recordPoints(device_commands, escape_layout_, &push, sizeof push, rows * res);
      continue;
    }
    const VkDescriptorSet set = target == Target::kArena ? slots_[s].arena_set : slots_[s].escape_set;
    uint8_t* destination = target == Target::kHost ? counts + (row - first_row) * res * count_bytes : nullptr;
    if (Status st = dispatch(s, pipeline, escape_layout_, set, &push, sizeof push, rows * res, destination, count_bytes,
                             device_bytes, nullptr);
        !st) {
      (void)finishAll();
      return st;
    }
  }
  if (target != Target::kDevice) return finishAll();
  if (cap >= 0) {
    // The counts the mesh reads past the cap, to the limit (escapeInto).
    EscapeRefinePush refine{push, static_cast<uint32_t>(cap)};
    refine.escape.limit = static_cast<uint32_t>(limit);
    refine.escape.first_row = static_cast<uint32_t>(first_row);
    refine.escape.count = static_cast<uint32_t>(end_row - first_row) * static_cast<uint32_t>(res);
    refine.escape.word_offset = static_cast<uint32_t>(word_offset);
    recordRefine(device_commands, static_cast<uint32_t>(kernel.kernel), &refine, (end_row - first_row) * res);
  }
  // The reader's own submission follows on the queue (escapeInto); the counts need no barrier
  // towards the host.
  if (queries_) vkCmdWriteTimestamp(device_commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 1);
  if (Status st = submitCommandSlot(context_, device_slot.submission); !st) return st;
  device_slot.points = (end_row - first_row) * res;
  device_slot.destination = nullptr;
  device_slot.count_bytes = count_bytes;
  device_slot.device_bytes = device_bytes;
  device_slot.tail_destination = nullptr;
  return okStatus();
}

Result<uint8_t*> GpuEscape::arena(uint64_t bytes) {
  if (!packed_counts_ || bytes == 0 || bytes > context_.facts.max_storage_buffer_range ||
      bytes / 4 > UINT32_MAX)  // word offsets are uint32
    return static_cast<uint8_t*>(nullptr);
  if (arena_.size < bytes) {
    if (Status s = finishAll(); !s) return s.error();
    destroyBuffer(context_, arena_);
    // A mesher on the device copies its slab out of it (generators/gpu_mesh.h).
    Result<Buffer> created = createBuffer(context_, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                          true, "escape count blocks");
    if (!created) return created.error();
    arena_ = *created;
    arena_sets_stale_ = true;
  }
  return static_cast<uint8_t*>(arena_.mapped);
}

Result<McSlabView> meshSlabOnDevice(GpuEscape& escape, GpuMesher& mesher, const EscapeKernelParams& kernel,
                                    const EscapeSlab& slab, const EscapeSlab* next) {
  assert(GpuMesher::supports(slab.res, slab.last - slab.first + 1, slab.limit));
  const uint32_t bits = escape.deviceBits(slab.limit);
  auto ahead = [&](const EscapeSlab& s, unsigned which) {
    GpuMesher::CountsAhead a;
    a.escape = &escape;
    a.kernel = {static_cast<double>(kernel.kernel), kernel.c[0], kernel.c[1], kernel.c[2], kernel.c[3],
                kernel.julia_threshold, kernel.axis_rho2, kernel.trap_c2};
    a.values = s.values;
    a.first = s.first, a.last = s.last, a.limit = s.limit;
    a.which = which;
    return a;
  };
  // Counts into counts buffer `which`, submitted and not waited for.
  auto countsInto = [&](const EscapeSlab& s, unsigned which) -> Status {
    const uint64_t bytes = static_cast<uint64_t>(s.last - s.first + 1) * squaredResolution(s.res) * bits / 8;
    Result<const Buffer*> counts = mesher.countsBuffer(bytes, which);
    if (!counts) return counts.error();
    // To the cap, then past it only where an edge crosses the level (the mesh reads no other
    // count above it): the Mandelbulb's interior, which never escapes, is most of its iterations
    // (res 2048 on an H200: 662 → 351 ms). Julia's counts cost too little for the list to pay
    // (86 → 111 ms).
    const int cap = escape.refinesCounts() && kernel.kernel == EscapeKernel::kMandelbulbFast
                        ? static_cast<int>(std::floor(s.level)) + 1
                        : -1;
    return escape.escapeInto(kernel, *s.values, s.first, s.last - s.first + 1, s.limit, **counts, cap);
  };
  // This slab's counts: made ahead by the call before, or now.
  unsigned which = 0;
  const std::optional<GpuMesher::CountsAhead> made = std::exchange(mesher.counts_ahead, std::nullopt);
  if (made && *made == ahead(slab, made->which)) {
    which = made->which;
  } else if (Status s = countsInto(slab, which); !s) {
    return s.error();
  }
  // The next slab's into the other buffer once this one's scan is queued: the device makes them
  // while the host reads the totals, before the mesh (a queue runs in order; the mesher's
  // submissions wait on the device for counts, not the host).
  std::function<Status()> while_scanning;
  if (next && GpuMesher::supports(next->res, next->last - next->first + 1, next->limit))
    while_scanning = [&]() -> Status {
      if (Status s = countsInto(*next, which ^ 1u); !s) return s;
      mesher.counts_ahead = ahead(*next, which ^ 1u);
      return okStatus();
    };
  Result<McSlabView> mesh = mesher.meshSlab(slab, bits, which, while_scanning);
  // The next slab's counts were made before this slab's mesh; this only counts their time.
  const Status settled = escape.settle();
  if (!mesh) {
    mesher.counts_ahead.reset();
    return mesh;
  }
  if (!settled) return settled.error();
  return mesh;
}

Status GpuEscape::perturbation(const std::vector<glm::dvec2>& orbit, const std::vector<double>& dcx,
                               const std::vector<double>& dcy, int max_iter, uint32_t* counts, EscapeTail* tails) {
  assert(orbit.size() >= 2 && !dcx.empty() && max_iter >= 0);
  if (dcy.empty()) return okStatus();
  if (Status s = finishAll(); !s) return s;
  if (Status s = makeCounts(); !s) return s;
  for (Slot& slot : slots_) {
    if (slot.tails.buffer) continue;
    Result<Buffer> created = createBuffer(context_, kGpuPerturbationChunkPoints * sizeof(EscapeTail),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "escape tails");
    if (!created) return created.error();
    slot.tails = *created;
  }
  if (Status s = uploadStorage(context_, orbit_, orbit.data(), orbit.size() * sizeof(glm::dvec2), "reference orbit"); !s) return s;
  if (Status s = uploadStorage(context_, dcx_, dcx.data(), dcx.size() * sizeof(double), "pixel offsets"); !s) return s;
  if (Status s = uploadStorage(context_, dcy_, dcy.data(), dcy.size() * sizeof(double), "row offsets"); !s) return s;
  for (Slot& slot : slots_)
    writeSet(context_, slot.perturbation_set, {&orbit_, &dcx_, &dcy_, &slot.counts, &slot.tails});
  const uint64_t cols = dcx.size();
  PerturbationPush push{};
  push.tail_radius2 = kTailRadius2;
  push.cols = static_cast<uint32_t>(cols);
  push.max_iter = static_cast<uint32_t>(max_iter);
  push.last = static_cast<uint32_t>(orbit.size() - 1);
  push.tail_steps = kMaxTailSteps;
  const uint64_t rows_per_chunk = std::max<uint64_t>(1, kGpuPerturbationChunkPoints / cols);
  size_t s = 0;
  for (uint64_t row = 0; row < dcy.size(); row += rows_per_chunk, s ^= 1) {
    const uint64_t rows = std::min<uint64_t>(rows_per_chunk, dcy.size() - row);
    push.first_row = static_cast<uint32_t>(row);
    push.count = static_cast<uint32_t>(rows * cols);
    if (Status st = dispatch(s, perturbation_, perturbation_layout_, slots_[s].perturbation_set, &push, sizeof push,
                             rows * cols, counts + row * cols, sizeof(uint32_t), sizeof(uint32_t), tails + row * cols);
        !st) {
      (void)finishAll();
      return st;
    }
  }
  return finishAll();
}

}  // namespace dpoint
