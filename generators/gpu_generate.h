// Escape counts on a Vulkan device for `dpoint generate` (issue #14): the classification of the
// Julia and fast Mandelbulb grids (shaders/generate/escape.comp) and mandelbrot2d's perturbation deltas
// (shaders/generate/perturbation.comp), in fp64, equal to the CPU's counts bit for bit (the shaders say
// why). The generators see plain functions (generators/escape_grid.h EscapePlaneFunction,
// generators/mandelbrot2d.h PerturbationFunction), so they stay free of Vulkan; cli/ wraps these
// calls into them.
//
// Work goes out in dispatches of at most kGpuChunkPoints points (whole rows), two in flight: the
// device computes one while the host copies the other's counts out of mapped memory, or, for
// counts bound for the arena (a host-visible buffer the generator takes its blocks from), writes
// them there in place with nothing to copy. Inputs the
// shaders read on every iteration (axis values, the reference orbit) live in device-local memory.
// One thread at a time may call a GpuEscape (it records on the context's one queue and pool).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "generators/gpu_mesh.h"
#include "generators/mandelbrot2d.h"
#include "vulkan/context.h"
#include "vulkan/buffers.h"

namespace dpoint {

enum class EscapeKernel : uint32_t { kJulia = 0, kMandelbulbFast = 1 };

// What a kernel needs beyond the points; the constants are the CPU code's (generators/julia.h,
// generators/mandelbulb.h), passed in so that they are written down once.
struct EscapeKernelParams {
  EscapeKernel kernel = EscapeKernel::kJulia;
  glm::dvec4 c{0.0};             // Julia's constant
  double julia_threshold = 0.0;  // Julia: escaped when x² + (y² + z² + w²) > this
  double axis_rho2 = 0.0;        // Mandelbulb: x² + y² at or below which φ is taken as 0
  double trap_c2 = 0.0;          // Mandelbulb: |c|² at or below which the count is the limit
};

inline constexpr uint64_t kGpuChunkPoints = uint64_t{1} << 23;  // 32 MiB of counts per dispatch
// mandelbrot2d's dispatches also return 16-byte escape tails: a quarter as many points, so that its
// tail buffers (made at the first such call) add 2 × 32 MiB.
inline constexpr uint64_t kGpuPerturbationChunkPoints = kGpuChunkPoints / 4;

// Whether the device can run the kernels: shaderFloat64 and shaderInt64 (the exact rounding).
// kNoDevice naming the device and what it lacks.
Status gpuGenerateUsable(const DeviceFacts& facts);

class GpuEscape {
 public:
  // pack_counts: whether escape.comp packs the counts (bytes a count as escapePlanes returns them)
  // or writes uint32 that the host narrows; unset: packed on a GPU, whole on lavapipe (where the
  // packing's barriers cost time). The counts are the same either way.
  static Result<std::unique_ptr<GpuEscape>> create(const VulkanContext& context,
                                                   std::optional<bool> pack_counts = std::nullopt);
  ~GpuEscape();
  GpuEscape(const GpuEscape&) = delete;
  GpuEscape& operator=(const GpuEscape&) = delete;

  // Count (p − first)·res² + j·res + k = min(count, limit) for the points (axis[p], axis[j],
  // axis[k]) of planes first ≤ p < first + planes, res = axis.size(), in
  // escapeGridBytesPerCount(limit) little-endian bytes each (generators/escape_grid.h
  // EscapePlaneFunction).
  // Where `counts` lies in the arena (below) and each row's bytes are whole words, the dispatches
  // write there in place; elsewhere they are copied out of a staging buffer.
  Status escapePlanes(const EscapeKernelParams& kernel, const std::vector<double>& axis, int first, int planes,
                      int limit, uint8_t* counts);

  // `bytes` of host-visible memory that escapePlanes writes in place (generators/escape_grid.h
  // EscapeArena), valid until the next call asks for more; nullptr where the counts are not
  // packed (lavapipe) or one buffer cannot hold that much.
  Result<uint8_t*> arena(uint64_t bytes);

