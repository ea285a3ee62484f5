// Marching cubes of escape counts on a Vulkan device (issue #38 item 4): one slab of final counts
// (every count to the limit) in, the slab's mesh out, equal bit for bit to the one
// marchingCubesSlab (generators/marching_cubes.h) makes on the host with the escape grid's
// vertices (generators/escape_grid.cpp's SlabField::vertex). shaders/generate/mesh_slab.comp says
// how: a scan over the slab's elements in canonical order numbers the vertices and the triangles.
//
// The counts never leave the device: GpuEscape::escapeInto writes them into the mesher's memory
// (generators/gpu_generate.h meshSlabOnDevice). Two submissions a slab: the counts and their scan,
// then (with the output buffers grown to the totals) the vertices and triangles, copied across to
// host-visible memory, where the caller reads them; the next slab's counts are submitted between
// them, into the other of two counts buffers. One thread at a
// time may call a GpuMesher, and the same thread as the GpuEscape beside it: both record on the
// context's one queue and pool.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/result.h"
#include "generators/escape_grid.h"
#include "generators/marching_cubes.h"
#include "vulkan/buffers.h"
#include "vulkan/context.h"

namespace dpoint {

class GpuMesher {
 public:
  static Result<std::unique_ptr<GpuMesher>> create(const VulkanContext& context);
  ~GpuMesher();
  GpuMesher(const GpuMesher&) = delete;
  GpuMesher& operator=(const GpuMesher&) = delete;

  // Whether meshSlab takes a slab of `planes` planes of res² counts up to `limit`: counts of one
  // byte (the fraction table has (limit + 1)² entries) and element numbers below 2^31.
  static bool supports(int res, int planes, int limit);

  // Device memory for a slab's counts, `bytes` of them, the first or the second of two (`which`):
  // GpuEscape::escapeInto writes them there, one slab's while another's are meshed.
  Result<const Buffer*> countsBuffer(uint64_t bytes, unsigned which);

  // marchingCubesSlab(res, res, slab.first, slab.last, slab.owns_last_plane, …, slab.seam_positions)
  // with SlabField's vertices (slab.level, frame, values, step) from the slab's final counts, which
  // countsBuffer(…, which) holds, `bits` (8 or 32) each. The view is of host-visible memory that
  // stays as it is until the second call after this one (two buffers, used in turn). With
  // slab.ply_rows, the view has the binary PLY rows instead (McSlabView::vertex_rows and
  // face_rows). `while_scanning`, if set, is called once the first submission is on the queue
  // and before the host waits for it: work submitted there (the next slab's counts into the other
  // counts buffer) runs on the device while the host reads this slab's totals.
  Result<McSlabView> meshSlab(const EscapeSlab& slab, uint32_t bits, unsigned which,
                              const std::function<Status()>& while_scanning = {});

  // Grows the slab buffers for slabs of up to these counts (meshSlab grows them as needed).
  // row_bytes: the slabs' vertex rows (EscapeSlab::rowBytes()), 0 where they are not made as rows.
  Status reserve(uint64_t vertices, uint64_t triangles, bool colors, size_t row_bytes);

  // The counts made ahead into counts buffer `which` by meshSlabOnDevice (generators/gpu_generate.h)
  // while the slab before was meshed: planes first..last of the grid `values` to `limit`, by the
  // escape `escape` with the kernel `kernel` (its kind and constants); taken by the next call if it
  // is for that slab.
  struct CountsAhead {
    const void* escape = nullptr;
    std::array<double, 8> kernel{};
    const std::vector<double>* values = nullptr;
    int first = 0, last = 0, limit = 0;
    unsigned which = 0;
    bool operator==(const CountsAhead&) const = default;
  };
  std::optional<CountsAhead> counts_ahead;

  // The passes' time on the device (timestamps), in ms: counting and scanning, the vertices, the
  // triangles, and copying the mesh across to host-visible memory.
  // copied_beside: the rows were copied across on the transfer queue, beside the next slab's work;
  // `copy` is then the rows' pass alone.
  struct Times {
    double scan = 0.0, vertices = 0.0, triangles = 0.0, copy = 0.0;
    bool copied_beside = false;
    double total() const { return scan + vertices + triangles + copy; }
  };
  const Times& times() const { return times_; }

 private:
  explicit GpuMesher(const VulkanContext& context) : context_(context) {}
  Status init();
  // Records into a slot and submits on the main queue; signals `signal` too where set.
  Status submit(CommandSlot& slot, const std::function<void(VkCommandBuffer)>& record,
                VkSemaphore signal = VK_NULL_HANDLE);
  // A slab's rows copied across to its readback buffer on the context's transfer queue (where it
  // has one), beside the next slab's work on the main queue: the semaphore the rows' submission
  // signals, and the copy's submission. One for each readback buffer.
  struct Copy {
    VkSemaphore ready = VK_NULL_HANDLE;
    CommandSlot slot;
  };
  bool copyBeside() const;  // the device has a transfer queue: the rows are copied there
  // The rows' buffers r released by the main queue's family (release) or acquired by the transfer
  // queue's.
  void rowsOwnership(VkCommandBuffer commands, unsigned r, bool release) const;
  Status submitCopy(Copy& copy, unsigned r, const Buffer& readback, uint64_t vertex_row_bytes, uint64_t face_row_bytes);
  Status ensure(Buffer& buffer, uint64_t bytes, bool host_visible, const char* what);
  void stamp(VkCommandBuffer commands, uint32_t query) const;
  Status readStamps();

  const VulkanContext& context_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  // By pass: mesh_colors.comp (5), and mesh_rows.comp's vertex rows, face rows and vertex rows with
  // the colours as bytes and as floats (6–9); 0–4, mesh_slab.comp's, are in slab_passes_.
  VkPipeline passes_[10] = {};
  VkPipeline slab_passes_[2][5] = {};  // mesh_slab.comp's passes 0–4 for counts of 8 and 32 bits (kBits)
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  CommandSlot submissions_[2];  // recorded again for each slab: the counts' scan (0) and the mesh (1)
  Copy copies_[2];
  Buffer counts_[2], axis_, fractions_, cases_, vertex_groups_, triangle_groups_, totals_;
  Buffer ids_y_, ids_z_, ids_x_, positions_, triangles_, colors_;
  Buffer element_edges_, cell_cases_;  // what passes 0 and 1 found, a byte an element, for passes 3 and 4
  Buffer vertex_rows_[2], face_rows_[2];  // the second only where the rows are copied beside (copyBeside)
  Buffer readback_[2];  // host-visible, used in turn: a slab's positions, colours and triangles
  unsigned next_readback_ = 0;
  std::vector<double> axis_values_;       // what axis_ holds
  double fractions_level_ = 0.0;           // the level and stride fractions_ was made for
  uint32_t fractions_stride_ = 0;
  Times times_;
};

}  // namespace dpoint
