#include "viewer/render.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <future>
#include <optional>

#include "core/interrupt.h"
#include "core/memory.h"
#include "core/parallel.h"
#include "core/text.h"
#include "vulkan/buffers.h"
#include "viewer/pipelines.h"
#include "viewer/render_internal.h"
#include "viewer/selftest.h"

namespace dpoint {
namespace {

using detail::Chunk;
using detail::Resources;

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Points per draw: every per-chunk buffer must fit one allocation and, when read as a storage
// buffer (pulled positions, probe output), one descriptor range.
size_t chunkPoints(const DeviceFacts& facts, const RenderOptions& options, bool pulled) {
  uint64_t limit = uint64_t{1} << 30;
  if (facts.max_memory_allocation) limit = std::min(limit, facts.max_memory_allocation);
  limit -= 64;  // a planar layout pads each plane to 16 bytes
  uint64_t per_point = std::max<uint64_t>(positionBytes(options.mode), 4);
  if (pulled || options.probe) {
    limit = std::min(limit, facts.max_storage_buffer_range);
    if (options.probe) per_point = std::max<uint64_t>(per_point, sizeof(glm::vec4));
  }
  uint64_t points = std::max<uint64_t>(1, limit / per_point);
  // The compute backend dispatches one 256-thread group per kSplatPointsPerGroup points of a chunk.
  if (options.backend == Backend::kCompute)
    points = std::min<uint64_t>(points, uint64_t{facts.max_dispatch_groups_x} * kSplatPointsPerGroup);
  if (options.max_chunk_points) points = std::min(points, options.max_chunk_points);
  // The compute splat of batch mode reads points in pairs that must share a batch: chunks start
  // at even points (ModeInfo::chunk_multiple).
  if (const uint64_t multiple = modeInfo(options.mode).chunk_multiple; multiple > 1)
    points = std::max<uint64_t>(multiple, points / multiple * multiple);
  return static_cast<size_t>(points);
}

uint64_t shadingMargin(const RenderOptions& options) {
  return static_cast<uint64_t>(shadeRadii(options.point_size, options.edl.radius, options.edl.fuse).margin());
}

Status checkOptions(const VulkanContext& context, size_t count, const Camera& camera, const RenderOptions& options) {
  if (count == 0) return Error{"nothing to render: the point set is empty", ExitCode::kBadInput};
  if (count > UINT32_MAX)
    return Error{"more than 2^32 points (" + std::to_string(count) + ") are not supported", ExitCode::kResourceLimit};
  if (options.frames == 0) return Error{"--frames 0: must be at least 1", ExitCode::kUsage};
  // Each draw has buffers of its own (a review finding: --chunk-points 1 made 100,000 draws of
  // 100,000 points, which took 990 MB past --max-memory 200M; NVIDIA's driver allows 4,096
  // allocations in all).
  if (options.max_chunk_points && (count - 1) / options.max_chunk_points + 1 > kMaxChunks)
    return Error{"--chunk-points " + std::to_string(options.max_chunk_points) + ": " + std::to_string(count) +
                     " points would take more than " + std::to_string(kMaxChunks) + " draws; give at least " +
                     std::to_string((count - 1) / kMaxChunks + 1),
                 ExitCode::kUsage};
  const DeviceFacts& f = context.facts;
  if (!(options.point_size >= 1.0f) || options.point_size > f.max_point_size)
    return Error{"--point-size " + formatNumber(options.point_size) + ": must be 1.." + formatNumber(f.max_point_size) +
                     " on " + f.name,
                 ExitCode::kUsage};
  if (options.backend == Backend::kRaster && options.point_size != 1.0f && !f.large_points)
    return Error{"--point-size above 1 needs the largePoints feature, which " + f.name + " lacks", ExitCode::kNoDevice};
  if (options.backend == Backend::kCompute) {
    if (!f.int64_atomics)
      return Error{"--backend compute needs shaderInt64 and shaderBufferInt64Atomics, which " + f.name + " lacks",
                   ExitCode::kNoDevice};
    if (uint64_t{4} * count > f.max_storage_buffer_range)
      return Error{"--backend compute keeps every colour in one storage buffer: " + std::to_string(count) +
                       " points exceed " + f.name + "'s maxStorageBufferRange; use --backend raster",
                   ExitCode::kResourceLimit};
  }
  // The picture's size comes from the command line: refused here rather than by a failed allocation.
  const uint64_t width = camera.width, height = camera.height;
  const std::string picture = "a " + std::to_string(width) + "x" + std::to_string(height) + " picture";
  if (options.backend == Backend::kRaster && std::max(width, height) > f.max_image_dimension)
    return Error{picture + " is larger than " + f.name + " draws (" + std::to_string(f.max_image_dimension) +
                     " pixels a side at most)",
                 ExitCode::kResourceLimit};
  if (options.shading == Shading::kEdl && !shadingFits(f, camera.width, camera.height, options))
    return Error{"shading reads " + picture + " with a margin of " + std::to_string(shadingMargin(options)) +
                     " pixels as texel buffers: more than " + f.name + "'s maxTexelBufferElements of " +
                     std::to_string(f.max_texel_buffer_elements) + "; use --shade none",
                 ExitCode::kResourceLimit};
  if (options.backend == Backend::kCompute && 8 * width * height > f.max_storage_buffer_range)
    return Error{"--backend compute keeps a 64-bit key per pixel in one storage buffer: " + picture + " exceeds " +
                     f.name + "'s maxStorageBufferRange of " + std::to_string(f.max_storage_buffer_range) + " bytes",
                 ExitCode::kResourceLimit};
  const ModeInfo& mode = modeInfo(options.mode);
  if (mode.attribute_needs_r64_vertex && options.native_path == NativePath::kAttribute && !f.r64g64b64_vertex)
    return Error{f.name + " does not list R64G64B64_SFLOAT as a vertex format; " + std::string(mode.name) +
                     " mode must pull positions",
                 ExitCode::kNoDevice};
  return okStatus();
}

// The device runs the mode: its features, and for emulated double the self-test.
Status checkMode(const VulkanContext& context, const RenderOptions& options) {
  SelfTest self_test{true, ""};
  if (modeInfo(options.mode).needs_self_test) {
    Result<SelfTest> ran = runPrecisionSelfTest(context);
    if (!ran) return ran.error();
    self_test = *ran;
  }
  // The compute probe writes from a compute shader, which needs no vertex-stage stores.
  return modeUsable(context, options.mode, self_test, options.probe && options.backend == Backend::kRaster);
}

void writeDescriptors(const VulkanContext& context, const Resources& r, const Chunk& chunk, bool pulled, bool probe) {
  auto whole = [](const Buffer& b) { return VkDescriptorBufferInfo{b.buffer, 0, VK_WHOLE_SIZE}; };
  VkDescriptorBufferInfo infos[6] = {
      whole(r.camera),
      pulled ? whole(chunk.positions) : whole(r.dummy),
      r.batches.buffer ? whole(r.batches) : whole(r.dummy),
      probe ? whole(chunk.probe) : whole(r.dummy),
      whole(r.dummy),  // the compute backend's visibility
      r.batch_plan.buffer ? whole(r.batch_plan) : whole(r.dummy),
  };
  static_assert(kBindingCamera == 0, "the camera uniform is binding 0");
  writeBufferDescriptors(context, chunk.set, infos, true);
}

void recordDraws(VkCommandBuffer commands, const Resources& r, VkPipeline pipeline, const RenderOptions& options,
                 uint32_t width, uint32_t height, bool timed) {
  VkClearValue clears[2] = {};
  for (int c = 0; c < 4; ++c)
    clears[0].color.float32[c] = static_cast<float>((options.background_rgba8 >> (8 * c)) & 0xffu) / 255.0f;
  clears[1].depthStencil = {0.0f, 0};  // reversed Z: 0 is the far plane
  VkRenderPassBeginInfo begin = {VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = r.pipelines.render_pass;
  begin.framebuffer = r.framebuffer;
  begin.renderArea = {{0, 0}, {width, height}};
  begin.clearValueCount = 2;
  begin.pClearValues = clears;
  if (timed) vkCmdResetQueryPool(commands, r.queries, 0, 2);
  vkCmdBeginRenderPass(commands, &begin, VK_SUBPASS_CONTENTS_INLINE);
  if (timed) vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, r.queries, 0);
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  for (const Chunk& chunk : r.chunks) {
    PushConstants push;
    push.point_size = options.point_size;
    push.first_index = static_cast<uint32_t>(chunk.first);
    push.count = static_cast<uint32_t>(chunk.count);
    push.batch_shift = batchShift(options.mode);
    push.depth_scale = r.round_depth_scale;
    push.bulge = r.round_bulge;
    vkCmdPushConstants(commands, r.pipelines.layout, kPointPushStages, 0, sizeof(push), &push);
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_GRAPHICS, r.pipelines.layout, 0, 1, &chunk.set, 0, nullptr);
    VkDeviceSize offset = 0;
    if (!r.pipelines.pulls_positions) vkCmdBindVertexBuffers(commands, 0, 1, &chunk.positions.buffer, &offset);
    vkCmdBindVertexBuffers(commands, 1, 1, &chunk.colors.buffer, &offset);
    vkCmdDraw(commands, static_cast<uint32_t>(chunk.count), 1, 0, 0);
  }
  if (timed) vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, r.queries, 1);
  vkCmdEndRenderPass(commands);
}