  // escapePlanes's counts into device memory (`target`, from its start) and nowhere else, for a
  // mesher on the device (generators/gpu_mesh.h), deviceBits(limit) bits each: packed as in the
  // arena on a GPU, whole uint32 on lavapipe. Returns once its one submission is on the queue: a
  // submission after it on the context's queue whose barrier waits for compute writes reads the
  // counts (no host round trip between); settle() once such a submission has finished.
  // With `cap` below the limit, for marching cubes (which reads a count above the level only where
  // an edge crosses it): counts to the cap, floor(level) + 1, then to the limit only at the points at
  // the cap that have a neighbour below it along an axis within the slab (shaders/generate/
  // escape.comp, ESCAPE_REFINE); elsewhere a count at or above the level stays at the cap.
  Status escapeInto(const EscapeKernelParams& kernel, const std::vector<double>& axis, int first, int planes,
                    int limit, const Buffer& target, int cap = -1);
  // Whether meshSlabOnDevice counts to the cap first (escapeInto's `cap`): on a GPU, where the
  // interior's iterations cost most (res-2048 Mandelbulb on an H200: see docs/performance.md);
  // not on lavapipe, whose gathers make the list pass cost more than it saves. Tests set it.
  bool refinesCounts() const { return refine_counts_; }
  void setRefinesCounts(bool refine) { refine_counts_ = refine; }
  // Waits for the dispatches in flight and counts their time (pointsDone, gpuMs).
  Status settle() { return finishAll(); }
  uint32_t deviceBits(int limit) const;

  // counts[r·dcx.size() + col] and tails[...]: mandelbrot2d's perturbed count of δc = (dcx[col],
  // dcy[r]) against `orbit` and its escape tail (generators/mandelbrot2d.cpp).
  Status perturbation(const std::vector<glm::dvec2>& orbit, const std::vector<double>& dcx,
                      const std::vector<double>& dcy, int max_iter, uint32_t* counts, EscapeTail* tails);

  // The points classified so far and the GPU time their dispatches took (timestamps around each
  // dispatch; 0 on a queue without timestamps): the classification alone, for the bench.
  uint64_t pointsDone() const { return points_done_; }
  double gpuMs() const { return gpu_ms_; }
  // Host milliseconds spent waiting for dispatches to finish, and copying their counts out of the
  // mapped buffers (on several threads): where the thread feeding the generator spends its time.
  double waitMs() const { return wait_ms_; }
  double copyMs() const { return copy_ms_; }

 private:
  struct Slot {
    Buffer counts;  // made by makeCounts
    Buffer tails;  // mandelbrot2d's escape tails; made at the first perturbation call
    VkDescriptorSet escape_set = VK_NULL_HANDLE, perturbation_set = VK_NULL_HANDLE;
    VkDescriptorSet arena_set = VK_NULL_HANDLE;  // the escape kernel writing into arena_
    VkDescriptorSet target_set = VK_NULL_HANDLE;  // and into escapeInto's target (slot 0's only)
    CommandSlot submission;                  // its dispatch's command buffer and fence
    void* destination = nullptr;             // where the counts of the dispatch in flight go; null: in place
    uint32_t count_bytes = 4;                // and the bytes of each there
    uint32_t device_bytes = 4;               // the bytes of each in `counts`
    EscapeTail* tail_destination = nullptr;  // where its tails go (a perturbation dispatch), or null
    uint64_t points = 0;                     // 0: idle
  };

