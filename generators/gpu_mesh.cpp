#include "generators/gpu_mesh.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>

#include "generators/perlin.h"
#include "vulkan/shader.h"

#include "shaders/mesh_colors.comp.h"
#include "shaders/mesh_rows.comp.h"
#include "shaders/mesh_slab.comp.h"

namespace dpoint {
namespace {

// Elements a workgroup takes: 256 invocations of 16 (mesh_slab.comp's kGroupElements). Fewer,
// larger groups keep the one-workgroup scan of their counts (pass 2) short.
constexpr uint32_t kGroupElements = 4096;
constexpr uint32_t kBindings = 17;
constexpr uint32_t kFaceRowBytes = 13;  // the byte 3, three uint ids
// Timestamps: the counts and scans (submission 1), the vertices, the triangles and the copies out.
// Passes 0–4 are mesh_slab.comp's (slab_passes_, for the counts' bits); passes_ holds these.
constexpr uint32_t kColorPass = 5, kVertexRowPass = 6, kFaceRowPass = 7, kColoredVertexRowPass = 8,
                   kFloatColoredVertexRowPass = 9;
enum Stamp : uint32_t { kStart, kScanned, kStart2, kVertices, kTriangles, kCopied, kStamps };

// Push constants of shaders/generate/mesh_slab.comp (std430: the double at 0, then the uints).
struct MeshPush {
  double step;
  uint32_t n, plane, planes, first, word_offset, bits, above_at, stride, seed_frame;
  uint32_t vertex_elements, triangle_elements, vertex_group_count, triangle_group_count, groups_x, pad;
  uint32_t rows, row_bytes, faces, vertex_base;
};
static_assert(sizeof(MeshPush) == 88);

// Workgroups of 256 invocations of 4 rows each for `rows` rows.
uint32_t rowGroups(uint64_t rows) { return static_cast<uint32_t>((rows + 4 * 256 - 1) / (4 * 256)); }

}  // namespace

bool GpuMesher::supports(int res, int planes, int limit) {
  const uint64_t plane = static_cast<uint64_t>(res) * static_cast<uint64_t>(res);
  return res >= 2 && planes >= 2 && limit >= 1 && escapeGridBytesPerCount(limit) == 1 &&
         (2 * static_cast<uint64_t>(planes) - 1) * plane < (uint64_t{1} << 31);
}

Result<std::unique_ptr<GpuMesher>> GpuMesher::create(const VulkanContext& context) {
  std::unique_ptr<GpuMesher> mesher(new GpuMesher(context));
  if (Status s = mesher->init(); !s) return s.error();
  return mesher;
}

Status GpuMesher::init() {
  if (context_.facts.timestamp_period_ns > 0.0f) {
    VkQueryPoolCreateInfo query_info = {VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = kStamps;
    VK_TRY(vkCreateQueryPool(context_.device, &query_info, nullptr, &queries_));
  }
  if (Status s = computeLayouts(context_, kBindings, sizeof(MeshPush), set_layout_, layout_); !s) return s;
  Result<VkDescriptorSet> set = storageSet(context_, set_layout_, kBindings, pool_);
  if (!set) return set.error();
  set_ = *set;

  // The case table: for mask m, 16 bytes: the triangle count, then its 3·count cube edges; then
  // the noise's permutation (a word each) and gradients (a float each).
  std::vector<uint8_t> cases(256 * 16 + 256 * 4 + 48 * 4, 0);
  for (unsigned m = 0; m < 256; ++m) {
    const McCase& c = marchingCubesCase(m);
    cases[16 * m] = c.triangle_count;
    std::copy(c.edges.begin(), c.edges.end(), cases.begin() + 16 * m + 1);
  }
  for (unsigned i = 0; i < 256; ++i) {
    const uint32_t word = perlinPermutation()[i];
    std::memcpy(&cases[256 * 16 + 4 * i], &word, 4);
  }
  std::memcpy(&cases[256 * 16 + 256 * 4], perlinGradients(), 48 * sizeof(float));
  if (Status s = uploadStorage(context_, cases_, cases.data(), cases.size(), "marching cubes cases"); !s) return s;
  if (Status s = ensure(totals_, 4 * sizeof(uint32_t), true, "meshing totals"); !s) return s;
  if (copyBeside())
    for (Copy& copy : copies_) {
      VkSemaphoreCreateInfo semaphore_info = {VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      VK_TRY(vkCreateSemaphore(context_.device, &semaphore_info, nullptr, &copy.ready));
    }
  for (CommandSlot& slot : submissions_)
    if (Status s = createCommandSlot(context_, slot); !s) return s;
  return okStatus();
}

Status GpuMesher::submit(CommandSlot& slot, const std::function<void(VkCommandBuffer)>& record, VkSemaphore signal) {
  if (Status s = beginCommandSlot(context_, slot); !s) return s;
  record(slot.commands);
  SlotSync sync;
  sync.signal = signal;
  return submitCommandSlot(context_, slot, sync);
}

bool GpuMesher::copyBeside() const { return context_.transfer_queue != VK_NULL_HANDLE; }

void GpuMesher::rowsOwnership(VkCommandBuffer commands, unsigned r, bool release) const {
  // A queue family ownership transfer of the rows' buffers from the main queue's family to the
  // transfer queue's: the release on the main queue, the acquire on the transfer queue.
  VkBufferMemoryBarrier barriers[2] = {{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER}, {VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER}};
  const Buffer* buffers[2] = {&vertex_rows_[r], &face_rows_[r]};
  for (int i = 0; i < 2; ++i) {
    barriers[i].srcAccessMask = release ? VK_ACCESS_SHADER_WRITE_BIT : 0;
    barriers[i].dstAccessMask = release ? 0 : VK_ACCESS_TRANSFER_READ_BIT;
    barriers[i].srcQueueFamilyIndex = context_.facts.queue_family;
    barriers[i].dstQueueFamilyIndex = *context_.facts.transfer_family;
    barriers[i].buffer = buffers[i]->buffer;
    barriers[i].offset = 0;
    barriers[i].size = VK_WHOLE_SIZE;
  }
  vkCmdPipelineBarrier(commands, release ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                       release ? VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT : VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 2,
                       barriers, 0, nullptr);
}

Status GpuMesher::submitCopy(Copy& copy, unsigned r, const Buffer& readback, uint64_t vertex_row_bytes,
                             uint64_t face_row_bytes) {
  if (!copy.slot.commands)
    if (Status s = createCommandSlot(context_, copy.slot, context_.transfer_pool); !s) return s;
  if (Status s = beginCommandSlot(context_, copy.slot); !s) return s;
  const VkCommandBuffer commands = copy.slot.commands;
  rowsOwnership(commands, r, false);
  const VkBufferCopy vertex_copy{0, 0, vertex_row_bytes}, face_copy{0, vertex_row_bytes, face_row_bytes};
  if (vertex_row_bytes) vkCmdCopyBuffer(commands, vertex_rows_[r].buffer, readback.buffer, 1, &vertex_copy);
  if (face_row_bytes) vkCmdCopyBuffer(commands, face_rows_[r].buffer, readback.buffer, 1, &face_copy);
  VkMemoryBarrier to_host = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr,
                       0, nullptr);
  SlotSync sync;
  sync.queue = context_.transfer_queue;
  sync.wait = copy.ready;
  sync.wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  return submitCommandSlot(context_, copy.slot, sync);
}

GpuMesher::~GpuMesher() {
  const VkDevice device = context_.device;
  for (CommandSlot& slot : submissions_) destroyCommandSlot(context_, slot);
  for (Copy& copy : copies_) {
    destroyCommandSlot(context_, copy.slot);
    if (copy.ready) vkDestroySemaphore(device, copy.ready, nullptr);
  }
  for (Buffer* b : {&element_edges_, &cell_cases_, &counts_[0], &counts_[1], &axis_, &fractions_, &cases_, &vertex_groups_, &triangle_groups_,
                    &totals_, &ids_y_, &ids_z_, &ids_x_, &positions_, &triangles_, &colors_, &vertex_rows_[0],
                    &vertex_rows_[1], &face_rows_[0], &face_rows_[1], &readback_[0], &readback_[1]})
    destroyBuffer(context_, *b);
  if (pool_) vkDestroyDescriptorPool(device, pool_, nullptr);
  if (queries_) vkDestroyQueryPool(device, queries_, nullptr);
  for (VkPipeline p : passes_)
    if (p) vkDestroyPipeline(device, p, nullptr);
  for (VkPipeline(&by_bits)[5] : slab_passes_)
    for (VkPipeline p : by_bits)
      if (p) vkDestroyPipeline(device, p, nullptr);
  if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device, set_layout_, nullptr);
}

// Grows `buffer` to at least `bytes` (by half again, so a slab a little larger than the last does
// not make a new one); its old contents are not kept.
Status GpuMesher::ensure(Buffer& buffer, uint64_t bytes, bool host_visible, const char* what) {
  bytes = std::max<uint64_t>(bytes, 16);
  if (buffer.size >= bytes) return okStatus();
  destroyBuffer(context_, buffer);
  const uint64_t grown = std::max<uint64_t>(bytes, buffer.size + buffer.size / 2);
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  Result<Buffer> created = createBuffer(context_, grown, usage, host_visible, what);
  if (!created) return created.error();
  buffer = *created;
  return okStatus();
}

void GpuMesher::stamp(VkCommandBuffer commands, uint32_t query) const {
  if (queries_) vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, query);
}