// Where a chunk's points come from: the set itself when it is in memory (offset = the chunk's
// first index), or a block just read from a stream (offset 0). Fails with the stream's error.
struct BlockView {
  const PointSet* set = nullptr;
  size_t offset = 0;
};
using ChunkPoints = std::function<Result<BlockView>(size_t first, size_t count)>;

Status uploadPoints(const VulkanContext& context, Resources& r, size_t total, const ChunkPoints& chunk_points,
                    const RenderOptions& options, const ModeEncoding& encoding, bool pulled, size_t per_chunk) {
  const uint32_t stride = positionBytes(options.mode);
  const PositionLayout& layout = modeInfo(options.mode).layout;
  const bool compute = options.backend == Backend::kCompute;
  VkBufferUsageFlags position_usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT |
      (pulled || compute ? VK_BUFFER_USAGE_STORAGE_BUFFER_BIT : VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  // RGBA8 colours of `count` points of `view`, encoded straight into the upload at byte `at`: in a
  // buffer per chunk for the raster backend's vertex input, one for the whole set for the compute
  // resolve.
  auto upload_colors = [&](Buffer& out, BlockView view, size_t count, VkDeviceSize at) {
    return uploadBuffer(context, out, count * 4, [&](void* dst, VkDeviceSize offset, VkDeviceSize bytes) {
      encodeColors(*view.set, view.offset + offset / 4, bytes / 4, static_cast<uint32_t*>(dst));
    }, 4, VkDeviceSize{32} << 20, at);
  };
  auto create = [&](Buffer& out, VkDeviceSize bytes, VkBufferUsageFlags usage, const std::string& what) {
    Result<Buffer> buffer = createUploadTarget(context, bytes, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, what);
    if (!buffer) return Status(buffer.error());
    out = *buffer;
    return okStatus();
  };
  if (compute) {
    if (Status status = create(r.all_colors, total * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "colours"); !status)
      return status;
  }
  for (size_t first = 0; first < total; first += per_chunk) {
    Chunk& chunk = r.chunks.emplace_back();
    chunk.first = first;
    chunk.count = std::min(per_chunk, total - first);
    Result<BlockView> view = chunk_points(chunk.first, chunk.count);
    if (!view) return view.error();
    std::string what = "points " + std::to_string(first) + ".." + std::to_string(first + chunk.count - 1);
    if (Status status = create(chunk.positions, positionBufferBytes(options.mode, chunk.count), position_usage,
                               what + " positions");
        !status)
      return status;
    // Plane by plane (one, interleaved, for every mode but adaptive): a point's bytes in a plane,
    // `element`, are the whole point's where there is one plane.
    const VkDeviceSize element = layout.planes == 1 ? stride : layout.element_bytes;
    const VkDeviceSize plane_bytes = planeStride(chunk.count) * element;
    Status status = okStatus();
    for (uint32_t plane = 0; plane < layout.planes && status; ++plane) {
      status = uploadBuffer(context, chunk.positions, chunk.count * element,
          [&](void* dst, VkDeviceSize offset, VkDeviceSize bytes) {
            encodePositions(encoding, *view->set, view->offset + offset / element, bytes / element, dst,
                            chunk.first - view->offset, plane);
          }, element, VkDeviceSize{32} << 20, plane * plane_bytes);
    }
    if (!status) return status;
    if (compute && options.near_end_first) detail::sampleSplatOrder(chunk, *view->set, view->offset);
    if (compute) {
      status = upload_colors(r.all_colors, *view, chunk.count, VkDeviceSize{chunk.first} * 4);
    } else {
      status = create(chunk.colors, chunk.count * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, what + " colours");
      if (status) status = upload_colors(chunk.colors, *view, chunk.count, 0);
    }
    if (!status) return status;
    if (options.probe) {
      Result<Buffer> probe = createBuffer(context, chunk.count * sizeof(glm::vec4),
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, true,
                                          what + " probe");
      if (!probe) return probe.error();
      chunk.probe = *probe;
    }
  }
  return okStatus();
}

Status createTargets(const VulkanContext& context, Resources& r, uint32_t width, uint32_t height, bool keep_depth) {
  Result<GpuImage> color = createImage(context, width, height, kColorFormat,
      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
  if (!color) return color.error();
  r.color = *color;
  Result<GpuImage> depth = createImage(context, width, height, kDepthFormat,
      VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | (keep_depth ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0),
      VK_IMAGE_ASPECT_DEPTH_BIT);
  if (!depth) return depth.error();
  r.depth = *depth;
  VkImageView views[2] = {r.color.view, r.depth.view};
  VkFramebufferCreateInfo info = {VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  info.renderPass = r.pipelines.render_pass;
  info.attachmentCount = 2;
  info.pAttachments = views;
  info.width = width;
  info.height = height;
  info.layers = 1;
  VK_TRY(vkCreateFramebuffer(context.device, &info, nullptr, &r.framebuffer));
  Result<Buffer> readback = createBuffer(context, VkDeviceSize{width} * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                         true, "picture readback");
  if (!readback) return readback.error();
  r.readback = *readback;
  return okStatus();
}

Status createDescriptors(const VulkanContext& context, Resources& r, bool pulled, bool probe) {
  const uint32_t sets = static_cast<uint32_t>(r.chunks.size()) + (r.shade.log ? 1 : 0);
  if (Status status = detail::createDescriptorPool(context, r, sets, 5); !status)
    return status;
  for (Chunk& chunk : r.chunks) {
    VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    allocate.descriptorPool = r.descriptor_pool;
    allocate.descriptorSetCount = 1;
    allocate.pSetLayouts = &r.pipelines.set_layout;
    VK_TRY(vkAllocateDescriptorSets(context.device, &allocate, &chunk.set));
    writeDescriptors(context, r, chunk, pulled, probe);
  }
  return r.shade.log ? detail::createShadeDescriptors(context, r) : okStatus();
}

Status createUniforms(const VulkanContext& context, Resources& r, const Camera& camera, const ModeEncoding& encoding) {
  std::vector<uint8_t> uniform = cameraUniform(encoding, camera);
  uniform.resize(std::max<size_t>(uniform.size(), 256), 0);
  Result<Buffer> ubo = createBuffer(context, uniform.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                    false, "camera uniform");
  if (!ubo) return ubo.error();
  r.camera = *ubo;
  Status status = uploadBuffer(context, r.camera, uniform.size(), [&](void* dst, VkDeviceSize offset, VkDeviceSize bytes) {
    std::memcpy(dst, uniform.data() + offset, bytes);
  });
  if (!status) return status;
  Result<Buffer> dummy = createBuffer(context, 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false, "unused binding");
  if (!dummy) return dummy.error();
  r.dummy = *dummy;
  return okStatus();
}

// What the plan's buffer holds (binding 5): the tiers of every batch (0: culled), then for the
// compute backend, for each chunk that culls a batch or starts inside one (tests' small chunks),
// the list of the batches it overlaps that the plan keeps, batch | tiers << 30 (setting the
// chunk's list_first and list_count). A chunk without a list is splatted whole, a workgroup per
// 1024 points (from either end: RenderOptions::near_end_first): no load of the list stands before
// its points' loads.
std::vector<uint32_t> batchPlanWords(Resources& r, const ModeEncoding& encoding, bool compute) {
  std::vector<uint32_t> words(encoding.batch_plan.begin(), encoding.batch_plan.end());
  if (!compute) return words;
  for (detail::Chunk& chunk : r.chunks) {
    const size_t first = encoding.batchOf(chunk.first), last = encoding.batchOf(chunk.first + chunk.count - 1);
    bool whole = chunk.first % encoding.batchSize() == 0;
    for (size_t b = first; b <= last && whole; ++b) whole = encoding.batch_plan[b] != 0;
    chunk.listed = !whole;
    if (whole) continue;
    chunk.list_first = static_cast<uint32_t>(words.size());
    for (size_t b = first; b <= last; ++b)
      if (const uint32_t tiers = encoding.batch_plan[b]) words.push_back(static_cast<uint32_t>(b) | tiers << 30);
    chunk.list_count = static_cast<uint32_t>(words.size()) - chunk.list_first;
  }
  return words;
}

// The per-batch modes' matrices and plan, once every batch is known (a stream appends them block
// by block).
Status uploadBatchMatrices(const VulkanContext& context, Resources& r, const RenderOptions& options,
                           const ModeEncoding& encoding) {
  if (!modeInfo(options.mode).batch_points) return okStatus();
  auto upload = [&](Buffer& out, const void* data, VkDeviceSize bytes, const std::string& what) -> Status {
    Result<Buffer> buffer = createBuffer(context, std::max<VkDeviceSize>(bytes, 16),
                                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, what);
    if (!buffer) return buffer.error();
    out = *buffer;
    if (bytes == 0) return okStatus();
    return uploadBuffer(context, out, bytes, [&](void* dst, VkDeviceSize offset, VkDeviceSize n) {
      std::memcpy(dst, static_cast<const uint8_t*>(data) + offset, n);
    });
  };
  const std::vector<glm::mat4> matrices = batchMatrices(encoding);
  if (Status status = upload(r.batches, matrices.data(), matrices.size() * sizeof(glm::mat4), "batch matrices"); !status)
    return status;
  const std::vector<uint32_t> plan = batchPlanWords(r, encoding, options.backend == Backend::kCompute);
  return upload(r.batch_plan, plan.data(), plan.size() * sizeof(uint32_t), "batch plan");
}

Status timeFrames(const VulkanContext& context, Resources& r, const RenderOptions& options, const Camera& camera,
                  RenderResult& out) {
  const uint32_t width = camera.width, height = camera.height;
  bool timestamps = context.facts.timestamp_period_ns > 0.0f;
  if (timestamps) {
    VkQueryPoolCreateInfo query_info = {VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = 2;
    VK_TRY(vkCreateQueryPool(context.device, &query_info, nullptr, &r.queries));
  }
  Result<VkCommandBuffer> commands = allocateCommandBuffer(context);
  if (!commands) return commands.error();
  r.frame_commands = *commands;
  VkCommandBufferBeginInfo begin = {VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  VK_TRY(vkBeginCommandBuffer(r.frame_commands, &begin));
  if (options.backend == Backend::kCompute)
    detail::recordCompute(r.frame_commands, r, r.compute.splat, options, width, height, timestamps);
  else
    recordDraws(r.frame_commands, r, r.pipelines.draw, options, width, height, timestamps);
  if (options.shading == Shading::kEdl)
    detail::recordShade(r.frame_commands, r, detail::edlPush(camera, options.edl, options.point_size), options.backend == Backend::kRaster);
  VK_TRY(vkEndCommandBuffer(r.frame_commands));
  VkFenceCreateInfo fence_info = {VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VK_TRY(vkCreateFence(context.device, &fence_info, nullptr, &r.fence));

  // One frame: submit, wait, and its wall time from submit to fence.
  auto drawFrame = [&]() -> Result<double> {
    if (interrupted()) return interruptedError();  // between frames: the GPU is idle here
    Clock::time_point start = Clock::now();
    VkSubmitInfo submit = {VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &r.frame_commands;
    VK_TRY(queueSubmit(context, submit, r.fence));
    VK_TRY(waitForFence(context, r.fence));
    double wall = msSince(start);
    VK_TRY(vkResetFences(context.device, 1, &r.fence));
    return wall;
  };
  // The warm-up: a count of frames, then frames until its time has passed (RenderOptions).
  const Clock::time_point warmup_start = Clock::now();
  while (out.warmup_frames < options.warmup_frames ||
         (options.warmup_ms > 0.0 && msSince(warmup_start) < options.warmup_ms)) {
    if (Result<double> drawn = drawFrame(); !drawn) return drawn.error();
    ++out.warmup_frames;
  }
  out.warmup_ms = out.warmup_frames ? msSince(warmup_start) : 0.0;
  for (uint32_t frame = 0; frame < options.frames; ++frame) {
    Result<double> wall = drawFrame();
    if (!wall) return wall.error();
    out.frame_ms.push_back(*wall);
    if (timestamps) {
      uint64_t ticks[2] = {0, 0};
      VK_TRY(vkGetQueryPoolResults(context.device, r.queries, 0, 2, sizeof(ticks), ticks, sizeof(uint64_t),
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
      out.gpu_ms.push_back(static_cast<double>(ticks[1] - ticks[0]) * context.facts.timestamp_period_ns * 1e-6);
    }
  }
  return okStatus();
}

Status readPicture(const VulkanContext& context, Resources& r, uint32_t width, uint32_t height, RenderResult& out) {
  Clock::time_point start = Clock::now();
  Status status = submitOnce(context, [&](VkCommandBuffer commands) {
    if (const Buffer& rows = r.shaded.buffer ? r.shaded : r.picture; rows.buffer) {
      // packed RGBA8 rows: the eye-dome pass's, or the compute resolve's
      VkBufferCopy copy{0, 0, VkDeviceSize{width} * height * 4};
      vkCmdCopyBuffer(commands, rows.buffer, r.readback.buffer, 1, &copy);
    } else {
      VkBufferImageCopy copy{};
      copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      copy.imageExtent = {width, height, 1};  // bufferRowLength 0: rows packed, pitch = width · 4
      vkCmdCopyImageToBuffer(commands, r.color.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, r.readback.buffer, 1, &copy);
    }
    VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
  });
  if (!status) return status;
  status = invalidateBuffer(context, r.readback);
  if (!status) return status;
  out.image.width = width;
  out.image.height = height;
  const auto* bytes = static_cast<const uint8_t*>(r.readback.mapped);
  out.image.rgba.assign(bytes, bytes + size_t{width} * height * 4);
  out.readback_ms = msSince(start);
  return okStatus();
}

Status runProbe(const VulkanContext& context, Resources& r, const RenderOptions& options, uint32_t width,
                uint32_t height, size_t count, RenderResult& out) {
  Status status = submitOnce(context, [&](VkCommandBuffer commands) {
    const bool compute = options.backend == Backend::kCompute;
    // Zeros first: a point no splat reads (its batch culled) keeps a clip position of 0, which no
    // view holds (w = 0).
    for (const Chunk& chunk : r.chunks) vkCmdFillBuffer(commands, chunk.probe.buffer, 0, VK_WHOLE_SIZE, 0);
    VkMemoryBarrier cleared = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    cleared.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    cleared.dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         compute ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_VERTEX_SHADER_BIT, 0, 1,
                         &cleared, 0, nullptr, 0, nullptr);
    if (compute)
      detail::recordCompute(commands, r, r.compute.probe, options, width, height, false);
    else
      recordDraws(commands, r, r.pipelines.probe, options, width, height, false);
    VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands, compute ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_VERTEX_SHADER_BIT,
                         VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
  });
  if (!status) return status;
  out.probe_clip.resize(count);
  for (const Chunk& chunk : r.chunks) {
    status = invalidateBuffer(context, chunk.probe);
    if (!status) return status;
    std::memcpy(out.probe_clip.data() + chunk.first, chunk.probe.mapped, chunk.count * sizeof(glm::vec4));
  }
  return okStatus();
}

// Both entry points: `total` points, a chunk at a time from `chunk_points`; `encoding` is complete
// for a set in memory, and for a stream grows block by block (chunk_points adds each block).
Result<RenderResult> renderChunks(const VulkanContext& context, size_t total, const ChunkPoints& chunk_points,
                                  const ModeEncoding& encoding, const Camera& given_camera,
                                  const RenderOptions& given_options,
                                  std::chrono::steady_clock::time_point upload_start, uint64_t max_chunk_points,
                                  const StreamSettle* settle = nullptr) {
  Camera camera = given_camera;
  RenderOptions options = given_options;
  const bool compute = options.backend == Backend::kCompute;
  // Resolved once: the splat's pipeline, the upload (the chunks' order samples, from
  // options.near_end_first) and the choice of ends follow it; a stream's settled options, made
  // afresh, do not change it.
  const bool near_end_first = compute && options.early_depth && options.near_end_first;
  options.near_end_first = near_end_first;
  // Positions come from a storage buffer in the compute backend, for native mode on a device
  // without double vertex attributes, and always for a mode with no vertex attributes (adaptive).
  const ModeShaders& shaders = modeInfo(options.mode).shaders;
  bool pulled = shaders.vertex_pull.code != nullptr &&
                (compute || shaders.attribute_count == 0 || options.native_path == NativePath::kPull ||
                 (options.native_path == NativePath::kAuto && !context.facts.r64g64b64_vertex));
  Resources r(context);
  // The driver compiles the pipelines while the points are encoded and uploaded: on NVIDIA's a
  // cold shader cache takes 50-100 ms, as long as the upload of 16.7M points. Declared after r,
  // so an early return waits for it before r is torn down. A stream settled after its upload
  // (renderStreamOnce) knows its point size, and so its pipelines, only then.
  std::future<Status> pipelines_made, shade_made;
  auto make_pipelines = [&]() {
    const bool shading = options.shading == Shading::kEdl;
    pipelines_made = std::async(std::launch::async, [&, shading]() -> Status {
      if (compute) {
        Result<ComputePipelines> pipelines =
            createComputePipelines(context, options.mode, options.probe,
                                   SplatVariant{options.early_depth, options.subgroup_merge.value_or(context.facts.type != "cpu"),
                                                options.pair_merge.value_or(context.facts.type != "cpu"),
                                                options.point_size != 1.0f, options.round_points,
                                                near_end_first},
                                   shading);
        if (!pipelines) return pipelines.error();
        r.compute = *pipelines;
      } else {
        Result<PointPipelines> pipelines =
            createPointPipelines(context, options.mode, pulled, options.probe, camera.width, camera.height, shading,
                                 options.round_points && options.point_size != 1.0f);
        if (!pipelines) return pipelines.error();
        r.pipelines = *pipelines;
      }
      return okStatus();
    });
    // And the shading's beside them: on lavapipe making them takes as long as uploading 1.5M points.
    shade_made = std::async(std::launch::async, [&, shading]() -> Status {
      if (!shading) return okStatus();
      Result<ShadePipeline> pipeline =
          createShadePipeline(context, shadeRadii(options.point_size, options.edl.radius, options.edl.fuse));
      if (!pipeline) return pipeline.error();
      r.shade = *pipeline;
      return okStatus();
    });
  };
  if (!settle) make_pipelines();

  RenderResult out;
  out.pulled_positions = pulled;
  RenderOptions chunking = options;
  chunking.max_chunk_points = max_chunk_points;
  Status status = uploadPoints(context, r, total, chunk_points, options, encoding, pulled,
                               chunkPoints(context.facts, chunking, pulled || compute));
  if (status && settle) {
    const PrecisionMode mode = options.mode;
    const Backend backend = options.backend;
    status = (*settle)(camera, options);
    assert(options.mode == mode && options.backend == backend);
    (void)mode, (void)backend;
    if (status) make_pipelines();
  }
  const bool shading = options.shading == Shading::kEdl;
  detail::roundPointPush(camera, options, r.round_depth_scale, r.round_bulge);
  if (status) status = createUniforms(context, r, camera, encoding);
  if (status) status = uploadBatchMatrices(context, r, options, encoding);
  if (status && near_end_first) out.reversed_chunks = detail::chooseSplatEnds(r, camera);
  Status made = pipelines_made.valid() ? pipelines_made.get() : okStatus();
  Status shade = shade_made.valid() ? shade_made.get() : okStatus();
  if (!status) return status.error();
  if (!made) return made.error();
  if (!shade) return shade.error();
  out.chunks = static_cast<uint32_t>(r.chunks.size());
  out.gpu_bytes = uint64_t{bytesPerPoint(options.mode)} * total;
  if (modeInfo(options.mode).batch_points) out.batch_plan = batchPlanStats(encoding, total);
  out.upload_ms = msSince(upload_start);

  if (compute) {
    status = detail::createComputeTargets(context, r, camera.width, camera.height);
    if (status && shading) status = detail::createShadeTargets(context, r, camera, options, false);
    if (status) status = detail::createComputeDescriptors(context, r, options.probe);
  } else {
    status = createTargets(context, r, camera.width, camera.height, shading);
    if (status && shading) status = detail::createShadeTargets(context, r, camera, options, true);
    if (status) status = createDescriptors(context, r, pulled, options.probe);
  }
  if (status) status = timeFrames(context, r, options, camera, out);
  if (status) status = readPicture(context, r, camera.width, camera.height, out);
  if (status && options.probe) status = runProbe(context, r, options, camera.width, camera.height, total, out);
  if (!status) return status.error();
  return out;
}

// Reads a stream's chunks in order, each while the one before is encoded and uploaded: two
// blocks on the host, one being read, one being uploaded.
class StreamBlocks {
 public:
  StreamBlocks(const PointStream& stream, ModeEncoding& encoding) : stream_(stream), encoding_(encoding) {}
  ~StreamBlocks() {
    if (pending_.valid()) pending_.wait();
  }
  Result<BlockView> get(size_t first, size_t count) {
    if (interrupted()) return interruptedError();  // between blocks: SIGINT ends a long stream
    const unsigned current = next_;
    Status status = pending_.valid() && pending_first_ == first ? pending_.get() : read(first, count, current);
    if (status) status = addPoints(encoding_, blocks_[current], first);
    if (!status) return status.error();
    const size_t after = first + count;
    if (after < stream_.count) {
      const unsigned slot = next_ = current ^ 1u;
      pending_first_ = after;
      pending_ = std::async(std::launch::async, [this, after, count, slot] {
        return read(after, std::min(count, stream_.count - after), slot);
      });
    }
    return BlockView{&blocks_[current], 0};
  }

 private:
  Status read(size_t first, size_t count, unsigned slot) {
    PointSet& block = blocks_[slot];
    if (Status status = stream_.read(first, count, block); !status) return status;
    if (block.size() != count || (stream_.has_colors && block.colors.size() != count))
      return Error{"the stream gave " + std::to_string(block.size()) + " points for " + std::to_string(first) + ".." +
                   std::to_string(first + count - 1)};
    return okStatus();
  }

  const PointStream& stream_;
  ModeEncoding& encoding_;
  PointSet blocks_[2];
  unsigned next_ = 0;
  size_t pending_first_ = 0;
  std::future<Status> pending_;
};

// --mode auto's walk over the modes the device runs, on bounds_of's bounds: in the device's speed
// order, or by predicted time to the picture (AutoTarget).
Result<ModeChoice> chooseOnDevice(const VulkanContext& context, Backend backend, bool probe, const BoundsOf& bounds_of,
                                  const AutoTarget& target, const BoundsOf& box_bounds_of = {}) {
  Result<SelfTest> self_test = runPrecisionSelfTest(context);
  if (!self_test) return self_test.error();
  const bool compute = backend == Backend::kCompute;
  auto usable = [&](PrecisionMode mode) { return modeUsable(context, mode, *self_test, probe && !compute).ok(); };
  const DeviceClass device_class = deviceClassOf(context.facts.type);
  const bool by_time = target.points > 0 && target.frames <= 1;
  const unsigned threads = resolveThreads(target.threads);
  ModeChoice choice =
      chooseMode(autoOrder(device_class, compute, target.points, threads, target.frames), usable, bounds_of, box_bounds_of);
  if (by_time) {
    choice.by_picture_time = true;
    choice.predicted_ms = predictedPictureMs(choice.mode, device_class, compute, target.points, threads, 1);
    if (choice.runner_up)
      choice.runner_up_predicted_ms = predictedPictureMs(*choice.runner_up, device_class, compute, target.points, threads, 1);
  }
  for (ModeChoice::Rejected& r : choice.rejected)
    if (Status why = modeUsable(context, r.mode, *self_test, probe && !compute); !why) r.reason = why.error().message;
  return choice;
}

}  // namespace

bool shadingFits(const DeviceFacts& f, uint32_t width, uint32_t height, const RenderOptions& options) {
  const uint64_t margin = shadingMargin(options);
  return (uint64_t{width} + 2 * margin) * (uint64_t{height} + 2 * margin) <= f.max_texel_buffer_elements;
}

Status detail::createDescriptorPool(const VulkanContext& context, Resources& r, uint32_t sets, uint32_t storage_per_set) {
  VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, sets},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storage_per_set * sets},
                                   {VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, kShadeBindings}};
  VkDescriptorPoolCreateInfo info = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  info.maxSets = sets;
  info.poolSizeCount = r.shade.log ? 3 : 2;
  info.pPoolSizes = sizes;
  VK_TRY(vkCreateDescriptorPool(context.device, &info, nullptr, &r.descriptor_pool));
  return okStatus();
}

Result<RenderResult> renderPoints(const VulkanContext& context, const PointSet& points, const Camera& camera,
                                  const RenderOptions& options, const ModeEncoding* prepared) {
  Status status = checkOptions(context, points.size(), camera, options);
  if (!status) return status.error();
  if (status = checkMode(context, options); !status) return status.error();
  Clock::time_point upload_start = Clock::now();
  std::optional<Result<ModeEncoding>> made;
  if (!prepared) {
    made = prepareEncoding(options.mode, points, camera, options.tolerance_px);
    if (!*made) return made->error();
    prepared = &**made;
  }
  // The prediction's encoding is this render's: the same mode, camera and tolerance.
  assert(prepared->mode == options.mode && prepared->tolerance_px == options.tolerance_px);
  assert(prepared->width == camera.width && prepared->height == camera.height);
  assert(prepared->frame.eye == sceneFrame(options.mode, camera).eye);
  assert(prepared->batches.size() ==
         (modeInfo(options.mode).batch_points ? (points.size() + prepared->batchSize() - 1) / prepared->batchSize() : 0));
  return renderChunks(context, points.size(),
                      [&](size_t first, size_t) -> Result<BlockView> { return BlockView{&points, first}; }, *prepared,
                      camera, options, upload_start, options.max_chunk_points);
}

namespace {

Result<RenderResult> streamChunks(const VulkanContext& context, const PointStream& stream, const Camera& camera,
                                  const RenderOptions& options,
                                  const StreamSettle* settle, ModeEncoding& encoding) {
  assert(!options.probe && "the probe keeps every point's clip position: render the set in memory");
  Status status = checkOptions(context, stream.count, camera, options);
  if (!status) return status.error();
  if (status = checkMode(context, options); !status) return status.error();
  Clock::time_point upload_start = Clock::now();
  encoding = beginEncoding(options.mode, camera, options.tolerance_px);
  StreamBlocks blocks(stream, encoding);
  // Whole batches per block, so batch mode's frames line up with the chunks.
  uint64_t limit = options.max_chunk_points ? std::min<uint64_t>(options.max_chunk_points, kStreamBlockPoints)
                                            : kStreamBlockPoints;
  if (const uint64_t batch = modeInfo(options.mode).batch_points) limit = std::max<uint64_t>(batch, limit / batch * batch);
  return renderChunks(context, stream.count,
                      [&](size_t first, size_t count) { return blocks.get(first, count); }, encoding, camera, options,
                      upload_start, limit, settle);
}

}  // namespace

Result<RenderResult> renderStream(const VulkanContext& context, const PointStream& stream, const Camera& camera,
                                  const RenderOptions& options) {
  ModeEncoding encoding;
  return streamChunks(context, stream, camera, options, nullptr, encoding);
}

Result<RenderResult> renderStreamOnce(const VulkanContext& context, const PointStream& stream, const Camera& provisional,
                                      const RenderOptions& options, const StreamSettle& settle) {
  ModeEncoding encoding;
  const StreamSettle reframed = [&](Camera& camera, RenderOptions& settled) {
    if (Status status = settle(camera, settled); !status) return status;
    return reframeEncoding(encoding, camera);
  };
  return streamChunks(context, stream, provisional, options, &reframed, encoding);
}

Result<ModeChoice> chooseModeOnDevice(const VulkanContext& context, const PointSet& points, const Camera& camera,
                                      Backend backend, bool probe, double tolerance_px, const AutoTarget& target,
                                      const std::optional<Box>& box) {
  BoundsOf box_bounds_of;
  if (box && !probe)
    box_bounds_of = [&](std::span<const PrecisionMode> modes) {
      return predictBoxBounds(BatchBoxes{points.size(), {*box}}, camera, modes, tolerance_px);
    };
  return chooseOnDevice(context, backend, probe, [&](std::span<const PrecisionMode> modes) {
    return predictErrorBounds(points, camera, modes, tolerance_px);
  }, target, box_bounds_of);
}

Result<ModeChoice> chooseModeOnDevice(const VulkanContext& context, const BatchBoxes& boxes, const Camera& camera,
                                      Backend backend, double tolerance_px, const AutoTarget& target) {
  return chooseOnDevice(context, backend, false, [&](std::span<const PrecisionMode> modes) {
    return predictBoxBounds(boxes, camera, modes, tolerance_px);
  }, target);
}

double medianOf(std::vector<double> values) {
  if (values.empty()) return 0.0;
  size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  double upper = values[mid];
  if (values.size() % 2) return upper;
  double lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

double percentileOf(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size())));
  return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

static_assert(kStreamBlockUnit % kBatchSize == 0 && kStreamBlockUnit % kBoxPoints == 0 &&
              kMinStreamBlockPoints % kStreamBlockUnit == 0 && kStreamBlockPoints % kStreamBlockUnit == 0);

uint64_t streamBlockPoints(uint64_t limit, uint64_t point_bytes) {
  if (limit == 0) limit = defaultMemoryLimit();
  const uint64_t fits = limit / (2 * point_bytes) / kStreamBlockUnit * kStreamBlockUnit;
  return std::clamp(fits, kMinStreamBlockPoints, kStreamBlockPoints);
}

Result<uint64_t> checkStreamMemory(const std::string& name, uint64_t count, uint64_t limit, uint64_t point_bytes,
                                   uint64_t held, const std::string& held_what) {
  const uint64_t cap = limit ? limit : defaultMemoryLimit();
  const uint64_t block = streamBlockPoints(cap > held ? cap - held : 1, point_bytes);
  if (Status s = checkMemory(name + ": streaming " + std::to_string(count) + " points a block at a time" +
                                 (held ? " beside " + formatBytes(held) + " of " + held_what : std::string()),
                             streamHeldBytes(count, block, point_bytes) + held, limit);
      !s)
    return s.error();
  return block;
}

}  // namespace dpoint