  GpuEscape(const VulkanContext& context, bool pack_counts) : context_(context), packed_counts_(pack_counts) {}
  Status init();
  Status useAxis(const std::vector<double>& axis);  // uploads it where axis_ holds another
  // The slots' staging buffers for counts copied out to the host (Target::kHost, perturbation),
  // made at the first such call: counts in the arena or in device memory need none (2 × 32 MiB of
  // host-visible memory that a device mesher's run never touched).
  Status makeCounts();
  enum class Target { kHost, kArena, kDevice };      // where a dispatch's counts go
  // Dispatches the rows of planes first..first + planes − 1 in chunks: copied out to `counts`
  // (kHost), or written in place from word `word_offset` of the arena or of escapeInto's target.
  // Into device memory, with cap in [0, limit): counted to the cap, then to the limit where the
  // mesh reads them (escapeInto).
  Status escapeRows(const EscapeKernelParams& kernel, uint64_t res, int first, int planes, int limit, Target target,
                    uint64_t word_offset, uint8_t* counts, int cap = -1);
  // escape_refine's pipelines, set and a list of `list_bytes` at least (no dispatch in flight).
  Status makeRefine(uint64_t list_bytes);
  // Its two passes over the slab's `points` counts, capped at the push's cap (an
  // EscapeRefinePush), into `commands` after the counts' dispatches (the push constants as given
  // for the first; the second keeps them).
  void recordRefine(VkCommandBuffer commands, uint32_t kernel, const void* push, uint64_t points) const;
  // Records and submits one dispatch into slot `s`, after finishing what the slot had in flight.
  Status dispatch(size_t s, VkPipeline pipeline, VkPipelineLayout layout, VkDescriptorSet set, const void* push,
                  uint32_t push_bytes, uint64_t points, void* destination, uint32_t count_bytes,
                  uint32_t device_bytes, EscapeTail* tail_destination);
  // Resets a slot's two timestamps (from `query`) and writes the first.
  void stampStart(VkCommandBuffer commands, uint32_t query) const;
  // Pushes the constants and dispatches groups for `points` points (the pipeline and set bound).
  void recordPoints(VkCommandBuffer commands, VkPipelineLayout layout, const void* push, uint32_t push_bytes,
                    uint64_t points) const;
  Status finish(Slot& slot);  // waits for the slot's dispatch and copies its counts (and tails) out
  Status finishAll();

  const VulkanContext& context_;
  VkDescriptorSetLayout escape_set_layout_ = VK_NULL_HANDLE, perturbation_set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout escape_layout_ = VK_NULL_HANDLE, perturbation_layout_ = VK_NULL_HANDLE;
  VkPipeline escape_[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};  // by EscapeKernel
  // escapeInto's counts to a cap, then past it where the mesh reads them: the list of those
  // points and their pipelines (by kernel, then pass), made at the first such call.
  VkDescriptorSetLayout refine_set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout refine_layout_ = VK_NULL_HANDLE;
  VkPipeline refine_[2][2] = {};
  VkDescriptorSet refine_set_ = VK_NULL_HANDLE;
  Buffer refine_list_;
  VkPipeline perturbation_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  Slot slots_[2];
  const bool packed_counts_;  // escape.comp packs the counts, else writes uint32
  bool refine_counts_ = false;  // refinesCounts(); init sets it from the device type
  VkQueryPool queries_ = VK_NULL_HANDLE;  // two timestamps per slot
  uint64_t points_done_ = 0;
  double gpu_ms_ = 0.0;
  double wait_ms_ = 0.0, copy_ms_ = 0.0;
  Buffer axis_, orbit_, dcx_, dcy_;
  Buffer arena_;
  bool arena_sets_stale_ = true;  // the slots' arena sets do not name axis_ and arena_ yet
  std::vector<double> axis_values_;  // what axis_ holds
};

// slab's mesh on the device: its counts by `escape` into the mesher's memory (escapeInto), then
// marching cubes by `mesher`; nothing crosses to the host but the mesh. The slab must be one the
// mesher takes (GpuMesher::supports). With `next` (the slab the following call will mesh), its
// counts are made while this slab's are scanned, so that the device does not wait for the host
// between the slabs (GpuMesher::counts_ahead). The body of an EscapeSlabMesher; one thread at a
// time.
Result<McSlabView> meshSlabOnDevice(GpuEscape& escape, GpuMesher& mesher, const EscapeKernelParams& kernel,
                                    const EscapeSlab& slab, const EscapeSlab* next = nullptr);

}  // namespace dpoint