Status GpuMesher::readStamps() {
  if (!queries_) return okStatus();
  uint64_t ticks[kStamps] = {};
  VK_TRY(vkGetQueryPoolResults(context_.device, queries_, 0, kStamps, sizeof(ticks), ticks, sizeof(uint64_t),
                               VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const double ms = context_.facts.timestamp_period_ns * 1e-6;
  times_.scan += static_cast<double>(ticks[kScanned] - ticks[kStart]) * ms;
  times_.vertices += static_cast<double>(ticks[kVertices] - ticks[kStart2]) * ms;
  times_.triangles += static_cast<double>(ticks[kTriangles] - ticks[kVertices]) * ms;
  times_.copy += static_cast<double>(ticks[kCopied] - ticks[kTriangles]) * ms;
  return okStatus();
}

Status GpuMesher::reserve(uint64_t vertices, uint64_t triangles, bool colors, size_t row_bytes) {
  if (Status s = ensure(positions_, vertices * 3 * sizeof(double), false, "slab vertices"); !s) return s;
  if (Status s = ensure(triangles_, triangles * 3 * sizeof(uint32_t), false, "slab triangles"); !s) return s;
  if (colors)
    if (Status s = ensure(colors_, vertices * 3 * sizeof(float), false, "slab colours"); !s) return s;
  uint64_t readback = vertices * 3 * sizeof(double) + (colors ? vertices * 3 * sizeof(float) : 0) +
                      triangles * 3 * sizeof(uint32_t);
  if (row_bytes) {
    for (unsigned r = 0; r < (copyBeside() ? 2u : 1u); ++r) {
      if (Status s = ensure(vertex_rows_[r], (vertices + 3) / 4 * 4 * row_bytes, false, "slab vertex rows"); !s)
        return s;
      if (Status s = ensure(face_rows_[r], (triangles + 3) / 4 * 4 * kFaceRowBytes, false, "slab face rows"); !s)
        return s;
    }
    readback = vertices * row_bytes + triangles * kFaceRowBytes;
  }
  for (Buffer& b : readback_)
    if (Status s = ensure(b, readback, true, "slab mesh for the host"); !s) return s;
  return okStatus();
}

Result<const Buffer*> GpuMesher::countsBuffer(uint64_t bytes, unsigned which) {
  assert(which < 2);
  if (Status s = ensure(counts_[which], bytes, false, "escape counts of a slab"); !s) return s.error();
  return &counts_[which];
}

Result<McSlabView> GpuMesher::meshSlab(const EscapeSlab& slab, uint32_t bits, unsigned which,
                                       const std::function<Status()>& while_scanning) {
  assert(which < 2);
  const Buffer& slab_counts = counts_[which];
  const int planes = slab.last - slab.first + 1;
  assert(supports(slab.res, planes, slab.limit) && slab.values && slab.values->size() == static_cast<size_t>(slab.res));
  assert(bits == 8 || bits == 32);
  const uint64_t n = static_cast<uint64_t>(slab.res), plane = n * n;
  assert(slab_counts.size * 8 >= static_cast<uint64_t>(planes) * plane * bits);

  // The inputs beside the counts: the axis, and the fractions t of every pair of counts (the CPU's
  // division).
  if (*slab.values != axis_values_) {
    if (Status s =
            uploadStorage(context_, axis_, slab.values->data(), slab.values->size() * sizeof(double), "grid axis");
        !s)
      return s.error();
    axis_values_ = *slab.values;
  }
  const uint32_t stride = static_cast<uint32_t>(slab.limit) + 1;
  if (!fractions_.buffer || fractions_level_ != slab.level || fractions_stride_ != stride) {
    std::vector<double> fractions(static_cast<size_t>(stride) * stride, 0.0);
    for (uint32_t v1 = 0; v1 < stride; ++v1)
      for (uint32_t v2 = 0; v2 < stride; ++v2)
        if (v1 != v2) fractions[v1 * stride + v2] = (slab.level - v1) / (static_cast<double>(v2) - v1);
    if (Status s =
            uploadStorage(context_, fractions_, fractions.data(), fractions.size() * sizeof(double), "edge fractions");
        !s)
      return s.error();
    fractions_level_ = slab.level;
    fractions_stride_ = stride;
  }

  MeshPush push{};
  push.step = slab.step;
  push.n = static_cast<uint32_t>(n);
  push.plane = static_cast<uint32_t>(plane);
  push.planes = static_cast<uint32_t>(planes);
  push.first = static_cast<uint32_t>(slab.first);
  push.word_offset = 0;
  push.bits = bits;
  push.above_at = slab.level >= 4294967295.0 ? 0xFFFFFFFFu : static_cast<uint32_t>(std::floor(slab.level));
  push.stride = stride;
  push.seed_frame = slab.frame == GridFrame::kSeed ? 1u : 0u;
  // mesh_slab.comp's passes 0–4 (kPass, kBits) for counts of these bits, made at the first slab
  // that has them (a GpuEscape's bits are the same for every slab; the tests use both kinds).
  VkPipeline (&slab_passes)[5] = slab_passes_[bits == 8 ? 0 : 1];
  for (uint32_t pass = 0; pass < 5 && !slab_passes[pass]; ++pass) {
    const uint32_t constants[2] = {pass, bits};
    Result<VkPipeline> p = createComputePipeline(context_, kMeshSlabComp, sizeof(kMeshSlabComp), layout_, constants);
    if (!p) return p.error();
    slab_passes[pass] = *p;
  }
  // Made at the first slab that wants them: mesh_colors.comp, and mesh_rows.comp's two kinds.
  auto made = [&](unsigned index, const uint32_t* code, size_t bytes, std::span<const uint32_t> constants) -> Status {
    if (passes_[index]) return okStatus();
    Result<VkPipeline> p = createComputePipeline(context_, code, bytes, layout_, constants);
    if (!p) return p.error();
    passes_[index] = *p;
    return okStatus();
  };
  if (slab.noise_colors)
    if (Status s = made(kColorPass, kMeshColorsComp, sizeof(kMeshColorsComp), {}); !s) return s.error();
  // The vertex rows' colours, mesh_rows.comp's kColors (none, bytes, floats), and their pass.
  const uint32_t row_colors = !slab.noise_colors ? 0u : slab.float_colors ? 2u : 1u;
  static constexpr uint32_t kVertexRowPasses[3] = {kVertexRowPass, kColoredVertexRowPass, kFloatColoredVertexRowPass};
  const uint32_t vertex_pass = kVertexRowPasses[row_colors];
  if (slab.ply_rows) {
    // kPass and kColors of mesh_rows.comp.
    const uint32_t vertex_constants[2] = {0u, row_colors};
    static constexpr uint32_t kFaces[2] = {1u, 0u};
    if (Status s = made(vertex_pass, kMeshRowsComp, sizeof(kMeshRowsComp), vertex_constants); !s) return s.error();
    if (Status s = made(kFaceRowPass, kMeshRowsComp, sizeof(kMeshRowsComp), kFaces); !s) return s.error();
  }
  const uint64_t vertex_elements = (2 * static_cast<uint64_t>(planes) - 1) * plane;
  const uint64_t triangle_elements = static_cast<uint64_t>(planes - 1) * plane;
  push.vertex_elements = static_cast<uint32_t>(vertex_elements);
  push.triangle_elements = static_cast<uint32_t>(triangle_elements);
  push.vertex_group_count = static_cast<uint32_t>((vertex_elements + kGroupElements - 1) / kGroupElements);
  push.triangle_group_count = static_cast<uint32_t>((triangle_elements + kGroupElements - 1) / kGroupElements);

  if (Status s = ensure(vertex_groups_, push.vertex_group_count * sizeof(uint32_t), false, "meshing group counts"); !s)
    return s.error();
  if (Status s = ensure(triangle_groups_, push.triangle_group_count * sizeof(uint32_t), false, "meshing group counts");
      !s)
    return s.error();
  if (Status s = ensure(ids_y_, planes * plane * sizeof(uint32_t), false, "vertex ids"); !s) return s.error();
  if (Status s = ensure(ids_z_, planes * plane * sizeof(uint32_t), false, "vertex ids"); !s) return s.error();
  if (Status s = ensure(ids_x_, (planes - 1) * plane * sizeof(uint32_t), false, "vertex ids"); !s) return s.error();
  // Passes 0 and 1 keep a byte an element (whole groups) for passes 3 and 4.
  if (Status s = ensure(element_edges_, uint64_t{push.vertex_group_count} * kGroupElements, false, "crossed edges"); !s)
    return s.error();
  if (Status s = ensure(cell_cases_, uint64_t{push.triangle_group_count} * kGroupElements, false, "cell cases"); !s)
    return s.error();
  if (Status s = ensure(positions_, 3 * sizeof(double), false, "slab vertices"); !s) return s.error();
  if (Status s = ensure(triangles_, 3 * sizeof(uint32_t), false, "slab triangles"); !s) return s.error();
  if (Status s = ensure(colors_, 3 * sizeof(float), false, "slab colours"); !s) return s.error();
  // The rows' buffers: two where the transfer queue copies them out beside the next slab's work
  // (one is read while the other is written), else one; used in turn with the readback buffers.
  const bool beside = slab.ply_rows && copyBeside();
  const unsigned r = beside ? next_readback_ : 0;
  if (Status s = ensure(vertex_rows_[r], 4, false, "slab vertex rows"); !s) return s.error();
  if (Status s = ensure(face_rows_[r], 4, false, "slab face rows"); !s) return s.error();
  auto bind = [&] {
    const VkDescriptorBufferInfo infos[kBindings] = {
        {slab_counts.buffer, 0, VK_WHOLE_SIZE}, {axis_.buffer, 0, VK_WHOLE_SIZE},
        {fractions_.buffer, 0, VK_WHOLE_SIZE}, {cases_.buffer, 0, VK_WHOLE_SIZE},
        {vertex_groups_.buffer, 0, VK_WHOLE_SIZE}, {triangle_groups_.buffer, 0, VK_WHOLE_SIZE},
        {totals_.buffer, 0, VK_WHOLE_SIZE},    {ids_y_.buffer, 0, VK_WHOLE_SIZE},
        {ids_z_.buffer, 0, VK_WHOLE_SIZE},     {ids_x_.buffer, 0, VK_WHOLE_SIZE},
        {positions_.buffer, 0, VK_WHOLE_SIZE}, {triangles_.buffer, 0, VK_WHOLE_SIZE},
        {colors_.buffer, 0, VK_WHOLE_SIZE},    {vertex_rows_[r].buffer, 0, VK_WHOLE_SIZE},
        {face_rows_[r].buffer, 0, VK_WHOLE_SIZE}, {element_edges_.buffer, 0, VK_WHOLE_SIZE},
        {cell_cases_.buffer, 0, VK_WHOLE_SIZE}};
    writeBufferDescriptors(context_, set_, infos);
  };
  bind();

  const uint32_t max_x = std::max<uint32_t>(context_.facts.max_dispatch_groups_x, 1);
  auto dispatch = [&](VkCommandBuffer commands, uint32_t pass, uint32_t groups) {
    const uint32_t x = std::min(groups, max_x);
    push.groups_x = x;
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pass < 5 ? slab_passes[pass] : passes_[pass]);
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
    vkCmdPushConstants(commands, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(commands, x, (groups + x - 1) / x, 1);
  };
  auto barrier = [](VkCommandBuffer commands, VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
    VkMemoryBarrier b = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = dst;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, dst_stage, 0,
                         1, &b, 0, nullptr, 0, nullptr);
  };
  const VkAccessFlags shader_rw = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;

  // The counts (written by GpuEscape's dispatches, submitted before) and the scans; while they
  // run, what the caller has to submit next (the next slab's counts, queued before this slab's
  // second submission, so that the device has them to do while the host reads the totals).
  Status status = submit(submissions_[0], [&](VkCommandBuffer commands) {
    if (queries_) vkCmdResetQueryPool(commands, queries_, 0, kStamps);
    barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, shader_rw);
    stamp(commands, kStart);
    dispatch(commands, 0, push.vertex_group_count);
    dispatch(commands, 1, push.triangle_group_count);
    barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, shader_rw);
    dispatch(commands, 2, 2);
    stamp(commands, kScanned);
    barrier(commands, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  });
  if (status && while_scanning) status = while_scanning();
  if (Status waited = waitCommandSlot(context_, submissions_[0]); status && !waited) status = waited;
  if (!status) return status.error();
  if (Status s = invalidateBuffer(context_, totals_); !s) return s.error();
  uint32_t totals[4];
  std::memcpy(totals, totals_.mapped, sizeof totals);
  const uint64_t vertices = totals[0], triangles = totals[1];

  // The vertices and triangles into device memory, then copied across to host-visible memory by
  // the transfer engine (a shader's scattered writes across the bus were several times slower).
  // Read back as the positions, the colours (with slab.noise_colors) and the triangles; or, with
  // slab.ply_rows, as the vertex rows (of every vertex made: the last plane's in-plane ones, which
  // the next slab owns, are not known from the others until pass 3 has run) and the face rows.
  const uint64_t position_bytes = vertices * 3 * sizeof(double), triangle_bytes = triangles * 3 * sizeof(uint32_t);
  const uint64_t color_bytes = slab.noise_colors ? vertices * 3 * sizeof(float) : 0;
  const uint64_t row_bytes = slab.rowBytes();
  // The rows' buffers hold whole blocks of 4 rows (mesh_rows.comp writes whole words).
  const uint64_t vertex_row_bytes = slab.ply_rows ? vertices * row_bytes : 0;
  const uint64_t face_row_bytes = slab.ply_rows ? triangles * kFaceRowBytes : 0;
  const uint64_t old_sizes[5] = {positions_.size, triangles_.size, colors_.size, vertex_rows_[r].size, face_rows_[r].size};
  if (Status s = ensure(positions_, position_bytes, false, "slab vertices"); !s) return s.error();
  if (Status s = ensure(triangles_, triangle_bytes, false, "slab triangles"); !s) return s.error();
  if (Status s = ensure(colors_, color_bytes, false, "slab colours"); !s) return s.error();
  if (Status s = ensure(vertex_rows_[r], (vertices + 3) / 4 * 4 * row_bytes, false, "slab vertex rows"); !s)
    return s.error();
  if (Status s = ensure(face_rows_[r], (triangles + 3) / 4 * 4 * kFaceRowBytes, false, "slab face rows"); !s)
    return s.error();
  const unsigned readback_index = next_readback_;
  Buffer& readback = readback_[readback_index];
  next_readback_ ^= 1;
  // The copy of two slabs before, out of these rows' buffers into this readback buffer, has been
  // waited for by its reader (the view's contract); this only marks it done.
  if (Status s = waitCommandSlot(context_, copies_[readback_index].slot); !s) return s.error();
  const uint64_t readback_bytes =
      slab.ply_rows ? vertex_row_bytes + face_row_bytes : position_bytes + color_bytes + triangle_bytes;
  if (Status s = ensure(readback, readback_bytes, true, "slab mesh for the host"); !s) return s.error();
  const uint64_t new_sizes[5] = {positions_.size, triangles_.size, colors_.size, vertex_rows_[r].size, face_rows_[r].size};
  if (!std::equal(old_sizes, old_sizes + 5, new_sizes)) bind();
  push.rows = static_cast<uint32_t>(vertices);
  push.row_bytes = static_cast<uint32_t>(row_bytes);
  push.faces = static_cast<uint32_t>(triangles);
  push.vertex_base = slab.vertex_base;
  status = submit(submissions_[1], [&](VkCommandBuffer commands) {
    // What the first submission's passes wrote (the group offsets, the kept bytes).
    barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, shader_rw);
    stamp(commands, kStart2);
    dispatch(commands, 3, push.vertex_group_count);
    if (slab.noise_colors && vertices) {
      barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, shader_rw);
      dispatch(commands, kColorPass, static_cast<uint32_t>((vertices + 255) / 256));
    }
    stamp(commands, kVertices);
    barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, shader_rw);
    dispatch(commands, 4, push.triangle_group_count);
    stamp(commands, kTriangles);
    if (slab.ply_rows) {
      barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, shader_rw);
      if (vertices) dispatch(commands, vertex_pass, rowGroups(vertices));
      if (triangles) dispatch(commands, kFaceRowPass, rowGroups(triangles));
    }
    if (beside) {
      // The rows go to the transfer queue (released there), which copies them across.
      stamp(commands, kCopied);
      rowsOwnership(commands, r, true);
      return;
    }
    barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    auto across = [&](const Buffer& from, uint64_t at, uint64_t bytes) {
      if (bytes == 0) return;
      const VkBufferCopy copy{0, at, bytes};
      vkCmdCopyBuffer(commands, from.buffer, readback.buffer, 1, &copy);
    };
    if (slab.ply_rows) {
      across(vertex_rows_[r], 0, vertex_row_bytes);
      across(face_rows_[r], vertex_row_bytes, face_row_bytes);
    } else {
      across(positions_, 0, position_bytes);
      across(colors_, position_bytes, color_bytes);
      across(triangles_, position_bytes + color_bytes, triangle_bytes);
    }
    stamp(commands, kCopied);
    barrier(commands, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }, beside ? copies_[readback_index].ready : VK_NULL_HANDLE);
  // Beside: the copy across on the transfer queue, once the rows are made (the semaphore); the
  // host waits for it only where the rows are read (the view's `ready`).
  if (status && beside) status = submitCopy(copies_[readback_index], r, readback, vertex_row_bytes, face_row_bytes);
  if (Status waited = waitCommandSlot(context_, submissions_[1]); status && !waited) status = waited;
  if (!status) return status.error();
  if (Status s = readStamps(); !s) return s.error();
  times_.copied_beside = beside;
  for (const Buffer* b : {&totals_, &readback})
    if (b == &totals_ || !beside)
      if (Status s = invalidateBuffer(context_, *b); !s) return s.error();
  std::memcpy(totals, totals_.mapped, sizeof totals);

  McSlabView out;
  out.first_plane_vertices = totals[2];
  const uint64_t last_first = totals[3];  // the first id of the last plane's in-plane vertices
  out.last_plane_vertices = static_cast<uint32_t>(vertices - last_first);
  const uint64_t owned = slab.owns_last_plane ? vertices : last_first;
  if (slab.ply_rows) {
    const auto* rows = static_cast<const uint8_t*>(readback.mapped);
    out.row_vertices = owned;
    // A tile's last slab: the seam plane's rows follow, the copies the tile file holds.
    out.vertex_rows = {rows, (slab.seam_positions ? vertices : owned) * row_bytes};
    out.face_rows = {rows + vertex_row_bytes, face_row_bytes};
    if (beside)
      out.ready = [this, readback_index]() -> Status {
        if (Status s = waitCommandSlot(context_, copies_[readback_index].slot); !s) return s;
        return invalidateBuffer(context_, readback_[readback_index]);
      };
    return out;
  }
  const auto* positions = static_cast<const glm::dvec3*>(readback.mapped);
  out.positions = {positions, owned};
  if (!slab.owns_last_plane && slab.seam_positions)
    out.seam_positions = {positions + last_first, vertices - last_first};
  const auto* bytes = static_cast<const uint8_t*>(readback.mapped);
  if (color_bytes) out.colors = {reinterpret_cast<const glm::vec3*>(bytes + position_bytes), vertices};
  out.triangles = {reinterpret_cast<const uint32_t*>(bytes + position_bytes + color_bytes), 3 * triangles};
  return out;
}

}  // namespace dpoint
