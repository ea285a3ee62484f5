// The pipelines of the renderer. The raster backend: render pass (RGBA8 colour + D32 depth, reversed Z),
// and one pipeline per precision mode, built from the SPIR-V compiled at build time (each mode's
// variants and vertex attributes are in its row, viewer/modes.h). The probe
// pipeline is the same shader with the specialization constant kProbe on (DESIGN §5).
#pragma once

#include <span>

#include "vulkan/context.h"
#include "vulkan/shader.h"
#include "viewer/encode.h"

namespace dpoint {

inline constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

// Descriptor bindings shared by every mode (shaders/render/project.glsl): 0 camera uniform,
// 1 positions (the compute backend's in every mode; the raster backend's for the modes that pull
// them from a storage buffer), 2 batch matrices, 3 probe output, 5 the batch plan (per-batch modes:
// the raster backend's tiers per batch, the compute backend's list of batches to splat).
inline constexpr uint32_t kBindingCamera = 0, kBindingPositions = 1, kBindingBatches = 2, kBindingProbe = 3,
                          kBindingBatchPlan = 5;

// Push constants of shaders/render/project.glsl (both backends).
struct PushConstants {
  float splitter = 4097.0f;  // 2^12 + 1: Dekker's split of a 24-bit significand
  float point_size = 1.0f;
  uint32_t first_index = 0;  // index of the draw's first point in the whole set
  uint32_t batch_shift = kBatchShift;  // batchShift(mode): a point's batch is index >> batch_shift
  uint32_t width = 0, height = 0;  // compute backend
  uint32_t count = 0;       // points in the chunk
  uint32_t list_first = 0;  // compute backend, per-batch modes: the chunk's first batch-list entry
  uint32_t listed = 0;      // bit 0: this chunk's workgroups take their batches from the list; bit 1: from its end
  // Round points (shaders/render/push.glsl's roundDepth; roundPointPush fills them).
  float depth_scale = 0.0f;
  float bulge = 0.0f;
};
// The raster backend's stages that read them: the fragment shader of round points too.
inline constexpr VkShaderStageFlags kPointPushStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// Descriptor bindings of the compute backend beyond the shared four: 4 the visibility buffer
// (one uint64 per pixel); the resolve pass has its own set (visibility, colours, picture).
inline constexpr uint32_t kBindingVisibility = 4;
inline constexpr uint32_t kComputeGroupSize = 256;  // local_size_x of both compute shaders
// Points per splat thread (the shader's kPointsPerThread): a workgroup splats 1024 consecutive
// points, each thread one from every 256, so every load is still coalesced.
inline constexpr uint32_t kSplatPointsPerThread = 4;
inline constexpr uint32_t kSplatPointsPerGroup = kComputeGroupSize * kSplatPointsPerThread;

struct PointPipelines {
  VkRenderPass render_pass = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline draw = VK_NULL_HANDLE;
  VkPipeline probe = VK_NULL_HANDLE;  // only when asked for
  bool pulls_positions = false;       // the mode reads a storage buffer instead of vertex input
};

// `pull` selects vertex pulling for a mode with a pull variant (native; ignored by the others). `keep_depth` stores
// the depth attachment and leaves it ready to copy (TRANSFER_SRC_OPTIMAL) for the eye-dome pass. `round`: points
// larger than a pixel are discs (RenderOptions::round_points).
Result<PointPipelines> createPointPipelines(const VulkanContext& context, PrecisionMode mode, bool pull,
                                            bool with_probe, uint32_t width, uint32_t height, bool keep_depth = false,
                                            bool round = false);
void destroyPointPipelines(const VulkanContext& context, PointPipelines& pipelines);

// The compute backend (DESIGN §4): a splat pass per mode (and its probe twin) and the resolve.
struct ComputePipelines {
  VkDescriptorSetLayout splat_set = VK_NULL_HANDLE, resolve_set = VK_NULL_HANDLE;
  VkPipelineLayout splat_layout = VK_NULL_HANDLE, resolve_layout = VK_NULL_HANDLE;
  VkPipeline splat = VK_NULL_HANDLE, probe = VK_NULL_HANDLE, resolve = VK_NULL_HANDLE;
};
struct ResolvePush {
  uint32_t pixels = 0;
  uint32_t background = 0;
  // With write_log: where the log distances go (EdlPush's width, padded_width, margin) and the
  // depth's scale.
  uint32_t width = 0, padded_width = 0, margin = 0;
  float depth_scale = 0.0f;
};
// The splat's variant, fixed when its pipeline is made (specialization constants).
struct SplatVariant {
  // Off: every visible point does its atomic (the plain path tests compare with).
  bool early_depth = true;
  // With early_depth, on a device that has it (DeviceFacts::subgroup_merge): the lanes of a
  // subgroup on one pixel test and write once.
  bool subgroup_merge = true;
  // With early_depth; batch and adaptive modes: two consecutive points on one pixel.
  bool pair_merge = true;
  // Points may be larger than a pixel; false for a render of 1-px points, whose splat then has no
  // square loop (lavapipe: 1.4-1.6x faster, issue #38).
  bool large_points = true;
  // With large_points: discs whose depth falls away to the rim (RenderOptions::round_points).
  bool round = false;
  // A chunk whose push constant `listed` has bit 1 set runs its workgroups from its last to its
  // first (RenderOptions::near_end_first).
  bool near_end_first = false;
};

// `write_log` has the resolve also write each pixel's log distance (binding 3) for the shading.
Result<ComputePipelines> createComputePipelines(const VulkanContext& context, PrecisionMode mode, bool with_probe,
                                                SplatVariant variant = {}, bool write_log = false);
void destroyComputePipelines(const VulkanContext& context, ComputePipelines& pipelines);

// Shading after either backend (shaders/render/shade_common.glsl): reads a float depth per pixel
// (0 = nothing drawn) and the RGBA8 picture, writes the shaded picture (bindings 0, 1, 2); every
// binding is a storage texel buffer, the candidates' (7) also fill_again's indirect dispatch.
struct ShadePipeline {
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline log = VK_NULL_HANDLE, fill = VK_NULL_HANDLE;
  VkPipeline fill_again = VK_NULL_HANDLE;  // over the first filling's candidates, by an indirect dispatch
  // Then either smooth_edl (ShadeRadii::fused) or smooth twice and edl.
  VkPipeline smooth_edl = VK_NULL_HANDLE, smooth = VK_NULL_HANDLE, edl = VK_NULL_HANDLE;
};
struct EdlPush {
  uint32_t width = 0, height = 0;
  // The log-distance buffers hold the picture inside a margin of `margin` pixels all round (no
  // point drawn there), so that no pass tests whether a neighbour is inside the picture.
  uint32_t padded_width = 0, margin = 0;
  float depth_scale = 0.0f;  // perspective: (far − near) / near; 0 for ortho
  float strength = 1.0f;
  int32_t edl_axis = 1, edl_diagonal = 1;  // the eye-dome neighbours' offsets (ShadeRadii)
  float fill_threshold = 0.0f;  // how much nearer (log2 eye distance) a surrounding pixel must be
  uint32_t axis = 0;            // smooth.comp's pass: 0 rows, 1 columns
};
inline constexpr float kShadeEmpty = 3.0e38f;    // shade_common.glsl's kEmpty: the log distance where nothing is drawn
inline constexpr uint32_t kShadeBindings = 8;  // shaders/render/shade_common.glsl
// shade_common.glsl's binding 7: a count and the (x, y, z) of fill_again.comp's indirect dispatch,
// then one pixel index a candidate.
inline constexpr uint32_t kCandidateHeader = 4;
inline constexpr uint32_t kShadeGroupSize = 16;  // local_size_x and _y of the shading passes but smooth_edl.comp
inline constexpr uint32_t kShadeStripGroupSize = 8;  // smooth_edl.comp's
// The shading passes' radii for a point size and an eye-dome radius (compiled into the shaders):
// the filling searches half a point and a pixel each way, the depth is averaged over a square a
// pixel narrower than two points, the eye-dome neighbours lie on a circle of the radius.
struct ShadeRadii {
  int fill = 1, smooth = 0;
  int edl_axis = 1, edl_diagonal = 1;  // the eye-dome neighbours' offsets along the axes and the diagonals
  // Smoothing and eye-dome lighting in one pass (smooth_edl.comp), which holds its window in
  // registers: where asked, for the radii of point sizes up to 8 px and eye-dome radii under 2.5 px.
  bool fused = false;
  int margin() const;  // of the log-distance buffers (EdlPush::margin)
};
inline constexpr int kMaxFusedSmooth = 7, kMaxFusedReach = 2;
inline constexpr uint32_t kShadeStripWidth = 4, kShadeStripHeight = 32;  // pixels a smooth_edl.comp invocation shades
ShadeRadii shadeRadii(float point_size, float edl_radius, bool fuse);
Result<ShadePipeline> createShadePipeline(const VulkanContext& context, ShadeRadii radii);
void destroyShadePipeline(const VulkanContext& context, ShadePipeline& pipeline);

}  // namespace dpoint
