// Escape counts on the Vulkan device (generators/gpu_generate.h) equal the CPU's bit for bit: the
// exact fp64 square root and reciprocal, the Julia and fast Mandelbulb grids at small odd and even
// resolutions, the meshes made from them, and mandelbrot2d's perturbation counts at every depth.
// On lavapipe here, with the validation layer on (any message fails the test).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <span>

#include "converters/ply.h"
#include "generators/julia.h"
#include "generators/mandelbrot2d.h"
#include "generators/mandelbulb.h"
#include "generators/perlin.h"
#include "vulkan/buffers.h"
#include "generators/gpu_generate.h"
#include "vulkan/shader.h"

#include "shaders/exact_fp64_test.comp.h"
#include "test_support.h"

namespace dpoint {
namespace {

class GpuGenerate : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ContextOptions options{"auto", true};
    options.transfer_queue = true;  // as `generate` opens it: a GPU's copies of the rows go there
    Result<std::unique_ptr<VulkanContext>> created = VulkanContext::create(options);
    if (!created) {
      setup_error_ = created.error().message;
      return;
    }
    context_ = std::move(*created);
    Result<std::unique_ptr<GpuEscape>> gpu = GpuEscape::create(*context_);
    if (gpu) gpu_ = std::move(*gpu);
    else setup_error_ = gpu.error().message;
    // lavapipe writes whole counts by default; this one packs them as a GPU does.
    Result<std::unique_ptr<GpuEscape>> packed = GpuEscape::create(*context_, true);
    if (packed) packed_ = std::move(*packed);
  }
  static void TearDownTestSuite() {
    packed_.reset();
    gpu_.reset();
    context_.reset();
  }
  void SetUp() override {
    ASSERT_TRUE(gpu_ && packed_) << setup_error_;
    context_->clearValidationMessages();
  }
  void TearDown() override {
    if (!context_) return;
    for (const std::string& m : context_->validationMessages()) ADD_FAILURE() << m;
  }

  // The device's plane function: counts packed in the shader (as on a GPU) or narrowed on the host.
  static EscapePlaneFunction planes(const EscapeKernelParams& kernel, const GridAxis& axis, bool packed = true) {
    std::vector<double> values(static_cast<size_t>(axis.resolution));
    for (int i = 0; i < axis.resolution; ++i) values[static_cast<size_t>(i)] = axis.value(i);
    GpuEscape* gpu = packed ? packed_.get() : gpu_.get();
    return [kernel, values, gpu](int first, int count, int limit, uint8_t* counts) {
      return gpu->escapePlanes(kernel, values, first, count, limit, counts);
    };
  }
  // The packed device's arena (GpuEscape::arena), as the CLI hands it to a generator.
  static EscapeArena arena() {
    return [](uint64_t bytes) -> uint8_t* {
      Result<uint8_t*> memory = packed_->arena(bytes);
      return memory ? *memory : nullptr;
    };
  }
  static EscapeKernelParams julia(const glm::dvec4& c) {
    return {EscapeKernel::kJulia, c, kJuliaEscapeSquare, 0.0};
  }
  static EscapeKernelParams mandelbulb() {
    return {EscapeKernel::kMandelbulbFast, glm::dvec4(0.0), 0.0, kMandelbulbAxisRho2, kMandelbulbTrapC2};
  }

  // The device's planes [first, first + count) against computeEscapeGrid's, packed (copied out and,
  // into the arena, in place where the rows are whole words) and narrowed: little-endian counts of
  // escapeGridBytesPerCount(limit) bytes, and not a byte written past them.
  static void expectSameGrid(const EscapeKernelParams& kernel, const EscapeRowFunction& row, const GridAxis& axis,
                             int limit, int first, int count) {
    Result<std::vector<uint32_t>> cpu = computeEscapeGrid(axis, limit, row, 0, first, count);
    ASSERT_TRUE(cpu.ok());
    const size_t bytes = static_cast<size_t>(escapeGridBytesPerCount(limit));
    for (int path = 0; path < 3; ++path) {
      const bool packed = path != 1, in_arena = path == 2;
      SCOPED_TRACE("res " + std::to_string(axis.resolution) + ", limit " + std::to_string(limit) + ", planes " +
                   std::to_string(first) + "+" + std::to_string(count) +
                   (in_arena ? ", arena" : packed ? ", packed" : ", narrowed"));
      std::vector<uint8_t> heap(cpu->size() * bytes + 16, 0xA5);
      std::span<uint8_t> gpu(heap);
      if (in_arena) {
        Result<uint8_t*> arena = packed_->arena(heap.size());
        ASSERT_TRUE(arena.ok() && *arena);
        gpu = std::span<uint8_t>(*arena, heap.size());
        std::fill(gpu.begin(), gpu.end(), uint8_t{0xA5});
      }
      Status s = planes(kernel, axis, packed)(first, count, limit, gpu.data());
      ASSERT_TRUE(s.ok()) << s.error().message;
      size_t differ = 0;
      for (size_t i = 0; i < cpu->size(); ++i) {
        const uint32_t c = bytes == 1 ? gpu[i] : gpu[2 * i] | uint32_t{gpu[2 * i + 1]} << 8;
        differ += c != (*cpu)[i];
      }
      EXPECT_EQ(differ, 0u) << "of " << cpu->size();
      for (size_t i = cpu->size() * bytes; i < gpu.size(); ++i) EXPECT_EQ(gpu[i], 0xA5) << "byte " << i;
    }
  }

  static inline std::unique_ptr<VulkanContext> context_;
  static inline std::unique_ptr<GpuEscape> gpu_, packed_;
  static inline std::string setup_error_;
};

// Runs shaders/generate/exact_fp64_test.comp on `inputs`: (sqrtRn, recipRn) of each, the first guesses moved
// `skew` ulps, in the bit-level form (`bits`) or the scaled one.
std::vector<double> runExactShader(const VulkanContext& context, const std::vector<double>& inputs, int32_t skew,
                                   bool bits) {
  const size_t n = inputs.size();
  const VkDeviceSize bytes = 3 * n * sizeof(double);
  Result<Buffer> data = createBuffer(context, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "test data");
  EXPECT_TRUE(data.ok());
  if (!data) return {};
  std::memcpy(data->mapped, inputs.data(), n * sizeof(double));
  VkMappedMemoryRange range = {VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  range.memory = data->memory;
  range.size = VK_WHOLE_SIZE;
  if (!data->coherent) vkFlushMappedMemoryRanges(context.device, 1, &range);
  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  Result<VkDescriptorSetLayout> set_layout = storageSetLayout(context, {binding});
  Result<VkPipelineLayout> layout = pipelineLayout(context, *set_layout, sizeof(uint32_t), VK_SHADER_STAGE_COMPUTE_BIT);
  Result<VkShaderModule> module = createShaderModule(context, kExactFp64TestComp, sizeof(kExactFp64TestComp));
  EXPECT_TRUE(set_layout.ok() && layout.ok() && module.ok());
  VkComputePipelineCreateInfo info = {VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = *module;
  info.stage.pName = "main";
  const int32_t constants[2] = {skew, bits ? 1 : 0};  // constant_id 0 and 2 (exact_fp64.glsl's kExactFp64Bits)
  const VkSpecializationMapEntry entries[2] = {{0, 0, sizeof(int32_t)}, {2, sizeof(int32_t), sizeof(int32_t)}};
  const VkSpecializationInfo specialization{2, entries, sizeof constants, constants};
  info.stage.pSpecializationInfo = &specialization;
  info.layout = *layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateComputePipelines(context.device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline), VK_SUCCESS);
  VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
  VkDescriptorPoolCreateInfo pool_info = {VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 1;
  pool_info.pPoolSizes = &pool_size;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateDescriptorPool(context.device, &pool_info, nullptr, &pool), VK_SUCCESS);
  VkDescriptorSetAllocateInfo allocate = {VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  allocate.descriptorPool = pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &*set_layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  EXPECT_EQ(vkAllocateDescriptorSets(context.device, &allocate, &set), VK_SUCCESS);
  VkDescriptorBufferInfo buffer_info{data->buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet write = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  write.dstSet = set;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  write.pBufferInfo = &buffer_info;
  vkUpdateDescriptorSets(context.device, 1, &write, 0, nullptr);
  const uint32_t count = static_cast<uint32_t>(n);
  Status run = submitOnce(context, [&](VkCommandBuffer commands) {
    vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, *layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(commands, *layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof count, &count);
    vkCmdDispatch(commands, (count + 63) / 64, 1, 1);
    VkMemoryBarrier barrier = {VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier, 0,
                         nullptr, 0, nullptr);
  });
  EXPECT_TRUE(run.ok());
  EXPECT_TRUE(invalidateBuffer(context, *data).ok());
  std::vector<double> out(2 * n);
  std::memcpy(out.data(), static_cast<const double*>(data->mapped) + n, 2 * n * sizeof(double));
  vkDestroyDescriptorPool(context.device, pool, nullptr);
  vkDestroyPipeline(context.device, pipeline, nullptr);
  vkDestroyShaderModule(context.device, *module, nullptr);
  vkDestroyPipelineLayout(context.device, *layout, nullptr);
  vkDestroyDescriptorSetLayout(context.device, *set_layout, nullptr);
  destroyBuffer(context, *data);
  return out;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST_F(GpuGenerate, exactSquareRootAndReciprocalEqualTheCpus) {
  std::mt19937_64 random(14);
  std::uniform_real_distribution<double> unit(1.0, 2.0);
  std::uniform_int_distribution<int> exponent(-1000, 1000);
  std::vector<double> inputs = {1.0, 2.0, 4.0, 0.25, 3.0, 0.5, 1e-60, 1e-240, 256.0, std::nextafter(4.0, 8.0),
                                std::nextafter(1.0, 0.0), std::nextafter(1.0, 2.0), std::nextafter(2.0, 0.0)};
  for (int i = 0; i < 20000; ++i) inputs.push_back(std::ldexp(unit(random), exponent(random)));
  // Near-ties: squares and reciprocals of the midpoints between neighbouring doubles, and their
  // neighbours, where a result off by one ulp would show.
  for (int i = 0; i < 20000; ++i) {
    const double r = unit(random);
    const long double mid = static_cast<long double>(r) + 0x1p-53L;
    const double square = static_cast<double>(mid * mid), inverse = static_cast<double>(1.0L / mid);
    for (double x : {square, inverse})
      for (double d : {std::nextafter(x, 0.0), x, std::nextafter(x, 8.0)}) inputs.push_back(d);
  }
  for (bool bits : {true, false}) {  // the bit-level form (GPUs) and the scaled one (lavapipe)
    for (int32_t skew : {0, 1, 4, 40}) {  // lavapipe's own guesses are already right: skewed ones are not
      SCOPED_TRACE(std::string(bits ? "bit-level" : "scaled") + ", guesses " + std::to_string(skew) + " ulps off");
      const std::vector<double> out = runExactShader(*context_, inputs, skew, bits);
      ASSERT_EQ(out.size(), 2 * inputs.size());
      size_t sqrt_differ = 0, recip_differ = 0;
      for (size_t i = 0; i < inputs.size(); ++i) {
        const double x = inputs[i];
        if (!sameBits(out[2 * i], std::sqrt(x)) && sqrt_differ++ < 5)
          ADD_FAILURE() << "sqrt(" << x << "): " << out[2 * i] << " vs " << std::sqrt(x);
        if (!sameBits(out[2 * i + 1], 1.0 / x) && recip_differ++ < 5)
          ADD_FAILURE() << "1/" << x << ": " << out[2 * i + 1] << " vs " << 1.0 / x;
      }
      EXPECT_EQ(sqrt_differ, 0u);
      EXPECT_EQ(recip_differ, 0u);
    }
  }
}

TEST_F(GpuGenerate, juliaGridEqualsTheCpusAtOddAndEvenResolutions) {
  const glm::dvec4 c(-0.7, 0.27015, 0.27015, 0.0);
  for (int res : {17, 31, 40}) {
    const GridAxis axis{res, -1.5, 1.5};
    expectSameGrid(julia(c), juliaRow(c), axis, 200, 0, res);
    expectSameGrid(julia(c), juliaRow(c), axis, 51, 3, 5);  // the classification cap, some planes
  }
  const glm::dvec4 other(0.3, -0.5, 0.1, 0.2);
  expectSameGrid(julia(other), juliaRow(other), GridAxis{23, -1.2, 1.3}, 300, 0, 23);
}

TEST_F(GpuGenerate, fastMandelbulbGridEqualsTheCpusAtOddAndEvenResolutions) {
  const EscapeRowFunction row = mandelbulbRow(MandelbulbVariant::kFast, 8.0);
  for (int res : {21, 33, 40}) {  // odd: the origin and the polar axis are sampled
    const GridAxis axis{res, -1.5, 1.5};
    expectSameGrid(mandelbulb(), row, axis, 100, 0, res);
    expectSameGrid(mandelbulb(), row, axis, 26, 5, 7);
  }
  expectSameGrid(mandelbulb(), row, GridAxis{25, -0.4, 0.6}, 400, 0, 25);
}

bool sameMesh(const PointSet& a, const PointSet& b) {
  return a.size() == b.size() && a.size() > 0 &&
         std::memcmp(a.positions.data(), b.positions.data(), a.size() * sizeof(glm::dvec3)) == 0 &&
         a.triangles == b.triangles;
}

TEST_F(GpuGenerate, meshesFromDevicePlanesEqualTheCpuMeshes) {
  MandelbulbParams bulb;
  bulb.resolution = 45;
  bulb.variant = MandelbulbVariant::kFast;
  Result<PointSet> cpu = generateMandelbulb(bulb);
  bulb.planes = planes(mandelbulb(), GridAxis{45, -1.5, 1.5});
  Result<PointSet> gpu = generateMandelbulb(bulb);
  ASSERT_TRUE(cpu.ok() && gpu.ok()) << (gpu.ok() ? "" : gpu.error().message);
  ASSERT_EQ(cpu->size(), gpu->size());
  EXPECT_EQ(std::memcmp(cpu->positions.data(), gpu->positions.data(), cpu->size() * sizeof(glm::dvec3)), 0);
  EXPECT_TRUE(cpu->triangles == gpu->triangles);
  // Every count to --max-iter on the device: the mesher reads the blocks' bytes in place.
  bulb.full_counts = true;
  Result<PointSet> full = generateMandelbulb(bulb);
  ASSERT_TRUE(full.ok()) << full.error().message;
  EXPECT_TRUE(sameMesh(*cpu, *full));
  // The blocks in the device's arena, written there in place (res 44: rows of whole words) or
  // copied in (res 45), capped and full.
  for (int res : {44, 45}) {
    MandelbulbParams on_cpu;
    on_cpu.resolution = res;
    on_cpu.variant = MandelbulbVariant::kFast;
    Result<PointSet> expected = generateMandelbulb(on_cpu);
    MandelbulbParams in_arena = on_cpu;
    in_arena.planes = planes(mandelbulb(), GridAxis{res, -1.5, 1.5});
    in_arena.arena = arena();
    for (bool full_counts : {false, true}) {
      in_arena.full_counts = full_counts;
      Result<PointSet> got = generateMandelbulb(in_arena);
      ASSERT_TRUE(expected.ok() && got.ok());
      EXPECT_TRUE(sameMesh(*expected, *got)) << "res " << res << (full_counts ? ", full" : ", capped");
    }
  }
  // Above 255 iterations a count takes two bytes: capped (widened for the CPU's finishing) and full.
  MandelbulbParams deep;
  deep.resolution = 33;
  deep.variant = MandelbulbVariant::kFast;
  deep.max_iter = 1100;  // the cap, ⌊1100/4⌋ + 1 = 276, needs two bytes too
  Result<PointSet> deep_cpu = generateMandelbulb(deep);
  deep.planes = planes(mandelbulb(), GridAxis{33, -1.5, 1.5});
  Result<PointSet> deep_capped = generateMandelbulb(deep);
  deep.full_counts = true;
  Result<PointSet> deep_full = generateMandelbulb(deep);
  ASSERT_TRUE(deep_cpu.ok() && deep_capped.ok() && deep_full.ok());
  EXPECT_TRUE(sameMesh(*deep_cpu, *deep_capped));
  EXPECT_TRUE(sameMesh(*deep_cpu, *deep_full));

  JuliaParams julia_params;
  julia_params.resolution = 38;
  Result<PointSet> julia_cpu = generateJulia(julia_params);
  julia_params.planes = planes(julia(julia_params.c), GridAxis{38, -1.5, 1.5});
  julia_params.arena = arena();
  Result<PointTile> tile = generateJuliaTile(julia_params, {1, 3});
  JuliaParams on_cpu;
  on_cpu.resolution = 38;
  Result<PointTile> tile_cpu = generateJuliaTile(on_cpu, {1, 3});
  ASSERT_TRUE(julia_cpu.ok() && tile.ok() && tile_cpu.ok());
  EXPECT_EQ(std::memcmp(tile->points.positions.data(), tile_cpu->points.positions.data(),
                        tile->points.size() * sizeof(glm::dvec3)),
            0);
  EXPECT_TRUE(tile->points.triangles == tile_cpu->points.triangles);

  bulb.variant = MandelbulbVariant::kSeed;  // libm's trigonometry: no device form
  Result<PointSet> refused = generateMandelbulb(bulb);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().code, ExitCode::kUsage);
  EXPECT_NE(refused.error().message.find("--variant seed runs on the CPU only"), std::string::npos);
}

// Marching cubes on the device (generators/gpu_mesh.h) makes the host's mesh bit for bit: both
// kinds, both frames, counts packed as a GPU writes them (rows of whole words at res 44, not at 45)
// and whole (lavapipe's), whole sets and tiles (a seam's copies, the last tile's own last plane),
// and a --level between counts; counts of two bytes are meshed on the host; a mesher's error ends
// the run with it.
TEST_F(GpuGenerate, marchingCubesOnTheDeviceEqualsTheHosts) {
  Result<std::unique_ptr<GpuMesher>> made = GpuMesher::create(*context_);
  ASSERT_TRUE(made.ok()) << made.error().message;
  GpuMesher& mesher = **made;
  int meshed = 0;
  auto on_device = [&](GpuEscape* escape, const EscapeKernelParams& kernel) {
    EscapeSlabMesher m;
    m.takes = &GpuMesher::supports;
    m.mesh = [&, escape, kernel](const EscapeSlab& slab, const EscapeSlab* next) {
      ++meshed;
      return meshSlabOnDevice(*escape, mesher, kernel, slab, next);
    };
    return m;
  };
  for (int res : {44, 45}) {
    for (GridFrame frame : {GridFrame::kNative, GridFrame::kSeed}) {
      for (bool packed : {true, false}) {
        SCOPED_TRACE("res " + std::to_string(res) + (frame == GridFrame::kSeed ? ", seed frame" : "") +
                     (packed ? ", packed" : ", whole"));
        GpuEscape* escape = packed ? packed_.get() : gpu_.get();
        MandelbulbParams bulb;
        bulb.resolution = res;
        bulb.variant = MandelbulbVariant::kFast;
        bulb.frame = frame;
        bulb.level = 9.5;
        Result<PointSet> expected = generateMandelbulb(bulb);
        bulb.planes = planes(mandelbulb(), GridAxis{res, -1.5, 1.5}, packed);
        bulb.full_counts = true;
        bulb.mesher = on_device(escape, mandelbulb());
        meshed = 0;
        Result<PointSet> got = generateMandelbulb(bulb);
        ASSERT_TRUE(expected.ok() && got.ok()) << (got.ok() ? "" : got.error().message);
        EXPECT_GT(meshed, 1);
        EXPECT_TRUE(sameMesh(*expected, *got));
        EXPECT_TRUE(got->colors.empty());
        // The seed noise colours made on the device: the host's seedColor, bit for bit.
        bulb.noise_colors = true;
        Result<PointSet> colored = generateMandelbulb(bulb);
        ASSERT_TRUE(colored.ok()) << colored.error().message;
        EXPECT_TRUE(sameMesh(*expected, *colored));
        PointSet host_colored = *expected;
        colorByNoise(host_colored, 0);
        ASSERT_EQ(colored->colors.size(), host_colored.colors.size());
        EXPECT_EQ(std::memcmp(colored->colors.data(), host_colored.colors.data(), host_colored.colors.size() * sizeof(glm::vec3)), 0);

        JuliaParams julia_params;
        julia_params.resolution = res;
        julia_params.frame = frame;
        JuliaParams on_cpu = julia_params;
        julia_params.planes = planes(julia(julia_params.c), GridAxis{res, -1.5, 1.5}, packed);
        julia_params.full_counts = true;
        julia_params.mesher = on_device(escape, julia(julia_params.c));
        for (uint32_t index : {0u, 1u, 2u}) {
          Result<PointTile> tile = generateJuliaTile(julia_params, {index, 3});
          Result<PointTile> tile_cpu = generateJuliaTile(on_cpu, {index, 3});
          ASSERT_TRUE(tile.ok() && tile_cpu.ok());
          EXPECT_TRUE(sameMesh(tile->points, tile_cpu->points)) << "tile " << index;
          EXPECT_EQ(tile->owned, tile_cpu->owned);
          ASSERT_EQ(tile->foreign.size(), tile_cpu->foreign.size());
          for (size_t i = 0; i < tile->foreign.size(); ++i)
            EXPECT_TRUE(tile->foreign[i].tile == tile_cpu->foreign[i].tile &&
                        tile->foreign[i].index == tile_cpu->foreign[i].index);
        }
      }
    }
  }
  // Coordinates past the noise's fast range (|v| + 200 from 1000 on): no colours from the mesher.
  MandelbulbParams wide;
  wide.resolution = 24;
  wide.variant = MandelbulbVariant::kFast;
  wide.lo = -900.0;
  wide.hi = 900.0;
  wide.planes = planes(mandelbulb(), GridAxis{24, -900.0, 900.0});
  wide.full_counts = true;
  wide.mesher = on_device(packed_.get(), mandelbulb());
  wide.noise_colors = true;
  Result<PointSet> wide_mesh = generateMandelbulb(wide);
  ASSERT_TRUE(wide_mesh.ok());
  EXPECT_TRUE(wide_mesh->colors.empty());
  // Two-byte counts (--max-iter 300): the mesher does not take them and the host meshes the slabs.
  MandelbulbParams deep;
  deep.resolution = 33;
  deep.variant = MandelbulbVariant::kFast;
  deep.max_iter = 300;
  Result<PointSet> deep_cpu = generateMandelbulb(deep);
  deep.planes = planes(mandelbulb(), GridAxis{33, -1.5, 1.5});
  deep.full_counts = true;
  deep.mesher = on_device(packed_.get(), mandelbulb());
  meshed = 0;
  Result<PointSet> deep_gpu = generateMandelbulb(deep);
  ASSERT_TRUE(deep_cpu.ok() && deep_gpu.ok());
  EXPECT_EQ(meshed, 0);
  EXPECT_TRUE(sameMesh(*deep_cpu, *deep_gpu));
  // A mesher that fails: the run ends with its error.
  deep.max_iter = 100;
  deep.mesher.mesh = [](const EscapeSlab&, const EscapeSlab*) -> Result<McSlabView> {
    return Error{"the device was lost", ExitCode::kNoDevice};
  };
  Result<PointSet> failed = generateMandelbulb(deep);
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.error().code, ExitCode::kNoDevice);
  EXPECT_EQ(failed.error().message, "the device was lost");
}

// The mesh as the device's PLY rows (EscapeRowSink), written by a PlyRowStream: writePly's file of
// the host's mesh, byte for byte, with the noise colours and without, odd and even resolutions
// (rows of 27 and 24 bytes, slabs whose rows start anywhere in a word).
TEST_F(GpuGenerate, rowsOnTheDeviceWriteTheHostsFile) {
  Result<std::unique_ptr<GpuMesher>> made = GpuMesher::create(*context_);
  ASSERT_TRUE(made.ok()) << made.error().message;
  GpuMesher& mesher = **made;
  test::TempDir dir;
  for (int res : {44, 45}) {
    for (bool colors : {true, false}) {
     // The counts to the cap and then past it where an edge crosses the level (a GPU's default),
     // packed as a GPU's and whole as lavapipe's, and all to the limit (lavapipe's): the same file.
     for (int counts = 0; counts < 3; ++counts) {
      const bool refine = counts < 2;
      GpuEscape* escape = counts == 1 ? gpu_.get() : packed_.get();
      SCOPED_TRACE("res " + std::to_string(res) + (colors ? ", colours" : "") + (refine ? ", refined" : "") +
                   (counts == 1 ? ", uint32 counts" : ""));
      escape->setRefinesCounts(refine);
      MandelbulbParams bulb;
      bulb.resolution = res;
      bulb.variant = MandelbulbVariant::kFast;
      Result<PointSet> expected = generateMandelbulb(bulb);
      ASSERT_TRUE(expected.ok());
      PlyWriteOptions write;
      if (colors) write.colors_of = seedColors;
      ASSERT_TRUE(writePly(dir.file("host.ply"), *expected, write).ok());

      bulb.planes = planes(mandelbulb(), GridAxis{res, -1.5, 1.5}, true);
      bulb.full_counts = true;
      bulb.noise_colors = colors;
      // Each slab's counts are made once: those of the slab named as `next` while the one before
      // is meshed, and taken from there.
      const uint64_t points_before = escape->pointsDone();
      uint64_t slab_points = 0, ahead = 0;
      bulb.mesher.takes = &GpuMesher::supports;
      bulb.mesher.mesh = [&](const EscapeSlab& slab, const EscapeSlab* next) {
        slab_points += static_cast<uint64_t>(slab.last - slab.first + 1) * static_cast<uint64_t>(res * res);
        ahead += next ? 1 : 0;
        return meshSlabOnDevice(*escape, mesher, mandelbulb(), slab, next);
      };
      bulb.mesher.reserve = [&](uint64_t v, uint64_t t, bool c, size_t r) { return mesher.reserve(v, t, c, r); };
      Result<std::unique_ptr<PlyRowStream>> stream = PlyRowStream::create(dir.file("device.ply"), colors, 0, nullptr);
      ASSERT_TRUE(stream.ok() && *stream);
      PlyRowStream& to = **stream;
      bulb.rows.colors = colors;
      bulb.rows.start = [&](uint64_t v, uint64_t t) { return to.start(v, t); };
      bulb.rows.slab = [&](std::span<const uint8_t> v, std::span<const uint8_t> f) { return to.add(v, f); };
      Result<PointSet> got = generateMandelbulb(bulb);
      ASSERT_TRUE(got.ok()) << got.error().message;
      EXPECT_EQ(got->size(), 0u);  // the rows went to the stream
      EXPECT_GT(ahead, 1u);
      EXPECT_EQ(escape->pointsDone() - points_before, slab_points);
      ASSERT_TRUE(to.started());
      ASSERT_TRUE(to.finish().ok());
      EXPECT_EQ(to.vertices(), expected->size());
      EXPECT_TRUE(test::readFile(dir.file("device.ply")) == test::readFile(dir.file("host.ply")));
     }
    }
  }
  for (GpuEscape* escape : {gpu_.get(), packed_.get()}) escape->setRefinesCounts(context_->facts.type != "cpu");
}

// A GPU's host-visible buffers come from the process's own memory, imported (the readback
// buffers the rows cross to the host in; ContextOptions::import_host_memory). Forced here on
// lavapipe for every size, with the validation layer: the same file, no message.
TEST_F(GpuGenerate, rowsReadBackThroughImportedHostMemoryWriteTheHostsFile) {
  ContextOptions options{"auto", true};
  options.import_host_memory = true;
  Result<std::unique_ptr<VulkanContext>> context = VulkanContext::create(options);
  ASSERT_TRUE(context.ok()) << context.error().message;
  VulkanContext& imports = **context;
  ASSERT_GT(imports.host_import_alignment, 0u);  // lavapipe has VK_EXT_external_memory_host
  imports.host_import_from = 0;
  {
    Result<Buffer> buffer = createBuffer(imports, 1000, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "a test");
    ASSERT_TRUE(buffer.ok()) << buffer.error().message;
    EXPECT_TRUE(buffer->host_pages && buffer->mapped == buffer->host_pages);
    EXPECT_EQ(buffer->host_bytes % imports.host_import_alignment, 0u);
    EXPECT_EQ(imports.device_memory_used.load(), buffer->host_bytes);
    destroyBuffer(imports, *buffer);
    EXPECT_EQ(imports.device_memory_used.load(), 0u);
  }
  Result<std::unique_ptr<GpuEscape>> escape = GpuEscape::create(imports, true);
  ASSERT_TRUE(escape.ok()) << escape.error().message;
  Result<std::unique_ptr<GpuMesher>> mesher = GpuMesher::create(imports);
  ASSERT_TRUE(mesher.ok()) << mesher.error().message;
  test::TempDir dir;
  MandelbulbParams bulb;
  bulb.resolution = 45;
  bulb.variant = MandelbulbVariant::kFast;
  Result<PointSet> expected = generateMandelbulb(bulb);
  ASSERT_TRUE(expected.ok());
  PlyWriteOptions write;
  write.colors_of = seedColors;
  ASSERT_TRUE(writePly(dir.file("host.ply"), *expected, write).ok());
  bulb.planes = planes(mandelbulb(), GridAxis{45, -1.5, 1.5}, true);
  bulb.full_counts = true;
  bulb.noise_colors = true;
  bulb.mesher.takes = &GpuMesher::supports;
  bulb.mesher.mesh = [&](const EscapeSlab& slab, const EscapeSlab* next) {
    return meshSlabOnDevice(**escape, **mesher, mandelbulb(), slab, next);
  };
  bulb.mesher.reserve = [&](uint64_t v, uint64_t t, bool c, size_t r) { return (*mesher)->reserve(v, t, c, r); };
  Result<std::unique_ptr<PlyRowStream>> stream = PlyRowStream::create(dir.file("device.ply"), true, 0, nullptr);
  ASSERT_TRUE(stream.ok() && *stream);
  bulb.rows.colors = true;
  bulb.rows.start = [&](uint64_t v, uint64_t t) { return (*stream)->start(v, t); };
  bulb.rows.slab = [&](std::span<const uint8_t> v, std::span<const uint8_t> f) { return (*stream)->add(v, f); };
  Result<PointSet> got = generateMandelbulb(bulb);
  ASSERT_TRUE(got.ok()) << got.error().message;
  ASSERT_TRUE((*stream)->finish().ok());
  EXPECT_TRUE(test::readFile(dir.file("device.ply")) == test::readFile(dir.file("host.ply")));
  mesher->reset();
  escape->reset();
  for (const std::string& m : imports.validationMessages()) ADD_FAILURE() << m;
}

// Where the device has no room for the list of the points to count past the cap (a device memory
// budget that the first run filled), the counts go to the limit instead, for the rest of the run:
// the same mesh.
TEST_F(GpuGenerate, countsGoToTheLimitWhereTheDeviceHasNoRoomForTheList) {
  Result<std::unique_ptr<GpuMesher>> made = GpuMesher::create(*context_);
  ASSERT_TRUE(made.ok()) << made.error().message;
  GpuMesher& mesher = **made;
  Result<std::unique_ptr<GpuEscape>> fresh = GpuEscape::create(*context_, true);  // no list made yet
  ASSERT_TRUE(fresh.ok()) << fresh.error().message;
  GpuEscape& escape = **fresh;
  MandelbulbParams bulb;
  bulb.resolution = 44;
  bulb.variant = MandelbulbVariant::kFast;
  Result<PointSet> expected = generateMandelbulb(bulb);
  ASSERT_TRUE(expected.ok());
  bulb.planes = planes(mandelbulb(), GridAxis{44, -1.5, 1.5}, true);
  bulb.full_counts = true;
  bulb.mesher.takes = &GpuMesher::supports;
  bulb.mesher.mesh = [&](const EscapeSlab& slab, const EscapeSlab* next) {
    return meshSlabOnDevice(escape, mesher, mandelbulb(), slab, next);
  };
  // Every buffer but the list made, at a size no slab passes (the whole mesh has 5,404 vertices).
  ASSERT_TRUE(mesher.reserve(100000, 200000, false, 0).ok());
  escape.setRefinesCounts(false);
  Result<PointSet> got = generateMandelbulb(bulb);
  ASSERT_TRUE(got.ok()) << got.error().message;
  EXPECT_TRUE(got->positions == expected->positions && got->triangles == expected->triangles);
  context_->device_memory_budget = context_->device_memory_used.load();
  escape.setRefinesCounts(true);
  got = generateMandelbulb(bulb);
  context_->device_memory_budget = 0;
  ASSERT_TRUE(got.ok()) << got.error().message;
  EXPECT_FALSE(escape.refinesCounts());
  EXPECT_TRUE(got->positions == expected->positions && got->triangles == expected->triangles);
}

// --max-memory is checked against what the path holds: the streamed rows hold the face rows (13
// bytes a triangle) and two slabs' copies, the mesh in memory holds the mesh, the host's workers
// their buffers and blocks too. At res 44 the estimates are about 240 KB, 380 KB and more than
// 440 KB: 300 KB lets the streamed rows through and refuses the others, naming --max-memory.
TEST_F(GpuGenerate, maxMemoryIsWhatTheStreamedRowsHold) {
  Result<std::unique_ptr<GpuMesher>> made = GpuMesher::create(*context_);
  ASSERT_TRUE(made.ok()) << made.error().message;
  GpuMesher& mesher = **made;
  test::TempDir dir;
  auto params = [&](bool mesher_elsewhere) {
    MandelbulbParams bulb;
    bulb.resolution = 44;
    bulb.variant = MandelbulbVariant::kFast;
    bulb.threads = 2;
    bulb.max_memory = 300u << 10;
    bulb.planes = planes(mandelbulb(), GridAxis{44, -1.5, 1.5}, true);
    bulb.full_counts = true;
    if (mesher_elsewhere) {
      bulb.mesher.takes = &GpuMesher::supports;
      bulb.mesher.mesh = [&](const EscapeSlab& slab, const EscapeSlab* next) {
        return meshSlabOnDevice(*packed_, mesher, mandelbulb(), slab, next);
      };
    }
    return bulb;
  };
  for (bool elsewhere : {false, true}) {
    SCOPED_TRACE(elsewhere ? "the mesh in memory, made on the device" : "the host's workers");
    Result<PointSet> refused = generateMandelbulb(params(elsewhere));
    ASSERT_FALSE(refused.ok());
    EXPECT_EQ(refused.error().code, ExitCode::kResourceLimit);
    EXPECT_NE(refused.error().message.find("--max-memory"), std::string::npos) << refused.error().message;
  }
  MandelbulbParams streamed = params(true);
  Result<std::unique_ptr<PlyRowStream>> stream = PlyRowStream::create(dir.file("rows.ply"), false, 0, nullptr);
  ASSERT_TRUE(stream.ok() && *stream);
  PlyRowStream& to = **stream;
  streamed.rows.start = [&](uint64_t v, uint64_t t) { return to.start(v, t); };
  streamed.rows.slab = [&](std::span<const uint8_t> v, std::span<const uint8_t> f) { return to.add(v, f); };
  Result<PointSet> got = generateMandelbulb(streamed);
  ASSERT_TRUE(got.ok()) << got.error().message;
  ASSERT_TRUE(to.finish().ok());
  EXPECT_GT(to.vertices(), 0u);
}

bool sameBits(const PointSet& a, const PointSet& b) {
  return a.size() == b.size() && a.colors.size() == b.colors.size() &&
         std::memcmp(a.positions.data(), b.positions.data(), a.size() * sizeof(glm::dvec3)) == 0 &&
         std::memcmp(a.colors.data(), b.colors.data(), a.colors.size() * sizeof(glm::vec3)) == 0;
}

PerturbationFunction onTheDevice(GpuEscape& gpu) {
  return [&gpu](const std::vector<glm::dvec2>& orbit, const std::vector<double>& dcx, const std::vector<double>& dcy,
                int max_iter, uint32_t* counts, EscapeTail* tails) {
    return gpu.perturbation(orbit, dcx, dcy, max_iter, counts, tails);
  };
}

TEST_F(GpuGenerate, mandelbrot2dPerturbationCountsAndTailsEqualTheCpusAtEveryDepth) {
  for (double width : {3.0, 1e-3, 1e-6, 1e-9, 1e-12}) {
    for (int res : {31, 32}) {
      SCOPED_TRACE("width " + std::to_string(width) + ", res " + std::to_string(res));
      Mandelbrot2dParams params;
      params.width = width;
      params.resolution = res;
      params.max_iter = 1500;
      Result<Mandelbrot2dEscapes> cpu = mandelbrot2dEscapes(params);
      params.perturbation = onTheDevice(*gpu_);
      Result<Mandelbrot2dEscapes> gpu = mandelbrot2dEscapes(params);
      ASSERT_TRUE(cpu.ok() && gpu.ok()) << (gpu.ok() ? "" : gpu.error().message);
      EXPECT_TRUE(cpu->counts == gpu->counts);
      ASSERT_EQ(cpu->tails.size(), gpu->tails.size());
      size_t differ = 0;
      for (size_t i = 0; i < cpu->tails.size(); ++i)
        differ += !sameBits(cpu->tails[i].z2, gpu->tails[i].z2) || cpu->tails[i].steps != gpu->tails[i].steps;
      EXPECT_EQ(differ, 0u) << "escape tails of " << cpu->tails.size();
    }
  }
}

TEST_F(GpuGenerate, mandelbrot2dColoursEqualTheCpusWholeAndInTiles) {
  // Auto max_iter; resolutions under and over the pre-pass's (the pre-pass on the device too).
  for (double width : {1e-6, 1e-12, 1e-15}) {
    for (int res : {33, 150}) {
      SCOPED_TRACE("width " + std::to_string(width) + ", res " + std::to_string(res));
      Mandelbrot2dParams params;
      params.width = width;
      params.resolution = res;
      if (width == 1e-6) params.max_iter = 600;  // the inside costs max_iter per point on lavapipe
      Result<PointSet> cpu = generateMandelbrot2d(params);
      params.perturbation = onTheDevice(*gpu_);
      Result<PointSet> gpu = generateMandelbrot2d(params);
      ASSERT_TRUE(cpu.ok() && gpu.ok()) << (gpu.ok() ? "" : gpu.error().message);
      EXPECT_TRUE(sameBits(*cpu, *gpu));
      Result<PointTile> tile = generateMandelbrot2dTile(params, {2, 5});
      ASSERT_TRUE(tile.ok());
      const size_t first = static_cast<size_t>(2 * res / 5) * static_cast<size_t>(res);
      ASSERT_LE(first + tile->points.size(), cpu->size());
      EXPECT_EQ(std::memcmp(tile->points.colors.data(), cpu->colors.data() + first,
                            tile->points.size() * sizeof(glm::vec3)),
                0);
    }
  }
}

}  // namespace
}  // namespace dpoint
